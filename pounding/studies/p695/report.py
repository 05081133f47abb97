"""A P695 archive's report: the printed table, the JSON summary, the plot."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from pounding.units import STANDARD_GRAVITY

__all__ = ["VERDICT_WORDS", "p695_summary", "p695_table", "p695_tables", "pounding_effect", "plot_p695"]

VERDICT_WORDS = {1: "PASS", 0: "FAIL", -1: "not determinable"}
_VARIANT = {"with_contacts": "with contacts", "without_contacts": "without contacts"}


def _g(value: float) -> float | None:
    return None if not math.isfinite(value) else float(value) / STANDARD_GRAVITY


def _plain(value: float) -> float | None:
    return float(value) if math.isfinite(value) else None


def p695_summary(ds) -> dict:
    """The verdict per building and variant as plain data (accelerations in g)."""
    out: dict = {"model": ds.attrs["model_name"], "sdc": ds.attrs["sdc"], "quality": ds.attrs["quality"],
                 **({"analysis": ds.attrs["analysis"]} if "analysis" in ds.attrs else {}),
                 "s_ms_g": ds.attrs["s_ms"] / STANDARD_GRAVITY, "s_m1_g": ds.attrs["s_m1"] / STANDARD_GRAVITY,
                 "records": int(ds.sizes["record"]), "buildings": {}}
    for name in ds.building.values:
        b = ds.sel(building=name)
        entry = {"system": str(b.system.values), "height_m": float(b.height), "T_a_s": float(b.approximate_period),
                 **({"pushover_axis": str(b.pushover_axis.values)} if "pushover_axis" in b else {}),
                 "C_u": float(b.upper_limit_coefficient), "T_s": float(b.period), "T1_s": float(b.period_t1),
                 "mu_T": float(b.period_based_ductility), "mu_T_lower_bound": bool(b.ductility_is_lower_bound),
                 "SSF": float(b.ssf), "S_MT_g": _g(float(b.s_mt)), "beta_TOT": float(b.beta_tot),
                 "ACMR_10": float(b.acmr_10), "ACMR_20": float(b.acmr_20), "variants": {}}
        for variant in ds.variant.values:
            v = b.sel(variant=variant)
            entry["variants"][str(variant)] = {"S_CT_g": _g(float(v.s_ct)), "CMR": _plain(float(v.cmr)),
                                               "ACMR": _plain(float(v.acmr)),
                                               "verdict": VERDICT_WORDS[int(v.passes)], "note": str(v.note.values),
                                               **({"records": _counts(v)} if "records_collapsed" in v else {})}
        out["buildings"][str(name)] = entry
    if "group_passes" in ds:
        out["group"] = {"buildings": ds.attrs["group"].split(","), "variants": {
            str(v): {"mean_ACMR": _plain(float(ds.group_mean_acmr.sel(variant=v))),
                     "ACMR_10": _plain(float(ds.group_acmr_10.sel(variant=v))),
                     "verdict": "PASS" if int(ds.group_passes.sel(variant=v)) else "FAIL"}
            for v in ds.variant.values}}
    return out


def _counts(v) -> dict[str, int]:
    """A building's records in one variant: collapsed, censored by another building's collapse, no collapse."""
    return {"collapsed": int(v.records_collapsed), "censored": int(v.records_censored),
            "no_collapse": int(v.records_not_collapsed)}


def pounding_effect(ds) -> list[str]:
    """One line per building: whether pounding turns its verdict (needs both variants)."""
    if "without_contacts" not in ds.variant.values:
        return []
    lines = []
    for name in ds.building.values:
        w = int(ds.passes.sel(variant="with_contacts", building=name))
        o = int(ds.passes.sel(variant="without_contacts", building=name))
        acmr = [float(ds.acmr.sel(variant=v, building=name)) for v in ("without_contacts", "with_contacts")]
        change = f" (ACMR {acmr[0]:.2f} -> {acmr[1]:.2f})" if all(map(math.isfinite, acmr)) else ""
        if -1 in (w, o):
            where = " and ".join(_VARIANT[v] for v, p in (("with_contacts", w), ("without_contacts", o)) if p == -1)
            lines.append(f"{name}: S_CT not determinable {where}; the verdicts are not compared")
        elif o == 1 and w == 0:
            lines.append(f"{name}: pounding turns it from PASS into FAIL{change}")
        elif o == 0 and w == 1:
            lines.append(f"{name}: pounding turns it from FAIL into PASS{change}")
        else:
            lines.append(f"{name}: pounding does not change the verdict, {VERDICT_WORDS[w]}{change}")
    return lines


def p695_table(ds) -> str:
    """The printed report: the building's inputs, then the verdict per variant."""
    g = STANDARD_GRAVITY
    lines = [f"FEMA P695 evaluation of '{ds.attrs['model_name']}': SDC {ds.attrs['sdc']} "
             f"(S_MS {ds.attrs['s_ms'] / g:.3g} g, S_M1 {ds.attrs['s_m1'] / g:.3g} g, {ds.attrs['spectrum_source']}), "
             f"quality {ds.attrs['quality']}, {ds.sizes['record']} records",
             f"{'building':<10}{'system':<14}{'h m':>7}{'T_a s':>7}{'C_u':>6}{'T s':>7}{'T1 s':>7}{'mu_T':>7}"
             f"{'SSF':>6}{'S_MT g':>8}{'b_TOT':>7}{'ACMR10':>8}{'ACMR20':>8}"]
    for name in ds.building.values:
        b = ds.sel(building=name)
        mu = f"{'>=' if int(b.ductility_is_lower_bound) else ''}{float(b.period_based_ductility):.2f}"
        lines.append(f"{str(name):<10}{str(b.system.values):<14}{float(b.height):7.1f}{float(b.approximate_period):7.3f}"
                     f"{float(b.upper_limit_coefficient):6.2f}{float(b.period):7.3f}{float(b.period_t1):7.3f}"
                     f"{mu:>7}{float(b.ssf):6.2f}{float(b.s_mt) / g:8.3f}{float(b.beta_tot):7.3f}"
                     f"{float(b.acmr_10):8.2f}{float(b.acmr_20):8.2f}")
    if str(ds.attrs.get("analysis", "")).startswith("three"):
        lines.append(f"{ds.attrs['analysis']}; mu_T: the smaller of the pushovers along x and y (torsion-free "
                     "chains): " + ", ".join(f"{b} {a}" for b, a in zip(ds.building.values, ds.pushover_axis.values)))
    counted = "records_collapsed" in ds
    lines.append(f"{'building':<10}{'variant':<18}{'S_CT g':>8}{'CMR':>7}{'ACMR':>7}"
                 + (f"{'collapsed':>10}{'censored':>9}{'no coll.':>9}" if counted else "")
                 + "  verdict (ACMR >= ACMR20)")
    for name in ds.building.values:
        for variant in ds.variant.values:
            v = ds.sel(building=name, variant=variant)
            note = str(v.note.values)
            records = "".join(f"{n:>{w}}" for n, w in zip(_counts(v).values(), (10, 9, 9))) if counted else ""
            lines.append(f"{str(name):<10}{_VARIANT.get(str(variant), str(variant)):<18}{float(v.s_ct) / g:8.3f}"
                         f"{float(v.cmr):7.2f}{float(v.acmr):7.2f}{records}  {VERDICT_WORDS[int(v.passes)]}"
                         + (f" ({note})" if note else ""))
    if "group_passes" in ds:
        for variant in ds.variant.values:
            lines.append(f"group {ds.attrs['group']} {_VARIANT.get(str(variant), str(variant))}: mean ACMR "
                         f"{float(ds.group_mean_acmr.sel(variant=variant)):.2f} against ACMR10 "
                         f"{float(ds.group_acmr_10.sel(variant=variant)):.2f}: "
                         f"{'PASS' if int(ds.group_passes.sel(variant=variant)) else 'FAIL'}")
    lines += pounding_effect(ds)
    return "\n".join(lines)


def p695_tables(ds) -> dict:
    """Tables of a P695 archive: ``verdict`` (per variant and building: S_CT, CMR, ACMR, pass, note, with
    the building's T, S_MT, μ_T, SSF, β_TOT and acceptable ACMRs beside) and ``records`` (per variant,
    building and record: the collapse intensity); units in the headers."""
    from pounding.results.tables import long_table

    beside = [n for n in ("system", "period", "period_t1", "period_based_ductility", "pushover_axis", "s_mt", "ssf",
                          "beta_tot", "acmr_10", "acmr_20") if n in ds.variables]
    counts = [n for n in ("records_collapsed", "records_censored", "records_not_collapsed") if n in ds.variables]
    verdict_table = long_table(ds, ["s_ct", "cmr", "acmr", "passes", "note"] + counts, extra=beside)
    per_record = ["collapse_intensity"] + (["record_outcome"] if "record_outcome" in ds.variables else [])
    return {"verdict": verdict_table, "records": long_table(ds, per_record)}


def _fraction_collapsed(v) -> tuple[np.ndarray | None, np.ndarray]:
    """The Kaplan-Meier fraction of records collapsed of one building and variant: (intensities m/s², fraction),
    (None, []) if no record ran (an archive without ``record_outcome``: finite values collapses, inf none)."""
    from pounding.studies.fragility import kaplan_meier

    values = v.collapse_intensity.values
    if "record_outcome" in v:
        outcome = v.record_outcome.values
    else:
        outcome = np.where(np.isnan(values), "failed", np.where(np.isinf(values), "no collapse", "collapsed"))
    ran = outcome != "failed"
    if not ran.any():
        return None, np.zeros(0)
    at, fraction = kaplan_meier(values[ran], outcome[ran] == "collapsed")
    return at, np.array([float(f) for f in fraction])


def plot_p695(ds, directory: str | os.PathLike) -> list[Path]:
    """``p695.png``: per building, the Kaplan-Meier fraction of records collapsed (censored records counted
    while observed) against the set's median Sa(T), per variant, with S_MT and S_CT marked."""
    from pounding.results.plots import plot_directory, pyplot, save_figure, suptitle

    plt = pyplot()
    out = plot_directory(directory)
    g = STANDARD_GRAVITY
    buildings = [str(b) for b in ds.building.values]
    fig, axes = plt.subplots(1, len(buildings), figsize=(5.2 * len(buildings), 4.0), squeeze=False)
    for ax, name in zip(axes[0], buildings):
        b = ds.sel(building=name)
        for variant, style in zip(ds.variant.values, ("-", "--")):
            at, fraction = _fraction_collapsed(b.sel(variant=variant))
            if at is None:
                continue
            ax.step(np.r_[0.0, at / g], np.r_[0.0, fraction], style, where="post",
                    label=f"{_VARIANT.get(str(variant), str(variant))}: ACMR {float(b.acmr.sel(variant=variant)):.2f} "
                          f"({VERDICT_WORDS[int(b.passes.sel(variant=variant))]})")
        ax.axvline(float(b.s_mt) / g, color="k", lw=0.8, ls=":", label=f"S_MT {float(b.s_mt) / g:.2f} g")
        ax.axhline(0.5, color="0.6", lw=0.6)
        ax.set_xlabel(f"median Sa(T = {float(b.period):.2f} s) of the normalised set (g)")
        ax.set_ylabel("fraction of records collapsed")
        ax.set_title(f"building {name}")
        ax.set_ylim(0, 1.02)
        ax.legend(fontsize=7, loc="lower right")
    suptitle(fig, f"{ds.attrs.get('title', 'FEMA P695')}\n{_p695_intensity(ds)}")
    return [save_figure(fig, out / "p695.png")]


def _p695_intensity(ds) -> str:
    """The records and intensities of a P695 archive in words, for its figure's title."""
    from pounding.studies.common import records_text

    g = STANDARD_GRAVITY
    return (f"{records_text(list(ds.record.values))}, normalised (FEMA P695 Appendix A) and scaled by the collapse "
            f"hunt; SDC {ds.attrs.get('sdc', '')}: S_MS {float(ds.attrs.get('s_ms', 'nan')) / g:.3g} g, "
            f"S_M1 {float(ds.attrs.get('s_m1', 'nan')) / g:.3g} g")

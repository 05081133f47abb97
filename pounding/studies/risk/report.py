"""The risk archive (the IDA's, plus the risk variables), its printed table, CSV tables and figure."""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

import numpy as np

from pounding.units import STANDARD_GRAVITY

__all__ = ["assemble_risk_dataset", "separation_demands", "COLLAPSE_TARGET", "risk_table", "risk_tables", "plot_risk", "SEPARATION_POINTS"]

#: Separations at which λ(g) is tabulated in the archive (0 to 1.25 x the largest finite demand).
SEPARATION_POINTS = 121


def _var(dims, data, units, long_name):
    return (dims, data, {"units": units, "long_name": long_name})


def _pounding_vars(plan, stripes: np.ndarray, demands: np.ndarray) -> tuple[dict, np.ndarray]:
    """Per contact: λ(g) on a grid, its probability, the separation meeting the target, the own gap's risk."""
    from pounding.studies.risk.integrals import (exceedance_rates, lowest_stripe_share, probability_in,
                                                 rate_for_probability, separation_for_rate)

    p, years = plan.target
    target = rate_for_probability(p, years)
    finite = demands[np.isfinite(demands)]
    grid = np.linspace(0.0, 1.25 * float(finite.max()) if finite.size else 1.0, SEPARATION_POINTS)
    nc = demands.shape[-1]
    rates = np.full((nc, grid.size), np.nan)
    meets, own, share = np.full(nc, np.nan), np.full(nc, np.nan), np.full(nc, np.nan)
    for c in range(nc):
        d = demands[:, :, c].T   # (stripe, record)
        if not np.any(~np.isnan(d)):
            continue
        rates[c] = exceedance_rates(plan.curve, stripes, d, grid)
        meets[c] = separation_for_rate(plan.curve, stripes, d, target)
        own[c] = exceedance_rates(plan.curve, stripes, d, plan.gaps[c:c + 1])[0]
        share[c] = lowest_stripe_share(stripes, d, meets[c] if math.isfinite(meets[c]) else 0.0)
    words = f"in {years:g} years"
    return {
        "pounding_rate": _var(("contact", "separation"), rates, "yr-1",
                              "mean annual frequency of pounding at the separation, lambda(g) = integral of "
                              "P(D > g | IM) |d lambda_IM|"),
        "pounding_probability": _var(("contact", "separation"), probability_in(rates, years), "1",
                                     f"probability of pounding {words}, 1 - exp(-{years:g} lambda)"),
        "target_separation": _var(("contact",), meets, "m",
                                  f"smallest separation whose probability of pounding {words} is at most "
                                  f"{100 * p:g} % (inf: none)"),
        "gap_pounding_rate": _var(("contact",), own, "yr-1", "mean annual frequency of pounding at the model's gap"),
        "gap_pounding_probability": _var(("contact",), probability_in(own, years), "1",
                                         f"probability of pounding {words} at the model's gap"),
        "model_gap": _var(("contact",), plan.gaps, "m", "the model's own gap"),
        "lowest_stripe_pounding": _var(("contact",), share, "1",
                                       "fraction of the lowest stripe's runs that pound at the target separation "
                                       "(the integral takes 0 below that stripe: keep it small)"),
        "required_separation": _var(("record", "level", "contact"), demands, "m",
                                    "separation the run without contacts needed: largest approach of the two "
                                    "sides (inf: a building collapsed; NaN: the run failed)"),
    }, grid


def _code_vars(plan, stripes: np.ndarray, demands: np.ndarray, contacts: list[str]) -> dict:
    """Per code and contact: the code's separation and the annual frequency and probability of pounding at it."""
    from pounding.studies.risk.integrals import exceedance_rates, probability_in

    years = plan.target[1]
    separation = np.array([[plan.codes[code].get(label, np.nan) for label in contacts] for code in plan.codes])
    rates = np.full(separation.shape, np.nan)
    for c in range(len(contacts)):
        d = demands[:, :, c].T   # (stripe, record)
        given = np.isfinite(separation[:, c])
        if np.any(~np.isnan(d)) and given.any():
            rates[given, c] = exceedance_rates(plan.curve, stripes, d, separation[given, c])
    return {
        "code_separation": _var(("code", "contact"), separation, "m",
                                "the code's separation of the level pair (same property; NaN: not a contact of "
                                "the code's rows)"),
        "code_pounding_rate": _var(("code", "contact"), rates, "yr-1",
                                   "mean annual frequency of pounding at the code's separation"),
        "code_pounding_probability": _var(("code", "contact"), probability_in(rates, years), "1",
                                          f"probability of pounding in {years:g} years at the code's separation"),
    }


def _collapse_vars(plan, ds) -> dict:
    """Per variant and building: collapse rate from the lognormal fit and from the stripes' fractions."""
    from pounding.studies.ida import exceeds
    from pounding.studies.risk.integrals import exceedance_rates, lognormal_rate, probability_in

    nv, nb = ds.variant.size, ds.building.size
    fitted, empirical = np.full((nv, nb), np.nan), np.full((nv, nb), np.nan)
    k = list(ds.fragility_limit.values).index("collapse")
    hit = exceeds(ds, None)   # (variant, record, level, building): 1, 0, NaN (failed or censored)
    for i in range(nv):
        for b in range(nb):
            theta, beta = float(ds.fragility_theta.values[i, b, k]), float(ds.fragility_beta.values[i, b, k])
            if theta > 0 and beta > 0:
                fitted[i, b] = lognormal_rate(plan.curve, theta, beta)
            if np.any(np.isfinite(hit[i, :, :, b])):
                empirical[i, b] = exceedance_rates(plan.curve, ds.level.values, hit[i, :, :, b].T,
                                                   np.array([0.5]))[0]
    years = COLLAPSE_TARGET[1]
    return {
        "collapse_rate": _var(("variant", "building"), fitted, "yr-1",
                              "mean annual frequency of collapse, lognormal collapse fragility on the hazard "
                              "curve (NaN: fragility not determinable)"),
        "collapse_probability": _var(("variant", "building"), probability_in(fitted, years), "1",
                                     f"probability of collapse in {years:g} years (lognormal fragility)"),
        "collapse_rate_empirical": _var(("variant", "building"), empirical, "yr-1",
                                        "mean annual frequency of collapse from the stripes' collapse fractions "
                                        "(no fit; 0 below the lowest stripe)"),
        "collapse_probability_empirical": _var(("variant", "building"), probability_in(empirical, years), "1",
                                               f"probability of collapse in {years:g} years (stripe fractions)"),
    }


#: ASCE 7-22's collapse risk target: (probability, years), 1 % in 50 years.
COLLAPSE_TARGET = (0.01, 50.0)


def separation_demands(ds, results: dict[str, dict], entries: list, contacts: list[str]) -> np.ndarray:
    """(record, level, contact): each run without contacts' required separation, m (+inf: a building
    collapsed; NaN: the run failed)."""
    levels = [float(x) for x in ds.level.values / STANDARD_GRAVITY]
    out = np.full((ds.record.size, len(levels), len(contacts)), np.nan)
    index = {c: k for k, c in enumerate(contacts)}
    for variant, r, level, key in entries:
        part = results.get(key) or {}
        if variant != "without_contacts" or part.get("status") != "ok" or "separation" not in part:
            continue
        j = int(np.argmin(np.abs(np.array(levels) - level)))
        for label, value in zip(part["separation"]["contact"], part["separation"]["required"]):
            if label in index:
                out[r, j, index[label]] = math.inf if part.get("unbounded") else value
    return out


def assemble_risk_dataset(plan, results: dict[str, dict[str, Any]], entries: list, *,
                          elapsed: float = float("nan"), ran: int = 0):
    """The IDA archive of the stripes (:func:`pounding.studies.ida.assemble_ida_dataset`) with the risk
    variables (module docstring of :mod:`pounding.studies.risk.study`)."""
    from pounding.studies.ida import assemble_ida_dataset

    ds = assemble_ida_dataset(plan.ida, results, entries, elapsed=elapsed, ran=ran)
    contacts = [str(c) for c in ds.contact.values]
    demands = separation_demands(ds, results, entries, contacts)
    gaps = plan.gaps if plan.gaps.size == len(contacts) else np.full(len(contacts), np.nan)
    plan = type(plan)(plan.ida, plan.curve, plan.target, gaps, plan.codes)
    variables, grid = _pounding_vars(plan, ds.level.values, demands)
    ds = ds.assign_coords(separation=("separation", grid, {"units": "m", "long_name": "separation g"}),
                          hazard_point=("hazard_point", np.arange(plan.curve.intensity.size),
                                        {"units": "1", "long_name": "row of the hazard curve"}))
    if plan.codes:
        ds = ds.assign_coords(code=("code", list(plan.codes), {"long_name": "design code of the separation"}))
        variables.update(_code_vars(plan, ds.level.values, demands, contacts))
    for name, value in {**variables, **_collapse_vars(plan, ds)}.items():
        ds[name] = value
    ds["hazard_intensity"] = _var(("hazard_point",), plan.curve.intensity, "m s-2",
                                  f"{plan.ida.im.describe()} of the hazard curve")
    ds["hazard_rate"] = _var(("hazard_point",), plan.curve.annual_rate, "yr-1",
                             "mean annual frequency of exceedance of the intensity")
    ds.attrs.update({"study": "risk", "hazard": plan.curve.source, "target_probability": plan.target[0],
                     "target_years": plan.target[1], "collapse_target_probability": COLLAPSE_TARGET[0],
                     "collapse_target_years": COLLAPSE_TARGET[1],
                     "title": ds.attrs["title"].replace("pounding IDA", "pounding risk (stripes)")})
    return ds


def _mm(value: float) -> str:
    return "none" if not math.isfinite(value) else f"{1000 * value:.0f} mm"


def risk_table(ds) -> str:
    """The printed summary: per contact the separation meeting the target and the own gap's risk; per building
    the collapse risk with and without pounding against 1 % in 50 years, one line each."""
    p, years = ds.attrs["target_probability"], ds.attrs["target_years"]
    lines = [f"hazard: {ds.attrs['hazard']}; stripes {', '.join(f'{x:.3g}' for x in ds.level.values / STANDARD_GRAVITY)} g",
             f"risk of pounding (runs without contacts): separation for {100 * p:g} % in {years:g} years, and the model's gap",
             f"  {'contact':<20} {'separation':>11} {'model gap':>10} {'P(' + format(years, 'g') + ' y) at gap':>16}"]
    for c, label in enumerate(ds.contact.values):
        share = float(ds.lowest_stripe_pounding.values[c])
        note = f"  (lowest stripe pounds in {100 * share:.0f} % of runs: add lower stripes)" if share > 0.1 else ""
        lines.append(f"  {str(label):<20} {_mm(float(ds.target_separation.values[c])):>11} "
                     f"{_mm(float(ds.model_gap.values[c])):>10} {100 * float(ds.gap_pounding_probability.values[c]):>15.2f} %"
                     + note)
    lines += _code_lines(ds)
    target = 100 * ds.attrs["collapse_target_probability"]
    lines.append(f"collapse in {ds.attrs['collapse_target_years']:g} years (lognormal fragility; stripe fractions) "
                 f"against {target:g} %:")
    variants = [str(v) for v in ds.variant.values]
    for b, building in enumerate(ds.building.values):
        parts, over = [], {}
        for i, variant in enumerate(variants):
            fitted = float(ds.collapse_probability.values[i, b])
            empirical = float(ds.collapse_probability_empirical.values[i, b])
            shown = "not determinable" if not math.isfinite(fitted) else f"{100 * fitted:.2f} %"
            parts.append(f"{variant.replace('_', ' ')} {shown} ({100 * empirical:.2f} %)")
            best = fitted if math.isfinite(fitted) else empirical
            over[variant] = best > target / 100
        verdict = _verdict(over.get("with_contacts", False), over.get("without_contacts", False))
        lines.append(f"  {building}: {'; '.join(parts)}: {verdict}")
    return "\n".join(lines)


def _code_lines(ds) -> list[str]:
    """Per contact, each code's separation and the probability of pounding at it (none without ``--code``)."""
    from pounding.studies.design_check import CODE_NAMES

    if "code" not in ds.dims:
        return []
    years = ds.attrs["target_years"]
    lines = [f"risk of pounding at the codes' separations (same property), in {years:g} years:"]
    for c, label in enumerate(ds.contact.values):
        parts = [f"{CODE_NAMES.get(str(code), str(code))} {_mm(float(ds.code_separation.values[k, c]))}: "
                 f"{100 * float(ds.code_pounding_probability.values[k, c]):.2f} %"
                 for k, code in enumerate(ds.code.values) if math.isfinite(float(ds.code_separation.values[k, c]))]
        lines.append(f"  {str(label):<20} {'; '.join(parts) if parts else 'no code separation'}")
    return lines


def _verdict(with_contacts: bool, without_contacts: bool) -> str:
    if with_contacts:
        return "over the target with or without pounding" if without_contacts else \
            "POUNDING TAKES IT OVER THE TARGET"
    return "over the target only with the contacts held open" if without_contacts else \
        "below the target with and without pounding"


def risk_tables(ds) -> dict:
    """CSV tables: ``pounding`` (per contact), ``collapse`` (per variant and building), ``curve`` (per contact and
    separation), then the IDA's (fragility, runs)."""
    from pounding.results.tables import long_table
    from pounding.studies.ida import ida_tables

    return {"pounding": long_table(ds, ["target_separation", "model_gap", "gap_pounding_rate",
                                        "gap_pounding_probability", "lowest_stripe_pounding"]),
            "collapse": long_table(ds, ["collapse_rate", "collapse_probability", "collapse_rate_empirical",
                                        "collapse_probability_empirical"]),
            "curve": long_table(ds, ["pounding_rate", "pounding_probability"]),
            **({"codes": long_table(ds, ["code_separation", "code_pounding_rate", "code_pounding_probability"])}
               if "code" in ds.dims else {}),
            **ida_tables(ds)}


#: Markers of the codes' separations on the risk figure, in the order of the archive's ``code``.
CODE_MARKERS = ("s", "^")


def plot_risk(ds, directory: str | os.PathLike) -> list[Path]:
    """``pounding_risk.png``: per contact, the probability of pounding in the target's years against the
    separation (log scale), the target and each contact's separation meeting it, own gap and (``--code``) the
    codes' separations marked."""
    from pounding.results.plots import plot_directory, pyplot, save_figure, suptitle
    from pounding.studies.design_check import CODE_NAMES

    plt = pyplot()
    out = plot_directory(directory)
    p, years = ds.attrs["target_probability"], ds.attrs["target_years"]
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for c, label in enumerate(ds.contact.values):
        line, = ax.plot(1000 * ds.separation.values, ds.pounding_probability.values[c], label=str(label))
        meets = float(ds.target_separation.values[c])
        if math.isfinite(meets):
            ax.plot([1000 * meets], [p], "o", color=line.get_color())
        gap = float(ds.model_gap.values[c])
        if math.isfinite(gap) and gap <= ds.separation.values[-1]:
            ax.axvline(1000 * gap, color=line.get_color(), ls=":", lw=1)
        for k, marker in zip(range(ds.sizes.get("code", 0)), CODE_MARKERS):
            ax.plot([1000 * float(ds.code_separation.values[k, c])], [float(ds.code_pounding_probability.values[k, c])],
                    marker, color=line.get_color(), mfc="none", ms=7)
    for k, marker in zip(range(ds.sizes.get("code", 0)), CODE_MARKERS):   # one legend entry per code
        ax.plot([], [], marker, color="k", mfc="none", label=f"{CODE_NAMES.get(str(ds.code.values[k]), '')} separation")
    ax.axhline(p, color="k", ls="--", lw=1, label=f"target {100 * p:g} % in {years:g} years")
    ax.set_yscale("log")
    ax.set_xlabel("separation g (mm); dotted: the model's gap")
    ax.set_ylabel(f"probability of pounding in {years:g} years")
    suptitle(fig, f"pounding risk over the hazard curve {Path(ds.attrs['hazard']).name}\n{ds.attrs.get('title', '')}",
             8)
    ax.legend(fontsize=8)
    path = out / "pounding_risk.png"
    save_figure(fig, path)
    return [path]

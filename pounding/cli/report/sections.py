"""One archive's section of a report: what was modelled, under what, the status and warnings, the summary,
tables and figures of its kind, and how to make it again.

Everything is read from the archive through what the other commands use: the
model from the YAML the archive keeps (or the file it names), the summary of
``pounding info``, the tables of ``pounding table``
(:func:`pounding.cli.csv_option.archive_tables`) and the figures of
``pounding plot`` (:func:`pounding.cli.run.draw_figures`).
"""

from __future__ import annotations

import json
import tempfile
from pathlib import Path

from pounding import __version__
from pounding.cli.report.html import Facts, Figure, Notes, Section, Table, Text
from pounding.cli.report.kinds import Kind, study_errors
from pounding.errors import PoundingError

__all__ = ["archive_section", "model_blocks", "reproduce_rows", "warning_lines", "figure_blocks"]


def _model(ds):
    """The model an archive ran and where it was read from: ``(Model or None, source, note)``."""
    from pounding.model.model import load_model, model_from_text

    attrs = ds.attrs
    text, path = None, attrs.get("model_path") or attrs.get("model_file") or attrs.get("base_model_file") or None
    if "run_spec" in attrs:
        spec = json.loads(attrs["run_spec"])
        text, base = spec.get("model"), spec.get("base_dir")
    else:
        text, base = attrs.get("base_model"), None
    try:
        if text:
            return model_from_text(text, name=attrs.get("model_name", "model"), path=path, base_dir=base), \
                "the model as run, kept in the archive", ""
        if path:
            return load_model(path), f"{path} (the file as it reads now; the archive keeps its name only)", ""
    except (PoundingError, OSError) as exc:
        return None, str(path or "the archive"), f"the model cannot be read again: {exc}"
    return None, "", "the archive names no model"


def _xi_rows(model) -> list[tuple[str, str]]:
    """Each ξ formula the model's contacts use: its p(e) = ξ·v0/kh and its reference."""
    from pounding.contact import xi

    used = sorted({str(g.law.xi) for g in model.gaps if getattr(g.law, "xi", None)})
    rows = []
    for entry in xi.catalogue():
        names = {entry["key"], *[a.strip() for a in str(entry["aliases"]).split(",") if a.strip()]}
        for key in used:
            if key in names:
                rows.append((key, f"p(e) = {entry['p(e)']}; {entry['reference']}"))
    return rows


def model_blocks(ds) -> list:
    """"What was modelled": the model's overview, its buildings (periods, damping), contacts (laws with their
    parameters) and links, and the ξ formulas used with their references."""
    model, source, note = _model(ds)
    if model is None:
        return [Notes("What was modelled", [note or "no model recorded"], "warning")]
    blocks = [Facts("What was modelled", [("read from", source), *model.overview()]),
              Notes("Buildings, contacts and ground motion", model.summary_lines())]
    xi_rows = _xi_rows(model)
    if xi_rows:
        blocks.append(Facts("ξ formulas of the contacts (damping of the Hertz-damp law)", xi_rows))
    return blocks


def warning_lines(kind: str, ds) -> list[str]:
    """The warnings the archive stored when it ran and, of a run, those its results call for."""
    from pounding.cli.run import stored_warnings

    lines = stored_warnings(ds)
    if kind == "run" and "storey_building" in ds:
        from pounding.results.checks import run_warnings

        lines += [w for w in run_warnings(ds).values() if w not in lines]
    return lines


def reproduce_rows(kind: str, ds, path: Path) -> list[tuple[str, str]]:
    """The software that wrote the archive and made the report, and the command that writes it again."""
    from pounding.provenance import command_text

    attrs = ds.attrs
    rows = [("written by", str(attrs.get("source", "unknown"))), ("report made by", f"pounding {__version__}")]
    if attrs.get("command"):
        rows.append(("command", str(attrs["command"])))
        rows.append(("run in", str(attrs.get("command_directory", "")) or "(not recorded)"))
    else:
        rows.append(("command", "not recorded (written from Python, or by a pounding older than `pounding report`)"))
    if kind == "run":
        rows.append(("rerun from the archive", command_text(["pounding", "rerun", str(path), "-o",
                                                             f"{path.stem}-rerun.nc"])
                     + "  (the same model, record and scale; refused if the record's samples changed)"))
    if attrs.get("history"):
        rows.append(("history", " | ".join(str(attrs["history"]).splitlines())))
    return rows


def figure_blocks(kind: str, ds) -> list:
    """The figures ``pounding plot`` draws of the archive, as PNG blocks (in the order drawn)."""
    from pounding.cli.run import draw_figures

    with tempfile.TemporaryDirectory(prefix="pounding-report-") as folder:
        paths = draw_figures(kind, ds, Path(folder))
        return [Figure(Path(p).name, Path(p).read_bytes()) for p in paths if Path(p).suffix.lower() == ".png"]


def _drawable(kind: str, ds) -> bool:
    """Whether ``pounding plot`` has something to draw: a study with no run that ended has not."""
    if kind in ("sweep", "compare", "gap", "ida", "risk") and "status" in ds.variables:
        return bool(ds.status.isin(["ok", "completed", "collapsed", "unstable"]).any())
    return True


def archive_section(index: int, path: Path, kind: Kind, ds) -> Section:
    """The section of the archive *path* (of *kind*, opened as *ds*), numbered *index* in the report."""
    from pounding.cli.csv_option import archive_tables
    from pounding.cli.run import archive_summary, damaged_if_garbled

    section = Section(f"archive-{index}", f"{index}. {path.name}: {kind.what}")
    with damaged_if_garbled(path):
        section.blocks.append(Facts("Archive", [("file", str(path)), ("kind", kind.name),
                                                ("title", str(ds.attrs.get("title", "")))]))
        section.blocks += model_blocks(ds)
        section.blocks.append(Facts("Under what", kind.excitation(ds)))
        section.blocks.append(Facts("Status", kind.status(ds)))
        warnings = warning_lines(kind.name, ds)
        section.blocks.append(Notes("Warnings", warnings or ["none"], "warning" if warnings else "note"))
        errors = study_errors(ds)
        if errors:
            section.blocks.append(Notes("Failed runs", errors, "failure"))
        section.blocks.append(Text("Summary (as `pounding info` prints it)", archive_summary(kind.name, ds)))
        for name, frame in archive_tables(kind.name, ds).items():
            section.blocks.append(Table(f"Table: {name}", name, frame))
        if _drawable(kind.name, ds):
            section.blocks += figure_blocks(kind.name, ds)
        else:
            section.blocks.append(Notes("Figures", ["none: every run failed"], "failure"))
        section.blocks.append(Facts("How to make it again", reproduce_rows(kind.name, ds, path)))
    return section

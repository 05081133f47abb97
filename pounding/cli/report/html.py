"""The report's HTML: one self-contained page (styles inline, figures as ``data:`` PNG, no script, no link
out of the file), every text escaped.

A report is a list of :class:`Section` (one per archive); each holds blocks in
order: :class:`Facts` (label-value rows), :class:`Table` (a pandas table),
:class:`Figure` (PNG bytes), :class:`Text` (preformatted lines) and
:class:`Notes` (a list, e.g. warnings).  :func:`render` lays them out under a
table of contents.
"""

from __future__ import annotations

import base64
import math
from dataclasses import dataclass, field
from html import escape
from typing import Sequence, Union

import numpy as np

__all__ = ["Facts", "Table", "Figure", "Text", "Notes", "Section", "render", "cell_text", "MAX_ROWS"]

#: Rows of a table shown in the report; the rest are counted (``pounding table ARCHIVE --csv`` writes all).
MAX_ROWS = 200


@dataclass
class Facts:
    """Label-value rows under a heading."""
    heading: str
    rows: Sequence[tuple[str, str]]


@dataclass
class Table:
    """A table (:class:`pandas.DataFrame`, units in the headers) named *name*, under a heading."""
    heading: str
    name: str
    frame: object
    note: str = ""


@dataclass
class Figure:
    """A PNG figure, *name* its file name as ``pounding plot`` writes it."""
    name: str
    png: bytes


@dataclass
class Text:
    """Preformatted text (a summary as the terminal prints it) under a heading."""
    heading: str
    text: str


@dataclass
class Notes:
    """A list of one-line notes under a heading (warnings, failures); *kind* styles them."""
    heading: str
    items: Sequence[str]
    kind: str = "note"


Block = Union[Facts, Table, Figure, Text, Notes]


@dataclass
class Section:
    """One archive's part of the report: *anchor* is its id in the page, *title* its heading."""
    anchor: str
    title: str
    blocks: list = field(default_factory=list)


_STYLE = """
body{font-family:system-ui,-apple-system,"Segoe UI",Roboto,sans-serif;margin:2em auto;max-width:78em;padding:0 1em;
color:#1b1b1b;line-height:1.4}
h1{font-size:1.6em}h2{border-bottom:2px solid #345;padding-bottom:.2em;margin-top:2.2em}h3{margin-top:1.6em}
table{border-collapse:collapse;font-size:.85em;margin:.5em 0}td,th{border:1px solid #bbb;padding:.15em .5em;
text-align:left;vertical-align:top}th{background:#eef1f5}td.n{text-align:right;font-variant-numeric:tabular-nums}
table.facts th{width:14em}pre{background:#f6f8fa;padding:.6em;overflow-x:auto;font-size:.85em}
figure{margin:1em 0}figure img{max-width:100%;height:auto;border:1px solid #ddd}
figcaption{font-size:.85em;color:#555}.warning li{color:#8a4b00}.failure li{color:#a00}
.scroll{overflow-x:auto;max-height:32em;overflow-y:auto}nav li{margin:.1em 0}
"""


def cell_text(value) -> str:
    """A table cell as shown: numbers with 6 significant digits (``nan`` for a missing one), text as is."""
    if isinstance(value, (bool, np.bool_)):
        return str(bool(value)).lower()
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        return "nan" if math.isnan(value) else f"{float(value):.6g}"
    if isinstance(value, bytes):
        return value.decode("utf-8", "replace")
    return str(value)


def _table(block: Table) -> str:
    frame = block.frame
    shown = frame.iloc[:MAX_ROWS]
    head = "".join(f"<th>{escape(str(c))}</th>" for c in shown.columns)
    from pandas.api.types import is_bool_dtype, is_numeric_dtype

    numeric = [is_numeric_dtype(dtype) and not is_bool_dtype(dtype) for dtype in shown.dtypes]
    rows = []
    for values in shown.itertuples(index=False, name=None):
        rows.append("<tr>" + "".join(f"<td{' class=n' if n else ''}>{escape(cell_text(v))}</td>"
                                     for v, n in zip(values, numeric)) + "</tr>")
    note = block.note
    if len(frame) > MAX_ROWS:
        note = (f"the first {MAX_ROWS} of {len(frame)} rows; `pounding table ARCHIVE --csv FILE` writes them all"
                + (f"; {note}" if note else ""))
    return (f"<h3>{escape(block.heading)}</h3>" + (f"<p>{escape(note)}</p>" if note else "")
            + f"<div class=scroll><table data-table=\"{escape(block.name)}\"><thead><tr>{head}</tr></thead>"
            f"<tbody>{''.join(rows)}</tbody></table></div>")


def _block(block: Block) -> str:
    if isinstance(block, Facts):
        rows = "".join(f"<tr><th>{escape(k)}</th><td>{escape(v)}</td></tr>" for k, v in block.rows)
        return f"<h3>{escape(block.heading)}</h3><table class=facts>{rows}</table>"
    if isinstance(block, Table):
        return _table(block)
    if isinstance(block, Figure):
        data = base64.b64encode(block.png).decode("ascii")
        return (f"<figure><img src=\"data:image/png;base64,{data}\" alt=\"{escape(block.name)}\" "
                f"data-figure=\"{escape(block.name)}\"><figcaption>{escape(block.name)}</figcaption></figure>")
    if isinstance(block, Text):
        return f"<h3>{escape(block.heading)}</h3><pre>{escape(block.text)}</pre>"
    items = "".join(f"<li>{escape(item)}</li>" for item in block.items)
    return f"<h3>{escape(block.heading)}</h3><ul class=\"{escape(block.kind)}\">{items}</ul>"


def render(sections: Sequence[Section], title: str, preamble: Sequence[tuple[str, str]] = ()) -> str:
    """The whole page: *title*, the *preamble* facts, a table of contents, then every section.

    Returns
    -------
    str
        HTML5 text, UTF-8, needing nothing outside itself.
    """
    toc = "".join(f"<li><a href=\"#{escape(s.anchor)}\">{escape(s.title)}</a></li>" for s in sections)
    facts = "".join(f"<tr><th>{escape(k)}</th><td>{escape(v)}</td></tr>" for k, v in preamble)
    body = "".join(f"<section id=\"{escape(s.anchor)}\"><h2>{escape(s.title)}</h2>"
                   + "".join(_block(b) for b in s.blocks) + "</section>" for s in sections)
    return ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">"
            f"<title>{escape(title)}</title><style>{_STYLE}</style></head><body>"
            f"<h1>{escape(title)}</h1><table class=facts>{facts}</table>"
            f"<nav><h2>Contents</h2><ul>{toc}</ul></nav>{body}</body></html>\n")

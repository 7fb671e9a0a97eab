"""The Python package's import direction (docs/architecture.md, "Import direction"): read with `ast`, not by
importing, so a lazy import inside a function counts as much as one at the top of a module.

What counts as an edge: every `import freefloat...` / `from freefloat... import` / relative import, at module level
AND inside functions and methods. A function-level import is still a dependency (it runs whenever the function
does); it only hides a cycle from the interpreter, which is why cycles were written that way. Imports under
`if TYPE_CHECKING:` are NOT counted: they never run (annotations are strings in this package) and name a type,
not a dependency. The edge goes to the most specific module named (`from freefloat.campaign.spec import x` is an
edge to `freefloat.campaign.spec`, `from freefloat.campaign import spec` too), not to the parent packages the
interpreter also initialises: a package `__init__` that re-exports its modules would otherwise close a cycle with
every one of them.

Three checks, each failure naming both modules and the line:
- no cycle between modules (a cycle is reported by one of its edges, with the whole cycle);
- no import of a module of a later layer (`LAYERS`, the order docs/architecture.md states); `freefloat/__init__.py`
  (the public API that gathers every stage) and `__main__` modules are exempt;
- no import of another package's private name: a module `a.b._m` or a name `_f` defined in a module of package
  `a.b` may be imported only from inside `a.b` (`freefloat._core` is therefore usable everywhere in `freefloat`,
  `freefloat.cli._common` only in `freefloat.cli`).
"""

from __future__ import annotations

import ast
from pathlib import Path

from _helpers import cycles

ROOT = Path(__file__).resolve().parent.parent / "python" / "freefloat"

# The layer order (docs/architecture.md): a module may import from its own layer and the layers before it. A module
# takes the layer of the longest prefix listed here; every module must match one.
LAYERS: list[tuple[str, list[str]]] = [
    (
        "core",
        [
            "freefloat._core",
            "freefloat._arrays",
            "freefloat._cpu",
            "freefloat.constants",
            "freefloat.viz",
            "freefloat.data",
            "freefloat.io.arrow",
            "freefloat.io.schema",
            "freefloat.io.data",
        ],
    ),
    (
        "model",
        [
            "freefloat.model",
            "freefloat.models",
            "freefloat.algorithms",
            "freefloat.derivatives",
            "freefloat.trajectories",
            "freefloat.dq",
            "freefloat.io.results",
            "freefloat.io.trajectory_files",
            "freefloat.io.mjcf",
        ],
    ),
    (
        "simulation",
        [
            "freefloat.simulation",
            "freefloat.io",
            "freefloat.io.telemetry",
            "freefloat.io.mujoco",
        ],
    ),
    ("sensors", ["freefloat.sensors"]),
    (
        "scenario files",
        [
            "freefloat.io.scenario_blocks",
            "freefloat.io.scenario_schemas",
            "freefloat.io.scenario_files",
            "freefloat.simulation.scenario",
        ],
    ),
    (
        "identification, post-capture, control",
        ["freefloat.identification", "freefloat.postcapture", "freefloat.control"],
    ),
    ("mission, demo", ["freefloat.mission", "freefloat.demo"]),
    ("campaign", ["freefloat.campaign"]),
    ("report", ["freefloat.report"]),
    ("cli", ["freefloat.cli"]),
]
EXEMPT = {"freefloat", "freefloat.__main__", "freefloat.cli.__main__"}


def _modules() -> dict[str, tuple[Path, bool]]:
    mods = {}
    for p in sorted(ROOT.rglob("*.py")):
        parts = list(p.relative_to(ROOT.parent).with_suffix("").parts)
        is_pkg = parts[-1] == "__init__"
        mods[".".join(parts[:-1] if is_pkg else parts)] = (p, is_pkg)
    mods["freefloat._core"] = (ROOT / "_core.pyi", False)  # the compiled engine (its stub is read)
    return mods


MODULES = _modules()


def _is_type_checking(node: ast.If) -> bool:
    t = node.test
    return (isinstance(t, ast.Name) and t.id == "TYPE_CHECKING") or (
        isinstance(t, ast.Attribute) and t.attr == "TYPE_CHECKING"
    )


def _imports(module: str, path: Path, is_pkg: bool):
    """(target module, imported name or None, line) of every freefloat-internal import that can run."""
    out = []

    def target(name):
        while name not in MODULES and "." in name:
            name = name.rsplit(".", 1)[0]
        return name

    def visit(node):
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.If) and _is_type_checking(child):
                for sub in child.orelse:
                    visit(ast.Module(body=[sub], type_ignores=[]))
                continue
            if isinstance(child, ast.Import):
                out.extend(
                    (target(a.name), None, child.lineno) for a in child.names if a.name.split(".")[0] == "freefloat"
                )
            elif isinstance(child, ast.ImportFrom):
                if child.level:
                    base = module.split(".")[: None if is_pkg else -1]
                    base = base[: len(base) - (child.level - 1)]
                    name = ".".join(base + ([child.module] if child.module else []))
                else:
                    name = child.module or ""
                if name.split(".")[0] != "freefloat":
                    continue
                for a in child.names:
                    sub = f"{name}.{a.name}"
                    out.append((sub, None, child.lineno) if sub in MODULES else (target(name), a.name, child.lineno))
            visit(child)

    visit(ast.parse(path.read_text(), str(path)))
    return [(t, n, line) for t, n, line in out if t != module]


EDGES = {m: _imports(m, p, is_pkg) for m, (p, is_pkg) in MODULES.items() if m != "freefloat._core"}


def _where(module: str, line: int) -> str:
    return f"{MODULES[module][0].relative_to(ROOT.parent.parent)}:{line}"


def _layer(module: str) -> int:
    best, layer = -1, None
    for i, (_, prefixes) in enumerate(LAYERS):
        for p in prefixes:
            if (module == p or module.startswith(p + ".")) and len(p) > best:
                best, layer = len(p), i
    return layer


def test_every_module_has_a_layer():
    missing = [m for m in MODULES if m not in EXEMPT and _layer(m) is None]
    assert not missing, f"modules without a layer in LAYERS (add them, and to docs/architecture.md): {missing}"


def test_no_import_cycle():
    graph = {m: sorted({t for t, _, _ in es if t in MODULES}) for m, es in EDGES.items()}
    found = cycles(graph)
    msgs = []
    for comp in found:
        edges = [
            f"{m} imports {t}{f' ({n})' if n else ''} at {_where(m, line)}"
            for m in sorted(comp)
            for t, n, line in EDGES[m]
            if t in comp
        ]
        msgs.append(f"import cycle between {sorted(comp)}:\n    " + "\n    ".join(edges))
    assert not msgs, "\n".join(msgs)


def test_imports_follow_the_layer_order():
    bad = []
    for m, es in EDGES.items():
        if m in EXEMPT:
            continue
        for t, n, line in es:
            if t in MODULES and _layer(t) > _layer(m):
                bad.append(
                    f"{m} ({LAYERS[_layer(m)][0]}) imports {t}{f' ({n})' if n else ''} ({LAYERS[_layer(t)][0]}, a "
                    f"later layer) at {_where(m, line)}"
                )
    assert not bad, "imports against the layer order of docs/architecture.md:\n" + "\n".join(bad)


def _scope(module: str, name: str | None) -> str | None:
    """The package a private module or name belongs to (None: the import is not of a private thing)."""
    parts = module.split(".")
    if name is not None and name.startswith("_") and not name.startswith("__"):
        return module if MODULES[module][1] else ".".join(parts[:-1])
    for i, p in enumerate(parts):
        if p.startswith("_") and not p.startswith("__"):
            return ".".join(parts[:i])
    return None


def test_no_import_of_another_packages_private_names():
    bad = []
    for m, es in EDGES.items():
        for t, n, line in es:
            if t not in MODULES:
                continue
            scope = _scope(t, n)
            if scope is not None and not (m == scope or m.startswith(scope + ".")):
                bad.append(f"{m} imports {t}{f'.{n}' if n else ''}, private to {scope}, at {_where(m, line)}")
    assert not bad, "imports of another package's private module or name:\n" + "\n".join(bad)


def test_the_checker_sees_function_level_imports_and_skips_type_checking_ones():
    """Guards on the checker itself: postcapture/results.py imports its plots inside `save` (an edge), and
    postcapture/plots.py names the result type under `if TYPE_CHECKING:` (no edge)."""
    assert "freefloat.postcapture.plots" in {t for t, _, _ in EDGES["freefloat.postcapture.results"]}
    assert "freefloat.postcapture.results" not in {t for t, _, _ in EDGES["freefloat.postcapture.plots"]}
    assert len(EDGES) > 90, "the AST walk found too few modules: the checks would be vacuous"


def test_the_cycle_finder_finds_every_cycle_and_nothing_else():
    """`_helpers.cycles` (used here and by the engine's layer test): two cycles, a tail out of one, a self-contained
    chain, and a chain long enough to overflow a recursive search."""
    g = {"a": ["b"], "b": ["c"], "c": ["a", "d"], "d": [], "e": ["f"], "f": ["e"], "x": ["y"], "y": []}
    assert sorted(map(sorted, cycles(g))) == [["a", "b", "c"], ["e", "f"]]
    chain = {i: [i + 1] for i in range(20_000)}
    assert cycles(chain) == []
    chain[20_000] = [0]
    assert [len(c) for c in cycles(chain)] == [20_001]

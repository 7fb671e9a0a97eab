"""The engine's import direction (docs/architecture.md, "Engine layers"), read from the Rust sources.

Every `crate::…` and `super::…` path in `crates/freefloat-core/src` (in `use` declarations and inline, outside
comments and `#[cfg(test)]` code) is resolved to the file that defines it, following the re-exports of
`mod.rs` files (a facade re-exporting its children is not a dependency of the facade). Two checks:

(a) no cycle between files;
(b) no file imports from a top-level module of a later layer than its own (`LAYERS` below, the order
    docs/architecture.md states; a module may import from its own layer's other modules only where
    `SAME_LAYER` allows it, in the direction given).

A failure names both files and the offending line. Run this file as a script to print the graph's top-level edges.
"""

from __future__ import annotations

import re
from pathlib import Path

from _helpers import cycles

SRC = Path(__file__).resolve().parents[1] / "crates" / "freefloat-core" / "src"

# Bottom first. Keep in step with docs/architecture.md ("Engine layers").
LAYERS: list[list[str]] = [
    ["threads", "interrupt", "trajectory", "error"],
    ["spatial"],
    ["model"],
    ["dualquat"],
    ["data", "check"],
    ["config", "rk"],
    ["kinematics", "dynamics", "regressors"],
    ["dqdynamics", "environment", "sensors"],
    ["sim"],
    ["estimation", "excitation"],
    ["control", "postcapture"],
    ["lib"],
]

# Files that sit in another module's layer: the dual-quaternion solver's workspace types are part of `Data`
# (every workspace lives in `Data`), so they sit with `data`, below the solver that fills them.
FILE_LAYER: dict[str, str] = {
    "dqdynamics/workspace.rs": "data",
    "dqdynamics/sixvec.rs": "data",
}

# Imports allowed inside one layer, as (importer, imported) pairs of top-level modules.
SAME_LAYER: set[tuple[str, str]] = {
    ("error", "trajectory"),
    ("interrupt", "error"),
    ("check", "data"),
    ("dynamics", "kinematics"),
    ("regressors", "kinematics"),
    ("regressors", "dynamics"),
    ("dqdynamics", "environment"),
    ("sensors", "environment"),
    ("dqdynamics", "sensors"),
    ("environment", "sensors"),
    ("excitation", "estimation"),
    ("postcapture", "control"),
    ("control", "postcapture"),
}


def _layer_of() -> dict[str, int]:
    return {m: i for i, layer in enumerate(LAYERS) for m in layer}


def _module_of(path: Path) -> list[str]:
    """Module path of a source file: `a/b.rs` and `a/b/mod.rs` are both `a::b`."""
    rel = path.relative_to(SRC).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] in ("mod", "lib"):
        parts = parts[:-1]
    return parts


def _file_of(mod: list[str]) -> Path | None:
    if not mod:
        return SRC / "lib.rs"
    for cand in (SRC.joinpath(*mod).with_suffix(".rs"), SRC.joinpath(*mod, "mod.rs")):
        if cand.exists():
            return cand
    return None


def _strip(text: str) -> list[str]:
    """Source lines without comments and without `#[cfg(test)]` items (blanked, so line numbers stay)."""
    text = re.sub(r"/\*.*?\*/", lambda m: "\n" * m.group(0).count("\n"), text, flags=re.S)
    lines = [re.sub(r"//.*", "", ln) for ln in text.split("\n")]
    out, skip_depth, pending = [], None, False
    for ln in lines:
        if skip_depth is not None:
            skip_depth += ln.count("{") - ln.count("}")
            out.append("")
            if skip_depth <= 0 and ("}" in ln or ";" in ln):
                skip_depth = None
            continue
        if pending:
            pending = False
            opens = ln.count("{") - ln.count("}")
            out.append("")
            if opens > 0:
                skip_depth = opens
            continue
        if ln.strip().startswith("#[cfg(test)]"):
            pending = True
            out.append("")
            continue
        out.append(ln)
    return out


def _expand(tree: str) -> list[str]:
    """`a::{b, c::{d, e}}` -> [`a::b`, `a::c::d`, `a::c::e`]."""
    tree = re.sub(r"\s+", "", tree)
    i = tree.find("{")
    if i < 0:
        return [re.sub(r"as\w+$", "", tree)] if tree else []
    head, body = tree[:i], tree[i + 1 : tree.rfind("}")]
    parts, depth, cur = [], 0, ""
    for ch in body:
        if ch == "," and depth == 0:
            parts.append(cur)
            cur = ""
            continue
        depth += ch == "{"
        depth -= ch == "}"
        cur += ch
    parts.append(cur)
    return [head + sub for p in parts if p for sub in _expand(p)]


_USE = re.compile(r"\b(pub(?:\([\w:]+\))?\s+)?use\s+((?:crate|super)::[^;]*);", re.S)
_INLINE = re.compile(r"\b((?:crate|super)(?:::\w+)+)")


def _paths(lines: list[str]) -> list[tuple[int, str, bool, str]]:
    """(line number, path, is a `pub use`, line text) for every crate/super path of a file."""
    text = "\n".join(lines)
    found, spans = [], []
    for m in _USE.finditer(text):
        lineno = text.count("\n", 0, m.start()) + 1
        for p in _expand(m.group(2)):
            found.append((lineno, p, bool(m.group(1)), lines[lineno - 1].strip()))
        spans.append((m.start(), m.end()))
    for m in _INLINE.finditer(text):
        if any(a <= m.start() < b for a, b in spans):
            continue
        lineno = text.count("\n", 0, m.start()) + 1
        found.append((lineno, m.group(1), False, lines[lineno - 1].strip()))
    return found


def _absolute(importer: Path, path: str) -> list[str]:
    segs = path.split("::")
    if segs[0] == "crate":
        return segs[1:]
    here = _module_of(importer)
    # `super` of `a/b.rs` (module a::b) is a; in `a/mod.rs` (module a) it is the crate root's child's parent
    while segs and segs[0] == "super":
        here = here[:-1]
        segs = segs[1:]
    return here + segs


_REEXPORTS: dict[Path, dict[str, str]] = {}


def _reexports(f: Path) -> dict[str, str]:
    """Names a file re-exports (`pub use x::y::Name;`) -> absolute path of the original."""
    if f not in _REEXPORTS:
        table: dict[str, str] = {}
        _REEXPORTS[f] = table
        lines = _strip(f.read_text())
        text = "\n".join(lines)
        for m in re.finditer(r"\bpub(?:\([\w:]+\))?\s+use\s+([^;]*);", text, re.S):
            for p in _expand(m.group(1)):
                segs = p.split("::")
                if segs[0] not in ("crate", "super", "self"):
                    segs = _module_of(f) + segs  # a child module, `pub use child::Name`
                elif segs[0] == "self":
                    segs = _module_of(f) + segs[1:]
                else:
                    segs = _absolute(f, p)
                table[segs[-1]] = "::".join(segs)
    return _REEXPORTS[f]


def _resolve(segs: list[str], depth: int = 0) -> Path | None:
    """The file defining the item at the absolute module path `segs`."""
    best, k = None, 0
    for k in range(len(segs), -1, -1):
        f = _file_of(segs[:k])
        if f is not None:
            best = f
            break
    if best is None or depth > 8:
        return best
    rest = segs[k:]
    if rest and rest[0] in _reexports(best):
        target = _reexports(best)[rest[0]].split("::")
        if target != segs:
            return _resolve(target + rest[1:], depth + 1) or best
    return best


def _files() -> list[Path]:
    return sorted(p for p in SRC.rglob("*.rs") if p.name != "tests.rs")


def edges() -> list[tuple[Path, Path, int, str]]:
    """(importer, imported, line number, line) for every dependency between two different files."""
    out = []
    for f in _files():
        own = _module_of(f)
        for lineno, path, is_pub, line in _paths(_strip(f.read_text())):
            segs = _absolute(f, path)
            if is_pub and segs[: len(own)] == own and f.name in ("mod.rs", "lib.rs"):
                continue  # a facade re-exporting its own children
            target = _resolve(segs)
            if target is None or target == f:
                continue
            if f.name in ("mod.rs", "lib.rs") and _module_of(target)[: len(own)] == own and is_pub:
                continue
            if (f, target, lineno, line) not in out[-8:]:
                out.append((f, target, lineno, line))
    return out


def _top(f: Path) -> str:
    if _rel(f) in FILE_LAYER:
        return FILE_LAYER[_rel(f)]
    m = _module_of(f)
    return m[0] if m else "lib"


def _rel(f: Path) -> str:
    return str(f.relative_to(SRC))


def test_every_top_level_module_has_a_layer() -> None:
    layer = _layer_of()
    missing = sorted({_top(f) for f in _files()} - set(layer))
    assert not missing, f"engine modules without a layer in LAYERS (and docs/architecture.md): {missing}"


def test_no_import_against_the_layer_order() -> None:
    layer = _layer_of()
    bad = []
    for a, b, lineno, line in edges():
        ta, tb = _top(a), _top(b)
        if ta == tb or ta == "lib":
            continue
        la, lb = layer.get(ta), layer.get(tb)
        if la is None or lb is None:
            continue
        if lb > la or (lb == la and (ta, tb) not in SAME_LAYER):
            bad.append(f"{_rel(a)}:{lineno} imports {_rel(b)} ({ta} -> {tb} goes against the layer order): {line}")
    assert not bad, "imports against the engine's layer order:\n" + "\n".join(bad)


def test_no_cycle_between_files() -> None:
    graph: dict[Path, list[tuple[Path, int, str]]] = {}
    for a, b, lineno, line in edges():
        graph.setdefault(a, []).append((b, lineno, line))
    comps = cycles({a: [b for b, _, _ in es] for a, es in graph.items()})
    msgs = []
    for comp in comps:
        members = set(comp)
        for a in comp:
            for b, lineno, line in graph.get(a, []):
                if b in members:
                    msgs.append(f"{_rel(a)}:{lineno} imports {_rel(b)} (a cycle): {line}")
    assert not msgs, "cycles between engine files:\n" + "\n".join(msgs)


if __name__ == "__main__":
    pairs: dict[tuple[str, str], str] = {}
    for a, b, lineno, line in edges():
        if _top(a) != _top(b):
            pairs.setdefault((_top(a), _top(b)), f"{_rel(a)}:{lineno}: {line}")
    for (ta, tb), where in sorted(pairs.items()):
        print(f"{ta:12} -> {tb:12} e.g. {where}")

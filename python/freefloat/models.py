"""Built-in robots (the YAML files of `crates/freefloat-core/models/`, embedded in the engine).

    ff.models.names()            # ['naveen_dual_arm', ..., 'zhang2020_3d']
    m = ff.models.load("naveen_dual_arm")

Names say whose robot it is: `naveen_*` (Naveen, Shah, Misra: the dual-arm robot with three reaction wheels),
`zhang2020_*` (Zhang, Yue, Yuan 2020: post-capture robots with small, medium, large target and a 3-D one),
`valverde_*` (Valverde 2018, chapters 5 and 7). Earlier names (`seed000_*`, `seed001_*`, `thesis_*`) still load:
the engine keeps an alias table; listings show the current names only.
"""

from __future__ import annotations

from . import _core
from .model import Model

#: what `freefloat models` says once about the earlier names
ALIAS_NOTE = "earlier names (seed000_*, seed001_*, thesis_*) still load as aliases of these"


def names() -> list[str]:
    """Names of the built-in robots (current names; aliases are not listed)."""
    return list(_core.Model.builtin_names())


def is_builtin(name: str) -> bool:
    """Whether `name` is a built-in robot or an alias of one."""
    try:
        _core.Model.builtin_source(name)
        return True
    except ValueError:
        return False


def load(name: str) -> Model:
    """Load a built-in robot by name (or alias)."""
    return Model(_core.Model.builtin(name))


def source(name: str) -> str:
    """The YAML text of a built-in robot (a starting point for your own model file)."""
    return _core.Model.builtin_source(name)

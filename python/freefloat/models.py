"""Built-in robots (the YAML files of the repository's `models/`, embedded in the engine).

    ff.models.names()            # ['seed000_2d_large', ..., 'thesis_ch7_two_arm']
    m = ff.models.load("seed001_dual_arm")
"""

from __future__ import annotations

from . import _core
from .model import Model


def names() -> list[str]:
    """Names of the built-in robots."""
    return list(_core.Model.builtin_names())


def load(name: str) -> Model:
    """Load a built-in robot by name."""
    return Model(_core.Model.builtin(name))


def source(name: str) -> str:
    """The YAML text of a built-in robot (a starting point for your own model file)."""
    return _core.Model.builtin_source(name)

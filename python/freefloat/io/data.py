"""Access to the files shipped inside the package (folder `freefloat/data/`): built-in post-capture scenarios,
designed trajectories and campaign specs (`freefloat campaign --list`).

They are found with `importlib.resources`, so they work the same from a wheel, a normal install and an editable
install of a source checkout. Built-in robots are not here: they are embedded in the engine (`ff.models`).

    from freefloat import data                          # the same functions as freefloat.io.data
    data.names("scenarios")                             # ['zhang2020_2d_large', ...]
    data.read_text("scenarios", "zhang2020_2d_medium")  # the YAML text
    with data.path("trajectories", "naveen_exciting_trajectory") as p: ...

Earlier names (`ALIASES`) are still accepted everywhere a name is; listings show the current names.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from importlib import resources
from pathlib import Path

from .._core import InputError

#: kind -> file suffix of the shipped files
KINDS = {"scenarios": ".yaml", "trajectories": ".json", "campaigns": ".yaml"}

#: kind -> {earlier name: current name}; earlier names still load, listings show the current ones
ALIASES = {
    "scenarios": {
        "seed000_2d_large": "zhang2020_2d_large",
        "seed000_2d_medium": "zhang2020_2d_medium",
        "seed000_2d_small": "zhang2020_2d_small",
        "seed000_2d_sweep": "zhang2020_2d_sweep",
        "seed000_3d": "zhang2020_3d",
    },
    "trajectories": {"seed001_exciting_trajectory": "naveen_exciting_trajectory"},
}

#: the package that holds the files
PACKAGE = "freefloat.data"


def _folder(kind: str):
    if kind not in KINDS:
        raise InputError(f"unknown data kind '{kind}' (one of: {', '.join(KINDS)})")
    return resources.files(PACKAGE).joinpath(kind)


def resolve(kind: str, name: str) -> str:
    """The current name for `name` (itself, or the file an earlier name stands for)."""
    suffix = KINDS.get(kind, "")
    stem = name[: -len(suffix)] if suffix and name.endswith(suffix) else name
    return ALIASES.get(kind, {}).get(stem, stem)


def names(kind: str) -> list[str]:
    """Names (file stems) of the shipped files of one kind, sorted."""
    folder = _folder(kind)
    suffix = KINDS[kind]
    return sorted(p.name[: -len(suffix)] for p in folder.iterdir() if p.name.endswith(suffix))


def _entry(kind: str, name: str):
    suffix = KINDS.get(kind, "")
    f = _folder(kind).joinpath(resolve(kind, name) + suffix)
    if not f.is_file():
        raise InputError(f"no built-in {kind[:-1]} '{name}' (built-in: {', '.join(names(kind))})")
    return f


def exists(kind: str, name: str) -> bool:
    """Whether a shipped file of that kind and name exists."""
    try:
        _entry(kind, name)
        return True
    except InputError:
        return False


def read_text(kind: str, name: str) -> str:
    """The text of a shipped file."""
    return _entry(kind, name).read_text(encoding="utf-8")


@contextlib.contextmanager
def path(kind: str, name: str) -> Iterator[Path]:
    """A real file-system path to a shipped file for the duration of the `with` block (extracted to a
    temporary file only if the package is imported from an archive)."""
    with resources.as_file(_entry(kind, name)) as p:
        yield Path(p)

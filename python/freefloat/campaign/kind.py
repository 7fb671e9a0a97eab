"""One scenario kind of a campaign (`Kind`) and the plain-JSON forms of scenario mappings that the registry, the
kinds of `file_kinds.py` and the campaign files (`spec.py`) share: the canonical JSON text a run key hashes, the
round trip to plain JSON types, and the dotted paths of a mapping. It imports nothing of the campaign, so the
registry, the kinds and the spec all build on it without importing one another in a circle."""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import dataclass, field

from ..io.results import json_default


def _identity(d: dict) -> dict:
    return d


@dataclass(frozen=True)
class Kind:
    """One scenario kind: load its scenario, list its parameter paths, run it, name its summary numbers."""

    name: str
    description: str
    load: Callable[[object], dict]
    parameters: Callable[[dict], list]
    run: Callable[[dict, int], dict]
    #: the canonical JSON-able form of a scenario mapping (what the run key hashes)
    normalize: Callable[[dict], dict] = _identity
    #: summary names a report shows first
    headline: tuple = field(default_factory=tuple)
    #: top-level sections a campaign may add that the kind's `run` consumes itself (not keys of its scenario
    #: files, so the scenario schema does not check them; `run` does)
    campaign_keys: tuple = field(default_factory=tuple)


def canonical(obj) -> str:
    """The canonical JSON text of a mapping (sorted keys, no spaces; numpy values as plain numbers)."""
    return json.dumps(obj, sort_keys=True, separators=(",", ":"), default=json_default)


def json_roundtrip(d: dict) -> dict:
    """Plain JSON types (tuples -> lists, numpy scalars -> numbers), so the run key is stable."""
    return json.loads(canonical(d))


def leaf_paths(d, prefix: str = "") -> list[str]:
    """Every dotted path of a nested mapping: mappings and lists (themselves and their items) and scalars."""
    out = []
    if isinstance(d, dict):
        for k, v in d.items():
            p = f"{prefix}{k}"
            out.append(p)
            out += leaf_paths(v, p + ".")
    elif isinstance(d, list):
        for i, v in enumerate(d):
            p = f"{prefix}{i}"
            out.append(p)
            out += leaf_paths(v, p + ".")
    return out

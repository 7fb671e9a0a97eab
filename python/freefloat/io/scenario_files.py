"""Scenario files: YAML that says what to run (robot, initial state, gains, settings) for one command.

Every scenario file has a `kind` (absent means `postcapture`, the first kind there was), and each kind belongs to
one command. This module finds a scenario by built-in name or file path, parses it with errors that name the file
and line, checks it against its kind's declared schema (`scenario_schemas.py`: unknown keys, types, ranges; errors name
the file, line and key) and that it is of the kind the calling command runs; each command then reads its keys.

    from freefloat.io import scenario_files
    d, source = scenario_files.read("valverde_ch4_example_a", kind="control_adaptive")
    for s in scenario_files.listing(): print(s.name, s.kind, s.command)
"""

from __future__ import annotations

import difflib
from dataclasses import dataclass
from pathlib import Path

import yaml

from .._core import InputError
from . import data, scenario_schemas, schema  # noqa: F401  (scenario_schemas declares the kinds)

#: kind -> the command that runs scenarios of that kind (declared with each kind's schema: `scenario_schemas.py`)
KINDS = schema.commands()
DEFAULT_KIND = "postcapture"


@dataclass(frozen=True)
class ScenarioEntry:
    """One built-in scenario as `freefloat scenarios` lists it."""

    name: str
    kind: str
    description: str

    @property
    def command(self) -> str:
        return f"{KINDS[self.kind]} {self.name}"


def _parse_yaml(text: str, source: str, check: bool = True) -> dict:
    try:
        d = yaml.safe_load(text)
    except RecursionError:
        raise InputError(f"{source}: nested too deeply to be a scenario file") from None
    except yaml.YAMLError as e:
        mark = getattr(e, "problem_mark", None)
        where = f" line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
        problem = getattr(e, "problem", None) or str(e)
        raise InputError(f"{source}:{where}: not valid YAML ({problem})") from None
    if d is None:
        raise InputError(
            f"{source}: the file is empty (a scenario file is a YAML mapping of keys: model, duration, ...)"
        )
    if not isinstance(d, dict):
        raise InputError(f"{source}: a scenario file must be a YAML mapping of keys, got {type(d).__name__}")
    bad = [k for k in d if not isinstance(k, str)]
    if bad:
        raise InputError(f"{source}: key {bad[0]!r}: keys must be names (text), got {type(bad[0]).__name__}")
    kind = d.get("kind", DEFAULT_KIND)
    if not isinstance(kind, str) or kind not in KINDS:
        close = difflib.get_close_matches(str(kind), KINDS, n=1)
        hint = f" (did you mean '{close[0]}'?)" if close else ""
        raise InputError(f"{source}: key 'kind': unknown scenario kind '{kind}'{hint} (one of: {', '.join(KINDS)})")
    if check:
        schema.check(kind, d, source, text)
    return d


# the YAML text of each scenario read, by its source description: for the line of an error found later
_TEXTS: dict[str, str] = {}


def error_at(source: str, err: Exception) -> InputError:
    r"""An InputError for a problem found after the schema check (by the engine, against the robot), with the
    file's line of the key the problem names (`argument \`actuators.tanks[0].mass\`: ...` or
    `actuators.tanks[0].mass: ...`)."""
    import re

    msg = str(err)
    m = re.match(r"(?:argument `([\w.\[\]]+)`|([a-z_]+(?:\[\d+\])?(?:\.[\w]+(?:\[\d+\])?)*))\s*:\s*", msg)
    if not m:
        return InputError(f"{source}: {msg}")
    key = m.group(1) or m.group(2)
    rest = msg[m.end() :]
    line = ""
    text = _TEXTS.get(source)
    if text is not None:
        try:
            root = yaml.compose(text, Loader=yaml.SafeLoader)
            parent, node = schema._node_at(root, schema._parse_dotted(key))
            node = node if node is not None else parent
            if node is not None:
                line = f" line {node.start_mark.line + 1}:"
        except yaml.YAMLError:
            pass
    return InputError(f"{source}:{line} key '{key}': {rest}")


def read(spec: str | Path, kind: str) -> tuple[dict, str]:
    """The parsed scenario `spec` (a built-in name or a file path) and a description of where it came from.

    Raises InputError when it is not found, is not valid YAML, or is of another kind than `kind` (naming the
    command that runs it)."""
    if kind not in KINDS:
        raise ValueError(f"unknown scenario kind {kind!r}")
    p = Path(spec)
    if not p.suffix and data.exists("scenarios", str(spec)):
        text, source = data.read_text("scenarios", str(spec)), f"built-in scenario '{spec}'"
    elif p.suffix and p.is_file():
        source = str(p)
        try:
            text = p.read_text(encoding="utf-8")
        except UnicodeDecodeError as e:
            raise InputError(f"{source}: not UTF-8 text (byte {e.start}: {e.reason}); save the file as UTF-8") from None
    else:
        own = ", ".join(s.name for s in listing() if s.kind == kind) or "none"
        raise InputError(f"scenario '{spec}' not found (built-in {kind} scenarios: {own}; or give a .yaml file path)")
    d = _parse_yaml(text, source)
    _TEXTS[source] = text
    found = d.get("kind", DEFAULT_KIND)
    if found != kind:
        raise InputError(f"{source} is a '{found}' scenario, not '{kind}': run it with `{KINDS[found]} {spec}`")
    return d, source


def listing() -> list[ScenarioEntry]:
    """Every built-in scenario, sorted by kind (in the order of KINDS) and name."""
    out = []
    for name in data.names("scenarios"):
        d = _parse_yaml(data.read_text("scenarios", name), f"built-in scenario '{name}'", check=False)
        out.append(ScenarioEntry(name, d.get("kind", DEFAULT_KIND), str(d.get("description", "")).strip()))
    order = list(KINDS)
    return sorted(out, key=lambda s: (order.index(s.kind), s.name))

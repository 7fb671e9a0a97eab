"""Declared schemas of freefloat's YAML files, checked before any command reads a value.

Each scenario kind (and the campaign spec) is a pydantic model: the keys it accepts, their types and their ranges.
A file is checked against its kind's model; the first problem becomes one `InputError` that names the file, the
line, the key as the file spells it, what was wrong and, for an unknown key, the closest valid key:

    my.yaml: line 4: unknown key 'sample_perod' (did you mean 'sample_period'?)
    my.yaml: line 5: key 'duration': expected a number, got 'ten'
    my.yaml: line 12: key 'identification.transit_tolerance': must be > 0, got -0.001

Why pydantic (v2): its models are a declaration that reads like the file (one class per block), it forbids
unknown keys, checks nested mappings and lists and reports each problem with its location inside the document,
which is all a schema checker needs; the line numbers come from PyYAML's node tree (`yaml.compose`) walked along
that location. (jsonschema would need the same line mapping and writes its schemas as nested dicts that read
less like the file.)

A block that several kinds share (an `actuators:` or `sensors:` section, say) is one declaration:

    class Gyro(Block):
        noise: NonNegative = 0.0
    register_block("sensors", Sensors, kinds=("postcapture",))

after which every file of those kinds may have that block, checked like the rest.
"""

from __future__ import annotations

import contextlib
import contextvars
import dataclasses
import difflib
import math
import re
import typing
from typing import Annotated, Any, Literal

import yaml
from pydantic import BaseModel, ConfigDict, Field, PlainValidator, ValidationError, create_model

from .._core import InputError

__all__ = [
    "Block",
    "block_of",
    "check",
    "commands",
    "fields_of",
    "key",
    "kinds",
    "register_block",
    "register_kind",
]


class Block(BaseModel):
    """A mapping of the file: unknown keys are errors, and values are not converted behind the user's back (a
    quoted "10" is not a number)."""

    model_config = ConfigDict(extra="forbid", strict=True, frozen=True)


# -- value types ---------------------------------------------------------------------------------------------
# Each is a PlainValidator with its own message, so that a union ("a number or a list of numbers") is one
# error that says what is accepted, not one error per alternative.


class _Bad(ValueError):
    pass


def _describe(x) -> str:
    s = repr(x)
    return s if len(s) <= 60 else s[:57] + "..."


# PyYAML reads YAML 1.1, where `1e6` (no dot) is text, not a number as in YAML 1.2 and everywhere else: such
# text is taken as the number it spells (and only such text: `ten` or `0.1A` are refused).
_NUMERIC = re.compile(r"[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?")


def _number(x, what: str = "a number") -> float:
    if isinstance(x, str) and _NUMERIC.fullmatch(x.strip()):
        x = float(x)
    if isinstance(x, bool) or not isinstance(x, (int, float)):
        raise _Bad(f"expected {what}, got {_describe(x)}")
    if not math.isfinite(x):
        raise _Bad(f"expected a finite number, got {x}")
    return float(x)


# types_only(): ranges (and checks across keys) are not enforced — a campaign checks its grid values' types up
# front and lets a value out of range fail its own run, which the campaign records as that run's error
_TYPES_ONLY = contextvars.ContextVar("freefloat_schema_types_only", default=False)


@contextlib.contextmanager
def types_only():
    tok = _TYPES_ONLY.set(True)
    try:
        yield
    finally:
        _TYPES_ONLY.reset(tok)


def _range(lo=None, hi=None, lo_open=False, hi_open=False):
    def check(x: float) -> float:
        if _TYPES_ONLY.get():
            return x
        if lo is not None and (x <= lo if lo_open else x < lo):
            raise _Bad(f"must be {'>' if lo_open else '>='} {lo:g}, got {x:g}")
        if hi is not None and (x >= hi if hi_open else x > hi):
            raise _Bad(f"must be {'<' if hi_open else '<='} {hi:g}, got {x:g}")
        return x

    return check


def number(lo=None, hi=None, lo_open=False, hi_open=False):
    """A finite number (an integer is accepted) within the given range."""
    rng = _range(lo, hi, lo_open, hi_open)
    return Annotated[float, PlainValidator(lambda x: rng(_number(x)))]


def integer(lo=None, hi=None):
    rng = _range(lo, hi)

    def v(x):
        if isinstance(x, bool) or not isinstance(x, int):
            raise _Bad(f"expected an integer, got {_describe(x)}")
        rng(x)
        return x

    return Annotated[int, PlainValidator(v)]


def numbers(n: int | None = None, lo=None, lo_open=False, scalar_ok=False, nested_ok=False):
    """A list of finite numbers (of length `n` when given); `scalar_ok`: a single number is accepted too;
    `nested_ok`: a list of lists (a matrix) is accepted too."""
    rng = _range(lo, None, lo_open)
    what = []
    if scalar_ok:
        what.append("a number")
    what.append(f"a list of {n} numbers" if n else "a list of numbers")
    if nested_ok:
        what.append("a matrix (list of lists)")
    what_s = " or ".join(what)

    def v(x):
        if scalar_ok and not isinstance(x, list):
            return rng(_number(x, what_s))
        if not isinstance(x, list):
            raise _Bad(f"expected {what_s}, got {_describe(x)}")
        if nested_ok and x and all(isinstance(r, list) for r in x):
            return [[_number(y, what_s) for y in r] for r in x]
        if n is not None and len(x) != n:
            raise _Bad(f"expected {what_s}, got {len(x)} entries")
        return [rng(_number(y, what_s)) for y in x]

    return Annotated[Any, PlainValidator(v)]


def text():
    def v(x):
        if not isinstance(x, str):
            raise _Bad(f"expected text, got {_describe(x)}")
        return x

    return Annotated[str, PlainValidator(v)]


def mapping_of(value_type_check, what: str):
    """A mapping of names (as the file chooses them: joint or body names) to values checked by a function."""

    def v(x):
        if not isinstance(x, dict):
            raise _Bad(f"expected a mapping of {what}, got {_describe(x)}")
        for k, y in x.items():
            try:
                value_type_check(y)
            except _Bad as e:
                raise _Bad(f"entry '{k}': {e}") from None
        return x

    return Annotated[dict, PlainValidator(v)]


Text = text()
Number = number()
Positive = number(lo=0, lo_open=True)
NonNegative = number(lo=0)
Bool = Annotated[bool, Field(strict=True)]
Anything = Any  # free-form blocks (the paper's printed values, notes): not checked


def _name_or_index(x):
    if isinstance(x, bool) or not isinstance(x, (str, int)) or (isinstance(x, int) and x < 0):
        raise _Bad(f"expected a tank name or index, got {x!r}")
    return x


#: a reference to an item of a list by its name or its index (a thruster's tank)
TankRef = Annotated[Any, PlainValidator(_name_or_index)]


# -- blocks declared by the objects that run them ------------------------------------------------------------
def key(schema_type, default=dataclasses.MISSING, *, default_factory=dataclasses.MISSING):
    """A dataclass field that carries its schema type: the class that runs a block (an actuator, say) declares each
    key once, with its default, and `block_of` makes the schema block from it."""
    return dataclasses.field(default=default, default_factory=default_factory, metadata={"schema": schema_type})


def block_of(cls, order=None, name: str | None = None, *, base: type[Block] | None = None, tags=None) -> type[Block]:
    """The schema block of a dataclass whose fields are declared with `key`: the same keys, defaults and
    required keys, with their schema types, in `order` (the keys as the engine lists them; default: the class's).
    `base`: a Block subclass carrying cross-key checks; `tags`: required keys the file has but the class does not
    (a sensor's `type`, which is the class itself), as {key: schema type}, listed first."""
    fs = {f.name: f for f in dataclasses.fields(cls)}
    names = list(order) if order is not None else list(fs)
    if sorted(names) != sorted(fs):
        raise TypeError(f"{cls.__name__}: schema order {names} is not its fields {list(fs)}")
    spec = {k: (t, ...) for k, t in (tags or {}).items()}
    for n in names:
        f = fs[n]
        if "schema" not in f.metadata:
            raise TypeError(f"{cls.__name__}.{n}: declare it with schema.key(TYPE, default) to derive its schema")
        if f.default is not dataclasses.MISSING:
            default = f.default
        elif f.default_factory is not dataclasses.MISSING:
            default = f.default_factory()
        else:
            default = ...
        spec[n] = (f.metadata["schema"], default)
    return create_model(name or f"{cls.__name__}Block", __base__=base or Block, **spec)


# -- registry ------------------------------------------------------------------------------------------------
_KINDS: dict[str, type[BaseModel]] = {}
_COMMANDS: dict[str, str] = {}
_BLOCKS: dict[str, tuple[type[BaseModel], tuple[str, ...]]] = {}
_BUILT: dict[str, type[BaseModel]] = {}


def register_kind(kind: str, model: type[BaseModel], command: str | None = None) -> None:
    """Declare a scenario kind: its schema and the command that runs its files (the one registry of scenario kinds:
    the readers, `freefloat scenarios` and the schemas use it). The campaign spec is kind 'campaign', without a
    command (it is not a scenario)."""
    _KINDS[kind] = model
    if command is not None:
        _COMMANDS[kind] = command
    _BUILT.clear()


def register_block(name: str, model: type[BaseModel], kinds: tuple[str, ...]) -> None:
    """Declare an optional top-level block `name` that files of the given kinds may have, checked by `model`."""
    _BLOCKS[name] = (model, tuple(kinds))
    _BUILT.clear()


_REFUSED: dict[tuple[str, str], str] = {}


def refuse_block(name: str, kind: str, why: str) -> None:
    """A block that files of `kind` may not have, with the reason told to the user (rather than the plain
    "unknown key"): a block registered for other kinds whose runner this kind's command does not use."""
    _REFUSED[(name, kind)] = why


def kinds() -> list[str]:
    return list(_KINDS)


def commands() -> dict[str, str]:
    """Scenario kind -> the command that runs its files, in the order the kinds were declared."""
    return dict(_COMMANDS)


def _model(kind: str) -> type[BaseModel]:
    if kind not in _BUILT:
        base = _KINDS[kind]
        extra = {n: (m | None, None) for n, (m, ks) in _BLOCKS.items() if kind in ks and n not in base.model_fields}
        _BUILT[kind] = create_model(f"{base.__name__}WithBlocks", __base__=base, **extra) if extra else base
    return _BUILT[kind]


def _unwrap(tp, data=None):
    """The BaseModel class inside an annotation (Optional[M], list[M], dict[str, M]), or None. Of a union of
    models told apart by their `type` key, the one whose type is `data`'s."""
    if isinstance(tp, type) and issubclass(tp, BaseModel):
        return tp
    found = []
    for a in typing.get_args(tp):
        m = _unwrap(a, data)
        if m is not None:
            found.append(m)
    if len(found) > 1 and isinstance(data, dict) and "type" in data:
        for m in found:
            f = m.model_fields.get("type")
            if f is not None and data["type"] in typing.get_args(f.annotation):
                return m
    return found[0] if found else None


def fields_of(kind: str, path: tuple = (), data=None) -> list[str]:
    """The keys the schema of `kind` accepts at the dotted location `path` (a tuple of keys); `data`: the
    file's mapping, to tell the members of a union apart (a sensor list's entries by their `type`)."""
    m = _model(kind)
    cur = data
    for j, p in enumerate(path):
        if isinstance(p, int):
            cur = cur[p] if isinstance(cur, list) and 0 <= p < len(cur) else None
            continue
        f = m.model_fields.get(p)
        cur = cur.get(p) if isinstance(cur, dict) else None
        sub = cur
        if isinstance(sub, list):
            nxt = path[j + 1] if j + 1 < len(path) else None
            sub = sub[nxt] if isinstance(nxt, int) and 0 <= nxt < len(sub) else None
        m = _unwrap(f.annotation, sub) if f is not None else None
        if m is None:
            return []
    return list(m.model_fields)


# -- checking ------------------------------------------------------------------------------------------------
def _node_at(node, path):
    """The YAML node at `path` (keys and list indices), and the deepest node found on the way."""
    cur = node
    for p in path:
        nxt = None
        if isinstance(cur, yaml.MappingNode):
            for k, v in cur.value:
                if isinstance(k, yaml.ScalarNode) and k.value == str(p):
                    nxt = (k, v)
                    break
        elif isinstance(cur, yaml.SequenceNode) and isinstance(p, int) and 0 <= p < len(cur.value):
            nxt = (cur.value[p], cur.value[p])
        if nxt is None:
            return cur, None
        key_node, cur = nxt
    return cur, key_node if path else cur


def _data_path(d, loc) -> tuple:
    """pydantic's location with its internal steps (a union member's name, a validator's tag) dropped: the keys
    and indices as they are in the file."""
    out, cur = [], d
    for p in loc:
        if isinstance(cur, dict) and p in cur:
            out.append(p)
            cur = cur[p]
        elif isinstance(cur, list) and isinstance(p, int) and 0 <= p < len(cur):
            out.append(p)
            cur = cur[p]
        elif isinstance(cur, dict) and isinstance(p, str) and p == cur.get("type"):
            continue  # the tag of a union member told apart by `type` (a sensor's type): not a key of the file
        elif isinstance(cur, dict) and isinstance(p, str) and not any(c in p for c in "[]-"):
            out.append(p)  # a missing or unknown key: part of the path, though not in the data
            cur = None
    return tuple(out)


def _parse_dotted(s: str) -> tuple:
    """'actuators.thrusters[0].direction' -> ('actuators', 'thrusters', 0, 'direction')."""
    out = []
    for part in s.split("."):
        name, *idx = part.split("[")
        if name:
            out.append(name)
        out += [int(i.rstrip("]")) for i in idx]
    return tuple(out)


def _dotted(path) -> str:
    s = ""
    for p in path:
        s += f"[{p}]" if isinstance(p, int) else (f".{p}" if s else str(p))
    return s


def _message(kind: str, d: dict, err: dict, source: str, root) -> str:
    path = _data_path(d, err["loc"])
    typ = err["type"]
    where_node = None
    if root is not None:
        parent, key_node = _node_at(root, path)
        where_node = key_node if key_node is not None else parent
    line = f" line {where_node.start_mark.line + 1}:" if where_node is not None else ""
    if typ == "extra_forbidden":
        key = path[-1]
        if len(path) == 1 and (key, kind) in _REFUSED:
            return f"{source}:{line} key '{key}': {_REFUSED[(key, kind)]}"
        valid = fields_of(kind, path[:-1], d)
        close = difflib.get_close_matches(str(key), valid, n=1, cutoff=0.6)
        if close:
            return f"{source}:{line} unknown key '{_dotted(path)}' (did you mean '{close[0]}'?)"
        return f"{source}:{line} unknown key '{_dotted(path)}'; valid keys here: {', '.join(valid)}"
    if typ == "missing":
        return f"{source}:{line} missing key '{_dotted(path)}'"
    msg = err["msg"]
    if msg.startswith("Value error, "):
        msg = msg[len("Value error, ") :]
        m = re.match(r"key '([\w.\[\]]+)': ", msg)
        if m:  # a check across keys (after the keys themselves): it names the key to change
            named = _parse_dotted(m.group(1))
            # a key from the top of the file, or one relative to the block that checked it
            path = named if not path or named[0] == path[0] else tuple(path) + named
            msg = msg[m.end() :]
            if root is not None:
                parent, key_node = _node_at(root, path)
                node = key_node if key_node is not None else parent
                line = f" line {node.start_mark.line + 1}:"
    elif typ in ("model_type", "dict_type"):
        msg = f"expected a mapping of keys, got {_describe(err.get('input'))}"
    elif typ == "literal_error":
        msg = f"{msg[0].lower()}{msg[1:]}, got {_describe(err.get('input'))}"
    elif typ.endswith("_type") or typ.endswith("_parsing"):
        msg = f"{msg[0].lower()}{msg[1:]}, got {_describe(err.get('input'))}"
    return f"{source}:{line} key '{_dotted(path)}': {msg}"


def check(kind: str, d: dict, source: str, text: str | None = None) -> None:
    """Check the parsed mapping `d` against the schema of `kind`; InputError (file, line, key, problem) if not.
    `text` is the file's YAML text, for line numbers."""
    try:
        _model(kind).model_validate(d)
    except ValidationError as e:
        root = None
        if text is not None:
            try:
                root = yaml.compose(text, Loader=yaml.SafeLoader)
            except yaml.YAMLError:
                root = None
        # a typo shows as an unknown key and a missing one: the unknown key (with its suggestion) is the news
        errs = sorted(e.errors(include_url=False), key=lambda x: x["type"] != "extra_forbidden")
        first = _message(kind, d, errs[0], source, root)
        more = f" (and {len(errs) - 1} more problem{'s' if len(errs) > 2 else ''})" if len(errs) > 1 else ""
        raise InputError(first + more) from None


def validated_block(name: str, value):
    """The schema's reading of a registered block that `check` accepted (numbers as numbers, mappings as models)."""
    from pydantic import TypeAdapter

    return TypeAdapter(_BLOCKS[name][0]).validate_python(value)


def literal(*values):
    return Literal[values]  # type: ignore[valid-type]

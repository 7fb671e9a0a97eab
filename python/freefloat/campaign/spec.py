"""Campaign specs: YAML that says which scenario to run, which parameters to vary (a grid and/or Monte Carlo draws
over dotted parameter paths), and with which seeds. `expand` turns a spec into its list of runs, each with a key
(a hash of the run's inputs) so that a campaign can be resumed.

    name: zhang2020_velocity_sweep
    kind: postcapture                    # a kind of the registry (freefloat.campaign.registry.KINDS)
    scenario: zhang2020_2d_sweep         # built-in scenario name, a file path (relative to the spec), or a mapping
    set:                                 # fixed overrides, the same in every run
      duration: 60.0
    grid:                                # every combination of the listed values (the first path varies slowest)
      initial.base_velocity.0: [0, 50, 100, 150, 200]
      initial.base_velocity.1: [0, 50, 100, 150, 200]
    monte_carlo:                         # optional: `runs` draws per grid point
      runs: 20
      seed: 0                            # master seed: run seeds and draws derive from it (numpy SeedSequence)
      parameters:                        # optional random parameters, drawn per run
        noise.velocity: {distribution: loguniform, low: 1.0e-5, high: 1.0e-3}

A dotted path names a key of the scenario mapping; an integer component indexes a list
(`initial.base_velocity.0` is Vx). Without `monte_carlo` each grid point runs once with `seed` (default 0).
"""

from __future__ import annotations

import copy
import difflib
import hashlib
import itertools
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import yaml

from .._core import InputError
from . import registry
from .kind import canonical as _canonical
from .kind import leaf_paths  # noqa: F401  (re-exported: `freefloat.campaign.spec.leaf_paths`)

#: distributions a Monte Carlo parameter can be drawn from, with their required keys
DISTRIBUTIONS = {
    "uniform": ("low", "high"),
    "loguniform": ("low", "high"),
    "normal": ("mean", "std"),
    "choice": ("values",),
}
SPEC_KEYS = ("name", "description", "kind", "scenario", "set", "grid", "monte_carlo", "paper")


@dataclass
class Run:
    """One run of a campaign: its position, the overrides applied to the base scenario, its seed, and the key
    (hash of kind + final scenario + seed) that identifies its result in the dataset."""

    index: int
    params: dict  # dotted path -> value (grid values and Monte Carlo draws; not the fixed `set`)
    seed: int
    scenario: dict  # the base scenario with `set` and `params` applied
    kind: str
    key: str = ""

    def payload(self) -> dict:
        """What a worker needs to execute the run (small, picklable)."""
        return {
            "index": self.index,
            "key": self.key,
            "kind": self.kind,
            "seed": self.seed,
            "params": self.params,
            "scenario": self.scenario,
        }


@dataclass
class CampaignSpec:
    name: str
    kind: str
    scenario_ref: object  # name / path / mapping, as written
    base: dict  # the loaded base scenario
    source: str
    description: str = ""
    fixed: dict = field(default_factory=dict)
    grid: dict = field(default_factory=dict)
    monte_carlo: dict | None = None
    paper: dict = field(default_factory=dict)
    raw: dict = field(default_factory=dict)

    @property
    def runs_total(self) -> int:
        n = 1
        for v in self.grid.values():
            n *= len(v)
        return n * (int(self.monte_carlo["runs"]) if self.monte_carlo else 1)

    def fingerprint(self) -> str:
        """A hash of what the campaign runs (kind, base scenario, overrides, grid, draws), not its description:
        two specs with the same fingerprint produce the same runs."""
        what = {
            "kind": self.kind,
            "base": registry.get(self.kind).normalize(copy.deepcopy(self.base)),
            "set": self.fixed,
            "grid": self.grid,
            "monte_carlo": self.monte_carlo,
        }
        return _hash(what)

    def runs(self, limit: int | None = None) -> list[Run]:
        """The campaign's runs in order (grid points outer, Monte Carlo draws inner); the first `limit` only."""
        return expand(self, limit)


def _hash(obj) -> str:
    return hashlib.sha256(_canonical(obj).encode()).hexdigest()[:20]


def run_key(kind: str, scenario: dict, seed: int) -> str:
    """The key of a run: a hash of everything that determines its result (kind, final scenario, seed)."""
    return _hash({"kind": kind, "scenario": scenario, "seed": int(seed)})


# -- dotted paths -----------------------------------------------------------------------------------------
def _split(path: str) -> list:
    if not isinstance(path, str) or not path or any(not p for p in path.split(".")):
        raise InputError(f"parameter path {path!r}: expected dotted keys such as 'initial.base_velocity.0'")
    return [int(p) if p.lstrip("-").isdigit() else p for p in path.split(".")]


def get_path(d: dict, path: str):
    cur = d
    for p in _split(path):
        cur = cur[p]
    return cur


def set_path(d: dict, path: str, value) -> None:
    """Set `value` at the dotted `path` of the mapping `d` in place, creating missing mappings on the way."""
    parts = _split(path)
    cur = d
    for i, p in enumerate(parts[:-1]):
        nxt = parts[i + 1]
        if isinstance(cur, list):
            cur = cur[p]
            continue
        if cur.get(p) is None:
            cur[p] = [] if isinstance(nxt, int) else {}
        cur = cur[p]
    last = parts[-1]
    if isinstance(cur, list):
        if not isinstance(last, int) or not -len(cur) <= last < len(cur):
            raise InputError(f"parameter {path!r}: index {last} outside a list of {len(cur)}")
        cur[last] = value
    else:
        cur[last] = value


def check_path(path: str, valid: list[str], kind: str, where: str) -> None:
    """InputError naming `path` and the closest valid names when it is not one of `valid`."""
    _split(path)
    if path in valid:
        return
    close = difflib.get_close_matches(path, valid, n=3, cutoff=0.5)
    hint = f"; closest: {', '.join(close)}" if close else ""
    tops = sorted({v.split(".")[0] for v in valid})
    raise InputError(
        f"{where}: unknown parameter '{path}' for a {kind} scenario{hint} (top-level keys: {', '.join(tops)})"
    )


# -- reading ----------------------------------------------------------------------------------------------
def parse(d: dict, source: str, base_dir: Path | None = None) -> CampaignSpec:
    """A CampaignSpec from a parsed YAML mapping; InputError naming the key at fault."""
    if not isinstance(d, dict):
        raise InputError(f"{source}: a campaign spec must be a YAML mapping, got {type(d).__name__}")
    unknown = [k for k in d if k not in SPEC_KEYS]
    if unknown:
        close = difflib.get_close_matches(str(unknown[0]), SPEC_KEYS, n=1)
        raise InputError(
            f"{source}: unknown key '{unknown[0]}'"
            + (f" (did you mean '{close[0]}'?)" if close else "")
            + f"; keys of a campaign spec: {', '.join(SPEC_KEYS)}"
        )
    for k in ("name", "kind", "scenario"):
        if k not in d:
            raise InputError(f"{source}: missing key '{k}'")
    kind = registry.get(d["kind"], where=f"{source}: key 'kind'")
    ref = d["scenario"]
    if isinstance(ref, str) and base_dir is not None and Path(ref).suffix:
        p = Path(ref)
        ref = str(p if p.is_absolute() else base_dir / p)
    base = kind.load(ref)
    valid = kind.parameters(base)
    fixed = d.get("set") or {}
    grid = d.get("grid") or {}
    mc = d.get("monte_carlo")
    if not isinstance(fixed, dict):
        raise InputError(f"{source}: key 'set' must map parameter paths to values")
    if not isinstance(grid, dict):
        raise InputError(f"{source}: key 'grid' must map parameter paths to lists of values")
    for p in fixed:
        check_path(str(p), valid, kind.name, f"{source}: set")
    for p, values in grid.items():
        check_path(str(p), valid, kind.name, f"{source}: grid")
        if not isinstance(values, list):
            raise InputError(f"{source}: grid '{p}' must be a list of values, got {type(values).__name__}")
        if not values:
            raise InputError(f"{source}: grid '{p}' has no values: the campaign would have no runs")
    if mc is not None:
        mc = _parse_mc(mc, source, valid, kind.name)
    if not grid and mc is None:
        raise InputError(f"{source}: neither 'grid' nor 'monte_carlo': the campaign would have no runs to vary")
    _check_values(kind.name, base, fixed, grid, source, kind.campaign_keys)
    spec = CampaignSpec(
        name=str(d["name"]),
        kind=kind.name,
        scenario_ref=d["scenario"],
        base=base,
        source=source,
        description=str(d.get("description", "")).strip(),
        fixed=dict(fixed),
        grid={str(k): list(v) for k, v in grid.items()},
        monte_carlo=mc,
        paper=d.get("paper") or {},
        raw=d,
    )
    return spec


def _check_values(kind: str, base: dict, fixed: dict, grid: dict, source: str, campaign_keys=()) -> None:
    """The base scenario with `set`, and with each grid value in turn, against the kind's declared schema
    (io/scenario_schemas.py): a value of the wrong type (a typo: every run would fail) is refused before any run
    starts; a value out of range is left to fail its own run, recorded as that run's error. The kind's
    `campaign_keys` (sections its run consumes itself) are left out of the schema check."""
    from ..io import schema

    if kind not in schema.kinds():
        return

    def scenario_part(d: dict) -> dict:
        return {k: v for k, v in d.items() if k not in campaign_keys}

    with schema.types_only():
        sc = copy.deepcopy(base)
        for p, v in fixed.items():
            set_path(sc, str(p), copy.deepcopy(v))
        schema.check(kind, scenario_part(sc), f"{source}: the scenario with 'set' applied")
        for p, values in grid.items():
            for v in values:
                one = copy.deepcopy(sc)
                set_path(one, str(p), copy.deepcopy(v))
                schema.check(kind, scenario_part(one), f"{source}: grid '{p}' = {v!r}")


def _parse_mc(mc, source, valid, kind) -> dict:
    if not isinstance(mc, dict):
        raise InputError(f"{source}: key 'monte_carlo' must be a mapping with 'runs' (and 'seed', 'parameters')")
    bad = [k for k in mc if k not in ("runs", "seed", "parameters")]
    if bad:
        raise InputError(f"{source}: monte_carlo: unknown key '{bad[0]}' (keys: runs, seed, parameters)")
    runs = mc.get("runs")
    if not isinstance(runs, int) or isinstance(runs, bool) or runs < 1:
        raise InputError(f"{source}: monte_carlo.runs must be a positive integer, got {runs!r}")
    seed = mc.get("seed", 0)
    if not isinstance(seed, int) or isinstance(seed, bool) or seed < 0:
        raise InputError(f"{source}: monte_carlo.seed must be a non-negative integer, got {seed!r}")
    params = mc.get("parameters") or {}
    if not isinstance(params, dict):
        raise InputError(f"{source}: monte_carlo.parameters must map parameter paths to distributions")
    for p, dist in params.items():
        check_path(str(p), valid, kind, f"{source}: monte_carlo.parameters")
        where = f"{source}: monte_carlo.parameters '{p}'"
        if not isinstance(dist, dict) or dist.get("distribution") not in DISTRIBUTIONS:
            raise InputError(f"{where}: expected {{distribution: one of {', '.join(DISTRIBUTIONS)}, ...}}")
        need = DISTRIBUTIONS[dist["distribution"]]
        missing = [k for k in need if k not in dist]
        if missing:
            raise InputError(f"{where}: a {dist['distribution']} distribution needs {', '.join(need)}")
        if dist["distribution"] == "choice":
            if not isinstance(dist["values"], list) or not dist["values"]:
                raise InputError(f"{where}: 'values' must be a non-empty list")
        else:
            a, b = (float(dist[k]) for k in need)
            if not (np.isfinite(a) and np.isfinite(b)):
                raise InputError(f"{where}: {need[0]} and {need[1]} must be finite numbers")
            if dist["distribution"] in ("uniform", "loguniform") and not a < b:
                raise InputError(f"{where}: low must be below high, got {a} and {b}")
            if dist["distribution"] == "loguniform" and a <= 0:
                raise InputError(f"{where}: a loguniform distribution needs low > 0, got {a}")
            if dist["distribution"] == "normal" and b < 0:
                raise InputError(f"{where}: std must be non-negative, got {b}")
    return {"runs": runs, "seed": seed, "parameters": {str(k): dict(v) for k, v in params.items()}}


def load(spec: str | Path) -> CampaignSpec:
    """A campaign spec by built-in name (`builtin_names()`) or YAML file path."""
    from .. import data

    p = Path(spec)
    if p.suffix in (".yaml", ".yml") and p.is_file():
        text, source, base_dir = p.read_text(encoding="utf-8"), str(p), p.resolve().parent
    elif not p.suffix and data.exists("campaigns", str(spec)):
        text, source, base_dir = data.read_text("campaigns", str(spec)), f"built-in campaign '{spec}'", None
    else:
        names = data.names("campaigns")
        close = difflib.get_close_matches(str(spec), names, n=2, cutoff=0.5)
        raise InputError(
            f"campaign spec '{spec}' not found"
            + (f" (did you mean {' or '.join(close)}?)" if close else "")
            + f"; built-in campaigns: {', '.join(names)}; or give a .yaml file path"
        )
    try:
        d = yaml.safe_load(text)
    except yaml.YAMLError as e:
        mark = getattr(e, "problem_mark", None)
        where = f" line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
        raise InputError(f"{source}:{where}: not valid YAML ({getattr(e, 'problem', None) or e})") from None
    if isinstance(d, dict):  # the declared schema (io/scenario_schemas.py): unknown keys and types, with lines
        from ..io import schema

        schema.check("campaign", d, source, text)
    return parse(d, source, base_dir)


def builtin_names() -> list[str]:
    from .. import data

    return data.names("campaigns")


# -- expansion --------------------------------------------------------------------------------------------
def _draw(dist: dict, rng: np.random.Generator):
    kind = dist["distribution"]
    if kind == "uniform":
        return float(rng.uniform(float(dist["low"]), float(dist["high"])))
    if kind == "loguniform":
        return float(np.exp(rng.uniform(np.log(float(dist["low"])), np.log(float(dist["high"])))))
    if kind == "normal":
        return float(rng.normal(float(dist["mean"]), float(dist["std"])))
    vals = dist["values"]
    return vals[int(rng.integers(len(vals)))]


def expand(spec: CampaignSpec, limit: int | None = None) -> list[Run]:
    """The runs of `spec` in order; the run seeds and draws derive from the master seed and the draw index, so a
    run's inputs do not depend on `limit` or on which other runs exist."""
    kind = registry.get(spec.kind)
    base = copy.deepcopy(spec.base)
    for p, v in spec.fixed.items():
        set_path(base, p, copy.deepcopy(v))
    grid_paths = list(spec.grid)
    points = list(itertools.product(*(spec.grid[p] for p in grid_paths))) if grid_paths else [()]
    mc = spec.monte_carlo
    draws = mc["runs"] if mc else 1
    master = mc["seed"] if mc else 0
    out: list[Run] = []
    for gi, point in enumerate(points):
        for di in range(draws):
            if limit is not None and len(out) >= limit:
                return out
            params = dict(zip(grid_paths, point))
            if mc:
                # the same draw index gets the same noise seed at every grid point (common random numbers:
                # differences between grid points are then not hidden by different noise)
                ss = np.random.SeedSequence([master, di])
                seed = int(ss.generate_state(1)[0])
                rng = np.random.default_rng(np.random.SeedSequence([master, di, gi, 1]))
                for p, dist in mc["parameters"].items():
                    params[p] = _draw(dist, rng)
            else:
                seed = 0
            sc = copy.deepcopy(base)
            for p, v in params.items():
                set_path(sc, p, copy.deepcopy(v))
            sc = kind.normalize(sc)
            r = Run(index=len(out), params=params, seed=seed, scenario=sc, kind=spec.kind)
            r.key = run_key(spec.kind, sc, seed)
            out.append(r)
    return out

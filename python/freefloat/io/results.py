"""What a simulation run writes and prints: the conservation summary (every number `--out DIR/results.json` holds)
and the output files (trajectory Parquet, results.json, conservation figure)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

#: trajectory file types `--out` accepts; any other suffix is refused (not taken for a directory name)
TRAJECTORY_SUFFIXES = (".parquet", ".pq", ".csv")


def out_paths(out: str | None, stem: str) -> tuple[Path | None, Path | None, Path | None]:
    """--out FILE.parquet (or FILE.csv) writes that file, FILE.results.json and FILE.png; --out DIR writes
    DIR/<stem>.parquet, DIR/results.json and DIR/<stem>.png. A path with another suffix is an error rather
    than a directory called, say, run.txt."""
    if out is None:
        return None, None, None
    p = Path(out)
    if p.suffix.lower() in TRAJECTORY_SUFFIXES:
        p.parent.mkdir(parents=True, exist_ok=True)
        return p, p.with_suffix(".results.json"), p.with_suffix(".png")
    if p.suffix and not p.is_dir():
        from .._core import InputError

        raise InputError(
            f"--out {out}: expected a trajectory file ({', '.join(TRAJECTORY_SUFFIXES)}) or a directory (no suffix)"
        )
    p.mkdir(parents=True, exist_ok=True)
    return p / f"{stem}.parquet", p / "results.json", p / f"{stem}.png"


def summarize(traj, wall: float) -> dict:
    """Conservation figures of a simulated trajectory (momentum drift, energy minus work) and its statistics."""
    d = traj.momentum_drift()
    e = traj.energy_balance()
    return {
        "samples": len(traj),
        "t_final": float(traj.t[-1]),
        "wall_time_s": wall,
        **traj.stats,
        "momentum_initial": traj.momentum[0].tolist(),
        "momentum_final": traj.momentum[-1].tolist(),
        "momentum_drift_linear_abs": d["linear_abs"],
        "momentum_drift_angular_abs": d["angular_abs"],
        "momentum_drift_linear_rel": d["linear_rel"],
        "momentum_drift_angular_rel": d["angular_rel"],
        "kinetic_energy_initial": float(traj.kinetic_energy[0]),
        "kinetic_energy_final": float(traj.kinetic_energy[-1]),
        "energy_minus_work_abs": e["abs"],
        "energy_minus_work_rel": e["rel"],
    }


def summary_text(title: str, s: dict) -> str:
    """The summary of `summarize` as the lines the command line prints (a blank line, then the title)."""
    return "\n".join(
        [
            f"\n{title}",
            f"  simulated {s['t_final']:.3f} s in {s['wall_time_s']:.3f} s wall ({s['steps']} steps, {s['method']})",
            f"  momentum drift   linear  {s['momentum_drift_linear_abs']:.3e} kg m/s   "
            f"(relative {s['momentum_drift_linear_rel']:.2e})",
            f"                   angular {s['momentum_drift_angular_abs']:.3e} kg m²/s  "
            f"(relative {s['momentum_drift_angular_rel']:.2e})",
            f"  kinetic energy   {s['kinetic_energy_initial']:.6g} J -> {s['kinetic_energy_final']:.6g} J",
            f"  |ΔE − work|      {s['energy_minus_work_abs']:.3e} J   (relative {s['energy_minus_work_rel']:.2e})",
        ]
    )


def write_run(traj, summary: dict, out, stem: str, title: str) -> list[Path]:
    """Write the trajectory, results.json and the conservation figure (see `out_paths`); returns the paths."""
    from ..viz import conservation

    pq, js, png = out_paths(out, stem)
    if pq is None:
        return []
    traj.to_csv(pq) if pq.suffix.lower() == ".csv" else traj.to_parquet(pq)
    conservation(traj, png, title)
    js.write_text(json.dumps(summary, indent=2))
    return [pq, js, png]


def json_default(o):
    """`json.dumps(..., default=json_default)`: numpy scalars and arrays as plain numbers and lists (every
    results.json, the campaign's run keys)."""
    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    raise TypeError(f"not JSON serialisable: {type(o).__name__}")

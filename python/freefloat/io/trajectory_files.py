"""Joint-trajectory files (JSON, format `freefloat-trajectory-1`): cycloidal, Fourier, or a stack of those, with
the names of the joints they drive. Written by `freefloat excite`, read by `freefloat identify minimal
--trajectory` and by the demo (the designed trajectory shipped in `freefloat.data`)."""

from __future__ import annotations

import json
from pathlib import Path

from .._core import InputError
from ..trajectories import Cycloidal, Fourier, Stacked


def save_trajectory(path, traj, joints, model_name: str = "") -> None:
    """A joint trajectory as JSON: cycloidal (start, range, directions, interval), Fourier coefficients, or a
    stack of those (e.g. Fourier arm joints with cycloidal wheels)."""
    d = _traj_to_dict(traj)
    d.update(joints=list(joints), model=model_name, format="freefloat-trajectory-1")
    Path(path).write_text(json.dumps(d, indent=2))


def _traj_to_dict(traj) -> dict:
    if isinstance(traj, Cycloidal):
        return {
            "kind": "cycloidal",
            "start": traj.start.tolist(),
            "range": traj.range_.tolist(),
            "directions": traj.directions.astype(int).tolist(),
            "interval": traj.interval,
        }
    if isinstance(traj, Fourier):
        return {
            "kind": "fourier",
            "q0": traj.q0.tolist(),
            "a": traj.a.tolist(),
            "b": traj.b.tolist(),
            "omega_f": traj.omega_f,
            "n_h": traj.n_h,
            "duration": traj.duration,
        }
    if isinstance(traj, Stacked):
        return {"kind": "stacked", "parts": [_traj_to_dict(p) for p in traj.parts]}
    raise InputError(f"save_trajectory: cannot write a {type(traj).__name__}")


def _traj_from_dict(d: dict, where: str):
    kind = d.get("kind")
    try:
        if kind == "cycloidal":
            return Cycloidal(d["start"], d["range"], d["directions"], interval=d["interval"])
        if kind == "fourier":
            return Fourier(d["a"], d["b"], d["q0"], omega_f=d["omega_f"], n_h=d["n_h"])
        if kind == "stacked":
            return Stacked(*[_traj_from_dict(p, where) for p in d["parts"]])
    except KeyError as e:
        raise InputError(f"{where}: missing field {e} in a {kind} trajectory") from None
    raise InputError(f"{where}: unknown trajectory kind {kind!r} (expected 'cycloidal', 'fourier' or 'stacked')")


def load_trajectory(spec):
    """(trajectory, joint names) from a file written by `save_trajectory` / `freefloat excite`, or from a built-in
    trajectory by name (`freefloat.data`, e.g. "naveen_exciting_trajectory"; earlier names are aliases)."""
    from . import data

    p = Path(spec)
    if not p.is_file():
        if not data.exists("trajectories", str(spec)):
            raise InputError(
                f"'{spec}' is neither a file nor a built-in trajectory "
                f"(built-in: {', '.join(data.names('trajectories'))})"
            )
        with data.path("trajectories", str(spec)) as shipped:
            return load_trajectory(shipped)
    try:
        d = json.loads(p.read_text())
    except (OSError, json.JSONDecodeError) as e:
        raise InputError(f"{p}: not a readable trajectory file ({e})") from None
    traj = _traj_from_dict(d, str(p))
    joints = d.get("joints")
    if not isinstance(joints, list) or len(joints) != traj.n:
        raise InputError(f"{p}: 'joints' must list {traj.n} joint names, one per trajectory column")
    return traj, joints

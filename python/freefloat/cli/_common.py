"""Helpers shared by the command modules: model and vector arguments, torque options, progress bars, and the
run summary (from `freefloat.io.results`)."""

from __future__ import annotations

from pathlib import Path

import click
import numpy as np

from .. import models
from ..io.results import out_paths, summarize, summary_text, write_run
from ..model import Model

__all__ = [
    "MODEL_HELP",
    "load_model",
    "out_paths",
    "parse_vector",
    "print_summary",
    "sine_torques",
    "summarize",
    "torque_options",
    "tqdm_bar",
    "write_outputs",
]

MODEL_HELP = "a built-in robot name (see `freefloat models`) or a .yaml / .urdf / MJCF (.xml) file"


def tqdm_bar(total: int, desc: str):
    from tqdm.auto import tqdm

    return tqdm(total=total, desc=desc, leave=False)


def torque_options(m: Model, torques: str, amplitude: float) -> dict:
    """`simulate` keyword arguments for the --torques option: 'zero', 'sine' or a .npy/.csv table (T, nv)."""
    if torques == "zero":
        return {}
    if torques == "sine":
        return {"torques": sine_torques(m, amplitude)}
    p = Path(torques)
    table = np.load(p) if p.suffix == ".npy" else np.loadtxt(p, delimiter=",", ndmin=2)
    return {"torques": table, "hold": "zoh"}


def load_model(spec: str, base: str = "free") -> Model:
    """A built-in name (or an earlier alias of one), or a path to a YAML, URDF or MJCF (.xml, .mjcf) file."""
    p = Path(spec)
    if not p.suffix and models.is_builtin(spec):
        return models.load(spec)
    if p.suffix.lower() in (".yaml", ".yml"):
        return Model.from_yaml(p)
    if p.suffix.lower() == ".urdf":
        return Model.from_urdf(p, base=base)
    if p.suffix.lower() in (".xml", ".mjcf"):
        return Model.from_mjcf(p)
    raise click.BadParameter(
        f"'{spec}' is neither a built-in robot ({', '.join(models.names())}) nor a .yaml/.urdf/.xml (MJCF) file",
        param_hint="MODEL",
    )


def parse_vector(text: str | None, n: int, name: str, default: np.ndarray) -> np.ndarray:
    if text is None:
        return default
    try:
        x = np.array([float(s) for s in text.replace(",", " ").split()])
    except ValueError:
        raise click.BadParameter(f"expected {n} numbers separated by commas", param_hint=name) from None
    if x.shape != (n,):
        raise click.BadParameter(f"expected {n} numbers, got {x.size}", param_hint=name)
    return x


def sine_torques(model: Model, amplitude: float):
    """Smooth internal torques on every non-base joint: amplitude·sin(2π f_j t + φ_j)."""
    nb = model.nvs[0]
    n = model.nv - nb
    f = 0.2 + 0.05 * np.arange(n)
    phi = np.arange(n, dtype=float)

    def torques(t, q, v):
        out = np.zeros(model.nv)
        out[nb:] = amplitude * np.sin(2 * np.pi * f * t + phi)
        return out

    return torques


def print_summary(title: str, s: dict) -> None:
    click.echo(summary_text(title, s))


def write_outputs(traj, summary, out, stem, title):
    written = write_run(traj, summary, out, stem, title)
    if written:
        click.echo(f"  wrote {', '.join(map(str, written))}")

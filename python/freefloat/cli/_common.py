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
    "debug_enabled",
    "report_error",
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


def debug_enabled(ctx: click.Context | None = None) -> bool:
    """Whether `--debug` (or FREEFLOAT_DEBUG=1) asked for tracebacks."""
    import os

    ctx = ctx or click.get_current_context(silent=True)
    root = ctx.find_root() if ctx is not None else None
    if root is not None and isinstance(root.obj, dict) and root.obj.get("debug"):
        return True
    return os.environ.get("FREEFLOAT_DEBUG", "").lower() in ("1", "true", "yes")


def _where(e: BaseException) -> str:
    """The innermost frame of freefloat's own code (file:line) where an unexpected exception came from."""
    import traceback

    frames = [f for f in traceback.extract_tb(e.__traceback__) if "freefloat" in f.filename]
    if not frames:
        return ""
    f = frames[-1]
    return f" in {Path(f.filename).name}:{f.lineno}"


def report_error(e: BaseException) -> int:
    """Print `e` as one line on stderr and return the exit code: 2 for a refused input (freefloat's errors, a
    file that cannot be read), 3 for anything unexpected (a bug: the line says so and how to get the traceback)."""
    from .. import _core

    if isinstance(e, (_core.InputError, _core.ModelError, _core.NumericalError)):
        msg, code = str(e), 2
    elif isinstance(e, UnicodeDecodeError):
        msg, code = f"not UTF-8 text (byte {e.start}: {e.reason}); save the file as UTF-8", 2
    elif isinstance(e, OSError) and e.filename is not None:
        msg, code = f"{e.filename}: {e.strerror or e}", 2
    elif isinstance(e, MemoryError):
        msg, code = "out of memory (the run or model is too large for this machine)", 2
    else:
        kind = type(e).__name__
        text = str(e).strip().splitlines()[0] if str(e).strip() else ""
        msg = (
            f"internal error{_where(e)}: {kind}{': ' + text if text else ''} "
            "(this is a bug in freefloat: please report it with the output of `freefloat --debug ...`)"
        )
        code = 3
    msg = " ".join(line.strip() for line in msg.splitlines() if line.strip())  # one line, whatever the source
    click.echo(f"error: {msg}", err=True)
    return code


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

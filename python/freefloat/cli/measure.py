"""`freefloat measure`: a simulated run turned into sensor telemetry (gyro, star tracker, encoders, tachometers,
base velocity/position, force/torque) that `freefloat identify` reads."""

from __future__ import annotations

from pathlib import Path

import click

from .._core import InputError
from ._common import load_model


def _load_run(path: Path):
    """A Trajectory from a run directory (DIR/trajectory.parquet of `freefloat simulate --out DIR`) or a
    trajectory .parquet file."""
    from ..simulation import Trajectory

    p = path / "trajectory.parquet" if path.is_dir() else path
    if not p.exists():
        raise click.BadParameter(
            f"{path}: no trajectory here (expected a directory from `freefloat simulate --out DIR`, holding "
            "trajectory.parquet, or a trajectory .parquet file)",
            param_hint="RUN",
        )
    if p.suffix.lower() not in (".parquet", ".pq"):
        raise click.BadParameter(f"{p}: a trajectory must be a .parquet file written by `freefloat simulate`")
    return Trajectory.from_parquet(p)


@click.command("measure", context_settings={"help_option_names": ["-h", "--help"]})
@click.argument("run", type=click.Path(path_type=Path))
@click.option(
    "--sensors",
    "sensors_spec",
    required=True,
    help="A preset name or a sensors file. Presets by hardware class, each a gyro, base velocity, joint "
    "tachometers and encoders at 100 Hz with datasheet figures: mems (industrial MEMS IMU, ADIS16470 class), "
    "tactical (tactical fibre-optic gyro, KVH DSP-1750 class), navigation (navigation-grade IMU, Honeywell HG9900 "
    "class); and naveen (Naveen, Shah, Misra's white rate noise at every sample of the run). A sensors file is "
    "YAML or JSON: a `sensors:` list, each entry with `type:` gyro, star_tracker, encoder, tachometer, "
    "base_velocity, base_position or force_torque, its `rate:` [Hz], `latency:` [s] and error parameters, "
    "optionally `telemetry: {poses: integrate|measured, rate: Hz}`; or `preset: tactical` (or "
    "`preset: {name: tactical, rate: 50}`) plus more `sensors:`. Numbers and sources: docs/sensors.md.",
)
@click.option("--out", required=True, type=click.Path(path_type=Path), help="Directory for the telemetry files.")
@click.option("--seed", type=int, default=0, show_default=True, help="Seed of the sensors' random errors.")
@click.option(
    "--model",
    "model_spec",
    help="The run's model (built-in name or file) when the trajectory file's metadata does not name a built-in.",
)
def measure_cmd(run, sensors_spec, out, seed, model_spec):
    """Sample the simulated RUN with a set of sensors and write the telemetry they would send down.

    RUN is a directory written by `freefloat simulate MODEL --out DIR` (it reads DIR/trajectory.parquet) or a
    trajectory .parquet file. Every sensor samples the run at its own rate and adds its errors (bias, noise,
    quantisation, latency; models and units in docs/sensors.md). A sensor's period must be a whole number of the
    run's sample spacing (record every step, or choose rates that divide the run's rate); nothing is
    interpolated.

    Writes OUT/telemetry.csv (read by `freefloat identify minimal MODEL --data OUT/telemetry.csv`; it declares
    the rate sensors' white noise, so the errors-in-variables bias removal is applied), OUT/sensor_<name>.csv
    (each sensor's own samples, force/torque included) and OUT/results.json.

    Example:  freefloat simulate naveen_dual_arm --t-final 20 --out run &&
    freefloat measure run --sensors tactical --out telem"""
    from .. import sensors as sn

    traj = _load_run(run)
    if model_spec:
        m = load_model(model_spec)
    elif traj.model_name:
        try:
            m = load_model(traj.model_name)
        except click.BadParameter:
            raise click.BadParameter(
                f"the trajectory's model '{traj.model_name}' is not a built-in robot; name its file with --model",
                param_hint="--model",
            ) from None
    else:
        raise click.BadParameter("the trajectory file does not name its model; give --model", param_hint="--model")
    try:
        sset = sn.load(sensors_spec)
    except FileNotFoundError as e:
        raise click.BadParameter(str(e), param_hint="--sensors") from None
    if m.nq != traj.q.shape[1] or m.nv != traj.v.shape[1]:
        raise InputError(
            f"model '{m.name}' has nq = {m.nq}, nv = {m.nv}; the trajectory has {traj.q.shape[1]} and "
            f"{traj.v.shape[1]} columns (wrong --model?)"
        )
    meas = sn.measure(m, traj, sset, seed=seed)
    tel = meas.telemetry
    if tel is None:
        click.echo(f"{m.name}: {len(traj.t)} run samples, seed {seed}; no telemetry table: {meas.why_no_telemetry}")
    else:
        click.echo(
            f"{m.name}: {len(traj.t)} run samples -> {len(tel.t)} telemetry samples "
            f"({tel.t[0]:.6g} .. {tel.t[-1]:.6g} s), seed {seed}"
        )
    for name, s in meas.streams.items():
        click.echo(f"  {name:16s} {1.0 / s.period:10.6g} Hz  {len(s.t):8d} samples  {len(s.columns)} columns")
    if tel is not None and tel.rate_noise is not None:
        click.echo("  declared white rate noise (for identification): " + ", ".join(f"{x:.3g}" for x in tel.rate_noise))
    written = meas.write(out)
    click.echo(f"  wrote {', '.join(map(str, written))}")

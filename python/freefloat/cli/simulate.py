"""`freefloat simulate`: simulate a robot and report conservation."""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import click
import numpy as np

from .._core import InputError, Interrupted
from ..simulation import simulate
from ..simulation.environment import load_environment
from ._common import load_model, out_paths, parse_vector, print_summary, summarize, torque_options, write_outputs


@click.command("simulate")
@click.argument("model")
@click.option(
    "--base",
    type=click.Choice(["free", "planar", "fixed"]),
    default="free",
    show_default=True,
    help="Base joint for a URDF model (built-in robots and YAML/MJCF files declare their own base joint).",
)
@click.option("--t-final", type=float, default=10.0, show_default=True, help="Simulated time [s].")
@click.option("--dt", type=float, default=1e-3, show_default=True, help="RK4 step, or RK45 output interval [s].")
@click.option(
    "--method",
    type=click.Choice(["rk4", "rk45"]),
    default="rk4",
    show_default=True,
    help="Fixed-step RK4 or adaptive Dormand-Prince 5(4).",
)
@click.option("--rtol", type=float, default=1e-9, show_default=True, help="RK45 relative tolerance.")
@click.option("--atol", type=float, default=1e-12, show_default=True, help="RK45 absolute tolerance.")
@click.option(
    "--torques",
    default="sine",
    show_default=True,
    help="'zero', 'sine' (smooth internal joint torques), or a .npy/.csv file of shape (T, nv) sampled every --dt.",
)
@click.option("--amplitude", type=float, default=5.0, show_default=True, help="Amplitude of the 'sine' torques [N m].")
@click.option("--q0", help="Initial configuration, nq comma-separated numbers (default: neutral).")
@click.option("--v0", help="Initial velocity, nv comma-separated numbers (default: zero).")
@click.option("--record-every", type=int, default=10, show_default=True, help="RK4: keep every n-th step.")
@click.option(
    "--formulation",
    type=click.Choice(["aba", "dq"]),
    default="aba",
    show_default=True,
    help="Dynamics: the engine's ABA, or the dual-quaternion Newton-Euler system (Valverde 2018 ch. 6).",
)
@click.option(
    "--actuators",
    "actuators_file",
    type=click.Path(dir_okay=False),
    help="YAML file with an `actuators:` block (wheels on revolute joints, thrusters, propellant tanks; see "
    "docs/actuators.md). The model's joint limits (effort, velocity) apply with or without it.",
)
@click.option(
    "--input-timing",
    type=click.Choice(["step", "stage"]),
    default=None,
    help="Read --torques once per step and hold it (step), or at every Runge-Kutta stage (stage). Default: step "
    "for a table file, stage for the built-in torque functions (sine).",
)
@click.option(
    "--environment",
    "environment_file",
    type=click.Path(exists=True, dir_okay=False),
    help="A YAML file with an `environment:` block (orbit, gravity_gradient, j2, disturbance; or a scenario file "
    "holding one): the robot then orbits a central body and feels its gravity gradient.",
)
@click.option(
    "--out",
    help="FILE.parquet or FILE.csv (plus FILE.results.json and FILE.png beside it), or a directory (gets "
    "trajectory.parquet, results.json, trajectory.png). Every file written is listed. After Ctrl-C the part "
    "simulated so far is written there.",
)
@click.option(
    "--max-memory",
    type=float,
    default=None,
    help="Largest recording to hold in memory [GB] (default: half the memory available). Longer runs are refused "
    "before they start; record fewer samples with --record-every.",
)
def simulate_cmd(
    model,
    base,
    t_final,
    dt,
    method,
    rtol,
    atol,
    torques,
    amplitude,
    q0,
    v0,
    record_every,
    formulation,
    actuators_file,
    input_timing,
    environment_file,
    out,
    max_memory,
):
    """Simulate MODEL (a built-in name or a .yaml/.urdf file) and report conservation. MODEL may also be a
    scenario file of `kind: simulate` (robot, duration, dt, initial state, torques and the `actuators:`,
    `environment:`, `sensors:` blocks; see docs/scenarios.md): its keys then replace the options.

    The robot floats freely; joints are driven by --torques. The summary gives the drift of total
    linear and angular momentum (conserved with internal torques only) and the difference between
    the change of kinetic energy and the work done, both of which measure integration error.

    Ctrl-C stops the run within a fraction of a second; with --out the part simulated so far is written
    (and results.json says the run was interrupted)."""
    if _is_simulate_scenario(model):
        return _run_scenario(click.get_current_context(), model, out)
    m = load_model(model, base)
    _check_base(click.get_current_context(), model, base, m)
    q = parse_vector(q0, m.nq, "--q0", m.neutral())
    v = parse_vector(v0, m.nv, "--v0", np.zeros(m.nv))
    kw = torque_options(m, torques, amplitude)
    if environment_file:
        kw["environment"] = load_environment(environment_file)
    if actuators_file:
        kw["actuators"] = read_actuators(actuators_file)
    if out:
        # check --out now, and load the file writer before the run, so that a Ctrl-C is answered at once
        pq, _, _ = out_paths(out, "trajectory")
        if pq.suffix.lower() != ".csv":
            import pyarrow.parquet  # noqa: F401
    t0 = time.perf_counter()
    try:
        traj = simulate(
            m,
            q,
            v,
            t_final,
            dt,
            method=method,
            rtol=rtol,
            atol=atol,
            record_every=record_every,
            progress=True,
            formulation=formulation,
            input_timing=input_timing,
            # interactive runs stop on Ctrl-C: no step limit, only the memory check
            max_steps=2**62,
            max_memory=None if max_memory is None else max_memory * 1e9,
            **kw,
        )
    except Interrupted as e:
        _save_partial(e, m, out, time.perf_counter() - t0)
        sys.exit(130)
    except InputError as e:
        if "max_memory" in str(e):  # name the options, not the Python arguments
            raise InputError(f"{e} (options --record-every, --dt, --t-final, --max-memory GB)") from None
        raise
    s = summarize(traj, time.perf_counter() - t0)
    s["model"] = m.name
    print_summary(f"{m.name}: {t_final} s, {method}, {formulation}", s)
    warn = traj.integration_warning()
    if warn:
        click.echo(f"warning: {warn}", err=True)
        s["integration_warning"] = warn
    write_outputs(traj, s, out, "trajectory", f"{m.name}: conservation")


def _is_simulate_scenario(spec: str) -> bool:
    """A YAML file whose top-level `kind` is `simulate`, or a built-in scenario of that kind."""
    import yaml

    from ..io import data

    p = Path(spec)
    if not p.suffix:
        return not models_is_builtin(spec) and data.exists("scenarios", spec)
    if p.suffix.lower() not in (".yaml", ".yml") or not p.is_file():
        return False
    try:
        d = yaml.safe_load(p.read_text(encoding="utf-8"))
    except (yaml.YAMLError, UnicodeDecodeError):
        return False  # the model reader says what is wrong
    return isinstance(d, dict) and d.get("kind") == "simulate"


def models_is_builtin(name: str) -> bool:
    from .. import models

    return models.is_builtin(name)


# the options a scenario file replaces: given with one, they are an error rather than silently overridden
_SCENARIO_KEYS = {
    "base": "model",
    "t_final": "duration",
    "dt": "dt",
    "method": "method",
    "rtol": "rtol",
    "atol": "atol",
    "torques": "torques",
    "amplitude": "torques",
    "q0": "initial.q",
    "v0": "initial.v",
    "record_every": "record_every",
    "formulation": "formulation",
    "actuators_file": "actuators",
    "input_timing": "input_timing",
    "environment_file": "environment",
}


def _run_scenario(ctx, spec: str, out) -> None:
    from ..simulation.scenario import load, run

    for opt, key in _SCENARIO_KEYS.items():
        if ctx.get_parameter_source(opt) not in (None, click.core.ParameterSource.DEFAULT):
            flag = "--" + opt.replace("_file", "").replace("_", "-")
            raise click.BadParameter(
                f"{spec} is a simulate scenario: set '{key}' in the file instead of {flag}", param_hint=flag
            )
    sc = load(spec)
    if out:
        pq, _, _ = out_paths(out, "trajectory")
        if pq.suffix.lower() != ".csv":
            import pyarrow.parquet  # noqa: F401
    t0 = time.perf_counter()
    try:
        r = run(sc, progress=True, max_steps=2**62)
    except Interrupted as e:
        _save_partial(e, sc.model, out, time.perf_counter() - t0)
        sys.exit(130)
    traj = r.trajectory
    s = summarize(traj, time.perf_counter() - t0)
    s["model"] = sc.model.name
    s["scenario"] = sc.name
    print_summary(f"{sc.name} ({sc.model.name}): {sc.duration} s, {sc.method}, {sc.formulation}", s)
    warn = traj.integration_warning()
    if warn:
        click.echo(f"warning: {warn}", err=True)
        s["integration_warning"] = warn
    if r.measurement is not None:
        s["measurement"] = r.measurement.summary()
        for name, st in r.measurement.streams.items():
            click.echo(f"  sensor {name:16s} {1.0 / st.period:10.6g} Hz  {len(st.t):8d} samples")
    write_outputs(traj, s, out, "trajectory", f"{sc.name}: conservation")
    if r.measurement is not None and out:
        # beside the trajectory, in a folder of its own (the measurement writes its own results.json)
        pq, _, _ = out_paths(out, "trajectory")
        tel_dir = pq.parent / "telemetry" if pq.parent == Path(out) else pq.parent / (pq.stem + "_telemetry")
        written = r.measurement.write(tel_dir)
        click.echo(f"  wrote {', '.join(map(str, written))}")


def read_actuators(path):
    """The `actuators:` block of a YAML file (or the whole file if it is the block itself) as an Actuators."""
    import yaml

    from ..simulation.actuators import Actuators

    p = Path(path)
    if not p.exists():
        raise InputError(f"--actuators: file not found: {p}")
    try:
        d = yaml.safe_load(p.read_text())
    except yaml.YAMLError as e:
        raise InputError(f"{p}: not valid YAML: {e}") from None
    if isinstance(d, dict) and "actuators" in d:
        d = d["actuators"]
    return Actuators.from_dict(d, where=f"{p}: actuators")


def _check_base(ctx, spec: str, base: str, m) -> None:
    """--base chooses the base joint of a URDF file only; given for another model it is an error, not ignored."""
    explicit = ctx.get_parameter_source("base") not in (None, click.core.ParameterSource.DEFAULT)
    if not explicit or Path(spec).suffix.lower() == ".urdf":
        return
    own = m.joint_types[0]
    if base == own:
        return
    raise click.BadParameter(
        f"'{spec}' declares its own base joint ('{own}'); --base {base} applies to URDF files only. To simulate it "
        f"with a {base} base, save its description (`freefloat models --show {spec} > robot.yaml` for a built-in "
        f"robot), change the root body's joint to {base}, and simulate that file",
        param_hint="--base",
    )


def _save_partial(e: Interrupted, m, out, elapsed: float) -> None:
    """After Ctrl-C: say where the run stopped and write the part simulated so far when --out was given."""
    traj = getattr(e, "partial", None)
    if traj is None or len(traj) == 0:
        click.echo(f"interrupted: {e}; nothing was recorded", err=True)
        return
    click.echo(
        f"interrupted: {e}; {len(traj)} samples recorded, t = {traj.t[0]:g} .. {traj.t[-1]:g} s",
        err=True,
    )
    if not out:
        click.echo("  (give --out to keep the part simulated so far)", err=True)
        return
    s = summarize(traj, elapsed)
    s["model"] = m.name
    s["interrupted"] = str(e)
    s["t_end"] = float(traj.t[-1])
    # the trajectory and results.json only: the figure (matplotlib) would delay the exit by seconds
    pq, js, _ = out_paths(out, "trajectory")
    traj.to_csv(pq) if pq.suffix.lower() == ".csv" else traj.to_parquet(pq)
    js.write_text(json.dumps(s, indent=2))
    click.echo(f"  wrote {pq}, {js} (the part simulated before the interrupt; no figure)", err=True)

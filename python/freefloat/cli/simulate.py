"""`freefloat simulate`: simulate a robot and report conservation."""

from __future__ import annotations

import time

import click
import numpy as np

from ..environment import load_environment
from ..simulation import simulate
from ._common import load_model, parse_vector, print_summary, summarize, torque_options, write_outputs


@click.command("simulate")
@click.argument("model")
@click.option(
    "--base",
    type=click.Choice(["free", "planar", "fixed"]),
    default="free",
    show_default=True,
    help="Base joint for a URDF model.",
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
    "--environment",
    "environment_file",
    type=click.Path(exists=True, dir_okay=False),
    help="A YAML file with an `environment:` block (orbit, gravity_gradient, j2, disturbance; or a scenario file "
    "holding one): the robot then orbits a central body and feels its gravity gradient.",
)
@click.option(
    "--out",
    help="FILE.parquet or FILE.csv (plus FILE.results.json and FILE.png beside it), or a directory (gets "
    "trajectory.parquet, results.json, trajectory.png). Every file written is listed.",
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
    environment_file,
    out,
):
    """Simulate MODEL (a built-in name or a .yaml/.urdf file) and report conservation.

    The robot floats freely; joints are driven by --torques. The summary gives the drift of total
    linear and angular momentum (conserved with internal torques only) and the difference between
    the change of kinetic energy and the work done, both of which measure integration error."""
    m = load_model(model, base)
    q = parse_vector(q0, m.nq, "--q0", m.neutral())
    v = parse_vector(v0, m.nv, "--v0", np.zeros(m.nv))
    kw = torque_options(m, torques, amplitude)
    if environment_file:
        kw["environment"] = load_environment(environment_file)
    t0 = time.perf_counter()
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
        **kw,
    )
    s = summarize(traj, time.perf_counter() - t0)
    s["model"] = m.name
    print_summary(f"{m.name}: {t_final} s, {method}, {formulation}", s)
    warn = traj.integration_warning()
    if warn:
        click.echo(f"warning: {warn}", err=True)
        s["integration_warning"] = warn
    write_outputs(traj, s, out, "trajectory", f"{m.name}: conservation")

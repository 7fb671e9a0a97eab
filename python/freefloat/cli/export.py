"""`freefloat export`: write a robot model for another tool (MuJoCo MJCF, URDF)."""

from __future__ import annotations

from pathlib import Path

import click

from ._common import load_model


@click.command("export", context_settings={"help_option_names": ["-h", "--help"]})
@click.argument("model")
@click.option("--mjcf", "mjcf_path", type=click.Path(dir_okay=False), help="Write MuJoCo MJCF (XML) to this file.")
@click.option("--urdf", "urdf_path", type=click.Path(dir_okay=False), help="Write URDF to this file.")
@click.option(
    "--gravity/--no-gravity",
    default=False,
    show_default=True,
    help="MJCF: write the model's gravity (default zero gravity: an orbiting robot).",
)
def export_cmd(model, mjcf_path, urdf_path, gravity):
    """Write MODEL (a built-in robot name, or a .yaml / .urdf / MJCF .xml file) for another simulator.

    MJCF: the base gets a free joint, inertias are written at full precision as centre of mass + full inertia
    about it, the compiler neither fuses static bodies nor recomputes or balances inertias, gravity is zero
    unless --gravity, the integrator RK4 with a 1 ms step, each 1-DoF joint a motor (ctrl = joint torque),
    frames become sites, body tags are kept. Read the MuJoCo states back with `freefloat convert --from mujoco`.

    Example: freefloat export naveen_dual_arm_consistent --mjcf robot.xml"""
    if not mjcf_path and not urdf_path:
        raise click.UsageError("give --mjcf FILE and/or --urdf FILE")
    m = load_model(model)
    written = []
    if mjcf_path:
        m.to_mjcf(mjcf_path, gravity=gravity)
        written.append(mjcf_path)
    if urdf_path:
        m.to_urdf(urdf_path)
        written.append(urdf_path)
    click.echo(f"{m}\nwrote {', '.join(str(Path(w)) for w in written)}")

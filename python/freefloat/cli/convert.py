"""`freefloat convert`: telemetry from another tool's recorded states, in freefloat's conventions."""

from __future__ import annotations

from pathlib import Path

import click

from ._common import MODEL_HELP, load_model


@click.command("convert", context_settings={"help_option_names": ["-h", "--help"]})
@click.argument("states", type=click.Path(dir_okay=False))
@click.option("--from", "source", type=click.Choice(["mujoco"]), required=True, help="Where STATES come from (MuJoCo).")
@click.option("--model", "model_spec", required=True, help="The robot: " + MODEL_HELP + ".")
@click.option(
    "--mjcf",
    "mjcf_path",
    type=click.Path(dir_okay=False),
    help="The MJCF file MuJoCo simulated, when it is not MODEL itself (default: MODEL if it is an .xml file, "
    "else MODEL's own export, as `freefloat export --mjcf` writes it).",
)
@click.option(
    "--out",
    required=True,
    type=click.Path(dir_okay=False),
    help="Telemetry file to write: .parquet (or .pq), or .csv.",
)
def convert_cmd(states, source, model_spec, mjcf_path, out):
    """Convert STATES (an .npz with arrays t, qpos, qvel recorded from MuJoCo's MjData, one row per sample)
    to a freefloat telemetry file for `freefloat identify minimal MODEL --data OUT`.

    Joints are matched by name. Per joint: the free joint's quaternion goes from w, x, y, z to x, y, z, w and
    its linear velocity from the world frame to the base frame (MuJoCo's angular velocity is already in the
    base frame); ball-joint quaternions are reordered; hinge and slide coordinates are measured from the
    joint's `ref`. The converted data are then checked: the model's momentum must fit them (convention check).

    Example: freefloat convert --from mujoco states.npz --model robot.xml --out telemetry.parquet"""
    from ..identification.conventions import check_conventions
    from ..identification.minimal import minimal_parameters
    from ..io.mujoco import telemetry_from_states_file

    m = load_model(model_spec)
    mj = mjcf_path or (model_spec if Path(model_spec).suffix.lower() in (".xml", ".mjcf") else None)
    telem = telemetry_from_states_file(m, states, mj)
    o = Path(out)
    o.parent.mkdir(parents=True, exist_ok=True)
    if o.suffix.lower() in (".parquet", ".pq"):
        telem.to_parquet(o)
    else:
        telem.to_csv(o)
    click.echo(f"{len(telem)} samples, t = {telem.t[0]:g} .. {telem.t[-1]:g} s, model {m.name} (nq={m.nq}, nv={m.nv})")
    try:
        import numpy as np

        rep = check_conventions(minimal_parameters(m, "numeric"), telem.q, telem.v, np.zeros((len(telem), 6)))
        click.echo(rep.message() + " (assuming zero total momentum)")
    except Exception as e:  # the check is advice here; identification runs it again with the user's options
        click.echo(f"(convention check skipped: {e})")
    click.echo(f"wrote {o}")

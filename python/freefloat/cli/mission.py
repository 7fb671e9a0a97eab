"""`freefloat mission`: capture a target, identify it online, berth it with the estimate."""

from __future__ import annotations

import sys

import click

from .._core import Interrupted


@click.command("mission")
@click.argument("mission", required=False)
@click.option("--out", type=click.Path(file_okay=False), help="Directory for results.json, table.txt and the figure.")
@click.option("--seed", type=int, default=0, show_default=True, help="Seed of the sensors' random streams.")
@click.option(
    "--controller",
    type=click.Choice(["policy", "mpc"]),
    help="Berth controller: the DDP policy (feed-forward + Riccati gains, the default) or receding-horizon DDP.",
)
@click.option("--list", "list_", is_flag=True, help="List the built-in missions and exit.")
def mission_cmd(mission, out, seed, controller, list_):
    """Run a capture mission end to end on one engine.

    MISSION is a built-in name (`freefloat mission --list`) or a YAML file (`kind: mission`). Three phases:

    \b
    1. capture: the grasp of a drifting, tumbling target as an inelastic impact
       (momentum conserved; the grasp impulse is reported);
    2. detumble + identify: Zhang, Yue, Yuan 2020's post-capture controllers damp the stack while the
       standard-parameter RLS identifies base and target from the telemetry; the model is handed over
       when its covariance and its drift over a trailing window are within the mission's tolerances;
    3. berth: DDP (Valverde 2018, ch. 8) brings the target to its berth pose, optimised on the nominal
       model (target guessed), on the identified one and on the truth, each run on the true plant.

    Prints the comparison (pose error, settling time, thrust impulse and propellant, peak base rate, wheel
    momentum); --out also writes results.json (every number), table.txt and mission_timeline.png.
    Ctrl-C keeps the phases done."""
    from .. import mission as fm

    if list_ or not mission:
        for name, desc in fm.list_missions():
            click.echo(f"{name}\n    {desc}")
        if not list_:
            click.echo("\ngive a mission name or file: freefloat mission NAME [--out DIR]")
        return
    m = fm.load_mission(mission)
    try:
        res = fm.run(m, seed=seed, controller=controller, progress=lambda s: click.echo(s, err=True))
    except Interrupted as e:
        part = getattr(e, "partial", None)
        click.echo(f"interrupted: {e}", err=True)
        if part is not None and out:
            fm.write(part, out)
            click.echo(f"kept the phases done in {out}", err=True)
        sys.exit(130)
    click.echo(fm.table(res), nl=False)
    if out:
        files = fm.write(res, out)
        click.echo(f"wrote {', '.join(str(f) for f in files)}")

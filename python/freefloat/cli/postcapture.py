"""`freefloat identify postcapture` and `freefloat scenarios` (Zhang, Yue, Yuan 2020)."""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import click

from .._core import Interrupted


@click.command("postcapture")
@click.argument("scenario")
@click.option("--out", help="Directory for results.json, table.txt and the figures.")
@click.option(
    "--noise/--no-noise",
    default=None,
    help="Force measurement noise on (the scenario's `noise`, or the default study levels) or off.",
)
@click.option(
    "--seed",
    type=int,
    default=0,
    show_default=True,
    help="Seed of the measurement noise (the `noise:` block, or the random streams of the `sensors:`).",
)
@click.option(
    "--sweep/--no-sweep",
    default=True,
    show_default=True,
    help="For a scenario with a `sweep` section: also run the initial-velocity sweep (Figs. 6-9).",
)
@click.option(
    "--forgetting",
    type=float,
    help="Forgetting factor of the standard-parameter RLS (default: the scenario's, 1 = none).",
)
@click.option(
    "--p0",
    type=float,
    help="Prior covariance P0 (times the identity) of all four estimators, i.e. how little the initial guesses are "
    "trusted: a ridge of weight 1/P0 pulls the estimate toward them (default: the scenario's, 1e6 as in the paper). "
    "Larger values (1e8-1e14) remove the guesses' bias from noise-free runs; docs/postcapture.md, Table 6.",
)
@click.option(
    "--project/--no-project",
    default=None,
    help="Report the standard-parameter estimate projected onto physically consistent parameters.",
)
@click.option(
    "--accelerations",
    type=click.Choice(["exact", "central_difference", "savgol", "rts"]),
    help="Accelerations for the force form: exact at the samples (default), central differences of the sampled "
    "velocities, their Savitzky-Golay derivative (measurement.savgol_window, savgol_polyorder in the scenario; "
    "default a cubic over 21 samples), or a Rauch-Tung-Striebel smoother of the rates whose bandwidth is set by "
    "generalised cross-validation from the noise in the record.",
)
@click.option(
    "--impulses",
    type=click.Choice(["simpson", "trapezoid"]),
    help="Thrust impulses for the momentum form: Simpson on the 1 kHz thrust (default) or trapezoid on the samples.",
)
@click.option(
    "--momentum-point",
    type=click.Choice(["base", "origin"]),
    help="Point the momentum form balances angular momentum about: the moving base point (default; robust when the "
    "system drifts and the attitude is integrated from a gyro) or the inertial origin (the paper's eqs. 9-10).",
)
def identify_postcapture_cmd(
    scenario, out, noise, seed, sweep, forgetting, p0, project, accelerations, impulses, momentum_point
):
    """Zhang, Yue, Yuan 2020: identify base and captured target online, in one step (momentum- and force-based).

    SCENARIO is a built-in name (`freefloat scenarios`) or a YAML file. Simulates the post-capture motion
    (RK4, 1 ms; eq. 40 momentum damping, eq. 39 attitude stabilisation by the arm), samples it at the
    scenario's rate and runs four online estimators: the paper's modified RLS and the ordinary RLS on
    standard parameters, each with the momentum and the force equations. Prints our final values and
    transit times beside the paper's; --out writes results.json, table.txt and the figures."""
    import time as _time

    from tqdm import tqdm

    from .. import postcapture as pc

    sc = pc.load_scenario(scenario)
    if noise is True and not sc.noise:
        sc.noise = dict(pc.DEFAULT_NOISE)
    elif noise is False:
        sc.noise = None
    if forgetting is not None:
        if not 0 < forgetting <= 1:
            raise click.BadParameter("must be in (0, 1]", param_hint="--forgetting")
        sc.forgetting = forgetting
    if p0 is not None:
        if not (math.isfinite(p0) and p0 > 0):
            raise click.BadParameter(f"must be a positive finite number, got {p0}", param_hint="--p0")
        sc.P0 = p0
    if project is not None:
        sc.project = project
    if accelerations:
        sc.measurement["accelerations"] = accelerations
    if impulses:
        sc.measurement["impulses"] = impulses
    if momentum_point:
        sc.measurement["momentum_point"] = momentum_point
    t0 = _time.perf_counter()
    try:
        with tqdm(total=2, desc=f"{sc.name}", unit="stage", leave=False) as bar:
            res = pc.run(sc, seed=seed, progress=lambda what: (bar.set_postfix_str(what), bar.update(1)))
    except Interrupted as e:  # Ctrl-C: keep the simulated part and the estimator histories up to the stop
        _save_partial(e, out)
        sys.exit(130)
    wall = _time.perf_counter() - t0
    click.echo(res.table())
    for w in res.warnings():  # also in results.json ("warnings")
        click.echo(f"warning: {w}", err=True)
    r = res.residuals
    click.echo(
        f"equations at the true parameters: momentum form max residual {r['momentum']['paper_angular']:.2e} "
        f"(rhs up to {r['momentum']['paper_angular_scale']:.2e}), force form {r['force']['paper_angular']:.2e} "
        f"(rhs up to {r['force']['paper_angular_scale']:.2e})"
    )
    ex = res.extra
    if "propellant" in ex:  # a scenario with thrusters and tanks (actuators: block)
        mb, pb = ex["mass_balance"], ex.get("momentum_balance", {})
        click.echo(
            f"propellant used {sum(ex['propellant']['used_kg']):.4g} kg; base mass change + propellant through the "
            f"nozzles = {mb['residual_kg']:.1e} kg"
            + (f"; momentum balance relative residual {pb['relative_residual']:.1e}" if pb else "")
        )
    click.echo(
        f"simulation + measurements + 4 estimators: {wall:.2f} s (simulation {res.timings['simulation']:.2f} s)"
        + (
            f"; noise {sc.noise}"
            if sc.noise
            else (f"; measured by the sensors {sc.sensors.names()}" if sc.sensors is not None else "; noise-free")
        )
        + (f"; measurement {sc.measurement}" if sc.measurement else "")
    )
    sw = None
    if sweep and sc.sweep:
        vels = sc.sweep["velocities"]
        try:
            with tqdm(total=len(vels), desc="velocity sweep", unit="run", leave=False) as bar:
                sw = pc.sweep(sc, progress=lambda k, n: bar.update(1))
        except KeyboardInterrupt:  # the main run is complete: keep it, without the sweep
            res.interrupted, res.t_end = "stopped in the velocity sweep (the main run is complete)", sc.duration
            _save_partial(Interrupted(res.interrupted), out, res)
            sys.exit(130)
        click.echo(pc.sweep_table(sw, paper=sc.paper_sweep))
    if out:
        path = res.save(out)
        if sw is not None:
            data = json.loads(path.read_text())
            data["velocity_sweep"] = sw
            path.write_text(json.dumps(data, indent=1))
            pc.plot_sweep(sw, Path(out))
        click.echo(f"wrote {path} and figures in {out}")


def _save_partial(e, out, res=None) -> None:
    """After Ctrl-C: say where the run stopped and, with --out, write what was finished (results.json with
    `interrupted: true`, table.txt, simulation.npz, histories.npz; no figures)."""
    res = getattr(e, "partial", None) if res is None else res
    click.echo(f"interrupted: {e}", err=True)
    if res is None:
        return
    if res.histories:
        click.echo(res.table())
    if not out:
        click.echo("  (give --out to keep the part simulated and the estimator histories)", err=True)
        return
    path = res.save(out)
    click.echo(f"  wrote {path}, table.txt, simulation.npz and histories.npz in {out} (no figures)", err=True)


@click.command("scenarios")
def scenarios_cmd():
    """List the built-in scenarios and shipped trajectories, one per line: name, what it reproduces, and the
    command that runs it.

    A scenario file (YAML; the built-in ones ship inside the package) says what to run: the robot, the initial
    state, the gains and the settings. Its `kind` key names the command that runs it (no `kind` means a
    post-capture identification scenario, Zhang, Yue, Yuan 2020). Copy one, edit it, and pass the file path
    instead of the name. The shipped joint trajectories (the exciting trajectory designed for Naveen, Shah,
    Misra's robot) are used with `freefloat identify minimal naveen_dual_arm --trajectory NAME`."""
    from ..io import data as shipped
    from ..io import scenario_files

    kind = None
    for s in scenario_files.listing():
        if s.kind != kind:
            kind = s.kind
            click.echo(f"# {scenario_files.KINDS[kind]} NAME --out DIR")
        click.echo(f"{s.name:<28} {s.description}")
    click.echo("# trajectories: freefloat identify minimal naveen_dual_arm --trajectory NAME")
    for name in shipped.names("trajectories"):
        click.echo(f"{name:<28} {_trajectory_summary(shipped, name)}")


def _trajectory_summary(shipped, name: str) -> str:
    import json

    d = json.loads(shipped.read_text("trajectories", name))
    return (
        f"joint trajectory ({d.get('kind', '?')}, {len(d.get('directions', []))} intervals, designed on "
        f"{d.get('model', '?')}): `identify minimal --trajectory {name}`"
    )

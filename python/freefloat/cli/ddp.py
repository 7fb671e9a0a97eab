"""`freefloat control ddp SCENARIO`: DDP end-effector control of a free-floating robot (Valverde 2018, ch. 8)."""

from __future__ import annotations

import json
from pathlib import Path

import click

from .._core import InputError


@click.command("ddp")
@click.argument("scenario")
@click.option("--out", type=click.Path(file_okay=False), help="Directory for results.json and the figures.")
@click.option(
    "--cost",
    type=click.Choice(["dq", "log"]),
    default=None,
    help="End-effector pose cost: 'dq' = the thesis' component-wise dual-quaternion difference (eq. 8.56), "
    "'log' = log-SE(3) as Crocoddyl uses. Default: the scenario's.",
)
@click.option("--max-iter", type=int, default=None, help="Maximum DDP iterations (default: the scenario's).")
@click.option("--no-schedule", is_flag=True, help="Constant End-column weights instead of the Table 8.2 schedule.")
@click.option("--no-keep-out", is_flag=True, help="Drop the soft keep-out term on the joints.")
@click.option(
    "--initial-controls",
    type=click.Choice(["zero", "gaussian"]),
    default=None,
    help="Initial control guess (default: the scenario's).",
)
@click.option(
    "--line-search",
    type=click.Choice(["scenario", "backtracking", "fixed"]),
    default="scenario",
    show_default=True,
    help="'backtracking' tries steps 1, 1/2, ..., 1/512 with the expected-improvement test; 'fixed' is the "
    "thesis' single step 0.1.",
)
@click.option("--variant", type=click.Choice(["ddp", "fddp"]), default=None, help="DDP or feasibility-driven DDP.")
@click.option("--no-plots", is_flag=True, help="Write results.json only.")
def ddp_cmd(scenario, out, cost, max_iter, no_schedule, no_keep_out, initial_controls, line_search, variant, no_plots):
    """Solve a DDP end-effector problem (Valverde 2018, ch. 8) on a built-in scenario or your own YAML file.

    Built-in: valverde_ch8_tracking (three-phase helicoidal reference, 640 steps of 0.05 s) and
    valverde_ch8_stabilisation (fixed pose of eq. 8.53, 1000 steps of 0.015 s). Progress is printed per iteration
    (cost, step length, regularisation); Ctrl-C stops and keeps the best iterate. With --out, results.json and the
    figures (poses in 3D, pose errors, base wrench, joint torques, cost per iteration) go to DIR.

    Note: until analytic dynamics derivatives land, the step Jacobians are central finite differences, so an
    iteration takes about a second or two."""
    from ..control import ddp

    try:
        prob = ddp.load_scenario(
            scenario,
            cost=cost,
            max_iter=max_iter,
            schedule=False if no_schedule else None,
            keep_out=False if no_keep_out else None,
            initial_controls=initial_controls,
        )
    except InputError as e:
        raise click.UsageError(str(e)) from None
    opts = {}
    if line_search == "backtracking":
        opts["alphas"] = [0.5**k for k in range(10)]
    elif line_search == "fixed":
        opts["alphas"] = [0.1]
    if variant:
        opts["variant"] = variant
    click.echo(
        f"{prob.name}: {prob.model.name}, N = {prob.horizon}, dt = {prob.dt} s, pose cost '{prob.cost_kind}', "
        f"up to {({**prob.options, **opts}).get('max_iter', 100)} iterations"
    )
    click.echo(f"{'iter':>5} {'cost':>16} {'step':>8} {'lambda':>9} {'expected':>11} {'gap':>9}")

    def progress(i):
        step = f"{i['alpha']:.4g}" if i["accepted"] else "reject"
        click.echo(
            f"{i['iter']:>5} {i['cost']:>16.8g} {step:>8} {i['lambda']:>9.2e} {i['expected']:>11.3e} {i['gap']:>9.1e}"
        )
        return True

    sol = ddp.solve(prob, progress=progress, **opts)
    res = ddp.results(prob, sol)
    res["timings"] = sol["timings"]
    click.echo(f"\nstopped: {res['stop_message']}")
    click.echo(
        f"  {res['iterations']} iterations, cost {res['initial_cost']:.6g} -> {res['final_cost']:.10g}, "
        f"{res['solve_time_s']:.2f} s ({1e3 * res['time_per_iteration_s']:.1f} ms per iteration)"
    )
    click.echo(
        f"  end effector over the final {res['final_hold_s']:.1f} s: position error <= "
        f"{1e3 * res['ee_position_error_final_hold_max_m']:.2f} mm, angle error <= "
        f"{res['ee_angle_error_final_hold_max_deg']:.4f} deg"
    )
    click.echo(
        f"  peak base force {res['base_force_peak_N']:.4g} N, peak base torque {res['base_torque_peak_Nm']:.4g} N m, "
        f"peak joint torque {res['joint_torque_peak_Nm']:.4g} N m"
    )
    if out:
        d = Path(out)
        d.mkdir(parents=True, exist_ok=True)
        (d / "results.json").write_text(json.dumps(res, indent=2))
        if not no_plots:
            from ..control.ddp_plots import plot_all

            paths = plot_all(prob, sol, d)
            click.echo(f"  wrote {d / 'results.json'} and {len(paths)} figures")
        else:
            click.echo(f"  wrote {d / 'results.json'}")

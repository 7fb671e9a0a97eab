"""`freefloat control ddp SCENARIO`: DDP end-effector control of a free-floating robot (Valverde 2018, ch. 8)."""

from __future__ import annotations

import json
import sys
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
@click.option(
    "--dq-sign",
    type=click.Choice(["nearest", "literal"]),
    default=None,
    help="How the 'dq' pose cost meets the reference's sign: 'nearest' compares with whichever of +q_D and -q_D is "
    "nearer (a pose metric); 'literal' is the thesis' q_G - q_D, which is largest at the exact pose once the "
    "quaternion has changed sign (a reference turning by 360 degrees does). Default: the scenario's.",
)
@click.option(
    "--wrist",
    type=click.Choice(["rate", "torque"]),
    default=None,
    help="'rate': the thesis' massless wrist, its Euler-angle rates being controls (eq. 8.51); 'torque': the "
    "model's wrist bodies (0.1 kg each) driven by joint torques. Default: the scenario's.",
)
@click.option(
    "--robot",
    default=None,
    help="Robot instead of the scenario's: a built-in name or a model file with the same joint and frame names, "
    "e.g. valverde_ch8_arm (the same arm on a 50 kg base; the built-in scenarios use valverde_ch8_servicer, "
    "1500 kg).",
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
@click.option(
    "--second-order",
    is_flag=True,
    help="Full DDP: add the second-order dynamics terms (eqs. 8.39-8.44) to the backward pass instead of iLQG's "
    "first-order model. Each iteration then costs about 2 (2 nv + nu) dynamics-derivative evaluations per node "
    "(on the chapter 8 tracking problem about 35x an iLQG iteration); see docs/ddp.md for when it pays.",
)
@click.option("--no-plots", is_flag=True, help="Write results.json only.")
@click.option(
    "--warm-start",
    is_flag=True,
    help="Start from the solution of an easier companion problem (same scenario with the log-SE(3) pose cost, "
    "constant End weights, no keep-out, backtracking line search), with whole joint turns made within one step "
    "removed (they put the dual quaternion on the opposite sign; docs/ddp.md), instead of the scenario's initial "
    "controls.",
)
@click.option(
    "--closed-loop",
    is_flag=True,
    help="After the solve, run the optimised policy (feed-forward + Riccati gains on the measured state) in the "
    "simulator with the true dynamics (RK4), next to the open-loop feed-forward, and report both.",
)
@click.option(
    "--mpc",
    is_flag=True,
    help="With --closed-loop: also run receding-horizon DDP (re-solve a window from the measured state every "
    "--replan steps, warm-started by the previous window shifted in time).",
)
@click.option("--horizon", type=int, default=100, show_default=True, help="MPC window, in DDP steps.")
@click.option("--replan", type=int, default=5, show_default=True, help="MPC re-plan period, in DDP steps.")
@click.option(
    "--mpc-iter", type=int, default=5, show_default=True, help="DDP iterations per MPC re-plan (warm-started)."
)
@click.option(
    "--model-error",
    type=float,
    default=0.0,
    show_default=True,
    help="Relative mass (and inertia) error of the simulated plant's --error-body against the model the "
    "controller was optimised on, e.g. 0.1 for +10 %.",
)
@click.option(
    "--error-body",
    default=None,
    help="Body whose mass is wrong in the plant (default: the last body with mass, the arm's last link with a "
    "rate-driven wrist).",
)
@click.option(
    "--substeps", type=int, default=5, show_default=True, help="Simulator RK4 steps per DDP step (closed loop)."
)
def ddp_cmd(
    scenario,
    out,
    cost,
    dq_sign,
    wrist,
    robot,
    max_iter,
    no_schedule,
    no_keep_out,
    initial_controls,
    line_search,
    variant,
    second_order,
    no_plots,
    warm_start,
    closed_loop,
    mpc,
    horizon,
    replan,
    mpc_iter,
    model_error,
    error_body,
    substeps,
):
    """Solve a DDP end-effector problem (Valverde 2018, ch. 8) on a built-in scenario or your own YAML file.

    Built-in: valverde_ch8_tracking (three-phase helicoidal reference, 640 steps of 0.05 s) and
    valverde_ch8_stabilisation (fixed pose of eq. 8.53, 1000 steps of 0.015 s), both with the thesis' settings and
    its massless wrist driven by Euler-angle rates, on a 1500 kg base; their defaults meet the thesis' acceptance
    figures (docs/ddp.md). --dq-sign literal, --wrist torque and --robot valverde_ch8_arm undo one choice each.
    Progress is printed per iteration
    (cost, step length, regularisation); Ctrl-C stops and keeps the best iterate. With --out, results.json and the
    figures (poses in 3D, pose errors, base wrench, joint torques, cost per iteration) go to DIR.

    With --closed-loop the optimised policy u = u_k + L_k (x - x_k) runs in the simulator (true continuous
    dynamics, RK4, optionally a plant with a --model-error mass error) next to the open-loop feed-forward, and with
    --mpc a receding-horizon DDP as well; results.json gets a `closed_loop` block and the figures
    closed_loop_errors.png and closed_loop_base_wrench.png.

    Example: freefloat control ddp valverde_ch8_tracking --cost log --no-schedule --line-search backtracking
    --closed-loop --mpc --horizon 100 --replan 5 --model-error 0.1 --out out/"""
    from ..control import ddp

    try:
        prob = ddp.load_scenario(
            scenario,
            cost=cost,
            max_iter=max_iter,
            schedule=False if no_schedule else None,
            keep_out=False if no_keep_out else None,
            initial_controls=initial_controls,
            wrist=wrist,
            dq_sign=dq_sign,
            robot=robot,
        )
    except InputError as e:
        raise click.UsageError(str(e)) from None
    if mpc and not closed_loop:
        raise click.UsageError("--mpc needs --closed-loop")
    if closed_loop:
        if horizon < 1 or replan < 1 or replan > horizon:
            raise click.UsageError(f"--replan must be between 1 and --horizon ({horizon}), got {replan}")
        if mpc_iter < 1 or substeps < 1:
            raise click.UsageError("--mpc-iter and --substeps must be at least 1")
        if not (model_error > -1.0):
            raise click.UsageError(f"--model-error must be > -1 (relative), got {model_error}")
    opts = {}
    if line_search == "backtracking":
        opts["alphas"] = [0.5**k for k in range(10)]
    elif line_search == "fixed":
        opts["alphas"] = [0.1]
    if variant:
        opts["variant"] = variant
    if second_order:
        opts["second_order"] = True
    warm = None
    if warm_start:
        guide = ddp.load_scenario(scenario, cost="log", schedule=False, keep_out=False, wrist=wrist, robot=robot)
        click.echo("warm start: solving the companion problem (log-SE(3) cost, End weights, no keep-out) ...")
        prob, gsol = ddp.warm_started(prob, guide)
        warm = {
            "iterations": int(gsol["iterations"]),
            "final_cost": float(gsol["cost"]),
            "solve_time_s": float(gsol["solve_time_s"]),
            "stop": gsol["stop"],
            "unwound_turns": gsol["unwound"],
        }
        click.echo(
            f"  companion: {warm['iterations']} iterations, cost {warm['final_cost']:.8g}, {warm['solve_time_s']:.2f} s"
            f" ({gsol['stop_message']})"
        )
    click.echo(
        f"{prob.name}: {prob.model.name}, N = {prob.horizon}, dt = {prob.dt} s, pose cost '{prob.cost_kind}', "
        f"up to {({**prob.options, **opts}).get('max_iter', 100)} iterations"
        + (", full DDP (second-order dynamics terms)" if second_order else "")
    )
    click.echo(f"{'iter':>5} {'cost':>16} {'step':>8} {'lambda':>9} {'expected':>11} {'gap':>9}")

    def progress(i):
        step = f"{i['alpha']:.4g}" if i["accepted"] else "reject"
        click.echo(
            f"{i['iter']:>5} {i['cost']:>16.8g} {step:>8} {i['lambda']:>9.2e} {i['expected']:>11.3e} {i['gap']:>9.1e}"
        )
        return True

    if closed_loop:
        opts["refresh_gains"] = True  # gains at the returned iterate, for the closed loop
    sol = ddp.solve(prob, progress=progress, **opts)
    res = ddp.results(prob, sol)
    res["timings"] = sol["timings"]
    res["second_order"] = bool(second_order)
    if warm is not None:
        res["warm_start"] = warm
    # Ctrl-C during the solve: the best iterate is kept and written, without the closed loop or figures (they
    # take seconds), and the command exits with 130 as every interrupted freefloat command does
    interrupted = sol["stop"] == "interrupted"
    if interrupted:
        res["interrupted"] = True
    runs = {}
    if closed_loop and not interrupted:
        runs, res["closed_loop"] = _closed_loop(
            prob, sol, mpc, horizon, replan, mpc_iter, model_error, error_body, substeps
        )
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
        if not no_plots and not interrupted:
            from ..control.ddp_plots import plot_all

            paths = plot_all(prob, sol, d)
            if runs:
                from ..control.ddp_closed_loop import plot

                paths += plot(runs, prob, d)
            click.echo(f"  wrote {d / 'results.json'} and {len(paths)} figures")
        else:
            click.echo(
                f"  wrote {d / 'results.json'}" + (" (the best iterate before the interrupt; no figure)" * interrupted)
            )
    if interrupted:
        sys.exit(130)


def _closed_loop(prob, sol, mpc, horizon, replan, mpc_iter, model_error, error_body, substeps):
    from ..control import ddp_closed_loop as cl

    # the default error body is the last one with mass (a rate-driven wrist is massless)
    body = error_body or prob.model.body_names[-1 - len(prob.rate_joints)]
    try:
        plant = cl.perturbed_model(prob.model, model_error, body) if model_error else prob.model
    except InputError as e:
        raise click.UsageError(str(e)) from None
    click.echo(
        f"\nclosed loop: plant = {prob.model.name}"
        + (f" with {body} {100 * model_error:+g} % mass" if model_error else " (no model error)")
        + f", simulated by RK4 at dt/{substeps}"
    )
    modes = ["open_loop", "policy"] + (["mpc"] if mpc else [])
    runs, block = {}, {"plant": {"model_error": model_error, "error_body": body, "substeps": substeps}}
    for mode in modes:
        from tqdm.auto import tqdm

        bar = tqdm(total=prob.horizon, desc=f"  {mode}", unit="step", leave=False, disable=None)

        def progress(k, n, bar=bar):
            bar.update(k - bar.n)
            return True

        try:
            r = cl.run(
                prob,
                mode,
                plant,
                solution=sol,
                substeps=substeps,
                mpc_horizon=horizon,
                replan=replan,
                mpc_options={"max_iter": mpc_iter},
                progress=progress,
            )
        finally:
            bar.close()
        runs[mode] = r
        s = cl.summary(r)
        block[mode] = s
        extra = ""
        if mode == "mpc":
            m = s["mpc"]
            extra = (
                f"; {m['replans']} re-plans of {horizon} steps every {replan}, {m['iterations']} iterations, "
                f"{m['solve_time_s']:.2f} s solving (slowest re-plan {1e3 * m['max_replan_s']:.0f} ms)"
            )
        click.echo(
            f"  {mode:>9}: final-hold error <= {1e3 * s['ee_position_error_final_hold_max_m']:.2f} mm, "
            f"{s['ee_angle_error_final_hold_max_deg']:.3f} deg; RMS {1e3 * s['ee_position_error_rms_m']:.2f} mm{extra}"
        )
    return runs, block

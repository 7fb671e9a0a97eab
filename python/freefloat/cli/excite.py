"""`freefloat excite`: design an exciting trajectory for the minimal parameters."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import click
import numpy as np

from .._core import Interrupted
from ._common import load_model, tqdm_bar


@click.command("excite")
@click.argument("model")
@click.option(
    "--guess",
    help="Robot (built-in name or file) whose inertial parameters are the rough guess the design "
    "uses for the base response (default: MODEL's own). For Naveen, Shah, Misra: naveen_dual_arm_offset.",
)
@click.option("--weight", type=float, default=None, help="w of eq. 32 (default 1000 rad²/s², see docs/excitation.md).")
@click.option(
    "--min-gain",
    type=float,
    default=None,
    help="Relative decrease of the condition number that counts as an improvement in the pruning "
    "(default 0.01; 0 is Algorithm 1 as printed, which keeps nearly every interval).",
)
@click.option("--maxiter", type=int, default=100, show_default=True, help="SQP iterations per optimisation step.")
@click.option("--q-limit", type=float, default=None, help="Arm joint position limit ±[deg] (default 270).")
@click.option("--rate-limit", type=float, default=None, help="Arm joint rate limit [rad/s] (default 1.6π ≈ 5.03).")
@click.option(
    "--acc-limit", type=float, default=None, help="Arm joint acceleration limit [rad/s²] (default 1.6π² ≈ 15.79)."
)
@click.option(
    "--compare/--no-compare",
    default=False,
    show_default=True,
    help="Then simulate MODEL along the designed trajectory, along the same number of un-designed intervals "
    "and along the un-pruned step-1 trajectory, with the paper's noise, and compare identification errors.",
)
@click.option(
    "--fourier/--no-fourier",
    default=False,
    show_default=True,
    help="Also optimise the paper's baseline, a 5-term Fourier series per arm joint (11 variables each), on the "
    "same objective over the same duration; written as fourier_trajectory.json and compared with --compare.",
)
@click.option(
    "--out",
    default="freefloat-excite",
    show_default=True,
    help="Directory for trajectory.json, results.json and fig4.png.",
)
def excite_cmd(model, guess, weight, min_gain, maxiter, q_limit, rate_limit, acc_limit, compare, fourier, out):
    """Design an exciting trajectory for identifying MODEL's minimal parameters (Naveen, Shah, Misra, Sec. V).

    Three steps, each with a progress bar: (1) SQP over two seeds per arm joint (start angle and range of the
    cycloids, eqs. 28-31) on every direction combination of the driven joints, minimising eq. 32 (condition
    number of the minimal regressor plus a reward for fast motion) within the joint limits (eqs. 33-37);
    (2) pruning of the intervals by Algorithm 1; (3) SQP again on the kept intervals. The base motion comes
    from the momentum model with the --guess parameters. Prints the seeds (Table 3 format) and writes the
    trajectory for `freefloat identify minimal MODEL --trajectory OUT/trajectory.json`."""
    from ..identification import excitation as exc

    m = load_model(model)
    g = m if guess is None else load_model(guess)
    n_arm = len(g.joints_tagged("arm_"))
    limits = exc.Limits.naveen(n_arm)  # the documented defaults, overridden option by option
    if q_limit is not None:
        limits.q_min, limits.q_max = np.full(n_arm, -np.deg2rad(q_limit)), np.full(n_arm, np.deg2rad(q_limit))
    if rate_limit is not None:
        limits.qd_max = np.full(n_arm, rate_limit)
    if acc_limit is not None:
        limits.qdd_max = np.full(n_arm, acc_limit)
    kw = {} if weight is None else {"weight": weight}
    design = exc.ExcitationDesign(g, limits=limits, **kw)
    click.echo(
        f"designing an exciting trajectory for {m.name} (guess: {g.name}): {design.n_arm} arm joints, "
        f"{len(design.wheels)} wheels, {design.n_intervals} direction combinations, {design.n_min} minimal parameters"
    )
    try:
        res = design.design(maxiter=maxiter, progress=True, **({} if min_gain is None else {"min_gain": min_gain}))
    except Interrupted as e:  # Ctrl-C: keep the best design found so far
        _save_partial(e, out)
        sys.exit(130)
    click.echo(res.summary())
    click.echo(res.table3())
    click.echo("time: " + ", ".join(f"{k} {v:.1f} s" for k, v in res.timings.items()))
    res.save(out)
    summary = res.to_dict()
    extra = {}
    try:
        _after_design(design, res, summary, extra, m, g, out, maxiter, fourier, compare)
    except KeyboardInterrupt:  # Ctrl-C in the Fourier baseline or the comparison: the design is already saved
        during = "the Fourier baseline" if fourier and "fourier" not in summary else "the comparison"
        summary["interrupted"] = f"after the design, in {during}"
        Path(out, "results.json").write_text(json.dumps(summary, indent=2))
        click.echo(
            f"interrupted: {summary['interrupted']}; the design is complete and saved in {out} "
            "(trajectory.json, results.json with `interrupted`)",
            err=True,
        )
        sys.exit(130)
    o = Path(out)
    click.echo(f"wrote {o / 'trajectory.json'}, {o / 'results.json'} and {o / 'fig4.png'}")


def _after_design(design, res, summary, extra, m, g, out, maxiter, fourier, compare):
    """The optional Fourier baseline and comparison, after the design is saved."""
    from ..identification import excitation as exc

    if fourier:
        bar = tqdm_bar(maxiter, "Fourier baseline: SQP over 11 coefficients per joint")
        try:
            fstep, ftraj = design.fourier_baseline(
                res.directions, maxiter=maxiter, progress=lambda it, c: (bar.update(1), bar.set_postfix(C=f"{c:.4g}"))
            )
            bar.update(bar.total - bar.n)  # converged before maxiter: the finished optimiser fills its bar
        finally:
            bar.close()
        click.echo(
            f"Fourier baseline ({len(res.directions) * design.interval:g} s, {fstep.x.size} variables): "
            f"κ = {fstep.condition_number:.4g}, C = {fstep.objective:.4g} "
            f"(cycloids, {2 * design.n_arm} variables: "
            f"κ = {res.step3.condition_number:.4g}, C = {res.step3.objective:.4g})"
        )
        exc.save_trajectory(Path(out) / "fourier_trajectory.json", ftraj, design.joints, g.name)
        summary["fourier"] = {
            "condition_number": fstep.condition_number,
            "objective": fstep.objective,
            "variables": int(fstep.x.size),
            "iterations": fstep.iterations,
        }
        extra["Fourier baseline (same duration)"] = ftraj
        Path(out, "results.json").write_text(json.dumps(summary, indent=2))
    if compare:
        click.echo("\ncomparison with the paper's noise (identification of MODEL's minimal parameters):")
        summary["comparison"] = exc.compare(m, res, progress=True, extra=extra)
        click.echo(exc.comparison_table(summary["comparison"]))
        Path(out, "results.json").write_text(json.dumps(summary, indent=2))


def _save_partial(e, out) -> None:
    """After Ctrl-C during the design: say where it stopped and write the best design so far (trajectory.json,
    results.json with `interrupted: true`)."""
    part = getattr(e, "partial", None)
    click.echo(f"interrupted: {e}", err=True)
    if part is None:
        return
    part.save(out)
    o = Path(out)
    kept = f"{o / 'trajectory.json'} (the best design so far) and " if part.best is not None else ""
    click.echo(f"  wrote {kept}{o / 'results.json'} (interrupted: true; no figure)", err=True)

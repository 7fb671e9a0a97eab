"""`freefloat identify`: the group, and `identify minimal` (minimal parameters from telemetry, optionally a full
consistent set and validation by prediction). `identify postcapture` is in `cli.postcapture`."""

from __future__ import annotations

import json
from pathlib import Path

import click
import numpy as np

from .._core import InputError
from ._common import load_model, parse_vector


@click.group("identify", context_settings={"help_option_names": ["-h", "--help"]})
def identify_group():
    """Identify inertial parameters from measured (or simulated) motion.

    `freefloat identify minimal MODEL --data FILE` estimates the minimal parameters (the combinations the
    momentum model can see; `freefloat params minimal MODEL` lists them) from telemetry of a free-floating
    robot."""


@identify_group.command("minimal")
@click.argument("model")
@click.option(
    "--data",
    type=click.Path(),
    help="Telemetry file (.parquet or .csv) with columns t [s], q.<label>, v.<label> (labels as in a "
    "`freefloat simulate` output: base.x .. base.qw, base.vx .. base.wz, then joint names). "
    "Orders and frames: q = base position (inertial frame), base quaternion x, y, z, w (w LAST), joint "
    "angles; v = base linear velocity and base angular velocity both in the BASE (body) frame, then joint "
    "rates. Optionally momentum.px ... momentum.Lz (total momentum, inertial frame, angular about the "
    "inertial origin) or the external wrench wrench.fx ... wrench.mz (inertial frame, moment about the "
    "origin); without them the momentum is conserved (h0, zero by default). MuJoCo states (w-first "
    "quaternion, world-frame linear velocity) must first go through `freefloat convert --from mujoco`.",
)
@click.option(
    "--simulate",
    "n_sim",
    type=int,
    help="Instead of --data: simulate N one-second excitation intervals of the "
    "Naveen, Shah, Misra robot (cycloids from the paper's Table 3 seeds) with the paper's rate noise.",
)
@click.option(
    "--trajectory",
    "traj_file",
    help="Instead of --data: simulate MODEL along this joint trajectory (a file such as DIR/trajectory.json from "
    "`freefloat excite`, or a built-in trajectory name listed by `freefloat scenarios`, e.g. "
    "naveen_exciting_trajectory) with the paper's rate noise, and identify from that.",
)
@click.option(
    "--case1",
    is_flag=True,
    help="Instead of --data: reproduce Naveen, Shah, Misra's Case 1 (their Table 5: median 2.08 %, max 174 % "
    "relative error of the 52 minimal parameters, condition number 248.8) under the paper's own conditions, on MODEL "
    "= naveen_dual_arm: 67 one-second excitation intervals from the paper's Table 3 seeds, the paper's rate noise, "
    "plain least squares, sampled at --case1-rate. Then one of freefloat's improvements per row (1 kHz samples, "
    "errors-in-variables bias removal, the designed exciting trajectory), so each one's gain can be read. Prints "
    "the table; --out writes results.json and table.txt. About 10-30 s. The other options do not apply.",
)
@click.option(
    "--case1-rate",
    type=float,
    default=20.0,
    show_default=True,
    help="With --case1: sampling rate [Hz] of the paper-conditions row (the paper does not give its rate; 20 Hz "
    "gives errors near the paper's median). At most 1000 Hz, the simulation's rate; rounded to a whole number of "
    "its 1 ms steps.",
)
@click.option(
    "--case1-draws",
    type=click.IntRange(min=1),
    default=3,
    show_default=True,
    help="With --case1: number of noise draws (seeds 0, 1, ...); each row shows the median over them.",
)
@click.option(
    "--method",
    type=click.Choice(["auto", "closed-form", "numeric"]),
    default="auto",
    show_default=True,
    help="Minimal-parameter set: Naveen, Shah, Misra's closed form (revolute trees in modified-DH frames), "
    "numeric (any robot), or auto: the closed form where it applies, else numeric (the same default, names and "
    "order as `freefloat params minimal`).",
)
@click.option(
    "--known", help="Comma-separated bodies with known parameters (default: bodies tagged 'known' or 'wheel')."
)
@click.option(
    "--h0",
    help="Conserved total momentum [px,py,pz,Lx,Ly,Lz]; overrides the data's momentum columns "
    "(default: those, else zero).",
)
@click.option(
    "--weights",
    help="Weighted least squares: 'auto' (two steps: each momentum component weighted by the inverse "
    "of its residual variance) or six inverse variances for px,py,pz,Lx,Ly,Lz (default: unweighted).",
)
@click.option(
    "--rate-noise",
    default="data",
    show_default=True,
    help="Standard deviations of the white noise on the measured rates, 'base linear, base angular, joint' (e.g. "
    "50e-6,80e-6,50e-6, or 'paper' for those), used to remove the errors-in-variables bias of least squares. "
    "'data' (default, the same for every source): the levels the telemetry declares; simulated telemetry "
    "(--simulate, --trajectory, and the OUT/telemetry.parquet they write) declares the paper's noise it carries, "
    "a file without a declaration gets plain least squares. 'none': plain least squares. The estimator that ran "
    "is printed.",
)
@click.option(
    "--full/--no-full",
    default=False,
    show_default=True,
    help="Also compute a full, physically consistent set of standard parameters that reproduces the identified "
    "minimal ones (a convex program) and write it as OUT/identified.urdf.",
)
@click.option(
    "--prior",
    help="With --full/--validate: the model (built-in name or file) whose parameters choose the "
    "parts the data cannot see (default: MODEL itself; for naveen_dual_arm try naveen_dual_arm_offset).",
)
@click.option(
    "--validate/--no-validate",
    default=False,
    show_default=True,
    help="Predict base twist and joint torques of the true (MODEL) and identified robots along the paper's "
    "Fourier trajectory (Sec. VI.D, 40 s) and print the RMS errors next to Naveen, Shah, Misra "
    "Table 6. Implies --full.",
)
@click.option(
    "--truth/--no-truth",
    default=None,
    help="Compare the estimate with MODEL's own parameters (default: on for --simulate/--trajectory, whose data "
    "come from MODEL; off for --data: real telemetry has no truth unless --truth or --truth-model is given).",
)
@click.option(
    "--truth-model",
    help="Compare the estimate with this model's parameters (built-in name or file), e.g. the robot a "
    "--data file was simulated from.",
)
@click.option(
    "--check",
    type=click.Choice(["error", "warn", "off"]),
    default="error",
    show_default=True,
    help="Convention check before identifying: fit the momentum model to the data as written and with the usual "
    "mistakes corrected (quaternion w-first, base velocities in the world frame). 'error' stops when a mistake "
    "explains the data and names it; 'warn' only warns; 'off' skips the check.",
)
@click.option(
    "--out",
    help="Directory for results.json and the figures (and the simulated telemetry, identified.urdf; with --case1: "
    "results.json and table.txt).",
)
def identify_minimal_cmd(
    model,
    data,
    n_sim,
    traj_file,
    case1,
    case1_rate,
    case1_draws,
    method,
    known,
    h0,
    weights,
    rate_noise,
    full,
    prior,
    validate,
    truth,
    truth_model,
    check,
    out,
):
    """Estimate the minimal inertial parameters of MODEL from motion data.

    The robot floats freely, so its total momentum is conserved (zero when released at rest) or changes by the
    recorded external impulses (wrench.* columns): the momentum model then relates the measured base and joint
    motion to the unknown parameters linearly. Bodies with known parameters (reaction wheels) supply the scale.
    Prints the estimate with standard deviations (and the true value and relative error with --truth) and the
    paper's error figures; --full gives a complete URDF back, --validate checks it by prediction.

    \b
    Examples:
      freefloat identify minimal naveen_dual_arm_consistent --simulate 64 --validate \\
          --prior naveen_dual_arm_offset --out ident/
      freefloat identify minimal naveen_dual_arm --case1 --out case1/   # Naveen, Shah, Misra's Case 1"""
    from ..identification import identify as idf

    ctx = click.get_current_context()
    given = [p for p in _CASE1_ONLY if _given(ctx, p)]
    if case1:
        if data is not None or n_sim is not None or traj_file is not None:
            raise click.UsageError("--case1 simulates its own data: drop --data, --simulate and --trajectory")
        other = [p for p in _NOT_WITH_CASE1 if _given(ctx, p)]
        if other:
            raise click.UsageError(
                "--case1 runs the paper's Case 1 with fixed settings; these options do not apply to it: "
                + ", ".join("--" + p.replace("_", "-") for p in other)
            )
        _case1(model, case1_rate, case1_draws, out)
        return
    if given:
        raise click.UsageError(", ".join("--" + p.replace("_", "-") for p in given) + " only go with --case1")
    m = load_model(model)
    if sum(x is not None for x in (data, n_sim, traj_file)) != 1:
        raise click.UsageError("give exactly one of --data FILE, --simulate N, --trajectory FILE and --case1")
    known_list = None if known is None else [k for k in known.split(",") if k]
    h = None if h0 is None else parse_vector(h0, 6, "--h0", np.zeros(6))
    w = (
        None
        if weights is None
        else ("auto" if weights.strip() == "auto" else parse_vector(weights, 6, "--weights", None))
    )
    rn = rate_noise.strip().lower()
    if rn == "paper":
        from ..constants import SIGMA_ANG, SIGMA_JOINT, SIGMA_LIN

        rate_noise = f"{SIGMA_LIN},{SIGMA_ANG},{SIGMA_JOINT}"
    if rn in ("data", "none"):
        sig = rn
    else:
        sig = parse_vector(rate_noise, 3, "--rate-noise", None)
        if w is not None:
            raise click.BadParameter("the bias removal is for unweighted least squares: drop --weights", "--rate-noise")
    data_is_simulated = data is None
    if n_sim is not None:
        click.echo(f"simulating {n_sim} excitation intervals of {m.name} with the paper's rate noise ...")
        data, _ = idf.excitation_data(m, n_intervals=n_sim, progress=True)
    if traj_file is not None:
        from ..io.trajectory_files import load_trajectory

        try:
            trajectory, joints = load_trajectory(traj_file)
        except InputError as e:
            raise click.BadParameter(str(e), param_hint="--trajectory") from None
        click.echo(f"simulating {m.name} along {traj_file} ({trajectory.duration:g} s) with the paper's rate noise ...")
        data, _ = idf.trajectory_data(m, trajectory, joints, progress=True)
    if out and (n_sim is not None or traj_file is not None):  # keep the simulated telemetry beside the results
        Path(out).mkdir(parents=True, exist_ok=True)
        data.to_parquet(Path(out) / "telemetry.parquet")
        click.echo(f"wrote {Path(out) / 'telemetry.parquet'} (the simulated telemetry, with its rate noise declared)")
    if truth_model is not None:
        truth_ref = load_model(truth_model)
    elif truth if truth is not None else data_is_simulated:
        truth_ref = m
    else:
        truth_ref = None
    res = idf.identify_minimal(m, data, known=known_list, method=method, h0=h, weights=w, rate_noise=sig, check=check)
    if res.conventions is not None:
        click.echo(res.conventions.message())
    click.echo(f"estimator: {res.estimator}")
    click.echo(res.table(truth=truth_ref))
    summary = res.to_dict(truth=truth_ref)
    if out:
        res.save(out, truth=truth_ref)
        o = Path(out)
        click.echo(f"wrote {o / 'results.json'}" + (f" and {o / 'minimal_parameters.png'}" if truth_ref else ""))
    if full or validate:
        summary.update(_full_and_validate(m, res, prior, validate, out))
        if out:
            Path(out, "results.json").write_text(json.dumps(summary, indent=2))


#: options that only `--case1` takes, and the options of `identify minimal` that do not apply to it
_CASE1_ONLY = ("case1_rate", "case1_draws")
_NOT_WITH_CASE1 = (
    "method",
    "known",
    "h0",
    "weights",
    "rate_noise",
    "full",
    "prior",
    "validate",
    "truth",
    "truth_model",
    "check",
)


def _given(ctx, name: str) -> bool:
    """Whether the user gave the option (on the command line or by environment), not its default."""
    src = ctx.get_parameter_source(name)
    return src is not None and src not in (
        click.core.ParameterSource.DEFAULT,
        click.core.ParameterSource.DEFAULT_MAP,
    )


def _case1(model, rate, draws, out) -> None:
    """--case1 of `identify minimal`: Naveen, Shah, Misra's Case 1 like for like (`freefloat.demo.case1_table`,
    shared with `freefloat demo --case1`), the table printed and, with --out, results.json and table.txt."""
    from .. import demo

    m = load_model(model)
    res = demo.case1_table(rate, seeds=range(draws), echo=click.echo, progress=True, model=m)
    table = res.pop("table")
    res["paper"] = {
        "median_pct": demo.PAPER_CASE1[0],
        "max_pct": demo.PAPER_CASE1[1],
        "condition_number": demo.PAPER_CASE1_KAPPA,
    }
    if out:
        o = Path(out)
        o.mkdir(parents=True, exist_ok=True)
        (o / "results.json").write_text(json.dumps(res, indent=2))
        (o / "table.txt").write_text(table + "\n")
        click.echo(f"wrote {o / 'results.json'} and {o / 'table.txt'}")


def _full_and_validate(m, res, prior, validate, out) -> dict:
    """--full / --validate of `identify minimal`: consistent standard parameters, URDF, Table 6 prediction."""
    from ..identification.validation import identified_model, predict

    prior_model = None if prior is None else load_model(prior)
    click.echo("\nphysically consistent standard parameters (convex program) ...")
    ident, c, how = identified_model(m, res, prior_model)
    click.echo(
        f"  reproduces the identified minimal parameters to {c.max_rel_deviation:.3g} relative "
        f"(whitened misfit {c.misfit:.3g}); smallest pseudo-inertia eigenvalue {c.min_eigenvalue.min():.3g}; "
        f"solver {c.solver}"
    )
    extra = {
        "consistent": {
            "parameters": c.parameters.tolist(),
            "max_rel_deviation": c.max_rel_deviation,
            "misfit": c.misfit,
            "solver": c.solver,
        }
    }
    if out:
        c.model(m).to_urdf(Path(out) / "identified.urdf")
        click.echo(f"  wrote {Path(out) / 'identified.urdf'}")
    if validate:
        click.echo(
            f"prediction along the Fourier trajectory of Sec. VI.D (40 s, both robots); identified robot: {how} ..."
        )
        pred = predict(m, ident, progress=True)
        click.echo(pred.table())
        extra["prediction"] = pred.to_dict() | {"identified_robot": how}
        if out:
            pred.save(out)
            click.echo(f"  wrote {Path(out) / 'prediction.json'} and {Path(out) / 'prediction_errors.png'}")
    return extra

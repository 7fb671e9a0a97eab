"""Command line: `freefloat --help` lists the commands; each has its own `--help`."""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import click
import numpy as np

from . import _core, models
from .model import Model
from .simulation import Trajectory, simulate

MODEL_HELP = "a built-in robot name (see `freefloat models`) or a .yaml / .urdf file"


def tqdm_bar(total: int, desc: str):
    from tqdm.auto import tqdm

    return tqdm(total=total, desc=desc, leave=False)


def torque_options(m: Model, torques: str, amplitude: float) -> dict:
    """`simulate` keyword arguments for the --torques option: 'zero', 'sine' or a .npy/.csv table (T, nv)."""
    if torques == "zero":
        return {}
    if torques == "sine":
        return {"torques": sine_torques(m, amplitude)}
    p = Path(torques)
    table = np.load(p) if p.suffix == ".npy" else np.loadtxt(p, delimiter=",", ndmin=2)
    return {"torques": table, "hold": "zoh"}


def load_model(spec: str, base: str = "free") -> Model:
    """A built-in name, or a path to a YAML or URDF file."""
    p = Path(spec)
    if spec in models.names():
        return models.load(spec)
    if p.suffix.lower() in (".yaml", ".yml"):
        return Model.from_yaml(p)
    if p.suffix.lower() == ".urdf":
        return Model.from_urdf(p, base=base)
    raise click.BadParameter(f"'{spec}' is neither a built-in robot ({', '.join(models.names())}) nor a .yaml/.urdf file", param_hint="MODEL")


def parse_vector(text: str | None, n: int, name: str, default: np.ndarray) -> np.ndarray:
    if text is None:
        return default
    try:
        x = np.array([float(s) for s in text.replace(",", " ").split()])
    except ValueError:
        raise click.BadParameter(f"expected {n} numbers separated by commas", param_hint=name) from None
    if x.shape != (n,):
        raise click.BadParameter(f"expected {n} numbers, got {x.size}", param_hint=name)
    return x


def out_paths(out: str | None, stem: str) -> tuple[Path | None, Path | None, Path | None]:
    """--out FILE.parquet writes FILE.parquet, FILE.results.json and FILE.png; --out DIR writes
    DIR/<stem>.parquet, DIR/results.json and DIR/<stem>.png."""
    if out is None:
        return None, None, None
    p = Path(out)
    if p.suffix == ".parquet":
        p.parent.mkdir(parents=True, exist_ok=True)
        return p, p.with_suffix(".results.json"), p.with_suffix(".png")
    p.mkdir(parents=True, exist_ok=True)
    return p / f"{stem}.parquet", p / "results.json", p / f"{stem}.png"


def sine_torques(model: Model, amplitude: float):
    """Smooth internal torques on every non-base joint: amplitude·sin(2π f_j t + φ_j)."""
    nb = model.nvs[0]
    n = model.nv - nb
    f = 0.2 + 0.05 * np.arange(n)
    phi = np.arange(n, dtype=float)

    def torques(t, q, v):
        out = np.zeros(model.nv)
        out[nb:] = amplitude * np.sin(2 * np.pi * f * t + phi)
        return out

    return torques


def summarize(traj: Trajectory, wall: float) -> dict:
    d = traj.momentum_drift()
    e = traj.energy_balance()
    return {
        "samples": len(traj), "t_final": float(traj.t[-1]), "wall_time_s": wall, **traj.stats,
        "momentum_initial": traj.momentum[0].tolist(), "momentum_final": traj.momentum[-1].tolist(),
        "momentum_drift_linear_abs": d["linear_abs"], "momentum_drift_angular_abs": d["angular_abs"],
        "momentum_drift_linear_rel": d["linear_rel"], "momentum_drift_angular_rel": d["angular_rel"],
        "kinetic_energy_initial": float(traj.kinetic_energy[0]), "kinetic_energy_final": float(traj.kinetic_energy[-1]),
        "energy_minus_work_abs": e["abs"], "energy_minus_work_rel": e["rel"],
    }


def print_summary(title: str, s: dict) -> None:
    click.echo(f"\n{title}")
    click.echo(f"  simulated {s['t_final']:.3f} s in {s['wall_time_s']:.3f} s wall ({s['steps']} steps, {s['method']})")
    click.echo(f"  momentum drift   linear  {s['momentum_drift_linear_abs']:.3e} kg m/s   (relative {s['momentum_drift_linear_rel']:.2e})")
    click.echo(f"                   angular {s['momentum_drift_angular_abs']:.3e} kg m²/s  (relative {s['momentum_drift_angular_rel']:.2e})")
    click.echo(f"  kinetic energy   {s['kinetic_energy_initial']:.6g} J -> {s['kinetic_energy_final']:.6g} J")
    click.echo(f"  |ΔE − work|      {s['energy_minus_work_abs']:.3e} J   (relative {s['energy_minus_work_rel']:.2e})")


def write_outputs(traj, summary, out, stem, title):
    from . import plots

    pq, js, png = out_paths(out, stem)
    if pq is None:
        return
    traj.to_parquet(pq)
    plots.conservation(traj, png, title)
    js.write_text(json.dumps(summary, indent=2))
    click.echo(f"  wrote {pq}, {js}, {png}")


class FriendlyGroup(click.Group):
    """Turn the engine's errors into one clear line instead of a traceback."""

    def invoke(self, ctx):
        try:
            return super().invoke(ctx)
        except (_core.ModelError, _core.InputError, _core.NumericalError, FileNotFoundError) as e:
            click.echo(f"error: {e}", err=True)
            sys.exit(2)


@click.group(cls=FriendlyGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="freefloat")
def main():
    """freefloat: model, simulate and identify free-floating space robots.

    Start with `freefloat demo`, list robots with `freefloat models`, and simulate one with
    `freefloat simulate seed001_dual_arm --out run.parquet`."""


@main.command("models")
@click.option("--show", metavar="NAME", help="Print the YAML description of one built-in robot.")
def models_cmd(show):
    """List the built-in robots (name, sizes, mass), or print one with --show."""
    if show:
        click.echo(models.source(show))
        return
    click.echo(f"{'name':32s} {'bodies':>6s} {'base':>7s} {'nq':>4s} {'nv':>4s} {'mass [kg]':>10s}")
    for n in models.names():
        m = models.load(n)
        click.echo(f"{n:32s} {m.nbodies:6d} {m.joint_types[0]:>7s} {m.nq:4d} {m.nv:4d} {m.total_mass:10.2f}")


@main.command("simulate")
@click.argument("model")
@click.option("--base", type=click.Choice(["free", "planar", "fixed"]), default="free", show_default=True, help="Base joint for a URDF model.")
@click.option("--t-final", type=float, default=10.0, show_default=True, help="Simulated time [s].")
@click.option("--dt", type=float, default=1e-3, show_default=True, help="RK4 step, or RK45 output interval [s].")
@click.option("--method", type=click.Choice(["rk4", "rk45"]), default="rk4", show_default=True, help="Fixed-step RK4 or adaptive Dormand-Prince 5(4).")
@click.option("--rtol", type=float, default=1e-9, show_default=True, help="RK45 relative tolerance.")
@click.option("--atol", type=float, default=1e-12, show_default=True, help="RK45 absolute tolerance.")
@click.option("--torques", default="sine", show_default=True,
              help="'zero', 'sine' (smooth internal joint torques), or a .npy/.csv file of shape (T, nv) sampled every --dt.")
@click.option("--amplitude", type=float, default=5.0, show_default=True, help="Amplitude of the 'sine' torques [N m].")
@click.option("--q0", help="Initial configuration, nq comma-separated numbers (default: neutral).")
@click.option("--v0", help="Initial velocity, nv comma-separated numbers (default: zero).")
@click.option("--record-every", type=int, default=10, show_default=True, help="RK4: keep every n-th step.")
@click.option("--formulation", type=click.Choice(["aba", "dq"]), default="aba", show_default=True,
              help="Dynamics: the engine's ABA, or the dual-quaternion Newton-Euler system (seed 003 ch. 6).")
@click.option("--out", help="FILE.parquet, or a directory (gets trajectory, results.json, figure).")
def simulate_cmd(model, base, t_final, dt, method, rtol, atol, torques, amplitude, q0, v0, record_every, formulation, out):
    """Simulate MODEL (a built-in name or a .yaml/.urdf file) and report conservation.

    The robot floats freely; joints are driven by --torques. The summary gives the drift of total
    linear and angular momentum (conserved with internal torques only) and the difference between
    the change of kinetic energy and the work done, both of which measure integration error."""
    m = load_model(model, base)
    q = parse_vector(q0, m.nq, "--q0", m.neutral())
    v = parse_vector(v0, m.nv, "--v0", np.zeros(m.nv))
    kw = torque_options(m, torques, amplitude)
    t0 = time.perf_counter()
    traj = simulate(m, q, v, t_final, dt, method=method, rtol=rtol, atol=atol, record_every=record_every, progress=True,
                    formulation=formulation, **kw)
    s = summarize(traj, time.perf_counter() - t0)
    s["model"] = m.name
    print_summary(f"{m.name}: {t_final} s, {method}, {formulation}", s)
    write_outputs(traj, s, out, "trajectory", f"{m.name}: conservation")


@main.command("reactions")
@click.argument("model")
@click.option("--base", type=click.Choice(["free", "fixed"]), default="free", show_default=True, help="Base joint for a URDF model.")
@click.option("--t-final", type=float, default=10.0, show_default=True, help="Simulated time [s].")
@click.option("--dt", type=float, default=1e-3, show_default=True, help="RK4 step [s].")
@click.option("--torques", default="sine", show_default=True,
              help="'zero', 'sine' (smooth internal joint torques), or a .npy/.csv file of shape (T, nv) sampled every --dt.")
@click.option("--amplitude", type=float, default=5.0, show_default=True, help="Amplitude of the 'sine' torques [N m].")
@click.option("--record-every", type=int, default=10, show_default=True, help="Evaluate the wrenches every n-th step.")
@click.option("--out", help="Directory: reactions.csv (every joint's wrench), results.json (peaks), reactions.png.")
def reactions_cmd(model, base, t_final, dt, torques, amplitude, record_every, out):
    """Joint reaction wrenches of MODEL along a simulated motion (dual-quaternion formulation, seed 003 ch. 6).

    The motion is simulated by the engine (RK4); at every recorded sample `ff.dq_dynamics` gives each
    joint's transmitted wrench from one linear system. The table lists, per joint, the peak reaction force
    and torque (the wrench without its actuated components) and when they occur."""
    from . import reactions as rx

    m = load_model(model, base)
    kw = torque_options(m, torques, amplitude)
    traj = simulate(m, m.neutral(), np.zeros(m.nv), t_final, dt, record_every=record_every, progress=True, **kw)
    r = rx.along(m, traj)
    click.echo(f"{m.name}: {t_final} s, {len(r.t)} samples; dq vs ABA accelerations agree to {r.max_acceleration_mismatch:.1e}")
    click.echo(f"  {'joint':24s} {'type':10s} {'peak |f| [N]':>14s} {'at t [s]':>9s} {'peak |tau| [N m]':>17s} {'at t [s]':>9s}")
    for pk in r.peaks()[1:] if m.parents[0] < 0 and m.joint_types[0] != "fixed" else r.peaks():
        click.echo(f"  {pk['joint']:24s} {pk['type']:10s} {pk['peak_force']:14.6g} {pk['t_peak_force']:9.3f} "
                   f"{pk['peak_torque']:17.6g} {pk['t_peak_torque']:9.3f}")
    if out:
        d = Path(out)
        d.mkdir(parents=True, exist_ok=True)
        cols = ["t"] + [f"{j}.{c}" for j in m.joint_names for c in ("fx", "fy", "fz", "tx", "ty", "tz")]
        data = np.column_stack([r.t, r.wrench.reshape(len(r.t), -1)])
        np.savetxt(d / "reactions.csv", data, delimiter=",", header=",".join(cols), comments="")
        (d / "results.json").write_text(json.dumps({"model": m.name, "t_final": t_final, "peaks": r.peaks(),
                                                     "acceleration_mismatch": r.max_acceleration_mismatch}, indent=2))
        rx.plot(r, d / "reactions.png", f"{m.name}: joint reaction wrenches")
        click.echo(f"  wrote {d / 'reactions.csv'}, {d / 'results.json'}, {d / 'reactions.png'}")


@main.command("demo")
@click.option("--out", default="freefloat-demo", show_default=True, help="Directory for the trajectory, results.json and figure.")
@click.option("--t-final", type=float, default=20.0, show_default=True, help="Length of the manoeuvre [s].")
def demo_cmd(out, t_final):
    """Run the main job on its built-in default, on the seed 001 dual-arm robot with three reaction wheels.

    1. Simulation: the robot floats freely while its six arm joints follow a smooth prescribed manoeuvre
       (hybrid dynamics: the base responds, the joint torques needed are recorded); prints and plots how
       well momentum and energy are conserved.
    2. Identification: the exciting trajectory designed by `freefloat excite` (shipped in the package) with the paper's
       rate noise, then the 52 minimal parameters from the momentum model; prints the paper's error
       figures and plots every parameter's error.
    3. Validation by prediction (seed 001 Sec. VI.D): true and identified robots along a Fourier trajectory."""
    m = models.load("seed001_dual_arm")
    arm = m.joints_tagged("arm_")
    idx = [m.idx_q[m.joint_names.index(j)] for j in arm]
    vidx = [m.idx_v[m.joint_names.index(j)] for j in arm]
    amp = np.deg2rad([40, 30, 45, -40, 25, -35])
    w = 2 * np.pi / t_final
    q0 = m.neutral()
    q0[3:7] = [0.0, 0.0, 0.0, 1.0]

    def prescription(t):
        # A cycloid per joint: rest-to-rest from 0 to amp over t_final (zero rate and acceleration at the ends).
        q, v, a = m.neutral(), np.zeros(m.nv), np.zeros(m.nv)
        q[idx] = amp * (t / t_final - np.sin(w * t) / (2 * np.pi))
        v[vidx] = amp / t_final * (1 - np.cos(w * t))
        a[vidx] = amp / t_final * w * np.sin(w * t)
        return q, v, a

    click.echo(f"demo: {m!r}\n  prescribed joints {', '.join(arm)}; base and wheels float")
    t0 = time.perf_counter()
    traj = simulate(m, q0, np.zeros(m.nv), t_final, 1e-3, prescribed=arm, prescription=prescription, record_every=10, progress=True)
    s = summarize(traj, time.perf_counter() - t0)
    s["model"] = m.name
    pq = np.asarray(traj.q)
    s["base_position_final"] = pq[-1, :3].tolist()
    s["base_quaternion_final"] = pq[-1, 3:7].tolist()
    s["peak_joint_torque"] = {j: float(np.abs(traj.tau[:, k]).max()) for j, k in zip(arm, vidx)}
    print_summary("seed 001 dual-arm manoeuvre (momentum starts at zero and must stay there)", s)
    click.echo(f"  base moved to {np.round(pq[-1, :3], 4).tolist()} m, attitude quaternion {np.round(pq[-1, 3:7], 4).tolist()}")
    click.echo("  peak joint torques [N m]: " + ", ".join(f"{j} {x:.2f}" for j, x in s["peak_joint_torque"].items()))
    write_outputs(traj, s, out, "demo", "seed 001 dual-arm manoeuvre")

    from . import identify as idf

    from .excitation import load_trajectory

    from . import data

    with data.path("trajectories", "seed001_exciting_trajectory") as p:
        designed, joints = load_trajectory(p)
    click.echo(f"\nidentification: the designed exciting trajectory ({designed.n_intervals} intervals, `freefloat excite`) "
               "with the paper's rate noise (50 µm/s, 80 µrad/s, 50 µrad/s)")
    telem, _ = idf.trajectory_data(m, designed, joints, progress=True)
    plain = idf.identify_minimal(m, telem).errors(m)
    from .telemetry import SIGMA_ANG, SIGMA_JOINT, SIGMA_LIN

    res = idf.identify_minimal(m, telem, rate_noise=(SIGMA_LIN, SIGMA_ANG, SIGMA_JOINT))
    e = res.errors(m)
    click.echo(f"  {len(res.names)} minimal parameters, condition number {res.fit.condition_number:.4g}; relative error "
               f"median {e['median_rel_error_pct']:.3g} %, max {e['max_rel_error_pct']:.3g} % (seed 001 Case 1: 2.08 %, 174 %)")
    click.echo(f"  (plain least squares, without removing the errors-in-variables bias: median "
               f"{plain['median_rel_error_pct']:.3g} %, max {plain['max_rel_error_pct']:.3g} %)")
    ident_dir = Path(out) / "identification"
    res.save(ident_dir, truth=m)
    s["identification"] = res.to_dict(truth=m)

    from .validation import identified_model, predict

    click.echo("\nvalidation by prediction (seed 001 Sec. VI.D): true and identified robots along a 40-s Fourier trajectory")
    ident, _, how = identified_model(m, res, models.load("seed001_dual_arm_offset"))
    pred = predict(m, ident, dt=2e-3, progress=True)
    click.echo(f"  identified robot: {how}")
    click.echo("\n".join("  " + ln for ln in pred.table().splitlines()))
    pred.save(ident_dir)
    s["prediction"] = pred.to_dict() | {"identified_robot": how}
    Path(out, "results.json").write_text(json.dumps(s, indent=2))
    click.echo(f"  wrote {ident_dir}/results.json, minimal_parameters.png, prediction.json and prediction_errors.png")


@main.group("params", context_settings={"help_option_names": ["-h", "--help"]})
def params_group():
    """Inertial parameters: which combinations of them the momentum model can identify.

    The momentum of a free-floating robot is linear in the 10 standard parameters of each body
    (mass, first moment, inertia), but only certain combinations of them affect it. Run
    `freefloat params minimal MODEL` to list those combinations."""


@params_group.command("minimal")
@click.argument("model")
@click.option("--method", type=click.Choice(["closed-form", "numeric"]), default="numeric", show_default=True,
              help="'numeric': QR of the momentum regressor over random states (any robot). 'closed-form': seed "
                   "001's grouping rules (revolute joints in modified-DH frames only), numbered like its Table 4.")
@click.option("--known", help="Comma-separated body names whose parameters are known and not identified "
                              "(default: bodies tagged 'known' or 'wheel'); pass '' for none.")
@click.option("--out", help="Directory; gets results.json with names, expressions, values and rank.")
def minimal_cmd(model, method, known, out):
    """Print the minimal (identifiable) inertial parameters of MODEL.

    MODEL is a built-in robot name or a .yaml/.urdf file. Each line is one minimal parameter: a linear
    combination of standard parameters (body.m, body.mcx = mass times CoM x, body.Ixx = inertia about
    the body-frame origin, ...), with its value for the model's own parameters. Momentum measurements
    determine these combinations and nothing finer."""
    from .minimal import minimal_parameters  # scipy is only needed here

    m = load_model(model)
    names = None if known is None else [s.strip() for s in known.split(",") if s.strip()]
    try:
        mp = minimal_parameters(m, method=method, known=names)
    except ValueError as e:
        raise click.UsageError(str(e)) from None
    values = mp.from_standard(m.parameters())
    ex = mp.expressions()
    known_names = [m.body_names[i] for i in mp.known]
    click.echo(f"{m.name}: {mp.n_min} minimal parameters ({method}; rank {mp.rank} of {mp.matrix.shape[1]} "
               f"standard columns); known bodies: {', '.join(known_names) or 'none'}")
    w = max(len(n) for n in mp.names)
    for k, (n, e, x) in enumerate(zip(mp.names, ex, values)):
        click.echo(f"  {n:{w}s} = {x:14.6g}   = {e}")
    if out:
        d = Path(out)
        d.mkdir(parents=True, exist_ok=True)
        res = {"model": m.name, "method": method, "rank": mp.rank, "n_standard": int(mp.matrix.shape[1]),
               "known_bodies": known_names, "unknown_bodies": [m.body_names[i] for i in mp.unknown],
               "names": mp.names, "expressions": ex, "values": values.tolist()}
        (d / "results.json").write_text(json.dumps(res, indent=2))
        click.echo(f"  wrote {d / 'results.json'}")


@main.group("identify", context_settings={"help_option_names": ["-h", "--help"]})
def identify_group():
    """Identify inertial parameters from measured (or simulated) motion.

    `freefloat identify minimal MODEL --data FILE` estimates the minimal parameters (the combinations the
    momentum model can see; `freefloat params minimal MODEL` lists them) from telemetry of a free-floating
    robot."""


@identify_group.command("minimal")
@click.argument("model")
@click.option("--data", type=click.Path(), help="Telemetry file (.parquet or .csv) with columns t, q.<label>, v.<label> "
                                                  "(labels as in a `freefloat simulate` output) and optionally momentum.px ... momentum.Lz "
                                                  "or the external wrench wrench.fx ... wrench.mz (inertial frame, moment about the origin).")
@click.option("--simulate", "n_sim", type=int, help="Instead of --data: simulate N one-second excitation intervals of the "
                                                     "seed 001 robot (cycloids from the paper's Table 3 seeds) with the paper's rate noise.")
@click.option("--trajectory", "traj_file", type=click.Path(exists=True, dir_okay=False),
              help="Instead of --data: simulate MODEL along this joint trajectory (e.g. DIR/trajectory.json from "
                   "`freefloat excite`) with the paper's rate noise, and identify from that.")
@click.option("--method", type=click.Choice(["closed-form", "numeric"]), default="closed-form", show_default=True,
              help="Minimal-parameter set: seed 001's closed form (revolute trees in modified-DH frames) or numeric (any robot).")
@click.option("--known", help="Comma-separated bodies with known parameters (default: bodies tagged 'known' or 'wheel').")
@click.option("--h0", help="Conserved total momentum [px,py,pz,Lx,Ly,Lz]; overrides the data's momentum columns (default: those, else zero).")
@click.option("--weights", help="Weighted least squares: 'auto' (two steps: each momentum component weighted by the inverse "
                                "of its residual variance) or six inverse variances for px,py,pz,Lx,Ly,Lz (default: unweighted).")
@click.option("--rate-noise", help="Standard deviations of the white noise on the measured rates, 'base linear, base "
                                   "angular, joint' (e.g. 50e-6,80e-6,50e-6, or 'paper' for those): removes the "
                                   "errors-in-variables bias of least squares (with --simulate, 'paper' is the default).")
@click.option("--full/--no-full", default=False, show_default=True,
              help="Also compute a full, physically consistent set of standard parameters that reproduces the identified "
                   "minimal ones (a convex program) and write it as OUT/identified.urdf.")
@click.option("--prior", help="With --full/--validate: the model (built-in name or file) whose parameters choose the "
                              "parts the data cannot see (default: MODEL itself; for seed001 try seed001_dual_arm_offset).")
@click.option("--validate/--no-validate", default=False, show_default=True,
              help="Predict base twist and joint torques of the true (MODEL) and identified robots along the paper's "
                   "Fourier trajectory (Sec. VI.D, 40 s) and print the RMS errors next to seed 001 Table 6. Implies --full.")
@click.option("--truth/--no-truth", default=True, show_default=True,
              help="Compare the estimate with the model file's own parameters (right when the data was simulated from it).")
@click.option("--out", help="Directory for results.json and the figures (and the simulated telemetry, identified.urdf).")
def identify_minimal_cmd(model, data, n_sim, traj_file, method, known, h0, weights, rate_noise, full, prior, validate, truth, out):
    """Estimate the minimal inertial parameters of MODEL from motion data.

    The robot floats freely, so its total momentum is conserved (zero when released at rest) or changes by the
    recorded external impulses (wrench.* columns): the momentum model then relates the measured base and joint
    motion to the unknown parameters linearly. Bodies with known parameters (reaction wheels) supply the scale.
    Prints the estimate with standard deviations (and the true value and relative error with --truth) and the
    paper's error figures; --full gives a complete URDF back, --validate checks it by prediction.

    Example: freefloat identify minimal seed001_dual_arm_consistent --simulate 64 --validate
    --prior seed001_dual_arm_offset --out ident/"""
    from . import identify as idf

    m = load_model(model)
    if sum(x is not None for x in (data, n_sim, traj_file)) != 1:
        raise click.UsageError("give exactly one of --data FILE, --simulate N and --trajectory FILE")
    known_list = None if known is None else [k for k in known.split(",") if k]
    h = None if h0 is None else parse_vector(h0, 6, "--h0", np.zeros(6))
    w = None if weights is None else ("auto" if weights.strip() == "auto" else parse_vector(weights, 6, "--weights", None))
    if rate_noise is None and (n_sim is not None or traj_file is not None) and w is None:
        rate_noise = "paper"  # the simulated data carries the paper's noise, so its levels are known
    if rate_noise is not None and rate_noise.strip() == "paper":
        from .telemetry import SIGMA_ANG, SIGMA_JOINT, SIGMA_LIN

        rate_noise = f"{SIGMA_LIN},{SIGMA_ANG},{SIGMA_JOINT}"
    sig = None if rate_noise is None else parse_vector(rate_noise, 3, "--rate-noise", None)
    if n_sim is not None:
        click.echo(f"simulating {n_sim} excitation intervals of {m.name} with the paper's rate noise ...")
        data, _ = idf.excitation_data(m, n_intervals=n_sim, progress=True)
    if traj_file is not None:
        from .excitation import load_trajectory

        trajectory, joints = load_trajectory(traj_file)
        click.echo(f"simulating {m.name} along {traj_file} ({trajectory.duration:g} s) with the paper's rate noise ...")
        data, _ = idf.trajectory_data(m, trajectory, joints, progress=True)
    if out and (n_sim is not None or traj_file is not None):  # keep the simulated telemetry beside the results
        Path(out).mkdir(parents=True, exist_ok=True)
        data.to_parquet(Path(out) / "telemetry.parquet")
    res = idf.identify_minimal(m, data, known=known_list, method=method, h0=h, weights=w, rate_noise=sig)
    click.echo(res.table(truth=m if truth else None))
    summary = res.to_dict(truth=m if truth else None)
    if out:
        res.save(out, truth=m if truth else None)
        click.echo(f"wrote {out}/results.json" + (f" and {out}/minimal_parameters.png" if truth else ""))
    if full or validate:
        summary.update(_full_and_validate(m, res, prior, validate, out))
        if out:
            Path(out, "results.json").write_text(json.dumps(summary, indent=2))


def _full_and_validate(m, res, prior, validate, out) -> dict:
    """--full / --validate of `identify minimal`: consistent standard parameters, URDF, Table 6 prediction."""
    from .validation import identified_model, predict

    prior_model = None if prior is None else load_model(prior)
    click.echo("\nphysically consistent standard parameters (convex program) ...")
    ident, c, how = identified_model(m, res, prior_model)
    click.echo(f"  reproduces the identified minimal parameters to {c.max_rel_deviation:.3g} relative "
               f"(whitened misfit {c.misfit:.3g}); smallest pseudo-inertia eigenvalue {c.min_eigenvalue.min():.3g}; "
               f"solver {c.solver}")
    extra = {"consistent": {"parameters": c.parameters.tolist(), "max_rel_deviation": c.max_rel_deviation,
                            "misfit": c.misfit, "solver": c.solver}}
    if out:
        c.model(m).to_urdf(Path(out) / "identified.urdf")
        click.echo(f"  wrote {out}/identified.urdf")
    if validate:
        click.echo(f"prediction along the Fourier trajectory of Sec. VI.D (40 s, both robots); identified robot: {how} ...")
        pred = predict(m, ident, progress=True)
        click.echo(pred.table())
        extra["prediction"] = pred.to_dict() | {"identified_robot": how}
        if out:
            pred.save(out)
            click.echo(f"  wrote {out}/prediction.json and {out}/prediction_errors.png")
    return extra


@main.command("excite")
@click.argument("model")
@click.option("--guess", help="Robot (built-in name or file) whose inertial parameters are the rough guess the design "
                              "uses for the base response (default: MODEL's own). For seed 001: seed001_dual_arm_offset.")
@click.option("--weight", type=float, default=None, help="w of eq. 32 (default 1000 rad²/s², see docs/excitation.md).")
@click.option("--min-gain", type=float, default=None,
              help="Relative decrease of the condition number that counts as an improvement in the pruning "
                   "(default 0.01; 0 is Algorithm 1 as printed, which keeps nearly every interval).")
@click.option("--maxiter", type=int, default=100, show_default=True, help="SQP iterations per optimisation step.")
@click.option("--q-limit", type=float, default=None, help="Arm joint position limit ±[deg] (default 270).")
@click.option("--rate-limit", type=float, default=None, help="Arm joint rate limit [rad/s] (default 1.6π ≈ 5.03).")
@click.option("--acc-limit", type=float, default=None, help="Arm joint acceleration limit [rad/s²] (default 1.6π² ≈ 15.79).")
@click.option("--compare/--no-compare", default=False, show_default=True,
              help="Then simulate MODEL along the designed trajectory, along the same number of un-designed intervals "
                   "and along the un-pruned step-1 trajectory, with the paper's noise, and compare identification errors.")
@click.option("--fourier/--no-fourier", default=False, show_default=True,
              help="Also optimise the paper's baseline, a 5-term Fourier series per arm joint (11 variables each), on the "
                   "same objective over the same duration; written as fourier_trajectory.json and compared with --compare.")
@click.option("--out", default="freefloat-excite", show_default=True,
              help="Directory for trajectory.json, results.json and fig4.png.")
def excite_cmd(model, guess, weight, min_gain, maxiter, q_limit, rate_limit, acc_limit, compare, fourier, out):
    """Design an exciting trajectory for identifying MODEL's minimal parameters (seed 001, Sec. V).

    Three steps, each with a progress bar: (1) SQP over two seeds per arm joint (start angle and range of the
    cycloids, eqs. 28-31) on every direction combination of the driven joints, minimising eq. 32 (condition
    number of the minimal regressor plus a reward for fast motion) within the joint limits (eqs. 33-37);
    (2) pruning of the intervals by Algorithm 1; (3) SQP again on the kept intervals. The base motion comes
    from the momentum model with the --guess parameters. Prints the seeds (Table 3 format) and writes the
    trajectory for `freefloat identify minimal MODEL --trajectory OUT/trajectory.json`."""
    from . import excitation as exc

    m = load_model(model)
    g = m if guess is None else load_model(guess)
    n_arm = len(g.joints_tagged("arm_"))
    limits = exc.Limits.seed001(n_arm)  # the documented defaults, overridden option by option
    if q_limit is not None:
        limits.q_min, limits.q_max = np.full(n_arm, -np.deg2rad(q_limit)), np.full(n_arm, np.deg2rad(q_limit))
    if rate_limit is not None:
        limits.qd_max = np.full(n_arm, rate_limit)
    if acc_limit is not None:
        limits.qdd_max = np.full(n_arm, acc_limit)
    kw = {} if weight is None else {"weight": weight}
    design = exc.ExcitationDesign(g, limits=limits, **kw)
    click.echo(f"designing an exciting trajectory for {m.name} (guess: {g.name}): {design.n_arm} arm joints, "
               f"{len(design.wheels)} wheels, {design.n_intervals} direction combinations, {design.n_min} minimal parameters")
    res = design.design(maxiter=maxiter, progress=True, **({} if min_gain is None else {"min_gain": min_gain}))
    click.echo(res.summary())
    click.echo(res.table3())
    click.echo("time: " + ", ".join(f"{k} {v:.1f} s" for k, v in res.timings.items()))
    res.save(out)
    summary = res.to_dict()
    extra = {}
    if fourier:
        bar = tqdm_bar(maxiter, "Fourier baseline: SQP over 11 coefficients per joint")
        try:
            fstep, ftraj = design.fourier_baseline(res.directions, maxiter=maxiter,
                                                   progress=lambda it, c: (bar.update(1), bar.set_postfix(C=f"{c:.4g}")))
        finally:
            bar.close()
        click.echo(f"Fourier baseline ({len(res.directions) * design.interval:g} s, {fstep.x.size} variables): "
                   f"κ = {fstep.condition_number:.4g}, C = {fstep.objective:.4g} "
                   f"(cycloids, {2 * design.n_arm} variables: κ = {res.step3.condition_number:.4g}, C = {res.step3.objective:.4g})")
        exc.save_trajectory(Path(out) / "fourier_trajectory.json", ftraj, design.joints, g.name)
        summary["fourier"] = {"condition_number": fstep.condition_number, "objective": fstep.objective,
                              "variables": int(fstep.x.size), "iterations": fstep.iterations}
        extra["Fourier baseline (same duration)"] = ftraj
        Path(out, "results.json").write_text(json.dumps(summary, indent=2))
    if compare:
        click.echo("\ncomparison with the paper's noise (identification of MODEL's minimal parameters):")
        summary["comparison"] = exc.compare(m, res, progress=True, extra=extra)
        click.echo(exc.comparison_table(summary["comparison"]))
        Path(out, "results.json").write_text(json.dumps(summary, indent=2))
    click.echo(f"wrote {out}/trajectory.json, {out}/results.json and {out}/fig4.png")


@identify_group.command("postcapture")
@click.argument("scenario")
@click.option("--out", help="Directory for results.json, table.txt and the figures.")
@click.option("--noise/--no-noise", default=None,
              help="Force measurement noise on (the scenario's `noise`, or the default study levels) or off.")
@click.option("--seed", type=int, default=0, show_default=True, help="Seed of the measurement noise.")
@click.option("--sweep/--no-sweep", default=True, show_default=True,
              help="For a scenario with a `sweep` section: also run the initial-velocity sweep (Figs. 6-9).")
@click.option("--forgetting", type=float, help="Forgetting factor of the standard-parameter RLS (default: the scenario's, 1 = none).")
@click.option("--project/--no-project", default=None,
              help="Report the standard-parameter estimate projected onto physically consistent parameters.")
@click.option("--accelerations", type=click.Choice(["exact", "central_difference"]),
              help="Accelerations for the force form: exact at the samples (default) or central differences of the sampled velocities.")
@click.option("--impulses", type=click.Choice(["simpson", "trapezoid"]),
              help="Thrust impulses for the momentum form: Simpson on the 1 kHz thrust (default) or trapezoid on the samples.")
def identify_postcapture_cmd(scenario, out, noise, seed, sweep, forgetting, project, accelerations, impulses):
    """Seed 000: identify base and captured target online, in one step (momentum- and force-based).

    SCENARIO is a built-in name (`freefloat scenarios`) or a YAML file. Simulates the post-capture motion
    (RK4, 1 ms; eq. 40 momentum damping, eq. 39 attitude stabilisation by the arm), samples it at the
    scenario's rate and runs four online estimators: the paper's modified RLS and the ordinary RLS on
    standard parameters, each with the momentum and the force equations. Prints our final values and
    transit times beside the paper's; --out writes results.json, table.txt and the figures."""
    import time as _time

    from tqdm import tqdm

    from . import postcapture as pc

    sc = pc.load_scenario(scenario)
    if noise is True and not sc.noise:
        sc.noise = dict(pc.DEFAULT_NOISE)
    elif noise is False:
        sc.noise = None
    if forgetting is not None:
        if not 0 < forgetting <= 1:
            raise click.BadParameter("must be in (0, 1]", param_hint="--forgetting")
        sc.forgetting = forgetting
    if project is not None:
        sc.project = project
    if accelerations:
        sc.measurement["accelerations"] = accelerations
    if impulses:
        sc.measurement["impulses"] = impulses
    t0 = _time.perf_counter()
    with tqdm(total=2, desc=f"{sc.name}", unit="stage", leave=False) as bar:
        res = pc.run(sc, seed=seed, progress=lambda what: (bar.set_postfix_str(what), bar.update(1)))
    wall = _time.perf_counter() - t0
    click.echo(res.table())
    r = res.residuals
    click.echo(f"equations at the true parameters: momentum form max residual {r['momentum']['paper_angular']:.2e} "
               f"(rhs up to {r['momentum']['paper_angular_scale']:.2e}), force form {r['force']['paper_angular']:.2e} "
               f"(rhs up to {r['force']['paper_angular_scale']:.2e})")
    click.echo(f"simulation + measurements + 4 estimators: {wall:.2f} s (simulation {res.timings['simulation']:.2f} s)"
               + (f"; noise {sc.noise}" if sc.noise else "; noise-free")
               + (f"; measurement {sc.measurement}" if sc.measurement else ""))
    sw = None
    if sweep and sc.sweep:
        vels = sc.sweep["velocities"]
        with tqdm(total=len(vels), desc="velocity sweep", unit="run", leave=False) as bar:
            sw = pc.sweep(sc, progress=lambda k, n: bar.update(1))
        click.echo(pc.sweep_table(sw, paper=sc.paper_sweep))
    if out:
        path = res.save(out)
        if sw is not None:
            data = json.loads(path.read_text())
            data["velocity_sweep"] = sw
            path.write_text(json.dumps(data, indent=1))
            pc.plot_sweep(sw, Path(out))
        click.echo(f"wrote {path} and figures in {out}")


@main.command("scenarios")
def scenarios_cmd():
    """List the built-in post-capture scenarios (seed 000), one per line with what it reproduces.

    A scenario file (YAML; the built-in ones ship inside the package) names the robot, the captured target, the
    controller gains, the initial velocities and the identification settings. Run one with
    `freefloat identify postcapture NAME --out DIR`."""
    from . import postcapture as pc

    for name, desc in pc.list_scenarios():
        click.echo(f"{name:<22} {desc}")


if __name__ == "__main__":
    main()

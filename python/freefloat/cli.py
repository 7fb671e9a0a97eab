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
    kw = {}
    if torques == "sine":
        kw["torques"] = sine_torques(m, amplitude)
    elif torques != "zero":
        p = Path(torques)
        table = np.load(p) if p.suffix == ".npy" else np.loadtxt(p, delimiter=",", ndmin=2)
        kw.update(torques=table, hold="zoh")
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
    kw = {}
    if torques == "sine":
        kw["torques"] = sine_torques(m, amplitude)
    elif torques != "zero":
        p = Path(torques)
        table = np.load(p) if p.suffix == ".npy" else np.loadtxt(p, delimiter=",", ndmin=2)
        kw.update(torques=table, hold="zoh")
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
    2. Identification: 32 one-second excitation intervals (cycloids from the paper's seeds) with the
       paper's rate noise, then the 52 minimal parameters from the momentum model; prints the paper's
       error figures and plots every parameter's error."""
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

    click.echo("\nidentification: 32 excitation intervals with the paper's rate noise (50 µm/s, 80 µrad/s, 50 µrad/s)")
    telem, _ = idf.excitation_data(m, n_intervals=32, progress=True)
    res = idf.identify_minimal(m, telem)
    e = res.errors(m)
    click.echo(f"  {len(res.names)} minimal parameters, condition number {res.fit.condition_number:.4g}; relative error "
               f"median {e['median_rel_error_pct']:.3g} %, max {e['max_rel_error_pct']:.3g} % (seed 001 Case 1: 2.08 %, 174 %)")
    ident_dir = Path(out) / "identification"
    res.save(ident_dir, truth=m)
    s["identification"] = res.to_dict(truth=m)
    Path(out, "results.json").write_text(json.dumps(s, indent=2))
    click.echo(f"  wrote {ident_dir}/results.json and {ident_dir}/minimal_parameters.png")


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
                                                  "(labels as in a `freefloat simulate` output) and optionally momentum.px ... momentum.Lz.")
@click.option("--simulate", "n_sim", type=int, help="Instead of --data: simulate N one-second excitation intervals of the "
                                                     "seed 001 robot (cycloids from the paper's Table 3 seeds) with the paper's rate noise.")
@click.option("--method", type=click.Choice(["closed-form", "numeric"]), default="closed-form", show_default=True,
              help="Minimal-parameter set: seed 001's closed form (revolute trees in modified-DH frames) or numeric (any robot).")
@click.option("--known", help="Comma-separated bodies with known parameters (default: bodies tagged 'known' or 'wheel').")
@click.option("--h0", help="Conserved total momentum [px,py,pz,Lx,Ly,Lz]; overrides the data's momentum columns (default: those, else zero).")
@click.option("--truth/--no-truth", default=True, show_default=True,
              help="Compare the estimate with the model file's own parameters (right when the data was simulated from it).")
@click.option("--out", help="Directory for results.json and the error figure (and the simulated telemetry).")
def identify_minimal_cmd(model, data, n_sim, method, known, h0, truth, out):
    """Estimate the minimal inertial parameters of MODEL from motion data.

    The robot floats freely, so its total momentum is conserved (zero when released at rest): the momentum
    model then relates the measured base and joint motion to the unknown parameters linearly. Bodies with
    known parameters (reaction wheels) supply the scale. Prints the estimate with standard deviations (and
    the true value and relative error with --truth) and the paper's error figures."""
    from . import identify as idf

    m = load_model(model)
    if (data is None) == (n_sim is None):
        raise click.UsageError("give exactly one of --data FILE and --simulate N")
    known_list = None if known is None else [k for k in known.split(",") if k]
    h = None if h0 is None else parse_vector(h0, 6, "--h0", np.zeros(6))
    if n_sim is not None:
        click.echo(f"simulating {n_sim} excitation intervals of {m.name} with the paper's rate noise ...")
        data, _ = idf.excitation_data(m, n_intervals=n_sim, progress=True)
        if out:
            Path(out).mkdir(parents=True, exist_ok=True)
            data.to_parquet(Path(out) / "telemetry.parquet")
    res = idf.identify_minimal(m, data, known=known_list, method=method, h0=h)
    click.echo(res.table(truth=m if truth else None))
    if out:
        res.save(out, truth=m if truth else None)
        click.echo(f"wrote {out}/results.json" + (f" and {out}/minimal_parameters.png" if truth else ""))


if __name__ == "__main__":
    main()

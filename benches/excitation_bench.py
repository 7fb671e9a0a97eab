#!/usr/bin/env python3
"""Exciting-trajectory design objective (Naveen, Shah, Misra, eq. 32): freefloat vs a Pinocchio + numpy peer.

Problem: guessed robot naveen_dual_arm_offset, `ExcitationDesign` defaults: all 256 direction combinations
(one 1-s cycloidal interval each, six arm joints with design seeds, three wheels on fixed seeds), seeds
x = d.feasible_start(d.all_directions).  One evaluation of eq. 32, C = κ(G_m) + w·N_l N_m / Σh², needs
  * the joint path on a grid of 10 points per interval (2,561 points),
  * the zero-momentum base twist at every grid point (momentum model of the guess),
  * the base pose by the trapezoidal rule on the group between grid points,
  * the 6 x 52 minimal momentum-regressor block at τ = 0.1, 0.3, ..., 0.9 s of every interval (1,280 points
    -> a 7,680 x 52 matrix G_m), κ from the eigenvalues of GᵀG, the mean square of the base twist and the six
    arm joint rates at those points.

freefloat: `d.evaluate(x)` (cycloid evaluated in Python, everything else in one Rust call).
Pinocchio + numpy peer (written here from the definitions, not from freefloat's code):
  the same joint path (`d.cycloid(x, dirs).evaluate(t)`, inside the peer's timed call as it is inside
  freefloat's); per grid point `pin.computeCentroidalMap` at the base identity (zero momentum is zero about
  any point, so the base pose does not matter there), then one batched numpy solve A_b v_b = −A_j q̇_j for all
  points; Rodrigues increments and a running product of rotation matrices for the attitude, a cumulative sum
  for the position; per sampled point the first six rows of `pin.computeJointTorqueRegressor(q, 0, v)` with
  zero gravity - with zero velocity and acceleration = v, the base rows are Σ_i ᵇX_i* I_i v_i, i.e. the system's
  momentum regressor about the base origin in base axes - carried to the inertial origin and axes with the
  integrated base pose in numpy; the minimal columns, GᵀG, numpy.linalg.eigvalsh, κ, mean square, C.
  Pinocchio gets the guess through `Model.to_urdf` (continuous joints rewritten as revolute so q layouts
  agree) with a free-flyer root; joints and regressor columns are matched by name.
Before anything is timed: the peer's regressor blocks against `ff.momentum_regressor` at its own states
(relative 1e-9) and its κ, mean square and objective against freefloat's (relative 1e-6).

Timed (wall clock, median of interleaved repeats):
  objective      : d.evaluate(x) vs the peer (both including the cycloid evaluation); also freefloat's Rust
                   call alone on a pre-evaluated path, and the cycloid evaluation alone;
  gradient batch : the 13 evaluations of one forward-difference gradient (x and 12 perturbations, as
                   `ExcitationDesign.optimize` forms them) in one d.evaluate(X) call (2 worker threads) vs
                   13 sequential d.evaluate(x_i) calls;
  full design    : d.design(progress=False) wall time (few repeats), kept intervals, κ after step 3.

    python benches/excitation_bench.py            # full run (about 70 s here; the design dominates)
    python benches/excitation_bench.py --quick    # fewer repeats; design capped at 5 SQP iterations per step
    python benches/excitation_bench.py --out DIR  # write excitation_bench.{json,md} there (default benches/results,
                                                  # with --quick benches/results/quick: a smoke run never
                                                  # overwrites the full results)
"""

from __future__ import annotations

import argparse
import gc
import json
import os
import platform
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

# OpenBLAS's idle worker threads busy-wait (~0.1 s) after each of the peer's BLAS calls before they sleep, and on a
# 2-core machine they took the core that freefloat's two-thread evaluation needed next: its median was 6.1 ms against
# a minimum of 3.6 ms (bimodal), and 2.7 ms with the shortest wait OpenBLAS allows, the peer's time unchanged (26.7 and
# 26.8 ms; 15 interleaved repeats each, 2026-12-07). The same setting as benches/identify_vs_numpy.py.
os.environ.setdefault("OPENBLAS_THREAD_TIMEOUT", "4")

import numpy as np  # noqa: E402

import freefloat as ff  # noqa: E402
from freefloat import excitation as exc  # noqa: E402
from freefloat.identification.estimation import absolute_columns  # noqa: E402

MODEL = "naveen_dual_arm_offset"
#: the issue's targets: one evaluation of eq. 32 over 256 intervals, and the whole three-step design
TARGETS = {"ff_objective_s": 5e-3, "design_s": 60.0}
AGREE_RTOL = 1e-6  # κ, mean square, objective (κ from GᵀG: both sides square the condition number)
REGRESSOR_RTOL = 1e-9  # regressor blocks, same algebra up to rounding


# ----------------------------------------------------------------------------------------------- Pinocchio peer
class PinPeer:
    """Eq. 32 computed with Pinocchio's kinematics and numpy, for an ExcitationDesign `d`."""

    def __init__(self, d, tmpdir: Path):
        import pinocchio as pin

        self.pin, self.d = pin, d
        g = d.guess
        raw = tmpdir / f"{g.name}.urdf"
        g.to_urdf(raw)
        # The export writes unlimited joints as URDF "continuous", which Pinocchio parametrises by (cos, sin);
        # as revolute joints (wide limits, which play no part here) the q layout is ours.
        text = re.sub(
            r'type="continuous">',
            'type="revolute">\n    <limit lower="-1e6" upper="1e6" velocity="1e6" effort="1e6"/>',
            raw.read_text(),
        )
        rev = tmpdir / f"{g.name}_revolute.urdf"
        rev.write_text(text)
        pm = pin.buildModelFromUrdf(str(rev), pin.JointModelFreeFlyer())
        pm.gravity = pin.Motion.Zero()  # the torque regressor must be the momentum regressor, nothing else
        if (pm.nq, pm.nv) != (g.nq, g.nv):
            raise SystemExit(f"Pinocchio model has nq={pm.nq}, nv={pm.nv}; freefloat has nq={g.nq}, nv={g.nv}")
        self.pm, self.pd = pm, pm.createData()
        names = list(pm.names)
        # driven joints' q/v indices in Pinocchio's model, looked up by name (not copied from freefloat)
        jid = {n: names.index(n) for n in d.joints}
        self.iq = np.array([pm.joints[jid[n]].idx_q for n in d.joints])
        self.iv = np.array([pm.joints[jid[n]].idx_v for n in d.joints])
        # freefloat's standard-parameter column c (body c // 10, parameter c % 10) -> Pinocchio's column; the
        # free-flyer joint Pinocchio adds is named root_joint, as freefloat's base joint
        body_joint = list(g.joint_names)
        if len(body_joint) != g.nbodies or body_joint[0] not in names:
            raise SystemExit(f"cannot match bodies to Pinocchio joints: {body_joint} vs {names}")
        pin_block = [names.index(n) - 1 for n in body_joint]
        self.std_to_pin = np.array([10 * pin_block[c // 10] + c % 10 for c in range(10 * g.nbodies)])
        self.cols = self.std_to_pin[absolute_columns(d.mp)]
        q0 = np.asarray(d.q0, dtype=float)
        # everything but the driven joints stays at q0 (as in freefloat); the base pose is integrated separately
        self.q_loc = pin.neutral(pm)
        others = np.setdiff1d(np.arange(7, pm.nq), self.iq)
        if others.size:
            raise SystemExit(
                "the peer assumes every non-base joint is driven (true for the Naveen, Shah, Misra robots)"
            )
        self.R0 = quat_to_matrix(q0[3:7] / np.linalg.norm(q0[3:7]))
        self.p0 = q0[:3].copy()

    def path(self, x, dirs):
        """Joint angles and rates on the grid (same cycloid code as freefloat's evaluate)."""
        return self.d.cycloid(x, dirs).evaluate(self.d._grid(len(dirs)))[:2]

    def evaluate(self, x, dirs, keep=False):
        pin, pm, pd, d = self.pin, self.pm, self.pd, self.d
        q, qd = self.path(x, dirs)
        N, nv = len(q), pm.nv
        Q = np.tile(self.q_loc, (N, 1))
        Q[:, self.iq] = q
        V = np.zeros((N, nv))
        V[:, self.iv] = qd
        # zero-momentum base twist: Pinocchio's free-flyer velocity is the base twist in the base frame, as ours
        A = np.empty((N, 6, nv))
        for k in range(N):
            A[k] = pin.computeCentroidalMap(pm, pd, Q[k])
        rhs = -np.einsum("nij,nj->ni", A[:, :, 6:], V[:, 6:])
        tw = np.linalg.solve(A[:, :, :6], rhs[..., None])[..., 0]  # (N, 6) [v; ω]
        V[:, :6] = tw
        # trapezoidal rule on the group: R_{k+1} = R_k exp(h (ω_k + ω_{k+1}) / 2), p by the mean of R v
        h = d.interval / d.grid
        dR = rodrigues(0.5 * h * (tw[:-1, 3:] + tw[1:, 3:]))
        R = np.empty((N, 3, 3))
        R[0] = self.R0
        for k in range(N - 1):
            R[k + 1] = R[k] @ dR[k]
        vel = np.einsum("nij,nj->ni", R, tw[:, :3])
        pos = np.empty((N, 3))
        pos[0] = self.p0
        pos[1:] = self.p0 + np.cumsum(0.5 * h * (vel[:-1] + vel[1:]), axis=0)
        # momentum regressor at the sampled points: base rows of the torque regressor with v = 0, a = v
        idx = np.arange(d.offset, N, d.stride)
        zero = np.zeros(nv)
        Kb = np.empty((len(idx), 6, 10 * (pm.njoints - 1)))
        for r, i in enumerate(idx):
            Kb[r] = pin.computeJointTorqueRegressor(pm, pd, Q[i], zero, V[i])[:6]
        K = self.to_world(Kb[:, :, self.cols], R[idx], pos[idx])
        G = K.reshape(-1, K.shape[-1])
        lam = np.clip(np.linalg.eigvalsh(G.T @ G), 0.0, None)[::-1]
        sv = np.sqrt(lam)
        kappa = sv[0] / max(sv[-1], 1e-16 * sv[0]) if sv[0] > 0 else np.inf
        sumsq = np.sum(tw[idx] ** 2) + np.sum(qd[idx, : d.n_arm] ** 2)
        ms = sumsq / ((6 + d.n_arm) * len(idx))
        out = {"objective": kappa + d.weight / ms, "condition_number": kappa, "mean_square": ms, "singular_values": sv}
        if keep:  # states for the regressor check (not part of the timed work)
            Qw = Q[idx].copy()
            Qw[:, :3] = pos[idx]
            Qw[:, 3:7] = matrix_to_quat(R[idx])
            out.update(states=(Qw, V[idx].copy()), blocks=K)
        return out

    @staticmethod
    def to_world(Kb, R, p):
        """Momentum-regressor blocks about the base origin in base axes -> about the inertial origin in inertial
        axes: lin' = R lin, ang' = R ang + p x lin' (force transformation by the base placement)."""
        lin = np.einsum("nij,njc->nic", R, Kb[:, :3])
        ang = np.einsum("nij,njc->nic", R, Kb[:, 3:]) + np.cross(p[:, :, None], lin, axis=1)
        return np.concatenate([lin, ang], axis=1)


def rodrigues(w):
    """(N, 3) rotation vectors -> (N, 3, 3) rotation matrices (series near zero, where 1 - cos loses digits)."""
    th2 = np.einsum("ni,ni->n", w, w)
    th = np.sqrt(th2)
    small = th < 1e-4
    ths = np.where(small, 1.0, th)
    a = np.where(small, 1 - th2 / 6 + th2 * th2 / 120, np.sin(ths) / ths)
    b = np.where(small, 0.5 - th2 / 24 + th2 * th2 / 720, (1 - np.cos(ths)) / ths**2)
    S = np.zeros((len(w), 3, 3))
    S[:, 0, 1], S[:, 0, 2], S[:, 1, 2] = -w[:, 2], w[:, 1], -w[:, 0]
    S[:, 1, 0], S[:, 2, 0], S[:, 2, 1] = w[:, 2], -w[:, 1], w[:, 0]
    return np.eye(3) + a[:, None, None] * S + b[:, None, None] * (S @ S)


def quat_to_matrix(qt):
    x, y, z, w = qt
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def matrix_to_quat(R):
    """(N, 3, 3) -> (N, 4) x y z w, via Pinocchio (only for the check's states)."""
    import pinocchio as pin

    return np.array([pin.Quaternion(r).coeffs() for r in R])


# ------------------------------------------------------------------------------------------------------ timing
def interleaved(jobs, repeats):
    """{name: [seconds...]}; one warm-up call each, then the jobs take turns so machine noise hits them alike."""
    for f in jobs.values():
        f()
    ts = {k: [] for k in jobs}
    for _ in range(repeats):
        for k, f in jobs.items():
            gc.collect()
            t0 = time.perf_counter()
            f()
            ts[k].append(time.perf_counter() - t0)
    return ts


def stats(v):
    return {"median": statistics.median(v), "min": min(v), "max": max(v), "n": len(v)}


def rel(a, b):
    return float(abs(a - b) / abs(b))


def environment():
    import pinocchio as pin
    import scipy

    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as f:
            cpu = next((ln.split(":", 1)[1].strip() for ln in f if ln.startswith("model name")), cpu)
    except OSError:
        pass
    root = Path(__file__).resolve().parent.parent
    try:
        head = subprocess.run(
            ["git", "-C", str(root), "rev-parse", "--short", "HEAD"], capture_output=True, text=True
        ).stdout.strip()
        dirty = subprocess.run(
            ["git", "-C", str(root), "status", "--porcelain", "--untracked-files=no"], capture_output=True, text=True
        ).stdout.strip()
        git = head + ("+dirty" if dirty else "") if head else None
    except OSError:
        git = None
    return {
        "git": git,
        "python": sys.version.split()[0],
        "platform": platform.platform(),
        "cpu": cpu,
        "nproc": os.cpu_count(),
        "loadavg_start": list(os.getloadavg()) if hasattr(os, "getloadavg") else None,
        "freefloat": ff.__version__,
        "pinocchio": pin.__version__,
        "numpy": np.__version__,
        "scipy": scipy.__version__,
    }


# -------------------------------------------------------------------------------------------------------- main
def main():
    ap = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[0],
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog=__doc__.split("\n\n", 1)[1],
    )
    ap.add_argument(
        "--quick", action="store_true", help="smoke test: 5 repeats, one design capped at 5 SQP iterations per step"
    )
    ap.add_argument("--repeats", type=int, default=None, help="timing repeats (default 31, quick 5)")
    ap.add_argument("--design-repeats", type=int, default=None, help="full-design repeats (default 2, quick 1)")
    ap.add_argument("--out", type=Path, default=None)
    ap.add_argument("--json", default=None, help="also write the results (JSON) to this file (read by run_all.py)")
    args = ap.parse_args()
    if args.out is None:
        args.out = Path(__file__).resolve().parent / "results" / ("quick" if args.quick else "")
    repeats = args.repeats or (5 if args.quick else 31)
    design_repeats = args.design_repeats or (1 if args.quick else 2)
    design_maxiter = 5 if args.quick else 100  # 100 is ExcitationDesign.design's default
    env = environment()

    guess = ff.models.load(MODEL)
    d = exc.ExcitationDesign(guess)
    dirs = d.all_directions
    x = d.feasible_start(dirs)
    n_int = len(dirs)

    with tempfile.TemporaryDirectory() as tmp:
        peer = PinPeer(d, Path(tmp))

        # ---- agreement first: regressor blocks at the peer's own states, then eq. 32's parts
        r_ff = d.evaluate(x)
        r_pe = peer.evaluate(x, dirs, keep=True)
        Qw, Vw = r_pe["states"]
        pick = np.linspace(0, len(Qw) - 1, 64).astype(int)
        K_ff = np.asarray(ff.momentum_regressor(guess, Qw[pick], Vw[pick]))[..., absolute_columns(d.mp)]
        reg_err = float(np.abs(r_pe["blocks"][pick] - K_ff).max() / np.abs(K_ff).max())
        agreement = {
            "regressor_max_rel": reg_err,
            "condition_number_rel": rel(r_pe["condition_number"], r_ff["condition_number"][0]),
            "mean_square_rel": rel(r_pe["mean_square"], r_ff["mean_square"][0]),
            "objective_rel": rel(r_pe["objective"], r_ff["objective"][0]),
            "singular_values_max_rel": float(
                np.max(np.abs(r_pe["singular_values"] - r_ff["singular_values"][0]) / r_ff["singular_values"][0])
            ),
        }
        # the gradient batch must give the sequential numbers (same Rust path, split over threads)
        hstep = 1e-6 * np.maximum(1.0, np.abs(x))
        X = np.vstack([x, x + np.diag(hstep)])
        rb = d.evaluate(X)
        seq = np.array([d.evaluate(xi)["objective"][0] for xi in X])
        agreement["batch_vs_sequential_max_rel"] = float(np.max(np.abs(rb["objective"] - seq) / np.abs(seq)))
        # A single evaluation splits its rows over both threads, a batch gives each path one thread: the Gram
        # blocks are summed in a different order, so the two agree to rounding (not bitwise).
        ok = (
            reg_err <= REGRESSOR_RTOL
            and agreement["batch_vs_sequential_max_rel"] <= 1e-9
            and all(agreement[k] <= AGREE_RTOL for k in ("condition_number_rel", "mean_square_rel", "objective_rel"))
        )
        if not ok:
            raise SystemExit(f"ABORT: peer and freefloat disagree: {agreement}")

        # ---- 1. one evaluation of eq. 32
        q_pre, qd_pre = peer.path(x, dirs)
        t_obj = interleaved(
            {
                "ff_evaluate": lambda: d.evaluate(x),
                "peer_evaluate": lambda: peer.evaluate(x, dirs),
                "ff_rust_call_only": lambda: d._objective(q_pre[None], qd_pre[None]),
                "cycloid_only": lambda: peer.path(x, dirs),
            },
            repeats,
        )

    # ---- 2. the 13 evaluations of one finite-difference gradient
    t_grad = interleaved(
        {
            "batch_one_call": lambda: d.evaluate(X),
            "sequential_13_calls": lambda: [d.evaluate(xi) for xi in X],
        },
        max(3, repeats // 2),
    )

    # ---- 3. the whole design
    designs = []
    for _ in range(design_repeats):
        gc.collect()
        t0 = time.perf_counter()
        res = d.design(maxiter=design_maxiter, progress=False)
        designs.append(
            {
                "seconds": time.perf_counter() - t0,
                "steps_s": res.timings,
                "kept": int(len(res.prune.kept)),
                "condition_number": res.step3.condition_number,
                "objective": res.step3.objective,
                "step1_iterations": res.step1.iterations,
                "step3_iterations": res.step3.iterations,
            }
        )
    design_med = statistics.median(v["seconds"] for v in designs)

    so = {k: stats(v) for k, v in t_obj.items()}
    sg = {k: stats(v) for k, v in t_grad.items()}
    ratios = {
        "peer_over_ff_evaluate": so["peer_evaluate"]["median"] / so["ff_evaluate"]["median"],
        "sequential_over_batch": sg["sequential_13_calls"]["median"] / sg["batch_one_call"]["median"],
    }
    res = {
        "benchmark": "excitation objective (Naveen, Shah, Misra eq. 32)",
        "model": MODEL,
        "quick": args.quick,
        "problem": {
            "intervals": n_int,
            "grid_points": int(n_int * d.grid + 1),
            "sampled_points": int(n_int * d.samples),
            "regressor_shape": [6 * n_int * d.samples, int(d.n_min)],
            "weight": d.weight,
            "seeds": x.tolist(),
            "threads": d.threads,
        },
        "environment": env,
        "repeats": repeats,
        "freefloat_at_x": {
            "objective": float(r_ff["objective"][0]),
            "condition_number": float(r_ff["condition_number"][0]),
            "mean_square": float(r_ff["mean_square"][0]),
        },
        "agreement": agreement,
        "agreement_tolerances": {"parts": AGREE_RTOL, "regressor": REGRESSOR_RTOL},
        "agreement_passed": bool(ok),
        "objective_seconds": so,
        "gradient_batch_seconds": sg,
        "gradient_batch_evaluations": int(len(X)),
        "design": {
            "maxiter": design_maxiter,
            "repeats": designs,
            "seconds_median": design_med,
            "kept_intervals": designs[-1]["kept"],
            "condition_number": designs[-1]["condition_number"],
            "paper": {"kept": exc.PAPER_KEPT, "condition_number": exc.PAPER_KAPPA},
        },
        "ratios": ratios,
        "targets": TARGETS,
        "meets_targets": {
            "ff_objective_s": bool(so["ff_evaluate"]["median"] < TARGETS["ff_objective_s"]),
            "design_s": bool(design_med < TARGETS["design_s"]) if not args.quick else None,
        },
        "loadavg_end": list(os.getloadavg()) if hasattr(os, "getloadavg") else None,
    }

    ms = lambda s: f"{1e3 * s['median']:.2f}"
    md = [
        "# Exciting-trajectory objective (Naveen, Shah, Misra eq. 32): freefloat vs a Pinocchio + numpy peer",
        "",
        f"{MODEL}, {n_int} intervals x 1 s: {res['problem']['grid_points']:,} grid points for the base response, "
        f"{res['problem']['sampled_points']:,} sampled points -> "
        f"{6 * n_int * d.samples:,} x {d.n_min} minimal regressor; "
        f"seeds `d.feasible_start(d.all_directions)`.",
        f"At these seeds: C = {res['freefloat_at_x']['objective']:.6g}, "
        f"κ = {res['freefloat_at_x']['condition_number']:.6g}, "
        f"mean square {res['freefloat_at_x']['mean_square']:.6g}.",
        f"Agreement (checked before timing): regressor {reg_err:.1e}, κ {agreement['condition_number_rel']:.1e}, "
        f"mean square {agreement['mean_square_rel']:.1e}, objective {agreement['objective_rel']:.1e} "
        f"(tolerance {AGREE_RTOL:g}); batch vs sequential {agreement['batch_vs_sequential_max_rel']:.1e}.",
        f"Median of {repeats} interleaved repeats; {env['nproc']} hardware threads shared with other jobs "
        f"(load average at start {env['loadavg_start'][0]:.2f}, end {res['loadavg_end'][0]:.2f}); {env['cpu']}; "
        f"pinocchio {env['pinocchio']}, numpy {env['numpy']}, git {env['git']}.",
        "",
        "## One evaluation of eq. 32",
        "",
        "| what | median [ms] | min [ms] |",
        "|---|---|---|",
        f"| freefloat `d.evaluate(x)` | {ms(so['ff_evaluate'])} | {1e3 * so['ff_evaluate']['min']:.2f} |",
        f"| Pinocchio + numpy peer | {ms(so['peer_evaluate'])} | {1e3 * so['peer_evaluate']['min']:.2f} |",
        f"| freefloat Rust call alone (path pre-evaluated) | {ms(so['ff_rust_call_only'])} | "
        f"{1e3 * so['ff_rust_call_only']['min']:.2f} |",
        f"| cycloid evaluation alone (in both of the first two rows) | {ms(so['cycloid_only'])} | "
        f"{1e3 * so['cycloid_only']['min']:.2f} |",
        "",
        f"Peer / freefloat: {ratios['peer_over_ff_evaluate']:.1f}x.  "
        f"Target for freefloat: < {1e3 * TARGETS['ff_objective_s']:.0f} ms "
        f"({'met' if res['meets_targets']['ff_objective_s'] else 'NOT met'}).",
        "",
        "## One finite-difference gradient (13 evaluations)",
        "",
        "| what | median [ms] | min [ms] |",
        "|---|---|---|",
        f"| one `d.evaluate(X)` call, X 13 x 12, {d.threads} worker threads | "
        f"{ms(sg['batch_one_call'])} | "
        f"{1e3 * sg['batch_one_call']['min']:.2f} |",
        f"| 13 sequential `d.evaluate(x_i)` calls | {ms(sg['sequential_13_calls'])} | "
        f"{1e3 * sg['sequential_13_calls']['min']:.2f} |",
        "",
        f"Sequential / batch: {ratios['sequential_over_batch']:.2f}x (each sequential call already splits its points "
        "over the 2 worker threads, so the batch can gain only what those calls leave idle: about 1x is the "
        "ceiling on 2 cores).",
        "",
        "## Full design (`d.design(progress=False)`)",
        "",
        f"maxiter {design_maxiter}{' (capped for --quick: not the real design time)' if args.quick else ''}; "
        f"{design_repeats} run(s): "
        + ", ".join(f"{v['seconds']:.1f} s" for v in designs)
        + f"; median {design_med:.1f} s"
        + (
            f" (target < {TARGETS['design_s']:.0f} s: {'met' if res['meets_targets']['design_s'] else 'NOT met'})."
            if not args.quick
            else "."
        ),
        f"Kept intervals {res['design']['kept_intervals']} of {n_int}, "
        f"κ after step 3 {res['design']['condition_number']:.4g} "
        f"(paper: {exc.PAPER_KEPT} kept, κ {exc.PAPER_KAPPA}); steps (last run): "
        + ", ".join(f"{k} {v:.1f} s" for k, v in designs[-1]["steps_s"].items())
        + ".",
    ]
    text = "\n".join(md) + "\n"
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "excitation_bench.json").write_text(json.dumps(res, indent=2))
    if args.json:
        Path(args.json).write_text(json.dumps(res, indent=1, default=str))
    (args.out / "excitation_bench.md").write_text(text)
    print(text)


if __name__ == "__main__":
    main()

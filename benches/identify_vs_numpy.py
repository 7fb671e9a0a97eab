#!/usr/bin/env python3
"""Minimal-parameter identification from momentum (Naveen, Shah, Misra, eqs. 26-27):
freefloat vs the strongest numpy/scipy peer we could write.

Problem: naveen_dual_arm, 67 intervals x 1 s at 1 kHz = 67,000 samples -> a 402,000 x 52 minimal regressor
(wheels known, closed-form minimal parameters).  The states come from a simulation (ff.simulate, RK4, dt = 1 ms,
every step recorded) with a prescribed smooth multi-sine on the six arm joints and the three wheels; the
measured momentum is the simulated momentum plus Gaussian noise (sigma 0.1 on every component).

freefloat: `freefloat.estimation.least_squares` - the engine streams over the samples (split over the cores),
  builds each sample's kept regressor columns and folds them straight into the normal equations; the
  402,000 x 52 matrix is never formed.  It keeps the normal equations only when the measured, equilibrated
  condition number is small (and refines on the true residual when it is not tiny), otherwise it re-streams
  through a Householder QR.
numpy peer: body placements and twists either from ff.forward_kinematics / ff.body_velocities, transposed once
  into components-first arrays and not timed (the rows `regressor` and `end_to_end`: the regressor algebra alone
  is compared, freefloat doing its kinematics and the peer not), or from its own vectorised numpy kinematics,
  timed (the rows `regressor_kin` and `end_to_end_kin`: both start from the measured q, v, h), then
  - build: only the 52 kept columns of all 67,000 samples, each with a few array operations over contiguous
    memory written straight into its slot of a column-ordered (52, 6, T) array (a Fortran-ordered 402,000 x 52
    matrix for LAPACK, no copy), the known wheels' momentum only for their nonzero parameters;
  - solve: normal equations by BLAS (A^T A, A^T y; OpenBLAS uses every core it is allowed) and scipy's
    cho_factor / cho_solve.  Of the routes a numpy user would pick (numpy.linalg.lstsq, normal equations +
    cho_solve, scipy.linalg.qr(mode='economic') + a triangular solve) this is the fastest by far, and here as
    accurate as the others (the problem is well conditioned: all three agree with freefloat to ~1e-15); the
    three routes are timed once each and recorded.

Timed (wall clock, interleaved repeats, median and min-max):
  regressor : freefloat's streaming build pass (kinematics + kept columns + right-hand side, no solve)
              vs the peer's build of G and y;
  end_to_end: freefloat least_squares (from Q, V, H) vs the peer's build + normal-equation solve;
  *_kin     : the same with the peer's kinematics timed (freefloat's rows are the same measurements).
Both regressors, both estimates and both kinematics are checked to agree before anything is timed.

Cores: by default both programs use every core (freefloat splits the samples over threads, OpenBLAS threads its
products).  `--cores 1` re-runs the script pinned to one core with OPENBLAS_NUM_THREADS=1 (single-core numbers
for both).

    python benches/identify_vs_numpy.py            # full run (67,000 samples)
    python benches/identify_vs_numpy.py --quick    # 6,700 samples, fewer repeats
    python benches/identify_vs_numpy.py --cores 1  # both pinned to one core
    python benches/identify_vs_numpy.py --out DIR  # write identify_vs_numpy.{json,md} there (default benches/results)
    python benches/identify_vs_numpy.py --json F   # also write the results (JSON) to file F (for run_all.py)
"""

from __future__ import annotations

import argparse
import gc
import json
import os
import platform
import statistics
import subprocess
import sys
import time
from pathlib import Path

# OpenBLAS's idle worker threads busy-wait for 2^28 cycles (~0.1 s) after every BLAS call before they sleep. On a
# 2-core machine they took a core from whichever job ran next: the freefloat pass after the peer's solve measured
# 1.5-2x its own wall time in process CPU time. The shortest wait OpenBLAS allows (2^4 cycles; read when numpy
# first loads OpenBLAS) removes that without slowing the peer: its medians stayed within 2 % (4 runs of each
# setting, 2026-12-04). An idle pause between the jobs instead was tried and dropped: it made the peer's solve
# 1.7-2.5x slower.
os.environ.setdefault("OPENBLAS_THREAD_TIMEOUT", "4")

import numpy as np  # noqa: E402
import scipy.linalg as sla  # noqa: E402

import freefloat as ff  # noqa: E402
from freefloat import estimation as est  # noqa: E402

MODEL = "naveen_dual_arm"
DRIVEN = ["J1", "J2", "J3", "J4", "J5", "J6", "Wx", "Wy", "Wz"]
NOISE = 0.1
# end to end: >= 6x since issue 36 (the 10x target retired on the floor analysis in BENCHMARKS.md, "Identification")
TARGETS = {"regressor": 5.0, "end_to_end": 6.0, "regressor_kin": 5.0, "end_to_end_kin": 6.0}


def multisine(m, seed=1):
    """prescription(t) -> (q, v, a): per driven joint a sum of three sines (smooth, persistently exciting)."""
    traj = ff.trajectories.MultiSine.random(len(DRIVEN), seed)
    traj.amp[6:] *= 20.0  # wheels spin faster than the arm joints
    return traj.prescription(m, DRIVEN)


def make_data(m, seconds):
    presc = multisine(m)
    q0, v0, _ = presc(0.0)
    tr = ff.simulate(m, q0, v0, seconds, 1e-3, prescribed=DRIVEN, prescription=presc, record_every=1)
    Q, V = tr.q[1:], tr.v[1:]  # 1000 samples per second
    H = tr.momentum[1:] + np.random.default_rng(2).normal(scale=NOISE, size=tr.momentum[1:].shape)
    return Q, V, H


# ------------------------------------------------------------------------------------------------- numpy peer
#: the six inertia columns of a body's ten (Ixx Ixy Iyy Ixz Iyz Izz) as pairs (j, k) of R's columns and ω's entries
PAIRS = {4: (0, 0), 5: (0, 1), 6: (1, 1), 7: (0, 2), 8: (1, 2), 9: (2, 2)}


def quat_columns(qt):
    """(4, ...) quaternion components x y z w -> the three columns r_0, r_1, r_2 of R, each (3, ...)."""
    x, y, z, w = qt
    xx, yy, zz, xy, xz, yz, xw, yw, zw = x * x, y * y, z * z, x * y, x * z, y * z, x * w, y * w, z * w
    r0 = np.stack([1 - 2 * (yy + zz), 2 * (xy + zw), 2 * (xz - yw)])
    r1 = np.stack([2 * (xy - zw), 1 - 2 * (xx + zz), 2 * (yz + xw)])
    r2 = np.stack([2 * (xz + yw), 2 * (yz - xw), 1 - 2 * (xx + yy)])
    return r0, r1, r2


def cross(a, b, out=None):
    """Cross product of (3, ...) arrays, components first, written into `out` (explicit: faster than np.cross)."""
    if out is None:
        out = np.empty(np.broadcast_shapes(a.shape, b.shape))
    np.multiply(a[1], b[2], out=out[0])
    out[0] -= a[2] * b[1]
    np.multiply(a[2], b[0], out=out[1])
    out[1] -= a[0] * b[2]
    np.multiply(a[0], b[1], out=out[2])
    out[2] -= a[1] * b[0]
    return out


def peer_inputs(fk, tw, H):
    """The peer's inputs in the layout a numpy user would choose (components first, samples last, so every
    operation below runs over contiguous memory): placements (7, nb, T), twists (6, nb, T), momenta (6, T).
    Computed once up front and not timed."""
    return (
        np.ascontiguousarray(fk.transpose(2, 1, 0)),
        np.ascontiguousarray(tw.transpose(2, 1, 0)),
        np.ascontiguousarray(H.T),
    )


class Kin:
    """Per-body inertial-frame quantities of all samples at once: R's columns r_k, v_o = R v, ω_o = R ω, p × v_o.

    p (3, nb, T) body origins; r the three columns of R, each (3, nb, T); v, w (3, nb, T) body twists in the body
    frame."""

    def __init__(self, p, r, v, w):
        self.p, self.r, self.v, self.w = p, r, v, w
        self.vo = r[0] * v[0] + r[1] * v[1] + r[2] * v[2]
        self.wo = r[0] * w[0] + r[1] * w[1] + r[2] * w[2]
        self.pvo = cross(self.p, self.vo)

    @classmethod
    def from_placements(cls, fkT, twT):
        """From freefloat's placements (7, nb, T: position, quaternion x y z w) and twists (6, nb, T)."""
        return cls(fkT[:3], quat_columns(fkT[3:]), twT[:3], twT[3:])

    def column(self, c, out):
        """Column c (body c // 10, parameter c % 10) of the momentum regressor into out (6, T):
        m: [v_o; p x v_o];  h_k: [w_o x r_k; r_k x v_o + p x (w_o x r_k)];  I_jk: [0; r_j w_k + r_k w_j]
        (Naveen, Shah, Misra, eq. 10, written in inertial-frame quantities)."""
        b, k = divmod(int(c), 10)
        r, w = self.r, self.w
        if k == 0:
            out[:3] = self.vo[:, b]
            out[3:] = self.pvo[:, b]
        elif k <= 3:
            rk = r[k - 1][:, b]
            lin = cross(self.wo[:, b], rk, out=out[:3])
            cross(rk, self.vo[:, b], out=out[3:])
            out[3:] += cross(self.p[:, b], lin)
        else:
            i, j = PAIRS[k]
            out[:3] = 0.0
            np.multiply(r[i][:, b], w[j, b], out=out[3:])
            if i != j:
                out[3:] += r[j][:, b] * w[i, b]
        return out


def _comb(terms, out):
    """out = Σ c·a over (c, a) in terms, the exact 0/1 geometry folded: zero coefficients are skipped, ±1 cost no
    multiplication. At least one coefficient is nonzero."""
    terms = [(c, a) for c, a in terms if c != 0.0]
    c, a = terms[0]
    if c == 1.0:
        out[...] = a
    elif c == -1.0:
        np.negative(a, out=out)
    else:
        np.multiply(a, c, out=out)
    for c, a in terms[1:]:
        if c == 1.0:
            out += a
        elif c == -1.0:
            out -= a
        else:
            out += c * a
    return out


class NumpyKinematics:
    """The peer's own kinematics: body placements and twists of all samples at once in vectorised numpy, for the
    rows where the peer starts, like freefloat, from the measured q and v (Featherstone, RBDA §4.1, joint by joint
    from the root). Components first, samples last. The joint frames' geometry is read from the model once, with
    its exact zeros and ones folded (a placement rotation that is a signed permutation costs no multiplication, a
    zero offset no term). Handles what the benchmark robot has: a free root and revolute joints about a principal
    axis of their frame."""

    def __init__(self, m):
        types, axes = list(m.joint_types), np.asarray(m.joint_axes, float)
        if types[0] != "free" or any(t != "revolute" for t in types[1:]):
            raise SystemExit(f"ABORT: the numpy kinematics handles a free root and revolute joints, not {types}")
        self.nb, self.parents = m.nbodies, list(m.parents)
        self.iq, self.iv = list(m.idx_q), list(m.idx_v)
        self.joints = []
        for i in range(1, self.nb):
            hit = [k for k in range(3) if np.array_equal(axes[i], np.eye(3)[k])]
            if not hit:
                raise SystemExit(f"ABORT: joint {i} axis {axes[i]} is not a principal axis")
            X = np.asarray(m.placements[i], float)
            self.joints.append((i, X[:3, :3].copy(), X[:3, 3].copy(), hit[0]))

    def __call__(self, Q, V):
        """(p, r, v, w) as `Kin` takes them, from Q (T, nq) and V (T, nv)."""
        QT, VT = np.ascontiguousarray(Q.T), np.ascontiguousarray(V.T)
        T, nb = QT.shape[1], self.nb
        p, r = np.empty((3, nb, T)), np.empty((3, 3, nb, T))  # r[k, a, i]: component a of column k of R_i
        v, w = np.empty((3, nb, T)), np.empty((3, nb, T))
        # the free root: position, rotation from the unit quaternion (x y z w), body-frame twist [v; ω]
        p[:, 0] = QT[0:3]
        rc = quat_columns(QT[3:7])
        for k in range(3):
            r[k, :, 0] = rc[k]
        v[:, 0], w[:, 0] = VT[0:3], VT[3:6]
        u = np.empty((3, T))
        for i, R0, t0, k in self.joints:
            par = self.parents[i]
            c, s_ = np.cos(QT[self.iq[i]]), np.sin(QT[self.iq[i]])
            rp = r[:, :, par]
            # M = R_p R0 (column j = Σ_k R0[k, j] r_k), then R_i = M Rot_k(θ): columns a, b = the two others
            # (cyclic) turn by θ, column k stays
            M = np.empty((3, 3, T))
            for j in range(3):
                for a in range(3):
                    _comb([(R0[kk, j], rp[kk, a]) for kk in range(3)], M[j, a])
            a_, b_ = (k + 1) % 3, (k + 2) % 3
            ri = r[:, :, i]
            ri[k] = M[k]
            np.multiply(M[a_], c, out=ri[a_])
            ri[a_] += M[b_] * s_
            np.multiply(M[b_], c, out=ri[b_])
            ri[b_] -= M[a_] * s_
            # p_i = p_p + R_p t0
            p[:, i] = p[:, par]
            for kk in range(3):
                if t0[kk] != 0.0:
                    p[:, i] += t0[kk] * rp[kk]
            # twist: x_i = Rot_k(θ)ᵀ R0ᵀ x_p for ω, and for v after moving to the joint origin (v_p + ω_p × t0);
            # then ω_i += e_k q̇ (a revolute joint's subspace is [0; e_k] in its own frame)
            wp, vp = w[:, par], v[:, par]
            u[0], u[1], u[2] = vp[0], vp[1], vp[2]
            for a in range(3):
                b1, b2 = (a + 1) % 3, (a + 2) % 3  # (ω × t)_a = ω_b1 t_b2 − ω_b2 t_b1
                if t0[b2] != 0.0:
                    u[a] += t0[b2] * wp[b1]
                if t0[b1] != 0.0:
                    u[a] -= t0[b1] * wp[b2]
            for src, dst in ((wp, w[:, i]), (u, v[:, i])):
                x = np.empty((3, T))
                for j in range(3):
                    _comb([(R0[kk, j], src[kk]) for kk in range(3)], x[j])
                dst[k] = x[k]
                np.multiply(x[a_], c, out=dst[a_])
                dst[a_] += x[b_] * s_
                np.multiply(x[b_], c, out=dst[b_])
                dst[b_] -= x[a_] * s_
            w[k, i] += VT[self.iv[i]]
        return p, (r[0], r[1], r[2]), v, w


def numpy_build(kin, H6, cols, known):
    """The minimal regressor and right-hand side of all samples at once: G (n, 6, T), y (6, T) = H - K_known P_known.

    Only the n kept columns are computed (not the 10 nb of the full regressor), each straight into its slot of
    G, and the known bodies' momentum only for their nonzero parameters. G is laid out column by column, which
    is what LAPACK and the BLAS want (A = G.reshape(n, 6T).T is a Fortran-ordered view, no copy): rows are
    ordered component-major (all samples' p_x, then p_y, ...), a row permutation of freefloat's sample-major
    order that changes no least-squares result."""
    G = np.empty((len(cols), 6, H6.shape[1]))
    for j, c in enumerate(cols):
        kin.column(c, G[j])
    y = H6.copy()
    tmp = np.empty_like(y)
    kept = set(int(c) for c in cols)
    for c in np.flatnonzero(known):
        if int(c) not in kept:
            y -= known[c] * kin.column(c, tmp)
    return G, y


def solve_normal(G, y):
    """Normal equations: AᵀA and Aᵀy by BLAS (both cores), Cholesky (scipy cho_factor / cho_solve)."""
    A_t = G.reshape(G.shape[0], -1)
    c = sla.cho_factor(A_t @ A_t.T, check_finite=False)
    return sla.cho_solve(c, A_t @ y.ravel(), check_finite=False)


def solve_lstsq(G, y):
    """numpy.linalg.lstsq (LAPACK gelsd, SVD based)."""
    return np.linalg.lstsq(G.reshape(G.shape[0], -1).T, y.ravel(), rcond=None)[0]


def solve_qr(G, y):
    """scipy.linalg.qr(mode='economic') then a triangular solve."""
    Qm, R = sla.qr(G.reshape(G.shape[0], -1).T, mode="economic", check_finite=False)
    return sla.solve_triangular(R, Qm.T @ y.ravel(), check_finite=False)


SOLVERS = {"normal equations + cho_solve": solve_normal, "lstsq": solve_lstsq, "scipy qr economic": solve_qr}


def numpy_identify(kin, H6, cols, known, solve=solve_normal):
    return solve(*numpy_build(kin, H6, cols, known))


# ------------------------------------------------------------------------------------------------------ timing
def interleaved(jobs, repeats):
    """({name: [wall seconds of each repeat]}, {name: [CPU seconds of this process, all threads]}); the jobs
    take turns so machine noise hits them alike. CPU time is what survives a loaded machine best on one core;
    on several cores it sums the threads' time."""
    ts = {k: [] for k in jobs}
    cpu = {k: [] for k in jobs}
    for _ in range(repeats):
        for k, f in jobs.items():
            gc.collect()
            c0, t0 = time.process_time(), time.perf_counter()
            f()
            ts[k].append(time.perf_counter() - t0)
            cpu[k].append(time.process_time() - c0)
    return ts, cpu


def git_hash():
    try:
        here = Path(__file__).resolve().parent
        return subprocess.run(
            ["git", "rev-parse", "--short", "HEAD"], cwd=here, capture_output=True, text=True, check=True
        ).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def pin_to_cores(cores):
    """Re-run this script restricted to `cores` cores, with OpenBLAS limited to as many threads (it reads the
    variable when numpy is first imported, hence the fresh process; freefloat's threads follow the affinity)."""
    if os.environ.get("FF_BENCH_PINNED") == str(cores):
        return
    env = dict(os.environ, FF_BENCH_PINNED=str(cores), OPENBLAS_NUM_THREADS=str(cores), OMP_NUM_THREADS=str(cores))
    os.sched_setaffinity(0, set(sorted(os.sched_getaffinity(0))[:cores]))
    os.execve(sys.executable, [sys.executable, *sys.argv], env)


def main():
    ap = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[0],
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog=__doc__.split("\n\n", 1)[1],
    )
    ap.add_argument("--quick", action="store_true", help="6,700 samples and 3 repeats (smoke test)")
    ap.add_argument("--repeats", type=int, default=None, help="timing repeats (default 7, quick 3)")
    ap.add_argument("--cores", type=int, default=None, help="pin both programs to this many cores (default: all)")
    ap.add_argument("--out", type=Path, default=Path(__file__).resolve().parent / "results")
    ap.add_argument("--json", type=Path, default=None, help="also write the results as JSON to this file")
    args = ap.parse_args()
    if args.cores is not None:
        if args.cores < 1:
            ap.error("--cores must be at least 1")
        pin_to_cores(args.cores)
    repeats = args.repeats or (3 if args.quick else 7)
    seconds = 6.7 if args.quick else 67.0
    load_before = os.getloadavg()

    m = ff.models.load(MODEL)
    mp = ff.minimal_parameters(m, method="closed-form")
    truth = mp.from_standard(m.parameters())
    Q, V, H = make_data(m, seconds)
    T = len(Q)
    cols, known = est.absolute_columns(mp), est.known_parameters(mp)
    fkT, twT, H6 = peer_inputs(ff.forward_kinematics(m, Q), ff.body_velocities(m, Q, V), H)
    kin_ff = Kin.from_placements(fkT, twT)
    np_kin = NumpyKinematics(m)
    # the peer's own kinematics must reproduce freefloat's (placements, rotation columns, twists)
    mine = np_kin(Q[:500], V[:500])
    ref = (fkT[:3, :, :500], tuple(x[..., :500] for x in kin_ff.r), twT[:3, :, :500], twT[3:, :, :500])
    kin_err = max(float(np.abs(np.asarray(a) - np.asarray(b)).max()) for a, b in zip(mine, ref))
    if kin_err > 1e-12:
        raise SystemExit(f"ABORT: the numpy kinematics differs from freefloat's by {kin_err:.2e}")

    # agreement first: the two regressors (the peer's rows permuted back to sample-major) and the estimates
    K_ff = ff.momentum_regressor(m, Q[:500], V[:500])[..., cols]
    G, y = numpy_build(Kin(*mine), H6[:, :500], cols, known)
    reg_err = float(np.abs(G.transpose(2, 1, 0) - K_ff).max() / np.abs(K_ff).max())
    r = est.least_squares(m, Q, V, H, mp)
    G, y = numpy_build(kin_ff, H6, cols, known)
    routes = {}
    for name, solve in SOLVERS.items():
        t0 = time.perf_counter()
        x = solve(G, y)
        routes[name] = {
            "seconds_once": time.perf_counter() - t0,
            "agreement_with_freefloat": float(np.abs(r.estimate - x).max() / np.abs(x).max()),
        }
    del G, y
    est_err = routes["normal equations + cho_solve"]["agreement_with_freefloat"]
    if reg_err > 1e-12 or max(v["agreement_with_freefloat"] for v in routes.values()) > 1e-9:
        raise SystemExit(f"disagreement: regressor {reg_err:.2e}, estimates {routes}")
    med, mx = est.relative_errors(r.estimate, truth)

    stream_args = (m, Q, V, H, cols.tolist(), known)
    jobs = {
        "ff_regressor": lambda: ff._core.momentum_regressor_stream(*stream_args),
        "np_regressor": lambda: numpy_build(Kin.from_placements(fkT, twT), H6, cols, known),
        "np_kin_regressor": lambda: numpy_build(Kin(*np_kin(Q, V)), H6, cols, known),
        "ff_end_to_end": lambda: est.least_squares(m, Q, V, H, mp),
        "np_end_to_end": lambda: numpy_identify(Kin.from_placements(fkT, twT), H6, cols, known),
        "np_kin_end_to_end": lambda: numpy_identify(Kin(*np_kin(Q, V)), H6, cols, known),
    }
    ts, cpu = interleaved(jobs, repeats)
    timings = {k: (statistics.median(v), min(v), max(v)) for k, v in ts.items()}
    cpu_median = {k: statistics.median(v) for k, v in cpu.items()}
    ratios = {
        "regressor": timings["np_regressor"][0] / timings["ff_regressor"][0],
        "end_to_end": timings["np_end_to_end"][0] / timings["ff_end_to_end"][0],
        "regressor_kin": timings["np_kin_regressor"][0] / timings["ff_regressor"][0],
        "end_to_end_kin": timings["np_kin_end_to_end"][0] / timings["ff_end_to_end"][0],
    }
    load_after = os.getloadavg()
    cores = len(os.sched_getaffinity(0))
    labels = {
        "regressor": "regressor build (ff streaming pass / numpy kept columns of all samples)",
        "end_to_end": "end to end (regressor + solve; numpy: normal equations + cho_solve)",
        "regressor_kin": "regressor build from q, v (the peer's own vectorised kinematics timed too)",
        "end_to_end_kin": "end to end from q, v, h (the peer's own vectorised kinematics timed too)",
    }
    rows = []
    for key, (ffk, npk) in {
        "regressor": ("ff_regressor", "np_regressor"),
        "end_to_end": ("ff_end_to_end", "np_end_to_end"),
        "regressor_kin": ("ff_regressor", "np_kin_regressor"),
        "end_to_end_kin": ("ff_end_to_end", "np_kin_end_to_end"),
    }.items():
        rows.append(
            {
                "key": key,
                "what": labels[key],
                "freefloat_s": timings[ffk][0],
                "freefloat_range_s": [timings[ffk][1], timings[ffk][2]],
                "peer": "numpy/scipy (vectorised, normal equations)",
                "peer_s": timings[npk][0],
                "peer_range_s": [timings[npk][1], timings[npk][2]],
                "ratio": ratios[key],
                "freefloat_cpu_s": cpu_median[ffk],
                "peer_cpu_s": cpu_median[npk],
                "cpu_ratio": cpu_median[npk] / cpu_median[ffk],
                "ratio_range": [timings[npk][1] / timings[ffk][2], timings[npk][2] / timings[ffk][1]],
                "target": f">= {TARGETS[key]:g}x",
                "met": bool(ratios[key] >= TARGETS[key]),
            }
        )
    res = {
        "bench": "identify_vs_numpy",
        "model": MODEL,
        "samples": T,
        "regressor_shape": [6 * T, int(mp.n_min)],
        "noise_sigma": NOISE,
        "states": f"ff.simulate RK4 {seconds} s at 1 kHz, prescribed multi-sine on {', '.join(DRIVEN)}",
        "repeats": repeats,
        "cores": cores,
        "openblas_threads": os.environ.get("OPENBLAS_NUM_THREADS", f"default ({cores} cores allowed)"),
        "openblas_thread_timeout": os.environ.get("OPENBLAS_THREAD_TIMEOUT"),
        "machine": platform.processor() or platform.machine(),
        "numpy": np.__version__,
        "git": git_hash(),
        "load_before": list(load_before),
        "load_after": list(load_after),
        "freefloat_method": r.method,
        "condition_number": r.condition_number,
        "agreement": {"regressor_max_rel": reg_err, "estimate_max_rel": est_err, "numpy_kinematics_max_abs": kin_err},
        "solve_routes": routes,
        "relative_error_percent": {"median": med, "max": mx},
        "seconds_all": ts,
        "seconds_median_min_max": {k: list(v) for k, v in timings.items()},
        "cpu_seconds_all": cpu,
        "ratios": ratios,
        "targets": TARGETS,
        "meets_targets": {k: bool(ratios[k] >= TARGETS[k]) for k in TARGETS},
        "rows": rows,
    }
    md = [
        "# Identification from momentum: freefloat vs a vectorised numpy/scipy peer",
        "",
        f"{MODEL}, {T:,} samples -> {6 * T:,} x {mp.n_min} minimal regressor; {res['states']}; noise sigma {NOISE}.",
        f"freefloat route: {r.method}; condition number {r.condition_number:.1f}; "
        f"agreement: regressor {reg_err:.1e}, estimate {est_err:.1e}, the peer's kinematics {kin_err:.1e}; "
        f"eqs. 38-39 errors: median {med:.3f} %, max {mx:.3f} %.",
        f"Median (min-max) of {repeats} interleaved repeats on {cores} core(s) (both programs use them all: "
        f"freefloat's threads, OpenBLAS threads {res['openblas_threads']}, idle spin "
        f"2^{res['openblas_thread_timeout']} cycles); git {res['git']}; load average "
        f"{load_before[0]:.1f} before, {load_after[0]:.1f} after.",
        "",
        "| what | freefloat [s] | numpy peer [s] | ratio | CPU-time ratio | target |",
        "|---|---|---|---|---|---|",
    ]
    for row in rows:
        f_lo, f_hi = row["freefloat_range_s"]
        p_lo, p_hi = row["peer_range_s"]
        md.append(
            f"| {row['what']} | {row['freefloat_s']:.4f} ({f_lo:.4f}-{f_hi:.4f}) | {row['peer_s']:.4f} "
            f"({p_lo:.4f}-{p_hi:.4f}) | {row['ratio']:.1f}x | {row['cpu_ratio']:.1f}x | "
            f"{row['target']} ({'met' if row['met'] else 'not met'}) |"
        )
    md += [
        "",
        f"Solve routes of the peer on the full {6 * T:,} x {mp.n_min} matrix (timed once each, build excluded):",
        "",
    ]
    md += ["| route | seconds | agreement with freefloat |", "|---|---|---|"]
    for name, v in routes.items():
        md.append(f"| {name} | {v['seconds_once']:.3f} | {v['agreement_with_freefloat']:.1e} |")
    text = "\n".join(md) + "\n"
    args.out.mkdir(parents=True, exist_ok=True)
    suffix = "" if args.cores is None else f"_{args.cores}core"
    (args.out / f"identify_vs_numpy{suffix}.json").write_text(json.dumps(res, indent=2))
    (args.out / f"identify_vs_numpy{suffix}.md").write_text(text)
    if args.json is not None:
        args.json.write_text(json.dumps(res, indent=2))
    print(text)


if __name__ == "__main__":
    main()

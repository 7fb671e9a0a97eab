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
numpy peer: body placements and twists from ff.forward_kinematics / ff.body_velocities, transposed once into
  components-first arrays (not timed: the regressor algebra is what is compared), then
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
  end_to_end: freefloat least_squares (from Q, V, H) vs the peer's build + normal-equation solve.
Both regressors and both estimates are checked to agree before anything is timed.

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

import numpy as np
import scipy.linalg as sla

import freefloat as ff
from freefloat import estimation as est

MODEL = "naveen_dual_arm"
DRIVEN = ["J1", "J2", "J3", "J4", "J5", "J6", "Wx", "Wy", "Wz"]
NOISE = 0.1
TARGETS = {"regressor": 5.0, "end_to_end": 10.0}


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
    """Per-body inertial-frame quantities of all samples at once: R's columns r_k, v_o = R v, ω_o = R ω, p × v_o."""

    def __init__(self, fkT, twT):
        self.p, self.v, self.w = fkT[:3], twT[:3], twT[3:]
        self.r = quat_columns(fkT[3:])
        r, v, w = self.r, self.v, self.w
        self.vo = r[0] * v[0] + r[1] * v[1] + r[2] * v[2]
        self.wo = r[0] * w[0] + r[1] * w[1] + r[2] * w[2]
        self.pvo = cross(self.p, self.vo)

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


def numpy_build(fkT, twT, H6, cols, known):
    """The minimal regressor and right-hand side of all samples at once: G (n, 6, T), y (6, T) = H - K_known P_known.

    Only the n kept columns are computed (not the 10 nb of the full regressor), each straight into its slot of
    G, and the known bodies' momentum only for their nonzero parameters. G is laid out column by column, which
    is what LAPACK and the BLAS want (A = G.reshape(n, 6T).T is a Fortran-ordered view, no copy): rows are
    ordered component-major (all samples' p_x, then p_y, ...), a row permutation of freefloat's sample-major
    order that changes no least-squares result."""
    kin = Kin(fkT, twT)
    G = np.empty((len(cols), 6, fkT.shape[2]))
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


def numpy_identify(fkT, twT, H6, cols, known, solve=solve_normal):
    return solve(*numpy_build(fkT, twT, H6, cols, known))


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

    # agreement first: the two regressors (the peer's rows permuted back to sample-major) and the estimates
    K_ff = ff.momentum_regressor(m, Q[:500], V[:500])[..., cols]
    G, y = numpy_build(fkT[..., :500], twT[..., :500], H6[:, :500], cols, known)
    reg_err = float(np.abs(G.transpose(2, 1, 0) - K_ff).max() / np.abs(K_ff).max())
    r = est.least_squares(m, Q, V, H, mp)
    G, y = numpy_build(fkT, twT, H6, cols, known)
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
        "np_regressor": lambda: numpy_build(fkT, twT, H6, cols, known),
        "ff_end_to_end": lambda: est.least_squares(m, Q, V, H, mp),
        "np_end_to_end": lambda: numpy_identify(fkT, twT, H6, cols, known),
    }
    ts, cpu = interleaved(jobs, repeats)
    timings = {k: (statistics.median(v), min(v), max(v)) for k, v in ts.items()}
    cpu_median = {k: statistics.median(v) for k, v in cpu.items()}
    ratios = {
        "regressor": timings["np_regressor"][0] / timings["ff_regressor"][0],
        "end_to_end": timings["np_end_to_end"][0] / timings["ff_end_to_end"][0],
    }
    load_after = os.getloadavg()
    cores = len(os.sched_getaffinity(0))
    labels = {
        "regressor": "regressor build (ff streaming pass / numpy kept columns of all samples)",
        "end_to_end": "end to end (regressor + solve; numpy: normal equations + cho_solve)",
    }
    rows = []
    for key, (ffk, npk) in {
        "regressor": ("ff_regressor", "np_regressor"),
        "end_to_end": ("ff_end_to_end", "np_end_to_end"),
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
        "machine": platform.processor() or platform.machine(),
        "numpy": np.__version__,
        "git": git_hash(),
        "load_before": list(load_before),
        "load_after": list(load_after),
        "freefloat_method": r.method,
        "condition_number": r.condition_number,
        "agreement": {"regressor_max_rel": reg_err, "estimate_max_rel": est_err},
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
        f"agreement: regressor {reg_err:.1e}, estimate {est_err:.1e}; "
        f"eqs. 38-39 errors: median {med:.3f} %, max {mx:.3f} %.",
        f"Median (min-max) of {repeats} interleaved repeats on {cores} core(s) (both programs use them all: "
        f"freefloat's threads, OpenBLAS threads {res['openblas_threads']}); git {res['git']}; load average "
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

#!/usr/bin/env python3
"""Valverde 2018 ch. 9 concurrent-learning estimation (the 10 s run of §9.5 on valverde_ch9_two_arm):
freefloat vs a vectorised numpy peer.

Two freefloat timings:
  estimator : `_core.cl_estimate` - the stack update and estimation law alone in the engine on the SAME per-step
              data as the peer (R_k, F_k along the run's motion, computed up front by the engine, not timed):
              Algorithm 3 (trace prefilter, element-wise singular-value test on the 11 per-body 7x7 blocks),
              Algorithm 4, the law (9.15) and the SVD gain (9.23-9.27) in square-root form (a QR tree of the
              stacked data), RK4 of the estimate;
  whole run : `freefloat.identification.concurrent.run` - the above plus the robot (RK4, 0.01 s; the
              dual-quaternion solver with its joint wrenches at every major step, ABA at the intermediate
              stages) and the data points, i.e. the issue's "whole 10 s run".
numpy peer: the same stack update and law on the same data, written as well as numpy allows: the candidate's Gram
  blocks with einsum, every trial replacement of Algorithm 3 at once (batched eigvalsh of (n, 11, 7, 7), the first
  passing index in its random order), the same trace prefilter, RR rebuilt with one sum, the square-root form
  from a batched QR of the (11, 8 N_s, 8) stacked data on every change, the gain from a batched SVD, RK4 with
  einsum over the blocks; no Python loop over bodies or trials, one over time steps (the algorithm is sequential).
Agreement, checked before timing: every estimator ends within 1 % on all 77 parameters, and for N_s = 10 (at most
one replacement can pass per step, so the random orders do not matter) the two final estimates agree to 1e-6 of
each parameter's scale.

Timed: wall clock of the whole run, median of `repeats` interleaved runs (freefloat, peer, freefloat, ...),
with min/max. Also: the block-diagonal saving (11 per-block 7x7 eigendecompositions vs one 77x77).

    python benches/cl_vs_numpy.py            # N_s = 10, 50, 100, 200, 300
    python benches/cl_vs_numpy.py --quick    # N_s = 10 and 50, 1 repeat
    python benches/cl_vs_numpy.py --out DIR  # write cl_vs_numpy.{json,md} there (default benches/results)
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import time
import warnings
from pathlib import Path

# the peer's matrices are 7x7 to 88x8: BLAS threads only add contention at that size
for _v in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_v, "1")

import numpy as np  # noqa: E402

import freefloat as ff  # noqa: E402
from freefloat.identification import concurrent as cl  # noqa: E402

SCENARIO = "valverde_ch9_two_arm"


def samples(sc):
    """Per-step (R, F) along the run's motion, from the engine (the peer's input; not timed)."""
    m = sc.model
    exc = {"amplitude": 0.5, "frequency": 1.0, "phase": 0.0, "t_start": 2.0, "t_end": 3.0, **sc.excitation}

    def tau(t, q, v):
        u = np.zeros(m.nv)
        if exc["t_start"] <= t <= exc["t_end"]:
            u[6:] = exc["amplitude"] * np.sin(exc["frequency"] * t + exc["phase"])
        return u

    traj = ff.simulate(m, sc.q0, sc.v0, sc.duration, sc.dt, torques=tau)
    R = np.empty((len(traj.t), m.nbodies, 8, 7))
    F = np.empty((len(traj.t), m.nbodies, 8))
    for k, t in enumerate(traj.t):
        R[k], F[k], _, _ = cl.sample(m, traj.q[k], traj.v[k], tau(t, traj.q[k], traj.v[k]))
    return traj.t, np.ascontiguousarray(R), np.ascontiguousarray(F)


def numpy_peer(t, R, F, m0, ns, sigma_th=1e-3, t_th=5.0, t_th2=4.9, sigma_th2=0.5, sigma_new=100.0, seed=1):
    """Algorithms 3-4, (9.15), (9.23)-(9.27), RK4 — vectorised over bodies and over trial replacements."""
    nt, nb = R.shape[0], R.shape[1]
    dt = t[1] - t[0]
    rng = np.random.default_rng(seed)
    Rs = np.zeros((ns, nb, 8, 7))
    Fs = np.zeros((ns, nb, 8))
    G = np.zeros((ns, nb, 7, 7))
    Gtr = np.zeros(ns)
    nc = 0
    RR = np.zeros((nb, 7, 7))
    sv_test = np.zeros(7 * nb)
    sv = np.zeros(7 * nb)
    T = np.zeros((nb, 7, 7))
    g = np.zeros((nb, 7))
    K = None
    m = m0.reshape(nb, 7).copy()
    est = np.empty((nt, 7 * nb))
    changed = False

    def rebuild():
        nonlocal RR, sv_test, sv, T, g
        RR = G[:nc].sum(axis=0)
        sv_test = np.sort(np.clip(np.linalg.eigvalsh(RR), 0, None).ravel())[::-1]
        A = np.concatenate([Rs[:nc], Fs[:nc, :, :, None]], axis=3)  # (nc, nb, 8, 8)
        A = A.transpose(1, 0, 2, 3).reshape(nb, 8 * nc, 8)
        r = np.linalg.qr(A, mode="r")[:, :8, :8] if 8 * nc >= 8 else np.zeros((nb, 8, 8))
        T, g = r[:, :7, :7], r[:, :7, 7]
        s = np.linalg.svd(T, compute_uv=False)
        sv = np.sort((s * s).ravel())[::-1]

    for k in range(nt):
        tk = t[k]
        if tk < t_th:
            Rc, Fc = R[k], F[k]
            Gc = np.einsum("bij,bik->bjk", Rc, Rc)
            if nc < ns:
                Rs[nc], Fs[nc], G[nc], Gtr[nc] = Rc, Fc, Gc, np.trace(Gc, axis1=1, axis2=2).sum()
                nc += 1
                rebuild()
                changed = True
            elif sv[-1] < sigma_th:
                perm = rng.permutation(ns)
                ctr = np.trace(Gc, axis1=1, axis2=2).sum()
                tol = 64 * np.finfo(float).eps * max(sv_test[0], 1e-300)
                cand = perm[ctr >= Gtr[perm] - tol * 7 * nb]
                if len(cand):
                    if ctr == 0 and Gtr[cand[0]] == 0:
                        p = cand[0]
                        Rs[p], Fs[p], G[p] = Rc, Fc, Gc
                    else:
                        trial = RR[None] - G[cand] + Gc[None]  # (n, nb, 7, 7)
                        tv = np.sort(np.clip(np.linalg.eigvalsh(trial), 0, None).reshape(len(cand), -1), axis=1)[
                            :, ::-1
                        ]
                        ok = np.all(tv >= sv_test[None] - tol, axis=1)
                        if ok.any():
                            p = cand[np.argmax(ok)]
                            Rs[p], Fs[p], G[p], Gtr[p] = Rc, Fc, Gc, ctr
                            rebuild()
                            changed = True
        est[k] = m.ravel()
        if k == nt - 1:
            break
        on = tk >= t_th2 - 1e-9 * dt
        if on and (K is None or changed):
            _, s, vt = np.linalg.svd(T)
            sig = s * s
            sref = np.sqrt(sv[0])
            sbar = np.where((s <= 1e-13 * sref) | (sig >= sigma_th2), 1.0, sigma_new / np.where(sig > 0, sig, 1.0))
            K = np.einsum("bji,bj,bjk->bik", vt, sbar, vt)
            changed = False

        def rate(x, K=K, on=on):
            e = np.einsum("bji,bj->bi", T, np.einsum("bij,bj->bi", T, x) - g)
            return -np.einsum("bij,bj->bi", K, e) if on else -e

        k1 = rate(m)
        k2 = rate(m + 0.5 * dt * k1)
        k3 = rate(m + 0.5 * dt * k2)
        k4 = rate(m + dt * k3)
        m = m + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    return est


def block_saving(repeats=200):
    """One 77x77 symmetric eigendecomposition vs 11 of 7x7 (numpy, batched), on a block-diagonal PSD matrix."""
    rng = np.random.default_rng(0)
    A = rng.normal(size=(11, 9, 7))
    blocks = np.einsum("bij,bik->bjk", A, A)
    full = np.zeros((77, 77))
    for b in range(11):
        full[7 * b : 7 * b + 7, 7 * b : 7 * b + 7] = blocks[b]

    def med(f):
        ts = []
        for _ in range(repeats):
            t0 = time.perf_counter()
            f()
            ts.append(time.perf_counter() - t0)
        return statistics.median(ts)

    t_full = med(lambda: np.linalg.eigvalsh(full))
    t_block = med(lambda: np.linalg.eigvalsh(blocks))
    same = np.allclose(
        np.sort(np.linalg.eigvalsh(full)), np.sort(np.linalg.eigvalsh(blocks).ravel()), rtol=1e-10, atol=1e-10
    )
    return {
        "full_77x77_us": t_full * 1e6,
        "blocks_11x7x7_us": t_block * 1e6,
        "ratio": t_full / t_block,
        "same": bool(same),
        "flops_ratio_estimate": 77**3 / (11 * 7**3),
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--repeats", type=int, default=None)
    ap.add_argument("--out", default=str(Path(__file__).parent / "results"))
    ap.add_argument("--json", default=None, help="also write the results (JSON) to this file (read by run_all.py)")
    a = ap.parse_args()
    ns_list = [10, 50] if a.quick else [10, 50, 100, 200, 300]
    repeats = a.repeats or (1 if a.quick else 5)
    sc = cl.load_scenario(SCENARIO)
    t, R, F = samples(sc)
    truth = cl.run(sc).truth
    scale = cl.parameter_scales(truth)
    rows = []
    agreement = {}
    warnings.simplefilter("ignore")
    for ns in ns_list:
        ref = cl.run(sc, ns=ns)
        peer = numpy_peer(t, R, F, sc.m0, ns)
        e_ff = float(np.max(np.abs(ref.final_estimate - truth) / scale))
        e_np = float(np.max(np.abs(peer[-1] - truth) / scale))
        agreement[ns] = {
            "freefloat_max_rel_error": e_ff,
            "numpy_max_rel_error": e_np,
            "final_estimate_max_rel_diff": float(np.max(np.abs(ref.final_estimate - peer[-1]) / scale)),
        }
        if not (e_ff < 0.01 and e_np < 0.01):
            raise SystemExit(f"N_s = {ns}: an estimator missed 1 % (freefloat {e_ff:.3g}, numpy {e_np:.3g})")
        if ns == 10 and agreement[ns]["final_estimate_max_rel_diff"] > 1e-6:
            raise SystemExit(f"N_s = 10: freefloat and numpy disagree ({agreement[ns]})")
        est_ff = ff._core.cl_estimate(R, F, sc.dt, sc.m0, ns=ns)
        agreement[ns]["engine_estimator_vs_run_max_rel_diff"] = float(
            np.max(np.abs(est_ff[-1] - ref.final_estimate) / scale)
        )
        tw, te, tn = [], [], []
        for _ in range(repeats):
            t0 = time.perf_counter()
            cl.run(sc, ns=ns)
            tw.append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            ff._core.cl_estimate(R, F, sc.dt, sc.m0, ns=ns)
            te.append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            numpy_peer(t, R, F, sc.m0, ns)
            tn.append(time.perf_counter() - t0)
        med = statistics.median
        rows.append(
            {
                "ns": ns,
                "whole_run_s": med(tw),
                "whole_run_min": min(tw),
                "whole_run_max": max(tw),
                "estimator_s": med(te),
                "estimator_min": min(te),
                "estimator_max": max(te),
                "numpy_s": med(tn),
                "numpy_min": min(tn),
                "numpy_max": max(tn),
                "ratio_estimator": med(tn) / med(te),
                "ratio_whole_run": med(tn) / med(tw),
            }
        )
        r_ = rows[-1]
        print(
            f"N_s {ns:4d}: whole run {r_['whole_run_s']:.3f} s, engine estimator {r_['estimator_s']:.4f} s, "
            f"numpy estimator {r_['numpy_s']:.3f} s: {r_['ratio_estimator']:.1f}x (whole run vs numpy estimator "
            f"{r_['ratio_whole_run']:.1f}x)"
        )
    bs = block_saving(50 if a.quick else 300)
    print(
        f"block-diagonal saving: 77x77 eigh {bs['full_77x77_us']:.1f} us vs 11 x 7x7 {bs['blocks_11x7x7_us']:.1f} us "
        f"({bs['ratio']:.1f}x)"
    )
    res = {
        "scenario": SCENARIO,
        "repeats": repeats,
        "rows": rows,
        "agreement": {str(k): v for k, v in agreement.items()},
        "block_saving": bs,
        "machine": platform.platform(),
        "when": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
        "targets": {"ns10_under_s": 0.2, "ns300_under_s": 2.0, "ratio_at_least": 10},
    }
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "cl_vs_numpy.json").write_text(json.dumps(res, indent=2))
    if a.json:
        Path(a.json).write_text(json.dumps(res, indent=1, default=str))
    md = [
        f"# freefloat vs numpy: Valverde 2018 ch. 9 concurrent learning ({res['when']})",
        "",
        f"Median of {repeats} interleaved repeats [min-max]. Estimator: the stack update and law on the same "
        "recorded data (engine vs numpy). Whole run: the engine's 10 s run including the robot simulation.",
        "",
        "| N_s | whole run [s] | engine estimator [s] | numpy estimator [s] | estimator ratio | whole run vs numpy |",
        "|---:|---:|---:|---:|---:|---:|",
    ]
    for r in rows:
        md.append(
            f"| {r['ns']} | {r['whole_run_s']:.3f} [{r['whole_run_min']:.3f}-{r['whole_run_max']:.3f}] | "
            f"{r['estimator_s']:.4f} [{r['estimator_min']:.4f}-{r['estimator_max']:.4f}] | "
            f"{r['numpy_s']:.3f} [{r['numpy_min']:.3f}-{r['numpy_max']:.3f}] | {r['ratio_estimator']:.1f} | "
            f"{r['ratio_whole_run']:.1f} |"
        )
    md += [
        "",
        f"Block-diagonal structure (numpy eigh): one 77x77 {bs['full_77x77_us']:.1f} us, eleven 7x7 batched "
        f"{bs['blocks_11x7x7_us']:.1f} us ({bs['ratio']:.1f}x; flop estimate {bs['flops_ratio_estimate']:.0f}x).",
    ]
    (out / "cl_vs_numpy.md").write_text("\n".join(md) + "\n")


if __name__ == "__main__":
    main()

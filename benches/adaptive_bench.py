#!/usr/bin/env python3
"""Speed of the ch. 4 adaptive pose tracker (Valverde 2018): the whole closed-loop simulation of example A
(continuous CL, Dormand-Prince at rtol = atol = 1e-10, 50 s) and example B (discrete CL, N_s = 50, RK4 at
0.01 s, 50 s) in freefloat's engine against a vectorised numpy/scipy implementation of the same closed loop
written from the thesis' equations (`solve_ivp` RK45 at the same tolerance for A; a numpy RK4 loop with the
same data stack for B). Interleaved repeats, medians and spread; the agreement of the two is checked first
(the script aborts when they disagree).

    python benches/adaptive_bench.py --out benches/results        # full runs
    python benches/adaptive_bench.py --quick --out /tmp/x          # 5 s runs, 1 repeat (CI smoke)
"""

from __future__ import annotations

import argparse
import json
import platform
import sys
import time
from pathlib import Path

import numpy as np

# ---------------------------------------------------------------------------------------------------------------
# The numpy peer: the closed loop of Valverde 2018 §4.2-4.5 from the equations, independent of the engine.
# Dual quaternions are 8-arrays [real (w, x, y, z), dual (w, x, y, z)].


def _qmul(a, b):
    a0, a1, a2, a3 = a
    b0, b1, b2, b3 = b
    return np.array(
        [
            a0 * b0 - a1 * b1 - a2 * b2 - a3 * b3,
            a0 * b1 + a1 * b0 + a2 * b3 - a3 * b2,
            a0 * b2 - a1 * b3 + a2 * b0 + a3 * b1,
            a0 * b3 + a1 * b2 - a2 * b1 + a3 * b0,
        ]
    )


def dmul(a, b):
    return np.concatenate([_qmul(a[:4], b[:4]), _qmul(a[4:], b[:4]) + _qmul(a[:4], b[4:])])


def dconj(a):
    return a * np.array([1, -1, -1, -1, 1, -1, -1, -1.0])


def swap(a):
    return np.concatenate([a[4:], a[:4]])


def _cross3(a, b):
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def dcross(a, b):
    """a × b of vector dual quaternions."""
    out = np.zeros(8)
    out[1:4] = _cross3(a[1:4], b[1:4])
    out[5:8] = _cross3(a[5:8], b[1:4]) + _cross3(a[1:4], b[5:8])
    return out


def mstar(v, x):
    """M(v) ⋆ x for v = [I11, I12, I13, I22, I23, I33, m]."""
    inert = np.array([[v[0], v[1], v[2]], [v[1], v[3], v[4]], [v[2], v[4], v[5]]])
    return np.concatenate([[x[0]], v[6] * x[1:4], [x[4]], inert @ x[5:8]])


def r_of(b):
    r = np.zeros((8, 7))
    r[1:4, 6] = b[1:4]
    b6, b7, b8 = b[5:8]
    r[5, 0:3] = b6, b7, b8
    r[6, [1, 3, 4]] = b6, b7, b8
    r[7, [2, 4, 5]] = b6, b7, b8
    return r


def skew8(a):
    def sk(x):
        return np.array([[0, -x[2], x[1]], [x[2], 0, -x[0]], [-x[1], x[0], 0]])

    m = np.zeros((8, 8))
    m[1:4, 1:4] = sk(a[1:4])
    m[5:8, 1:4] = sk(a[5:8])
    m[5:8, 5:8] = sk(a[1:4])
    return m


def h_of(a, b):
    return np.array(
        [
            a[5] * b[5],
            a[6] * b[5] + a[5] * b[6],
            a[7] * b[5] + a[5] * b[7],
            a[6] * b[6],
            a[7] * b[6] + a[6] * b[7],
            a[7] * b[7],
            a[1] * b[1] + a[2] * b[2] + a[3] * b[3],
        ]
    )


ONE_S = np.array([0, 0, 0, 0, 1.0, 0, 0, 0])


class Peer:
    """The closed loop of Valverde 2018, ch. 4 (adaptive pose tracking with concurrent learning) in numpy."""

    def __init__(self, sc, alpha):
        g = sc.gains
        self.kr, self.kq, self.kv, self.kw = (float(g[k]) for k in ("K_r", "K_q", "K_v", "K_w"))
        self.ki = float(g["K_i"])
        self.alpha = alpha
        self.truth = sc.truth
        v = sc.truth
        self.inert = np.array([[v[0], v[1], v[2]], [v[1], v[3], v[4]], [v[2], v[4], v[5]]])
        self.inert_inv = np.linalg.inv(self.inert)
        self.m = v[6]
        ra, rl = sc.reference["reference_angular"], sc.reference["reference_linear"]
        self.ref = (ra, rl)

    def reference(self, t):
        out, dout = np.zeros(8), np.zeros(8)
        for part, sl in zip(self.ref, (slice(1, 4), slice(5, 8))):
            o, a, w, ph = part
            out[sl] = o + a * np.sin(w * t + ph)
            dout[sl] = a * w * np.cos(w * t + ph)
        return out, dout

    def plant(self, t, q, w, vh):
        wd, wdd = self.reference(t)
        qc = dconj(q)
        wd_b = dmul(dmul(qc, wd), q)
        wdd_b = dmul(dmul(qc, wdd), q)
        wbi = w + wd_b
        e = dmul(qc, swap(q) - ONE_S)
        qdot = 0.5 * dmul(q, w)
        edot = dmul(dconj(qdot), swap(q) - ONE_S) + dmul(qc, swap(qdot))
        kpe = np.concatenate([[0], self.kr * e[1:4], [0], self.kq * e[5:8]])
        kpedot = np.concatenate([[0], self.kr * edot[1:4], [0], self.kq * edot[5:8]])
        s = w + swap(kpe)
        ss = swap(s)
        kds = np.concatenate([[0], self.kv * ss[1:4], [0], self.kw * ss[5:8]])
        cr = dcross(wd_b, w)
        vec_e = e * np.array([0, 1, 1, 1, 0, 1, 1, 1.0])
        f = -vec_e - kds + dcross(wbi, mstar(vh, swap(wbi))) + mstar(vh, swap(wdd_b) + swap(cr) - kpedot)
        rhs = (
            f - dcross(wbi, mstar(self.truth, swap(wbi))) - mstar(self.truth, swap(wdd_b)) - mstar(self.truth, swap(cr))
        )
        y = np.concatenate([[rhs[0]], rhs[1:4] / self.m, [rhs[4]], self.inert_inv @ rhs[5:8]])
        wdot = swap(y)
        adapt = -h_of(swap(dcross(s, wbi)), swap(wbi)) - h_of(ss, swap(wdd_b) + swap(cr) - kpedot)
        return dict(qdot=qdot, wdot=wdot, f=f, adapt=adapt, wdd_b=wdd_b, cr=cr, wbi=wbi)

    def regressor(self, p):
        return r_of(swap(p["wdot"] + p["wdd_b"] + p["cr"])) + skew8(p["wbi"]) @ r_of(swap(p["wbi"]))

    def rhs_continuous(self, t, x):
        q, w, vh = x[:8], x[8:16], x[16:23]
        P, Q = x[23:72].reshape(7, 7, order="F"), x[72:79]
        p = self.plant(t, q, w, vh)
        R = self.regressor(p)
        dv = self.ki * (p["adapt"] - self.alpha * (P @ vh - Q))
        return np.concatenate([p["qdot"], p["wdot"], dv, (R.T @ R).ravel(order="F"), R.T @ p["f"]])


def peer_example_a(sc, alpha, t_final, rtol, atol, output_dt):
    from scipy.integrate import solve_ivp

    peer = Peer(sc, alpha)
    x0 = np.concatenate([sc.q0, sc.w0, sc.estimate0, np.zeros(56)])
    grid = np.arange(0, t_final + 1e-9, output_dt)
    sol = solve_ivp(peer.rhs_continuous, (0, t_final), x0, method="RK45", rtol=rtol, atol=atol, t_eval=grid)
    if not sol.success:
        raise RuntimeError(sol.message)
    return sol.t, sol.y[16:23].T, sol.nfev


class PeerStack:
    """Valverde 2018 ch. 9 Algorithm 3 (element-wise singular-value test), the stop rule first."""

    def __init__(self, n_s, sigma_stop, seed):
        self.n_s, self.sigma_stop = n_s, sigma_stop
        self.rtr, self.rtf, self.tr = [], [], []
        self.RR, self.Rf, self.sv = np.zeros((7, 7)), np.zeros(7), np.zeros(7)
        self.rng = np.random.default_rng(seed)

    def _resum(self):
        self.RR = np.sum(self.rtr, axis=0)
        self.Rf = np.sum(self.rtf, axis=0)
        self.sv = np.sort(np.abs(np.linalg.eigvalsh(self.RR)))[::-1]

    def offer(self, R, f):
        if self.sv[-1] >= self.sigma_stop:
            return
        g, b = R.T @ R, R.T @ f
        if len(self.rtr) < self.n_s:
            self.rtr.append(g), self.rtf.append(b), self.tr.append(np.trace(g))
            self._resum()
            return
        tr = np.trace(g)
        for i in self.rng.permutation(self.n_s):
            if tr < self.tr[i]:
                continue
            sv = np.sort(np.abs(np.linalg.eigvalsh(self.RR - self.rtr[i] + g)))[::-1]
            if np.all(sv >= self.sv):
                self.rtr[i], self.rtf[i], self.tr[i] = g, b, tr
                self._resum()
                return


def peer_example_b(sc, alpha, t_final, dt, alpha_off_after=None, info=None):
    """Example B's closed loop in numpy. `alpha_off_after` (Remark 6): α = 0 from the first step start at least that
    long after numpy's `matrix_rank` of the stack's Σ R_kᵀR_k first reads 7; `info` (a dict) receives
    `rank7_time` and `alpha_off_time`."""
    peer = Peer(sc, alpha)
    st = PeerStack(sc.n_s, sc.sigma_stop, sc.seed)
    n = int(round(t_final / dt))
    x = np.concatenate([sc.q0, sc.w0, sc.estimate0])
    hist = np.empty((n + 1, 7))
    info = {} if info is None else info
    info.update(rank7_time=None, alpha_off_time=None)
    a = [alpha]

    def f(t, x):
        p = peer.plant(t, x[:8], x[8:16], x[16:23])
        cl = a[0] * (st.RR @ x[16:23] - st.Rf) if len(st.rtr) else 0.0
        return np.concatenate([p["qdot"], p["wdot"], peer.ki * (p["adapt"] - cl)]), p

    for k in range(n + 1):
        t = k * dt
        p = peer.plant(t, x[:8], x[8:16], x[16:23])
        st.offer(peer.regressor(p), p["f"])
        if info["rank7_time"] is None and np.linalg.matrix_rank(st.RR) == 7:
            info["rank7_time"] = t
        if alpha_off_after is not None and info["rank7_time"] is not None and info["alpha_off_time"] is None:
            if k >= round((info["rank7_time"] + alpha_off_after) / dt):
                info["alpha_off_time"], a[0] = t, 0.0
        hist[k] = x[16:23]
        if k == n:
            break
        k1, _ = f(t, x)
        k2, _ = f(t + dt / 2, x + dt / 2 * k1)
        k3, _ = f(t + dt / 2, x + dt / 2 * k2)
        k4, _ = f(t + dt, x + dt * k3)
        x = x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    return np.arange(n + 1) * dt, hist


# ---------------------------------------------------------------------------------------------------------------


def _row(title, med, spread, k):
    f, n = f"ff_{k}", f"np_{k}"
    return (
        f"| {title} | {med[f]:.3f} s ({spread[f][0]:.3f}-{spread[f][1]:.3f}) | "
        f"{med[n]:.2f} s ({spread[n][0]:.2f}-{spread[n][1]:.2f}) | {med[n] / med[f]:.0f}x |"
    )


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default="benches/results")
    ap.add_argument("--json", default=None, help="also write the results (JSON) to this file (read by run_all.py)")
    ap.add_argument("--quick", action="store_true", help="5 s runs, 1 repeat")
    ap.add_argument("--repeats", type=int, default=None)
    a = ap.parse_args(argv)
    from freefloat.control import adaptive as ad

    t_final = 5.0 if a.quick else 50.0
    repeats = a.repeats or (1 if a.quick else 5)
    sa = ad.load_scenario("valverde_ch4_example_a")
    sb = ad.load_scenario("valverde_ch4_example_b")
    sa.duration = sb.duration = t_final

    def ff_a():
        return ad.simulate(sa, 1.0)

    def ff_b():
        return ad.simulate(sb, 0.005)

    def np_a():
        return peer_example_a(sa, 1.0, t_final, sa.rtol, sa.atol, sa.output_dt)

    def np_b():
        return peer_example_b(sb, 0.005, t_final, sb.dt)

    # agreement first
    ra, pa = ff_a(), np_a()
    agree_a = float(np.max(np.abs(ra.estimate - pa[1])))
    rb, pb = ff_b(), np_b()
    agree_b = float(np.max(np.abs(rb.estimate - pb[1])))
    print(f"agreement: example A max |estimate difference| {agree_a:.2e} (two tolerance-1e-10 integrations), "
          f"example B {agree_b:.2e} (same RK4 steps)")  # fmt: skip
    if not (agree_a < 1e-6 and agree_b < 1e-9):
        print("freefloat and the numpy peer disagree; aborting", file=sys.stderr)
        return 1
    times = {k: [] for k in ("ff_a", "np_a", "ff_b", "np_b")}
    fns = {"ff_a": ff_a, "np_a": np_a, "ff_b": ff_b, "np_b": np_b}
    for _ in range(repeats):
        for k, fn in fns.items():  # interleaved
            t0 = time.perf_counter()
            fn()
            times[k].append(time.perf_counter() - t0)
    med = {k: float(np.median(v)) for k, v in times.items()}
    spread = {k: [float(min(v)), float(max(v))] for k, v in times.items()}
    res = {
        "t_final_s": t_final,
        "repeats": repeats,
        "agreement": {"example_a_max_abs": agree_a, "example_b_max_abs": agree_b},
        "median_s": med,
        "min_max_s": spread,
        "ratio_numpy_over_freefloat": {"example_a": med["np_a"] / med["ff_a"], "example_b": med["np_b"] / med["ff_b"]},
        "freefloat_steps": {"example_a": ra.steps, "example_b": rb.steps},
        "freefloat_evaluations": {"example_a": ra.evaluations, "example_b": rb.evaluations},
        "numpy_evaluations_example_a": pa[2],
        "machine": platform.platform(),
        "python": sys.version.split()[0],
    }
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "adaptive_bench.json").write_text(json.dumps(res, indent=1))
    if a.json:
        Path(a.json).write_text(json.dumps(res, indent=1, default=str))
    lines = [
        "# ch. 4 adaptive pose tracking: freefloat vs numpy/scipy",
        "",
        f"{t_final:g} s simulated, {repeats} interleaved repeats, median (min-max)",
        "",
        "| run | freefloat | numpy/scipy | ratio |",
        "|---|---|---|---|",
        _row("example A (continuous CL, DOPRI5 1e-10)", med, spread, "a"),
        _row("example B (discrete CL N_s = 50, RK4 0.01 s)", med, spread, "b"),
    ]
    (out / "adaptive_bench.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main())

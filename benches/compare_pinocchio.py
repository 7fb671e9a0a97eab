#!/usr/bin/env python3
"""freefloat vs Pinocchio / Crocoddyl on the same robot, timed in one run.

The robot is the built-in `naveen_dual_arm` (free base + two 3R arms + three reaction wheels; nq = 16,
nv = 15). Pinocchio gets it through freefloat's URDF export (`Model.to_urdf`), loaded with
`pin.buildModelFromUrdf(path, pin.JointModelFreeFlyer())` and zero gravity. The export writes the
unlimited revolute joints as URDF `continuous`, which Pinocchio turns into unbounded revolute joints with
(cos, sin) coordinates (nq = 25); for timing, the joints are rewritten as `revolute` with wide limits so
both libraries use the same q layout. Both versions are checked against `ff.aba` before anything is
timed (abort above 1e-9).

What is timed (wall clock, `time.perf_counter`; each measurement repeated, median and min reported,
repeats interleaved between the libraries so machine noise hits both alike):

1. core-to-core per call: one freefloat call on a stacked batch of N states, divided by N, against
   Pinocchio's batched C++ entry points `abaInParallel` / `rneaInParallel` with one thread. Pinocchio
   has no batched crba / centroidal momentum, so those rows compare against single calls from Python
   (marked "py-loop").
2. single call from Python: a `for` loop of calls with fixed inputs, per call.
3. a 10 s, 1 kHz RK4 simulation with sinusoidal torques on the six arm joints (wheels unactuated):
   ff.simulate with a torque table sampled at dt/2 (linear hold) and with a Python callable, against a
   naive Lie-group RK4 loop on Pinocchio written in Python and Crocoddyl's C++ RK4
   (`IntegratedActionModelRK`, one C++ step per Python call). Momentum drift of each run is computed
   afterwards with Pinocchio (independent of freefloat) and reported.

    python benches/compare_pinocchio.py                # full run (about 1-2 minutes)
    python benches/compare_pinocchio.py --quick        # smoke test (a few seconds of timing)
    python benches/compare_pinocchio.py --out /tmp/r   # write compare_pinocchio.{json,md} there

Needs `pin==4.0.0 libpinocchio==4.0.0 crocoddyl==3.2.1` (installed together; see BENCHMARKS.md).
"""

from __future__ import annotations

import argparse
import gc
import json
import os
import platform
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

MODEL = "naveen_dual_arm"

# Scenario of the simulation comparison (same as crates/freefloat-core/benches/dynamics.rs).
AMP = np.array([20.0, 15.0, 8.0, 20.0, 12.0, 10.0])  # N·m
FREQ = np.array([0.20, 0.30, 0.50, 0.25, 0.35, 0.45])  # Hz
PHASE = np.array([0.0, 0.5, 1.0, 1.5, 2.0, 2.5])  # rad
ARM_V = slice(6, 12)  # v indices of J1..J6 (wheels Wx, Wy, Wz are 12..14)

TARGETS = {
    "aba_core_vs_abaInParallel": "ff aba per call (batched) no slower than Pinocchio abaInParallel (1 thread)",
    "sim_vs_crocoddyl_rollout": "simulation >= 5x faster than Crocoddyl's RK4 rollout (ShootingProblem.rollout)",
    "sim_vs_crocoddyl": "simulation >= 5x faster than Crocoddyl's RK4 stepped one C++ step per Python call",
    "sim_vs_pin_python": "simulation >= 20x faster than the Python Pinocchio RK4 loop",
}


# ---------------------------------------------------------------------------------------------------
# set-up
# ---------------------------------------------------------------------------------------------------


def parse_args(argv=None):
    p = argparse.ArgumentParser(
        description="Time freefloat against Pinocchio (batched C++ and single Python calls) and against "
        "Pinocchio/Crocoddyl RK4 simulation loops, on the same robot, in one run. Prints a markdown "
        "report and writes compare_pinocchio.json and compare_pinocchio.md.",
    )
    p.add_argument(
        "--quick",
        action="store_true",
        help="smoke test: 2 repeats, small batch (2000), 2000 single calls, 1 s simulation",
    )
    p.add_argument(
        "--out",
        type=Path,
        default=None,
        help="output directory (default: benches/results next to this script; with --quick, "
        "benches/results/quick so a smoke test never overwrites the full results)",
    )
    p.add_argument("--repeats", type=int, default=None, help="repeats of every measurement (default 5; quick 2)")
    p.add_argument("--batch", type=int, default=None, help="batch size N for the core-to-core rows (default 20000)")
    p.add_argument("--calls", type=int, default=None, help="single calls per repeat (default 20000)")
    p.add_argument("--t-final", type=float, default=None, help="simulated time in s (default 10)")
    p.add_argument("--dt", type=float, default=1e-3, help="RK4 step (default 1e-3)")
    p.add_argument("--seed", type=int, default=0, help="random seed for the states")
    p.add_argument("--json", default=None, help="also write the results (JSON) to this file (read by run_all.py)")
    a = p.parse_args(argv)
    a.repeats = a.repeats or (2 if a.quick else 5)
    a.batch = a.batch or (2000 if a.quick else 20000)
    a.calls = a.calls or (2000 if a.quick else 20000)
    a.t_final = a.t_final or (1.0 if a.quick else 10.0)
    if a.out is None:
        a.out = Path(__file__).resolve().parent / "results" / ("quick" if a.quick else "")
    return a


def build_models(tmpdir: Path):
    """(ff model, Pinocchio model with revolute joints, Pinocchio model as exported (continuous))."""
    import pinocchio as pin

    import freefloat as ff

    m = ff.models.load(MODEL)
    raw = tmpdir / f"{MODEL}.urdf"
    m.to_urdf(raw)
    text = raw.read_text()
    n_cont = text.count('type="continuous"')
    # URDF requires <limit> on a revolute joint; the export writes none for unlimited joints, so give
    # the revolute version wide ones (limits play no part in aba/rnea/crba/simulation).
    import re

    text = re.sub(
        r'type="continuous">',
        'type="revolute">\n    <limit lower="-1e6" upper="1e6" velocity="1e6" effort="1e6"/>',
        text,
    )
    rev = tmpdir / f"{MODEL}_revolute.urdf"
    rev.write_text(text)

    pm_raw = pin.buildModelFromUrdf(str(raw), pin.JointModelFreeFlyer())
    pm = pin.buildModelFromUrdf(str(rev), pin.JointModelFreeFlyer())
    for p in (pm, pm_raw):
        p.gravity = pin.Motion.Zero()
    if (pm.nq, pm.nv) != (m.nq, m.nv):
        raise SystemExit(f"Pinocchio model has nq={pm.nq}, nv={pm.nv}; freefloat has nq={m.nq}, nv={m.nv}")
    if list(pm.names)[1:] != list(m.joint_names):
        raise SystemExit(f"joint order differs: pin {list(pm.names)[1:]} vs ff {list(m.joint_names)}")
    return m, pm, pm_raw, n_cont


def q_to_unbounded(pm_raw, q):
    """Map our q (revolute angles) to the exported model's q ((cos, sin) per continuous joint)."""
    out = np.zeros(pm_raw.nq)
    out[:7] = q[:7]
    for jid in range(2, pm_raw.njoints):
        j = pm_raw.joints[jid]
        ang = q[7 + (j.idx_v - 6)]
        if j.nq == 2:
            out[j.idx_q : j.idx_q + 2] = (np.cos(ang), np.sin(ang))
        else:
            out[j.idx_q] = ang
    return out


def check_agreement(m, pm, pm_raw, rng, n=5, tol=1e-9):
    """pin.aba == ff.aba (and rnea, crba, momentum) on random states; abort otherwise."""
    import pinocchio as pin

    import freefloat as ff

    pd, pd_raw = pm.createData(), pm_raw.createData()
    worst = {}

    def rel(a, b):
        return float(np.abs(np.asarray(a) - np.asarray(b)).max() / max(1.0, np.abs(np.asarray(b)).max()))

    for _ in range(n):
        q = m.random_configuration(rng)
        v = rng.normal(size=m.nv)
        tau = 10 * rng.normal(size=m.nv)
        a = rng.normal(size=m.nv)
        h = pin.computeCentroidalMomentum(pm, pd, q, v)
        c = pd.com[0].copy()
        mom_pin = np.r_[h.linear, h.angular + np.cross(c, h.linear)]
        errs = {
            "aba": rel(ff.aba(m, q, v, tau), pin.aba(pm, pd, q, v, tau)),
            "aba (exported URDF as is, continuous joints)": rel(
                ff.aba(m, q, v, tau), pin.aba(pm_raw, pd_raw, q_to_unbounded(pm_raw, q), v, tau)
            ),
            "rnea": rel(ff.rnea(m, q, v, a), pin.rnea(pm, pd, q, v, a)),
            "crba": rel(ff.crba(m, q), pin.crba(pm, pd, q)),
            "momentum": rel(ff.momentum(m, q, v), mom_pin),
        }
        for k, e in errs.items():
            worst[k] = max(worst.get(k, 0.0), e)
    bad = {k: e for k, e in worst.items() if not e <= tol}
    if bad:
        raise SystemExit(f"ABORT: freefloat and Pinocchio disagree on {MODEL}: {bad} (tolerance {tol})")
    return worst


def environment():
    import pinocchio as pin

    import freefloat as ff

    try:
        import crocoddyl

        croc = crocoddyl.__version__
    except ImportError as e:
        croc = f"unavailable ({e})"
    cpu = platform.processor() or ""
    try:
        with open("/proc/cpuinfo") as f:
            cpu = next((ln.split(":", 1)[1].strip() for ln in f if ln.startswith("model name")), cpu)
    except OSError:
        pass
    git = None
    try:
        import subprocess

        root = Path(__file__).resolve().parent.parent
        head = subprocess.run(
            ["git", "-C", str(root), "rev-parse", "--short", "HEAD"], capture_output=True, text=True, check=False
        ).stdout.strip()
        dirty = subprocess.run(
            ["git", "-C", str(root), "status", "--porcelain", "--untracked-files=no"],
            capture_output=True,
            text=True,
            check=False,
        ).stdout.strip()
        git = head + ("+dirty" if dirty else "") if head else None
    except OSError:
        pass
    return {
        "git": git,
        "python": sys.version.split()[0],
        "platform": platform.platform(),
        "cpu": cpu,
        "nproc": os.cpu_count(),
        "loadavg_start": os.getloadavg() if hasattr(os, "getloadavg") else None,
        "freefloat": ff.__version__,
        "pinocchio": pin.__version__,
        "crocoddyl": croc,
        "numpy": np.__version__,
    }


# ---------------------------------------------------------------------------------------------------
# timing helpers
# ---------------------------------------------------------------------------------------------------


def _clock(fn):
    gc.collect()
    gc.disable()
    try:
        t0, c0 = time.perf_counter(), time.process_time()
        out = fn()
        t1, c1 = time.perf_counter(), time.process_time()
    finally:
        gc.enable()
    return t1 - t0, c1 - c0, out


def run_interleaved(cases: dict, repeats: int, per: dict):
    """cases: name -> zero-arg callable; per: name -> divisor (calls per measurement).
    Returns name -> {"wall": [...], "cpu": [...]} in seconds per call; one warm-up call each."""
    for f in cases.values():
        f()
    res = {k: {"wall": [], "cpu": []} for k in cases}
    for _ in range(repeats):
        for k, f in cases.items():
            w, c, _ = _clock(f)
            res[k]["wall"].append(w / per[k])
            res[k]["cpu"].append(c / per[k])
    return res


def summary(samples):
    return {
        "median": statistics.median(samples["wall"]),
        "min": min(samples["wall"]),
        "max": max(samples["wall"]),
        "cpu_median": statistics.median(samples["cpu"]),
        "wall": samples["wall"],
    }


# ---------------------------------------------------------------------------------------------------
# 1 + 2: algorithms
# ---------------------------------------------------------------------------------------------------


def bench_algorithms(m, pm, args, rng):
    import pinocchio as pin

    import freefloat as ff

    N, C, R = args.batch, args.calls, args.repeats
    Q = np.array([m.random_configuration(rng) for _ in range(N)])
    V = rng.normal(size=(N, m.nv))
    T = 10 * rng.normal(size=(N, m.nv))
    # Pinocchio's batch API takes one state per column.
    Qc, Vc, Tc = (np.asfortranarray(X.T) for X in (Q, V, T))
    pool = pin.ModelPool(pm, 1)
    out_nv = np.zeros((m.nv, N), order="F")

    got = pin.abaInParallel(1, pool, Qc, Vc, Tc)
    err = float(np.abs(got.T - ff.aba(m, Q, V, T)).max())
    if not err <= 1e-9 * max(1.0, np.abs(got).max()):
        raise SystemExit(f"ABORT: abaInParallel and ff.aba (batch) differ by {err}")

    def pin_loop(fn):
        def run():
            for k in range(N):
                fn(k)

        return run

    pd = pm.createData()
    batch = {
        "ff aba": lambda: ff.aba(m, Q, V, T),
        "pin abaInParallel": lambda: pin.abaInParallel(1, pool, Qc, Vc, Tc, out_nv),
        "ff rnea": lambda: ff.rnea(m, Q, V, T),
        "pin rneaInParallel": lambda: pin.rneaInParallel(1, pool, Qc, Vc, Tc, out_nv),
        "ff crba": lambda: ff.crba(m, Q),
        "ff momentum": lambda: ff.momentum(m, Q, V),
        "ff centroidal_momentum_matrix": lambda: ff.centroidal_momentum_matrix(m, Q),
    }
    # A (N, nv, nv) result is N * 1.8 kB (36 MB for N = 20000), so the big-batch crba measures memory
    # traffic as much as the algorithm; a cache-sized batch shows the algorithm alone.
    n_small = min(N, 1000)
    Qs = Q[:n_small].copy()
    batch[f"ff crba, N={n_small}"] = lambda: ff.crba(m, Qs)
    per = {k: N for k in batch}
    per[f"ff crba, N={n_small}"] = n_small
    res_batch = run_interleaved(batch, R, per)

    q, v, tau = Q[0].copy(), V[0].copy(), T[0].copy()

    def loop(f):
        def run():
            for _ in range(C):
                f()

        return run

    single = {
        "ff aba": loop(lambda: ff.aba(m, q, v, tau)),
        "pin aba": loop(lambda: pin.aba(pm, pd, q, v, tau)),
        "ff rnea": loop(lambda: ff.rnea(m, q, v, tau)),
        "pin rnea": loop(lambda: pin.rnea(pm, pd, q, v, tau)),
        "ff crba": loop(lambda: ff.crba(m, q)),
        "pin crba": loop(lambda: pin.crba(pm, pd, q)),
        "ff momentum": loop(lambda: ff.momentum(m, q, v)),
        "pin computeCentroidalMomentum": loop(lambda: pin.computeCentroidalMomentum(pm, pd, q, v)),
        "ff centroidal_momentum_matrix": loop(lambda: ff.centroidal_momentum_matrix(m, q)),
        "pin computeCentroidalMap": loop(lambda: pin.computeCentroidalMap(pm, pd, q)),
        "empty Python loop + lambda": loop(lambda: None),
    }
    # The loop bodies call a lambda; the "empty" row measures that overhead (included in every row).
    res_single = run_interleaved(single, R, {k: C for k in single})
    return {k: summary(s) for k, s in res_batch.items()}, {k: summary(s) for k, s in res_single.items()}


# ---------------------------------------------------------------------------------------------------
# 3: simulation
# ---------------------------------------------------------------------------------------------------


def initial_state(m):
    q = m.neutral()
    q[0:3] = (0.5, -0.2, 0.1)
    ax = np.array([0.3, -0.5, 0.8])
    ax /= np.linalg.norm(ax)
    q[3:7] = np.r_[np.sin(0.3) * ax, np.cos(0.3)]  # 0.6 rad about ax, (x, y, z, w)
    v = np.zeros(m.nv)
    v[0:6] = (0.01, -0.02, 0.005, 0.01, 0.02, -0.015)
    v[ARM_V] = (0.05, -0.1, 0.08, -0.05, 0.1, -0.07)
    return q, v


def torque(t, nv):
    out = np.zeros(nv)
    out[ARM_V] = AMP * np.sin(2 * np.pi * FREQ * t + PHASE)
    return out


def torque_table(t_final, dt, nv):
    times = np.arange(round(2 * t_final / dt) + 1) * (dt / 2)
    vals = np.zeros((len(times), nv))
    vals[:, ARM_V] = AMP * np.sin(2 * np.pi * FREQ * times[:, None] + PHASE)
    return times, vals


def sim_ff_table(m, q0, v0, t_final, dt):
    import freefloat as ff

    times, vals = torque_table(t_final, dt, m.nv)  # built inside the timing (it is part of the cost)
    traj = ff.simulate(m, q0, v0, t_final=t_final, dt=dt, method="rk4", torques=vals, torque_times=times, hold="linear")
    return traj.q, traj.v, traj


def sim_ff_callable(m, q0, v0, t_final, dt):
    import freefloat as ff

    nv = m.nv

    def tau(t, q, v):
        out = np.zeros(nv)
        out[ARM_V] = AMP * np.sin(2 * np.pi * FREQ * t + PHASE)
        return out

    traj = ff.simulate(m, q0, v0, t_final=t_final, dt=dt, method="rk4", torques=tau)
    return traj.q, traj.v, traj


def sim_pin_python(pm, q0, v0, t_final, dt):
    """Naive Lie-group RK4 (stages at q ⊕ c·dt·v_i, one tangent increment): 4 aba + 4 integrate per step."""
    import pinocchio as pin

    d = pm.createData()
    nv = pm.nv
    n = round(t_final / dt)
    aba, integ = pin.aba, pin.integrate
    q, v = q0.copy(), v0.copy()
    Qs, Vs = [q], [v]
    h2, h6 = dt / 2, dt / 6
    for k in range(n):
        t = k * dt
        u1 = torque(t, nv)
        u2 = torque(t + h2, nv)
        u4 = torque(t + dt, nv)
        a1 = aba(pm, d, q, v, u1)
        v2 = v + h2 * a1
        a2 = aba(pm, d, integ(pm, q, h2 * v), v2, u2)
        v3 = v + h2 * a2
        a3 = aba(pm, d, integ(pm, q, h2 * v2), v3, u2)
        v4 = v + dt * a3
        a4 = aba(pm, d, integ(pm, q, dt * v3), v4, u4)
        q = integ(pm, q, h6 * (v + 2 * v2 + 2 * v3 + v4))
        v = v + h6 * (a1 + 2 * a2 + 2 * a3 + a4)
        Qs.append(q)
        Vs.append(v)
    return np.array(Qs), np.array(Vs), None


def make_croc(pm, dt, poly_two):
    import crocoddyl

    state = crocoddyl.StateMultibody(pm)
    act = crocoddyl.ActuationModelFloatingBase(state)
    if act.nu != pm.nv - 6:
        raise SystemExit(
            f"crocoddyl actuation has nu={act.nu}, expected {pm.nv - 6} (free-flyer name must be root_joint)"
        )
    costs = crocoddyl.CostModelSum(state, act.nu)
    dam = crocoddyl.DifferentialActionModelFreeFwdDynamics(state, act, costs)
    if poly_two:
        cp = crocoddyl.ControlParametrizationModelPolyTwoRK(act.nu, crocoddyl.RKType.four)
        iam = crocoddyl.IntegratedActionModelRK(dam, cp, crocoddyl.RKType.four, dt)
    else:
        iam = crocoddyl.IntegratedActionModelRK(dam, crocoddyl.RKType.four, dt)
    return iam


def sim_crocoddyl(pm, q0, v0, t_final, dt, poly_two=False):
    """One C++ RK4 step per Python call. Default control parametrization: u held over the step, set
    to the torque at mid-step (as in our earlier Pinocchio baseline). poly_two: quadratic control
    through (t, t+dt/2, t+dt), i.e. the exact stage torques, the same forcing as the other runs."""
    iam = make_croc(pm, dt, poly_two)
    d = iam.createData()
    nv = pm.nv
    n = round(t_final / dt)
    x = np.r_[q0, v0]
    Xs = [x]
    for k in range(n):
        t = k * dt
        if poly_two:
            u = np.concatenate([torque(t, nv)[6:], torque(t + dt / 2, nv)[6:], torque(t + dt, nv)[6:]])
        else:
            u = torque(t + dt / 2, nv)[6:]
        iam.calc(d, x, u)
        x = d.xnext.copy()
        Xs.append(x)
    X = np.array(Xs)
    return X[:, : pm.nq], X[:, pm.nq :], None


_PROBLEMS = {}


def poly_two_controls(t, dt, nv):
    """PolyTwoRK controls [u(t), u(t+dt/2), u(t+dt)] (arm joints) for every start time in t, built
    with array operations (as freefloat's torque table is) so Python does not dominate the timing."""
    cols = []
    for off in (0.0, dt / 2, dt):
        full = np.zeros((len(t), nv))
        full[:, ARM_V] = AMP * np.sin(2 * np.pi * FREQ * (t[:, None] + off) + PHASE)
        cols.append(full[:, 6:])
    return list(np.hstack(cols))


def sim_crocoddyl_rollout_prebuilt(pm, q0, v0, t_final, dt, chunk=1000):
    """As `sim_crocoddyl_rollout`, but the 1000-node problem is built once, outside the timing, and
    re-used for every chunk (x0 reset): the cost of Crocoddyl's C++ stepping alone."""
    import crocoddyl

    nv, n = pm.nv, round(t_final / dt)
    x = np.r_[q0, v0]
    key = (id(pm), dt, chunk)
    if key not in _PROBLEMS:
        iam = make_croc(pm, dt, poly_two=True)
        _PROBLEMS[key] = crocoddyl.ShootingProblem(x, [iam] * chunk, iam)
        return None  # first call only builds (see bench_simulation)
    problem = _PROBLEMS[key]
    Xs = [x[None]]
    for start in range(0, n, chunk):
        k = min(chunk, n - start)
        t = (start + np.arange(k)) * dt
        us = poly_two_controls(t, dt, nv)
        us += [us[-1]] * (chunk - k)  # a short last chunk: pad, and keep only its k steps
        problem.x0 = x
        xs = problem.rollout(us)
        Xs.append(np.array(xs[1 : k + 1]))
        x = np.array(xs[k])
    X = np.vstack(Xs)
    return X[:, : pm.nq], X[:, pm.nq :], None


def sim_crocoddyl_rollout(pm, q0, v0, t_final, dt, chunk=1000):
    """Crocoddyl's own C++ loop: ShootingProblem.rollout with PolyTwoRK control (the exact stage
    torques, as the ff table run). A 10 000-node problem takes about 9 GB (measured), so the
    horizon is rolled out in chunks of `chunk` nodes, each starting where the previous ended; the
    per-step work is the same. Controls are built inside the timing, as freefloat's torque table is."""
    import crocoddyl

    iam = make_croc(pm, dt, poly_two=True)
    nv, n = pm.nv, round(t_final / dt)
    x = np.r_[q0, v0]
    Xs = [x[None]]
    for start in range(0, n, chunk):
        k = min(chunk, n - start)
        t = (start + np.arange(k)) * dt
        us = poly_two_controls(t, dt, nv)
        problem = crocoddyl.ShootingProblem(x, [iam] * k, iam)
        xs = problem.rollout(us)
        Xs.append(np.array(xs[1:]))
        x = np.array(xs[-1])
    X = np.vstack(Xs)
    return X[:, : pm.nq], X[:, pm.nq :], None


def pin_momentum(pm, Q, V):
    """[p; L about the inertial origin] at every sample, with Pinocchio (independent of freefloat)."""
    import pinocchio as pin

    d = pm.createData()
    out = np.empty((len(Q), 6))
    for k in range(len(Q)):
        h = pin.computeCentroidalMomentum(pm, d, Q[k], V[k])
        p = h.linear
        out[k, :3] = p
        out[k, 3:] = h.angular + np.cross(d.com[0], p)
    return out


def drift(H):
    return {
        "linear_abs": float(np.linalg.norm(H[:, :3] - H[0, :3], axis=1).max()),
        "angular_abs": float(np.linalg.norm(H[:, 3:] - H[0, 3:], axis=1).max()),
    }


def bench_simulation(m, pm, args):
    import pinocchio as pin

    q0, v0 = initial_state(m)
    tf, dt = args.t_final, args.dt
    cases = {
        "ff.simulate, torque table (dt/2, linear hold)": lambda: sim_ff_table(m, q0, v0, tf, dt),
        "ff.simulate, Python callable torques": lambda: sim_ff_callable(m, q0, v0, tf, dt),
        "Pinocchio RK4 loop in Python (naive Lie-group RK4)": lambda: sim_pin_python(pm, q0, v0, tf, dt),
        "Crocoddyl IntegratedActionModelRK(four), u held at mid-step": lambda: sim_crocoddyl(pm, q0, v0, tf, dt),
        "Crocoddyl IntegratedActionModelRK(four), PolyTwoRK control": lambda: sim_crocoddyl(pm, q0, v0, tf, dt, True),
        "Crocoddyl ShootingProblem.rollout (C++ loop, PolyTwoRK, 1000-node chunks)": lambda: sim_crocoddyl_rollout(
            pm, q0, v0, tf, dt
        ),
        "Crocoddyl rollout alone (1000-node problem built outside the timing)": lambda: sim_crocoddyl_rollout_prebuilt(
            pm, q0, v0, tf, dt
        ),
    }
    sim_crocoddyl_rollout_prebuilt(pm, q0, v0, tf, dt)  # build the re-used problem before timing
    # Time (interleaved repeats), keeping the last output of each for the accuracy columns.
    last = {}

    def keep(k, f):
        def run():
            last[k] = f()

        return run

    res = run_interleaved({k: keep(k, f) for k, f in cases.items()}, args.repeats, {k: 1 for k in cases})
    out = {}
    ref_q = last[next(iter(cases))][0]
    for k, s in res.items():
        Q, V, traj = last[k]
        H = pin_momentum(pm, Q, V)
        row = summary(s)
        row["steps"] = len(Q) - 1
        row["us_per_step"] = row["median"] / row["steps"] * 1e6
        row["realtime_factor"] = tf / row["median"]
        row["drift_pin"] = drift(H)
        if traj is not None:
            row["drift_ff_own"] = traj.momentum_drift()
        # difference of the final configuration from the ff table run (same forcing => tiny)
        row["final_q_diff_vs_ff"] = float(np.linalg.norm(pin.difference(pm, ref_q[-1], Q[-1])))
        out[k] = row
    out["_initial_momentum"] = {
        "p_norm": float(np.linalg.norm(pin_momentum(pm, q0[None], v0[None])[0, :3])),
        "L_norm": float(np.linalg.norm(pin_momentum(pm, q0[None], v0[None])[0, 3:])),
    }
    return out


# ---------------------------------------------------------------------------------------------------
# report
# ---------------------------------------------------------------------------------------------------


def us(x):
    return f"{x * 1e6:.2f}"


def make_report(env, args, agree, batch, single, sim, ratios, checks):
    L = []
    L.append(f"# freefloat vs Pinocchio / Crocoddyl — `{MODEL}` (nq = 16, nv = 15)\n")
    L.append(
        f"Run: {time.strftime('%Y-%m-%d %H:%M:%S')}, {env['cpu']}, {env['nproc']} CPUs, "
        f"load average at start {tuple(round(x, 2) for x in env['loadavg_start'])}, "
        f"at end {tuple(round(x, 2) for x in env['loadavg_end'])}. "
        f"freefloat {env['freefloat']} (git {env['git']}), pin {env['pinocchio']}, crocoddyl {env['crocoddyl']}, "
        f"numpy {env['numpy']}, Python {env['python']}."
        + (" **--quick run (smoke test; numbers not meaningful).**" if args.quick else "")
        + "\n"
    )
    L.append(
        f"Repeats: {args.repeats} (interleaved). Batch N = {args.batch}; single-call loops of {args.calls} calls. "
        f"Agreement with Pinocchio before timing (max relative error): "
        + ", ".join(f"{k} {v:.1e}" for k, v in agree.items())
        + ".\n"
    )

    L.append("## Core-to-core: µs per call (batched)\n")
    L.append("| algorithm | freefloat batch median | min | Pinocchio | median | min | ff / pin (median) |")
    L.append("|---|---:|---:|---|---:|---:|---:|")
    pairs = [
        ("aba", "ff aba", "pin abaInParallel", batch, "abaInParallel(1 thread)"),
        ("rnea", "ff rnea", "pin rneaInParallel", batch, "rneaInParallel(1 thread)"),
        ("crba", "ff crba", "pin crba", single, "crba, py-loop (no batched API)"),
        (
            "momentum",
            "ff momentum",
            "pin computeCentroidalMomentum",
            single,
            "computeCentroidalMomentum, py-loop (no batched API)",
        ),
        (
            "centroidal momentum matrix",
            "ff centroidal_momentum_matrix",
            "pin computeCentroidalMap",
            single,
            "computeCentroidalMap, py-loop (no batched API)",
        ),
    ]
    for name, fk, pk, src, plabel in pairs:
        f, p = batch[fk], src[pk]
        L.append(
            f"| {name} | {us(f['median'])} | {us(f['min'])} | {plabel} | {us(p['median'])} | {us(p['min'])} | "
            f"{f['median'] / p['median']:.2f} |"
        )
        if name == "crba":
            small = next(k for k in batch if k.startswith("ff crba, N="))
            f = batch[small]
            L.append(
                f"| crba, batch {small.split('N=')[1]} (output fits in cache) | {us(f['median'])} | {us(f['min'])} | "
                f"(same) | {us(p['median'])} | {us(p['min'])} | {f['median'] / p['median']:.2f} |"
            )
    L.append("")
    L.append(
        "Pinocchio has batched C++ entry points only for aba and rnea; the other rows compare freefloat's batch "
        "against single Pinocchio calls from a Python loop, so those Pinocchio figures overstate its C++ cost "
        "by the binding overhead (about 0.4-0.9 µs per call). `computeCentroidalMomentum` and "
        "`computeCentroidalMap` work about the centre of mass, freefloat about the inertial origin (one extra "
        "shift). abaInParallel/rneaInParallel write into a preallocated output; freefloat allocates its result.\n"
    )
    L.append("## Single call from Python: µs per call\n")
    L.append("| algorithm | freefloat median | min | Pinocchio call | median | min | ff / pin (median) |")
    L.append("|---|---:|---:|---|---:|---:|---:|")
    for name, fk, pk in [
        ("aba", "ff aba", "pin aba"),
        ("rnea", "ff rnea", "pin rnea"),
        ("crba", "ff crba", "pin crba"),
        ("momentum", "ff momentum", "pin computeCentroidalMomentum"),
        ("centroidal momentum matrix", "ff centroidal_momentum_matrix", "pin computeCentroidalMap"),
    ]:
        f, p = single[fk], single[pk]
        L.append(
            f"| {name} | {us(f['median'])} | {us(f['min'])} | `{pk[4:]}` | {us(p['median'])} | {us(p['min'])} | "
            f"{f['median'] / p['median']:.2f} |"
        )
    e = single["empty Python loop + lambda"]
    L.append(f"| (empty loop + lambda, included above) | {us(e['median'])} | {us(e['min'])} | | | | |")
    L.append("")
    L.append(f"## Simulation: {args.t_final:g} s at dt = {args.dt:g} s, RK4, sinusoidal arm torques\n")
    im = sim["_initial_momentum"]
    L.append(
        f"Initial |p| = {im['p_norm']:.3f} kg·m/s, |L_O| = {im['L_norm']:.3f} kg·m²/s. Drift = max over all steps of "
        "‖p(t) − p(0)‖ and ‖L_O(t) − L_O(0)‖, computed with Pinocchio from the returned states. "
        "‖Δq_end‖ = ‖difference(q_end, q_end of the ff table run)‖.\n"
    )
    L.append("| method | wall median [s] | min [s] | µs/step | × real time | max‖Δp‖ | max‖ΔL_O‖ | ‖Δq_end‖ vs ff |")
    L.append("|---|---:|---:|---:|---:|---:|---:|---:|")
    for k, r in sim.items():
        if k.startswith("_"):
            continue
        L.append(
            f"| {k} | {r['median']:.4f} | {r['min']:.4f} | {r['us_per_step']:.1f} | {r['realtime_factor']:.0f} | "
            f"{r['drift_pin']['linear_abs']:.2e} | {r['drift_pin']['angular_abs']:.2e} | "
            f"{r['final_q_diff_vs_ff']:.1e} |"
        )
    L.append("")
    L.append("## Ratios (same run; > 1 means freefloat is faster)\n")
    L.append("| comparison | median ratio | min ratio | target | met? |")
    L.append("|---|---:|---:|---|---|")
    for k, r in ratios.items():
        L.append(f"| {r['label']} | {r['median']:.2f} | {r['min']:.2f} | {r.get('target', '')} | {checks.get(k, '')} |")
    L.append("")
    return "\n".join(L)


def main(argv=None):
    args = parse_args(argv)
    import pinocchio as pin  # noqa: F401

    import freefloat as ff  # noqa: F401

    env = environment()
    rng = np.random.default_rng(args.seed)
    with tempfile.TemporaryDirectory() as td:
        m, pm, pm_raw, n_cont = build_models(Path(td))
    agree = check_agreement(m, pm, pm_raw, rng)
    print(f"[compare_pinocchio] models agree: {agree}", file=sys.stderr)

    t0 = time.perf_counter()
    batch, single = bench_algorithms(m, pm, args, rng)
    print(f"[compare_pinocchio] algorithms timed in {time.perf_counter() - t0:.1f} s", file=sys.stderr)
    t0 = time.perf_counter()
    sim = bench_simulation(m, pm, args)
    print(f"[compare_pinocchio] simulations timed in {time.perf_counter() - t0:.1f} s", file=sys.stderr)
    env["loadavg_end"] = os.getloadavg() if hasattr(os, "getloadavg") else None

    def ratio(slow, fast, label, target=None):
        r = {"median": slow["median"] / fast["median"], "min": slow["min"] / fast["min"], "label": label}
        if target:
            r["target"] = target
        return r

    ft = sim["ff.simulate, torque table (dt/2, linear hold)"]
    fc = sim["ff.simulate, Python callable torques"]
    pl = sim["Pinocchio RK4 loop in Python (naive Lie-group RK4)"]
    cr = sim["Crocoddyl IntegratedActionModelRK(four), u held at mid-step"]
    cr2 = sim["Crocoddyl IntegratedActionModelRK(four), PolyTwoRK control"]
    cro = sim["Crocoddyl ShootingProblem.rollout (C++ loop, PolyTwoRK, 1000-node chunks)"]
    crp = sim["Crocoddyl rollout alone (1000-node problem built outside the timing)"]
    ratios = {
        "aba_core_vs_abaInParallel": ratio(
            batch["pin abaInParallel"], batch["ff aba"], "aba: abaInParallel / ff batch", ">= 1"
        ),
        "rnea_core_vs_rneaInParallel": ratio(
            batch["pin rneaInParallel"], batch["ff rnea"], "rnea: rneaInParallel / ff batch"
        ),
        "aba_single": ratio(single["pin aba"], single["ff aba"], "aba single call: pin / ff"),
        "rnea_single": ratio(single["pin rnea"], single["ff rnea"], "rnea single call: pin / ff"),
        "crba_single": ratio(single["pin crba"], single["ff crba"], "crba single call: pin / ff"),
        "momentum_single": ratio(
            single["pin computeCentroidalMomentum"], single["ff momentum"], "momentum single call: pin / ff"
        ),
        "sim_vs_crocoddyl_rollout": ratio(
            cro, ft, "sim: Crocoddyl C++ rollout incl. problem construction / ff table", ">= 5"
        ),
        "sim_vs_crocoddyl_rollout_alone": ratio(
            crp, ft, "sim: Crocoddyl C++ rollout alone (problem pre-built) / ff table", ">= 5"
        ),
        "sim_vs_crocoddyl": ratio(cr, ft, "sim: Crocoddyl RK4 stepped from Python (mid-step u) / ff table", ">= 5"),
        "sim_vs_pin_python": ratio(pl, ft, "sim: Pinocchio Python RK4 loop / ff table", ">= 20"),
        "sim_callable_vs_crocoddyl": ratio(cr, fc, "sim: Crocoddyl RK4 (mid-step u) / ff callable"),
        "sim_callable_vs_pin_python": ratio(pl, fc, "sim: Pinocchio Python RK4 loop / ff callable"),
        "sim_vs_crocoddyl_polytwo": ratio(cr2, ft, "sim: Crocoddyl RK4 (PolyTwoRK) / ff table"),
    }
    thresholds = {
        "aba_core_vs_abaInParallel": 1.0,
        "sim_vs_crocoddyl_rollout": 5.0,
        "sim_vs_crocoddyl_rollout_alone": 5.0,
        "sim_vs_crocoddyl": 5.0,
        "sim_vs_pin_python": 20.0,
    }
    checks = {k: ("yes" if ratios[k]["median"] >= t else "**NO**") for k, t in thresholds.items()}

    report = make_report(env, args, agree, batch, single, sim, ratios, checks)
    print(report)
    args.out.mkdir(parents=True, exist_ok=True)
    result = {
        "model": MODEL,
        "environment": env,
        "settings": {
            "quick": args.quick,
            "repeats": args.repeats,
            "batch": args.batch,
            "calls": args.calls,
            "t_final": args.t_final,
            "dt": args.dt,
            "seed": args.seed,
            "urdf_continuous_joints_rewritten_as_revolute": n_cont,
        },
        "agreement_max_rel_error": agree,
        "units": "seconds per call (algorithms), seconds per run (simulation)",
        "core_batched": batch,
        "single_call": single,
        "simulation": sim,
        "ratios": ratios,
        "targets": TARGETS,
        "targets_met": checks,
    }
    (args.out / "compare_pinocchio.json").write_text(json.dumps(result, indent=1))
    if args.json:
        Path(args.json).write_text(json.dumps(result, indent=1, default=str))
    (args.out / "compare_pinocchio.md").write_text(report + "\n")
    print(f"[compare_pinocchio] wrote {args.out / 'compare_pinocchio.json'} and .md", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())

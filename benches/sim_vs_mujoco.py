#!/usr/bin/env python3
"""freefloat's RK4 simulation against MuJoCo's on the same robot, and `simulate_many` throughput, in one run.

Robot: the built-in `seed001_dual_arm_consistent` (free base, two 3R arms, three reaction wheels; nq = 16,
nv = 15), exported to MJCF by `Model.to_mjcf` (what `freefloat export --mjcf` writes: RK4, 1 ms step, one motor
per 1-DoF joint, zero gravity) and loaded by MuJoCo with contacts disabled. Scenario: 10 s at 1 kHz from a
moving state, multi-sine torques on the six arm joints.

* freefloat: `ff.simulate` with a torque table sampled at dt/2 (linear hold: exact at the RK4 stage times).
* MuJoCo: an `mj_step` loop from Python (`ctrl` set from a precomputed table each step, the torque at the step's
  midpoint), and `mujoco.rollout` (the same loop in C, no Python per step) when available.
* freefloat with a Python torque function `torques(t, q, v)` (40 000 calls), for the binding-overhead row.
* `ff.simulate_many`: B members (different initial velocities) on 1 and 2 threads, against B sequential
  `ff.simulate` calls.

The two trajectories are compared before timing (abort if the base pose or joint angles differ by more than
1e-5 after 10 s; the torques differ inside each step — MuJoCo holds `ctrl` over a step, freefloat follows the
smooth torque — so they agree to O(dt²), not to round-off).

    python benches/sim_vs_mujoco.py            # full run (about a minute)
    python benches/sim_vs_mujoco.py --quick    # smoke test
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from compare_pinocchio import _clock  # noqa: E402

ROBOT = "seed001_dual_arm_consistent"
AMP = np.array([20.0, 15.0, 8.0, 20.0, 12.0, 10.0])
FREQ = np.array([0.20, 0.30, 0.50, 0.25, 0.35, 0.45])
PHASE = np.array([0.0, 0.5, 1.0, 1.5, 2.0, 2.5])
ARM_V = slice(6, 12)


def parse_args(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("--quick", action="store_true", help="1 s simulated, 2 repeats (smoke test)")
    p.add_argument("--out", type=Path, default=HERE / "results", help="folder for sim_vs_mujoco.{json,md}")
    p.add_argument("--repeats", type=int, default=None, help="interleaved repeats (default 7; quick 2)")
    p.add_argument("--t-final", type=float, default=None, help="simulated time in s (default 10; quick 1)")
    p.add_argument("--batch", type=int, default=None, help="members of the simulate_many batch (default 8; quick 4)")
    a = p.parse_args(argv)
    a.repeats = a.repeats or (2 if a.quick else 7)
    a.t_final = a.t_final or (1.0 if a.quick else 10.0)
    a.batch = a.batch or (4 if a.quick else 8)
    return a


def initial_state(m):
    q = m.neutral()
    q[0:3] = (0.5, -0.2, 0.1)
    ax = np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8])
    q[3:7] = np.r_[np.sin(0.3) * ax, np.cos(0.3)]
    v = np.zeros(m.nv)
    v[0:6] = (0.01, -0.02, 0.005, 0.01, 0.02, -0.015)
    v[ARM_V] = (0.05, -0.1, 0.08, -0.05, 0.1, -0.07)
    return q, v


def arm_torque(t):
    t = np.asarray(t, float)
    return AMP * np.sin(2 * np.pi * FREQ * t[..., None] + PHASE)


def ff_table(nv, t_final, dt):
    times = np.arange(round(2 * t_final / dt) + 1) * (dt / 2)
    vals = np.zeros((len(times), nv))
    vals[:, ARM_V] = arm_torque(times)
    return times, vals


def mujoco_setup(m, tmp: Path):
    import mujoco

    xml = tmp / "robot.xml"
    m.to_mjcf(xml)
    mj = mujoco.MjModel.from_xml_path(str(xml))
    mj.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONTACT)
    if mj.opt.integrator != mujoco.mjtIntegrator.mjINT_RK4 or abs(mj.opt.timestep - 1e-3) > 1e-15:
        raise SystemExit("ABORT: the MJCF export is not RK4 at 1 ms")
    return mj


def mujoco_state(m, mj, q, v):
    """freefloat (q, v) -> MuJoCo (qpos, qvel): quaternion w first, free-joint linear velocity in world axes."""
    import freefloat as ff

    qpos, qvel = mj.qpos0.copy(), np.zeros(mj.nv)
    qpos[0:3] = q[0:3]
    qpos[3:7] = (q[6], q[3], q[4], q[5])
    R = ff.quat_to_matrix(q[3:7])
    qvel[0:3] = R @ v[0:3]
    qvel[3:6] = v[3:6]
    # 1-DoF joints in the same order (the export keeps the body order), measured from qpos0
    qpos[7:] = mj.qpos0[7:] + q[7:]
    qvel[6:] = v[6:]
    return qpos, qvel


def mujoco_ctrl(mj, m, t_final, dt):
    """ctrl rows per step: the arm torques at each step's midpoint (MuJoCo holds ctrl over the step)."""
    n = round(t_final / dt)
    ctrl = np.zeros((n, mj.nu))
    tau = arm_torque((np.arange(n) + 0.5) * dt)
    # actuators are named after their joints by the export; map arm joints' v index -> actuator index
    import mujoco

    names = [mujoco.mj_id2name(mj, mujoco.mjtObj.mjOBJ_ACTUATOR, i) for i in range(mj.nu)]
    jn = list(m.joint_names)
    for k, vi in enumerate(range(ARM_V.start, ARM_V.stop)):
        j = jn[[i for i in range(len(jn)) if m.idx_v[i] == vi][0]]
        a = next(i for i, nm in enumerate(names) if nm is not None and j in nm)
        ctrl[:, a] = tau[:, k]
    return ctrl


def main(argv=None):
    args = parse_args(argv)
    import mujoco

    import freefloat as ff

    m = ff.models.load(ROBOT)
    q0, v0 = initial_state(m)
    dt, T = 1e-3, args.t_final
    n = round(T / dt)
    times, vals = ff_table(m.nv, T, dt)
    with tempfile.TemporaryDirectory() as tmp:
        mj = mujoco_setup(m, Path(tmp))
    md = mujoco.MjData(mj)
    qpos0, qvel0 = mujoco_state(m, mj, q0, v0)
    ctrl = mujoco_ctrl(mj, m, T, dt)

    def run_ff():
        return ff.simulate(m, q0, v0, t_final=T, dt=dt, torques=vals, torque_times=times, hold="linear")

    def run_ff_callable():
        def tau(t, q, v):
            out = np.zeros(15)
            out[ARM_V] = AMP * np.sin(2 * np.pi * FREQ * t + PHASE)
            return out

        return ff.simulate(m, q0, v0, t_final=T, dt=dt, torques=tau)

    def run_ff_vectorised():
        def tau_of_t(t):
            out = np.zeros((len(t), 15))
            out[:, ARM_V] = AMP * np.sin(2 * np.pi * FREQ * t[:, None] + PHASE)
            return out

        tt, tv = ff.torque_table(tau_of_t, T, dt)  # inside the timing: it is part of the cost
        return ff.simulate(m, q0, v0, t_final=T, dt=dt, torques=tv, torque_times=tt, hold="linear")

    def run_mj_loop():
        mujoco.mj_resetData(mj, md)
        md.qpos[:], md.qvel[:] = qpos0, qvel0
        out = np.empty((n + 1, mj.nq))
        out[0] = md.qpos
        for k in range(n):
            md.ctrl[:] = ctrl[k]
            mujoco.mj_step(mj, md)
            out[k + 1] = md.qpos
        return out

    rollout = None
    try:
        from mujoco import rollout as _rollout

        state0 = np.empty(mujoco.mj_stateSize(mj, mujoco.mjtState.mjSTATE_FULLPHYSICS))
        mujoco.mj_resetData(mj, md)
        md.qpos[:], md.qvel[:] = qpos0, qvel0
        mujoco.mj_getState(mj, md, state0, mujoco.mjtState.mjSTATE_FULLPHYSICS)

        def rollout():
            st, _ = _rollout.rollout(mj, md, state0[None, :], ctrl[None, :, :])
            return st

    except ImportError:
        pass

    # agreement before timing: base pose and joint angles at the end
    tr = run_ff()
    qm = run_mj_loop()
    qf = np.array([mujoco_state(m, mj, q, np.zeros(m.nv))[0] for q in tr.q])
    # quaternion sign is arbitrary
    s = np.sign(np.sum(qf[:, 3:7] * qm[:, 3:7], axis=1))[:, None]
    qf[:, 3:7] *= s
    err = float(np.abs(qf - qm).max())
    if not err < 1e-5:
        raise SystemExit(f"ABORT: freefloat and MuJoCo trajectories differ by {err:.3g} (> 1e-5)")
    err_rollout = None
    if rollout is not None:
        st = rollout()
        err_rollout = float(np.abs(st[0, -1, 1 : 1 + mj.nq] - qm[-1]).max())

    # simulate_many: B members with different initial velocities
    rng = np.random.default_rng(0)
    B = args.batch
    V0 = np.tile(v0, (B, 1)) + 0.01 * rng.normal(size=(B, m.nv))
    Q0 = np.tile(q0, (B, 1))

    def many(threads):
        return lambda: ff.simulate_many(
            m, Q0, V0, T, dt, torques=vals, torque_times=times, hold="linear", threads=threads
        )

    def sequential():
        return [
            ff.simulate(m, Q0[k], V0[k], t_final=T, dt=dt, torques=vals, torque_times=times, hold="linear")
            for k in range(B)
        ]

    got = many(2)()
    ref = sequential()
    err_many = max(float(np.abs(a.q - b.q).max()) for a, b in zip(got, ref))
    if got.failures or not err_many == 0.0:
        raise SystemExit(f"ABORT: simulate_many differs from sequential simulate calls by {err_many}")

    cases = {
        "freefloat simulate (table)": run_ff,
        "freefloat simulate (Python torque function)": run_ff_callable,
        "freefloat simulate (vectorised torque function, ff.torque_table)": run_ff_vectorised,
        "MuJoCo mj_step loop (Python)": run_mj_loop,
    }
    if rollout is not None:
        cases["MuJoCo rollout (C loop)"] = rollout
    cases[f"freefloat {B} x simulate, sequential"] = sequential
    cases[f"freefloat simulate_many B={B}, 1 thread"] = many(1)
    cases[f"freefloat simulate_many B={B}, 2 threads"] = many(2)
    load0 = os.getloadavg()
    for f in cases.values():
        f()
    res = {k: {"wall": [], "cpu": []} for k in cases}
    for _ in range(args.repeats):
        for k, f in cases.items():
            w, c, _ = _clock(f)
            res[k]["wall"].append(w)
            res[k]["cpu"].append(c)
    load1 = os.getloadavg()

    def med(k, what="wall"):
        return statistics.median(res[k][what])

    def ratio(a, b):
        r = [x / y for x, y in zip(res[a]["wall"], res[b]["wall"])]
        rc = [x / y for x, y in zip(res[a]["cpu"], res[b]["cpu"]) if y > 0]
        return statistics.median(r), min(r), max(r), (statistics.median(rc) if rc else float("nan"))

    ffk = "freefloat simulate (table)"
    rows = [("MuJoCo mj_step loop / freefloat", ratio("MuJoCo mj_step loop (Python)", ffk), ">= 3.5 (issue 36)")]
    if rollout is not None:
        rows.append(("MuJoCo rollout (C) / freefloat", ratio("MuJoCo rollout (C loop)", ffk), ">= 3.5 (issue 36)"))
    rows.append(("Python torque function / table", ratio("freefloat simulate (Python torque function)", ffk), "<= 1.5"))
    rows.append(
        (
            "vectorised torque function (ff.torque_table) / table",
            ratio("freefloat simulate (vectorised torque function, ff.torque_table)", ffk),
            "<= 1.5",
        )
    )
    rows.append(
        (
            f"simulate_many B={B}: 1 thread / 2 threads (throughput gain)",
            ratio(f"freefloat simulate_many B={B}, 1 thread", f"freefloat simulate_many B={B}, 2 threads"),
            ">= 1.8",
        )
    )
    rows.append(
        (
            f"{B} sequential simulate / simulate_many 2 threads",
            ratio(f"freefloat {B} x simulate, sequential", f"freefloat simulate_many B={B}, 2 threads"),
            ">= 1.8",
        )
    )
    lines = [
        "# freefloat vs MuJoCo: RK4 simulation (benches/sim_vs_mujoco.py)",
        "",
        f"{ROBOT}, {T:g} s at 1 kHz, RK4; MuJoCo {mujoco.__version__} (contacts off). {args.repeats} interleaved "
        f"repeats; load average {load0[0]:.2f} / {load1[0]:.2f} (start / end), {os.cpu_count()} CPUs. Agreement of "
        f"the trajectories: {err:.2g} (rollout vs mj_step loop {err_rollout}); simulate_many vs sequential: "
        f"{err_many:.2g}.",
        "",
        "| run | wall median [ms] | min-max [ms] | CPU median [ms] |",
        "|---|---:|---:|---:|",
    ]
    for k in cases:
        lines.append(
            f"| {k} | {1e3 * med(k):.1f} | {1e3 * min(res[k]['wall']):.1f}-{1e3 * max(res[k]['wall']):.1f} | "
            f"{1e3 * med(k, 'cpu'):.1f} |"
        )
    lines += [
        "",
        "Ratios per repeat (wall; CPU-time ratio beside it: on a loaded machine the process gets a fraction of a core"
        " and CPU time is the fairer measure; for the 2-thread rows CPU time adds both threads, so only wall time"
        " shows the throughput gain, and only when a second core is free).",
        "",
        "| ratio | wall median | wall min-max | CPU median | target |",
        "|---|---:|---:|---:|---|",
    ]
    for name, (r, lo, hi, rc), tgt in rows:
        lines.append(f"| {name} | {r:.2f} | {lo:.2f}-{hi:.2f} | {rc:.2f} | {tgt} |")
    text = "\n".join(lines) + "\n"
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "sim_vs_mujoco.md").write_text(text)
    payload = {
        "agreement": {"ff_vs_mujoco_max_abs": err, "rollout_vs_loop": err_rollout, "simulate_many": err_many},
        "times": res,
        "ratios": {
            name: {"median": r, "min": lo, "max": hi, "cpu_median": rc, "target": tgt}
            for name, (r, lo, hi, rc), tgt in rows
        },
        "loadavg": [load0, load1],
    }
    (args.out / "sim_vs_mujoco.json").write_text(json.dumps(payload, indent=1))
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())

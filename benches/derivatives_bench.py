#!/usr/bin/env python3
"""Speed of the dynamics derivatives: freefloat vs Pinocchio `computeABADerivatives` and Crocoddyl `calcDiff`.

Models (each built from one body list, rendered to freefloat YAML and built in Pinocchio directly, so both
libraries see the same robot): the ch. 8 spacecraft of Valverde 2018 with the RRR arm and Z-Y-X wrist
(nv = 12; geometry and masses of the Crocoddyl baseline) and a random free-floating revolute tree (nv = 6 + 20).

Timed, each on the same N random states, R interleaved repeats (median, min-max):

* ABA derivatives, one Python call per state: `ff.derivatives.aba_derivatives` vs `pin.computeABADerivatives`
  (both return da/dq, da/dv, M^-1; both pay their binding's overhead), in a loop that uses each result and lets it
  go, as a solver does (the headline row). Pinocchio returns views of its one `Data` (the next call overwrites
  them), freefloat new arrays; so a second row keeps all N results, Pinocchio's copied (`.copy()`: without it the N
  kept results would all be the last one), which is what keeping them costs with each library.
* ABA derivatives, stacked: one `ff.derivatives.aba_derivatives` call on the N states (a Rust loop), per state.
  Pinocchio has no batched entry point for it, so its per-call figure above is its best from Python.
* The per-node dynamics-plus-derivatives block of a DDP iteration (ch. 8 model only): freefloat's stacked
  `step_derivatives` (semi-implicit Euler, Fx and Fu) + `frame_log_error_derivatives` (log-SE(3) error and its
  Jacobian) vs Crocoddyl's `ShootingProblem.calcDiff` over N `IntegratedActionModelEuler` nodes (one C++ loop)
  with the baseline's costs (frame placement, state, control) and with no cost at all; and the same for RK4
  (ours: Lie-group RK4 / Crocoddyl: `IntegratedActionModelRK` four).

Before timing, freefloat's derivatives are checked against Pinocchio's on every model (abort above 1e-8).
The issue's target: the per-node block at most 0.5x Crocoddyl's calcDiff.

    python benches/derivatives_bench.py [--quick] [--out benches/results]
"""

from __future__ import annotations

import argparse
import json
import platform
import sys
import time
from pathlib import Path

import numpy as np

import freefloat as ff

D = ff.derivatives


# ------------------------------------------------------------------------------------------------ models
def ch8_bodies():
    """(name, parent index, axis, xyz, rpy, mass, com, inertia diag) after the free base (index 0)."""
    i3 = [1.0, 1.0, 1.0]
    w = [0.01, 0.01, 0.01]
    return [
        ("waist", 0, "z", [0, 0, 1], [0, 0, 0], 5.0, [0, 0, 1], i3),
        ("shoulder", 1, "z", [0.75, 0, 4], [np.pi / 2, 0, 0], 5.0, [1.5, 0, 0], i3),
        ("elbow", 2, "z", [3, 0, 0], [0, 0, 0], 5.0, [1.5, 0, 0], i3),
        ("wrist_z", 3, "z", [3, 0, 0], [0, 0, 0], 0.1, [0, 0, 0], w),
        ("wrist_y", 4, "y", [0, 0, 0], [0, 0, 0], 0.1, [0, 0, 0], w),
        ("wrist_x", 5, "x", [0, 0, 0], [0, 0, 0], 0.1, [0, 0, 0], w),
    ], (50.0, [10.0, 10.0, 10.0])


def random_bodies(n, seed):
    """A branching revolute tree whose file order is depth-first (each body hangs from the previous body or
    one of its ancestors), so Pinocchio keeps the same joint order; axes along x, y or z of rotated frames."""
    rng = np.random.default_rng(seed)
    bodies, path = [], [0]
    for i in range(1, n + 1):
        k = int(rng.integers(max(0, len(path) - 3), len(path)))
        parent = path[k]
        path = path[: k + 1] + [i]
        bodies.append(
            (
                f"b{i}",
                parent,
                "xyz"[int(rng.integers(0, 3))],
                list(rng.uniform(-0.8, 0.8, size=3)),
                list(rng.uniform(-3, 3, size=3)),
                float(rng.uniform(1, 5)),
                list(rng.uniform(-0.3, 0.3, size=3)),
                list(rng.uniform(0.3, 0.5, size=3)),
            )
        )
    return bodies, (200.0, [40.0, 50.0, 60.0])


AXES = {"x": [1, 0, 0], "y": [0, 1, 0], "z": [0, 0, 1]}


def to_yaml(name, bodies, base):
    bm, bi = base
    lines = [
        f"name: {name}",
        "base: free",
        "bodies:",
        f"  - {{name: base, inertial: {{mass: {bm}, com: [0, 0, 0], inertia: {bi}}}}}",
    ]
    names = ["base"] + [b[0] for b in bodies]
    for nm, parent, ax, xyz, rpy, mass, com, inertia in bodies:
        lines.append(
            f"  - {{name: {nm}, parent: {names[parent]}, joint: {{type: revolute, axis: {AXES[ax]}}}, "
            f"origin: {{xyz: {[float(x) for x in xyz]}, rpy: {[float(x) for x in rpy]}}}, "
            f"inertial: {{mass: {mass}, com: {[float(x) for x in com]}, inertia: {[float(x) for x in inertia]}}}}}"
        )
    lines += ["frames:", f"  - {{name: ee, body: {bodies[-1][0]}}}"]
    return "\n".join(lines) + "\n"


def to_pinocchio(bodies, base):
    import pinocchio as pin

    model = pin.Model()
    model.gravity = pin.Motion.Zero()
    bm, bi = base
    jids = [model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "root_joint")]
    model.appendBodyToJoint(jids[0], pin.Inertia(bm, np.zeros(3), np.diag(bi)), pin.SE3.Identity())
    joint = {"x": pin.JointModelRX, "y": pin.JointModelRY, "z": pin.JointModelRZ}
    for nm, parent, ax, xyz, rpy, mass, com, inertia in bodies:
        pl = pin.SE3(pin.rpy.rpyToMatrix(np.array(rpy, float)), np.array(xyz, float))
        j = model.addJoint(jids[parent], joint[ax](), pl, nm)
        model.appendBodyToJoint(j, pin.Inertia(mass, np.array(com, float), np.diag(inertia)), pin.SE3.Identity())
        jids.append(j)
    model.addFrame(pin.Frame("ee", jids[-1], 0, pin.SE3.Identity(), pin.FrameType.OP_FRAME))
    return model


def states(nv, n, rng):
    Q = np.zeros((n, 7 + nv - 6))
    Q[:, :3] = rng.normal(size=(n, 3))
    quat = rng.normal(size=(n, 4))
    Q[:, 3:7] = quat / np.linalg.norm(quat, axis=1, keepdims=True)
    Q[:, 7:] = rng.uniform(-1.5, 1.5, size=(n, nv - 6))
    return Q, rng.normal(size=(n, nv)) * 0.5, rng.normal(size=(n, nv))


# ------------------------------------------------------------------------------------------------ timing
def per_item(f, n):
    t0 = time.perf_counter()
    f()
    return (time.perf_counter() - t0) / n * 1e6


def stats(xs):
    xs = np.asarray(xs)
    return {"median_us": float(np.median(xs)), "min_us": float(xs.min()), "max_us": float(xs.max())}


def crocoddyl_problem(pm, dt, n, rk4, with_costs, refs):
    import crocoddyl as croc
    import pinocchio as pin

    state = croc.StateMultibody(pm)
    act = croc.ActuationModelFull(state)
    fid = pm.getFrameId("ee")

    def dam(k):
        costs = croc.CostModelSum(state, act.nu)
        if with_costs:
            # the baseline's terms: frame placement (weighted), base twist (state residual), control
            wp = np.r_[[156 / 4] * 3, [312 / 4] * 3]
            costs.addCost(
                "ee",
                croc.CostModelResidual(
                    state,
                    croc.ActivationModelWeightedQuad(wp),
                    croc.ResidualModelFramePlacement(state, fid, refs[k], act.nu),
                ),
                1.0,
            )
            wx = np.r_[np.zeros(pm.nv), [2.0] * 6, np.zeros(pm.nv - 6)]
            costs.addCost(
                "vel",
                croc.CostModelResidual(
                    state, croc.ActivationModelWeightedQuad(wx), croc.ResidualModelState(state, act.nu)
                ),
                1.0,
            )
            costs.addCost("u", croc.CostModelResidual(state, croc.ResidualModelControl(state, act.nu)), 1e-3)
        return croc.DifferentialActionModelFreeFwdDynamics(state, act, costs)

    def integ(k):
        if rk4:
            return croc.IntegratedActionModelRK(dam(k), croc.RKType.four, dt)
        return croc.IntegratedActionModelEuler(dam(k), dt)

    running = [integ(k) for k in range(n)]
    problem = croc.ShootingProblem(np.r_[pin.neutral(pm), np.zeros(pm.nv)], running, integ(n))
    problem.nthreads = 1
    return problem


def use_each(f, *args):
    """Call `f(*head, q, v, tau)` on each state in turn, keeping only the latest result (a solver's loop)."""
    *head, Q, V, T = args
    r = None
    for k in range(len(Q)):
        r = f(*head, Q[k], V[k], T[k])
    return r


def bench_model(name, bodies, base, n, reps, rng, have_croc, results, agreement, md):
    """Check against Pinocchio, then time one model; fills results, agreement and md."""
    import pinocchio as pin

    m = ff.Model.from_yaml_string(to_yaml(name, bodies, base))
    pm = to_pinocchio(bodies, base)
    pd = pm.createData()
    nv = m.nv
    Q, V, T = states(nv, n, rng)
    # agreement with Pinocchio first
    worst = 0.0
    for k in range(min(n, 20)):
        ours = D.aba_derivatives(m, Q[k], V[k], T[k])
        theirs = pin.computeABADerivatives(pm, pd, Q[k], V[k], T[k])
        for a, b in zip(ours, theirs):
            b = np.asarray(b)
            if b is theirs[2]:
                b = np.triu(b) + np.triu(b, 1).T
            worst = max(worst, float(np.abs(a - b).max() / max(1.0, np.abs(b).max())))
    agreement[name] = worst
    if not worst < 1e-8:
        sys.exit(f"{name}: freefloat's ABA derivatives differ from Pinocchio's by {worst:.3g} (relative)")

    timings = {
        k: []
        for k in (
            "ff_aba_derivatives_call",
            "pin_computeABADerivatives_call",
            "ff_aba_derivatives_call_kept",
            "pin_computeABADerivatives_call_kept",
            "ff_aba_derivatives_stacked",
        )
    }
    croc_runs = {}
    if name.startswith("ch8"):
        dt = 0.05
        refs = []
        for k in range(n + 1):
            pin.framesForwardKinematics(pm, pd, Q[k % n])
            refs.append(pd.oMf[pm.getFrameId("ee")].copy())
        target = np.array([pin.SE3ToXYZQUAT(refs[k]) for k in range(n)])
        for k in ("ff_euler_block_stacked", "ff_rk4_block_stacked"):
            timings[k] = []
        if have_croc:
            xs = [np.r_[Q[k % n], V[k % n]] for k in range(n + 1)]
            us = [T[k] for k in range(n)]
            for label, rk4, costs in (
                ("euler_costs", False, True),
                ("euler_nocost", False, False),
                ("rk4_costs", True, True),
            ):
                prob = crocoddyl_problem(pm, dt, n, rk4, costs, refs)
                prob.calc(xs, us)
                croc_runs[label] = prob
                timings[f"croc_calcDiff_{label}"] = []

    for _ in range(reps):
        timings["ff_aba_derivatives_call"].append(per_item(lambda: use_each(D.aba_derivatives, m, Q, V, T), n))
        timings["pin_computeABADerivatives_call"].append(
            per_item(lambda: use_each(pin.computeABADerivatives, pm, pd, Q, V, T), n)
        )
        timings["ff_aba_derivatives_call_kept"].append(
            per_item(lambda: [D.aba_derivatives(m, Q[k], V[k], T[k]) for k in range(n)], n)
        )
        timings["pin_computeABADerivatives_call_kept"].append(
            per_item(
                lambda: [
                    tuple(x.copy() for x in pin.computeABADerivatives(pm, pd, Q[k], V[k], T[k])) for k in range(n)
                ],
                n,
            )
        )
        timings["ff_aba_derivatives_stacked"].append(per_item(lambda: D.aba_derivatives(m, Q, V, T), n))
        if name.startswith("ch8"):
            timings["ff_euler_block_stacked"].append(
                per_item(
                    lambda: (D.step_derivatives(m, Q, V, T, dt), D.frame_log_error_derivatives(m, Q, "ee", target)), n
                )
            )
            timings["ff_rk4_block_stacked"].append(
                per_item(
                    lambda: (
                        D.step_derivatives(m, Q, V, T, dt, method="rk4"),
                        D.frame_log_error_derivatives(m, Q, "ee", target),
                    ),
                    n,
                )
            )
            for label, prob in croc_runs.items():
                # calc before calcDiff is what a DDP iteration does; only calcDiff is timed
                timings[f"croc_calcDiff_{label}"].append(per_item(lambda p=prob: p.calcDiff(xs, us), n + 1))
    res = {k: stats(v) for k, v in timings.items()}
    results[name] = {"nv": nv, "timings": res}
    med = {k: v["median_us"] for k, v in res.items()}
    ratios = {
        "ff_call_over_pin_call": med["ff_aba_derivatives_call"] / med["pin_computeABADerivatives_call"],
        "ff_stacked_over_pin_call": med["ff_aba_derivatives_stacked"] / med["pin_computeABADerivatives_call"],
        "ff_kept_over_pin_copied": med["ff_aba_derivatives_call_kept"] / med["pin_computeABADerivatives_call_kept"],
    }
    if "croc_calcDiff_euler_costs" in med:
        ratios["ff_euler_block_over_croc_calcDiff"] = med["ff_euler_block_stacked"] / med["croc_calcDiff_euler_costs"]
        ratios["ff_euler_block_over_croc_calcDiff_nocost"] = (
            med["ff_euler_block_stacked"] / med["croc_calcDiff_euler_nocost"]
        )
        ratios["ff_rk4_block_over_croc_rk4_calcDiff"] = med["ff_rk4_block_stacked"] / med["croc_calcDiff_rk4_costs"]
    results[name]["ratios"] = ratios
    md.append(f"\n### {name} (nv = {nv}), {n} states x {reps} repeats, µs per state: median (min-max)\n")
    md.append("| call | median | min | max |\n|---|---:|---:|---:|")
    for k, v in res.items():
        md.append(f"| `{k}` | {v['median_us']:.2f} | {v['min_us']:.2f} | {v['max_us']:.2f} |")
    md.append("\n" + ", ".join(f"{k} = {v:.2f}" for k, v in ratios.items()))
    print(f"{name}: " + ", ".join(f"{k} {v['median_us']:.2f} µs" for k, v in res.items()))
    print("   ratios: " + ", ".join(f"{k} {v:.2f}" for k, v in ratios.items()))


def main(argv=None):
    ap = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("--quick", action="store_true", help="few states and repeats (a smoke run, not a measurement)")
    ap.add_argument("--states", type=int, default=None, help="states per repeat (default 640, quick 40)")
    ap.add_argument("--repeats", type=int, default=None, help="interleaved repeats (default 7, quick 2)")
    ap.add_argument("--out", type=Path, default=None, help="folder for derivatives_bench.json/.md")
    ap.add_argument("--json", default=None, help="also write the results (JSON) to this file (read by run_all.py)")
    args = ap.parse_args(argv)
    n = args.states or (40 if args.quick else 640)
    reps = args.repeats or (2 if args.quick else 7)
    import pinocchio as pin

    try:
        import crocoddyl  # noqa: F401

        have_croc = True
    except ImportError:
        have_croc = False

    rng = np.random.default_rng(0)
    models = {"ch8_spacecraft_wrist": ch8_bodies(), "random_tree_26": random_bodies(20, 1)}
    results, agreement, md = {}, {}, []
    for name, (bodies, base) in models.items():
        bench_model(name, bodies, base, n, reps, rng, have_croc, results, agreement, md)

    out = {
        "machine": {
            "python": sys.version.split()[0],
            "platform": platform.platform(),
            "processor": platform.processor(),
        },
        "versions": {"freefloat": ff.__version__, "pinocchio": pin.__version__},
        "states": n,
        "repeats": reps,
        "quick": args.quick,
        "agreement_max_rel_error": agreement,
        "results": results,
    }
    if args.out:
        args.out.mkdir(parents=True, exist_ok=True)
        (args.out / "derivatives_bench.json").write_text(json.dumps(out, indent=2))
        (args.out / "derivatives_bench.md").write_text(
            "# freefloat dynamics derivatives vs Pinocchio and Crocoddyl\n" + "\n".join(md) + "\n"
        )
    if args.json:
        Path(args.json).write_text(json.dumps(out, indent=1, default=str))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

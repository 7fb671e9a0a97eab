#!/usr/bin/env python3
"""Dynamics kernels (ABA, RNEA, CRBA) against Pinocchio, per call, core to core, on three robots, in one run.

Robots: the built-in `seed001_dual_arm_consistent` (free base, two 3R arms, three wheels; nv = 15) and two random
free-floating trees with nv = 12 and nv = 30 (revolute and prismatic joints, random placements, inertias and
branching; `tests/random_trees.py`, which builds the Pinocchio model directly from the tree description, never
from a freefloat object). Before anything is timed, ABA, RNEA and CRBA of both libraries are compared on random
states (abort above 1e-9, relative).

What is timed (wall clock and process CPU time; repeats interleaved between the libraries so machine noise hits
both alike; median, min and max over the repeats):

* ABA and RNEA: one freefloat call on a stacked batch of N states (`ff.aba(m, Q, V, T)`), divided by N, against
  Pinocchio's batched C++ `abaInParallel` / `rneaInParallel` with one thread, writing into a preallocated output.
* All three against Pinocchio's C++ called from C++ (`benches/pinocchio_peer.cpp`, `pinocchio_peer.py`): a loop
  of `pinocchio::crba` / `aba` / `rnea` over the same states, compiled at run time with g++ -O3 -march=native
  against the headers of the pip `pin` wheel (plus `cmeel-eigen`), cached under ~/.cache/freefloat-bench, run as
  a child process and timed inside it (wall and its own CPU time), interleaved with freefloat's repeats. Its
  outputs are checked against freefloat's first (abort above 1e-9, relative). This is the CRBA row; without g++
  or the headers (or with --no-cpp) the script says why and falls back to the estimate below.
* freefloat's own loop (the `*_loop` rows): the same kernel called in a loop inside the engine over the same states
  (`_core._time_kernel`, through the checked public function), timed there; against the C++ peer's loop this is
  core to core with no binding, argument conversion or output allocation on either side.
* CRBA, the old estimate (kept as the `crba_estimate` row): a Python loop of `pin.crba` minus the same loop on a
  one-body free-flyer model (the binding and loop cost, measured in the same run); freefloat's is a stacked batch
  of N = 1000.
* Single calls from Python (`ff.aba` / `pin.aba`, `ff.crba` / `pin.crba`, `ff.momentum` /
  `pin.computeCentroidalMomentum`), on the seed 001 robot.

    python benches/kernels_vs_pinocchio.py               # full run (about a minute)
    python benches/kernels_vs_pinocchio.py --quick       # smoke test
    python benches/kernels_vs_pinocchio.py --out DIR     # write kernels_vs_pinocchio.{json,md} there

Ratios are freefloat's time over Pinocchio's (< 1: freefloat is faster). Targets (issue 16): ABA <= 0.5,
RNEA and CRBA <= 0.7, single calls from Python <= 1.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import statistics
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "tests"))

from compare_pinocchio import _clock, environment  # noqa: E402
from pinocchio_peer import CppPeer  # noqa: E402

SEED_ROBOT = "seed001_dual_arm_consistent"
TARGETS = {"aba": 0.5, "rnea": 0.7, "crba": 0.7}


def parse_args(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("--quick", action="store_true", help="few repeats and small batches (smoke test, seconds)")
    p.add_argument("--out", type=Path, default=HERE / "results", help="folder for the .json and .md results")
    p.add_argument("--repeats", type=int, default=None, help="interleaved repeats of every measurement (default 7)")
    p.add_argument("--batch", type=int, default=None, help="states per batched call (default 20000)")
    p.add_argument("--calls", type=int, default=None, help="single calls per repeat (default 20000)")
    p.add_argument("--seed", type=int, default=0, help="random seed of the states")
    p.add_argument("--no-cpp", action="store_true", help="skip the C++ Pinocchio peer (no g++ or headers needed)")
    a = p.parse_args(argv)
    a.repeats = a.repeats or (2 if a.quick else 7)
    a.batch = a.batch or (500 if a.quick else 20000)
    a.calls = a.calls or (500 if a.quick else 20000)
    return a


# ---------------------------------------------------------------------------------------------------------------
# robots: (freefloat model, callables of the Pinocchio side in freefloat's layout)
# ---------------------------------------------------------------------------------------------------------------


class PinSide:
    """Pinocchio model plus the q/v layout maps (identity for the seed robot)."""

    def __init__(self, model, q_to, v_to, v_from, cols_from):
        import pinocchio as pin

        self.pin = pin
        self.model = model
        self.data = model.createData()
        self.q_to, self.v_to, self.v_from, self.cols_from = q_to, v_to, v_from, cols_from

    def aba(self, q, v, tau):
        return self.v_from(self.pin.aba(self.model, self.data, self.q_to(q), self.v_to(v), self.v_to(tau)))

    def rnea(self, q, v, a):
        return self.v_from(self.pin.rnea(self.model, self.data, self.q_to(q), self.v_to(v), self.v_to(a)))

    def crba(self, q):
        M = self.pin.crba(self.model, self.data, self.q_to(q))
        M = np.triu(M) + np.triu(M, 1).T
        return self.cols_from(self.cols_from(M).T).T


def seed_robot(tmp: Path):
    import pinocchio as pin

    import freefloat as ff

    m = ff.models.load(SEED_ROBOT)
    path = tmp / "seed.urdf"
    m.to_urdf(path)
    # the export writes unlimited revolute joints as `continuous` ((cos, sin) in Pinocchio); make them revolute so
    # both libraries use the same q layout (limits play no part in the dynamics)
    text = re.sub(
        r'type="continuous">',
        'type="revolute">\n    <limit lower="-1e6" upper="1e6" velocity="1e6" effort="1e6"/>',
        path.read_text(),
    )
    path.write_text(text)
    pm = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    pm.gravity = pin.Motion(np.asarray(m.gravity, float), np.zeros(3))
    if (pm.nq, pm.nv) != (m.nq, m.nv) or list(pm.names)[1:] != list(m.joint_names):
        raise SystemExit("ABORT: the Pinocchio model of the seed robot has a different layout")
    ident = lambda x: np.asarray(x, float)  # noqa: E731
    return m, PinSide(pm, ident, ident, ident, ident)


def random_robot(nv: int, seed: int):
    import freefloat as ff

    import random_trees as rt

    n_joints = nv - 6
    desc = rt.random_tree(
        np.random.default_rng(seed),
        name=f"random_tree_nv{nv}",
        n_children=n_joints,
        base="free",
        gravity=np.array([0.0, 0.0, -9.81]),
        joint_types=("revolute", "prismatic"),
        joint_p=(0.8, 0.2),
    )
    m = ff.Model.from_yaml_string(desc.to_yaml())
    if m.nv != nv:
        raise SystemExit(f"ABORT: random tree has nv = {m.nv}, wanted {nv}")
    pt = rt.build_pinocchio(desc)
    return m, PinSide(pt.model, pt.q_to_pin, pt.v_to_pin, pt.v_from_pin, pt.cols_from_pin)


def check_agreement(m, ps, rng, n=5):
    import freefloat as ff

    def rel(a, b):
        return float(np.abs(np.asarray(a) - np.asarray(b)).max() / max(1.0, np.abs(np.asarray(b)).max()))

    worst = {"aba": 0.0, "rnea": 0.0, "crba": 0.0}
    for _ in range(n):
        q = m.random_configuration(rng)
        v, tau, a = rng.normal(size=m.nv), 10 * rng.normal(size=m.nv), rng.normal(size=m.nv)
        worst["aba"] = max(worst["aba"], rel(ff.aba(m, q, v, tau), ps.aba(q, v, tau)))
        worst["rnea"] = max(worst["rnea"], rel(ff.rnea(m, q, v, a), ps.rnea(q, v, a)))
        worst["crba"] = max(worst["crba"], rel(ff.crba(m, q), ps.crba(q)))
    bad = {k: e for k, e in worst.items() if not e <= 1e-9}
    if bad:
        raise SystemExit(f"ABORT: freefloat and Pinocchio disagree on {m.name}: {bad}")
    return worst


# ---------------------------------------------------------------------------------------------------------------
# timing
# ---------------------------------------------------------------------------------------------------------------


def stats(s):
    return {
        "median": statistics.median(s["wall"]),
        "min": min(s["wall"]),
        "max": max(s["wall"]),
        "cpu_median": statistics.median(s["cpu"]),
    }


def ratio_stats(a, b):
    """Per-repeat ratio a/b (same repeat, so the same machine state): median, min, max."""
    r = [x / y for x, y in zip(a["wall"], b["wall"])]
    rc = [x / y for x, y in zip(a["cpu"], b["cpu"]) if y > 0]
    return {
        "median": statistics.median(r),
        "min": min(r),
        "max": max(r),
        "cpu_median": statistics.median(rc) if rc else None,
    }


def one_body_freeflyer():
    import pinocchio as pin

    pm = pin.Model()
    jid = pm.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "root")
    pm.appendBodyToJoint(jid, pin.Inertia.FromBox(100.0, 1.0, 2.0, 3.0), pin.SE3.Identity())
    return pm


def ff_loop(m, kernel, Q, V, T, calls):
    """freefloat's loop of `calls` kernel calls over the rows of Q, V, T, timed inside the engine: (wall, cpu) s."""
    import freefloat as ff

    # both clocks read inside the engine around the loop alone, as the C++ peer reads its own (the CPU clock is the
    # loop's thread's: the process's would also count idle-spinning BLAS threads)
    wall, cpu, _ = ff._core._time_kernel(m, kernel, Q, V, T, calls)
    return wall, cpu


class SelfTimed:
    """A case timed by someone else (the C++ peer): `fn()` returns (wall, cpu) seconds."""

    def __init__(self, fn):
        self.fn = fn


def run_interleaved(cases: dict, repeats: int, per: dict):
    """`compare_pinocchio.run_interleaved` that also takes `SelfTimed` cases (timed inside the C++ peer, whose CPU
    time is its own process's). Returns name -> {"wall": [...], "cpu": [...]}, seconds per call; one warm-up each."""
    for f in cases.values():
        f.fn() if isinstance(f, SelfTimed) else f()
    res = {k: {"wall": [], "cpu": []} for k in cases}
    for _ in range(repeats):
        for k, f in cases.items():
            w, c = f.fn() if isinstance(f, SelfTimed) else _clock(f)[:2]
            res[k]["wall"].append(w / per[k])
            res[k]["cpu"].append(c / per[k])
    return res


def check_peer(m, ps, peer, k, Q, V, T, tmp, n=50):
    """The C++ peer's outputs against freefloat's on the first n states (abort above 1e-9, relative)."""
    import freefloat as ff

    n = min(n, len(Q))
    mine = {"crba": ff.crba(m, Q[:n]), "aba": ff.aba(m, Q[:n], V[:n], T[:n]), "rnea": ff.rnea(m, Q[:n], V[:n], T[:n])}
    worst = {}
    for kernel, a in mine.items():
        got = peer.outputs(k, kernel, n, tmp, m.nv)
        got = (
            np.array([ps.cols_from(ps.cols_from(x).T).T for x in got])
            if kernel == "crba"
            else np.array([ps.v_from(x) for x in got])
        )
        worst[kernel] = float(np.abs(got - a).max() / max(1.0, np.abs(a).max()))
    bad = {k: e for k, e in worst.items() if not e <= 1e-9}
    if bad:
        raise SystemExit(f"ABORT: the C++ Pinocchio peer and freefloat disagree on {m.name}: {bad}")
    return worst


def bench_core(m, ps, args, rng, peer=None, tmp=None):
    import pinocchio as pin

    import freefloat as ff

    N, R = args.batch, args.repeats
    Q = np.array([m.random_configuration(rng) for _ in range(N)])
    V = rng.normal(size=(N, m.nv))
    T = 10 * rng.normal(size=(N, m.nv))
    Qp = np.asfortranarray(np.array([ps.q_to(q) for q in Q]).T)
    Vp = np.asfortranarray(np.array([ps.v_to(x) for x in V]).T)
    Tp = np.asfortranarray(np.array([ps.v_to(x) for x in T]).T)
    pool = pin.ModelPool(ps.model, 1)
    out = np.zeros((m.nv, N), order="F")
    got = pin.abaInParallel(1, pool, Qp, Vp, Tp)
    mine = ff.aba(m, Q, V, T)
    err = max(float(np.abs(ps.v_from(got[:, k]) - mine[k]).max()) for k in range(min(N, 50)))
    if not err <= 1e-9 * max(1.0, float(np.abs(got).max())):
        raise SystemExit(f"ABORT: abaInParallel and batched ff.aba differ by {err}")

    n_crba = min(N, 1000)
    Qs = Q[:n_crba].copy()
    qp0 = ps.q_to(Q[0])
    pd = ps.data
    pm1 = one_body_freeflyer()
    pd1 = pm1.createData()
    q1 = pin.neutral(pm1)

    def pin_loop(model, data, qq, calls):
        def run():
            for _ in range(calls):
                pin.crba(model, data, qq)

        return run

    cases = {
        "ff aba": lambda: ff.aba(m, Q, V, T),
        "pin abaInParallel": lambda: pin.abaInParallel(1, pool, Qp, Vp, Tp, out),
        "ff rnea": lambda: ff.rnea(m, Q, V, T),
        "pin rneaInParallel": lambda: pin.rneaInParallel(1, pool, Qp, Vp, Tp, out),
        "ff crba": lambda: ff.crba(m, Qs),
        "pin crba loop": pin_loop(ps.model, pd, qp0, n_crba),
        "pin crba loop, 1-body model": pin_loop(pm1, pd1, q1, n_crba),
    }
    per = {k: N for k in cases}
    per.update({"ff crba": n_crba, "pin crba loop": n_crba, "pin crba loop, 1-body model": n_crba})
    # freefloat's own loop over the same states, timed inside the engine like the C++ peer times its loop (warm, no
    # Python, no output allocation): the core-to-core figure for the C++ rows
    for kernel, calls in (("aba", N), ("rnea", N), ("crba", n_crba)):
        cases[f"ff loop {kernel}"] = SelfTimed(lambda kernel=kernel, calls=calls: ff_loop(m, kernel, Q, V, T, calls))
        per[f"ff loop {kernel}"] = calls
    peer_err = None
    if peer is not None:
        kp = peer.load(ps.model, Qp.T, Vp.T, Tp.T, tmp)
        peer_err = check_peer(m, ps, peer, kp, Q, V, T, tmp)
        # the same states and numbers of calls as freefloat's batches (CRBA: the first n_crba states)
        for kernel, calls in (("aba", N), ("rnea", N), ("crba", n_crba)):
            cases[f"pin C++ {kernel}"] = SelfTimed(lambda kernel=kernel, calls=calls: peer.time(kp, kernel, calls))
            per[f"pin C++ {kernel}"] = calls
    res = run_interleaved(cases, R, per)
    # Pinocchio's CRBA in C++ alone: the loop minus the same loop on a one-body model (binding + loop cost)
    res["pin crba (C++ estimate)"] = {
        k: [a - b for a, b in zip(res["pin crba loop"][k], res["pin crba loop, 1-body model"][k])]
        for k in ("wall", "cpu")
    }
    rows = {
        "aba": ratio_stats(res["ff aba"], res["pin abaInParallel"]) | {"peer": "pin abaInParallel"},
        "rnea": ratio_stats(res["ff rnea"], res["pin rneaInParallel"]) | {"peer": "pin rneaInParallel"},
        "crba": ratio_stats(res["ff crba"], res["pin crba (C++ estimate)"]) | {"peer": "pin crba (C++ estimate)"},
    }
    if peer is not None:
        # the C++ peer is the stronger measurement: it becomes the CRBA row, the estimate stays beside it
        rows["crba_estimate"] = rows.pop("crba")
        for kernel in ("aba", "rnea", "crba"):
            key = kernel if kernel == "crba" else f"{kernel}_cpp"
            rows[key] = ratio_stats(res["ff " + kernel], res[f"pin C++ {kernel}"]) | {"peer": f"pin C++ {kernel}"}
            # both loops timed inside their own programs (freefloat: `_core._time_kernel`), no binding on either side
            rows[f"{kernel}_loop"] = ratio_stats(res[f"ff loop {kernel}"], res[f"pin C++ {kernel}"]) | {
                "peer": f"pin C++ {kernel}",
                "freefloat": "ff loop",
            }
    return {k: stats(s) for k, s in res.items()}, rows, peer_err


def bench_single(m, ps, args, rng):
    import pinocchio as pin

    import freefloat as ff

    C, R = args.calls, args.repeats
    q = m.random_configuration(rng)
    v, tau = rng.normal(size=m.nv), 10 * rng.normal(size=m.nv)
    qp, vp, tp = ps.q_to(q), ps.v_to(v), ps.v_to(tau)
    pm, pd = ps.model, ps.data

    def loop(f):
        def run():
            for _ in range(C):
                f()

        return run

    cases = {
        "ff aba": loop(lambda: ff.aba(m, q, v, tau)),
        "pin aba": loop(lambda: pin.aba(pm, pd, qp, vp, tp)),
        "ff crba": loop(lambda: ff.crba(m, q)),
        "pin crba": loop(lambda: pin.crba(pm, pd, qp)),
        "ff momentum": loop(lambda: ff.momentum(m, q, v)),
        "pin computeCentroidalMomentum": loop(lambda: pin.computeCentroidalMomentum(pm, pd, qp, vp)),
    }
    res = run_interleaved(cases, R, {k: C for k in cases})
    rows = {
        "aba": ratio_stats(res["ff aba"], res["pin aba"]),
        "crba": ratio_stats(res["ff crba"], res["pin crba"]),
        "momentum": ratio_stats(res["ff momentum"], res["pin computeCentroidalMomentum"]),
    }
    return {k: stats(s) for k, s in res.items()}, rows


def us(x):
    return f"{1e6 * x:.2f}"


def report(env, args, results, single, single_rows, peer_note=""):
    lines = [
        "# Dynamics kernels vs Pinocchio (benches/kernels_vs_pinocchio.py)",
        "",
        f"git {env['git']}, Pinocchio {env['pinocchio']}, {env['cpu']}, {env['nproc']} CPUs; load average "
        f"{env['loadavg_start']} at the start, {env['loadavg_end']} at the end. {args.repeats} interleaved "
        f"repeats, batch N = {args.batch}, {args.calls} single calls per repeat.",
        "",
        "Ratio = freefloat time / Pinocchio time per call, per repeat (wall median [min-max], and the median of "
        "the per-repeat CPU-time ratios, on which 'met?' is judged). < 1: freefloat is faster.",
        "",
        "| robot | nv | kernel | freefloat [µs] | Pinocchio [µs] | ratio | CPU ratio | target | met? |",
        "|---|---:|---|---:|---:|---:|---:|---:|---|",
    ]
    for name, r in results.items():
        for k, row in r["rows"].items():
            kernel = k.split("_")[0]
            # judged on the CPU-time ratio (the machine is shared); an estimate <= 0 (noise larger than the
            # difference it is taken from) is no measurement
            judged = row["cpu_median"] if row["cpu_median"] is not None else row["median"]
            ok = 0 < judged <= TARGETS[kernel]
            verdict = "yes" if ok else ("**no**" if judged > 0 else "no estimate")
            mine = f"{row.get('freefloat', 'ff')} {kernel}"  # "ff" = the batched call, "ff loop" = the engine's loop
            label = f"{kernel} ({mine.removesuffix(' ' + kernel)}) vs {row['peer']}"
            lines.append(
                f"| {name} | {r['nv']} | {label} | {us(r['times'][mine]['median'])} | "
                f"{us(r['times'][row['peer']]['median'])} | {row['median']:.2f} [{row['min']:.2f}-{row['max']:.2f}] | "
                f"{row['cpu_median']:.2f} | <= {TARGETS[kernel]} | {verdict} |"
            )
    lines += [
        "",
        "Peers: `pin abaInParallel` / `pin rneaInParallel` are Pinocchio's batched C++ calls (one thread) from Python; "
        "`pin C++ ...` is Pinocchio's C++ called in a loop by a C++ program (benches/pinocchio_peer.cpp, built with "
        "g++ -O3 -march=native against the pip wheel's headers), timed inside that program. freefloat: `ff` is the "
        "batched call from Python (`ff.aba(m, Q, V, T)`, outputs allocated and filled), `ff loop` the same kernel "
        "called in a loop inside the engine over the same states (`_core._time_kernel`), timed there: the like of the "
        "C++ peer's loop, core to core. `pin crba (C++ "
        "estimate)` is a Python loop of `pin.crba` minus the same loop on a one-body model. " + (peer_note or ""),
        "",
        f"## Single calls from Python ({SEED_ROBOT})",
        "",
        "| call | freefloat [µs] | Pinocchio [µs] | ratio | CPU ratio | target |",
        "|---|---:|---:|---:|---:|---|",
    ]
    names = {"aba": "pin aba", "crba": "pin crba", "momentum": "pin computeCentroidalMomentum"}
    for k, row in single_rows.items():
        lines.append(
            f"| {k} | {us(single['ff ' + k]['median'])} | {us(single[names[k]]['median'])} | "
            f"{row['median']:.2f} [{row['min']:.2f}-{row['max']:.2f}] | {row['cpu_median']:.2f} | <= 1 |"
        )
    return "\n".join(lines) + "\n"


def main(argv=None):
    args = parse_args(argv)
    env = environment()
    rng = np.random.default_rng(args.seed)
    results = {}
    peer, why = (None, "disabled (--no-cpp)") if args.no_cpp else CppPeer.start()
    peer_note = "" if peer else f"The C++ peer is unavailable ({why}); CRBA is judged against the estimate."
    if not peer:
        print("C++ Pinocchio peer unavailable: " + why, flush=True)
    try:
        with tempfile.TemporaryDirectory() as tmp:
            robots = [(SEED_ROBOT, lambda: seed_robot(Path(tmp)))]
            robots += [(f"random tree nv={nv}", lambda nv=nv: random_robot(nv, 1000 + nv)) for nv in (12, 30)]
            single = single_rows = None
            for name, build in robots:
                m, ps = build()
                agree = check_agreement(m, ps, rng)
                times, rows, peer_err = bench_core(m, ps, args, rng, peer, Path(tmp))
                results[name] = {
                    "nv": m.nv,
                    "agreement_max_rel": agree,
                    "cpp_peer_agreement_max_rel": peer_err,
                    "times": times,
                    "rows": rows,
                }
                if name == SEED_ROBOT:
                    single, single_rows = bench_single(m, ps, args, rng)
                print(
                    f"{name}: "
                    + ", ".join(f"{k} {r['median']:.2f} [{r['min']:.2f}-{r['max']:.2f}]" for k, r in rows.items()),
                    flush=True,
                )
    finally:
        if peer:
            peer.close()
    env["loadavg_end"] = os.getloadavg()
    print("single calls: " + ", ".join(f"{k} {r['median']:.2f}" for k, r in single_rows.items()))
    args.out.mkdir(parents=True, exist_ok=True)
    md = report(env, args, results, single, single_rows, peer_note)
    (args.out / "kernels_vs_pinocchio.md").write_text(md)
    payload = {
        "environment": env,
        "cpp_peer": "benches/pinocchio_peer.cpp, g++ -O3 -march=native" if peer else f"unavailable: {why}",
        "args": {k: (str(v) if isinstance(v, Path) else v) for k, v in vars(args).items()},
        "results": results,
        "single": single,
        "single_rows": single_rows,
    }
    (args.out / "kernels_vs_pinocchio.json").write_text(json.dumps(payload, indent=1))
    print(md)
    return 0


if __name__ == "__main__":
    sys.exit(main())

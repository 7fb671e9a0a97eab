"""Print the tables of docs/ddp.md §2.1 and §2.5: the chapter 8 scenarios (Valverde 2018) run from a zero start with the
thesis' settings, once per combination of robot (the 1500 kg servicer base of the defaults, or valverde_ch8_arm's
50 kg base), wrist (rate-driven as in the thesis, or torque-driven) and dual-quaternion sign (nearest, or the thesis'
literal q_G - q_D), with the numbers of the acceptance criteria D.18-D.22; then the stabilisation on the 50 kg model
with its base's mass and inertia scaled. About a minute on a 2-core machine.

    python tools/ddp_thesis_table.py [--quick]

--quick runs only the defaults and the earlier defaults (50 kg base, torque wrist, literal sign)."""

from __future__ import annotations

import argparse
import itertools
import math
from dataclasses import replace

import numpy as np

from freefloat import _core
from freefloat.control import ddp

ROBOTS = {"servicer": "valverde_ch8_servicer", "50 kg base": "valverde_ch8_arm"}


def criteria(prob: ddp.Problem, sol: dict) -> dict:
    """The numbers of D.18-D.22 from the solution's states and controls (not from `ddp.results`): end-effector pose
    errors from the engine's chain dual quaternion against the reference (final hold t >= t_f - 5 s, phase 2 of the
    tracking t in [7, 27] s, the final node), the base twist's peaks (first six velocities, base axes), the summed
    squared base force and torque, and each keep-out joint's fraction of nodes within 1 deg of its centre. SI units
    and degrees. `tests/test_ddp.py` checks the scenarios' defaults with this function."""
    m, xs, us = prob.model, np.asarray(sol["xs"]), np.asarray(sol["us"])
    g = _core.ddp_frame_dual_quats(m._core, np.ascontiguousarray(xs[:, : m.nq]), prob.frame)
    e = ddp.pose_errors(g, prob.reference_dq)
    pos, ang = np.linalg.norm(e["position"], axis=1), np.degrees(e["angle"])
    t = np.arange(len(xs)) * prob.dt
    hold, move = t >= t[-1] - 5 - 1e-9, (t >= 7) & (t <= 27)
    vb = xs[:, m.nq : m.nq + 6]
    dwell = {}
    for ko in prob.keep_out:
        theta = xs[:-1, m.idx_q[m.joint_names.index(ko["joint"])]]
        dwell[ko["joint"]] = float(np.mean(np.abs(np.angle(np.exp(1j * (theta - ko["center"])))) < math.radians(1)))
    return {
        "iterations": int(sol["iterations"]),
        "stop": sol["stop"],
        "cost": float(sol["cost"]),
        "hold_pos": float(pos[hold].max()),
        "hold_ang": float(ang[hold].max()),
        "move_rms": float(np.sqrt(np.mean(pos[move] ** 2))) if move.any() else float("nan"),
        "final_pos": float(pos[-1]),
        "final_ang": float(ang[-1]),
        "base_speed": float(np.linalg.norm(vb[:, :3], axis=1).max()),
        "base_rate": float(np.linalg.norm(vb[:, 3:], axis=1).max()),
        "f2": float(np.sum(us[:, :3] ** 2)),
        "tau2": float(np.sum(us[:, 3:6] ** 2)),
        "dwell": dwell,
    }


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="only the defaults and the earlier defaults")
    a = ap.parse_args(argv)
    combos = list(itertools.product(ROBOTS, ("rate", "torque"), ("nearest", "literal")))
    if a.quick:
        combos = [("servicer", "rate", "nearest"), ("50 kg base", "torque", "literal")]

    print("Tracking (D.18: hold <= 50 mm and 5 deg, phase-2 RMS <= 50 mm; D.19: base < 0.011 m/s and < 0.05 rad/s)")
    print(
        "| robot | wrist | dq sign | final cost | hold: position / angle | phase-2 RMS | base speed / rate "
        "| D.18 | D.19 |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    for robot, wrist, sign in combos:
        p = ddp.load_scenario("valverde_ch8_tracking", robot=ROBOTS[robot], wrist=wrist, dq_sign=sign)
        c = criteria(p, ddp.solve(p))
        d18 = c["hold_pos"] <= 0.05 and c["hold_ang"] <= 5 and c["move_rms"] <= 0.05
        d19 = c["base_speed"] < 0.011 and c["base_rate"] < 0.05
        dwell = max(c["dwell"].values(), default=0.0)
        print(
            f"| {robot} | {wrist} | {sign} | {c['cost']:.4g} | "
            f"{1e3 * c['hold_pos']:.1f} mm / {c['hold_ang']:.2f} deg | "
            f"{1e3 * c['move_rms']:.1f} mm | {c['base_speed']:.4f} / {c['base_rate']:.3f} | "
            f"{'passes' if d18 else 'fails'} | {'passes' if d19 else 'fails'} |   (sum f^2 {c['f2']:.3g}, "
            f"sum tau^2 {c['tau2']:.3g}, dwell {100 * dwell:.1f} %)",
            flush=True,
        )

    print("\nStabilisation (D.22: final error <= 50 mm and 5 deg)")
    print("| robot | wrist | dq sign | iterations | final cost | final error | D.22 |")
    print("|---|---|---|---|---|---|---|")
    for robot, wrist, sign in combos:
        p = ddp.load_scenario("valverde_ch8_stabilisation", robot=ROBOTS[robot], wrist=wrist, dq_sign=sign)
        c = criteria(p, ddp.solve(p))
        d22 = c["final_pos"] <= 0.05 and c["final_ang"] <= 5
        print(
            f"| {robot} | {wrist} | {sign} | {c['iterations']} ({c['stop']}) | {c['cost']:.5g} | "
            f"{1e3 * c['final_pos']:.1f} mm / {c['final_ang']:.2f} deg | {'passes' if d22 else 'fails'} |",
            flush=True,
        )
    if a.quick:
        return

    print("\nStabilisation on valverde_ch8_arm, rate wrist, nearest sign, its base's mass and inertia scaled together")
    print("| base scale | iterations | final error |")
    print("|---|---|---|")
    for scale in (1, 10, 20, 30, 50, 100):
        p = ddp.load_scenario("valverde_ch8_stabilisation", robot="valverde_ch8_arm")
        P = np.array(p.model.parameters())
        P[0] *= scale
        p = replace(p, model=p.model.with_parameters(P))
        c = criteria(p, ddp.solve(p, max_iter=400))
        err = f"{1e3 * c['final_pos']:.1f} mm / {c['final_ang']:.2f} deg"
        print(f"| x{scale} | {c['iterations']} ({c['stop']}) | {err} |")


if __name__ == "__main__":
    main()

"""Figures of a DDP solve in the manner of Valverde 2018, Figs. 8.1-8.14: end-effector pose sequence in 3D with the
reference, error quaternion and position error in G, error Euler angle and position-error norm, base forces and
torques, joint torques (and wrist torques), cost per iteration."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .. import _core
from ..viz import pyplot
from .ddp import Problem, dq_to_pose, pose_errors


def plot_all(problem: Problem, sol: dict, out: Path, prefix: str = "") -> list[Path]:
    """Write every figure into `out`; returns the paths."""
    plt = pyplot()
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    m = problem.model
    xs, us = np.asarray(sol["xs"]), np.asarray(sol["us"])
    t = np.arange(problem.horizon + 1) * problem.dt
    tu = t[:-1]
    g = _core.ddp_frame_dual_quats(m._core, np.ascontiguousarray(xs[:, : m.nq]), problem.frame)
    ref = problem.reference_dq
    err = pose_errors(g, ref)
    pg, pr = dq_to_pose(g), dq_to_pose(ref)
    paths = []

    def save(fig, name):
        p = out / f"{prefix}{name}.png"
        fig.tight_layout()
        fig.savefig(p, dpi=110)
        plt.close(fig)
        paths.append(p)

    # Fig. 8.1 / 8.7 / 8.12: pose sequence in 3D, desired vs actual.
    fig = plt.figure(figsize=(6.5, 5.5))
    ax = fig.add_subplot(projection="3d")
    ax.plot(pr[:, 0], pr[:, 1], pr[:, 2], "k--", lw=1, label="reference")
    ax.plot(pg[:, 0], pg[:, 1], pg[:, 2], "C0", lw=1.5, label="end effector")
    step = max(1, len(t) // 12)
    for k in range(0, len(t), step):
        rot = _core.quat_to_matrix(np.asarray(pg[k, 3:7]))
        for c, col in enumerate(("r", "g", "b")):
            a = rot[:, c] * 0.15
            ax.plot([pg[k, 0], pg[k, 0] + a[0]], [pg[k, 1], pg[k, 1] + a[1]], [pg[k, 2], pg[k, 2] + a[2]], col, lw=0.8)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")
    ax.legend()
    ax.set_title("End-effector poses (axes every %.1f s)" % (step * problem.dt))
    save(fig, "ee_poses_3d")

    # Fig. 8.2 / 8.8: error quaternion and position error in G.
    fig, axs = plt.subplots(2, 1, figsize=(7, 5.5), sharex=True)
    for i, lab in enumerate(("q0", "q1", "q2", "q3")):
        axs[0].plot(t, err["error_dq"][:, i], label=lab)
    axs[0].set_ylabel("error quaternion q_D/G")
    axs[0].legend(ncol=4, fontsize=8)
    for i, lab in enumerate(("x", "y", "z")):
        axs[1].plot(t, err["position"][:, i], label=lab)
    axs[1].set_ylabel("position error in G [m]")
    axs[1].set_xlabel("t [s]")
    axs[1].legend(ncol=3, fontsize=8)
    save(fig, "error_quaternion_position")

    # Fig. 8.3 / 8.9: error Euler angle and error-vector norm.
    fig, axs = plt.subplots(2, 1, figsize=(7, 5), sharex=True)
    axs[0].plot(t, np.degrees(err["angle"]))
    axs[0].set_ylabel("error Euler angle [deg]")
    axs[1].semilogy(t, np.maximum(np.linalg.norm(err["position"], axis=1), 1e-12))
    axs[1].set_ylabel("|position error| [m]")
    axs[1].set_xlabel("t [s]")
    save(fig, "error_angle_norm")

    # Fig. 8.4 / 8.10: base forces and torques.
    fig, axs = plt.subplots(2, 1, figsize=(7, 5), sharex=True)
    for i, lab in enumerate("xyz"):
        axs[0].plot(tu, us[:, i], label=f"f_{lab}")
        axs[1].plot(tu, us[:, 3 + i], label=f"tau_{lab}")
    axs[0].set_ylabel("base force [N]")
    axs[1].set_ylabel("base torque [N m]")
    axs[1].set_xlabel("t [s]")
    axs[0].legend(ncol=3, fontsize=8)
    axs[1].legend(ncol=3, fontsize=8)
    save(fig, "base_wrench")

    # Fig. 8.5 / 8.11: joint torques and the wrist's Euler-angle rates (or torques, with a torque-driven wrist).
    names = m.joint_names[1:]
    rate = set(problem.rate_joints)
    fig, axs = plt.subplots(2, 1, figsize=(7, 5), sharex=True)
    for j, name in enumerate(names):
        a = axs[1] if name.startswith("wrist") or name in rate else axs[0]
        a.plot(tu, us[:, 6 + j], label=name)
    axs[0].set_ylabel("arm joint torques [N m]")
    axs[1].set_ylabel("wrist rates [rad/s]" if rate else "wrist torques [N m]")
    axs[1].set_xlabel("t [s]")
    axs[0].legend(fontsize=8)
    axs[1].legend(fontsize=8)
    save(fig, "joint_torques")

    # Fig. 8.14: joint angles.
    fig, ax = plt.subplots(figsize=(7, 3.5))
    for j, name in enumerate(names):
        ax.plot(t, np.degrees(xs[:, m.idx_q[j + 1]]), label=name)
    if problem.keep_out:
        ax.axhspan(-1, 1, color="0.85", label="keep-out band")
    ax.set_ylabel("joint angle [deg]")
    ax.set_xlabel("t [s]")
    ax.legend(fontsize=8, ncol=3)
    save(fig, "joint_angles")

    # Cost per iteration.
    fig, ax = plt.subplots(figsize=(6, 3.5))
    h = sol["history"]
    ax.semilogy([x["iter"] for x in h], [x["cost"] for x in h], "o-", ms=3)
    ax.set_xlabel("iteration")
    ax.set_ylabel("cost")
    save(fig, "cost_per_iteration")
    return paths

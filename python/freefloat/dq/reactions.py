"""Joint reaction wrenches along a trajectory, from the dual-quaternion formulation (`ff.dq_dynamics`).

    r = ff.reactions.along(model, traj)      # traj: a Trajectory (q, v, tau at each sample)
    r.wrench       # (T, nbodies, 6) total wrench each joint transmits onto its child body
    r.reaction     # the constraint part: the wrench without its actuated components
    r.peaks()      # per joint: peak |reaction force|, peak |reaction torque| and their times

Wrenches are [force; torque about the child body origin] in child body axes (see `dq_dynamics`). The
actuated component is the projection on the joint's motion: the torque along a revolute axis, the force
along a prismatic axis, both of these for a cylindrical joint, the torque in the plane of a universal
joint's two axes (which turns with its second angle), the whole torque of a spherical joint; a fixed joint
has none.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..algorithms import dq_dynamics


@dataclass
class Reactions:
    t: np.ndarray
    joint_names: list[str]
    joint_types: list[str]
    wrench: np.ndarray  # (T, nbodies, 6)
    reaction: np.ndarray  # (T, nbodies, 6)
    max_acceleration_mismatch: float  # max |a_dq - traj.ddq| / max(1, |traj.ddq|), a consistency check

    def peaks(self) -> list[dict]:
        out = []
        for i, name in enumerate(self.joint_names):
            f = np.linalg.norm(self.reaction[:, i, :3], axis=1)
            tq = np.linalg.norm(self.reaction[:, i, 3:], axis=1)
            kf, kt = int(np.argmax(f)), int(np.argmax(tq))
            out.append(
                {
                    "joint": name,
                    "type": self.joint_types[i],
                    "peak_force": float(f[kf]),
                    "t_peak_force": float(self.t[kf]),
                    "peak_torque": float(tq[kt]),
                    "t_peak_torque": float(self.t[kt]),
                }
            )
        return out


def reaction_part(model, W: np.ndarray, q: np.ndarray | None = None) -> np.ndarray:
    """Remove the actuated components from joint wrenches W (..., nbodies, 6). A universal joint's motion
    directions depend on the configuration, so models with one need `q` (..., nq) matching W's samples."""
    R = np.array(W, dtype=float, copy=True)
    axes = np.asarray(model.joint_axes, float)
    if "universal" in model.joint_types:
        if q is None:
            raise ValueError(
                "reaction_part: the model has universal joints, whose motion directions depend on q; pass q"
            )
        q = np.asarray(q, float)
        axes2 = np.asarray(model.joint_axes2, float)
    for i, kind in enumerate(model.joint_types):
        if model.parents[i] < 0:
            if kind != "fixed":
                R[..., i, :] = 0.0  # a free base joint transmits only its actuation; a fixed one only reaction
            continue
        a = axes[i] / np.linalg.norm(axes[i])
        if kind == "revolute":
            R[..., i, 3:] -= np.einsum("...k,k->...", R[..., i, 3:], a)[..., None] * a
        elif kind == "prismatic":
            R[..., i, :3] -= np.einsum("...k,k->...", R[..., i, :3], a)[..., None] * a
        elif kind == "cylindrical":  # actuated: the force along and the torque about the axis
            R[..., i, :3] -= np.einsum("...k,k->...", R[..., i, :3], a)[..., None] * a
            R[..., i, 3:] -= np.einsum("...k,k->...", R[..., i, 3:], a)[..., None] * a
        elif kind == "universal":
            # torque along R(a2, θ2)ᵀ a1 and along a2 (orthonormal): the two actuated directions
            a2 = axes2[i] / np.linalg.norm(axes2[i])
            th = q[..., model.idx_q[i] + 1]
            c, s = np.cos(th)[..., None], np.sin(th)[..., None]
            # Rodrigues for R(a2, -θ) a with a ⟂ a2: a cos θ − (a2 × a) sin θ
            s1 = a * c - np.cross(a2, a) * s
            R[..., i, 3:] -= np.einsum("...k,...k->...", R[..., i, 3:], s1)[..., None] * s1
            R[..., i, 3:] -= np.einsum("...k,k->...", R[..., i, 3:], a2)[..., None] * a2
        elif kind == "spherical":
            R[..., i, 3:] = 0.0
    return R


def along(model, traj, fext=None) -> Reactions:
    """Joint wrenches at every sample of `traj` (its q, v and the generalized forces tau that acted)."""
    a, W = dq_dynamics(model, traj.q, traj.v, traj.tau, fext)
    scale = max(1.0, float(np.abs(traj.ddq).max())) if traj.ddq.size else 1.0
    mismatch = float(np.abs(a - traj.ddq).max()) / scale if a.size else 0.0
    return Reactions(
        np.asarray(traj.t),
        list(model.joint_names),
        list(model.joint_types),
        W,
        reaction_part(model, W, traj.q),
        mismatch,
    )


def plot(r: Reactions, path, title: str | None = None):
    from ..viz import pyplot

    plt = pyplot()
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(9, 6), sharex=True)
    for i, name in enumerate(r.joint_names):
        if r.joint_types[i] in ("free", "planar") or i == 0:
            continue
        ax1.plot(r.t, np.linalg.norm(r.reaction[:, i, :3], axis=1), label=name)
        ax2.plot(r.t, np.linalg.norm(r.reaction[:, i, 3:], axis=1), label=name)
    ax1.set_ylabel("|reaction force| [N]")
    ax2.set_ylabel("|reaction torque| [N m]")
    ax2.set_xlabel("t [s]")
    ax1.legend(fontsize="small", ncol=3)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path

"""MuJoCo interop: models both ways, and telemetry from MuJoCo state (`pip install freefloat[mujoco]`).

    xml = model.to_mjcf("robot.xml")                      # free joint on the base, zero gravity, RK4 1 ms
    robot = ff.Model.from_mjcf("robot.xml")                # a free joint at the root becomes the free base
    telem = telemetry_from_mujoco(robot, "robot.xml", t, qpos, qvel)   # MuJoCo state -> freefloat conventions

Where each half lives, and why:
- **Writing** MJCF is in the engine (`crates/freefloat-core/src/model/mjcf.rs`), beside the URDF writer: it needs
  the engine's centre of mass and inertia about it, and the same full-precision number format.
- **Reading** MJCF goes through MuJoCo's own compiler (`mujoco.MjModel`), then hands the compiled numbers to the
  engine's YAML model builder. MJCF means what that compiler makes of it (default classes, `angle` units, five
  ways to write an orientation, `inertiafromgeom`, `fusestatic`, `<include>`), so a second parser (in Rust next to
  `urdf.rs`, or with the standard library's XML) would be a second, diverging copy of MuJoCo's rules; reading the
  compiled model means freefloat gets exactly the robot MuJoCo simulates. The cost is that `from_mjcf` needs the
  `mujoco` package (an optional extra), which anyone holding an MJCF file has.

State conventions (each checked against MuJoCo itself in tests/test_mujoco.py):
- free joint: `qpos` = [position of the body frame (world), quaternion **w, x, y, z**], `qvel` = [linear velocity
  of the body-frame origin in the **world** frame, angular velocity in the **body** frame];
  freefloat: q = [position, quaternion **x, y, z, w**], v = [linear velocity in the **base** frame, angular in the
  base frame]. So the quaternion is reordered and the linear velocity rotated by Rᵀ.
- ball joint: quaternion w-first (reordered), angular velocity in the child frame (as freefloat's spherical joint).
- hinge/slide: freefloat q = qpos − qpos0 (MuJoCo places bodies at `ref`, freefloat at q = 0), v = qvel.
Joints are matched by name (then by body name, for unnamed MuJoCo joints), never by position in the arrays."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .._core import InputError
from .mjcf import FIXED_PREFIX, TAG_PREFIX, _xyzw, load_mjmodel, mujoco_module
from .telemetry import Telemetry

__all__ = [
    "FIXED_PREFIX",
    "TAG_PREFIX",
    "load_mjmodel",
    "model_from_mjcf",
    "mujoco_module",
    "read_states",
    "state_layout",
    "telemetry_from_mujoco",
    "telemetry_from_states_file",
]


def model_from_mjcf(source, name: str | None = None):
    """A freefloat `Model` of an MJCF file (see `Model.from_mjcf`)."""
    from ..model import Model

    return Model.from_mjcf(source, name)


# -- MuJoCo state -> Telemetry ------------------------------------------------------------------------------
def state_layout(model, mj) -> list:
    """For each body of `model`, the MuJoCo joint ids that carry its coordinates, matched by joint name (a
    cylindrical/universal joint J as J.theta/J.d or J.theta1/J.theta2), else by body name. Raises InputError
    naming the joints that do not match, both ways."""
    import mujoco

    J, B = mujoco.mjtObj.mjOBJ_JOINT, mujoco.mjtObj.mjOBJ_BODY
    T = mujoco.mjtJoint
    expect = {
        "free": [T.mjJNT_FREE],
        "revolute": [T.mjJNT_HINGE],
        "prismatic": [T.mjJNT_SLIDE],
        "spherical": [T.mjJNT_BALL],
        "cylindrical": [T.mjJNT_HINGE, T.mjJNT_SLIDE],
        "universal": [T.mjJNT_HINGE, T.mjJNT_HINGE],
    }
    suffix = {"cylindrical": (".theta", ".d"), "universal": (".theta1", ".theta2")}
    layout, used, errors = [], set(), []
    for i, (jt, jn, bn) in enumerate(zip(model.joint_types, model.joint_names, model.body_names)):
        if jt not in expect:
            if jt == "fixed":
                layout.append([])
                continue
            raise InputError(f"model '{model.name}': {jt} base has no MuJoCo state mapping (free or fixed bases only)")
        want = expect[jt]
        names = [jn + s for s in suffix[jt]] if jt in suffix else [jn]
        ids = [mujoco.mj_name2id(mj, J, n) for n in names]
        if any(k < 0 for k in ids) and jt in suffix:
            ids = [mujoco.mj_name2id(mj, J, jn)] + [-1]
        if any(k < 0 for k in ids):  # by body: the joints of the MuJoCo body named like this body
            b = mujoco.mj_name2id(mj, B, bn)
            if b < 0 and i == 0 and jt == "free":  # an unnamed free base: the model's only free joint
                frees = [k for k in range(mj.njnt) if mj.jnt_type[k] == T.mjJNT_FREE]
                ids = frees if len(frees) == 1 else ids
            elif b >= 0:  # only unnamed MuJoCo joints: a named one with another name is a mismatch to report
                cand = list(range(mj.body_jntadr[b], mj.body_jntadr[b] + mj.body_jntnum[b]))
                ids = cand if cand and not any(mujoco.mj_id2name(mj, J, k) for k in cand) else ids
        if len(ids) != len(want) or any(k < 0 for k in ids):
            errors.append(f"'{jn}' ({jt}, body '{bn}')")
            layout.append(None)
            continue
        got = [int(mj.jnt_type[k]) for k in ids]
        if got != want:
            tname = {T.mjJNT_HINGE: "hinge", T.mjJNT_SLIDE: "slide", T.mjJNT_BALL: "ball", T.mjJNT_FREE: "free"}
            raise InputError(
                f"joint '{jn}' is {jt} in model '{model.name}' but the MuJoCo joint(s) "
                f"{', '.join(mujoco.mj_id2name(mj, J, k) or str(k) for k in ids)} are "
                f"{', '.join(tname[g] for g in got)}"
            )
        used.update(ids)
        layout.append(ids)
    extra = [mujoco.mj_id2name(mj, J, k) or f"#{k}" for k in range(mj.njnt) if k not in used]
    if errors or extra:
        msg = []
        if errors:
            msg.append(f"joints of model '{model.name}' not found in the MuJoCo model: {', '.join(errors)}")
        if extra:
            msg.append(f"MuJoCo joints model '{model.name}' does not have: {', '.join(extra)}")
        names = [mujoco.mj_id2name(mj, J, k) or f"#{k}" for k in range(mj.njnt)]
        raise InputError(
            "; ".join(msg) + f" (MuJoCo joints: {', '.join(names)}). Is this the model that was simulated?"
        )
    return layout


def telemetry_from_mujoco(model, mjmodel, t, qpos, qvel) -> Telemetry:
    """Telemetry in freefloat's conventions from MuJoCo states: t (T,), qpos (T, mj.nq), qvel (T, mj.nv) as
    recorded from `MjData.time`, `.qpos`, `.qvel`. `mjmodel`: the MuJoCo model that produced them (an MjModel,
    an MJCF path or text, or None for `model`'s own MJCF export). Conversions per joint, by name (module
    docstring): free-joint quaternion w-first -> x-y-z-w, its linear velocity world -> base frame (angular is
    already in the base frame), ball quaternions reordered, hinge/slide measured from `ref`."""
    from ..algorithms import quat_to_matrix

    mj = load_mjmodel(model if mjmodel is None else mjmodel)
    t = np.asarray(t, dtype=float)
    qpos = np.asarray(qpos, dtype=float)
    qvel = np.asarray(qvel, dtype=float)
    if t.ndim != 1:
        raise InputError(f"argument `t`: expected a 1-D array of times, got shape {t.shape}")
    for nm_, a, n, what in (("qpos", qpos, mj.nq, "nq"), ("qvel", qvel, mj.nv, "nv")):
        if a.ndim != 2 or a.shape != (len(t), n):
            raise InputError(
                f"argument `{nm_}`: expected shape ({len(t)}, {n}) (one row per time, MuJoCo's {what} = {n} "
                f"columns), got {a.shape}"
            )
        if not np.all(np.isfinite(a)):
            r = int(np.argmax(~np.all(np.isfinite(a), axis=1)))
            raise InputError(f"argument `{nm_}`: row {r} is not finite")
    layout = state_layout(model, mj)
    q, v = np.zeros((len(t), model.nq)), np.zeros((len(t), model.nv))
    for i, ids in enumerate(layout):
        iq, iv, jt = model.idx_q[i], model.idx_v[i], model.joint_types[i]
        if not ids:
            continue
        a, d = mj.jnt_qposadr[ids[0]], mj.jnt_dofadr[ids[0]]
        if jt in ("free", "spherical"):
            o = a + (3 if jt == "free" else 0)
            n = np.linalg.norm(qpos[:, o : o + 4], axis=1)
            if np.any(np.abs(n - 1) > 1e-6):
                r = int(np.argmax(np.abs(n - 1) > 1e-6))
                raise InputError(
                    f"argument `qpos`: row {r}, columns {o}..{o + 3} (quaternion of joint '{model.joint_names[i]}'): "
                    f"norm {n[r]:.6g}, not a unit quaternion"
                )
        if jt == "free":
            q[:, iq : iq + 3] = qpos[:, a : a + 3]
            q[:, iq + 3 : iq + 7] = _xyzw(qpos[:, a + 3 : a + 7])
            R = quat_to_matrix(q[:, iq + 3 : iq + 7])  # base -> world
            v[:, iv : iv + 3] = np.einsum("tji,tj->ti", R, qvel[:, d : d + 3])  # Rᵀ v_world
            v[:, iv + 3 : iv + 6] = qvel[:, d + 3 : d + 6]
        elif jt == "spherical":
            q[:, iq : iq + 4] = _xyzw(qpos[:, a : a + 4])
            v[:, iv : iv + 3] = qvel[:, d : d + 3]
        else:  # revolute, prismatic, cylindrical, universal: one coordinate per MuJoCo joint
            for k, jid in enumerate(ids):
                a, d = mj.jnt_qposadr[jid], mj.jnt_dofadr[jid]
                q[:, iq + k] = qpos[:, a] - mj.qpos0[a]
                v[:, iv + k] = qvel[:, d]
    return Telemetry(t=t.copy(), q=q, v=v, model_name=model.name, q_labels=model.q_labels(), v_labels=model.v_labels())


def read_states(path) -> tuple:
    """(t, qpos, qvel) from an .npz file holding arrays `t` (or `time`), `qpos` and `qvel`."""
    p = Path(path)
    if not p.exists():
        raise FileNotFoundError(f"states file not found: {p}")
    try:
        z = np.load(p, allow_pickle=False)
    except (OSError, ValueError) as e:
        raise InputError(f"{p}: cannot be read as a numpy .npz file ({e})") from None
    keys = set(getattr(z, "files", []))
    tk = "t" if "t" in keys else "time" if "time" in keys else None
    missing = [k for k, ok in (("t", tk), ("qpos", "qpos" in keys), ("qvel", "qvel" in keys)) if not ok]
    if missing:
        raise InputError(
            f"{p}: missing array(s) {', '.join(missing)} (expected `t`, `qpos`, `qvel` as recorded from MjData; "
            f"the file has {', '.join(sorted(keys)) or 'none'})"
        )
    return z[tk], z["qpos"], z["qvel"]


def telemetry_from_states_file(model, path, mjmodel=None) -> Telemetry:
    """`telemetry_from_mujoco` on an .npz of `t`, `qpos`, `qvel` (see `read_states`)."""
    t, qpos, qvel = read_states(path)
    return telemetry_from_mujoco(model, mjmodel, t, qpos, qvel)

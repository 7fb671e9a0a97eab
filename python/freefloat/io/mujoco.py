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

import re
import warnings
from pathlib import Path

import numpy as np

from .._core import InputError, ModelError
from .telemetry import Telemetry

#: MJCF custom text elements carrying freefloat's body tags (wheel, known, ...) through a round trip
TAG_PREFIX = "freefloat.tags."
#: ... and the names of fixed joints, which have no MJCF element
FIXED_PREFIX = "freefloat.fixed_joint."


def mujoco_module():
    """The `mujoco` package, or a clear error saying how to install it."""
    try:
        import mujoco
    except ImportError:
        raise InputError(
            "MuJoCo interop needs the `mujoco` package: pip install 'freefloat[mujoco]' (or pip install mujoco)"
        ) from None
    return mujoco


def load_mjmodel(source):
    """A compiled `mujoco.MjModel` from an MjModel, an MJCF path, MJCF text, or a freefloat `Model` (its export)."""
    mujoco = mujoco_module()
    if isinstance(source, mujoco.MjModel):
        return source
    if hasattr(source, "to_mjcf"):
        return mujoco.MjModel.from_xml_string(source.to_mjcf())
    if isinstance(source, str) and source.lstrip().startswith("<"):
        return _compile(lambda: mujoco.MjModel.from_xml_string(source), "<string>")
    p = Path(source)
    if not p.exists():
        raise FileNotFoundError(f"MJCF file not found: {p}")
    return _compile(lambda: mujoco.MjModel.from_xml_path(str(p)), str(p))


def _compile(fn, where):
    try:
        return fn()
    except ValueError as e:  # MuJoCo's compiler errors (they carry the element and line)
        raise ModelError(f"{where}: MuJoCo cannot compile this model: {' '.join(str(e).split())}") from None


# -- MJCF -> Model ----------------------------------------------------------------------------------------
def model_from_mjcf(source, name: str | None = None):
    """A freefloat `Model` of an MJCF file (see `Model.from_mjcf`)."""
    from ..model import Model

    text = Path(source).read_text() if not (isinstance(source, str) and source.lstrip().startswith("<")) else source
    where = "<string>" if text is source else str(source)
    spec = _spec_from_mjmodel(load_mjmodel(source), text, where, name)
    import yaml

    return Model.from_yaml_string(yaml.safe_dump(spec, sort_keys=False))


def _line(text: str, tag: str, name: str) -> str:
    """' (line N)' of the first <tag ... name="name"> in the MJCF text, or '' (defaults, includes)."""
    if not name:
        return ""
    m = re.search(rf"<{tag}\b[^>]*\bname\s*=\s*[\"']{re.escape(name)}[\"']", text)
    return f" (line {text.count(chr(10), 0, m.start()) + 1})" if m else ""


def _spec_from_mjmodel(mj, text: str, where: str, name: str | None) -> dict:
    """The YAML model description (docs/model_format.md) of a compiled MuJoCo model, with every MuJoCo feature
    freefloat cannot represent refused by name."""
    import mujoco

    from ..algorithms import quat_to_matrix

    def nm(obj, i):
        return mujoco.mj_id2name(mj, obj, i) or ""

    J, B = mujoco.mjtObj.mjOBJ_JOINT, mujoco.mjtObj.mjOBJ_BODY
    problems = []
    if mj.ntendon:
        tendons = ", ".join(nm(mujoco.mjtObj.mjOBJ_TENDON, i) or str(i) for i in range(mj.ntendon))
        problems.append(f"{mj.ntendon} tendon(s) ({tendons})")
    if mj.neq:
        problems.append(f"{mj.neq} equality constraint(s) (closed loops, welds, couplings)")
    if getattr(mj, "nflex", 0):
        problems.append(f"{mj.nflex} flex object(s)")
    contact_off = bool(mj.opt.disableflags & mujoco.mjtDisableBit.mjDSBL_CONTACT)
    hits = [g for g in range(mj.ngeom) if (mj.geom_contype[g] or mj.geom_conaffinity[g])]
    if hits and not contact_off:
        names = [
            f"'{nm(mujoco.mjtObj.mjOBJ_GEOM, g) or g}' on body '{nm(B, mj.geom_bodyid[g]) or 'world'}'"
            f"{_line(text, 'geom', nm(mujoco.mjtObj.mjOBJ_GEOM, g))}"
            for g in hits[:5]
        ]
        problems.append(
            f"{len(hits)} geom(s) with contact enabled ({', '.join(names)}{', ...' if len(hits) > 5 else ''}); "
            'freefloat has no contact model: set contype="0" conaffinity="0" on them, or '
            '<option><flag contact="disable"/></option>'
        )
    arm = [j for j in range(mj.njnt) if mj.dof_armature[mj.jnt_dofadr[j]] != 0]
    if arm:
        problems.append(
            "armature (rotor inertia freefloat does not model) on joint(s) "
            + ", ".join(f"'{nm(J, j)}'{_line(text, 'joint', nm(J, j))}" for j in arm)
        )
    if problems:
        raise ModelError(f"{where}: this MuJoCo model uses what freefloat cannot represent: " + "; ".join(problems))
    ignored = [
        nm(J, j) or str(j)
        for j in range(mj.njnt)
        if mj.dof_damping[mj.jnt_dofadr[j]] or mj.jnt_stiffness[j] or mj.dof_frictionloss[mj.jnt_dofadr[j]]
    ]
    if ignored:
        warnings.warn(
            f"{where}: joint damping/stiffness/friction on {', '.join(ignored)} is ignored (internal forces: they do "
            "not change the total momentum identification uses, but freefloat simulations leave them out)",
            stacklevel=3,
        )

    roots = [b for b in range(1, mj.nbody) if mj.body_parentid[b] == 0]
    if len(roots) != 1:
        raise ModelError(
            f"{where}: expected one body tree under <worldbody>, found {len(roots)} root bodies "
            f"({', '.join(nm(B, b) or str(b) for b in roots)})"
        )
    tags, fixed_names = {}, {}
    for k in range(mj.ntext):
        tn = nm(mujoco.mjtObj.mjOBJ_TEXT, k)
        a = mj.text_adr[k]
        raw = bytes(mj.text_data[a : a + mj.text_size[k]]).split(b"\0")[0].decode()
        if tn.startswith(TAG_PREFIX):
            tags[tn[len(TAG_PREFIX) :]] = raw.split()
        elif tn.startswith(FIXED_PREFIX):
            fixed_names[tn[len(FIXED_PREFIX) :]] = raw.strip()

    def fmt(x):
        return [float(v) for v in np.asarray(x, dtype=float)]

    offset = {}  # body -> joint anchor in the MuJoCo body frame: freefloat's body frame sits there
    bodies, used_names = [], set()
    for b in range(1, mj.nbody):
        bname = nm(B, b) or f"body{b}"
        js = list(range(mj.body_jntadr[b], mj.body_jntadr[b] + mj.body_jntnum[b])) if mj.body_jntnum[b] > 0 else []
        types = [int(mj.jnt_type[j]) for j in js]
        T = mujoco.mjtJoint
        jnames = [nm(J, j) for j in js]
        where_j = ", ".join(f"'{n or '(unnamed)'}'{_line(text, 'joint', n)}" for n in jnames)
        body = {"name": bname}
        if b == roots[0]:
            if types == [T.mjJNT_FREE]:
                base = "free"
            elif not types:
                base = "fixed"
                if np.any(mj.body_pos[b] != 0) or np.any(mj.body_quat[b] != [1, 0, 0, 0]):
                    warnings.warn(
                        f"{where}: the fixed base '{bname}' is placed away from the world origin; freefloat's fixed "
                        "base sits at the origin (this only matters with gravity)",
                        stacklevel=3,
                    )
            else:
                raise ModelError(
                    f"{where}: root body '{bname}' has joint(s) {where_j}: freefloat needs a free joint (floating "
                    "base) or none (fixed base) at the root"
                )
            offset[b] = np.zeros(3)
        else:
            anchors = {tuple(mj.jnt_pos[j]) for j in js}
            if len(anchors) > 1:
                raise ModelError(f"{where}: body '{bname}': joints {where_j} have different anchors (pos)")
            offset[b] = np.array(anchors.pop()) if anchors else np.zeros(3)
            joint = _joint_spec(mj, js, types, jnames, bname, where, where_j)
            if not js and fixed_names.get(bname):
                joint["name"] = fixed_names[bname]
            if joint["name"] in used_names:
                joint["name"] = f"{bname}_joint"
            used_names.add(joint["name"])
            p = mj.body_parentid[b]
            R = quat_to_matrix(_xyzw(mj.body_quat[b]))
            body["parent"] = nm(B, p) or f"body{p}"
            body["joint"] = joint
            body["origin"] = {
                "xyz": fmt(mj.body_pos[b] + R @ offset[b] - offset[p]),
                "quat": fmt(_xyzw(mj.body_quat[b])),
            }
        m = float(mj.body_mass[b])
        if m > 0:
            Ri = quat_to_matrix(_xyzw(mj.body_iquat[b]))
            Ic = Ri @ np.diag(mj.body_inertia[b]) @ Ri.T  # principal inertia rotated back to the body axes
            Ic = 0.5 * (Ic + Ic.T)
            body["inertial"] = {
                "mass": m,
                "com": fmt(mj.body_ipos[b] - offset[b]),
                "inertia": {
                    "xx": float(Ic[0, 0]),
                    "yy": float(Ic[1, 1]),
                    "zz": float(Ic[2, 2]),
                    "xy": float(Ic[0, 1]),
                    "xz": float(Ic[0, 2]),
                    "yz": float(Ic[1, 2]),
                },
            }
        if bname in tags:
            body["tags"] = tags[bname]
        bodies.append(body)
    frames = []
    for s in range(mj.nsite):
        b = mj.site_bodyid[s]
        if b == 0:
            continue
        frames.append(
            {
                "name": nm(mujoco.mjtObj.mjOBJ_SITE, s) or f"site{s}",
                "body": nm(B, b) or f"body{b}",
                "origin": {"xyz": fmt(mj.site_pos[s] - offset[b]), "quat": fmt(_xyzw(mj.site_quat[s]))},
            }
        )
    raw_name = bytes(mj.names).split(b"\0")[0].decode(errors="replace")  # <mujoco model="..."> comes first
    model_name = name or re.sub(r"[^A-Za-z0-9_-]", "_", raw_name) or "mjcf_robot"
    spec = {"name": model_name, "base": base, "gravity": fmt(mj.opt.gravity), "angles": "rad", "bodies": bodies}
    if frames:
        spec["frames"] = frames
    return spec


def _joint_spec(mj, js, types, jnames, bname, where, where_j) -> dict:
    import mujoco

    T = mujoco.mjtJoint
    axes = [np.asarray(mj.jnt_axis[j], dtype=float) for j in js]

    def limits(j):
        if not mj.jnt_limited[j]:
            return {}
        lo, hi = (float(x) for x in mj.jnt_range[j])
        return {"limits": {"lower": lo, "upper": hi}}

    if not types:
        return {"name": f"{bname}_joint", "type": "fixed"}
    if len(types) == 1:
        kind = {T.mjJNT_HINGE: "revolute", T.mjJNT_SLIDE: "prismatic", T.mjJNT_BALL: "spherical"}.get(types[0])
        if kind is None:
            raise ModelError(
                f"{where}: body '{bname}': joint {where_j} is a free joint below the root; freefloat has one "
                "free joint, at the base"
            )
        out = {"name": jnames[0] or f"{bname}_joint", "type": kind}
        if kind != "spherical":
            out["axis"] = [float(x) for x in axes[0]]
            out.update(limits(js[0]))
        return out
    if len(types) == 2 and types == [T.mjJNT_HINGE, T.mjJNT_SLIDE] and np.allclose(axes[0], axes[1], atol=1e-12):
        return {
            "name": _stem(jnames, (".theta", ".d"), bname),
            "type": "cylindrical",
            "axis": list(map(float, axes[0])),
        }
    if len(types) == 2 and types == [T.mjJNT_HINGE, T.mjJNT_HINGE] and abs(float(axes[0] @ axes[1])) <= 1e-9:
        return {
            "name": _stem(jnames, (".theta1", ".theta2"), bname),
            "type": "universal",
            "axis": list(map(float, axes[0])),
            "axis2": list(map(float, axes[1])),
        }
    kinds = ", ".join(
        {T.mjJNT_HINGE: "hinge", T.mjJNT_SLIDE: "slide", T.mjJNT_BALL: "ball", T.mjJNT_FREE: "free"}[t] for t in types
    )
    raise ModelError(
        f"{where}: body '{bname}' has joints {where_j} ({kinds}); freefloat maps one joint per body, or a hinge "
        "then a slide on the same axis (cylindrical), or two hinges on orthogonal axes (universal)"
    )


def _stem(jnames, suffixes, bname) -> str:
    if all(n.endswith(s) for n, s in zip(jnames, suffixes)):
        return jnames[0][: -len(suffixes[0])]
    return jnames[0] or f"{bname}_joint"


def _xyzw(q_wxyz) -> np.ndarray:
    q = np.asarray(q_wxyz, dtype=float)
    return np.concatenate([q[..., 1:4], q[..., 0:1]], axis=-1)


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

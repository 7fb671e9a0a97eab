"""MJCF in: MuJoCo's compiler reads the file, and the compiled numbers become the YAML model description that the
engine's model builder reads (`Model.from_mjcf`). Why through MuJoCo's compiler, and the state conventions of the
other direction: `freefloat/io/mujoco.py`. This module imports no other part of freefloat but the engine and the
rotation helper, so `Model` can use it without an import cycle."""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import numpy as np

from .._core import InputError, ModelError

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
def mjcf_spec(source, name: str | None = None) -> dict:
    """The YAML model description (docs/model_format.md) of an MJCF file or text, as MuJoCo's compiler reads it
    (`Model.from_mjcf` builds the model from it)."""
    text = Path(source).read_text() if not (isinstance(source, str) and source.lstrip().startswith("<")) else source
    where = "<string>" if text is source else str(source)
    return _spec_from_mjmodel(load_mjmodel(source), text, where, name)


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

"""Self-checks of the oracle itself: random trees, their YAML, and the Pinocchio models built from them.

These need only numpy, PyYAML and Pinocchio (not freefloat), so they run in CI before and after the engine
exists.  If one fails, the oracle tests in test_pinocchio_oracle.py cannot be trusted.
"""

import math
from collections import Counter

import numpy as np
import pytest

import random_trees as rt  # tests/ is on sys.path under pytest's default import mode
from random_trees import assert_close

yaml = pytest.importorskip("yaml")
pin = pytest.importorskip("pinocchio", reason="Pinocchio (PyPI `pin`) is needed for the oracle self-checks")


SEEDS = rt.TREE_SEEDS
N_STATES = 3


def _states(desc, seed, n=N_STATES):
    rng = np.random.default_rng(10_000 + seed)
    for _ in range(n):
        yield (
            desc.random_q(rng),
            desc.random_v(rng),
            rng.normal(size=desc.nv),
            rng.normal(size=desc.nv),
            desc.random_fext(rng),
        )


_cache = {}


def tree(seed):
    """(description, Pinocchio tree); built once per seed."""
    if seed not in _cache:
        d = rt.tree_from_seed(seed)
        _cache[seed] = (d, rt.build_pinocchio(d))
    return _cache[seed]


def spatial_inertia(params):
    """6x6 spatial inertia about the body origin, [linear; angular] layout, from the 10 standard parameters."""
    m, mc, (Ixx, Ixy, Iyy, Ixz, Iyz, Izz) = params[0], params[1:4], params[4:]
    Io = np.array([[Ixx, Ixy, Ixz], [Ixy, Iyy, Iyz], [Ixz, Iyz, Izz]])
    return np.block([[m * np.eye(3), -rt.skew(mc)], [rt.skew(mc), Io]])


# ----------------------------------------------------------------------------------------------------------------
# YAML rendering
# ----------------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "x",
    [0.0, -0.0, 1.0, -2.5, 1e-05, 1.5e-07, 1e20, 6.02214076e23, 0.1, 1 / 3, math.pi, -1e-300, 5e-324, 123456789.125],
)
def test_yaml_float_round_trips_through_pyyaml(x):
    s = rt.yaml_float(x)
    back = yaml.safe_load(f"v: {s}")["v"]
    assert isinstance(back, float), f"{s!r} was read back as {type(back).__name__}"
    assert back == x and math.copysign(1, back) == math.copysign(1, x)


def test_numpy_geometry_matches_pinocchio():
    """The generator's own rotation helpers agree with Pinocchio's (URDF rpy, xyzw quaternions, axis-angle)."""
    rng = np.random.default_rng(7)
    # a known case first: yaw = 90 deg maps x to y; roll is applied first (R = Rz Ry Rx)
    assert_close(rt.rpy_to_matrix([0, 0, math.pi / 2]) @ [1, 0, 0], [0, 1, 0], atol=1e-15)
    assert_close(rt.rpy_to_matrix([0.3, 0.2, 0.1]), rt.rot_z(0.1) @ rt.rot_y(0.2) @ rt.rot_x(0.3), rtol=0, atol=0)
    for _ in range(50):
        rpy = rng.uniform(-3, 3, 3)
        assert_close(rt.rpy_to_matrix(rpy), pin.rpy.rpyToMatrix(rpy), rtol=1e-14, atol=1e-15, what="rpy")
        qx = rt.random_unit_quaternion(rng)
        assert_close(
            rt.quat_to_matrix(qx), pin.Quaternion(qx).toRotationMatrix(), rtol=1e-14, atol=1e-15, what="quaternion xyzw"
        )
        ax, th = rt.random_axis(rng), rng.uniform(-4, 4)
        assert_close(
            rt.axis_angle_matrix(ax, th),
            pin.AngleAxis(th, ax).toRotationMatrix(),
            rtol=1e-14,
            atol=1e-15,
            what="axis-angle",
        )


def _parse_yaml_model(text):
    """Re-read our YAML with an independent mini-loader following docs/model_format.md, into arrays."""
    doc = yaml.safe_load(text)
    deg = doc.get("angles", "rad") == "deg"
    ang = (lambda a: math.radians(a)) if deg else (lambda a: a)
    names = [b["name"] for b in doc["bodies"]]
    out = {
        "base": doc.get("base", "free"),
        "gravity": np.array(doc.get("gravity", [0.0, 0.0, 0.0]), float),
        "names": names,
        "parents": [],
        "types": [],
        "axes": [],
        "axes2": [],
        "placements": [],
        "params": [],
        "jnames": [],
    }
    for k, b in enumerate(doc["bodies"]):
        inertial = b["inertial"]
        if "params" in inertial:
            params = np.array(inertial["params"], float)
        else:
            m, c = float(inertial["mass"]), np.array(inertial["com"], float)
            t = inertial.get("inertia", inertial.get("inertia_origin"))
            I = np.array(
                [
                    [t["xx"], t.get("xy", 0.0), t.get("xz", 0.0)],
                    [t.get("xy", 0.0), t["yy"], t.get("yz", 0.0)],
                    [t.get("xz", 0.0), t.get("yz", 0.0), t["zz"]],
                ],
                float,
            )
            if "inertia" in inertial:
                I = rt.inertia_about_origin(m, c, I)
            params = np.array([m, *(m * c), I[0, 0], I[0, 1], I[1, 1], I[0, 2], I[1, 2], I[2, 2]])
        out["params"].append(params)
        if k == 0:
            out["parents"].append(-1)
            out["types"].append(out["base"])
            out["axes"].append(None)
            out["axes2"].append(None)
            out["placements"].append(np.eye(4))
            out["jnames"].append(None)
            continue
        j = b["joint"]
        out["parents"].append(names.index(b["parent"]))
        out["types"].append(j["type"])
        out["jnames"].append(j.get("name", f"{b['name']}_joint"))
        if j["type"] in ("revolute", "prismatic", "cylindrical", "universal"):
            ax = np.array(j.get("axis", [0.0, 0.0, 1.0]), float)
            out["axes"].append(ax / np.linalg.norm(ax))
        else:
            out["axes"].append(None)
        ax2 = np.array(j["axis2"], float) if "axis2" in j else None
        out["axes2"].append(None if ax2 is None else ax2 / np.linalg.norm(ax2))
        T = np.eye(4)
        if "origin" in b:
            o = b["origin"]
            # Pinocchio's rpy (the URDF convention), not ours: an independent reading of the file
            T = rt.homogeneous(
                pin.rpy.rpyToMatrix(np.array([ang(a) for a in o.get("rpy", [0, 0, 0])], float)), o.get("xyz", [0, 0, 0])
            )
        if "mdh" in b:
            h = b["mdh"]
            T = (
                T
                @ rt.homogeneous(rt.rot_x(ang(h["alpha"])))
                @ rt.homogeneous(p=[h["a"], 0, 0])
                @ rt.homogeneous(rt.rot_z(ang(h["theta"])))
                @ rt.homogeneous(p=[0, 0, h["d"]])
            )
        out["placements"].append(T)
    out["frames"] = {
        f["name"]: (
            names.index(f["body"]),
            rt.homogeneous(pin.rpy.rpyToMatrix(np.array([ang(a) for a in f["origin"]["rpy"]])), f["origin"]["xyz"]),
        )
        for f in doc.get("frames", [])
    }
    return doc, out


def _leaves(node, key=None, path=""):
    """(nearest mapping key, path, value) of every scalar in a parsed YAML document."""
    if isinstance(node, dict):
        for k, v in node.items():
            yield from _leaves(v, k, f"{path}.{k}")
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from _leaves(v, key, f"{path}[{i}]")
    else:
        yield key, path, node


@pytest.mark.parametrize("seed", SEEDS)
def test_yaml_round_trips_to_the_description(seed):
    d, _ = tree(seed)
    doc, y = _parse_yaml_model(d.to_yaml())
    # every number must come back as a number (a PyYAML float-syntax slip would turn it into a string)
    text_keys = {"name", "description", "base", "angles", "parent", "type", "body"}
    for key, path, leaf in _leaves(doc):
        if key not in text_keys:
            assert isinstance(leaf, float), f"{path} = {leaf!r} is not read back as a float"
    assert y["base"] == d.base
    assert np.array_equal(y["gravity"], d.gravity)
    assert y["names"] == [b.name for b in d.bodies]
    assert y["parents"] == d.parents
    assert y["types"] == [b.joint_type for b in d.bodies]
    assert y["jnames"][1:] == [b.effective_joint_name for b in d.bodies[1:]]
    for i, b in enumerate(d.bodies):
        assert_close(y["params"][i], b.parameters(), rtol=1e-14, atol=0, what=f"params of {b.name}")
        assert_close(y["placements"][i], b.rest_placement(), rtol=1e-14, atol=1e-15, what=f"placement of {b.name}")
        if b.axis is not None:
            assert_close(y["axes"][i], b.axis, rtol=1e-15, atol=1e-16, what=f"axis of {b.name}")
        if b.axis2 is not None:
            assert_close(y["axes2"][i], b.axis2, rtol=1e-15, atol=1e-16, what=f"axis2 of {b.name}")
        else:
            assert y["axes2"][i] is None, f"{b.name}: axis2 rendered for a {b.joint_type} joint"
    for f in d.frames:
        body, T = y["frames"][f.name]
        assert body == f.body
        assert_close(T, f.placement(), rtol=1e-14, atol=1e-15, what=f"frame {f.name}")


@pytest.mark.parametrize("seed", SEEDS)
def test_inertias_are_physically_consistent_with_margin(seed):
    """The loader checks consistency to 1e-9; the generated bodies must pass with a wide margin."""
    d, _ = tree(seed)
    for b in d.bodies:
        assert b.mass > 0
        ev = np.linalg.eigvalsh(b.inertia_com)
        assert ev.min() > 1e-6 * ev.max() > 0
        a, bb, c = ev
        assert a + bb - c > 1e-3 * ev.sum(), f"{b.name}: triangle inequality has no margin {ev}"


def test_generator_covers_every_feature():
    """The 60 trees together exercise every branch of the format and of the Pinocchio conversion."""
    seen = Counter()
    for s in SEEDS:
        d, p = tree(s)
        seen[f"base:{d.base}"] += 1
        seen["gravity:nonzero" if np.any(d.gravity) else "gravity:zero"] += 1
        seen[f"angles:{d.angles}"] += 1
        seen["omit_base_key"] += d.omit_base_key
        seen["omit_gravity_key"] += d.omit_gravity_key
        seen["non_depth_first_order"] += not np.array_equal(p.v_perm, np.arange(d.nv))
        seen["many_bodies"] += d.nbodies >= 15
        seen["frames"] += len(d.frames)
        for b in d.bodies:
            seen[f"form:{b.inertial_form}"] += 1
            if b.parent < 0:
                continue
            seen[f"joint:{b.joint_type}"] += 1
            seen["default_joint_name"] += b.joint_name is None
            seen["mdh"] += b.mdh is not None
            seen["mdh+origin"] += b.mdh is not None and b.origin_xyz is not None
            seen["omitted_axis"] += b.omit_axis
            seen["scaled_axis"] += b.axis_scale != 1.0
            seen["limits"] += b.limits is not None
            par = d.bodies[b.parent]
            seen["fixed_on_fixed"] += b.joint_type == "fixed" and par.joint_type == "fixed"
            seen["moving_under_fixed"] += b.joint_type != "fixed" and par.joint_type == "fixed"
            seen["welded_to_fixed_base"] += b.joint_type == "fixed" and par.parent < 0 and par.joint_type == "fixed"
        seen["frame_on_fixed_body"] += any(d.bodies[f.body].joint_type == "fixed" for f in d.frames)
    needed = [
        "base:free",
        "base:planar",
        "base:fixed",
        "gravity:zero",
        "gravity:nonzero",
        "angles:rad",
        "angles:deg",
        "omit_base_key",
        "omit_gravity_key",
        "non_depth_first_order",
        "many_bodies",
        "frames",
        "form:com",
        "form:origin",
        "form:params",
        "joint:revolute",
        "joint:prismatic",
        "joint:spherical",
        "joint:cylindrical",
        "joint:universal",
        "joint:fixed",
        "default_joint_name",
        "mdh",
        "mdh+origin",
        "omitted_axis",
        "scaled_axis",
        "limits",
        "fixed_on_fixed",
        "moving_under_fixed",
        "welded_to_fixed_base",
        "frame_on_fixed_body",
    ]
    missing = [k for k in needed if seen[k] == 0]
    assert not missing, f"no tree exercises {missing}; counts {dict(seen)}"


# ----------------------------------------------------------------------------------------------------------------
# Pinocchio model vs the description
# ----------------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("seed", SEEDS)
def test_layout_maps(seed):
    d, p = tree(seed)
    assert p.model.nv == d.nv
    assert p.model.nq == d.nq + (d.base == "planar")
    assert sorted(p.v_perm) == list(range(d.nv))
    for q, v, *_ in _states(d, seed):
        qp = p.q_to_pin(q)
        back = p.q_from_pin(qp)
        if d.base == "planar":
            # yaw comes back wrapped to (-pi, pi]
            assert abs(math.remainder(back[2] - q[2], 2 * math.pi)) < 1e-12
            back[2] = q[2]
            assert abs(np.hypot(qp[p.pin_q_slice[0]][2], qp[p.pin_q_slice[0]][3]) - 1) < 1e-15
        assert_close(back, q, rtol=1e-15, atol=1e-15, what="q round trip")
        assert_close(p.v_from_pin(p.v_to_pin(v)), v, rtol=0, atol=0, what="v round trip")
    # q and v maps agree: moving along our v coordinate k changes only the q coordinates of the body owning k
    qp = p.q_to_pin(q)
    for i, (qs, vs) in enumerate(zip(d.q_slices(), d.v_slices())):
        for k in range(vs.start, vs.stop):
            dv = np.zeros(d.nv)
            dv[k] = 0.1
            dq = p.q_from_pin(pin.integrate(p.model, qp, p.v_to_pin(dv))) - q
            if d.base == "planar":
                dq[2] = math.remainder(dq[2], 2 * math.pi)
            moved = np.flatnonzero(np.abs(dq) > 1e-12)
            assert moved.size and set(moved) <= set(range(qs.start, qs.stop)), (i, k, dq)
    # our neutral configuration is Pinocchio's neutral
    q0 = np.concatenate(
        [
            {
                "free": [0, 0, 0, 0, 0, 0, 1],
                "planar": [0, 0, 0],
                "spherical": [0, 0, 0, 1],
                "revolute": [0],
                "prismatic": [0],
                "cylindrical": [0, 0],
                "universal": [0, 0],
                "fixed": [],
            }[b.joint_type]
            for b in d.bodies
        ]
    ).astype(float)
    assert_close(p.q_to_pin(q0), pin.neutral(p.model), rtol=0, atol=0, what="neutral")


@pytest.mark.parametrize("seed", SEEDS)
def test_pinocchio_placements_match_numpy_kinematics(seed):
    """Pinocchio frames (joints, merged fixed bodies, extra frames) vs the description's own numpy FK."""
    d, p = tree(seed)
    for q, *_ in _states(d, seed):
        X = d.body_placements(q)
        for b, T in zip(d.bodies, X):
            assert_close(p.placement(q, b.name), T, rtol=1e-12, atol=1e-12, what=f"body {b.name}")
        for name, T in d.frame_placements(q).items():
            assert_close(p.placement(q, name), T, rtol=1e-12, atol=1e-12, what=f"frame {name}")
        fk = p.forward_kinematics(q)
        for i, T in enumerate(X):
            assert_close(fk[i, :3], T[:3, 3], rtol=1e-12, atol=1e-12, what="fk position")
            assert_close(rt.quat_to_matrix(fk[i, 3:]), T[:3, :3], rtol=1e-12, atol=1e-12, what="fk quaternion")


@pytest.mark.parametrize("seed", SEEDS)
def test_merged_mass_and_com_match_direct_sum(seed):
    d, p = tree(seed)
    assert rt.pin_total_mass(p.model) == pytest.approx(d.total_mass(), rel=1e-13)
    for q, *_ in _states(d, seed):
        assert_close(p.center_of_mass(q), d.center_of_mass(q), rtol=1e-12, atol=1e-13, what="CoM")


@pytest.mark.parametrize("seed", SEEDS)
def test_aba_equals_inverse_crba(seed):
    d, p = tree(seed)
    for q, v, tau, _, fext in _states(d, seed):
        M = p.crba(q)
        assert_close(M, M.T, rtol=0, atol=0, what="M symmetric")
        assert np.linalg.eigvalsh(M).min() > 0
        nle = p.nonlinear_effects(q, v)
        assert_close(p.aba(q, v, tau), np.linalg.solve(M, tau - nle), rtol=1e-10, what="aba")
        # with external forces: the bias becomes rnea(q, v, 0, fext)
        bias_f = p.rnea(q, v, np.zeros(d.nv), fext)
        assert_close(p.aba(q, v, tau, fext), np.linalg.solve(M, tau - bias_f), rtol=1e-10, what="aba fext")


@pytest.mark.parametrize("seed", SEEDS)
def test_crba_columns_match_rnea(seed):
    """M e_k = rnea(q, 0, e_k) - rnea(q, 0, 0): catches a permutation or subtree-ordering slip in M."""
    d, p = tree(seed)
    q = next(_states(d, seed))[0]
    g = p.rnea(q, np.zeros(d.nv), np.zeros(d.nv))
    Mr = np.column_stack([p.rnea(q, np.zeros(d.nv), e) - g for e in np.eye(d.nv)])
    assert_close(p.crba(q), Mr, rtol=1e-12, what="crba vs rnea columns")


@pytest.mark.parametrize("seed", SEEDS)
def test_rnea_fext_equals_body_jacobian_transpose(seed):
    """tau(fext) = tau(0) - sum_b J_b^T f_b with J_b the LOCAL Jacobian of body b's frame: checks that forces on
    merged fixed bodies are carried to their ancestor joint correctly."""
    d, p = tree(seed)
    for q, v, _, a, fext in _states(d, seed):
        expected = p.rnea(q, v, a) - sum(
            p.frame_jacobian(q, b.name, "local").T @ fext[i] for i, b in enumerate(d.bodies)
        )
        assert_close(p.rnea(q, v, a, fext), expected, rtol=1e-12, what="rnea fext")


@pytest.mark.parametrize("seed", SEEDS)
def test_momentum_shift_matches_sum_over_bodies(seed):
    """[p; L_O] from computeCentroidalMomentum + shift == sum over the *unmerged* bodies of X_b^* (I_b v_b)."""
    d, p = tree(seed)
    for q, v, *_ in _states(d, seed):
        X = d.body_placements(q)
        total = np.zeros(6)
        for b, T in zip(d.bodies, X):
            h = spatial_inertia(b.parameters()) @ p.frame_velocity_local(q, v, b.name)
            R, o = T[:3, :3], T[:3, 3]
            lin = R @ h[:3]
            total += np.concatenate([lin, R @ h[3:] + np.cross(o, lin)])
        assert_close(p.momentum(q, v), total, rtol=1e-12, what="momentum")
        assert_close(p.centroidal_momentum_matrix(q) @ v, total, rtol=1e-12, what="A_O v")


@pytest.mark.parametrize("seed", SEEDS[:20])
def test_jacobians_match_finite_differences(seed):
    """World-aligned Jacobian columns vs central differences of the numpy FK along Pinocchio's integrate."""
    d, p = tree(seed)
    q = next(_states(d, seed))[0]
    qp = p.q_to_pin(q)
    eps = 1e-6
    names = [b.name for b in d.bodies] + [f.name for f in d.frames]

    def placements(qpin):
        qq = p.q_from_pin(qpin)
        X = d.body_placements(qq)
        F = d.frame_placements(qq)
        return [X[i] for i in range(d.nbodies)] + [F[f.name] for f in d.frames]

    fd = np.zeros((len(names), 6, d.nv))
    for k in range(d.nv):
        dv = np.zeros(d.nv)
        dv[k] = eps
        Tp = placements(pin.integrate(p.model, qp, p.v_to_pin(dv)))
        Tm = placements(pin.integrate(p.model, qp, p.v_to_pin(-dv)))
        for n, (A, B) in enumerate(zip(Tp, Tm)):
            fd[n, :3, k] = (A[:3, 3] - B[:3, 3]) / (2 * eps)
            W = (A[:3, :3] - B[:3, :3]) / (2 * eps) @ (0.5 * (A[:3, :3] + B[:3, :3])).T
            fd[n, 3:, k] = [W[2, 1], W[0, 2], W[1, 0]]
    T0 = placements(qp)
    for n, name in enumerate(names):
        Jw = p.frame_jacobian(q, name, "world")
        assert_close(Jw, fd[n], rtol=1e-6, atol=1e-7, what=f"world Jacobian of {name}")
        R = T0[n][:3, :3]
        Jl = p.frame_jacobian(q, name, "local")
        assert_close(Jl, np.vstack([R.T @ Jw[:3], R.T @ Jw[3:]]), rtol=1e-12, atol=1e-14, what=f"local J {name}")


@pytest.mark.parametrize("seed", [s for s in SEEDS if rt.tree_from_seed(s).base == "planar"][:5])
def test_planar_base_velocity_convention(seed):
    """Planar v = [vx, vy, wz] in the base frame: a pure vx step moves the base along its own x axis."""
    d, p = tree(seed)
    q = next(_states(d, seed))[0]
    yaw = q[2]
    for v_base, dpos, dyaw in [
        ([0.3, 0, 0], [0.3 * math.cos(yaw), 0.3 * math.sin(yaw)], 0.0),
        ([0, 0.2, 0], [-0.2 * math.sin(yaw), 0.2 * math.cos(yaw)], 0.0),
        ([0, 0, 0.7], [0.0, 0.0], 0.7),
    ]:
        v = np.zeros(d.nv)
        v[:3] = v_base
        q1 = p.q_from_pin(pin.integrate(p.model, p.q_to_pin(q), p.v_to_pin(v)))
        assert_close(q1[:2] - q[:2], dpos, rtol=1e-14, atol=1e-14, what="planar translation")
        assert abs(math.remainder(q1[2] - q[2] - dyaw, 2 * math.pi)) < 1e-14


# ----------------------------------------------------------------------------------------------------------------
# URDF rendering (used by the oracle's random-URDF tests)
# ----------------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("seed", rt.URDF_TREE_SEEDS)
def test_urdf_rendering_matches_direct_model(seed):
    """Pinocchio's own URDF parser on `to_urdf` text == the Pinocchio model built directly from the description."""
    base = rt.BASE_TYPES[seed % 3]
    d = rt.urdf_tree_from_seed(seed, base)
    text = d.to_urdf(render_seed=seed)
    root = {"free": pin.JointModelFreeFlyer(), "planar": pin.JointModelPlanar(), "fixed": None}[base]
    model = pin.buildModelFromXML(text) if root is None else pin.buildModelFromXML(text, root)
    model.gravity = pin.Motion.Zero()
    data = model.createData()
    L = rt.NamedLayout(model, d.joint_rows())
    p = rt.build_pinocchio(d)
    assert rt.urdf_total_mass(text) == pytest.approx(d.total_mass(), rel=1e-14)
    assert rt.pin_total_mass(model) == pytest.approx(d.total_mass(), rel=1e-13)
    names = [b.name for b in d.bodies]
    for q, v, _tau, a, fext in _states(d, seed):
        qp = L.q_to_pin(q)
        pin.framesForwardKinematics(model, data, qp)
        for b, T in zip(d.bodies, d.body_placements(q)):
            assert_close(
                data.oMf[L.body_frame(b.name)[0]].homogeneous,
                T,
                rtol=1e-12,
                atol=1e-12,
                what=f"placement of link {b.name}",
            )
        assert_close(L.matrix_from_pin(pin.crba(model, data, qp)), p.crba(q), rtol=1e-12, what="crba")
        rn = pin.rnea(model, data, qp, L.v_to_pin(v), L.v_to_pin(a), L.fext_to_pin(names, fext))
        assert_close(L.v_from_pin(rn), p.rnea(q, v, a, fext), rtol=1e-12, what="rnea fext")
        assert_close(
            rt.pin_momentum_at_origin(model, data, qp, L.v_to_pin(v)), p.momentum(q, v), rtol=1e-12, what="momentum"
        )
        assert_close(rt.pin_center_of_mass(model, data, qp), d.center_of_mass(q), rtol=1e-12, atol=1e-13, what="CoM")


def test_urdf_rendering_covers_the_format():
    import xml.etree.ElementTree as ET

    seen = Counter()
    for seed in rt.URDF_TREE_SEEDS:
        d = rt.urdf_tree_from_seed(seed)
        text = d.to_urdf(render_seed=seed)
        root = ET.fromstring(text)
        joints = root.findall("joint")
        seen["continuous"] += sum(j.get("type") == "continuous" for j in joints)
        seen["fixed"] += sum(j.get("type") == "fixed" for j in joints)
        seen["prismatic"] += sum(j.get("type") == "prismatic" for j in joints)
        seen["default_axis"] += sum(j.get("type") != "fixed" and j.find("axis") is None for j in joints)
        order = rt.urdf_depth_first_joint_order(text)
        pin_model = pin.buildModelFromXML(text, pin.JointModelFreeFlyer())
        seen["document_order_is_not_pinocchio_order"] += order != list(pin_model.names)[2:]
        seen["document_order_is_not_file_order"] += order != [
            b.effective_joint_name for b in d.bodies[1:] if b.joint_type != "fixed"
        ]
        tags = [(e.tag, e.get("name")) for e in root]
        seen["joint_before_its_child_link"] += any(
            tags.index(("link", j.find("child").get("link"))) > tags.index(("joint", j.get("name"))) for j in joints
        )
    missing = [
        k
        for k in (
            "continuous",
            "fixed",
            "prismatic",
            "default_axis",
            "document_order_is_not_pinocchio_order",
            "document_order_is_not_file_order",
            "joint_before_its_child_link",
        )
        if not seen[k]
    ]
    assert not missing, f"no URDF tree exercises {missing}: {dict(seen)}"


def test_matrix_to_rpy_inverts_rpy_to_matrix():
    rng = np.random.default_rng(3)
    for _ in range(100):
        R = rt.random_rotation(rng)
        assert_close(rt.rpy_to_matrix(rt.matrix_to_rpy(R)), R, rtol=1e-13, atol=1e-14, what="rpy round trip")

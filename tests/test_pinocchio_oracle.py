"""freefloat against Pinocchio, an independent implementation of the same rigid-body algorithms.

Two families:

* random trees (tests/random_trees.py): every tree is rendered to our YAML, loaded by freefloat, and built
  *directly from the same description* as a Pinocchio model (never from freefloat's model object).  Every
  kinematic and dynamic entry point is compared body by body, for several random states.
* real URDF robots from example-robot-data, loaded by `ff.Model.from_urdf` and by `pin.buildModelFromUrdf`;
  joints are matched by name, so the comparison does not depend on how each library orders a branched tree
  (the order freefloat promises is checked on its own, against the URDF text).  Random trees rendered to URDF
  cover what those robots leave out (rotated inertial frames, default axes, shuffled document order).

Comparisons are norm-relative (`random_trees.assert_close`) at 1e-9 with a 1e-12 floor.
"""

import functools
import math
import os
import sys
import sysconfig
import zlib

import numpy as np
import pytest

import random_trees as rt  # tests/ is on sys.path under pytest's default import mode
from random_trees import assert_close

ff = pytest.importorskip("freefloat", reason="freefloat is not importable yet (the engine is not built)")
pin = pytest.importorskip("pinocchio", reason="Pinocchio (PyPI `pin`) is needed as the oracle")


RTOL = 1e-9
ATOL = 1e-12
SEEDS = rt.TREE_SEEDS
N_STATES = 3


# ----------------------------------------------------------------------------------------------------------------
# random trees
# ----------------------------------------------------------------------------------------------------------------


@functools.cache
def case(seed):
    """(description, freefloat model, Pinocchio tree) for one seed, built once."""
    d = rt.tree_from_seed(seed)
    return d, ff.Model.from_yaml_string(d.to_yaml()), rt.build_pinocchio(d)


def states(d, seed, n=N_STATES):
    """Random (q, v, tau-or-a, fext) in our layout; a different stream from the self-checks' on purpose."""
    rng = np.random.default_rng(20_000 + seed)
    return [(d.random_q(rng), d.random_v(rng), rng.normal(size=d.nv), d.random_fext(rng)) for _ in range(n)]


def close(actual, expected, what):
    assert_close(actual, expected, rtol=RTOL, atol=ATOL, what=what)


@pytest.mark.parametrize("seed", SEEDS)
def test_model_metadata(seed):
    d, m, p = case(seed)
    assert (m.nq, m.nv, m.nbodies) == (d.nq, d.nv, d.nbodies)
    assert list(m.body_names) == [b.name for b in d.bodies]
    assert list(m.parents) == d.parents
    assert list(m.joint_types) == [b.joint_type for b in d.bodies]
    # per-body like parents/joint_types; compare the tail so a list with or without a base entry both pass
    names = list(m.joint_names)
    assert len(names) in (d.nbodies, d.nbodies - 1)
    assert names[len(names) - (d.nbodies - 1) :] == [b.effective_joint_name for b in d.bodies[1:]]
    close(np.asarray(m.gravity, float), d.gravity, "gravity")
    P = np.asarray(m.parameters(), float)
    assert P.shape == (d.nbodies, 10)
    for i, b in enumerate(d.bodies):
        close(P[i], b.parameters(), f"parameters of {b.name}")
    q0 = np.asarray(m.neutral(), float)
    close(p.q_to_pin(q0), pin.neutral(p.model), "neutral")
    rng = np.random.default_rng(seed)
    for _ in range(3):
        q = np.asarray(m.random_configuration(rng), float)
        assert q.shape == (d.nq,) and np.all(np.isfinite(q))
        for b, sl in zip(d.bodies, d.q_slices()):
            if b.joint_type in ("free", "spherical"):
                assert abs(np.linalg.norm(q[sl][-4:]) - 1.0) < 1e-12, f"{b.name}: quaternion not unit {q[sl]}"


@pytest.mark.parametrize("seed", SEEDS)
def test_forward_kinematics(seed):
    d, m, p = case(seed)
    for q, *_ in states(d, seed):
        X = np.asarray(ff.forward_kinematics(m, q), float)
        assert X.shape == (d.nbodies, 7)
        ref = p.forward_kinematics(q)
        for i, b in enumerate(d.bodies):
            close(X[i, :3], ref[i, :3], f"position of {b.name}")
            assert abs(np.linalg.norm(X[i, 3:]) - 1.0) < 1e-12, f"{b.name}: quaternion not unit"
            # compare rotations, not quaternions: q and -q are the same attitude
            close(rt.quat_to_matrix(X[i, 3:]), rt.quat_to_matrix(ref[i, 3:]), f"rotation of {b.name}")


@pytest.mark.parametrize("seed", SEEDS)
def test_center_of_mass(seed):
    d, m, p = case(seed)
    for q, *_ in states(d, seed):
        close(ff.center_of_mass(m, q), p.center_of_mass(q), "center of mass")


@pytest.mark.parametrize("seed", SEEDS)
def test_momentum(seed):
    d, m, p = case(seed)
    for q, v, *_ in states(d, seed):
        close(ff.momentum(m, q, v), p.momentum(q, v), "momentum [p; L_O]")


@pytest.mark.parametrize("seed", SEEDS)
def test_centroidal_momentum_matrix(seed):
    d, m, p = case(seed)
    for q, v, *_ in states(d, seed):
        A = np.asarray(ff.centroidal_momentum_matrix(m, q), float)
        close(A, p.centroidal_momentum_matrix(q), "momentum matrix A_O")
        close(A @ v, ff.momentum(m, q, v), "A_O v == ff.momentum")


@pytest.mark.parametrize("seed", SEEDS)
def test_frame_jacobians(seed):
    d, m, p = case(seed)
    names = [b.name for b in d.bodies] + [f.name for f in d.frames]
    for q, *_ in states(d, seed, n=2):
        for name in names:
            for ref in ("local", "world"):
                J = np.asarray(ff.frame_jacobian(m, q, name, reference=ref), float)
                close(J, p.frame_jacobian(q, name, ref), f"{ref} Jacobian of {name}")
        # "local" is the documented default
        close(ff.frame_jacobian(m, q, names[-1]), p.frame_jacobian(q, names[-1], "local"), "default reference")


@pytest.mark.parametrize("seed", SEEDS)
def test_rnea(seed):
    d, m, p = case(seed)
    for q, v, a, fext in states(d, seed):
        close(ff.rnea(m, q, v, a), p.rnea(q, v, a), "rnea")
        close(ff.rnea(m, q, v, a, fext=fext), p.rnea(q, v, a, fext), "rnea with fext")
        close(ff.rnea(m, q, v, a, fext=np.zeros((d.nbodies, 6))), p.rnea(q, v, a), "rnea with zero fext")


@pytest.mark.parametrize("seed", SEEDS)
def test_crba(seed):
    d, m, p = case(seed)
    for q, *_ in states(d, seed):
        M = np.asarray(ff.crba(m, q), float)
        close(M, p.crba(q), "crba")
        close(M, M.T, "crba symmetric")


@pytest.mark.parametrize("seed", SEEDS)
def test_aba(seed):
    d, m, p = case(seed)
    for q, v, tau, fext in states(d, seed):
        ddq = np.asarray(ff.aba(m, q, v, tau), float)
        close(ddq, p.aba(q, v, tau), "aba")
        close(ff.aba(m, q, v, tau, fext=fext), p.aba(q, v, tau, fext), "aba with fext")
        # and freefloat's own forward/inverse dynamics agree
        close(ff.rnea(m, q, v, ddq), tau, "rnea(aba(tau)) == tau")


# ---- stacked (time-series) inputs ------------------------------------------------------------------------------


def _stack_seeds():
    """A few trees: one per base type, plus the largest tree."""
    picked = {}
    for s in SEEDS:
        picked.setdefault(rt.tree_from_seed(s).base, s)
    largest = max(SEEDS, key=lambda s: rt.tree_from_seed(s).nbodies)
    return sorted(set(picked.values()) | {largest})


@pytest.mark.parametrize("seed", _stack_seeds())
def test_stacked_inputs_match_a_loop(seed):
    d, m, p = case(seed)
    T = 4
    rng = np.random.default_rng(30_000 + seed)
    Q = np.array([d.random_q(rng) for _ in range(T)])
    V = rng.normal(size=(T, d.nv))
    U = rng.normal(size=(T, d.nv))
    F = rng.normal(size=(T, d.nbodies, 6))
    name = d.bodies[-1].name

    cases = {
        "forward_kinematics": (lambda *x: ff.forward_kinematics(m, *x), (Q,), (T, d.nbodies, 7), p.forward_kinematics),
        "center_of_mass": (lambda *x: ff.center_of_mass(m, *x), (Q,), (T, 3), p.center_of_mass),
        "momentum": (lambda *x: ff.momentum(m, *x), (Q, V), (T, 6), p.momentum),
        "centroidal_momentum_matrix": (
            lambda *x: ff.centroidal_momentum_matrix(m, *x),
            (Q,),
            (T, 6, d.nv),
            p.centroidal_momentum_matrix,
        ),
        "frame_jacobian local": (
            lambda *x: ff.frame_jacobian(m, *x, name, reference="local"),
            (Q,),
            (T, 6, d.nv),
            lambda q: p.frame_jacobian(q, name, "local"),
        ),
        "frame_jacobian world": (
            lambda *x: ff.frame_jacobian(m, *x, name, reference="world"),
            (Q,),
            (T, 6, d.nv),
            lambda q: p.frame_jacobian(q, name, "world"),
        ),
        "crba": (lambda *x: ff.crba(m, *x), (Q,), (T, d.nv, d.nv), p.crba),
        "rnea": (lambda *x: ff.rnea(m, *x), (Q, V, U), (T, d.nv), p.rnea),
        "rnea fext": (lambda *x: ff.rnea(m, *x[:3], fext=x[3]), (Q, V, U, F), (T, d.nv), p.rnea),
        "aba": (lambda *x: ff.aba(m, *x), (Q, V, U), (T, d.nv), p.aba),
        "aba fext": (lambda *x: ff.aba(m, *x[:3], fext=x[3]), (Q, V, U, F), (T, d.nv), p.aba),
    }
    for what, (fn, args, shape, oracle) in cases.items():
        out = np.asarray(fn(*args), float)
        assert out.shape == shape, f"{what}: stacked output shape {out.shape}, expected {shape}"
        for t in range(T):
            single = np.asarray(fn(*(x[t] for x in args)), float)
            if what == "forward_kinematics":
                # quaternion signs may legitimately differ between code paths; compare positions and rotations
                close(out[t][:, :3], single[:, :3], f"{what} stacked vs loop, t={t}")
                for i in range(d.nbodies):
                    close(rt.quat_to_matrix(out[t, i, 3:]), rt.quat_to_matrix(single[i, 3:]), f"{what} rot t={t}")
                close(out[t][:, :3], oracle(Q[t])[:, :3], f"{what} vs Pinocchio, t={t}")
                continue
            assert_close(out[t], single, rtol=1e-12, atol=1e-14, what=f"{what} stacked vs loop, t={t}")
            close(out[t], oracle(*(x[t] for x in args)), f"{what} vs Pinocchio, t={t}")


@pytest.mark.parametrize("seed", SEEDS[:3])
def test_from_yaml_file_equals_from_string(seed, tmp_path):
    d, m, p = case(seed)
    path = tmp_path / f"{d.name}.yaml"
    path.write_text(d.to_yaml())
    m2 = ff.Model.from_yaml(str(path))
    assert (m2.nq, m2.nv, list(m2.body_names)) == (m.nq, m.nv, list(m.body_names))
    q = states(d, seed, n=1)[0][0]
    close(ff.crba(m2, q), p.crba(q), "crba of the file-loaded model")


# ----------------------------------------------------------------------------------------------------------------
# real robots from example-robot-data
# ----------------------------------------------------------------------------------------------------------------

#: name -> URDF path inside example-robot-data's `robots/` folder.  Chosen to cover a 7-DoF arm with fixed
#: links and fingers (panda), a 6-DoF arm whose root link is a massless "world" (ur5), continuous joints
#: (kinova: Pinocchio stores them as cos/sin), branched trees with many fixed links (solo12, a1) and a dual-arm
#: torso with prismatic fingers (baxter).  A1's file lists its legs FR, FL, RR, RL, which is not the
#: alphabetical order Pinocchio uses.  Mimic tags (panda, baxter fingers) are ignored by both libraries.
#: ANYmal is not here: its URDF has a non-physical dummy inertia, which freefloat rejects (tested below).
ERD_ROBOTS = {
    "panda": "panda_description/urdf/panda.urdf",
    "ur5": "ur_description/urdf/ur5_robot.urdf",
    "kinova": "kinova_description/robots/kinova.urdf",
    "solo12": "solo_description/robots/solo12.urdf",
    "a1": "a1_description/urdf/a1.urdf",
    "baxter": "baxter_description/urdf/baxter.urdf",
}


def erd_urdf(rel):
    """Absolute path of an example-robot-data URDF, or skip.

    example-robot-data 5.x ships the Python loaders (`example_robot_data.robots_loader.getModelPath`);
    6.x ships only the data (under <prefix>/share/example-robot-data/robots), so look there as well.
    """
    try:
        from example_robot_data.robots_loader import getModelPath

        return os.path.join(getModelPath(rel), rel)
    except (ImportError, OSError):
        pass
    roots = {sysconfig.get_paths()["purelib"], sysconfig.get_paths()["data"], *sys.path}
    for root in roots:
        for prefix in ("cmeel.prefix/share", "share", "../../../share"):
            path = os.path.join(root, prefix, "example-robot-data", "robots", rel)
            if os.path.isfile(path):
                return os.path.normpath(path)
    pytest.skip(f"example-robot-data is not installed (no {rel}); pip install example-robot-data")


class UrdfPair:
    """freefloat and Pinocchio models of one URDF, joints matched by name (`random_trees.NamedLayout`)."""

    def __init__(self, text, base, path=None):
        self.text, self.base = text, base
        root = {"free": pin.JointModelFreeFlyer(), "planar": pin.JointModelPlanar(), "fixed": None}[base]
        if path is not None:
            self.m = ff.Model.from_urdf(path, base=base)
            self.model = pin.buildModelFromUrdf(path) if root is None else pin.buildModelFromUrdf(path, root)
        else:
            self.m = ff.Model.from_urdf_string(text, base=base)
            self.model = pin.buildModelFromXML(text) if root is None else pin.buildModelFromXML(text, root)
        # pin defaults to Earth gravity; freefloat's URDF default is zero: use whatever freefloat reports
        self.model.gravity = pin.Motion(np.asarray(self.m.gravity, float), np.zeros(3))
        self.data = self.model.createData()
        self.rows = rt.ff_joint_rows(self.m)
        assert self.rows[0][1] == base
        self.layout = rt.NamedLayout(self.model, self.rows)

    def random_state(self, rng):
        parts = []
        for _, t, _, _ in self.rows:
            if t == "free":
                parts += [rng.uniform(-1, 1, 3), rt.random_unit_quaternion(rng)]
            elif t == "planar":
                parts += [rng.uniform(-1, 1, 2), [rng.uniform(-4, 4)]]
            elif t == "revolute":
                parts.append([rng.uniform(-math.pi, math.pi)])
            elif t == "prismatic":
                parts.append([rng.uniform(-0.05, 0.05)])
            elif t == "spherical":
                parts.append(rt.random_unit_quaternion(rng))
        q = np.concatenate(parts)
        return q, rng.normal(size=self.m.nv), rng.normal(size=self.m.nv), rng.normal(size=(self.m.nbodies, 6))


def check_urdf_dynamics(u, label, rng, n_states=3):
    m, model, data, L = u.m, u.model, u.data, u.layout
    assert (m.nv, m.nq) == (
        model.nv,
        model.nq - (u.base == "planar") - sum(1 for j in model.joints[1:] if j.nq == 2 and j.nv == 1),
    ), f"{label}: nq/nv"
    mass = rt.urdf_total_mass(u.text)
    assert np.asarray(m.parameters(), float)[:, 0].sum() == pytest.approx(mass, rel=1e-12), f"{label}: mass"
    assert rt.pin_total_mass(model) == pytest.approx(mass, rel=1e-12)
    for _ in range(n_states):
        q, v, tau, fext = u.random_state(rng)
        qp, vp, tp = L.q_to_pin(q), L.v_to_pin(v), L.v_to_pin(tau)
        fp = L.fext_to_pin(m.body_names, fext)
        close(ff.aba(m, q, v, tau), L.v_from_pin(pin.aba(model, data, qp, vp, tp)), f"{label} aba")
        close(ff.aba(m, q, v, tau, fext=fext), L.v_from_pin(pin.aba(model, data, qp, vp, tp, fp)), f"{label} aba fext")
        close(ff.rnea(m, q, v, tau), L.v_from_pin(pin.rnea(model, data, qp, vp, tp)), f"{label} rnea")
        close(
            ff.rnea(m, q, v, tau, fext=fext), L.v_from_pin(pin.rnea(model, data, qp, vp, tp, fp)), f"{label} rnea fext"
        )
        close(ff.crba(m, q), L.matrix_from_pin(pin.crba(model, data, qp)), f"{label} crba")
        close(ff.momentum(m, q, v), rt.pin_momentum_at_origin(model, data, qp, vp), f"{label} momentum")
        close(
            ff.centroidal_momentum_matrix(m, q),
            L.cols_from_pin(rt.pin_momentum_matrix_at_origin(model, data, qp)),
            f"{label} momentum matrix",
        )
        close(ff.center_of_mass(m, q), rt.pin_center_of_mass(model, data, qp), f"{label} CoM")


def check_urdf_kinematics(u, label, rng, all_jacobians=False):
    """Each freefloat body is a URDF link, i.e. a Pinocchio BODY frame of the same name."""
    m, model, data, L = u.m, u.model, u.data, u.layout
    q = u.random_state(rng)[0]
    qp = L.q_to_pin(q)
    pin.framesForwardKinematics(model, data, qp)
    X = np.asarray(ff.forward_kinematics(m, q), float)
    for i, name in enumerate(m.body_names):
        M = data.oMf[L.body_frame(name)[0]]
        close(X[i, :3], M.translation, f"{label}: position of {name}")
        close(rt.quat_to_matrix(X[i, 3:]), M.rotation, f"{label}: rotation of {name}")
    # Jacobians of every leaf link (end effectors, feet), or of every link
    parents = set(m.parents)
    names = [n for k, n in enumerate(m.body_names) if all_jacobians or k not in parents]
    for name in names:
        fid = L.body_frame(name)[0]
        for ref, rf in (("local", pin.LOCAL), ("world", pin.LOCAL_WORLD_ALIGNED)):
            Jp = L.cols_from_pin(pin.computeFrameJacobian(model, data, qp, fid, rf))
            close(ff.frame_jacobian(m, q, name, reference=ref), Jp, f"{label}: {ref} Jacobian of {name}")


def check_urdf_velocity_order(u, label):
    """v follows the joints depth-first in URDF document order.

    For serial chains this is also Pinocchio's order.  For branched trees it need not be: Pinocchio (through
    urdfdom) visits sibling joints in *alphabetical* order of joint name (A1: FL, FR, RL, RR, while the file
    lists FR, FL, RR, RL), which is why the dynamics checks match joints by name.
    """
    moving = [name for name, t, _, _ in u.rows[1:] if rt.JOINT_NV[t] > 0]
    assert moving == rt.urdf_depth_first_joint_order(u.text), f"{label}: joint order"
    first = 1 if u.base == "fixed" else 2
    if moving == [u.model.names[j] for j in range(first, u.model.njoints)]:
        assert np.array_equal(u.layout.v_perm, np.arange(u.m.nv)), f"{label}: v order differs from Pinocchio's"


@functools.cache
def erd_pair(robot, base):
    path = erd_urdf(ERD_ROBOTS[robot])
    with open(path) as fh:
        return UrdfPair(fh.read(), base, path=path)


ERD_CASES = [(r, "free") for r in ERD_ROBOTS] + [
    ("panda", "fixed"),
    ("a1", "fixed"),
    ("ur5", "planar"),
    ("solo12", "planar"),
]


def _rng(*key):
    return np.random.default_rng(zlib.crc32("/".join(map(str, key)).encode()))


@pytest.mark.parametrize("robot,base", ERD_CASES)
def test_example_robot_whole_system_dynamics(robot, base):
    check_urdf_dynamics(erd_pair(robot, base), f"{robot}/{base}", _rng(robot, base))


@pytest.mark.parametrize("robot,base", ERD_CASES)
def test_example_robot_link_placements_and_jacobians(robot, base):
    check_urdf_kinematics(erd_pair(robot, base), f"{robot}/{base}", _rng(robot, base, "kin"))


@pytest.mark.parametrize("robot", list(ERD_ROBOTS))
def test_example_robot_velocity_order(robot):
    check_urdf_velocity_order(erd_pair(robot, "free"), robot)


def test_nonphysical_urdf_inertia_is_rejected():
    """ANYmal's URDF gives its dummy `base` link the inertia tensor 1e-6 * ones(3, 3) (eigenvalues 0, 0, 3e-6).
    Pinocchio accepts it; freefloat's loader must refuse it with an error that names the link."""
    path = erd_urdf("anymal_b_simple_description/robots/anymal.urdf")
    with pytest.raises(ff.ModelError, match=r"'base'.*allow_nonphysical=True"):
        ff.Model.from_urdf(path, base="free")
    # The opt-out loads it; whole-system dynamics then agree with Pinocchio's model of the same file.
    m = ff.Model.from_urdf(path, base="free", allow_nonphysical=True)
    pm = pin.buildModelFromUrdf(path, pin.JointModelFreeFlyer())
    pm.gravity = pin.Motion.Zero()
    assert m.total_mass == pytest.approx(pin.computeTotalMass(pm), rel=1e-12)
    # Map Pinocchio's joint order (alphabetical siblings) onto ours by joint name.
    rng = np.random.default_rng(7)
    q_pin = pin.randomConfiguration(pm, -np.ones(pm.nq), np.ones(pm.nq))
    q_pin[3:7] /= np.linalg.norm(q_pin[3:7])
    v_pin, tau_pin = rng.normal(size=pm.nv), rng.normal(size=pm.nv)
    qi, vi = list(range(7)), list(range(6))
    for name, nq in zip(m.joint_names[1:], m.nqs[1:]):
        if nq:
            j = pm.getJointId(name)
            qi.append(pm.joints[j].idx_q)
            vi.append(pm.joints[j].idx_v)
    q, v, tau = q_pin[qi], v_pin[vi], tau_pin[vi]
    a_pin = pin.aba(pm, pm.createData(), q_pin, v_pin, tau_pin)
    assert_close(ff.aba(m, q, v, tau), a_pin[vi], rtol=1e-9, atol=0, what="anymal aba")


def test_urdf_from_string_equals_from_file():
    path = erd_urdf(ERD_ROBOTS["panda"])
    with open(path) as fh:
        text = fh.read()
    a = ff.Model.from_urdf(path, base="free")
    b = ff.Model.from_urdf_string(text, base="free")
    assert list(a.body_names) == list(b.body_names) and (a.nq, a.nv) == (b.nq, b.nv)
    q = np.asarray(a.random_configuration(np.random.default_rng(0)), float)
    assert_close(ff.crba(b, q), ff.crba(a, q), rtol=1e-14, atol=0, what="crba from string vs file")


# ---- random trees rendered to URDF -----------------------------------------------------------------------------
# The example robots leave some of the URDF format unexercised (rotated inertial frames, omitted axes, siblings
# out of alphabetical order, joints listed before their links).  These trees cover it; the self-checks verify
# the rendering against a Pinocchio model built directly from the description.


@pytest.mark.parametrize("seed", rt.URDF_TREE_SEEDS)
def test_random_urdf_tree(seed):
    base = rt.BASE_TYPES[seed % 3]
    u = UrdfPair(rt.urdf_tree_from_seed(seed).to_urdf(render_seed=seed), base)
    label = f"urdf tree {seed}/{base}"
    check_urdf_velocity_order(u, label)
    check_urdf_dynamics(u, label, _rng(seed, base))
    check_urdf_kinematics(u, label, _rng(seed, base, "kin"), all_jacobians=True)

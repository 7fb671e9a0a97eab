"""Bad input gives a clear exception naming the problem and where; nothing crashes."""

import numpy as np
import pytest

import freefloat as ff

GOOD_YAML = """name: t
bodies:
  - name: base
    inertial: {mass: 10, inertia: [1, 1, 1]}
  - name: arm
    parent: base
    joint: {type: revolute, axis: [0, 0, 1]}
    inertial: {mass: 1, com: [0.5, 0, 0], inertia: [0.01, 0.1, 0.1]}
"""

URDF = """<?xml version="1.0"?>
<robot name="r">
  <link name="base"><inertial><mass value="10"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="arm"><inertial><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="j1" type="revolute">
    <parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
  </joint>
</robot>
"""


def test_good_files_load():
    """The reference files the bad-input tests mutate load to the robot they describe."""
    m = ff.Model.from_yaml_string(GOOD_YAML)
    assert (m.name, m.body_names, m.joint_types, m.nq, m.nv) == ("t", ["base", "arm"], ["free", "revolute"], 8, 7)
    # [m, m c, I about the body origin]: the CoM inertia (0.01, 0.1, 0.1) moved by 0.5 m along x (parallel axes)
    np.testing.assert_allclose(m.parameters()[1], [1, 0.5, 0, 0, 0.01, 0, 0.35, 0, 0, 0.35], rtol=0, atol=1e-15)
    u = ff.Model.from_urdf_string(URDF)
    assert (u.name, u.body_names, u.joint_names, u.joint_types) == (
        "r",
        ["base", "arm"],
        ["root_joint", "j1"],
        ["free", "revolute"],
    )
    assert u.total_mass == 11.0
    np.testing.assert_allclose(u.parameters()[1], [1, 0, 0, 0, 0.1, 0, 0.1, 0, 0, 0.1], rtol=0, atol=1e-15)


def test_yaml_syntax_error_has_line():
    with pytest.raises(ff.ModelError, match=r"line \d+"):
        ff.Model.from_yaml_string(GOOD_YAML.replace("parent: base", "parent: [base"))


def test_yaml_unknown_joint_type_names_body_and_line():
    with pytest.raises(ff.ModelError, match=r"line 5.*'arm'.*unknown joint type 'hinge'"):
        ff.Model.from_yaml_string(GOOD_YAML.replace("type: revolute", "type: hinge"))


def test_yaml_unknown_parent_and_key():
    with pytest.raises(ff.ModelError, match="parent 'nope'"):
        ff.Model.from_yaml_string(GOOD_YAML.replace("parent: base", "parent: nope"))
    with pytest.raises(ff.ModelError, match="unknown field `colour`"):
        ff.Model.from_yaml_string(GOOD_YAML.replace("    parent: base", "    colour: red\n    parent: base"))


@pytest.mark.parametrize(
    "inertial,msg",
    [
        ("{mass: -1, inertia: [1, 1, 1]}", "negative"),
        ("{mass: 1, inertia: [1, 1, 3]}", "triangle"),
        ("{mass: 1, inertia: {xx: 1, yy: 1, zz: 1, xy: 2}}", "positive semi-definite"),
    ],
)
def test_nonphysical_inertia_is_rejected(inertial, msg):
    text = GOOD_YAML.replace("{mass: 1, com: [0.5, 0, 0], inertia: [0.01, 0.1, 0.1]}", inertial)
    with pytest.raises(ff.ModelError, match=f"'arm'.*{msg}"):
        ff.Model.from_yaml_string(text)


def test_massless_moving_subtree_is_rejected():
    text = GOOD_YAML.replace("    inertial: {mass: 1, com: [0.5, 0, 0], inertia: [0.01, 0.1, 0.1]}\n", "")
    with pytest.raises(ff.ModelError, match="'arm'.*no mass"):
        ff.Model.from_yaml_string(text)


@pytest.mark.parametrize(
    "edit,msg",
    [
        (lambda s: s.replace('<child link="arm"/>', '<child link="ghost"/>'), r"line 5.*'j1'.*'ghost'"),
        (lambda s: s.replace('type="revolute"', 'type="screw"'), r"line 5.*unknown joint type 'screw'"),
        (lambda s: s.replace("</robot>", ""), "not well-formed XML"),
        (lambda s: s.replace('<axis xyz="0 0 1"/>', '<axis xyz="0 0 x"/>'), "three finite numbers"),
        (lambda s: s.replace('<mass value="1"/>', '<mass value="-1"/>'), r"line 4.*'arm'.*negative"),
    ],
)
def test_malformed_urdf(edit, msg):
    with pytest.raises(ff.ModelError, match=msg):
        ff.Model.from_urdf_string(edit(URDF))


def test_missing_files(tmp_path):
    with pytest.raises(FileNotFoundError):
        ff.Model.from_urdf(tmp_path / "none.urdf")
    with pytest.raises(FileNotFoundError):
        ff.Model.from_yaml(tmp_path / "none.yaml")
    with pytest.raises(ff.InputError, match="base must be"):
        ff.Model.from_urdf_string(URDF, base="flying")


def test_wrong_sizes_and_nan():
    m = ff.models.load("zhang2020_3d")
    q, v = m.neutral(), np.zeros(m.nv)
    with pytest.raises(ff.InputError, match=r"`q`.*\(13\) or \(T, 13\)"):
        ff.aba(m, q[:-1], v, v)
    with pytest.raises(ff.InputError, match=r"`tau`"):
        ff.aba(m, q, v, np.zeros(m.nv + 1))
    bad = v.copy()
    bad[4] = np.nan
    with pytest.raises(ff.InputError, match=r"`v`: entry 4 is NaN"):
        ff.rnea(m, q, bad, v)
    with pytest.raises(ff.InputError, match=r"`q`: sample 1, entry 0 is inf"):
        Q = np.tile(q, (3, 1))
        Q[1, 0] = np.inf
        ff.center_of_mass(m, Q)
    with pytest.raises(ff.InputError, match="share the time axis"):
        ff.momentum(m, np.tile(q, (3, 1)), np.zeros((4, m.nv)))
    with pytest.raises(ff.InputError, match="cannot be read"):
        ff.momentum(m, "not numbers", v)
    # an empty stack (a filter that selected nothing) is refused by name, in every batched kernel
    Q0, V0 = np.zeros((0, m.nq)), np.zeros((0, m.nv))
    for call in (
        lambda: ff.aba(m, Q0, V0, V0),
        lambda: ff.rnea(m, Q0, V0, V0),
        lambda: ff.crba(m, Q0),
        lambda: ff.momentum(m, Q0, V0),
        lambda: ff.momentum_regressor(m, Q0, V0),
    ):
        with pytest.raises(ff.InputError, match=r"`q` has 0 samples"):
            call()
    # ... and a single sample broadcast against an empty stack names the stacked argument
    with pytest.raises(ff.InputError, match=r"`tau` has 0 samples"):
        ff.aba(m, q, v, V0)
    with pytest.raises(ff.InputError, match="fext"):
        ff.rnea(m, q, v, v, fext=np.zeros((2, 6)))


def test_quaternion_policy():
    m = ff.models.load("zhang2020_3d")
    q = m.neutral()
    q2 = q.copy()
    q2[3:7] = [0.1, 0.2, 0.3, 0.9]
    q2[3:7] /= np.linalg.norm(q2[3:7])
    q_round = q2.copy()
    q_round[3:7] *= 1 + 1e-9  # round-off: normalised silently
    np.testing.assert_allclose(ff.forward_kinematics(m, q_round), ff.forward_kinematics(m, q2), atol=1e-12)
    q_bad = q2.copy()
    q_bad[3:7] *= 2  # a layout mistake: rejected
    with pytest.raises(ff.InputError, match=r"quaternion of joint 'root_joint' \(q\[3\.\.7\].*norm 2\.0"):
        ff.forward_kinematics(m, q_bad)


def test_unknown_frame_and_reference():
    m = ff.models.load("naveen_dual_arm")
    with pytest.raises(ff.InputError, match="'hand' is neither a body nor a frame"):
        ff.frame_jacobian(m, m.neutral(), "hand")
    with pytest.raises(ff.InputError, match="'local' or 'world'"):
        ff.frame_jacobian(m, m.neutral(), "L3", reference="global")
    with pytest.raises(ff.InputError, match="not a joint"):
        ff.hybrid_dynamics(m, m.neutral(), np.zeros(m.nv), np.zeros(m.nv), np.zeros(m.nv), ["J9"])


def test_with_parameters_checks():
    m = ff.models.load("zhang2020_3d")
    with pytest.raises(ff.InputError, match=r"\(8, 10\)"):
        m.with_parameters(np.zeros((3, 10)))
    P = m.parameters()
    P[2, 0] = -5
    with pytest.raises(ff.ModelError, match="negative"):
        m.with_parameters(P)


def test_simulation_bad_input_and_callback_errors():
    m = ff.models.load("valverde_ch5_single_arm")
    q, v = m.neutral(), np.zeros(m.nv)
    with pytest.raises(ff.InputError, match="t_final"):
        ff.simulate(m, q, v, -1.0, 1e-3)
    with pytest.raises(ff.InputError, match="controller_period"):
        ff.simulate(m, q, v, 1.0, 1e-3, controller=lambda t, q, v: np.zeros(m.nv))

    def boom(t, q, v):
        raise RuntimeError("sensor unplugged")

    with pytest.raises(RuntimeError, match="sensor unplugged"):
        ff.simulate(m, q, v, 1.0, 1e-3, torques=boom)
    with pytest.raises(ff.InputError, match=f"must return {m.nv} numbers"):
        ff.simulate(m, q, v, 1.0, 1e-3, torques=lambda t, q, v: np.zeros(3))
    with pytest.raises(ff.NumericalError, match="non-finite"):
        ff.simulate(m, q, v, 1.0, 1e-3, torques=lambda t, q, v: np.full(m.nv, np.nan))
    with pytest.raises(ff.InputError, match="strictly"):
        ff.simulate(m, q, v, 1.0, 1e-3, torques=np.zeros((3, m.nv)), torque_times=[0.0, 0.0, 1.0])


@pytest.mark.parametrize(
    "joint, msg",
    [
        ("{type: universal, axis: [1, 0, 0]}", "needs `axis2`"),
        ("{type: universal, axis: [1, 0, 0], axis2: [1, 1, 0]}", "must be orthogonal"),
        ("{type: universal, axis: [1, 0, 0], axis2: [0, 0, 0]}", "zero length"),
        ("{type: revolute, axis: [1, 0, 0], axis2: [0, 1, 0]}", "only meaningful for a universal joint"),
        ("{type: cylindrical, axis: [0, 0, 0]}", "zero length"),
    ],
)
def test_cylindrical_and_universal_joint_errors(joint, msg):
    with pytest.raises(ff.ModelError, match=msg) as e:
        ff.Model.from_yaml_string(GOOD_YAML.replace("{type: revolute, axis: [0, 0, 1]}", joint))
    assert "arm" in str(e.value)


@pytest.mark.parametrize(
    "joint", ["{type: cylindrical, axis: [0, 0, 1]}", "{type: universal, axis: [1, 0, 0], axis2: [0, 1, 0]}"]
)
def test_urdf_has_no_cylindrical_or_universal_joint(joint):
    m = ff.Model.from_yaml_string(GOOD_YAML.replace("{type: revolute, axis: [0, 0, 1]}", joint))
    with pytest.raises(ff.ModelError, match="URDF has no such joint type"):
        m.to_urdf()

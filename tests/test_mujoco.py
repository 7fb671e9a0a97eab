"""MuJoCo interop: MJCF both ways, state conventions checked against MuJoCo itself, the convention check, and
the end-to-end identification (export, simulate in MuJoCo, import, identify).

Oracles: MuJoCo's own kinematics (xmat, mj_objectVelocity), its momentum (subtree linear velocity and angular
momentum), its compiler's refusals, scipy's quaternion convention, and conservation of momentum."""

from __future__ import annotations

import numpy as np
import pytest

import freefloat as ff
from freefloat._core import InputError, ModelError

mujoco = pytest.importorskip("mujoco")
Rotation = pytest.importorskip("scipy.spatial.transform").Rotation

from freefloat.io.mujoco import telemetry_from_mujoco  # noqa: E402

ROBOT = "naveen_dual_arm_consistent"

ALL_JOINTS_YAML = """
name: alljoints
bodies:
  - name: base
    inertial: {mass: 20, com: [0.1, -0.05, 0.02], inertia: {xx: 2.0, yy: 2.5, zz: 3.0, xy: 0.1, xz: -0.05, yz: 0.02}}
  - name: a
    parent: base
    joint: {name: Ja, type: revolute, axis: [0, 0.6, 0.8]}
    origin: {xyz: [0.3, 0.1, 0.2], rpy: [0.2, -0.3, 0.5]}
    inertial: {mass: 3, com: [0.2, 0.01, 0.0], inertia: {xx: 0.05, yy: 0.2, zz: 0.21, xy: 0.01}}
  - name: b
    parent: a
    joint: {name: Jb, type: spherical}
    origin: {xyz: [0.4, 0, 0]}
    inertial: {mass: 2, com: [0.15, 0.02, -0.01], inertia: {xx: 0.03, yy: 0.1, zz: 0.11}}
  - name: c
    parent: b
    joint: {name: Jc, type: prismatic, axis: [1, 0, 0]}
    origin: {xyz: [0.3, 0, 0], rpy: [0, 0.4, 0]}
    inertial: {mass: 1, com: [0.1, 0, 0.03], inertia: {xx: 0.01, yy: 0.02, zz: 0.02}}
  - name: d
    parent: base
    joint: {name: Jd, type: cylindrical, axis: [0, 0, 1]}
    origin: {xyz: [-0.3, 0, 0.1]}
    inertial: {mass: 1.5, com: [0.05, 0.1, 0.2], inertia: {xx: 0.04, yy: 0.05, zz: 0.03}}
  - name: e
    parent: d
    joint: {name: Je, type: universal, axis: [1, 0, 0], axis2: [0, 1, 0]}
    origin: {xyz: [0, 0, 0.3]}
    inertial: {mass: 1.2, com: [0.0, 0.05, 0.1], inertia: {xx: 0.02, yy: 0.03, zz: 0.025}}
  - name: f
    parent: e
    joint: {name: Jf, type: fixed}
    origin: {xyz: [0, 0, 0.2]}
    inertial: {mass: 0.5, com: [0.01, 0, 0], inertia: {xx: 0.001, yy: 0.001, zz: 0.001}}
"""


def _mj_state(mj, rng):
    """A random MuJoCo state (normalised quaternions) and MjData after forward kinematics and velocities."""
    d = mujoco.MjData(mj)
    d.qpos[:] = mj.qpos0 + rng.normal(0, 0.7, mj.nq)
    for j in range(mj.njnt):
        a = mj.jnt_qposadr[j]
        if mj.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE:
            d.qpos[a + 3 : a + 7] /= np.linalg.norm(d.qpos[a + 3 : a + 7])
        if mj.jnt_type[j] == mujoco.mjtJoint.mjJNT_BALL:
            d.qpos[a : a + 4] /= np.linalg.norm(d.qpos[a : a + 4])
    d.qvel[:] = rng.normal(0, 1.0, mj.nv)
    mujoco.mj_forward(mj, d)
    return d


def _mj_momentum(mj, d):
    """MuJoCo's total momentum [p; L about the world origin] from its subtree quantities."""
    mujoco.mj_subtreeVel(mj, d)
    root = 1  # the robot's root body (world is 0)
    M = mj.body_subtreemass[root]
    p = M * d.subtree_linvel[root]
    return np.concatenate([p, d.subtree_angmom[root] + np.cross(d.subtree_com[root], p)])


# -- the writer ---------------------------------------------------------------------------------------------
def test_export_compiles_with_the_model_numbers():
    m = ff.models.load(ROBOT)
    xml = m.to_mjcf()
    for opt in ('fusestatic="false"', 'inertiafromgeom="false"', 'balanceinertia="false"', 'gravity="0.0 0.0 0.0"'):
        assert opt in xml
    mj = mujoco.MjModel.from_xml_string(xml)
    assert (mj.nq, mj.nv, mj.nbody - 1) == (m.nq, m.nv, m.nbodies)
    assert mj.jnt_type[0] == mujoco.mjtJoint.mjJNT_FREE
    np.testing.assert_allclose(mj.opt.gravity, 0.0)
    P = m.parameters()
    for i in range(m.nbodies):
        b = i + 1
        assert mujoco.mj_id2name(mj, mujoco.mjtObj.mjOBJ_BODY, b) == m.body_names[i]
        assert mj.body_mass[b] == P[i, 0]
        np.testing.assert_allclose(mj.body_ipos[b], P[i, 1:4] / P[i, 0], rtol=1e-14, atol=1e-15)
        # principal moments: MuJoCo's diagonalisation vs numpy's of the CoM inertia rebuilt by hand
        c = P[i, 1:4] / P[i, 0]
        Io = np.array([[P[i, 4], P[i, 5], P[i, 7]], [P[i, 5], P[i, 6], P[i, 8]], [P[i, 7], P[i, 8], P[i, 9]]])
        Ic = Io - P[i, 0] * (c @ c * np.eye(3) - np.outer(c, c))
        np.testing.assert_allclose(np.sort(mj.body_inertia[b]), np.linalg.eigvalsh(Ic), rtol=1e-12)


def test_export_gravity_only_when_asked():
    m = ff.models.load(ROBOT).with_gravity([0, 0, -9.81])
    assert mujoco.MjModel.from_xml_string(m.to_mjcf()).opt.gravity[2] == 0.0
    np.testing.assert_allclose(mujoco.MjModel.from_xml_string(m.to_mjcf(gravity=True)).opt.gravity, [0, 0, -9.81])


def test_export_refuses_nonphysical_bodies_like_mujoco_does():
    with pytest.raises(ModelError, match="L1.*triangle inequality.*naveen_dual_arm_consistent"):
        ff.models.load("naveen_dual_arm").to_mjcf()
    # MuJoCo itself refuses such an inertia when balanceinertia is off (what the writer protects against)
    xml = ff.models.load(ROBOT).to_mjcf()
    bad = xml.replace('fullinertia="8.77 7.68 15.299999999999997', 'fullinertia="2 3 22.1')
    assert bad != xml
    with pytest.raises(ValueError, match="A \\+ B >= C"):
        mujoco.MjModel.from_xml_string(bad)


def test_round_trip_keeps_parameters_placements_tags_frames(tmp_path):
    m = ff.models.load(ROBOT)
    p = tmp_path / "robot.xml"
    m.to_mjcf(p)
    r = ff.Model.from_mjcf(p)
    assert (r.name, r.body_names, r.joint_names, r.joint_types) == (m.name, m.body_names, m.joint_names, m.joint_types)
    assert r.tags == m.tags  # wheels and known bodies survive: identification keeps its scale
    np.testing.assert_allclose(r.parameters(), m.parameters(), rtol=1e-13, atol=1e-12)
    np.testing.assert_allclose(r.placements, m.placements, atol=1e-15)
    assert [f[:2] for f in r.frames] == [f[:2] for f in m.frames]


def test_all_joint_types_round_trip():
    m = ff.Model.from_yaml_string(ALL_JOINTS_YAML)
    r = ff.Model.from_mjcf(m.to_mjcf())
    assert r.joint_types == m.joint_types
    assert r.joint_names == m.joint_names
    np.testing.assert_allclose(r.parameters(), m.parameters(), rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(r.placements, m.placements, atol=1e-14)


# -- MuJoCo's state conventions, checked with MuJoCo itself -----------------------------------------------------
def test_mujoco_free_joint_conventions():
    """qpos quaternion is w-first; qvel linear is the world-frame velocity of the body origin, angular is in the
    body frame. Checked with MuJoCo's kinematics, its object velocity and a finite difference of its integrator."""
    mj = mujoco.MjModel.from_xml_string(ff.models.load(ROBOT).to_mjcf())
    d = _mj_state(mj, np.random.default_rng(3))
    wxyz = d.qpos[3:7]
    # quaternion order: scipy (x, y, z, w) of the reordered quaternion gives MuJoCo's body rotation
    R = Rotation.from_quat(np.r_[wxyz[1:], wxyz[0]]).as_matrix()
    np.testing.assert_allclose(d.xmat[1].reshape(3, 3), R, atol=1e-14)
    assert not np.allclose(Rotation.from_quat(wxyz).as_matrix(), R, atol=1e-3)  # the other order is wrong
    # velocities: mj_objectVelocity (XBODY: at the body frame, not the CoM) gives [angular; linear],
    # in world (0) or local (1) axes
    world, local = np.zeros(6), np.zeros(6)
    mujoco.mj_objectVelocity(mj, d, mujoco.mjtObj.mjOBJ_XBODY, 1, world, 0)
    mujoco.mj_objectVelocity(mj, d, mujoco.mjtObj.mjOBJ_XBODY, 1, local, 1)
    np.testing.assert_allclose(world[3:], d.qvel[0:3], atol=1e-12)  # linear: world frame
    np.testing.assert_allclose(local[0:3], d.qvel[3:6], atol=1e-12)  # angular: body frame
    assert not np.allclose(local[3:], d.qvel[0:3], atol=1e-3)
    # and by finite difference of MuJoCo's own position integrator
    h = 1e-7
    q2 = d.qpos.copy()
    mujoco.mj_integratePos(mj, q2, d.qvel, h)
    np.testing.assert_allclose((q2[0:3] - d.qpos[0:3]) / h, d.qvel[0:3], rtol=1e-6, atol=1e-7)


def test_mujoco_ball_joint_conventions():
    """Ball joint: qpos w-first, relative rotation child-in-parent; qvel angular velocity in the child frame."""
    m = ff.Model.from_yaml_string(ALL_JOINTS_YAML)
    mj = mujoco.MjModel.from_xml_string(m.to_mjcf())
    d = _mj_state(mj, np.random.default_rng(4))
    j = mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_JOINT, "Jb")
    a, dof, b = mj.jnt_qposadr[j], mj.jnt_dofadr[j], mj.jnt_bodyid[j]
    wxyz = d.qpos[a : a + 4]
    Rp, Rc = d.xmat[mj.body_parentid[b]].reshape(3, 3), d.xmat[b].reshape(3, 3)
    R0 = Rotation.from_quat(np.r_[mj.body_quat[b][1:], mj.body_quat[b][0]]).as_matrix()
    np.testing.assert_allclose(Rp.T @ Rc, R0 @ Rotation.from_quat(np.r_[wxyz[1:], wxyz[0]]).as_matrix(), atol=1e-13)
    wc, wp = np.zeros(6), np.zeros(6)
    mujoco.mj_objectVelocity(mj, d, mujoco.mjtObj.mjOBJ_XBODY, b, wc, 1)
    mujoco.mj_objectVelocity(mj, d, mujoco.mjtObj.mjOBJ_XBODY, mj.body_parentid[b], wp, 0)
    np.testing.assert_allclose(wc[0:3] - Rc.T @ wp[0:3], d.qvel[dof : dof + 3], atol=1e-12)


@pytest.mark.parametrize("which", [ROBOT, "alljoints"])
def test_converted_state_has_mujoco_momentum(which):
    """For random states, freefloat's momentum of the converted state equals MuJoCo's total momentum: every
    conversion (free, ball, hinge, slide, cylindrical, universal) at once, against an independent engine."""
    m = ff.models.load(ROBOT) if which == ROBOT else ff.Model.from_yaml_string(ALL_JOINTS_YAML)
    mj = mujoco.MjModel.from_xml_string(m.to_mjcf())
    rng = np.random.default_rng(5)
    for _ in range(5):
        d = _mj_state(mj, rng)
        tel = telemetry_from_mujoco(m, mj, [0.0], d.qpos[None], d.qvel[None])
        h = ff.algorithms.momentum(m, tel.q[0], tel.v[0])
        np.testing.assert_allclose(h, _mj_momentum(mj, d), rtol=1e-10, atol=1e-10)


HAND_MJCF = """
<mujoco model="hand written">
  <compiler angle="degree"/>
  <default><joint damping="0"/><geom contype="0" conaffinity="0"/></default>
  <worldbody>
    <body name="hub" pos="1 2 3" euler="10 20 30">
      <freejoint/>
      <geom type="box" size="0.5 0.4 0.3" density="500"/>
      <body name="arm" pos="0.6 0 0" axisangle="0 1 0 30">
        <joint name="shoulder" type="hinge" axis="0 0 1" pos="0.1 0.05 0" ref="15"/>
        <inertial pos="0.3 0.02 0" mass="4" diaginertia="0.02 0.3 0.31" quat="0.9 0.1 0.3 0.2"/>
        <body name="hand" pos="0.7 0 0">
          <joint name="wrist" type="ball" pos="0 0 0.05"/>
          <geom type="capsule" fromto="0 0 0 0.2 0 0" size="0.03"/>
        </body>
      </body>
    </body>
  </worldbody>
</mujoco>
"""


def test_from_mjcf_reads_what_mujoco_simulates():
    """A hand-written MJCF (degrees, euler/axisangle, joint anchors away from the body origin, a hinge `ref`,
    inertia from geoms, a rotated principal inertia): freefloat's momentum equals MuJoCo's for random states."""
    mj = mujoco.MjModel.from_xml_string(HAND_MJCF)
    m = ff.Model.from_mjcf(HAND_MJCF)
    assert m.joint_types == ["free", "revolute", "spherical"]
    assert m.name == "hand_written"
    np.testing.assert_allclose(m.total_mass, mj.body_subtreemass[1], rtol=1e-14)
    rng = np.random.default_rng(6)
    for _ in range(5):
        d = _mj_state(mj, rng)
        tel = telemetry_from_mujoco(m, mj, [0.0], d.qpos[None], d.qvel[None])
        np.testing.assert_allclose(
            ff.algorithms.momentum(m, tel.q[0], tel.v[0]), _mj_momentum(mj, d), rtol=1e-10, atol=1e-10
        )


# -- bad input ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "extra, match",
    [
        ('<tendon><fixed name="t1"><joint joint="j1" coef="1"/></fixed></tendon>', "tendon"),
        ('<equality><joint joint1="j1" joint2="j2"/></equality>', "equality"),
        ("", "contact enabled.*'g1' on body 'l1' \\(line"),
    ],
)
def test_from_mjcf_refuses_what_freefloat_cannot_represent(extra, match):
    contact = "" if extra == "" else ' contype="0" conaffinity="0"'
    xml = f"""<mujoco><worldbody><body name="b0"><freejoint/><inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/>
<body name="l1"><joint name="j1" type="hinge"/><geom name="g1" type="sphere" size="0.1"{contact}/>
<body name="l2"><joint name="j2" type="hinge"/><inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/></body></body>
</body></worldbody>{extra}</mujoco>"""
    with pytest.raises(ModelError, match=match):
        ff.Model.from_mjcf(xml)


def test_from_mjcf_refuses_unmappable_joints_with_line():
    xml = """<mujoco><worldbody><body name="b0"><freejoint/><inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/>
<body name="l1">
<joint name="ja" type="hinge" axis="1 0 0"/>
<joint name="jb" type="slide" axis="0 1 0"/>
<inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/></body></body></worldbody></mujoco>"""
    with pytest.raises(ModelError, match="'ja' \\(line 3\\), 'jb' \\(line 4\\) \\(hinge, slide\\)"):
        ff.Model.from_mjcf(xml)


def test_state_width_and_joint_name_mismatches():
    m = ff.models.load(ROBOT)
    mj = mujoco.MjModel.from_xml_string(m.to_mjcf())
    t = np.zeros(2)
    with pytest.raises(InputError, match="`qpos`: expected shape \\(2, 16\\)"):
        telemetry_from_mujoco(m, mj, t, np.zeros((2, 15)), np.zeros((2, 15)))
    with pytest.raises(InputError, match="`qvel`: expected shape \\(2, 15\\)"):
        telemetry_from_mujoco(m, mj, t, np.zeros((2, 16)), np.zeros((2, 16)))
    renamed = mujoco.MjModel.from_xml_string(m.to_mjcf().replace('"J3"', '"elbow"'))
    q0 = np.tile(mj.qpos0, (2, 1))
    with pytest.raises(InputError, match="not found in the MuJoCo model: 'J3'.*does not have: elbow"):
        telemetry_from_mujoco(m, renamed, t, q0, np.zeros((2, 15)))
    with pytest.raises(InputError, match="`qpos`: row 0, columns 3..6 .*'root_joint'.*norm 0"):
        telemetry_from_mujoco(m, mj, t, np.zeros((2, 16)), np.zeros((2, 15)))


# -- end to end -------------------------------------------------------------------------------------------------
def _simulate(mj, seconds=12.0, seed=1):
    """MuJoCo run: free joint, zero gravity, RK4 1 ms (from the export), smooth multi-sine motor torques."""
    assert mj.opt.integrator == mujoco.mjtIntegrator.mjINT_RK4 and mj.opt.timestep == 1e-3
    d = mujoco.MjData(mj)
    rng = np.random.default_rng(seed)
    f, ph = rng.uniform(0.1, 0.6, (mj.nu, 3)), rng.uniform(0, 2 * np.pi, (mj.nu, 3))
    amp = np.array([60, 40, 20, 60, 40, 20, 2, 2, 2.0])
    n = int(round(seconds / mj.opt.timestep))
    t, qpos, qvel = np.empty(n + 1), np.empty((n + 1, mj.nq)), np.empty((n + 1, mj.nv))
    for k in range(n + 1):
        t[k], qpos[k], qvel[k] = d.time, d.qpos, d.qvel
        d.ctrl[:] = amp * np.sin(2 * np.pi * f * d.time + ph).sum(1)
        mujoco.mj_step(mj, d)
    return t, qpos, qvel


@pytest.fixture(scope="module")
def mujoco_run(tmp_path_factory):
    d = tmp_path_factory.mktemp("mj")
    xml = d / "robot.xml"
    ff.models.load(ROBOT).to_mjcf(xml)
    mj = mujoco.MjModel.from_xml_path(str(xml))
    t, qpos, qvel = _simulate(mj)
    np.savez(d / "states.npz", t=t, qpos=qpos, qvel=qvel)
    return d, xml, mj, t, qpos, qvel


def test_end_to_end_export_simulate_import_identify(mujoco_run):
    d, xml, mj, t, qpos, qvel = mujoco_run
    robot = ff.Model.from_mjcf(xml)
    tel = telemetry_from_mujoco(robot, mj, t, qpos, qvel)
    # momentum is conserved (zero: released at rest, motors are internal) along the converted MuJoCo run
    assert np.abs(ff.algorithms.momentum(robot, tel.q, tel.v)).max() < 1e-8
    res = ff.identify_minimal(robot, tel)
    assert len(res.names) == 52
    e = res.errors(ff.models.load(ROBOT))  # truth: the built-in model that was exported
    assert e["median_rel_error_pct"] < 1e-6 and e["max_rel_error_pct"] < 1e-6, e
    assert res.conventions.cause is None and res.conventions.ok


def test_raw_mujoco_file_is_refused_with_the_cause(mujoco_run, tmp_path):
    d, xml, mj, t, qpos, qvel = mujoco_run
    robot = ff.Model.from_mjcf(xml)
    raw = ff.io.telemetry.Telemetry(t=t, q=qpos, v=qvel, q_labels=robot.q_labels(), v_labels=robot.v_labels())
    raw.to_parquet(tmp_path / "raw.parquet")
    with pytest.raises(InputError, match="w-first.*linear velocity is in the world frame.*convert --from mujoco"):
        ff.identify_minimal(robot, tmp_path / "raw.parquet")
    # only the velocity frame wrong: named alone
    tel = telemetry_from_mujoco(robot, mj, t, qpos, qvel)
    half = ff.io.telemetry.Telemetry(t=t, q=tel.q, v=np.c_[qvel[:, :3], tel.v[:, 3:]])
    with pytest.raises(InputError, match="argument `data`: .*: the base linear velocity is in the world frame"):
        ff.identify_minimal(robot, half)
    with pytest.warns(UserWarning, match="linear velocity is in the world frame"):
        ff.identify_minimal(robot, half, check="warn")


@pytest.mark.slow
def test_cli_export_convert_identify(mujoco_run, tmp_path):
    from click.testing import CliRunner

    from freefloat.cli import main

    d, xml, *_ = mujoco_run
    r = CliRunner()
    out = r.invoke(main, ["export", ROBOT, "--mjcf", str(tmp_path / "r.xml")])
    assert out.exit_code == 0, out.output
    assert (tmp_path / "r.xml").read_text() == xml.read_text()
    tel = tmp_path / "telemetry.parquet"
    out = r.invoke(main, ["convert", "--from", "mujoco", str(d / "states.npz"), "--model", ROBOT, "--out", str(tel)])
    assert out.exit_code == 0, out.output
    assert "momentum check passed" in out.output and f"wrote {tel}" in out.output
    out = r.invoke(main, ["identify", "minimal", str(tmp_path / "r.xml"), "--data", str(tel)])
    assert out.exit_code == 0, out.output
    assert "momentum check passed" in out.output

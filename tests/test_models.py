"""Built-in robots and model files: contents checked against numbers printed in the published works (docs/models.md)."""

import numpy as np
import pytest

import freefloat as ff

REQUIRED = [
    "naveen_dual_arm",
    "zhang2020_2d_small",
    "zhang2020_2d_medium",
    "zhang2020_2d_large",
    "zhang2020_3d",
    "valverde_ch5_single_arm",
    "valverde_ch7_two_arm",
]


def test_builtin_names_and_loading():
    names = ff.models.names()
    for n in REQUIRED:
        assert n in names
    for n in names:
        m = ff.models.load(n)
        assert m.nq == len(m.neutral()) and m.nbodies == len(m.body_names)


def test_naveen_standard_parameters_match_table2():
    # Naveen, Shah, Misra Table 2 as standard parameters about each link origin (docs/models.md),
    # order [Ixx Iyy Izz Ixy Iyz Izx m mx my mz] (L2 y-CoM corrected to -0.04).
    table2 = {
        "base": [1700.0, 1600.0, 1460.0, -84.48, -199.55, -114.29, 2000, 400.0, 600.0, 800.0],
        "L1": [3.47, 20.135, 38.635, 0.4, 3.825, 6.0, 50, 30.0, 2.5, -3.5],
        "L2": [1.314, 8.18, 25.134, 1.25, 1.67, 2.3, 40, 16.0, -1.6, -2.0],
        "L3": [31.95, 45.96, 55.03, 1.38, 5.5, 3.93, 30, 21.0, 12.0, 9.0],
        "L4": [2.01, 16.825, 32.255, 0.4, 2.33, 4.81, 50, 27.5, 2.0, -2.0],
        "L5": [2.725, 9.015, 21.455, 2.1125, 1.4625, 0.4825, 35, 15.75, 1.75, 1.75],
        "L6": [34.59, 60.4, 60.37, 27.1, -1.98, 21.27, 60, 36.0, -30.0, -21.0],
    }
    m = ff.models.load("naveen_dual_arm")
    P = m.parameters()
    for name, (xx, yy, zz, xy, yz, zx, mass, mx, my, mz) in table2.items():
        ours = P[m.body_index(name)]
        np.testing.assert_allclose(ours, [mass, mx, my, mz, xx, xy, yy, zx, yz, zz], rtol=0, atol=1e-9, err_msg=name)


def test_naveen_geometry_at_zero():
    # Geometry reconstructed from Appendix A (docs/models.md): J1 at [0.7,0.3,0.9] (+z0), J2 at [1.7,0.3,0.9]
    # (axis -y), J3 at [2.7,0.3,0.9], J4 at [-0.3,0.3,0.9].
    m = ff.models.load("naveen_dual_arm")
    fk = ff.forward_kinematics(m, m.neutral())
    pos = {n: fk[m.body_index(n), :3] for n in ("L1", "L2", "L3", "L4")}
    np.testing.assert_allclose(pos["L1"], [0.7, 0.3, 0.9], atol=1e-12)
    np.testing.assert_allclose(pos["L2"], [1.7, 0.3, 0.9], atol=1e-12)
    np.testing.assert_allclose(pos["L3"], [2.7, 0.3, 0.9], atol=1e-12)
    np.testing.assert_allclose(pos["L4"], [-0.3, 0.3, 0.9], atol=1e-12)
    J = ff.frame_jacobian(m, m.neutral(), "L2", reference="world")
    np.testing.assert_allclose(J[3:, m.idx_v[m.body_index("L2")]], [0, -1, 0], atol=1e-12)


def test_naveen_table2_is_not_physical_without_the_opt_out():
    text = ff.models.source("naveen_dual_arm").replace("allow_nonphysical: true", "allow_nonphysical: false")
    with pytest.raises(ff.ModelError, match=r"L1.*triangle"):
        ff.Model.from_yaml_string(text)


def test_valverde_ch5_end_effector_hint():
    # thesis ch. 8 hint: with theta2 = 5 deg, theta3 = -10 deg the end effector is at [6.727, 0, 5] m.
    m = ff.models.load("valverde_ch5_single_arm")
    q = m.neutral()
    joints = [j for j, t in zip(m.joint_names, m.joint_types) if t == "revolute"]
    q[m.idx_q[m.joint_names.index(joints[1])]] = np.deg2rad(5)
    q[m.idx_q[m.joint_names.index(joints[2])]] = np.deg2rad(-10)
    np.testing.assert_allclose(ff.frame_placement(m, q, "ee")[:3], [6.727, 0, 5], atol=1e-3)


def test_mdh_equals_explicit_placement():
    # Craig's modified DH: Rx(alpha) Tx(a) Rz(theta) Tz(d).
    common = (
        "name: t\nbodies:\n  - name: b\n    inertial: {mass: 1, inertia: [1, 1, 1]}\n"
        "  - name: l\n    parent: b\n    joint: {type: revolute}\n"
    )
    a = ff.Model.from_yaml_string(
        common + "    mdh: {alpha: 0.4, a: 1.5, d: 0.3, theta: 0.2}\n    inertial: {mass: 1, inertia: [1, 1, 1]}\n"
    )
    ca, sa, ct, st = np.cos(0.4), np.sin(0.4), np.cos(0.2), np.sin(0.2)
    Rx = np.array([[1, 0, 0], [0, ca, -sa], [0, sa, ca]])
    Rz = np.array([[ct, -st, 0], [st, ct, 0], [0, 0, 1]])
    T = np.eye(4)
    T[:3, :3] = Rx @ Rz
    T[:3, 3] = Rx @ np.array([1.5, 0, 0]) + Rx @ Rz @ np.array([0, 0, 0.3])
    np.testing.assert_allclose(a.placements[1], T, atol=1e-14)


@pytest.mark.parametrize(
    "name", ["naveen_dual_arm_consistent", "zhang2020_3d", "zhang2020_2d_medium", "valverde_ch5_single_arm"]
)
def test_urdf_round_trip_preserves_dynamics(tmp_path, name):
    m = ff.models.load(name)
    path = tmp_path / f"{name}.urdf"
    m.to_urdf(path)
    base = m.joint_types[0]
    m2 = ff.Model.from_urdf(path, base=base)
    rng = np.random.default_rng(0)
    q = m.random_configuration(rng)
    v = rng.normal(size=m.nv)
    tau = rng.normal(size=m.nv)
    np.testing.assert_allclose(ff.aba(m2, q, v, tau), ff.aba(m, q, v, tau), rtol=1e-10, atol=1e-10)
    np.testing.assert_allclose(ff.momentum(m2, q, v), ff.momentum(m, q, v), rtol=1e-10, atol=1e-10)
    assert m2.body_names[: m.nbodies] == m.body_names


def test_urdf_of_nonphysical_model_is_rejected_on_load(tmp_path):
    # URDF has no way to carry allow_nonphysical: reloading the verbatim Table 2 robot must fail loudly.
    path = tmp_path / "verbatim.urdf"
    ff.models.load("naveen_dual_arm").to_urdf(path)
    with pytest.raises(ff.ModelError, match=r"line \d+.*'L1'.*triangle"):
        ff.Model.from_urdf(path)


def test_with_parameters_round_trip_and_gravity():
    m = ff.models.load("zhang2020_3d")
    P = m.parameters()
    P2 = P.copy()
    P2[-1, 0] *= 2  # heavier target
    P2[-1, 1:] *= 2  # same centre of mass
    m2 = m.with_parameters(P2)
    np.testing.assert_allclose(m2.parameters(), P2)
    assert m2.total_mass == pytest.approx(m.total_mass + P[-1, 0])
    g = m.with_gravity([0, 0, -9.81])
    q, v = m.neutral(), np.zeros(m.nv)
    # A free-floating robot in uniform gravity falls with g and does not rotate.
    a = ff.aba(g, q, v, np.zeros(m.nv))
    np.testing.assert_allclose(a[:3], [0, 0, -9.81], atol=1e-9)
    np.testing.assert_allclose(a[3:], 0, atol=1e-9)

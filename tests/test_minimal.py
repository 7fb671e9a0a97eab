"""Minimal parameters of the momentum model (python/freefloat/minimal.py): Naveen, Shah, Misra's closed form against its
Table 4, the numeric (QR) method against the closed form, and the numeric method on other joint types."""

import numpy as np
import pytest
import scipy.linalg

import freefloat as ff

import random_trees as rt  # tests/ is on sys.path under pytest's default import mode

# Naveen, Shah, Misra, Table 4 "True" column, phi_m(1..52) in the paper's order.  Printed to 3 decimals, so
# the tolerance is half a unit of the last digit (5e-4, e.g. 2.1125 printed 2.112) plus float slack.
TABLE4_TRUE = [
    2130.560,
    2078.560,
    1555.700,
    -96.630,
    -269.450,
    -148.890,
    2265.000,
    440.500,
    679.500,
    1033.000,
    -2.525,
    192.775,
    7.400,
    3.825,
    6.000,
    100.000,
    -4.500,
    -36.866,
    55.134,
    1.250,
    1.670,
    -6.700,
    46.000,
    -1.600,
    -14.010,
    55.030,
    1.380,
    5.500,
    3.930,
    21.000,
    12.000,
    19.600,
    256.670,
    -18.850,
    2.330,
    4.810,
    122.500,
    21.250,
    -66.290,
    81.455,
    2.112,
    1.462,
    21.483,
    75.750,
    1.750,
    -25.810,
    60.370,
    27.100,
    -1.980,
    21.270,
    36.000,
    -30.000,
]
TABLE4_ATOL = 5e-4 + 1e-9


@pytest.fixture(scope="module")
def dual_arm():
    m = ff.models.load("naveen_dual_arm")
    return m, ff.minimal_parameters(m, method="numeric"), ff.minimal_parameters(m, method="closed-form")


def random_states(m, n, seed):
    rng = np.random.default_rng(seed)
    return np.array([m.random_configuration(rng) for _ in range(n)]), rng.normal(size=(n, m.nv))


def unknown_regressor(m, mp, Q, V):
    cols = [10 * b + k for b in mp.unknown for k in range(10)]
    return ff.momentum_regressor(m, Q, V)[..., cols]


def test_closed_form_reproduces_table4(dual_arm):
    m, _, mpc = dual_arm
    phi = mpc.from_standard(m.parameters())
    assert phi.shape == (52,) and len(mpc.names) == 52
    dev = np.abs(phi - TABLE4_TRUE)
    assert dev.max() <= TABLE4_ATOL, f"max deviation {dev.max():.2e} at phi_m({dev.argmax() + 1})"


def test_closed_form_expressions_match_appendix_a(dual_arm):
    _, _, mpc = dual_arm
    ex = mpc.expressions()
    # phi_m(4) with the corrected +0.09 (printed 0.9; docs/architecture.md, minimal parameters)
    # and phi_m(11), phi_m(16) of Appendix A
    assert ex[3] == "base.Ixy - 0.21*L1.m - 0.21*L2.m - 0.21*L3.m + 0.09*L4.m + 0.09*L5.m + 0.09*L6.m"
    assert ex[10] == "L1.Ixx - L1.Iyy - L2.m + L2.Iyy + L3.Iyy"
    assert ex[15] == "L1.mcx + L2.m + L3.m"
    assert mpc.names[0].startswith("phi_m(1)") and mpc.names[-1].startswith("phi_m(52)")


def test_numeric_rank_and_same_column_space(dual_arm):
    m, mpn, mpc = dual_arm
    assert mpn.rank == 52 and mpn.matrix.shape == (52, 70) and mpc.matrix.shape == (52, 70)
    assert mpn.unknown == mpc.unknown == list(range(7))
    Q, V = random_states(m, 20, seed=7)
    Ku = unknown_regressor(m, mpn, Q, V)
    rng = np.random.default_rng(3)
    for _ in range(5):  # arbitrary P, not only the true one
        P = rng.normal(size=(m.nbodies, 10)) * rng.uniform(0.1, 100.0)
        ref = Ku @ P[mpn.unknown].ravel()
        scale = np.abs(ref).max()
        np.testing.assert_allclose(mpn.regressor(Q, V) @ mpn.from_standard(P), ref, atol=1e-12 * scale)
        np.testing.assert_allclose(mpc.regressor(Q, V) @ mpc.from_standard(P), ref, atol=1e-12 * scale)
    # same row space of B: each map is an invertible transform of the other
    T = np.linalg.lstsq(mpn.matrix.T, mpc.matrix.T, rcond=None)[0]
    np.testing.assert_allclose(mpn.matrix.T @ T, mpc.matrix.T, atol=1e-10)


def test_deleted_directions_are_exact_combinations(dual_arm):
    m, mpn, mpc = dual_arm
    Q, V = random_states(m, 30, seed=11)
    G = unknown_regressor(m, mpn, Q, V).reshape(-1, 70)
    for mp in (mpn, mpc):
        N = scipy.linalg.null_space(mp.matrix)
        assert N.shape == (70, 18)  # 3 per revolute joint (Naveen, Shah, Misra, eqs. 18-20)
        assert np.abs(G @ N).max() <= 1e-12 * np.abs(G).max()


def test_regressor_columns_are_kept_standard_columns(dual_arm):
    _, mpn, mpc = dual_arm
    for mp in (mpn, mpc):
        np.testing.assert_array_equal(mp.matrix[:, mp.columns], np.eye(mp.n_min))


def test_known_wheels_move_to_the_right_hand_side(dual_arm):
    m, mpn, mpc = dual_arm
    assert [m.body_names[i] for i in mpn.known] == ["wheel_x", "wheel_y", "wheel_z"]
    Q, V = random_states(m, 10, seed=5)
    total = ff.momentum(m, Q, V)
    for mp in (mpn, mpc):
        rhs = mp.regressor(Q, V) @ mp.from_standard(m.parameters()) + mp.known_momentum(Q, V)
        np.testing.assert_allclose(rhs, total, atol=1e-10 * np.abs(total).max())
        assert mp.regressor(Q[0], V[0]).shape == (6, 52) and mp.known_momentum(Q[0], V[0]).shape == (6,)


def test_wheels_unknown_numeric_counts_their_columns():
    m = ff.models.load("naveen_dual_arm")
    mp = ff.minimal_parameters(m, known=[])
    assert mp.known == [] and len(mp.unknown) == 10
    # each wheel on a revolute joint adds 7 (same count as a link); its spin inertia about its own axis
    # is grouped like any Iyy/Izz.
    assert mp.rank == 52 + 3 * 7


@pytest.mark.slow
def test_numeric_other_joint_types():
    m = ff.models.load("valverde_ch7_two_arm")  # revolute, prismatic and spherical joints
    _check_numeric_reproduces_momentum(m, seed=2)
    with pytest.raises(ValueError, match='method="numeric"'):
        ff.minimal_parameters(m, method="closed-form")


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_numeric_random_trees(seed):
    rng = np.random.default_rng(1000 + seed)
    desc = rt.random_tree(
        rng,
        n_children=6,
        base="free",
        joint_types=("revolute", "prismatic", "spherical", "fixed"),
        joint_p=(0.25, 0.25, 0.3, 0.2),
    )
    _check_numeric_reproduces_momentum(ff.Model.from_yaml_string(desc.to_yaml()), seed=seed)


def _check_numeric_reproduces_momentum(m, seed):
    mp = ff.minimal_parameters(m, method="numeric")
    Q, V = random_states(m, 40, seed=100 + seed)  # 240 rows > 10 * nbodies columns
    Ku = unknown_regressor(m, mp, Q, V)
    rng = np.random.default_rng(seed)
    P = rng.normal(size=(m.nbodies, 10))
    ref = Ku @ P[mp.unknown].ravel()
    np.testing.assert_allclose(mp.regressor(Q, V) @ mp.from_standard(P), ref, atol=1e-11 * np.abs(ref).max())
    assert mp.rank == np.linalg.matrix_rank(Ku.reshape(-1, Ku.shape[-1])) <= 10 * len(mp.unknown)


def test_numeric_is_deterministic():
    m = ff.models.load("naveen_dual_arm")
    a, b = ff.minimal_parameters(m), ff.minimal_parameters(m)
    assert a.names == b.names and np.array_equal(a.matrix, b.matrix)


def test_closed_form_rejects_non_dh_placement():
    m = ff.models.load("naveen_dual_arm")
    # wheel_x spins about base x (joint axis not z): closed form must refuse once the wheels are unknown
    with pytest.raises(ValueError, match='method="numeric"'):
        ff.minimal_parameters(m, method="closed-form", known=[])


def test_bad_arguments():
    m = ff.models.load("naveen_dual_arm")
    with pytest.raises(ValueError, match="method"):
        ff.minimal_parameters(m, method="magic")
    with pytest.raises(ValueError, match="not a body"):
        ff.minimal_parameters(m, known=["nope"])
    mp = ff.minimal_parameters(m)
    with pytest.raises(ValueError, match="shape"):
        mp.from_standard(np.zeros((3, 10)))

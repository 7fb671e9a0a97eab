"""The dual-inertia regressor against the textbook body-frame Newton–Euler equations about the centre of mass,
f = m (v̇ + ω × v), τ = Ī ω̇ + ω × Ī ω, written here in numpy independently of the engine."""

import numpy as np
import pytest

import freefloat as ff


def _body(rng):
    a = rng.normal(size=(3, 3))
    return 1.0 + rng.random() * 5, a @ a.T + np.eye(3)


def _dq(a, b):
    return np.r_[0.0, a, 0.0, b]


def test_body_regressor_is_newton_euler_about_the_com():
    rng = np.random.default_rng(7)
    for _ in range(20):
        m, inertia = _body(rng)
        w, v, wd, vd = rng.normal(size=(4, 3))
        R = ff.dq.body_regressor(_dq(w, v), _dq(wd, vd))
        f = m * (vd + np.cross(w, v))
        tau = inertia @ wd + np.cross(w, inertia @ w)
        np.testing.assert_allclose(R @ ff.dq.inertia_params(m, inertia), _dq(f, tau), rtol=0, atol=1e-12)


def test_r_and_h_against_their_defining_identities():
    rng = np.random.default_rng(3)
    m, inertia = _body(rng)
    p = ff.dq.inertia_params(m, inertia)
    np.testing.assert_allclose(p, [*inertia[0], inertia[1, 1], inertia[1, 2], inertia[2, 2], m])
    a, b = _dq(*rng.normal(size=(2, 3))), _dq(*rng.normal(size=(2, 3)))
    m_star_b = np.r_[0.0, m * b[1:4], 0.0, inertia @ b[5:8]]
    np.testing.assert_allclose(ff.dq.r_matrix(b) @ p, m_star_b, atol=1e-13)
    assert ff.dq.h_vector(a, b) @ p == pytest.approx(a @ m_star_b, rel=1e-13)
    # rows 1 and 5 are zero and the force rows only see the mass: one sample has rank 4 (1 + 3), two generic
    # samples rank 7, the reason concurrent learning keeps a stack of them
    R1, R2 = (ff.dq.body_regressor(_dq(*rng.normal(size=(2, 3))), _dq(*rng.normal(size=(2, 3)))) for _ in range(2))
    assert np.all(R1[[0, 4]] == 0) and np.linalg.matrix_rank(R1) == 4
    assert np.linalg.matrix_rank(np.vstack([R1, R2])) == 7


def test_relative_regressor_with_the_desired_frame_at_rest_is_the_body_regressor():
    rng = np.random.default_rng(11)
    w, wd = _dq(*rng.normal(size=(2, 3))), _dq(*rng.normal(size=(2, 3)))
    q = ff.dq.from_pose([0.0, 0.0, np.sin(0.4), np.cos(0.4)], [1.0, 2.0, 3.0])
    zero = np.zeros(8)
    np.testing.assert_allclose(ff.dq.relative_regressor(wd, w, zero, zero, q), ff.dq.body_regressor(w, wd), atol=1e-14)


def test_bad_arguments_are_named():
    with pytest.raises(ff.InputError, match="argument `twist`: must be a vector dual quaternion"):
        ff.dq.body_regressor([1, 0, 0, 0, 0, 0, 0, 0], np.zeros(8))
    with pytest.raises(ff.InputError, match="argument `q_bd`"):
        ff.dq.relative_regressor(np.zeros(8), np.zeros(8), np.zeros(8), np.zeros(8), np.r_[2.0, np.zeros(7)])
    with pytest.raises(ff.InputError, match="argument `inertia`: expected a 3×3"):
        ff.dq.inertia_params(1.0, np.eye(2))
    with pytest.raises(ff.InputError, match="mass"):
        ff.dq.inertia_params(-1.0, np.eye(3))
    with pytest.raises(ff.InputError, match="argument `b`: entry 2 is NaN"):
        ff.dq.r_matrix([0, 1, np.nan, 0, 0, 0, 0, 0])

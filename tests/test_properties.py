"""Property tests (hypothesis): identities that must hold for every input, not only for the cases someone wrote
down. The dual-quaternion algebra (associativity, conjugation, unit poses, exp/log, the regressor's defining
identities) and the dynamics identities on random trees (ABA inverts RNEA, momentum = CMM · v = regressor · φ,
the inertia matrix is symmetric positive definite and gives the kinetic energy).

Random trees come from `random_trees.py` (plain numpy, independent of the engine), one per drawn seed; the
parameters φ in the momentum check are the description's own, not read back from the engine."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import freefloat as ff

import random_trees as rt

SETTINGS = settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
seeds = st.integers(min_value=0, max_value=2**32 - 1)
finite = st.floats(min_value=-10.0, max_value=10.0, allow_nan=False, allow_infinity=False)
dq8 = st.lists(finite, min_size=8, max_size=8).map(np.array)
vec3 = st.lists(finite, min_size=3, max_size=3).map(np.array)


def _close(a, b, rtol=1e-10):
    a, b = np.asarray(a, float), np.asarray(b, float)
    scale = max(1.0, float(np.max(np.abs(b))), float(np.max(np.abs(a))))
    np.testing.assert_allclose(a, b, rtol=0, atol=rtol * scale)


def _pose(rng):
    return ff.dq.from_pose(rt.random_unit_quaternion(rng), rng.normal(size=3))


# ---- dual-quaternion algebra -------------------------------------------------------------------------------------


@SETTINGS
@given(dq8, dq8, dq8)
def test_product_is_associative_and_conjugation_reverses_it(a, b, c):
    A, B, C = (ff.dq.DualQuaternion(x) for x in (a, b, c))
    _close(np.asarray((A * B) * C), np.asarray(A * (B * C)), 1e-12)
    _close(np.asarray((A * B).conj()), np.asarray(B.conj() * A.conj()), 1e-12)
    _close(np.asarray(A.swap().swap()), a, 0)


@SETTINGS
@given(seeds)
def test_unit_poses_compose_to_unit_poses_and_exp_inverts_log(seed):
    rng = np.random.default_rng(seed)
    p, q = _pose(rng), _pose(rng)
    assert (p * q).is_unit() and p.conj().is_unit()
    # exp ∘ log gives the pose back up to the sign of the double cover (q and −q are the same pose)
    back = np.asarray(ff.dq.exp(np.asarray(p.log())))
    _close(back * np.sign(back @ np.asarray(p)), np.asarray(p), 1e-9)
    x = ff.dq.vector(rng.normal(size=3), rng.normal(size=3))
    _close(np.asarray(p.shift_out(p.shift_in(x))), np.asarray(x), 1e-10)


@SETTINGS
@given(vec3, vec3, vec3, vec3, st.floats(0.01, 100.0), seeds)
def test_regressor_identities_hold_for_any_body(w, v, wd, vd, mass, seed):
    rng = np.random.default_rng(seed)
    a = rng.normal(size=(3, 3))
    inertia = a @ a.T + 0.01 * np.eye(3)
    p = ff.dq.inertia_params(mass, inertia)
    twist, rate = np.r_[0, w, 0, v], np.r_[0, wd, 0, vd]
    # the net dual force about the CoM: f = m (v̇ + ω × v), τ = Ī ω̇ + ω × Ī ω
    f = np.r_[0, mass * (vd + np.cross(w, v)), 0, inertia @ wd + np.cross(w, inertia @ w)]
    _close(ff.dq.body_regressor(twist, rate) @ p, f, 1e-11)
    # the dual momentum M ⋆ ω^s = m v + ε Ī ω, with ω^s = v + ε ω the swapped twist
    swapped, m_star = np.r_[0, v, 0, w], np.r_[0, mass * v, 0, inertia @ w]
    _close(ff.dq.r_matrix(swapped) @ p, m_star, 1e-12)
    _close(ff.dq.h_vector(rate, swapped) @ p, rate @ m_star, 1e-11)


# ---- dynamics identities on random trees -------------------------------------------------------------------------


def _tree(seed):
    rng = np.random.default_rng(seed)
    d = rt.random_tree(rng)
    return rng, d, ff.Model.from_yaml_string(d.to_yaml())


@SETTINGS
@given(seeds)
def test_aba_inverts_rnea(seed):
    rng, d, m = _tree(seed)
    q, v = d.random_q(rng), d.random_v(rng)
    a = rng.normal(size=d.nv)
    tau = ff.rnea(m, q, v, a)
    _close(ff.aba(m, q, v, tau), a, 1e-8)


@SETTINGS
@given(seeds)
def test_momentum_is_cmm_times_v_and_regressor_times_parameters(seed):
    rng, d, m = _tree(seed)
    q, v = d.random_q(rng), d.random_v(rng)
    h = ff.momentum(m, q, v)
    _close(ff.centroidal_momentum_matrix(m, q) @ v, h, 1e-10)
    _close(ff.momentum_regressor(m, q, v) @ d.parameters().ravel(), h, 1e-10)


@SETTINGS
@given(seeds)
def test_inertia_matrix_is_symmetric_positive_definite_and_gives_the_kinetic_energy(seed):
    rng, d, m = _tree(seed)
    q, v = d.random_q(rng), d.random_v(rng)
    M = ff.crba(m, q)
    _close(M, M.T, 1e-12)
    assert np.linalg.eigvalsh(0.5 * (M + M.T)).min() > 0
    _close(0.5 * v @ M @ v, ff.kinetic_energy(m, q, v), 1e-10)
    # M is RNEA's response to a unit acceleration at zero velocity
    k = int(rng.integers(d.nv))
    e = np.zeros(d.nv)
    e[k] = 1.0
    zero = np.zeros(d.nv)
    bias = ff.rnea(m, q, zero, zero)  # gravity only
    _close(ff.rnea(m, q, zero, e) - bias, M[:, k], 1e-9)


if __name__ == "__main__":  # pragma: no cover
    pytest.main([__file__, "-q"])

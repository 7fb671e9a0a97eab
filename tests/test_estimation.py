"""Least-squares identification from momentum (python/freefloat/estimation.py, engine crate `estimation`):
naveen_dual_arm driven by a prescribed multi-sine on the six arm joints and three wheels; exact recovery from
noise-free momentum, consistent standard deviations under noise, agreement with numpy.linalg.lstsq on the
explicitly built minimal regressor (eq. 26), rank deficiency reported, and the error figures (eqs. 38-39)."""

import os
import subprocess
import sys

import numpy as np
import pytest

import freefloat as ff
from freefloat import estimation as est

DRIVEN = ["J1", "J2", "J3", "J4", "J5", "J6", "Wx", "Wy", "Wz"]


def multisine(m, joints, seed, wheel_scale=20.0):
    """prescription(t) -> (q, v, a): per joint a sum of three sines (random amplitude, frequency, phase)."""
    traj = ff.trajectories.MultiSine.random(len(joints), seed)
    traj.amp[[j.startswith("W") for j in joints]] *= wheel_scale
    return traj.prescription(m, joints)


def run(m, joints=DRIVEN, t_final=6.0, seed=1):
    presc = multisine(m, joints, seed)
    q0, v0, _ = presc(0.0)
    return ff.simulate(m, q0, v0, t_final, 1e-3, prescribed=joints, prescription=presc, record_every=10)


@pytest.fixture(scope="module")
def case():
    m = ff.models.load("naveen_dual_arm")
    mp = ff.minimal_parameters(m, method="closed-form")  # wheels are known (tagged)
    return m, mp, run(m), mp.from_standard(m.parameters())


def explicit(mp, tr, H, weights=None):
    """The tall minimal regressor G_m and right-hand side of eq. 26, built explicitly, optionally weighted."""
    G = mp.regressor(tr.q, tr.v)
    y = H - mp.known_momentum(tr.q, tr.v)
    if weights is not None:
        sw = np.sqrt(weights)
        G, y = G * sw[:, None], y * sw
    return G.reshape(-1, mp.n_min), y.ravel()


def test_noise_free_momentum_recovers_the_minimal_parameters(case):
    m, mp, tr, truth = case
    assert mp.known == [7, 8, 9]
    for method in ("auto", "qr"):
        r = est.least_squares(m, tr.q, tr.v, tr.momentum, mp, method=method)
        rel = np.abs(r.estimate - truth) / np.abs(truth)
        assert rel.max() < 1e-8, (method, rel.max())
        assert r.rows == 6 * len(tr.t) and r.dof == r.rows - 52
        assert r.rss < 1e-16 * np.sum(tr.momentum**2)
    med, mx = est.relative_errors(r.estimate, truth)
    assert mx < 1e-6 and med <= mx  # percent


def test_equals_numpy_lstsq_on_the_explicit_regressor(case):
    m, mp, tr, truth = case
    rng = np.random.default_rng(3)
    H = tr.momentum + rng.normal(scale=0.5, size=tr.momentum.shape)
    for weights in (None, np.array([1.0, 2.0, 0.5, 4.0, 1.0, 0.25])):
        r = est.least_squares(m, tr.q, tr.v, H, mp, weights=weights)
        G, y = explicit(mp, tr, H, weights)
        x, res, rank, sv = np.linalg.lstsq(G, y, rcond=None)
        assert rank == 52
        np.testing.assert_allclose(r.estimate, x, rtol=0, atol=1e-10 * np.abs(x).max())
        np.testing.assert_allclose(r.rss, res[0], rtol=1e-9)
        np.testing.assert_allclose(r.condition_number, sv[0] / sv[-1], rtol=1e-9)
        cov = r.rss / (G.shape[0] - 52) * np.linalg.inv(G.T @ G)
        np.testing.assert_allclose(r.covariance, cov, rtol=1e-8, atol=1e-12 * np.abs(cov).max())
        np.testing.assert_allclose(r.std, np.sqrt(np.diag(cov)), rtol=1e-8)


def test_noisy_momentum_gives_consistent_standard_deviations(case):
    """With Gaussian noise of known sigma per component and weights 1/sigma^2, the normalised errors
    (estimate - truth)/std are ~N(0, 1): their mean square is near 1 and none is extreme."""
    m, mp, tr, truth = case
    sigma = np.array([0.2, 0.2, 0.2, 0.5, 0.5, 0.5])
    z2 = []
    for seed in range(5):
        rng = np.random.default_rng(100 + seed)
        H = tr.momentum + rng.normal(size=tr.momentum.shape) * sigma
        r = est.least_squares(m, tr.q, tr.v, H, mp, weights=1.0 / sigma**2)
        z = (r.estimate - truth) / r.std
        assert np.abs(z).max() < 5.0, np.abs(z).max()
        assert 0.7 < r.sigma < 1.3  # weighted residuals have unit variance
        z2.append(np.mean(z**2))
    # 5 x 52 normalised errors: mean square ~ chi^2_260 / 260, within [0.7, 1.35] with overwhelming probability
    assert 0.7 < np.mean(z2) < 1.35, z2


def test_unexcited_parameters_are_reported(case):
    """One state repeated (Fig. 4's single interval, taken to the limit) excites at most 6 combinations."""
    m, mp, tr, _ = case
    Q, V, H = (np.repeat(x[100:101], 20, axis=0) for x in (tr.q, tr.v, tr.momentum))
    with pytest.raises(ff.NumericalError, match=r"rank-deficient.*rank [1-6] of 52") as e:
        est.least_squares(m, Q, V, H, mp)
    assert str(e.value).count("x[") >= 46  # every unexcited direction is listed with its parameter indices
    assert "(phi_m(" in str(e.value)  # ... and the names of the minimal parameters


def test_relative_errors_follow_eqs_38_39():
    truth = np.array([2.0, -4.0, 10.0, 1.0])
    estimate = np.array([2.2, -4.0, 9.0, 1.5])  # 10 %, 0 %, 10 %, 50 %
    med, mx = est.relative_errors(estimate, truth)
    assert med == pytest.approx(10.0) and mx == pytest.approx(50.0)
    with pytest.raises(ff.InputError):
        est.relative_errors([1.0, 2.0], [1.0, 0.0])


def test_bad_arguments_are_named(case):
    m, mp, tr, _ = case
    with pytest.raises(ff.InputError, match="H"):
        est.least_squares(m, tr.q, tr.v, tr.momentum[:-1], mp)
    with pytest.raises(ff.InputError, match="weights"):
        est.least_squares(m, tr.q, tr.v, tr.momentum, mp, weights=[1.0, 1.0, 1.0, 1.0, 1.0, -1.0])
    with pytest.raises(ff.InputError, match="method"):
        est.least_squares(m, tr.q, tr.v, tr.momentum, mp, method="svd")


_SAME_BITS_SCRIPT = """
import os, sys, numpy as np, freefloat as ff
from freefloat import estimation as est
os.sched_setaffinity(0, {int(c) for c in sys.argv[1].split(",")})
m = ff.models.load("naveen_dual_arm")
mp = ff.minimal_parameters(m, method="closed-form")
rng = np.random.default_rng(3)
T = 9000  # above the engine's one-thread limit (4096): several chunks, several threads where allowed
Q = np.tile(m.neutral(), (T, 1)) + rng.uniform(-1, 1, (T, m.nq))
Q[:, 3:7] /= np.linalg.norm(Q[:, 3:7], axis=1, keepdims=True)
V = rng.uniform(-1, 1, (T, m.nv))
H = rng.uniform(-1, 1, (T, 6))
r = est.least_squares(m, Q, V, H, mp)
print(r.estimate.tobytes().hex(), float(r.rss).hex())
"""


@pytest.mark.skipif(not hasattr(os, "sched_setaffinity") or len(os.sched_getaffinity(0)) < 2, reason="needs 2 cores")
def test_the_estimate_is_the_same_to_the_bit_on_one_core_and_on_two():
    # The samples are streamed in fixed chunks whose partial sums are merged in chunk order, so the number of
    # threads (the cores the process may use) changes nothing, not even the last bit.
    cores = sorted(os.sched_getaffinity(0))[:2]
    one = subprocess.run([sys.executable, "-c", _SAME_BITS_SCRIPT, str(cores[0])], capture_output=True, text=True)
    two = subprocess.run(
        [sys.executable, "-c", _SAME_BITS_SCRIPT, ",".join(map(str, cores))], capture_output=True, text=True
    )
    assert one.returncode == 0 and two.returncode == 0, one.stderr + two.stderr
    assert one.stdout.strip() and one.stdout == two.stdout


def test_the_time_series_are_read_in_place_whatever_their_memory_layout(case):
    # Q, V, H are read where numpy keeps them when they are C-contiguous float64 (no copy), converted once
    # otherwise: every layout gives the same estimate to the bit, a read-only array is accepted, and the arrays
    # are neither changed nor left borrowed (still writeable afterwards).
    m, mp, tr, _ = case
    Q, V, H = (np.ascontiguousarray(x) for x in (tr.q, tr.v, tr.momentum))
    ref = est.least_squares(m, Q, V, H, mp).estimate
    before = [x.copy() for x in (Q, V, H)]
    frozen = H.copy()
    frozen.flags.writeable = False
    wide = np.zeros((len(V), 2 * m.nv))
    wide[:, ::2] = V  # a strided view: every other column
    layouts = {
        "Fortran order": (np.asfortranarray(Q), np.asfortranarray(V), np.asfortranarray(H)),
        "strided view": (Q, wide[:, ::2], H),
        "read-only": (Q, V, frozen),
        "lists": (Q.tolist(), V.tolist(), H.tolist()),
        "big-endian": (Q.astype(">f8"), V, H),
    }
    for name, (q, v, h) in layouts.items():
        got = est.least_squares(m, q, v, h, mp).estimate
        assert got.tobytes() == ref.tobytes(), name
    for x, x0 in zip((Q, V, H), before):
        assert np.array_equal(x, x0) and x.flags.writeable
        x[0, 0] += 0.0  # writing is allowed again: no borrow outlives the call


def test_a_non_finite_sample_is_named_with_its_argument(case):
    m, mp, tr, _ = case
    for name, k in (("Q", 0), ("V", 1), ("H", 2)):
        args = [np.array(tr.q), np.array(tr.v), np.array(tr.momentum)]
        args[k][123, 2] = np.nan
        with pytest.raises(ff.InputError, match=rf"argument `{name}`: sample 123: entry 2 is NaN"):
            est.least_squares(m, *args, mp)

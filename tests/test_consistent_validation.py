"""Physically consistent full parameters from minimal ones, validation by prediction (seed 001 Sec. VI.D),
identification with external impulses, and weighted least squares."""

import numpy as np
import pytest

import freefloat as ff
from freefloat import identify as idf
from freefloat import telemetry as tm
from freefloat import trajectories as tr
from freefloat import quat_to_matrix
from freefloat.consistent import consistent_parameters, is_consistent, pseudo_inertia
from freefloat.validation import default_fourier, predict


@pytest.fixture(scope="module")
def consistent_robot():
    return ff.models.load("seed001_dual_arm_consistent")


@pytest.fixture(scope="module")
def prior():
    return ff.models.load("seed001_dual_arm_offset")


def _params(m, c, I_c):
    """Standard parameters from mass, CoM and inertia about the CoM (parallel axis theorem, independent of J)."""
    I_o = I_c + m * (np.dot(c, c) * np.eye(3) - np.outer(c, c))
    return np.array([m, *(m * c), I_o[0, 0], I_o[0, 1], I_o[1, 1], I_o[0, 2], I_o[1, 2], I_o[2, 2]])


def test_pseudo_inertia_test_is_the_triangle_inequality():
    rng = np.random.default_rng(3)
    c = rng.normal(size=3)
    # Principal moments (1, 1.5, 2): consistent. (1, 1, 2.5): violates Izz <= Ixx + Iyy.
    assert is_consistent(_params(2.0, c, np.diag([1.0, 1.5, 2.0])))
    assert not is_consistent(_params(2.0, c, np.diag([1.0, 1.0, 2.5])))
    assert not is_consistent(_params(-1.0, c, np.diag([1.0, 1.5, 2.0])))  # negative mass
    # J's trace identity: tr(J) = m + tr(I_o)/2.
    p = _params(3.0, c, np.diag([1.0, 1.5, 2.0]))
    assert np.trace(pseudo_inertia(p)) == pytest.approx(p[0] + 0.5 * (p[4] + p[6] + p[9]))


def test_consistent_parameters_reproduce_exact_minimal_parameters(consistent_robot, prior):
    m = consistent_robot
    mp = ff.minimal_parameters(m, "closed-form")
    phi = mp.from_standard(m.parameters())
    c = consistent_parameters(mp, phi, prior=prior)
    assert c.max_rel_deviation < 1e-6
    assert all(is_consistent(c.parameters[b]) for b in range(m.nbodies))
    # The standard parameters differ from the truth (the data cannot see everything) ...
    assert np.abs(c.parameters - m.parameters()).max() > 1.0
    # ... yet the momentum of the new model equals the true robot's at random states (engine, not the map B).
    mi = c.model(m)
    rng = np.random.default_rng(0)
    for _ in range(5):
        q, v = m.random_configuration(rng), rng.normal(size=m.nv)
        h_true = ff.momentum(m, q, v)
        np.testing.assert_allclose(ff.momentum(mi, q, v), h_true, rtol=0, atol=1e-5 * np.abs(h_true).max())


def test_verbatim_table2_has_no_consistent_representative(prior):
    # seed 001's Table 2 links are not physically consistent; no consistent robot has the same minimal
    # parameters: the nearest one misses some of them by several percent (L4.Izz, L6.Izz, L6.Ixy).
    m = ff.models.load("seed001_dual_arm")
    mp = ff.minimal_parameters(m, "closed-form")
    c = consistent_parameters(mp, mp.from_standard(m.parameters()), prior=prior)
    assert c.max_rel_deviation > 0.02
    assert all(is_consistent(c.parameters[b]) for b in mp.unknown)


def test_bad_inputs_to_consistent_parameters(consistent_robot):
    mp = ff.minimal_parameters(consistent_robot, "closed-form")
    with pytest.raises(ff.InputError, match="phi"):
        consistent_parameters(mp, np.ones(3))
    with pytest.raises(ff.InputError, match="covariance"):
        consistent_parameters(mp, np.ones(mp.n_min), covariance=-np.eye(mp.n_min))


def test_prediction_of_the_same_robot_is_exact_and_of_a_representative_nearly(consistent_robot, prior):
    m = consistent_robot
    same = predict(m, m, dt=5e-3)
    assert np.abs(same.rms_twist).max() == 0.0 and np.abs(same.rms_torque).max() == 0.0
    # A different full parameter set with the same minimal parameters predicts the same motion and torques
    # (momentum AND dynamics depend only on the minimal parameters, seed 001 Sec. IV / digest A.9).
    mp = ff.minimal_parameters(m, "closed-form")
    rep = consistent_parameters(mp, mp.from_standard(m.parameters()), prior=prior).model(m)
    p = predict(m, rep, dt=5e-3)
    assert p.rms_twist.max() < 1e-8
    assert p.rms_torque.max() < 1e-6 * np.sqrt(np.mean(p.tau_true ** 2))
    # The prior alone (Table 2 "offset") predicts badly: the test can tell good from bad parameters.
    bad = predict(m, prior, dt=5e-3)
    assert bad.rms_twist.max() > 1e-4 and bad.rms_torque.max() > 0.1
    assert "Table 6" in p.table() and set(p.to_dict()) >= {"rms_twist", "rms_torque"}


def test_prediction_starts_with_zero_momentum_and_follows_fourier(consistent_robot):
    m = consistent_robot
    fourier = default_fourier(np.zeros(6))
    q, qd, qdd = fourier.evaluate(np.array([0.0, 7.0]))
    # eq. 41 is the derivative of eq. 40 (central difference).
    h = 1e-6
    qp, _, _ = fourier.evaluate(np.array([7.0 + h]))
    qm, _, _ = fourier.evaluate(np.array([7.0 - h]))
    np.testing.assert_allclose((qp - qm)[0] / (2 * h), qd[1], atol=1e-7)
    assert fourier.duration == pytest.approx(40.0)
    from freefloat.simulation import simulate_driven

    traj = simulate_driven(m, fourier, m.joints_tagged("arm_"), 5e-3, held=m.joints_tagged("wheel"), t_final=1.0)
    assert np.abs(traj.momentum).max() < 1e-9 * m.total_mass


def test_noisy_identification_predicts_far_below_the_noise_floor(consistent_robot, prior):
    m = consistent_robot
    telem, _ = idf.excitation_data(m, n_intervals=24, seed=1)
    res = ff.identify_minimal(m, telem)
    c = consistent_parameters(res.mp, res.estimate, covariance=res.fit.covariance, prior=prior)
    assert c.max_rel_deviation < 1e-5  # the noisy estimate is reachable by a consistent robot
    p = predict(m, c.model(m), dt=5e-3)
    # Paper Table 6: 1-4 x the rate noise (50 µm/s, 80 µrad/s); we require 100 x below it.
    assert p.rms_twist[:3].max() < 0.01 * 50e-6 and p.rms_twist[3:].max() < 0.01 * 80e-6
    assert p.rms_torque.max() < 0.1 * 0.3808


@pytest.fixture(scope="module")
def thrust_run():
    """Seed 001 robot with base thrusters firing while the arms and wheels move (16 intervals, all 52 excited)."""
    m = ff.models.load("seed001_dual_arm")
    arm, wh = m.joints_tagged("arm_"), m.joints_tagged("wheel")
    start, rng_ = tr.with_wheels(np.deg2rad(idf.TABLE3_START_DEG), idf.TABLE3_RANGE_RAD)
    cyc = tr.Cycloidal(start, rng_, tr.direction_combinations(9)[::16])
    presc = cyc.prescription(m, arm + wh)
    q0, v0, _ = presc(0.0)

    def thrust(t, q, v):
        tau = np.zeros(m.nv)
        tau[:6] = [20 * np.sin(t), 10.0, -5 * np.cos(2 * t), 3.0, -2 * np.sin(t), 1.0]
        return tau

    traj = ff.simulate(m, q0, v0, cyc.duration, 1e-3, prescribed=arm + wh, prescription=presc, torques=thrust)
    R, p = quat_to_matrix(traj.q[:, 3:7]), traj.q[:, :3]
    f = np.einsum("tij,tj->ti", R, traj.tau[:, :3])
    mo = np.cross(p, f) + np.einsum("tij,tj->ti", R, traj.tau[:, 3:6])  # moment about the inertial origin
    telem = tm.Telemetry(t=traj.t, q=traj.q, v=traj.v, model_name=m.name, q_labels=m.q_labels(),
                         v_labels=m.v_labels(), wrench=np.hstack([f, mo]))
    return m, traj, telem


def test_integrated_wrench_is_the_engine_momentum(thrust_run):
    _, traj, telem = thrust_run
    H = telem.integrated_momentum()
    assert np.abs(traj.momentum).max() > 10.0  # the thrusters really changed the momentum
    np.testing.assert_allclose(H, traj.momentum, atol=1e-7 * np.abs(traj.momentum).max() * 100)


def test_identification_with_external_impulses(thrust_run, tmp_path):
    m, _, telem = thrust_run
    truth = ff.minimal_parameters(m, "closed-form").from_standard(m.parameters())
    res = ff.identify_minimal(m, telem)
    np.testing.assert_allclose(res.estimate, truth, rtol=1e-5)
    # Without the wrench the conserved-momentum assumption is wrong and the estimate is useless.
    bare = tm.Telemetry(t=telem.t, q=telem.q, v=telem.v)
    assert ff.identify_minimal(m, bare).errors(m)["median_rel_error_pct"] > 10
    # The wrench columns survive a CSV round trip and are used from the file.
    path = tmp_path / "thrust.csv"
    telem.to_csv(path)
    np.testing.assert_allclose(ff.identify_minimal(m, path).estimate, res.estimate, rtol=1e-10)


def test_partial_wrench_columns_are_named(thrust_run, tmp_path):
    m, _, telem = thrust_run
    cols = telem.columns()
    del cols["wrench.mz"]
    import pyarrow as pa
    import pyarrow.parquet as pq

    path = tmp_path / "partial.parquet"
    pq.write_table(pa.table(cols), str(path))
    with pytest.raises(ff.InputError, match="wrench.mz"):
        tm.Telemetry.from_file(path, m)


def test_weighted_least_squares(consistent_robot):
    m = consistent_robot
    telem, _ = idf.excitation_data(m, n_intervals=16, seed=2)
    plain = ff.identify_minimal(m, telem)
    auto = ff.identify_minimal(m, telem, weights="auto")
    # Both are accurate; the weighted one uses different weights, so the estimates differ a little.
    assert auto.errors(m)["median_rel_error_pct"] < 0.5
    assert not np.allclose(auto.estimate, plain.estimate, rtol=1e-12, atol=0)
    with pytest.raises(ff.InputError, match="weights"):
        ff.identify_minimal(m, telem, weights="best")


def test_bias_compensation_removes_the_errors_in_variables_bias():
    # Least squares on noisy rates shrinks the estimate (about -0.05 % common mode with the paper's noise,
    # standard deviations ~10x too small). With the known rate noise the bias is removed and the reported
    # standard deviations match the actual errors (z-scores of order one).
    m = ff.models.load("seed001_dual_arm")
    telem, _ = idf.excitation_data(m, n_intervals=48, seed=5)
    truth = ff.minimal_parameters(m, "closed-form").from_standard(m.parameters())
    ls = ff.identify_minimal(m, telem)
    bc = ff.identify_minimal(m, telem, rate_noise=(tm.SIGMA_LIN, tm.SIGMA_ANG, tm.SIGMA_JOINT))
    rel_ls, rel_bc = (ls.estimate - truth) / truth, (bc.estimate - truth) / truth
    assert np.median(rel_ls) < -2e-4                      # the bias is there, and it is a shrinkage
    assert abs(np.median(rel_bc)) < 0.3 * abs(np.median(rel_ls))
    assert np.median(np.abs(rel_bc)) < 0.5 * np.median(np.abs(rel_ls))
    z_ls = np.sqrt(np.mean(((ls.estimate - truth) / ls.std) ** 2))
    z_bc = np.sqrt(np.mean(((bc.estimate - truth) / bc.std) ** 2))
    assert z_ls > 5 and z_bc < 3
    assert "bias compensation" in bc.fit.method
    with pytest.raises(ff.InputError, match="rate_noise"):
        ff.identify_minimal(m, telem, rate_noise=(1.0, 2.0))


def test_bias_compensation_refuses_a_noise_dominated_direction():
    # The first 20 direction combinations (not spread over the 256) leave one combination barely excited
    # (condition number ~4e5): compensating there would amplify noise, so the plain estimate comes back.
    m = ff.models.load("seed001_dual_arm")
    telem, _ = idf.excitation_data(m, n_intervals=20, spread=False, seed=0)
    plain = ff.identify_minimal(m, telem)
    with pytest.warns(UserWarning, match="least-excited direction"):
        bc = ff.identify_minimal(m, telem, rate_noise=(tm.SIGMA_LIN, tm.SIGMA_ANG, tm.SIGMA_JOINT))
    np.testing.assert_array_equal(bc.estimate, plain.estimate)
    assert "skipped" in bc.fit.method

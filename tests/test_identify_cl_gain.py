"""The ch. 9 SVD gain under sensor noise: the thesis' (9.27) stays the default, bit for bit; the truncated gain (9.27')
accelerates a weak direction only where the data outweigh κ times their noise estimate. Checked against numpy (the
rule on a small problem through the public estimator), and on the built-in run: without noise it is the thesis run
to the bit; with joint-wrench noise, where the thesis gain's error explodes, its error stays below the prior's."""

import subprocess
import sys

import numpy as np
import pytest

import freefloat as ff
from freefloat._core import InputError
from freefloat.identification import concurrent as cl
from freefloat.identification import concurrent_studies as studies

MODEL = "valverde_ch9_two_arm"
# noisy runs end with estimates that are not rigid bodies (the warning is the run's, not this file's subject)
pytestmark = pytest.mark.filterwarnings("ignore:the final estimate of")


@pytest.fixture(scope="module")
def scenario():
    return cl.load_scenario(MODEL)


@pytest.fixture(scope="module")
def model():
    return ff.models.load(MODEL)


def _rel(r):
    return np.abs(r.final_estimate - r.truth) / cl.parameter_scales(r.truth)


def test_default_is_the_thesis_gain_bit_for_bit(scenario, model):
    # the scenario has no `gain` key, so `run` leaves the engine's default in place
    assert "gain" not in scenario.estimator
    for kw in ({}, {"wrench_noise": 1e-3}, {"rate_noise": 1e-5}):
        a = cl.run(scenario, **kw)
        b = cl.run(scenario, gain="thesis", **kw)
        np.testing.assert_array_equal(a.estimates, b.estimates)
        assert a.settings["gain"] == "thesis" and a.gain_withheld == [0] * 11
    # the estimator class: the same gain blocks as gain="thesis" and as the explicit truncated gain's complement
    rng = np.random.default_rng(5)
    ests = [cl.ConcurrentLearningEstimator(11, np.zeros(77), t_th2=0.0, **kw) for kw in ({}, {"gain": "thesis"})]
    for _ in range(10):
        q = model.random_configuration(rng)
        R, F, _, _ = cl.sample(model, q, rng.normal(size=model.nv) * 0.2, rng.normal(size=model.nv) * 0.3, 1e-3)
        for e in ests:
            e.add_sample(R, F)
    for e in ests:
        e.step(1e-4)
    np.testing.assert_array_equal(ests[0].gain, ests[1].gain)
    np.testing.assert_array_equal(ests[0].estimate, ests[1].estimate)


def test_without_noise_the_truncated_gain_is_the_thesis_run(scenario):
    # measured: every direction passes (σ̂ ≤ 3e-16 per body), so K and the whole run are the thesis' to the bit
    a = cl.run(scenario)
    b = cl.run(scenario, gain="truncated")
    np.testing.assert_array_equal(a.estimates, b.estimates)
    assert b.gain_withheld == [0] * 11
    assert np.all(b.noise_sigma < 1e-12)
    assert _rel(b).max() < 1e-8  # the thesis' accuracy: 5.6e-10


@pytest.mark.parametrize("level", [1e-3, 1e-2])
def test_with_wrench_noise_the_truncated_gain_stays_bounded(scenario, level):
    # measured over 500 noise seeds: the truncated gain's largest relative error 0.9896 at 1e-3 N, 0.9905 at 1e-2 N
    # (the prior's error in the directions it leaves alone: the scenario starts every body at a tenth of its
    # inertia); the thesis gain's 1e4-1e6. The masses are strong directions: both gains estimate them alike.
    for seed in (7, 8, 9):
        th = cl.run(scenario, wrench_noise=level, noise_seed=seed)
        tr = cl.run(scenario, wrench_noise=level, noise_seed=seed, gain="truncated")
        assert _rel(th).max() > 1e3 * level / 1e-3
        assert _rel(tr).max() < 1.0
        assert np.median(_rel(tr)) < 0.5
        np.testing.assert_allclose(_rel(tr).reshape(-1, 7)[:, 6], _rel(th).reshape(-1, 7)[:, 6], rtol=1e-6)
        assert sum(tr.gain_withheld) > 0
        # σ̂ is of the size of the sensor noise (a body's wrench combines one or two joints' sensors)
        assert np.all((tr.noise_sigma > 0.5 * level) & (tr.noise_sigma < 3 * level))


def test_the_rule_on_a_small_problem_against_numpy():
    # one body, three samples with weakly excited parameter combinations and noisy wrenches; the gain the estimator
    # forms at t_th2 = 0 against (9.27') evaluated with numpy's SVD of the stacked samples
    rng = np.random.default_rng(4)
    truth = np.array([1.0, 0.1, -0.2, 2.0, 0.05, 1.5, 5.0])
    m0 = np.array([0.5, 0.0, 0.0, 0.5, 0.0, 0.5, 2.0])
    col = np.array([1.0, 0.3, 1e-2, 3e-3, 1e-3, 1e-4, 1e-5])
    R = rng.normal(size=(3, 1, 8, 7)) * col
    R[:, :, [0, 4], :] = 0
    F = np.einsum("kbij,j->kbi", R, truth) + 1e-4 * rng.normal(size=(3, 1, 8))
    F[:, :, [0, 4]] = 0
    kappa, sth2, snew = 6.0, 1e6, 50.0  # σ_th,2 above every σ_i: (9.27) would accelerate all seven
    est = cl.ConcurrentLearningEstimator(1, m0, ns=3, t_th2=0.0, sigma_th2=sth2, sigma_new=snew, gain="truncated")
    for k in range(3):
        est.add_sample(R[k], F[k])
    est.step(1e-6)
    A, b = R[:, 0].reshape(-1, 7), F[:, 0].reshape(-1)
    U, s, Vt = np.linalg.svd(A, full_matrices=False)
    rho = np.linalg.norm(b - A @ np.linalg.lstsq(A, b, rcond=None)[0])
    sigma_hat = rho / np.sqrt(18 - 7)  # 3 samples x 6 nonzero rows, rank 7
    np.testing.assert_allclose(est.noise_sigma, [sigma_hat], rtol=1e-9)
    evidence = np.abs(U.T @ (b - A @ m0))
    keep = evidence >= kappa * sigma_hat
    assert 0 < keep.sum() < 7, evidence / sigma_hat  # both outcomes occur, so the test can tell
    sbar = np.where(keep, snew / s**2, 1.0)
    K = Vt.T @ np.diag(sbar) @ Vt
    np.testing.assert_allclose(est.gain[0], K, rtol=0, atol=1e-8 * np.abs(K).max())
    assert est.gain_withheld.tolist() == [int((~keep).sum())]
    # the thesis gain on the same data accelerates all seven
    th = cl.ConcurrentLearningEstimator(1, m0, ns=3, t_th2=0.0, sigma_th2=sth2, sigma_new=snew)
    for k in range(3):
        th.add_sample(R[k], F[k])
    th.step(1e-6)
    K_th = Vt.T @ np.diag(snew / s**2) @ Vt
    np.testing.assert_allclose(th.gain[0], K_th, rtol=0, atol=1e-8 * np.abs(K_th).max())


def test_stack_changes_after_the_switch_keep_the_reference(scenario):
    # at N_s = 300 the stack changes at every step until t_th = 5 s, after the gain switched on at 4.9 s; the rule is
    # re-evaluated each time against the estimate of the switch (measured: 6 directions withheld at 1e-3 N, noise seed
    # 7; against the estimate of the moment, already at its least-squares values, 67 of the 69 would be)
    r = cl.run(scenario, ns=300, wrench_noise=1e-3, gain="truncated")
    assert sum(r.gain_withheld) <= 10, r.gain_withheld
    assert np.median(_rel(r)) < 0.05  # measured 0.022


def test_noise_study_reports_the_three_laws_side_by_side(scenario):
    rows = studies.noise_study(scenario, wrench_levels=[1e-3], rate_levels=[1e-5], seeds=[7, 8])
    assert [(r["kind"], r["gain"]) for r in rows] == [
        ("wrench", "plain"),
        ("wrench", "thesis"),
        ("wrench", "truncated"),
        ("rate", "plain"),
        ("rate", "thesis"),
        ("rate", "truncated"),
    ]
    by = {(r["kind"], r["gain"]): r for r in rows}
    assert by[("wrench", "thesis")]["max_final_relative_error"] > 1e3
    assert by[("wrench", "truncated")]["max_final_relative_error"] < 1.0
    assert by[("wrench", "truncated")]["withheld_directions"] > 0
    assert all(r["seeds"] == [7, 8] for r in rows)
    with pytest.raises(InputError, match="gains"):
        studies.noise_study(scenario, [1e-3], gains=("tikhonov",))
    with pytest.raises(InputError, match="seeds"):
        studies.noise_study(scenario, [1e-3], seeds=[])


# ---- bad input ------------------------------------------------------------------------------------------


def test_bad_gain_arguments_name_the_argument(scenario):
    for bad in ("tikhonov", "Thesis", ""):
        with pytest.raises(InputError, match="gain"):
            cl.ConcurrentLearningEstimator(11, scenario.m0, gain=bad)
        with pytest.raises(InputError, match="gain"):
            cl.run(scenario, gain=bad)
    for bad in (0.0, -1.0, float("nan"), float("inf")):
        with pytest.raises(InputError, match="kappa"):
            cl.ConcurrentLearningEstimator(11, scenario.m0, gain="truncated", kappa=bad)
        with pytest.raises(InputError, match="kappa"):
            cl.run(scenario, gain="truncated", kappa=bad)
    with pytest.raises(InputError, match="gain"):
        ff._core.cl_estimate(np.zeros((2, 1, 8, 7)), np.zeros((2, 1, 8)), 0.01, np.zeros(7), gain="svd")


def test_scenario_keys_are_checked_with_file_line_and_key(tmp_path):
    p = tmp_path / "bad.yaml"
    p.write_text("kind: identify_cl\nmodel: valverde_ch9_two_arm\nestimator:\n  ns: 10\n  gain: tikhonov\n")
    with pytest.raises(InputError, match=r"bad.yaml.*line 5.*estimator.gain"):
        cl.load_scenario(p)
    p.write_text("kind: identify_cl\nmodel: valverde_ch9_two_arm\nestimator:\n  kappa: 0\n")
    with pytest.raises(InputError, match=r"bad.yaml.*line 4.*estimator.kappa"):
        cl.load_scenario(p)
    p.write_text("kind: identify_cl\nmodel: valverde_ch9_two_arm\nestimator:\n  gain: truncated\n  kappa: 4.5\n")
    sc = cl.load_scenario(p)
    assert sc.estimator["gain"] == "truncated" and sc.estimator["kappa"] == 4.5
    r = cl.run(sc, wrench_noise=1e-3)
    assert r.settings["gain"] == "truncated" and r.settings["kappa"] == 4.5 and sum(r.gain_withheld) > 0


def test_cli_gain_options(tmp_path):
    exe = [sys.executable, "-m", "freefloat", "identify", "cl"]
    h = subprocess.run([*exe, "--help"], capture_output=True, text=True, check=True)
    assert "--gain [thesis|truncated]" in h.stdout and "--kappa" in h.stdout and "--noise-seeds" in h.stdout
    r = subprocess.run(
        [*exe, MODEL, "--no-sweep", "--gain", "truncated", "--wrench-noise", "1e-3", "--noise-seeds", "2"],
        capture_output=True,
        text=True,
    )
    assert r.returncode == 0, r.stderr
    assert "truncated gain (kappa 6)" in r.stdout and "noise seeds 7-8" in r.stdout
    lines = [ln.split() for ln in r.stdout.splitlines() if ln.startswith("wrench ")]
    assert [ln[2] for ln in lines] == ["plain", "thesis", "truncated"]
    assert float(lines[1][3]) > 1e3 and float(lines[2][3]) < 1.0
    for args, hint in (
        (["--gain", "svd"], "--gain"),
        (["--kappa", "-1"], "--kappa"),
        (["--noise-seeds", "0"], "--noise-seeds"),
    ):
        bad = subprocess.run([*exe, MODEL, "--no-sweep", "--no-noise", *args], capture_output=True, text=True)
        assert bad.returncode != 0 and hint in bad.stderr, bad.stderr

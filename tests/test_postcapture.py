"""Zhang, Yue, Yuan 2020 post-capture identification (issue 3): closed forms, simulation, both estimators, bad input.

Truth is read from the model YAML files themselves (mass, CoM offset, inertia about the CoM), not from
the code under test; cross-checks use conservation laws, the closed-form attitude response of eq. (39),
the paper's printed numbers and definitions evaluated directly (c × ċ with finite differences)."""

import json
from pathlib import Path

import numpy as np
import postcapture_numpy_oracle as oracle
import pytest
import yaml
from click.testing import CliRunner

import freefloat as ff
from freefloat import _core
from freefloat import postcapture as pc
from freefloat.cli import main
from freefloat.postcapture import equations as eq

ROOT = Path(__file__).resolve().parents[1]


def yaml_truth(model_name):
    """(m, b', I'_c) of base and target straight from the built-in model's YAML text."""
    d = yaml.safe_load(ff.models.source(model_name))
    out = {}
    for b in d["bodies"]:
        if b["name"] in ("base", "target"):
            i = b["inertial"]
            out[b["name"]] = (i["mass"], np.array(i["com"], float), np.diag(i["inertia"]).astype(float))
    return out


@pytest.fixture(scope="module")
def medium():
    return pc.run("zhang2020_2d_medium")


@pytest.fixture(scope="module")
def spatial():
    return pc.run("zhang2020_3d")


# -- closed forms against their definitions --------------------------------------------------------------
def rot(rng):
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    return q * np.sign(np.linalg.det(q))


def test_closed_forms_match_definitions():
    """H, D, B (momentum) and G, S, Q (force) reproduce m v_c, m c×ċ, I_c ω, m a_c, m c×c̈, Iβ + ω×Iω
    computed directly from a smooth random motion (derivatives by central differences). Checked on the
    numpy oracle (tests/postcapture_numpy_oracle.py), which tests/test_formulas.py checks the engine's rows
    against; the engine's own blocks have the same check in `postcapture/equations.rs`."""
    rng = np.random.default_rng(4)
    r0, v0, a0 = rng.normal(size=(3, 3))
    w0, b0 = rng.normal(size=(2, 3)) * 0.7
    R0 = rot(rng)
    m, b = 37.0, rng.normal(size=3) * 0.3
    Ic = rot(rng) @ np.diag([3.0, 4.0, 5.5]) @ rot(rng).T
    Ic = 0.5 * (Ic + Ic.T)

    def expm(w):
        th = np.linalg.norm(w)
        K = oracle.skew(w[None])[0] / th
        return np.eye(3) + np.sin(th) * K + (1 - np.cos(th)) * K @ K

    def motion(t):
        # ω(t) = w0 + b0 t (inertial); A(t) integrated exactly enough by a fine product of exponentials
        n = 400
        A = R0.copy()
        for k in range(n):
            s = (k + 0.5) * t / n
            A = expm((w0 + b0 * s) * t / n) @ A
        return r0 + v0 * t + 0.5 * a0 * t * t, A, v0 + a0 * t, w0 + b0 * t

    def c_of(t):
        r, A, _, _ = motion(t)
        return r + A @ b

    h, t = 1e-4, 0.3
    r, A, v, w = motion(t)
    p = oracle.PointMotion(r[None], A[None], v[None], w[None], a0[None], b0[None])
    c, cd = c_of(t), (c_of(t + h) - c_of(t - h)) / (2 * h)
    cdd = (c_of(t + h) - 2 * c + c_of(t - h)) / h**2
    mJ = oracle.mJ(m, b)
    np.testing.assert_allclose(oracle.B_block(p)[0] @ np.r_[m, m * b], m * cd, rtol=1e-6)
    np.testing.assert_allclose(oracle.H_block(p)[0] @ mJ, m * np.cross(c, cd), rtol=1e-6)
    Iw = A @ Ic @ A.T
    np.testing.assert_allclose(oracle.D_block(p)[0] @ oracle.inertia_sharp(Ic), Iw @ w, rtol=1e-12)
    np.testing.assert_allclose(oracle.G_block(p)[0] @ np.r_[m, m * b], m * cdd, rtol=1e-5)
    np.testing.assert_allclose(oracle.S_block(p)[0] @ mJ, m * np.cross(c, cdd), rtol=1e-5)
    np.testing.assert_allclose(
        oracle.Q_block(p)[0] @ oracle.inertia_sharp(Ic), Iw @ b0 + np.cross(w, Iw @ w), rtol=1e-12
    )
    # planar reduction (docs/postcapture.md): the bx² and by² columns of H coincide, the bx·by column vanishes
    pz = oracle.PointMotion(
        np.array([[1.0, 2, 0]]),
        np.eye(3)[None],
        np.array([[0.3, -1, 0]]),
        np.array([[0, 0, 0.4]]),
        np.zeros((1, 3)),
        np.zeros((1, 3)),
    )
    H = oracle.H_block(pz)[0]
    assert H[2, 4] == pytest.approx(H[2, 7]) and H[2, 5] == 0


# -- simulation ------------------------------------------------------------------------------------------
def test_simulation_obeys_eq_39_and_the_momentum_balance():
    sc = pc.load_scenario("zhang2020_2d_medium")
    sc.duration = 20.0
    m = ff.models.load(sc.model)
    sim = pc.simulate(sc, m)
    t, yaw = sim["t"], sim["q"][:, 2]
    sig = np.sqrt(0.5) / 2
    wd = np.sqrt(0.25 - sig**2)
    np.testing.assert_allclose(yaw, 0.1 / wd * np.exp(-sig * t) * np.sin(wd * t), atol=1e-10)
    # ∫F (Simpson on the 1 kHz thrust) equals the change of the engine's total momentum (eq. 9), and
    # ∫(M + x_F×F) the change of the angular momentum about the origin (eq. 10; momentum_point: origin; the
    # base point's balance is checked in tests/test_formulas.py)
    sc.measurement["momentum_point"] = "origin"
    meas = pc.measure(m, sim, sc)
    h = np.asarray(ff.momentum(m, meas.q, meas.v))
    np.testing.assert_allclose(meas.impulse_F[:, :2], h[:, :2] - h[0, :2], atol=1e-9 * np.abs(h[:, :2]).max())
    np.testing.assert_allclose(meas.impulse_M[:, 2], h[:, 5] - h[0, 5], atol=1e-9 * np.abs(h[:, 5]).max())
    # the damping thrust is eq. (40): clip(-P, ±10 N) per axis
    F = meas.base_wrench[:, :2]  # yaw is ~0 after 15 s but not at the start: rotate to inertial
    c, s = np.cos(meas.q[:, 2]), np.sin(meas.q[:, 2])
    Fin = np.stack([c * F[:, 0] - s * F[:, 1], s * F[:, 0] + c * F[:, 1]], -1)
    np.testing.assert_allclose(Fin, np.clip(-h[:, :2], -10, 10), atol=1e-9)


# -- identification --------------------------------------------------------------------------------------
@pytest.mark.slow
def test_truth_vector_is_the_model_file(medium):
    tr = yaml_truth("zhang2020_2d_medium")
    (m1, b1, I1), (mn, bn, In) = tr["base"], tr["target"]
    np.testing.assert_allclose(medium.truth, [m1, b1[0], b1[1], I1[2, 2], mn, bn[0], bn[1], In[2, 2]], rtol=1e-12)
    # and Table 2 / the paper's results
    np.testing.assert_allclose(medium.truth, [500, 0.1, -0.1, 83.61, 250, 0.25, 0.1, 10.41])


@pytest.mark.slow
def test_identification_equations_hold_at_the_truth(medium, spatial):
    """Relative residuals at the model file's parameters: round-off plus the RK4 truncation of the
    simulated state (3D: 30 m/s, spinning wrist joints, hence the looser bound). These paper scenarios balance
    angular momentum about the inertial origin, as the paper; the base point's rows (their transport term is a
    quadrature, 2.8e-9 relative in 2D and 4.3e-9 in 3D) are checked in tests/test_formulas.py."""
    for res, tol in ((medium, 1e-9), (spatial, 1e-7)):
        for method, r in res.residuals.items():
            assert r["paper_linear"] <= tol * r["paper_linear_scale"], (res.scenario.name, method, r)
            assert r["paper_angular"] <= tol * r["paper_angular_scale"], (res.scenario.name, method, r)
            assert r["standard"] <= tol * r["standard_scale"], (res.scenario.name, method, r)


@pytest.mark.slow
def test_noise_free_2d_converges_to_the_model_file(medium):
    for method in pc.METHODS:
        for solver in pc.SOLVERS:
            err = medium.rel_error(method, solver)
            assert err.max() < 1e-3, (method, solver, dict(zip(medium.names, err)))  # paper's 0.1 % band
    # every parameter ends inside the 0.1 % band and stays (a transit time exists)
    assert all(s is not None for _, s in medium.transits("momentum", "modified_rls"))
    # paper: the target inertia converges last (Figs. 4-5)
    tt = [s for _, s in medium.transits("momentum", "modified_rls")]
    assert np.argmax(tt) == medium.names.index("In")


@pytest.mark.slow
def test_standard_form_is_at_least_as_accurate(medium, spatial):
    """Issue 3: the linear standard-parameter RLS reaches the same or smaller error than the modified RLS."""
    for res in (medium, spatial):
        for method in pc.METHODS:
            std = res.rel_error(method, "standard_rls")
            mod = res.rel_error(method, "modified_rls")
            assert std.max() <= mod.max() * 1.01, (res.scenario.name, method, std.max(), mod.max())


@pytest.mark.slow
def test_noise_free_3d(spatial):
    names = spatial.names
    tr = yaml_truth("zhang2020_3d")
    assert spatial.truth[names.index("mn")] == tr["target"][0]
    for method in pc.METHODS:
        for solver in pc.SOLVERS:
            err = dict(zip(names, spatial.rel_error(method, solver)))
            for p in ("m1", "b1x", "b1y", "b1z", "mn", "bnx", "bny", "Inxx", "Inyy", "Inzz", "I1xx", "I1yy", "I1zz"):
                assert err[p] < 1e-2, (method, solver, p, err[p])  # the paper's 1 % band
            assert abs(spatial.final(method, solver)[names.index("bnz")]) < 1e-8  # zero true value


@pytest.mark.slow
def test_3d_force_form_sees_the_base_inertia_only_while_the_base_turns(spatial):
    """Why ours reverses Table 6's finding on the base inertia at the paper's prior (docs/postcapture.md): the
    force form's angular rows (eq. 31) carry the base's principal moments through its angular acceleration and
    gyroscopic terms, which vanish once eq. (39) has stopped the base, so their information stops growing within
    ~10 s; the momentum form's rows (eq. 16) are cumulative differences from t0, which keep the initial rate, so
    theirs grows with every sample. x, the slowest mode with the smallest initial rate, gets the least."""
    sc = spatial.scenario
    m = ff.models.load(sc.model)
    meas = pc.measure(m, spatial.simulation, sc, None)
    tgt = pc.target_index(m)
    cols = [0, 3, 5]  # I'1xx, I'1yy, I'1zz in θ = [I'1#, I'n#], I# = [I11, I12, I13, I22, I23, I33] (eq. 21)

    def info(rows, t_end):  # Σ over samples up to t_end of the squared I'1 columns of Φ
        keep = rows.t <= t_end + 1e-9
        return (rows.Phi[keep][:, :, cols] ** 2).sum(axis=(0, 1))

    force = eq.paper_force_rows(m, meas, 0, tgt)
    mom = eq.paper_momentum_rows(m, meas, 0, tgt)
    f10, f100 = info(force, 10.0), info(force, 100.0)
    m10, m100 = info(mom, 10.0), info(mom, 100.0)
    print("force info at 10 / 100 s", f10, f100, "momentum", m10, m100)
    assert (f100 < 1.02 * f10).all(), (f10, f100)  # frozen once the base is still
    assert (m100 > 5 * m10).all(), (m10, m100)  # grows ~linearly with time
    assert f100[0] < f100[1] < f100[2], f100  # x is the least excited axis
    assert (f100 < m100).all()


@pytest.mark.slow
def test_3d_force_form_is_faster_on_the_base_inertia_once_the_prior_is_weak(spatial):
    """Zhang, Yue, Yuan 2020, Table 6: the force form reaches the 1 % band on the base's principal moments in
    1.0-2.3 s, faster than the momentum form. With the paper's prior P0 = 1e6 (its eqs. 34-38 initial
    covariances) ours does not (docs/postcapture.md: I'1xx 12.2 s against 7.7 s): the prior's ridge, weighed
    against the little information the force form gets (previous test), leaves the modified RLS 0.5 % off, most
    of it through D(μ) from the guesses of m and m b'. Pinned here: (1) with a weaker prior the paper's ordering
    holds for each moment and for both solvers, at the paper's speed; (2) at P0 = 1e6 guessing m and m b' right
    removes most of the force form's I'1xx bias."""
    import dataclasses

    sc = spatial.scenario
    m = ff.models.load(sc.model)
    meas = pc.measure(m, spatial.simulation, sc, None)
    names = spatial.names
    for P0 in (1e8, 1e10):
        res = pc.identify(m, meas, dataclasses.replace(sc, P0=P0))
        for solver in pc.SOLVERS:
            tf, tm = res.transits("force", solver), res.transits("momentum", solver)
            for p in ("I1xx", "I1yy", "I1zz"):
                j = names.index(p)
                assert tf[j][1] is not None and tm[j][1] is not None, (P0, solver, p)
                assert tf[j][1] < tm[j][1], (P0, solver, p, tf[j][1], tm[j][1])
                assert tf[j][1] <= 2.5, (P0, solver, p, tf[j][1])  # the paper: 2.3, 1.1, 1.0 s
    j = names.index("I1xx")
    err_paper = spatial.rel_error("force", "modified_rls")[j]
    tr = yaml_truth("zhang2020_3d")  # the guesses of m and b' set to the model file's values
    guess = {k: dict(v) for k, v in sc.guess.items()}
    for key in ("base", "target"):
        guess[key]["mass"], guess[key]["com"] = float(tr[key][0]), tr[key][1].tolist()
    res = pc.identify(m, meas, dataclasses.replace(sc, guess=guess))
    err_mu_right = res.rel_error("force", "modified_rls")[j]
    print(f"force-form I'1xx error at P0 = 1e6: {err_paper:.2e}, with m and m b' guessed right {err_mu_right:.2e}")
    assert err_paper > 3e-3 and err_mu_right < 0.4 * err_paper, (err_paper, err_mu_right)


def test_cli_p0_is_checked():
    for bad in ("0", "-1", "nan", "inf"):
        r = CliRunner().invoke(main, ["identify", "postcapture", "zhang2020_2d_small", "--p0", bad])
        assert r.exit_code != 0 and "--p0" in r.output and "positive finite" in r.output, (bad, r.output)


@pytest.mark.slow
def test_mass_and_com_do_not_depend_on_the_solver(medium):
    """Both solvers see the same physics: m and b' agree to the accuracy of the estimates."""
    a = medium.final("momentum", "modified_rls")
    b = medium.final("force", "standard_rls")
    np.testing.assert_allclose(a, b, rtol=1e-3)


@pytest.mark.slow
def test_velocity_sweep_reproduces_the_papers_trend():
    """Figs. 6-9: momentum-based I'_n error grows with the initial base velocity, force-based does not."""
    sc = pc.load_scenario("zhang2020_2d_sweep")
    sw = pc.sweep(sc, velocities=[[0, 10], [200, 200]])
    j = sw["names"].index("In")
    mom = np.asarray(sw["errors"]["momentum/modified_rls"])[:, j]
    frc = np.asarray(sw["errors"]["force/modified_rls"])[:, j]
    assert mom[1] > 3 * mom[0]
    assert abs(frc[1] - frc[0]) < 0.3 * frc[0]
    # the scenario balances angular momentum about the inertial origin, as the paper; about the moving base point
    # the trend is gone: the lever arm r_B × P that grows with the velocity was its cause
    sc.measurement["momentum_point"] = "base"
    sw = pc.sweep(sc, velocities=[[0, 10], [200, 200]])
    base = np.asarray(sw["errors"]["momentum/modified_rls"])[:, j]
    print("momentum-based I'_n error at [0, 10] and [200, 200]: origin", mom, "base point", base)
    assert base[1] < mom[1] / 3 and base[1] < 2 * base[0], (base, mom)


@pytest.mark.slow
def test_noise_degrades_gracefully():
    sc = pc.load_scenario("zhang2020_2d_medium")
    sc.noise = dict(pc.DEFAULT_NOISE)
    res = pc.run(sc, seed=1)
    for method in pc.METHODS:
        err = dict(zip(res.names, res.rel_error(method, "standard_rls")))
        assert np.isfinite(list(err.values())).all()
        assert err["m1"] < 1e-2 and err["mn"] < 1e-2, (method, err)


# -- command line ----------------------------------------------------------------------------------------
@pytest.mark.slow
def test_cli_identify_postcapture(tmp_path):
    r = CliRunner().invoke(main, ["identify", "postcapture", "zhang2020_2d_small", "--out", str(tmp_path)])
    assert r.exit_code == 0, r.output
    # both forms, with the paper's columns and ours labelled apart (PAPER / OURS)
    assert "momentum-based" in r.output and "force-based" in r.output and "PAPER:" in r.output and "OURS" in r.output
    data = json.loads((tmp_path / "results.json").read_text())
    entry = data["methods"]["momentum"]["modified_rls"]["In"]
    assert entry["truth"] == pytest.approx(5.2)
    assert abs(entry["estimate"] - 5.2) < 5.2e-3 and entry["transit_time"] is not None
    assert entry["paper"] == [5.2, 13.4]  # Table 4
    assert (tmp_path / "momentum_estimates.png").exists() and (tmp_path / "force_estimates.png").exists()
    r = CliRunner().invoke(main, ["scenarios"])
    assert r.exit_code == 0 and "zhang2020_3d" in r.output


# -- bad input -------------------------------------------------------------------------------------------
def test_rls_bad_samples_raise_clear_errors():
    est = _core.RecursiveLS(np.zeros(2), np.ones(2))
    est.update(0.0, np.array([[1.0, 0.0]]), np.array([1.0]))
    with pytest.raises(ff.InputError, match="sample 1.*phi"):
        est.update(0.1, np.array([[np.nan, 0.0]]), np.array([1.0]))
    with pytest.raises(ff.InputError, match="backwards"):
        est.update(-1.0, np.array([[1.0, 0.0]]), np.array([1.0]))
    with pytest.raises(ff.InputError, match="shape"):
        est.update(0.2, np.array([[1.0, 0.0, 3.0]]), np.array([1.0]))
    assert np.isfinite(est.estimate).all()
    with pytest.raises(ff.InputError, match="positive definite"):
        _core.RecursiveLS(np.zeros(2), np.array([[1.0, 2.0], [2.0, 1.0]]))
    with pytest.raises(ff.InputError, match="forgetting"):
        _core.RecursiveLS(np.zeros(2), np.ones(2), 1.5)
    # a covariance that overflows is reported (never NaN); the estimator then refuses further samples
    big = _core.RecursiveLS(np.zeros(1), np.array([1e308]))
    with pytest.raises(ff.NumericalError, match="positive definiteness"):
        big.update(0.0, np.array([[1e10]]), np.array([1.0]))
    with pytest.raises(ff.NumericalError, match="failed earlier"):
        big.update(1.0, np.array([[1.0]]), np.array([1.0]))


def test_online_wrappers_accept_lists_and_name_bad_arguments():
    est = ff.online.RecursiveLS([0, 0], [1, 1], forgetting=1.0)
    est.update(0, [[1, 2]], [3])
    # one sample with p0 = I: θ = φᵀ y / (1 + |φ|²) = [1, 2]·3/6
    np.testing.assert_allclose(est.estimate, [0.5, 1.0], rtol=1e-15)
    with pytest.raises(ff.InputError, match="phi"):
        est.update(1, [["a", 2]], [3])
    m = ff.online.ModifiedRLS("planar", [600, 0, 0, 100, 10, 10], [1e6] * 6, [100, 10], [1e6] * 2)
    mu, th = m.update(0.1, np.ones((2, 6)), [1, 1], [[1, 1]], [1], np.zeros((1, 8)))
    assert np.isfinite(mu).all() and np.isfinite(th).all() and m.samples == 1


def test_modified_rls_bad_samples_raise_clear_errors():
    est = _core.ModifiedRLS(
        "planar", np.array([600.0, 0, 0, 100, 10, 10]), np.full(6, 1e6), np.array([100.0, 10.0]), np.full(2, 1e6)
    )
    t = np.array([0.1, 0.2])
    A, b = np.ones((2, 2, 6)), np.ones((2, 2))
    Phi, y, Psi = np.ones((2, 1, 2)), np.ones((2, 1)), np.zeros((2, 1, 8))
    Psi[1, 0, 3] = np.nan
    with pytest.raises(ff.InputError, match=r"sample 1: psi\[3\]"):
        est.run(t, A, b, Phi, y, Psi)
    with pytest.raises(ff.InputError, match="backwards"):
        est.run(np.array([0.05]), A[:1], b[:1], Phi[:1], y[:1], np.zeros((1, 1, 8)))
    with pytest.raises(ff.InputError, match="coupling"):
        _core.ModifiedRLS("cubic", np.zeros(6), np.ones(6), np.ones(2), np.ones(2))
    with pytest.raises(ff.InputError, match="mu0"):
        _core.ModifiedRLS("planar", np.zeros(6), np.ones(6), np.ones(2), np.ones(2))  # zero mass guess


def test_target_must_be_welded_to_the_end_effector():
    text = ff.models.source("zhang2020_2d_medium")
    loose = ff.Model.from_yaml_string(
        text.replace("joint: {name: grasp, type: fixed}", "joint: {name: grasp, type: revolute, axis: [0, 0, 1]}")
    )
    with pytest.raises(ff.InputError, match="welded"):
        pc.target_index(loose)
    with pytest.raises(ff.InputError, match="not found"):
        pc.load_scenario("no_such_scenario")


def test_simulation_bad_input():
    sc = pc.load_scenario("zhang2020_2d_medium")
    sc.excitation["amp"] = [0.02]
    with pytest.raises(ff.InputError, match="excitation_amp"):
        pc.simulate(sc)
    sc = pc.load_scenario("zhang2020_2d_medium")
    sc.v0[0] = np.nan
    with pytest.raises(ff.InputError, match="v0"):
        pc.simulate(sc)


@pytest.mark.slow
def test_projection_and_forgetting_options():
    """The projection leaves consistent (here: the true) parameters alone and repairs a non-physical set;
    a forgetting factor close to 1 still converges on noise-free data."""
    truth = np.array(ff.models.load("zhang2020_2d_medium").parameters())[4]
    np.testing.assert_allclose(eq.project_consistent(truth), truth, rtol=1e-9)
    bad = truth.copy()
    bad[4] = -1.0  # Ixx < 0: violates positivity
    fixed = eq.project_consistent(bad)
    m, b, Ic = eq.from_standard(fixed[None])
    assert m[0] > 0 and np.linalg.eigvalsh(Ic[0]).min() >= -1e-9
    sc = pc.load_scenario("zhang2020_2d_medium")
    sc.forgetting, sc.project = 0.9999, True
    res = pc.run(sc)
    assert res.rel_error("momentum", "standard_rls").max() < 1e-3


def test_measurement_options():
    """Central differences of the sampled velocities approximate the exact accelerations (to the O(h²) error of a
    0.1 s step) and drop the two end samples; an unknown mode is an InputError."""
    sc = pc.load_scenario("zhang2020_2d_medium")
    sc.duration = 10.0
    m = ff.models.load(sc.model)
    sim = pc.simulate(sc, m)
    exact = pc.measure(m, sim, sc)
    sc.measurement = {"accelerations": "central_difference", "impulses": "trapezoid"}
    fd = pc.measure(m, sim, sc)
    assert len(fd.t) == len(exact.t) - 2 and fd.t[0] == exact.t[1]
    np.testing.assert_allclose(fd.ddq, exact.ddq[1:-1], atol=2e-3 * np.abs(exact.ddq).max())
    np.testing.assert_allclose(fd.impulse_F, exact.impulse_F[1:-1], rtol=1e-2, atol=1e-3)
    sc.measurement = {"accelerations": "spline"}
    with pytest.raises(ff.InputError, match="accelerations"):
        pc.measure(m, sim, sc)


@pytest.mark.slow
def test_central_differences_in_the_inertial_frame_keep_the_force_form_accurate():
    """Zhang 2020 medium target with measured accelerations (10 Hz central differences) and trapezoid impulses:
    differencing the base velocity in the inertial frame keeps the force-based I'1, I'n within 0.5 % of the truth
    (differencing the rotating base-frame components, which drops ω×v, gave −2.4 % and −5.7 %)."""
    sc = pc.load_scenario("zhang2020_2d_medium")
    sc.measurement = {"accelerations": "central_difference", "impulses": "trapezoid"}
    res = pc.run(sc)
    rel = dict(zip(res.names, res.final("force", "modified_rls") / res.truth - 1))
    assert abs(rel["I1"]) < 5e-3 and abs(rel["In"]) < 5e-3, rel


@pytest.mark.slow
def test_table_and_figures_keep_paper_and_ours_apart(tmp_path):
    """Column headers say PAPER / OURS; 'not in the paper' (no printed value) differs from 'not converged' (ours
    not within tolerance at the end); the history figures are written with the tolerance band."""
    sc = pc.load_scenario("zhang2020_2d_medium")
    sc.duration = 4.0  # too short to converge: every 'ours' cell reads 'not converged'
    res = pc.run(sc)
    text = res.table()
    assert "PAPER: value (transit)" in text and "OURS " in text
    assert "not converged" in text
    assert "'not in the paper'" in text and "'not converged'" in text  # the legend explains both
    from freefloat.postcapture.plots import plot_histories

    paths = plot_histories(res, tmp_path)
    assert paths and all(p.exists() for p in paths)

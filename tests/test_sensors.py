"""Sensor models and `measure` (freefloat.sensors): each error model against its closed form or an independent
implementation — Allan deviation of a gyro's still record (IEEE Std 952 terms), the uniform quantisation error of
encoders and tachometers, the star tracker's error covariance, latency, the force/torque sensor against
Pinocchio's joint forces — plus reproducibility, bad input, the Naveen et al. preset against `add_noise`, and the
command line from simulation to identification."""

import json

import numpy as np
import pytest

import freefloat as ff
from freefloat import models
from freefloat import sensors as sn
from freefloat._core import InputError
from freefloat.io.telemetry import Telemetry, add_noise, integrate_poses


def still_run(model, n, dt, joints=None, rates=None):
    """A run of n evenly spaced samples: base at rest at the origin, joints as given (T, nj) or zero."""
    t = np.arange(n) * dt
    q = np.zeros((n, model.nq))
    q[:, 6] = 1.0
    v = np.zeros((n, model.nv))
    if joints is not None:
        q[:, 7:] = joints
    if rates is not None:
        v[:, 6:] = rates
    return {"t": t, "q": q, "v": v}


def overlapping_allan(y, dt, ms):
    """Overlapping Allan deviation of a rate record y at cluster sizes ms (IEEE Std 952-1997, Annex C), from the
    integrated angle θ: σ²(τ) = <(θ_{k+2m} − 2θ_{k+m} + θ_k)²> / (2 τ²), τ = m dt."""
    theta = np.concatenate([[0.0], np.cumsum(y) * dt])
    out = []
    for m in ms:
        d = theta[2 * m :] - 2 * theta[m:-m] + theta[: -2 * m]
        out.append(np.sqrt(np.mean(d * d) / (2 * (m * dt) ** 2)))
    return np.array(out)


# ---------------------------------------------------------------------------------------------------------------
@pytest.mark.slow
def test_gyro_allan_deviation_recovers_angle_random_walk_and_bias_instability():
    m = models.load("zhang2020_3d")
    rate, hours = 50.0, 2.0
    n = int(hours * 3600 * rate)
    N, B, Tc = 2e-5, 1e-4, 10.0
    run = still_run(m, n, 1.0 / rate)
    g = sn.Gyro(rate=rate, noise_density=N, bias_instability=B, bias_correlation_time=Tc)
    y = sn.measure(m, run, [g, sn.BaseVelocity(), sn.Tachometer()], seed=3).streams["gyro"].values
    assert y.shape == (n, 3)
    # slope −1/2 region: σ(τ) = N/√τ at τ = 0.02 … 0.1 s (the Gauss-Markov bias adds < 1 % there)
    ms = np.array([1, 2, 5])
    for a in range(3):
        ad = overlapping_allan(y[:, a], 1 / rate, ms)
        n_est = ad * np.sqrt(ms / rate)
        assert np.allclose(n_est, N, rtol=0.03), f"axis {a}: N estimates {n_est} vs {N}"
        slope = np.polyfit(np.log(ms), np.log(ad), 1)[0]
        assert abs(slope + 0.5) < 0.03, f"axis {a}: slope {slope}"
    # flat region: the peak of σ(τ) (at τ ≈ 1.89 Tc for the Gauss-Markov stand-in) is 0.664 B (IEEE Std 952)
    taus = np.geomspace(5.0, 80.0, 25)
    flats = []
    for a in range(3):
        ad = overlapping_allan(y[:, a], 1 / rate, np.unique(np.rint(taus * rate).astype(int)))
        flats.append(ad.max())
    flat = np.mean(flats)
    assert flat == pytest.approx(np.sqrt(2 * np.log(2) / np.pi) * B, rel=0.10), f"flat region {flats}"


def test_gyro_constant_bias_and_rate_random_walk():
    m = models.load("zhang2020_3d")
    rate, n = 10.0, 200_000
    run = still_run(m, n, 0.1)
    K = 1e-6
    y = (
        sn.measure(m, run, [sn.Gyro(rate=rate, bias=[1e-3, -2e-3, 0.0], rate_random_walk=K)], seed=1)
        .streams["gyro"]
        .values
    )
    # rate random walk: increments over τ have variance K² τ (the walk itself, bias removed)
    for a, b in enumerate([1e-3, -2e-3, 0.0]):
        assert y[0, a] == pytest.approx(b, abs=1e-9)
        lag = 100
        d = y[lag:, a] - y[:-lag, a]
        assert np.var(d) == pytest.approx(K**2 * lag / rate, rel=0.15)


def test_encoder_quantisation_error_is_uniform_with_variance_delta_squared_over_12():
    m = models.load("naveen_dual_arm")
    nj = m.nv - 6
    n = 50_000
    t = np.arange(n) * 1e-3
    joints = 0.3 * np.sin(np.outer(t, 0.7 + np.arange(nj))) + np.arange(nj)
    run = still_run(m, n, 1e-3, joints=joints)
    cpr = 4096
    s = sn.measure(m, run, [sn.Encoder(counts_per_rev=cpr)], seed=0).streams["encoder"]
    assert s.columns == [f"q.{j}" for j in m.joint_names[1:]]
    e = (s.values - joints).ravel()
    d = 2 * np.pi / cpr
    assert np.abs(e).max() <= d / 2 * (1 + 1e-9)
    assert np.var(e) == pytest.approx(d * d / 12, rel=0.02)
    hist, _ = np.histogram(e, bins=10, range=(-d / 2, d / 2))
    assert np.all(np.abs(hist / len(e) - 0.1) < 0.01), hist / len(e)
    # every value is a whole number of counts
    assert np.allclose(s.values / d, np.rint(s.values / d), atol=1e-6)


def test_tachometer_quantisation_and_noise():
    m = models.load("naveen_dual_arm")
    nj = m.nv - 6
    n = 40_000
    t = np.arange(n) * 1e-3
    rates = 5.0 * np.sin(np.outer(t, 0.3 + np.arange(nj)))
    run = still_run(m, n, 1e-3, rates=rates)
    res = 0.01
    wheels = m.joints_tagged("wheel")
    s = sn.measure(m, run, [sn.Tachometer(joints=wheels, resolution=res)], seed=0).streams["tachometer"]
    cols = [m.joint_names.index(w) - 1 for w in wheels]
    e = (s.values - rates[:, cols]).ravel()
    assert np.abs(e).max() <= res / 2 * (1 + 1e-9)
    assert np.var(e) == pytest.approx(res * res / 12, rel=0.03)
    s = sn.measure(m, run, [sn.Tachometer(noise=0.05, bias=0.2)], seed=4).streams["tachometer"]
    e = s.values - rates
    assert np.mean(e) == pytest.approx(0.2, abs=3 * 0.05 / np.sqrt(e.size))
    assert np.std(e) == pytest.approx(0.05, rel=0.02)
    assert np.allclose(s.white_sigma, 0.05)


def _quat_mul(a, b):
    ax, ay, az, aw = np.moveaxis(a, -1, 0)
    bx, by, bz, bw = np.moveaxis(b, -1, 0)
    return np.stack(
        [
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
            aw * bw - ax * bx - ay * by - az * bz,
        ],
        -1,
    )


def test_star_tracker_error_covariance_as_configured():
    m = models.load("zhang2020_3d")
    n = 60_000
    rng = np.random.default_rng(5)
    run = still_run(m, n, 0.01)
    qs = rng.normal(size=(n, 4))
    run["q"][:, 3:7] = qs / np.linalg.norm(qs, axis=1, keepdims=True)  # any attitudes
    sigma = [2e-5, 3e-5, 2e-4]  # cross-boresight, cross-boresight, about the boresight
    s = sn.measure(m, run, [sn.StarTracker(sigma=sigma)], seed=2).streams["star_tracker"]
    qt = run["q"][:, 3:7]
    conj = qt * np.array([-1, -1, -1, 1])
    err = _quat_mul(conj, s.values)
    err *= np.sign(err[:, 3:4])
    vec = err[:, :3]
    s_ = np.linalg.norm(vec, axis=1, keepdims=True)
    rotvec = 2 * np.arctan2(s_, err[:, 3:4]) * vec / s_
    cov = np.cov(rotvec.T)
    assert np.allclose(np.sqrt(np.diag(cov)), sigma, rtol=0.02)
    corr = cov / np.sqrt(np.outer(np.diag(cov), np.diag(cov)))
    assert np.all(np.abs(corr[~np.eye(3, dtype=bool)]) < 0.02)
    assert np.allclose(np.linalg.norm(s.values, axis=1), 1.0, atol=1e-12)


def test_latency_shifts_by_exactly_the_configured_delay():
    m = models.load("naveen_dual_arm")
    n, dt = 2001, 1e-3
    t = np.arange(n) * dt
    rates = np.sin(np.outer(t, 1.0 + np.arange(m.nv - 6)))
    run = still_run(m, n, dt, rates=rates)
    late = sn.measure(m, run, [sn.Tachometer(rate=100.0, latency=0.025)], seed=0).streams["tachometer"]
    on_time = sn.measure(m, run, [sn.Tachometer(rate=100.0)], seed=0).streams["tachometer"]
    k = np.arange(len(late.t)) * 10  # sample j measures the state at index 10 j ...
    assert np.array_equal(late.values, rates[k])
    assert np.allclose(late.t - t[k], 0.025, rtol=0, atol=1e-12)  # ... and is stamped 25 ms later
    assert np.array_equal(late.values, on_time.values[: len(late.t)])
    assert late.t[-1] <= t[-1] + 1e-12 and len(late.t) == len(on_time.t) - 3


def test_force_torque_sensor_matches_pinocchio_joint_force():
    pin = pytest.importorskip("pinocchio")
    import random_trees as rt

    compared = 0
    for seed in (1, 2, 3, 5, 8):
        d = rt.tree_from_seed(seed)
        if d.bodies[0].joint_type != "free":
            continue
        m = ff.Model.from_yaml_string(d.to_yaml())
        p = rt.build_pinocchio(d)
        joints = [i for i in range(1, m.nbodies) if m.joint_types[i] in ("revolute", "prismatic")]
        if not joints:
            continue
        rng = np.random.default_rng(seed)
        q = np.array([d.random_q(rng) for _ in range(3)])
        v = np.array([d.random_v(rng) for _ in range(3)])
        a = rng.normal(size=(3, m.nv))
        run = {"t": np.arange(3) * 0.01, "q": q, "v": v, "ddq": a}
        fts = [sn.ForceTorque(joint=m.joint_names[i], name=f"ft{i}") for i in joints]
        meas = sn.measure(m, run, fts, seed=0)
        for i in joints:
            got = meas.streams[f"ft{i}"].values
            assert meas.streams[f"ft{i}"].columns[0] == f"ft.ft{i}.fx"
            for k in range(3):
                pin.rnea(p.model, p.data, p.q_to_pin(q[k]), p.v_to_pin(v[k]), p.v_to_pin(a[k]))
                f = p.data.f[p.joint_of_body[i]]
                want = np.concatenate([f.linear, f.angular])
                rt.assert_close(got[k], want, rtol=1e-9, atol=1e-9, what=f"tree {seed} joint {m.joint_names[i]}")
                compared += 1
    assert compared >= 10, compared


def test_same_seed_reproduces_and_sensors_have_independent_streams():
    m = models.load("naveen_dual_arm")
    run = still_run(m, 1000, 1e-3)
    a = sn.measure(m, run, sn.naveen(), seed=11)
    b = sn.measure(m, run, sn.naveen(), seed=11)
    c = sn.measure(m, run, sn.naveen(), seed=12)
    for k in a.streams:
        assert np.array_equal(a.streams[k].values, b.streams[k].values)
        assert not np.array_equal(a.streams[k].values, c.streams[k].values)
    # adding a sensor leaves the others' errors unchanged
    more = sn.naveen()
    more.sensors.append(sn.StarTracker(sigma=1e-4))
    d = sn.measure(m, run, more, seed=11)
    assert np.array_equal(d.streams["gyro"].values, a.streams["gyro"].values)


@pytest.mark.parametrize(
    "sensor, key",
    [
        ({"type": "gyro", "noise_density": -1e-4}, "sensors.gyro.noise_density"),
        ({"type": "gyro", "rate": 0}, "sensors.gyro.rate"),
        ({"type": "gyro", "rate": -10}, "sensors.gyro.rate"),
        ({"type": "gyro", "rate": 2000}, "sensors.gyro.rate"),  # above the run's 1 kHz
        ({"type": "gyro", "rate": 300}, "sensors.gyro.rate"),  # does not divide 1 kHz
        ({"type": "gyro", "latency": -0.1}, "sensors.gyro.latency"),
        ({"type": "gyro", "latency": 0.0005}, "sensors.gyro.latency"),
        ({"type": "gyro", "noise_density": 1e-4, "noise_per_sample": 1e-3}, "sensors.gyro.noise_per_sample"),
        ({"type": "gyro", "nosie_density": 1e-4}, "sensors.gyro.nosie_density"),
        ({"type": "star_tracker", "sigma": [1e-5, -1e-5, 1e-4]}, "sensors.star_tracker.sigma"),
        ({"type": "encoder", "joints": ["no_such_joint"]}, "sensors.encoder.joints"),
        ({"type": "encoder", "counts_per_rev": 0}, "sensors.encoder.counts_per_rev"),
        ({"type": "tachometer", "noise": -1}, "sensors.tachometer.noise"),
        ({"type": "force_torque", "joint": "no_such_joint"}, "sensors.force_torque.joint"),
        ({"type": "force_torque"}, "sensors.force_torque.joint"),
        ({"type": "lidar"}, "sensors[0].type"),
    ],
)
def test_bad_sensor_input_names_the_key(sensor, key):
    m = models.load("naveen_dual_arm")
    run = still_run(m, 100, 1e-3)
    run["ddq"] = np.zeros((100, m.nv))
    with pytest.raises(InputError, match=key.replace(".", r"\.").replace("[", r"\[").replace("]", r"\]")):
        sn.measure(m, run, [sensor], seed=0)


def test_uneven_run_and_missing_velocity_sensor_are_errors():
    m = models.load("naveen_dual_arm")
    run = still_run(m, 100, 1e-3)
    run["t"] = run["t"] ** 1.01
    with pytest.raises(InputError, match="evenly spaced"):
        sn.measure(m, run, sn.naveen())
    run = still_run(m, 100, 1e-3)
    meas = sn.measure(m, run, [sn.Gyro(), sn.Tachometer()])
    assert meas.telemetry is None and len(meas.streams["gyro"].t) == 100
    with pytest.raises(InputError, match=r"no sensor measures v\.base\.vx"):
        meas.require_telemetry()
    with pytest.raises(InputError, match="telemetry.poses"):
        sn.SensorSet([], poses="guess")


def test_slower_sensors_are_held_and_measured_poses_come_from_the_sensors():
    m = models.load("naveen_dual_arm")
    n = 1001
    t = np.arange(n) * 1e-3
    rates = np.sin(np.outer(t, 1.0 + np.arange(m.nv - 6)))
    joints = np.cumsum(rates, axis=0) * 1e-3
    run = still_run(m, n, 1e-3, joints=joints, rates=rates)
    sset = sn.SensorSet(
        [
            sn.Gyro(rate=100),
            sn.BaseVelocity(rate=100),
            sn.Tachometer(rate=50),
            sn.StarTracker(rate=10),
            sn.BasePosition(rate=10),
            sn.Encoder(rate=100),
        ],
        poses="measured",
    )
    tel = sn.measure(m, run, sset).telemetry
    assert np.allclose(np.diff(tel.t), 0.01)
    k = np.rint(tel.t / 1e-3).astype(int)
    held = (k // 20) * 20  # the tachometers report every 20 ms: the latest report is held
    assert np.array_equal(tel.v[:, 6:], rates[held])
    assert np.array_equal(tel.q[:, 7:], joints[k])
    assert tel.rate_noise is None


# ---------------------------------------------------------------------------------------------------------------
@pytest.mark.slow
def test_naveen_preset_is_the_same_measurement_model_as_add_noise():
    """The preset and `add_noise` draw from different generators (ChaCha8 in the engine, numpy's PCG64), so the
    draws differ; the model is the same: zero-mean white noise of the paper's σ on each rate group, poses rebuilt
    by the same integration, the same declared rate noise, and the same identification error statistics."""
    from freefloat.identification import identify as idf

    m = models.load("naveen_dual_arm")
    clean, _ = idf.excitation_data(m, n_intervals=8, noise=False)
    groups = {"lin": slice(0, 3), "ang": slice(3, 6), "joint": slice(6, None)}
    sig = {"lin": ff.constants.SIGMA_LIN, "ang": ff.constants.SIGMA_ANG, "joint": ff.constants.SIGMA_JOINT}
    ours = sn.measure(m, clean, "naveen", seed=0).telemetry
    theirs = add_noise(clean, m, np.random.default_rng(0))
    assert np.array_equal(ours.t, clean.t) and np.array_equal(theirs.t, clean.t)
    for name, tel in (("preset", ours), ("add_noise", theirs)):
        e = tel.v - clean.v
        for g, sl in groups.items():
            x = e[:, sl].ravel()
            assert np.std(x) == pytest.approx(sig[g], rel=0.03), f"{name} {g}"
            assert abs(np.mean(x)) < 4 * sig[g] / np.sqrt(x.size), f"{name} {g} mean"
            lag1 = np.corrcoef(e[1:, sl].ravel(), e[:-1, sl].ravel())[0, 1]
            assert abs(lag1) < 0.02, f"{name} {g} is not white"
        assert np.allclose(tel.q, integrate_poses(m, tel.t, tel.v, clean.q[0]), rtol=0, atol=1e-12)
    assert np.allclose(idf._rate_sigmas(m, ours.rate_noise), idf._rate_sigmas(m, theirs.rate_noise))
    import warnings

    errs = {"preset": [], "add_noise": []}
    for seed in range(3):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            for name, tel in (
                ("preset", sn.measure(m, clean, "naveen", seed=seed).telemetry),
                ("add_noise", add_noise(clean, m, np.random.default_rng(seed))),
            ):
                errs[name].append(
                    idf.identify_minimal(m, tel, rate_noise="none", check="off").errors(m)["median_rel_error_pct"]
                )
    a, b = np.median(errs["preset"]), np.median(errs["add_noise"])
    assert 0.33 < a / b < 3.0, errs


# ---------------------------------------------------------------------------------------------------------------
@pytest.mark.slow
def test_cli_simulate_measure_identify(tmp_path):
    from click.testing import CliRunner

    from freefloat.cli import main

    r = CliRunner()
    run_dir, tel_dir = tmp_path / "run", tmp_path / "tel"
    res = r.invoke(main, ["simulate", "naveen_dual_arm", "--t-final", "2", "--dt", "1e-3", "--out", str(run_dir)])
    assert res.exit_code == 0, res.output
    sensors_file = tmp_path / "sensors.yaml"
    sensors_file.write_text(
        "sensors:\n"
        "  - {type: gyro, rate: 100, noise_density: 1.0e-5}\n"
        "  - {type: base_velocity, rate: 100, noise: 1.0e-5}\n"
        "  - {type: tachometer, rate: 100, noise: 1.0e-5}\n"
        "  - {type: encoder, rate: 100, counts_per_rev: 65536}\n"
        "  - {type: force_torque, name: wrist, rate: 50, joint: "
        + models.load("naveen_dual_arm").joint_names[6]
        + ", force_noise: 0.01}\n"
    )
    res = r.invoke(
        main, ["measure", str(run_dir), "--sensors", str(sensors_file), "--out", str(tel_dir), "--seed", "3"]
    )
    assert res.exit_code == 0, res.output
    assert (tel_dir / "telemetry.csv").exists() and (tel_dir / "sensor_wrist.csv").exists()
    info = json.loads((tel_dir / "results.json").read_text())
    assert info["streams"]["gyro"]["samples"] == 201 and info["streams"]["wrist"]["samples"] == 101
    m = models.load("naveen_dual_arm")
    tel = Telemetry.from_file(tel_dir / "telemetry.csv", m)
    assert len(tel.t) == 201 and tel.rate_noise is not None and len(tel.rate_noise) == m.nv
    res = r.invoke(main, ["identify", "minimal", "naveen_dual_arm", "--data", str(tel_dir / "telemetry.csv")])
    assert res.exit_code == 0, res.output
    res = r.invoke(main, ["measure", "--help"])
    assert res.exit_code == 0 and "--sensors" in res.output
    bad = tmp_path / "bad.yaml"
    bad.write_text("sensors:\n  - {type: gyro, rate: 3000}\n")
    res = r.invoke(main, ["measure", str(run_dir), "--sensors", str(bad), "--out", str(tel_dir)])
    assert res.exit_code != 0 and "sensors.gyro.rate" in res.output

"""Identification on `measure`d telemetry degrades with the sensors' noise level as the papers predict.

* Naveen, Shah, Misra (minimal parameters from momentum): the least-squares error grows with the rate noise
  (errors-in-variables: noisy rates on both sides of the momentum equation), and the errors-in-variables bias
  removal, fed the white-noise levels the sensors declare, lowers it at every level (the sensor set is a gyro
  with angle random walk, a base velocity sensor and tachometers at 1 kHz, 0.5 to 2 times the paper's levels).
* Zhang, Yue, Yuan 2020 (post-capture, momentum form, both RLS solvers): the final estimate's error grows with
  the noise on the measured base and joint rates (the paper has no noise; the trend is what its equations imply).
"""

import dataclasses
import warnings

import numpy as np
import pytest

from freefloat import models
from freefloat import sensors as sn
from freefloat.constants import SIGMA_ANG, SIGMA_JOINT, SIGMA_LIN

SEEDS = (0, 1, 2)


def _rate_sensors(scale, rate):
    """A gyro (angle random walk), a base velocity sensor and joint tachometers at `scale` × the paper's levels."""
    return sn.SensorSet(
        [
            sn.Gyro(rate=rate, noise_density=scale * SIGMA_ANG / np.sqrt(rate)),
            sn.BaseVelocity(rate=rate, noise=scale * SIGMA_LIN),
            sn.Tachometer(rate=rate, noise=scale * SIGMA_JOINT),
        ]
    )


@pytest.mark.slow
def test_naveen_minimal_parameters_degrade_with_noise_and_eiv_removal_helps():
    from freefloat.identification import identify as idf

    m = models.load("naveen_dual_arm")
    clean, _ = idf.excitation_data(m, n_intervals=16, noise=False)
    # up to 2x the paper's noise: beyond ~4x the bias removal refuses (a noise-dominated direction, by design)
    scales = (0.5, 1.0, 2.0)
    plain, eiv = [], []
    for s in scales:
        p_, e_ = [], []
        for seed in SEEDS:
            tel = sn.measure(m, clean, _rate_sensors(s, 1000.0), seed=seed).telemetry
            assert tel.rate_noise is not None
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                p_.append(
                    idf.identify_minimal(m, tel, rate_noise="none", check="off").errors(m)["median_rel_error_pct"]
                )
                e_.append(
                    idf.identify_minimal(m, tel, rate_noise="data", check="off").errors(m)["median_rel_error_pct"]
                )
        plain.append(np.median(p_))
        eiv.append(np.median(e_))
    print("noise scale", scales, "plain LS median error %", plain, "with EIV removal", eiv)
    assert plain[0] < plain[1] < plain[2], plain
    assert eiv[0] < eiv[1] < eiv[2], eiv
    assert all(e < p / 3 for e, p in zip(eiv, plain)), (eiv, plain)


@pytest.mark.slow
def test_zhang_postcapture_estimates_degrade_with_rate_noise():
    from freefloat import postcapture as pc

    sc = pc.load_scenario("zhang2020_3d")
    sc = dataclasses.replace(sc, duration=30.0) if dataclasses.is_dataclass(sc) else sc
    m = models.load(sc.model)
    sim = pc.simulate(sc, m)
    clean = pc.measure(m, sim, sc, None)
    rate = 1.0 / sc.sample_period
    levels = (0.0, 1e-4, 1e-3, 1e-2)
    errs = {"modified_rls": [], "standard_rls": []}
    for lvl in levels:
        per = {k: [] for k in errs}
        for seed in SEEDS if lvl > 0 else SEEDS[:1]:
            sset = sn.SensorSet(
                [
                    sn.Gyro(rate=rate, noise_per_sample=lvl),
                    sn.BaseVelocity(rate=rate, noise=lvl),
                    sn.Tachometer(rate=rate, noise=lvl),
                ]
            )
            tel = sn.measure(m, sim, sset, seed=seed).telemetry
            assert np.allclose(tel.t, clean.t)
            meas = dataclasses.replace(clean, v=tel.v)
            res = pc.pipeline.identify(m, meas, sc, methods=("momentum",))
            for solver in per:
                per[solver].append(float(np.median(res.rel_error("momentum", solver))))
        for solver in errs:
            errs[solver].append(np.median(per[solver]))
    print("rate noise", levels, "median final relative error", errs)
    for solver, e in errs.items():
        assert all(a < b for a, b in zip(e[1:], e[2:])), (solver, e)
        assert e[0] < e[-1], (solver, e)


def test_zhang_momentum_form_about_the_base_point_survives_an_integrated_attitude(zhang3d_measured_60s):
    """Issue 34: the 3D post-capture system drifts ~3.7 km in 100 s; about the inertial origin its angular momentum is
    dominated by r_B × P, and the gyro-integrated attitude bends the integrated base position by centimetres while the
    impulses see the true lever arm, so the momentum form's estimate is tens of percent off at a fibre-optic gyro's
    noise density. About the moving base point (the default) the position drops out. Measured here on 60 s of the
    built-in `zhang2020_3d_thrusters` telemetry (100 Hz gyro, base velocity, tachometers; poses integrated) given to
    the ideal-jet `zhang2020_3d` run (where the momentum form holds): RMS relative error of m1, mn and the target's
    principal moments, standard RLS."""
    err = {point: zhang3d_measured_60s("momentum", {"momentum_point": point}) for point in ("origin", "base")}
    print("momentum form, gyro N = 1e-6, RMS relative error:", err)
    assert err["origin"] > 0.1, err  # the failure this fixes (0.27 at 100 s in docs/postcapture.md)
    assert err["base"] < 0.03, err  # the floor left is the 100 Hz pose integration (about 1 %)

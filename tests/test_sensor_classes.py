"""Identification error by sensor class (`identification.sensor_classes`, campaign kind `sensor_classes`, the built-in
campaign `sensor_class_monte_carlo`): the runs' errors against the truth computed here, the issue's target with the
tactical preset, the summary statistics against numpy, the campaign and its report table, and the refusals."""

from __future__ import annotations

import math

import numpy as np
import pytest

import freefloat as ff
from freefloat import campaign as cp
from freefloat.identification import sensor_classes as scl


@pytest.fixture(scope="module")
def zhang_tactical():
    return scl.run("zhang", "tactical", 0)


def test_zhang_errors_are_the_relative_norms_of_the_target_groups(zhang_tactical):
    """Recompute the momentum form's errors at 100 s from the estimator's own history and the model file (the
    study integrates the poses by the Hermite rule)."""
    assert scl.INTEGRATION == "hermite"
    import dataclasses

    import freefloat.postcapture as pc
    from freefloat import sensors

    sc, m, sim = scl._zhang_motion()
    s2 = dataclasses.replace(
        sc,
        sensors=dataclasses.replace(sensors.load("tactical"), integration=scl.INTEGRATION),
        sensor_seed=0,
        measurement={"accelerations": "rts", "momentum_point": "base"},
    )
    res = pc.identify(m, pc.measure(m, sim, s2), s2, methods=("momentum",))
    t, h = res.histories[("momentum", "standard_rls")]
    est, tru = h[np.searchsorted(t, 100.0 + 1e-9) - 1], np.asarray(res.truth)
    n = res.names
    i = [n.index(x) for x in ("Inxx", "Inxy", "Inxz", "Inyy", "Inyz", "Inzz")]
    full = lambda v: np.array([[v[0], v[1], v[2]], [v[1], v[3], v[4]], [v[2], v[4], v[5]]])
    want_I = np.linalg.norm(full(est[i]) - full(tru[i])) / np.linalg.norm(full(tru[i]))
    j = n.index("mn")
    assert zhang_tactical["zhang_momentum.mass.100"] == pytest.approx(abs(est[j] - tru[j]) / tru[j], rel=1e-9)
    assert zhang_tactical["zhang_momentum.inertia.100"] == pytest.approx(want_I, rel=1e-9)
    assert zhang_tactical["estimator"] == "zhang" and zhang_tactical["sensor_class"] == "tactical"


def test_zhang_and_naveen_meet_the_issue_target_with_the_tactical_preset(zhang_tactical):
    """Within 5 % on mass and 10 % on inertia after 100 s (Naveen: the trajectory's 63 s), seed 0: Zhang's momentum
    form and Naveen's estimators. Zhang's force form does not, robustly: see the next test."""
    assert zhang_tactical["zhang_momentum.mass.100"] < 0.05 and zhang_tactical["zhang_momentum.inertia.100"] < 0.10
    nv = scl.run("naveen", "tactical", 0)
    assert nv["naveen_end_s"] == pytest.approx(63.0)
    for sub in ("naveen_ls", "naveen_eiv"):
        assert nv[f"{sub}.mass.100"] < 0.05 and nv[f"{sub}.inertia.100"] < 0.10, sub
        assert nv[f"{sub}.com.100"] < 0.05


def test_each_nudged_motion_is_another_sample_of_the_chaotic_capture():
    """A nudge of the initial velocities by 1e-9 (relative) gives a motion that differs by far more at 100 s (the
    capture is chaotic). Over nudged motions the momentum form stays within the target (median; a motion can come
    near the eq. 39 controller's singular arm configuration, where every estimate fails, or reach it, where the
    simulation stops), while the force form's mass error spreads over several percent, above the 5 % target in at
    least one of them (measured: 2.7-12 % over ten nudges)."""
    a, b = scl._zhang_motion()[2], scl._zhang_motion(1)[2]
    qa, qb = np.asarray(a["q"]), np.asarray(b["q"])
    assert np.abs(qa[0] - qb[0]).max() < 1e-6 and np.abs(qa[-1] - qb[-1]).max() > 1e-5
    runs = []
    for k in range(1, 9):
        try:
            runs.append(scl._zhang("tactical", 0, (100.0,), nudge=k))
        except ff.NumericalError:
            continue  # a motion that reached the singular configuration
        if len(runs) == 5:
            break
    assert len(runs) == 5
    mom = [r["zhang_momentum.mass.100"] for r in runs]
    force = sorted(r["zhang_force.mass.100"] for r in runs)
    assert np.median(mom) < 0.05 and np.median([r["zhang_momentum.inertia.100"] for r in runs]) < 0.10, mom
    assert force[-1] > 0.05 and force[2] > 0.01, force


def test_a_mems_joint_sensor_is_what_breaks_the_momentum_form(zhang_tactical):
    """The MEMS preset's joint rates (a 14-bit magnetic encoder differenced at 100 Hz: 0.15 rad/s) make the
    momentum form fail; with the navigation preset it is well within the target. (The force form's error depends on
    the particular motion even at this class, so one motion says little about it: see the spread test above.)"""
    mems = scl.run("zhang", "mems", 0)
    nav = scl.run("zhang", "navigation", 0)
    assert mems["zhang_momentum.inertia.100"] > 0.3
    assert nav["zhang_momentum.inertia.100"] < 0.05 and nav["zhang_momentum.mass.100"] < 0.01


def test_summary_is_the_median_and_95th_percentile_over_the_runs():
    rng = np.random.default_rng(1)
    rows = []
    for k in range(16):
        r = {"estimator": "naveen", "sensor_class": "mems"}
        for sub in scl.ESTIMATORS["naveen"]:
            for q in scl.QUANTITIES:
                for T in scl.HORIZONS:
                    r[f"{sub}.{q}.{T:g}"] = float(rng.lognormal())
        r["naveen_eiv.com.30"] = None if k < 3 else r["naveen_eiv.com.30"]  # no estimate in 3 runs
        rows.append(r)
    rows.append({"estimator": "zhang", "sensor_class": "mems", "naveen_ls.mass.10": 99.0})  # another estimator's
    s = scl.summary(rows)
    got = next(x for x in s if (x["estimator"], x["quantity"], x["horizon_s"]) == ("naveen_ls", "mass", 10.0))
    x = np.array([r["naveen_ls.mass.10"] for r in rows[:16]])
    assert got["runs"] == 16 and got["median"] == np.median(x) and got["p95"] == np.percentile(x, 95)
    com = next(x for x in s if (x["estimator"], x["quantity"], x["horizon_s"]) == ("naveen_eiv", "com", 30.0))
    assert com["finite"] == 13 and com["median"] == np.median([r["naveen_eiv.com.30"] for r in rows[3:16]])
    assert scl.horizons_of(rows) == (10.0, 30.0, 100.0)
    md = scl.table(rows)  # naveen's 2 × 3 rows, and zhang's (one run, no estimates: every cell —)
    assert md.count("\n") == 2 + 12 - 1 and "naveen_eiv | mems | com" in md
    assert "| zhang_force | mems | inertia | — / — | — / — | — / — | 1 |" in md
    assert scl.fmt_error(0.0123) == "1.2 %" and scl.fmt_error(math.nan) == "—" and scl.fmt_error(25.0) == "25×"


def test_bad_input_names_the_argument():
    with pytest.raises(ff.InputError, match="estimator.*zhang, naveen, cl"):
        scl.run("zang", "tactical")
    with pytest.raises(ff.InputError, match="sensor_class.*navigation, tactical, mems"):
        scl.run("zhang", "consumer")
    with pytest.raises(ff.InputError, match="horizons"):
        scl.run("zhang", "tactical", horizons=[10.0, -1.0])
    with pytest.raises(ff.InputError, match="unknown key 'sensor'"):
        cp.registry.KINDS["sensor_classes"].load({"sensor": "mems"})


def test_builtin_campaign_runs_and_its_report_has_the_table(tmp_path):
    spec = cp.load_spec("sensor_class_monte_carlo")
    assert spec.kind == "sensor_classes" and spec.runs_total == 3 * 3 * 16
    runs = spec.runs()
    assert {(r.scenario["estimator"], r.scenario["sensor_class"]) for r in runs} == {
        (e, c) for e in ("zhang", "naveen", "cl") for c in scl.CLASSES
    }
    assert len({r.seed for r in runs}) == 16  # the same 16 seeds at every grid point
    res = cp.run_campaign(spec, tmp_path, runs=2, workers=1, progress=False)
    assert res["runs_done"] == 2 and res["runs_failed"] == 0
    from freefloat.report import write_report

    html = write_report(tmp_path).read_text()
    assert "Identification error by sensor class" in html and "zhang_momentum" in html

"""Shared fixtures."""

import subprocess
import sys

import pytest


@pytest.fixture(scope="session")
def demo_run(tmp_path_factory):
    """One `freefloat demo --t-final 2` run from an empty folder, shared by the tests that inspect its output (it is
    the suite's longest command: the CLI test checks its results and the browser test opens its report).
    Returns (folder the command ran in, its output folder, the completed process)."""
    cwd = tmp_path_factory.mktemp("demo")
    r = subprocess.run(
        [sys.executable, "-m", "freefloat", "demo", "--t-final", "2", "--out", "demo"],
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=900,
    )
    assert r.returncode == 0, r.stderr[-3000:]
    return cwd, cwd / "demo", r


@pytest.fixture(scope="session")
def zhang3d_measured_60s():
    """The built-in `zhang2020_3d` capture, 60 s, simulated once, and a function that measures it with
    `zhang2020_3d_thrusters`' 100 Hz telemetry (gyro, base velocity, tachometers; poses integrated) under the given
    `measurement:` settings and identifies it: `identify(method, measurement) -> RMS relative error of m1, mn and
    the target's principal moments` (standard RLS, truth at each instant). Shared by the tests of the momentum form
    about the base point and of the RTS smoother's accelerations."""
    import dataclasses

    from freefloat import models
    from freefloat import postcapture as pc
    from freefloat.postcapture.estimators import target_index
    from freefloat.postcapture.spacecraft import truth_history

    base = pc.load_scenario("zhang2020_3d")
    sens = pc.load_scenario("zhang2020_3d_thrusters").sensors
    m = models.load(base.model)
    sim = pc.simulate(dataclasses.replace(base, duration=60.0), m)

    def identify(method: str, measurement: dict) -> float:
        sc = dataclasses.replace(base, duration=60.0, sensors=sens, sensor_seed=0, measurement=measurement)
        res = pc.identify(m, pc.measure(m, sim, sc), sc, methods=(method,))
        res.truth_history = truth_history(m, sim, False, target_index(m))
        return res.rms_rel_error(method, "standard_rls", ["m1", "mn", "Inxx", "Inyy", "Inzz"])

    return identify

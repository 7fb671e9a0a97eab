"""Work is sized before it starts: a run whose recording does not fit in memory, or a fixed-step run longer than
max_steps, is refused at once with a message that gives the size and the way out; an unattainable rk45
tolerance is refused with the bound that applies."""

import math
import subprocess
import sys
import time

import numpy as np
import pytest

import freefloat as ff
from freefloat.simulation import memory_limit


@pytest.fixture(scope="module")
def robot():
    return ff.models.load("naveen_dual_arm")


def test_the_issues_run_is_refused_before_any_work(robot):
    m = robot
    t0 = time.perf_counter()
    with pytest.raises(ff.InputError) as info:
        ff.simulate(m, m.neutral(), np.zeros(m.nv), 1e9, 1e-3)
    assert time.perf_counter() - t0 < 1.0  # refused, not run
    msg = str(info.value)
    assert "t_final" in msg and "samples" in msg and "GB" in msg and "max_memory" in msg and "record_every" in msg
    # the figure is samples x (nq + 3 nv + 9) x 8 bytes: 1e12 samples of this robot
    per = 8 * (m.nq + 3 * m.nv + 9)
    assert f"{per} bytes" in msg
    assert "1.000e12 samples" in msg


def test_max_memory_is_the_limit_and_can_be_raised(robot):
    m = robot
    per = 8 * (m.nq + 3 * m.nv + 9)
    samples = 1000 + 2  # 1 s at dt = 1e-3, every step and the last recorded
    with pytest.raises(ff.InputError, match="max_memory"):
        ff.simulate(m, m.neutral(), np.zeros(m.nv), 1.0, 1e-3, max_memory=per * samples * 0.9)
    tr = ff.simulate(m, m.neutral(), np.zeros(m.nv), 1.0, 1e-3, max_memory=per * samples * 1.1)
    assert len(tr) == 1001
    tr = ff.simulate(m, m.neutral(), np.zeros(m.nv), 0.01, 1e-3, max_memory=math.inf)
    assert len(tr) == 11


def test_default_limit_is_a_fraction_of_available_memory(monkeypatch):
    lim = memory_limit()
    assert 1e8 < lim < 1e15
    monkeypatch.setenv("FREEFLOAT_MAX_MEMORY", "2G")
    assert memory_limit() == 2e9
    monkeypatch.setenv("FREEFLOAT_MAX_MEMORY", "lots")
    with pytest.raises(ff.InputError, match="FREEFLOAT_MAX_MEMORY"):
        memory_limit()


def test_environment_limit_refuses_a_run(robot, monkeypatch):
    m = robot
    monkeypatch.setenv("FREEFLOAT_MAX_MEMORY", "100K")
    with pytest.raises(ff.InputError, match=r"0\.000100 GB"):
        ff.simulate(m, m.neutral(), np.zeros(m.nv), 1.0, 1e-3)


def test_fixed_step_run_longer_than_max_steps_is_refused_up_front(robot):
    m = robot
    t0 = time.perf_counter()
    with pytest.raises(ff.InputError, match="max_steps"):
        ff.simulate(m, m.neutral(), np.zeros(m.nv), 100.0, 1e-3, record_every=1000, max_steps=1000)
    assert time.perf_counter() - t0 < 1.0


@pytest.mark.parametrize("rtol", [1e-20, 1e-16])
def test_rk45_rtol_below_machine_precision_is_refused(robot, rtol):
    m = robot
    t0 = time.perf_counter()
    with pytest.raises(ff.InputError) as info:
        ff.simulate(m, m.neutral(), np.full(m.nv, 0.1), 1.0, 0.1, method="rk45", rtol=rtol)
    assert time.perf_counter() - t0 < 1.0
    msg = str(info.value)
    assert "rtol" in msg and "machine epsilon" in msg and "2.2e-14" in msg


def test_rk45_at_the_bound_runs(robot):
    m = robot
    tr = ff.simulate(m, m.neutral(), np.full(m.nv, 0.01), 0.05, 0.05, method="rk45", rtol=2.3e-14, atol=1e-14)
    assert len(tr) == 2


def test_cli_refuses_a_run_too_large_for_memory():
    t0 = time.perf_counter()
    r = subprocess.run(
        [sys.executable, "-m", "freefloat.cli", "simulate", "naveen_dual_arm", "--t-final", "1e9"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert r.returncode == 2, r.stderr[-2000:]
    assert "Traceback" not in r.stderr
    assert "GB" in r.stderr and "record" in r.stderr and "memory" in r.stderr, r.stderr
    assert time.perf_counter() - t0 < 120


def test_cli_max_memory_option():
    r = subprocess.run(
        [
            sys.executable,
            "-m",
            "freefloat.cli",
            "simulate",
            "naveen_dual_arm",
            "--t-final",
            "1",
            "--max-memory",
            "1e-6",
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert r.returncode == 2 and "memory limit of 0.00000100 GB" in r.stderr, r.stderr[-2000:]


def test_a_postcapture_scenario_too_long_for_memory_is_refused(monkeypatch):
    from freefloat import postcapture as pc

    sc = pc.load_scenario("zhang2020_2d_small")
    sc.duration = 1.0e7  # the issue's scenario: 1e10 recorded steps
    t0 = time.perf_counter()
    with pytest.raises(ff.InputError, match="duration .* memory"):
        pc.simulate(sc)
    monkeypatch.setenv("FREEFLOAT_MAX_MEMORY", "1G")
    sc.duration = 3.0e4  # 3e7 steps, ~8 GB: within a large machine's physical memory, not within 1 GB
    with pytest.raises(ff.InputError, match="limit of 1.000 GB"):
        pc.simulate(sc)
    assert time.perf_counter() - t0 < 1.0

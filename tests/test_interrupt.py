"""Ctrl-C stops a long engine call within a second and keeps what was finished: from Python (a SIGINT sent by a
timer thread while `simulate` runs, with and without Python callbacks) and from the command line (SIGINT to a
running `freefloat simulate ... --out DIR`, which writes the part simulated so far)."""

import json
import os
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import freefloat as ff

#: the stop must come within this many seconds of the signal (the engine polls every 20 ms)
STOP_WITHIN = 1.0


@pytest.fixture(scope="module")
def robot():
    return ff.models.load("naveen_dual_arm")


def _interrupt_after(delay: float, sent: list):
    """SIGINT to this process after `delay` seconds, from a timer thread (Python runs the handler in the main
    thread, which is inside the engine call); the time it was sent goes into `sent`."""

    def fire():
        sent.append(time.monotonic())
        os.kill(os.getpid(), signal.SIGINT)

    t = threading.Timer(delay, fire)
    t.start()
    return t


def _run_interrupted(call, delay=1.0):
    """Run `call` (a long simulation), interrupt it after `delay` s; returns (exception, seconds from the signal
    to the exception)."""
    sent = []
    timer = _interrupt_after(delay, sent)
    try:
        with pytest.raises(KeyboardInterrupt) as info:
            call()
        stopped = time.monotonic()
    finally:
        timer.cancel()
    assert sent, "the call ended before the signal was sent (make it longer)"
    return info.value, stopped - sent[0]


def _check_partial(exc, robot, t_final):
    assert isinstance(exc, ff.Interrupted), type(exc)
    assert "t = " in str(exc), str(exc)
    tr = exc.partial
    assert isinstance(tr, ff.Trajectory)
    assert 2 <= len(tr) and 0 < tr.t[-1] < t_final
    assert tr.q.shape == (len(tr), robot.nq) and np.all(np.isfinite(tr.q))
    assert np.all(np.diff(tr.t) > 0)
    assert "interrupted" in tr.stats
    # what was finished is a real motion: momentum conserved to round-off under internal torques
    assert tr.momentum_drift()["angular_rel"] < 1e-8


def test_ctrl_c_stops_simulate_without_callbacks(robot):
    """No Python code runs during this run (GIL released): the engine's hook re-takes the GIL to check signals."""
    m = robot
    rng = np.random.default_rng(0)
    v0 = 0.1 * rng.normal(size=m.nv)
    t_final = 1e5  # 1e8 RK4 steps: minutes; the signal comes after 1 s
    exc, dt_stop = _run_interrupted(
        lambda: ff.simulate(m, m.neutral(), v0, t_final, 1e-3, record_every=1000, max_steps=10**9)
    )
    assert dt_stop < STOP_WITHIN, f"stopped {dt_stop:.2f} s after the signal"
    _check_partial(exc, m, t_final)


def test_ctrl_c_stops_simulate_with_a_python_torque_function(robot):
    """Python runs in every stage here: the KeyboardInterrupt is raised inside the callback and becomes the
    same `Interrupted` with the samples so far."""
    m = robot
    nb = 6

    def torques(t, q, v):
        out = np.zeros(m.nv)
        out[nb:] = np.sin(t + np.arange(m.nv - nb))
        return out

    exc, dt_stop = _run_interrupted(
        lambda: ff.simulate(
            m, m.neutral(), np.zeros(m.nv), 1e5, 1e-3, record_every=100, torques=torques, max_steps=10**9
        )
    )
    assert dt_stop < STOP_WITHIN, f"stopped {dt_stop:.2f} s after the signal"
    _check_partial(exc, m, 1e5)


def test_ctrl_c_with_a_progress_bar(robot):
    m = robot
    exc, dt_stop = _run_interrupted(
        lambda: ff.simulate(
            m, m.neutral(), np.full(m.nv, 0.01), 1e5, 1e-3, record_every=1000, progress=True, max_steps=10**9
        )
    )
    assert dt_stop < STOP_WITHIN
    _check_partial(exc, m, 1e5)


def test_ctrl_c_stops_rk45(robot):
    m = robot
    exc, dt_stop = _run_interrupted(
        lambda: ff.simulate(m, m.neutral(), np.full(m.nv, 0.05), 1e5, 1.0, method="rk45", rtol=1e-12, max_steps=10**9)
    )
    assert dt_stop < STOP_WITHIN
    _check_partial(exc, m, 1e5)


def test_progress_returning_false_is_an_interruption_not_a_numerical_failure(robot):
    m = robot
    calls = []

    def progress(frac):
        calls.append(frac)
        return len(calls) < 3

    with pytest.raises(ff.Interrupted) as info:
        ff.simulate(m, m.neutral(), np.full(m.nv, 0.01), 1e4, 1e-3, record_every=1000, progress=progress)
    assert not isinstance(info.value, ff.NumericalError)
    assert "returned False" in str(info.value) and "numerical" not in str(info.value)
    assert len(calls) == 3
    assert len(info.value.partial) >= 1


def test_an_exception_in_a_callback_is_still_that_exception(robot):
    m = robot

    def torques(t, q, v):
        raise ZeroDivisionError("mine")

    with pytest.raises(ZeroDivisionError, match="mine"):
        ff.simulate(m, m.neutral(), np.zeros(m.nv), 1.0, 1e-3, torques=torques)


def _start_cli(args, cwd):
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    return subprocess.Popen(
        [sys.executable, "-m", "freefloat.cli", *args],
        cwd=cwd,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )


def _wait_running(p, seconds=120):
    """Wait (generously: a loaded machine imports slowly) until the simulation is under way: its progress bar
    appears on stderr."""
    buf = []
    done = threading.Event()

    def reader():
        for line in iter(lambda: p.stderr.read(1), ""):
            buf.append(line)
            if "simulated" in "".join(buf[-400:]):
                done.set()
        done.set()

    th = threading.Thread(target=reader, daemon=True)
    th.start()
    assert done.wait(seconds), "the simulation did not start"
    assert p.poll() is None, "".join(buf)
    return buf, th


def test_sigint_to_the_cli_stops_it_within_a_second_and_saves_the_partial_run(tmp_path):
    out = tmp_path / "run"
    # 1e6 s at dt = 1e-3 is 1e9 steps (hours); recording every 100 000th step keeps it within the memory check
    p = _start_cli(
        ["simulate", "naveen_dual_arm", "--t-final", "1e6", "--record-every", "100000", "--out", str(out)], tmp_path
    )
    try:
        buf, th = _wait_running(p)
        time.sleep(1.0)  # well into the run
        sent = time.monotonic()
        p.send_signal(signal.SIGINT)
        p.wait(timeout=60)
        took = time.monotonic() - sent
        th.join(5)
    finally:
        if p.poll() is None:
            p.kill()
    err = "".join(buf)
    assert p.returncode == 130, (p.returncode, err[-2000:])
    assert took < STOP_WITHIN, f"exited {took:.2f} s after SIGINT"
    assert "interrupted" in err and "t = " in err, err[-2000:]
    tr = ff.Trajectory.from_parquet(out / "trajectory.parquet")
    assert len(tr) >= 1 and 0 <= tr.t[-1] < 1e6
    res = json.loads((out / "results.json").read_text())
    assert "interrupted" in res and res["t_end"] == pytest.approx(tr.t[-1])


def test_ctrl_c_stops_an_identification_solve_within_a_second(robot):
    """The momentum least squares streams its samples on worker threads; the calling thread polls for Ctrl-C and
    stops them before their next block. A 1000-sample record repeated 600 times (600 000 samples, several
    seconds of work on this machine) is interrupted after 0.3 s."""
    from freefloat.identification.estimation import least_squares

    rng = np.random.default_rng(0)
    q = np.array([robot.random_configuration(rng) for _ in range(1000)])
    v = rng.normal(size=(1000, robot.nv))
    h = np.asarray(ff.momentum(robot, q, v))
    Q, V, H = (np.tile(x, (600, 1)) for x in (q, v, h))
    mp = ff.minimal_parameters(robot, "closed-form")
    t0 = time.monotonic()
    exc, latency = _run_interrupted(lambda: least_squares(robot, Q, V, H, mp), delay=0.3)
    assert isinstance(exc, ff.Interrupted), type(exc)
    assert "identification stopped" in str(exc), str(exc)
    assert latency < STOP_WITHIN, f"stopped {latency:.2f} s after the signal"
    assert time.monotonic() - t0 < 0.3 + STOP_WITHIN + 1.0
    # the same call without a signal still completes and is exact (the data are noise-free)
    res = least_squares(robot, q, v, h, mp)
    truth = mp.from_standard(robot.parameters())
    np.testing.assert_allclose(res.estimate, truth, rtol=1e-8, atol=1e-8)

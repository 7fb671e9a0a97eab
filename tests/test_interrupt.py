"""Ctrl-C stops a long engine call within a second and keeps what was finished: from Python (a SIGINT sent by a
timer thread while `simulate` runs, with and without Python callbacks) and from the command line (SIGINT to a
running `freefloat simulate ... --out DIR`, which writes the part simulated so far)."""

import json
import os
import signal
import threading
import time

import numpy as np
import pytest

import freefloat as ff

from _helpers import sigint_when, start_cli

#: the stop must come within this many seconds of the signal (the engine polls every 20 ms)
STOP_WITHIN = 1.0


@pytest.fixture(scope="module")
def robot():
    return ff.models.load("naveen_dual_arm")


def _interrupt_after(delay: float, sent: list, after: threading.Event | None = None):
    """SIGINT to this process after `delay` seconds (counted from `after` when given, waited for up to 120 s), from
    a thread (Python runs the handler in the main thread, which is inside the engine call); the time it was sent goes
    into `sent`. Returns the thread (a `threading.Timer`: `cancel()` stops it before it fires)."""

    def fire():
        if after is None or after.wait(120):
            time.sleep(0.0 if after is None else delay)
            sent.append(time.monotonic())
            os.kill(os.getpid(), signal.SIGINT)

    t = threading.Timer(0.0 if after is not None else delay, fire)
    t.daemon = True
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


def _check_partial(exc, robot, t_final, drift_per_step=0.0):
    assert isinstance(exc, ff.Interrupted), type(exc)
    assert "t = " in str(exc), str(exc)
    tr = exc.partial
    assert isinstance(tr, ff.Trajectory)
    assert 2 <= len(tr) and 0 < tr.t[-1] < t_final
    assert tr.q.shape == (len(tr), robot.nq) and np.all(np.isfinite(tr.q))
    assert np.all(np.diff(tr.t) > 0)
    assert "interrupted" in tr.stats
    # what was finished is a real motion: momentum conserved to round-off under internal torques (an adaptive
    # run's local errors, of order rtol, add up along the run, and a faster machine gets further before the
    # signal: 9184 s at rtol 1e-12, recorded every 1 s (9185 samples), drifted 1.15e-8 in CI)
    assert tr.momentum_drift()["angular_rel"] < max(1e-8, drift_per_step * len(tr))


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
    _check_partial(exc, m, 1e5, drift_per_step=1e-11)  # per recorded second: 10 x rtol


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


def test_sigint_to_the_cli_stops_it_within_a_second_and_saves_the_partial_run(tmp_path):
    out = tmp_path / "run"
    # 1e6 s at dt = 1e-3 is 1e9 steps (hours); recording every 100 000th step keeps it within the memory check
    p = start_cli(
        ["simulate", "naveen_dual_arm", "--t-final", "1e6", "--record-every", "100000", "--out", str(out)], tmp_path
    )
    # well into the run
    r = sigint_when(p, "simulated", 1.0)
    code, took, err = r.code, r.took, r.err
    assert code == 130, (code, err[-2000:])
    assert took < STOP_WITHIN, f"exited {took:.2f} s after SIGINT"
    assert "interrupted" in err and "t = " in err, err[-2000:]
    tr = ff.Trajectory.from_parquet(out / "trajectory.parquet")
    assert len(tr) >= 1 and 0 <= tr.t[-1] < 1e6
    res = json.loads((out / "results.json").read_text())
    assert "interrupted" in res and res["t_end"] == pytest.approx(tr.t[-1])


def test_ctrl_c_stops_an_identification_solve_within_a_second(robot):
    """The momentum least squares streams its samples on worker threads; the calling thread polls for Ctrl-C and
    stops them before their next block. A 1000-sample record repeated 1200 times (1.2 million samples, about a
    second of work in a release build on 2 cores, 2026-12-04) is interrupted after 0.3 s."""
    from freefloat.identification.estimation import least_squares

    rng = np.random.default_rng(0)
    q = np.array([robot.random_configuration(rng) for _ in range(1000)])
    v = rng.normal(size=(1000, robot.nv))
    h = np.asarray(ff.momentum(robot, q, v))
    Q, V, H = (np.tile(x, (1200, 1)) for x in (q, v, h))
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


# -- the excitation objective batch and the excitation design --------------------------------------------------
@pytest.fixture(scope="module")
def design():
    from freefloat.identification.excitation import ExcitationDesign

    return ExcitationDesign(ff.models.load("naveen_dual_arm_offset"))


def test_ctrl_c_stops_one_excitation_objective_batch_within_a_second(design):
    """One engine call evaluating 600 candidate trajectories (the whole 256-interval path each, 4-10 ms on one
    thread in a release build since the objective streams its Gram matrix: 1.5-3 s of work on two workers) is
    stopped by the calling thread's Ctrl-C check: the workers stop before their next grid point."""
    d = design
    x = d.feasible_start(d.all_directions)
    t = d._grid(len(d.all_directions))
    q, qd, _ = d.cycloid(x, d.all_directions).evaluate(t)
    Q = np.ascontiguousarray(np.broadcast_to(q, (600, *q.shape)))
    QD = np.ascontiguousarray(np.broadcast_to(qd, (600, *qd.shape)))
    exc, latency = _run_interrupted(lambda: d._objective(Q, QD), 0.5)
    assert isinstance(exc, ff.Interrupted), type(exc)
    assert "excitation objective stopped after" in str(exc) and "of 600" in str(exc), str(exc)
    assert latency < STOP_WITHIN, f"stopped {latency:.2f} s after the signal"
    # the same call, small, still completes and agrees with the one-path evaluation
    one = d._objective(q[None], qd[None])
    two = d._objective(np.stack([q, q]), np.stack([qd, qd]))
    # (one path gets both threads, two paths one each: the Gram sums differ in summation order only, and the
    # objective, a condition-number measure of about 2e3 here, amplifies that rounding: 1e-12 was met until the
    # kinematics took fused multiply-adds, 9.8e-12 after, on the CI machine)
    np.testing.assert_allclose(two["objective"], np.repeat(one["objective"], 2), rtol=1e-10)


def test_ctrl_c_in_the_excitation_design_keeps_the_best_design_so_far(design):
    """Ctrl-C during step 1 of the design: `Interrupted.partial` is the best feasible design evaluated; its
    objective, recomputed independently, is what it reports and no worse than the feasible start's."""
    from freefloat.identification.excitation import PartialDesign

    d = design
    first = threading.Event()
    evaluate = d.evaluate

    def counted(X, dirs=None):  # the signal goes once the optimiser has finished its first evaluation
        r = evaluate(X, dirs)
        first.set()
        return r

    def run():
        d.evaluate = counted
        try:
            return d.design(maxiter=1000, progress=False)
        finally:
            del d.evaluate

    sent = []
    _interrupt_after(0.3, sent, after=first)
    with pytest.raises(KeyboardInterrupt) as info:
        run()
    latency = time.monotonic() - sent[0]
    exc = info.value
    assert isinstance(exc, ff.Interrupted), type(exc)
    assert latency < STOP_WITHIN, f"stopped {latency:.2f} s after the signal"
    part = exc.partial
    assert isinstance(part, PartialDesign) and part.stopped_in == "step 1/3", part
    assert part.best is not None and part.best.evaluations > 0
    x = part.best.x
    A, b = d.linear_constraints(part.directions)
    assert np.all(A @ x >= b - 1e-9)
    lo, hi = np.array(d.bounds()).T
    assert np.all((lo <= x) & (x <= hi))
    # the same objective recomputed: equal up to rounding (the threads' summation order differs between the
    # batched call and this one; measured 3.7e-12 relative on a loaded machine), far below any real change
    again = d.evaluate(x, part.directions)
    assert again["objective"][0] == pytest.approx(part.best.objective, rel=1e-9)
    start = d.evaluate(d.feasible_start(part.directions), part.directions)
    assert part.best.objective <= start["objective"][0] * (1 + 1e-12)  # (the start itself, up to rounding)
    assert part.to_dict()["interrupted"] is True


def test_sigint_to_freefloat_excite_keeps_the_best_trajectory(tmp_path):
    out = tmp_path / "ex"
    p = start_cli(["excite", "naveen_dual_arm", "--guess", "naveen_dual_arm_offset", "--out", str(out)], tmp_path)
    # the first SQP iteration is done: there is a design to keep
    r = sigint_when(p, "C=", 0.5)
    code, took, err = r.code, r.took, r.err
    assert code == 130, (code, err[-2000:])
    assert took < STOP_WITHIN, f"exited {took:.2f} s after SIGINT"
    res = json.loads((out / "results.json").read_text())
    assert res["interrupted"] is True and res["stopped_in"] == "step 1/3"
    from freefloat.identification.excitation import load_trajectory

    traj = load_trajectory(out / "trajectory.json")
    assert traj is not None


def test_sigint_to_freefloat_control_ddp_keeps_the_best_iterate_and_exits_130(tmp_path):
    out = tmp_path / "ddp"
    args = ["control", "ddp", "valverde_ch8_tracking", "--max-iter", "100000", "--out", str(out)]
    p = start_cli(args, tmp_path, merged=True)
    r = sigint_when(p, "\n    2 ", 0.3)  # iteration 2's progress line: there is an iterate to keep
    code, took, err = r.code, r.took, r.err
    assert code == 130, (code, err[-2000:])
    assert took < STOP_WITHIN, f"exited {took:.2f} s after SIGINT"
    res = json.loads((out / "results.json").read_text())
    assert res["interrupted"] is True and res["stop"] == "interrupted"
    assert 2 <= res["iterations"] < 100000 and np.isfinite(res["final_cost"])
    assert res["final_cost"] <= res["initial_cost"]
    assert not list(out.glob("*.png")), "figures are skipped after Ctrl-C"


# -- ch. 9 estimate_recorded ------------------------------------------------------------------------------------
def _cl_data(n):
    from freefloat.identification import concurrent as cl

    m = ff.models.load("valverde_ch9_two_arm")
    rng = np.random.default_rng(3)
    R, F = [], []
    for _ in range(8):
        q = m.random_configuration(rng)
        r, f, _, _ = cl.sample(m, q, rng.normal(size=m.nv), rng.normal(size=m.nv))
        R.append(r)
        F.append(f)
    reps = -(-n // 8)
    R = np.ascontiguousarray(np.tile(np.array(R), (reps, 1, 1, 1))[:n])
    F = np.ascontiguousarray(np.tile(np.array(F), (reps, 1, 1))[:n])
    m0 = np.tile([0.1, 0.0, 0.0, 0.1, 0.0, 0.1, 1.0], m.nbodies)
    return R, F, m0


def test_ctrl_c_stops_ch9_estimate_recorded_and_keeps_the_estimates_so_far():
    from freefloat import _core

    # About 5 µs a sample for 11 bodies (2026-12-04; 30 µs when this test was written): 240 000 samples are about
    # 1.2 s of work and 1.4 GB of data, so the signal at 0.5 s lands well inside the estimator's loop. With 120 000
    # samples the whole call took 0.6 s and, on a loaded machine, the loop could end between its last check for
    # signals and the signal, which then surfaced as a plain KeyboardInterrupt.
    R, F, m0 = _cl_data(240_000)
    exc, latency = _run_interrupted(lambda: _core.cl_estimate(R, F, 1e-3, m0), delay=0.5)
    assert isinstance(exc, ff.Interrupted), type(exc)
    assert latency < STOP_WITHIN, f"stopped {latency:.2f} s after the signal"
    part = exc.partial
    k = len(part)
    assert 10 <= k < len(R) and part.shape[1] == m0.size
    assert f"after sample {k} of {len(R)}" in str(exc), str(exc)
    # the estimator is causal: an uninterrupted call on the first k samples gives the same estimates, bit for bit
    full = _core.cl_estimate(np.ascontiguousarray(R[:k]), np.ascontiguousarray(F[:k]), 1e-3, m0)
    assert np.array_equal(part, full)


# -- post-capture runs ------------------------------------------------------------------------------------------
def _long_postcapture(duration=2000.0):
    import copy

    from freefloat import postcapture as pc

    sc = copy.deepcopy(pc.load_scenario("zhang2020_2d_medium"))
    sc.duration = duration
    return sc


def test_ctrl_c_in_a_postcapture_run_keeps_the_motion_and_the_estimates_so_far():
    """The partial motion is the first part of an uninterrupted run of the same scenario, bit for bit, and the
    estimator histories are those of the uninterrupted run up to the stop."""
    from freefloat import postcapture as pc

    sc = _long_postcapture()
    exc, latency = _run_interrupted(lambda: pc.run(sc), delay=1.0)
    assert isinstance(exc, ff.Interrupted), type(exc)
    assert latency < STOP_WITHIN, f"stopped {latency:.2f} s after the signal"
    part = exc.partial
    assert part.interrupted and 1.0 < part.t_end < sc.duration
    sim = part.simulation
    assert sim["t"][-1] == part.t_end and len(sim["t"]) == round(part.t_end / sc.dt) + 1
    short = _long_postcapture(part.t_end)
    ref = pc.simulate(short)
    for k in ("t", "q", "v", "ddq", "tau"):
        assert np.array_equal(sim[k], ref[k]), k
    done = pc.run(short)
    assert set(part.histories) == set(done.histories) and len(part.histories) == 4
    for key, (t, h) in done.histories.items():
        assert np.array_equal(part.histories[key][0], t) and np.array_equal(part.histories[key][1], h), key
    d = part.to_dict()
    assert d["interrupted"] is True and d["t_end"] == part.t_end


def test_sigint_to_freefloat_identify_postcapture_writes_the_partial_run(tmp_path):
    import yaml

    from freefloat.io import data as shipped

    spec = yaml.safe_load(shipped.read_text("scenarios", "zhang2020_2d_medium.yaml"))
    spec["duration"] = 2000.0
    path = tmp_path / "long.yaml"
    path.write_text(yaml.safe_dump(spec))
    out = tmp_path / "pc"
    p = start_cli(["identify", "postcapture", str(path), "--out", str(out), "--no-sweep"], tmp_path)
    r = sigint_when(p, "stage", 1.0)
    code, took, err = r.code, r.took, r.err
    assert code == 130, (code, err[-2000:])
    assert took < STOP_WITHIN, f"exited {took:.2f} s after SIGINT"
    res = json.loads((out / "results.json").read_text())
    assert res["interrupted"] is True and 0 < res["t_end"] < 2000.0
    sim = np.load(out / "simulation.npz")
    assert sim["t"][-1] == pytest.approx(res["t_end"])
    hist = np.load(out / "histories.npz")
    assert hist["momentum_modified_rls"].shape[0] == len(hist["momentum_modified_rls_t"]) > 3


def test_a_postcapture_run_stopped_late_keeps_the_motion_without_running_the_estimators(monkeypatch):
    """When the estimators over the partial motion would delay the exit past the budget, only the motion is kept
    (and the message says so): forced here with a zero budget."""
    from freefloat import postcapture as pc
    from freefloat.postcapture import pipeline

    monkeypatch.setattr(pipeline, "POST_BUDGET_S", 0.0)
    sc = _long_postcapture()
    exc, latency = _run_interrupted(lambda: pc.run(sc), delay=0.5)
    assert isinstance(exc, ff.Interrupted) and latency < STOP_WITHIN
    part = exc.partial
    assert part.histories == {} and "estimators not run" in part.interrupted
    assert len(part.simulation["t"]) >= 2 and part.simulation["t"][-1] == part.t_end


def test_ctrl_c_stops_simulate_many_and_keeps_every_member_so_far(robot):
    m = robot
    rng = np.random.default_rng(1)
    v0 = 0.1 * rng.normal(size=(4, m.nv))
    exc, latency = _run_interrupted(
        lambda: ff.simulate_many(m, m.neutral(), v0, 1e4, 1e-3, record_every=100, threads=2), delay=0.5
    )
    assert isinstance(exc, ff.Interrupted), type(exc)
    assert latency < STOP_WITHIN, f"stopped {latency:.2f} s after the signal"
    runs = exc.partial
    assert len(runs) == 4
    cut = [k for k in range(4) if runs[k] is not None]
    assert cut, runs
    for k in cut:
        tr = runs[k]
        assert "interrupted" in tr.stats and 0 < tr.t[-1] < 1e4
        # the member's samples are those of a plain simulation of the same member up to its stop
        ref = ff.simulate(m, m.neutral(), v0[k], tr.t[-1], 1e-3, record_every=100)
        n = min(len(ref), len(tr))
        np.testing.assert_array_equal(tr.q[:n], ref.q[:n])
    for e in runs.failures.values():  # members that had not started
        assert isinstance(e, ff.Interrupted) and "before it started" in str(e)

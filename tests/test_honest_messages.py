"""Messages that name the real problem, and no silent fallbacks: overflow and NaN reported as such (not as a
singular inertia), too little telemetry counted in samples, a negative noise level, an unknown `known=` body,
complex input; a torque table that ends long before the run, a t_final that is not a multiple of dt, --base for
a model that declares its own base, and a post-capture run whose estimate is its initial guess."""

import json
import subprocess
import sys
import warnings

import numpy as np
import pytest

import freefloat as ff
from freefloat.identification import identify_minimal


@pytest.fixture(scope="module")
def robot():
    return ff.models.load("naveen_dual_arm")


@pytest.fixture(scope="module")
def motion(robot):
    m = robot
    rng = np.random.default_rng(3)
    return ff.simulate(m, m.neutral(), 0.05 * rng.normal(size=m.nv), 2.0, 1e-2)


# -- overflow and NaN ----------------------------------------------------------------------------------------
def test_huge_velocities_are_an_overflow_not_a_singular_inertia(robot):
    m = robot
    for call in (
        lambda: ff.simulate(m, m.neutral(), np.full(m.nv, 1e200), 0.01, 1e-3),
        lambda: ff.aba(m, m.neutral(), np.full(m.nv, 1e200), np.zeros(m.nv)),
    ):
        with pytest.raises(ff.NumericalError) as info:
            call()
        msg = str(info.value)
        assert "overflow" in msg and "1e200" in msg and "v[" in msg, msg
        assert "singular" not in msg


def test_nan_prescription_names_the_prescription_the_entry_and_the_time(robot):
    m = robot
    j = m.joint_names[-1]

    def presc(t):
        q = m.neutral()
        q[-1] = np.nan if t > 0.005 else 0.0
        return q, np.zeros(m.nv), np.zeros(m.nv)

    with pytest.raises(ff.InputError) as info:
        ff.simulate(m, m.neutral(), np.zeros(m.nv), 0.02, 1e-3, prescribed=[j], prescription=presc)
    msg = str(info.value)
    assert "prescription" in msg and "NaN" in msg and f"q[{m.nq - 1}]" in msg and j in msg and "t = 0.00" in msg
    assert "singular" not in msg


def test_a_joint_origin_of_1e308_is_reported_as_overflow(tmp_path, robot):
    text = ff.models.source("naveen_dual_arm").replace("xyz: [0.7, 0.3, 0.9]", "xyz: [1e308, 0.3, 0.9]", 1)
    assert "1e308" in text
    p = tmp_path / "far.yaml"
    p.write_text(text)
    try:
        m = ff.Model.from_yaml(p)
    except ff.ModelError as e:  # refusing it at load is just as honest
        assert "1e308" in str(e) or "finite" in str(e) or "large" in str(e)
        return
    # 1e308 itself is finite; the body frames beyond it overflow (1e308 + rotation terms, squared in inertias)
    with pytest.raises(ff.NumericalError) as info:
        ff.simulate(m, m.neutral(), np.full(m.nv, 0.1), 0.01, 1e-3)
    msg = str(info.value)
    assert "overflow" in msg and "singular" not in msg, msg


# -- identification -----------------------------------------------------------------------------------------
def _first(traj, n):
    return ff.Trajectory(
        t=traj.t[:n],
        q=traj.q[:n],
        v=traj.v[:n],
        ddq=traj.ddq[:n],
        tau=traj.tau[:n],
        momentum=traj.momentum[:n],
        kinetic_energy=traj.kinetic_energy[:n],
        work=traj.work[:n],
        model_name=traj.model_name,
        q_labels=traj.q_labels,
        v_labels=traj.v_labels,
        stats=traj.stats,
    )


@pytest.mark.parametrize("n", [0, 1])
def test_too_little_telemetry_is_counted_in_samples(robot, motion, n):
    with pytest.raises(ff.InputError) as info:
        identify_minimal(robot, _first(motion, n))
    msg = str(info.value)
    assert f"{n} sample" in msg and "need at least" in msg and "samples" in msg, msg
    assert "rows for" not in msg


def test_negative_rate_noise_names_the_sign(robot, motion):
    with pytest.raises(ff.InputError) as info:
        identify_minimal(robot, motion, rate_noise=(-1e-3, 1e-3, 1e-3))
    msg = str(info.value)
    assert "rate_noise" in msg and "-0.001" in msg and "zero or positive" in msg and "shape" not in msg


def test_unknown_known_body_lists_the_bodies(robot, motion):
    for method in ("auto", "closed-form", "numeric"):
        with pytest.raises(ff.InputError) as info:
            identify_minimal(robot, motion, known=["wheel_q"], method=method)
        msg = str(info.value)
        assert "known" in msg and "'wheel_q'" in msg and "base" in msg and "L1" in msg, msg
        assert "numeric" not in msg


def test_complex_input_is_refused_not_truncated(robot):
    m = robot
    q = m.neutral().astype(complex)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no ComplexWarning: a clear error instead
        with pytest.raises(ff.InputError, match="argument `q`: complex"):
            ff.aba(m, q, np.zeros(m.nv), np.zeros(m.nv))
        with pytest.raises(ff.InputError, match="argument `q0`: complex"):
            ff.simulate(m, q, np.zeros(m.nv), 0.01, 1e-3)


# -- no silent fallbacks -----------------------------------------------------------------------------------
def test_a_short_torque_table_warns_how_much_of_the_run_is_past_its_end(robot):
    m = robot
    table = np.zeros((10, m.nv))
    with pytest.warns(UserWarning) as rec:
        ff.simulate(m, m.neutral(), np.zeros(m.nv), 1.0, 1e-3, torques=table)
    msg = " ".join(str(w.message) for w in rec)
    assert "10 rows" in msg and "0.01 s" in msg and "0.99 s" in msg and "99.0 %" in msg, msg


def test_a_table_that_covers_the_run_does_not_warn(robot):
    m = robot
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ff.simulate(m, m.neutral(), np.zeros(m.nv), 0.1, 1e-3, torques=np.zeros((100, m.nv)))
        ff.simulate(m, m.neutral(), np.zeros(m.nv), 0.1, 1e-3, torques=np.zeros(m.nv))  # one constant row


def test_t_final_not_a_multiple_of_dt_warns_where_the_run_ends(robot):
    m = robot
    with pytest.warns(UserWarning, match=r"ends at t = 0\.01 s") as rec:
        tr = ff.simulate(m, m.neutral(), np.zeros(m.nv), 0.0104, 1e-3)
    assert "10 steps" in str(rec[0].message)
    assert tr.t[-1] == pytest.approx(0.01)  # what the warning said
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ff.simulate(m, m.neutral(), np.zeros(m.nv), 0.3, 0.1)  # 0.3 / 0.1 is 3 up to round-off: no warning


def _cli(*args):
    return subprocess.run([sys.executable, "-m", "freefloat.cli", *args], capture_output=True, text=True, timeout=300)


def test_base_fixed_for_a_builtin_robot_is_an_error_not_ignored():
    r = _cli("simulate", "naveen_dual_arm", "--base", "fixed", "--t-final", "0.01")
    assert r.returncode == 2, r.stderr
    assert "--base" in r.stderr and "URDF" in r.stderr and "free" in r.stderr and "Traceback" not in r.stderr
    # the base the model declares is accepted
    r = _cli("simulate", "naveen_dual_arm", "--base", "free", "--t-final", "0.01", "--torques", "zero")
    assert r.returncode == 0, r.stderr


def test_postcapture_without_excitation_says_the_estimate_is_the_guess(tmp_path):
    from freefloat import postcapture as pc

    sc = pc.load_scenario("zhang2020_2d_small")
    sc.excitation["amp"] = [0.0] * len(sc.excitation["amp"])
    sc.duration = min(sc.duration, 2.0)
    res = pc.run(sc)
    w = res.warnings()
    assert any("excitation amplitudes are all zero" in x for x in w), w
    d = res.to_dict()
    assert d["warnings"] == w
    json.dumps(d)

"""Closed-loop DDP: the optimised policy (feed-forward + Riccati gains on the tangent-space state error) and
receding-horizon DDP (MPC) driving freefloat's simulator (RK4 on the true continuous dynamics) of a plant whose
mass differs from the controller's model. The oracle is the simulator: the policy must hold the end effector
where the open-loop feed-forward drifts away."""

from __future__ import annotations

import json

import numpy as np
import pytest
from click.testing import CliRunner
from test_ddp import short

from freefloat import _core
from freefloat._core import InputError
from freefloat.cli import main
from freefloat.control import ddp
from freefloat.control import ddp_closed_loop as cl


def LIGHT(name, **kw):
    """A chapter 8 scenario on valverde_ch8_arm (50 kg base) with the torque-driven wrist."""
    return ddp.load_scenario(name, robot="valverde_ch8_arm", wrist="torque", **kw)


@pytest.fixture(scope="module")
def solved():
    """The tracking problem's first 6 s (the hold phase, the end effector pulled 0.48 m onto the reference),
    log-SE(3) cost, End weights, backtracking: converges in a few iterations. On the light 50 kg base with the
    torque-driven wrist, where the plant's mass error moves the end effector most."""
    prob = short(LIGHT("valverde_ch8_tracking", cost="log", schedule=False), 120)
    sol = ddp.solve(prob, max_iter=60, alphas=[0.5**k for k in range(10)], refresh_gains=True)
    assert sol["stop"] == "converged", sol["stop_message"]
    return prob, sol


def test_perturbed_model_scales_one_body():
    m = LIGHT("valverde_ch8_tracking").model
    p = cl.perturbed_model(m, 0.1, "link3")
    a, b = np.asarray(m.parameters()), np.asarray(p.parameters())
    i = list(m.body_names).index("link3")
    np.testing.assert_allclose(b[i], 1.1 * a[i], rtol=1e-12)
    np.testing.assert_array_equal(np.delete(b, i, 0), np.delete(a, i, 0))
    assert abs(p.total_mass - m.total_mass - 0.5) < 1e-12  # link3 is 5 kg
    last = cl.perturbed_model(m, 0.1)
    assert abs(np.asarray(last.parameters())[-1, 0] - 1.1 * a[-1, 0]) < 1e-12
    with pytest.raises(InputError, match="body"):
        cl.perturbed_model(m, 0.1, "no_such_body")
    with pytest.raises(InputError, match="mass_error"):
        cl.perturbed_model(m, float("nan"))


def test_policy_without_model_error_corrects_the_discretisation_mismatch(solved):
    """Same model, so the only mismatch is semi-implicit Euler at dt (the plan) against RK4 at dt/5 (the plant):
    already that makes the open-loop feed-forward miss the held pose by centimetres; the policy does not."""
    prob, sol = solved
    s = {}
    for mode in ("open_loop", "policy"):
        r = cl.run(prob, mode, solution=sol, substeps=5)
        assert r["xs"].shape == np.asarray(sol["xs"]).shape and r["us"].shape == np.asarray(sol["us"]).shape
        s[mode] = cl.summary(r, final_hold_s=1.0)
    # The policy applies ū_k exactly at the planned state and feedback on the error: node 0 is the plan's.
    assert (
        s["policy"]["ee_position_error_final_hold_max_m"] < 0.2 * s["open_loop"]["ee_position_error_final_hold_max_m"]
    )
    assert s["open_loop"]["ee_position_error_final_hold_max_m"] > 0.01, s


def test_policy_holds_where_open_loop_drifts_with_a_mass_error(solved):
    prob, sol = solved
    plant = cl.perturbed_model(prob.model, 0.1, "link3")
    s = {m: cl.summary(cl.run(prob, m, plant, solution=sol), final_hold_s=1.0) for m in ("open_loop", "policy")}
    ol, fb = s["open_loop"], s["policy"]
    assert fb["ee_position_error_final_hold_max_m"] < 0.2 * ol["ee_position_error_final_hold_max_m"], s
    assert fb["ee_position_error_final_hold_max_m"] < 0.02, s
    assert fb["ee_angle_error_final_hold_max_deg"] < ol["ee_angle_error_final_hold_max_deg"], s


def test_mpc_with_warm_starts_holds_the_pose(solved):
    prob, sol = solved
    plant = cl.perturbed_model(prob.model, 0.1, "link3")
    ol = cl.summary(cl.run(prob, "open_loop", plant, solution=sol), final_hold_s=1.0)
    r = cl.run(prob, "mpc", plant, solution=sol, mpc_horizon=40, replan=5, mpc_options={"max_iter": 3})
    s = cl.summary(r, final_hold_s=1.0)
    st = s["mpc"]
    assert st["replans"] == 120 // 5
    # Warm starts: the re-plans need only their small budget and none failed.
    assert st["iterations"] <= 50 + 3 * (st["replans"] - 1)
    assert st["troubled_replans"] == 0
    assert s["ee_position_error_final_hold_max_m"] < 0.2 * ol["ee_position_error_final_hold_max_m"], (s, ol)
    assert s["ee_position_error_final_hold_max_m"] < 0.02
    # Per-re-plan records (benches/mpc_bench.py reads them) against the controller's own running totals.
    raw = r["mpc"]
    times, its = raw["replan_times_s"], raw["replan_iterations"]
    assert len(times) == len(its) == len(raw["replan_costs"]) == raw["replans"]
    assert sum(its) == raw["iterations"] and all(1 <= i <= 50 for i in its) and all(i <= 3 for i in its[1:])
    assert abs(sum(times) - raw["solve_time_s"]) <= 1e-9 * raw["solve_time_s"]
    assert max(times[1:]) == raw["max_replan_s"] and min(times) > 0
    assert st["median_replan_s"] == float(np.median(times[1:]))
    assert st["p95_replan_s"] == float(np.percentile(times[1:], 95))
    assert "replan_times_s" not in st and "replan_iterations" not in st  # the summary keeps the statistics only


def test_mpc_cold_start_converges_too(solved):
    """No offline solution: the first window starts from zero controls, later ones from the shifted previous."""
    prob, _ = solved
    r = cl.run(prob, "mpc", mpc_horizon=40, replan=10, mpc_options={"max_iter": 5}, first_max_iter=60)
    s = cl.summary(r, final_hold_s=1.0)
    assert s["ee_position_error_final_hold_max_m"] < 0.02, s


def test_mpc_set_parameters_plans_on_the_new_model(solved):
    """A controller built on the wrong mass and given the plant's parameters plans what a controller built on the
    plant plans (same first window, same control), and no longer what it planned before."""
    prob, _ = solved
    plant = cl.perturbed_model(prob.model, 0.5, "link3")
    x0 = np.asarray(prob.x0, float)

    def mpc(model):
        return _core.DdpMpc(
            model._core, prob.dt, prob.horizon, prob.running, prob.terminal, 40, 5, options={"max_iter": 3}
        )

    wrong, right, updated = mpc(prob.model), mpc(plant), mpc(prob.model)
    updated.set_parameters(np.asarray(plant.parameters(), float))
    u_right, u_upd, u_wrong = right.control(0, x0), updated.control(0, x0), wrong.control(0, x0)
    np.testing.assert_allclose(u_upd, u_right, rtol=1e-12, atol=1e-12)
    assert np.abs(u_wrong - u_right).max() > 1e-3 * np.abs(u_right).max()
    assert updated.stats()["model_updates"] == 1 and wrong.stats()["model_updates"] == 0
    with pytest.raises(InputError, match=r"expected shape \(\d+, 10\)"):
        updated.set_parameters(np.zeros((2, 10)))
    bad = np.asarray(plant.parameters(), float)
    bad[1, 0] = np.nan
    with pytest.raises(InputError, match="not finite"):
        updated.set_parameters(bad)


def test_shrinking_horizon_keeps_the_task_end_a_deadline(solved):
    """Windows that shrink at the task's end: the first window is the same (same control at node 0), both hold
    the pose, and the last nodes' controls differ (fixed windows plan 40 nodes past the task's end). What the
    deadline buys is measured on the mission (tests/test_mission.py, the dual-arm berth)."""
    prob, sol = solved
    plant = cl.perturbed_model(prob.model, 0.1, "link3")
    kw = {"solution": sol, "mpc_horizon": 40, "replan": 5, "mpc_options": {"max_iter": 3}}
    fixed = cl.run(prob, "mpc", plant, **kw)
    shrunk = cl.run(prob, "mpc", plant, shrink=True, **kw)
    np.testing.assert_allclose(shrunk["us"][0], fixed["us"][0], rtol=1e-12, atol=1e-12)
    a, b = cl.summary(fixed, final_hold_s=1.0), cl.summary(shrunk, final_hold_s=1.0)
    assert b["ee_position_error_final_hold_max_m"] < 0.02, b
    assert shrunk["mpc"]["replans"] == fixed["mpc"]["replans"]
    # past the end the fixed windows plan 40 nodes beyond the task: the controls of the last nodes differ
    assert np.abs(shrunk["us"][-1] - fixed["us"][-1]).max() > 0
    assert a["ee_position_error_final_hold_max_m"] < 0.02, a


def test_observed_mpc_is_the_same_run_in_segments(solved):
    """The observer's segments are the same RK4 steps under the same held controls: an observer that keeps the
    model gives the run of one piece (to round-off), and sees every step of it exactly once."""
    prob, sol = solved
    plant = cl.perturbed_model(prob.model, 0.1, "link3")
    kw = {"solution": sol, "mpc_horizon": 40, "replan": 5, "mpc_options": {"max_iter": 3}}
    one = cl.run(prob, "mpc", plant, **kw)
    seen = []

    def observer(k, seg):
        seen.append((k, seg["t"][0], seg["t"][-1], len(seg["u"]), len(seg["t"])))
        # the held control at each step is what the controller applied at that step's node (the one-piece run's,
        # to round-off: the segments restart from the recorded state)
        kk = np.floor(seg["t"][:-1] / prob.dt + 1e-9).astype(int)
        np.testing.assert_allclose(seg["u"], one["us"][kk], rtol=0, atol=1e-9)
        return None

    seg = cl.run(prob, "mpc", plant, observer=observer, observe_every=20, **kw)
    np.testing.assert_allclose(seg["xs"], one["xs"], rtol=0, atol=1e-9)
    np.testing.assert_allclose(seg["t"], one["t"], rtol=0, atol=1e-12)
    assert [s[0] for s in seen] == list(range(20, prob.horizon + 1, 20))
    assert all(s[3] == 20 * 5 and s[4] == 20 * 5 + 1 for s in seen)
    assert abs(seen[-1][2] - prob.horizon * prob.dt) < 1e-9
    with pytest.raises(InputError, match="observer"):
        cl.run(prob, "policy", plant, solution=sol, observer=observer, observe_every=20)


def test_closed_loop_bad_input(solved):
    prob, sol = solved
    with pytest.raises(InputError, match="mode"):
        cl.run(prob, "sideways", solution=sol)
    with pytest.raises(InputError, match="solution"):
        cl.run(prob, "policy")
    with pytest.raises(InputError, match="replan"):
        cl.run(prob, "mpc", mpc_horizon=10, replan=20)
    with pytest.raises(InputError, match="horizon"):
        cl.run(prob, "mpc", mpc_horizon=0, replan=1)
    n, nu = prob.horizon, prob.model.nv
    with pytest.raises(InputError, match="gains"):
        _core.DdpPolicy(prob.model._core, np.asarray(sol["xs"]), np.asarray(sol["us"]), np.zeros((n, nu, nu)))
    pol = _core.DdpPolicy(prob.model._core, np.asarray(sol["xs"]), np.asarray(sol["us"]), np.asarray(sol["gains"]))
    x = np.asarray(sol["xs"])[0].copy()
    np.testing.assert_allclose(pol.control(0, x), np.asarray(sol["us"])[0], atol=1e-12)
    x[0] = np.nan
    with pytest.raises(InputError, match="argument `x`: entry 0 is NaN"):
        pol.control(0, x)


def test_cli_closed_loop_writes_results(tmp_path):
    r = CliRunner().invoke(
        main,
        [
            "control",
            "ddp",
            "valverde_ch8_stabilisation",
            "--cost",
            "log",
            "--max-iter",
            "2",
            "--closed-loop",
            "--mpc",
            "--horizon",
            "20",
            "--replan",
            "500",
            "--model-error",
            "0.1",
            "--out",
            str(tmp_path),
            "--no-plots",
        ],
    )
    # --replan above --horizon is refused before anything runs.
    assert r.exit_code != 0 and "--replan" in r.output


@pytest.mark.slow
def test_cli_closed_loop_and_mpc_tracking(tmp_path):
    args = ["control", "ddp", "valverde_ch8_tracking", "--cost", "log", "--no-schedule", "--line-search"]
    args += ["backtracking", "--max-iter", "40", "--closed-loop", "--mpc", "--horizon", "60", "--replan", "10"]
    args += ["--mpc-iter", "3", "--model-error", "0.1", "--error-body", "link3", "--out", str(tmp_path)]
    r = CliRunner().invoke(main, args)
    assert r.exit_code == 0, r.output
    res = json.loads((tmp_path / "results.json").read_text())
    c = res["closed_loop"]
    assert set(c) >= {"plant", "open_loop", "policy", "mpc"}
    for m in ("policy", "mpc"):
        assert c[m]["ee_position_error_final_hold_max_m"] < 0.2 * c["open_loop"]["ee_position_error_final_hold_max_m"]
    assert (tmp_path / "closed_loop_errors.png").exists()

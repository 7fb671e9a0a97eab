"""The capture mission (freefloat.mission, `freefloat mission`): the grasp impact against independent momentum
balances, the merged model against the unmerged one, the phases end to end, and the refusals."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

import freefloat as ff
from freefloat import _core
from freefloat import algorithms as alg
from freefloat import mission as fm
from freefloat.mission import phases

from _helpers import sigint_when, start_cli

TARGET_YAML = """
name: free_target
base: free
gravity: [0, 0, 0]
bodies:
  - name: target
    inertial: {{mass: {m}, com: [{c0}, {c1}, {c2}], inertia: [{i0}, {i1}, {i2}]}}
"""


def _state(m):
    q = m.neutral()
    q[3:7] = np.array([0.1, -0.2, 0.05, 0.97]) / np.linalg.norm([0.1, -0.2, 0.05, 0.97])
    q[7:13] = [0.3, 0.5, 1.0, 0.3, 0.7, 0.2]
    v = np.array([0.02, -0.01, 0.03, 0.01, -0.02, 0.015, 0.05, -0.04, 0.03, 0.02, -0.01, 0.06])
    return q, v


def test_grasp_conserves_momentum_of_servicer_plus_free_target():
    """Before: the servicer (target massless) and the target as its own free body, each by ff.momentum; after: the
    combined model at the impact's v_post. The impact solves M_c v+ = M_s v- + J^T I V (CRBA and Jacobian), the
    balance uses the momentum routine on two other models: agreement is not built in."""
    body = fm.spec.Body(320.0, np.array([-0.3, 0.05, 0.02]), np.diag([40.0, 30.0, 25.0]))
    servicer = ff.models.load("zhang2020_3d")
    t = servicer.body_index("target")
    combined = phases.model_with_target(servicer, t, body)
    q, v = _state(combined)
    fk = np.asarray(alg.forward_kinematics(combined, q[None]))[0, t]
    R = alg.quat_to_matrix(fk[3:])
    v_w, w_w = np.array([0.05, -0.02, 0.01]), np.array([0.04, 0.03, -0.05])  # target, inertial
    r = _core.capture_impact(combined._core, t, list(q), list(v), list(np.r_[R.T @ v_w, R.T @ w_w]))
    P = np.array(combined.parameters())
    P[t] = 0.0
    h_servicer = ff.momentum(combined.with_parameters(P), q, v)
    free = ff.Model.from_yaml_string(
        TARGET_YAML.format(m=body.mass, c0=body.com[0], c1=body.com[1], c2=body.com[2], i0=40.0, i1=30.0, i2=25.0)
    )
    h_target = ff.momentum(free, fk, np.r_[R.T @ v_w, R.T @ w_w])  # free base: twist in its own axes
    before = np.asarray(h_servicer) + np.asarray(h_target)
    after = np.asarray(ff.momentum(combined, q, r["v_post"]))
    assert np.abs(after - before).max() < 1e-12 * np.abs(before).max()
    assert r["energy_after"] < r["energy_before"]
    # the linear impulse on the target is its change of linear momentum m (v_com+ - v_com-), from its Jacobian
    imp = np.asarray(r["impulse_world"])
    J = np.asarray(alg.frame_jacobian(combined, q, "target", "world"))
    tw = J @ r["v_post"]
    c_w = R @ body.com
    dv = (tw[:3] + np.cross(tw[3:], c_w)) - (v_w + np.cross(w_w, c_w))
    assert np.allclose(imp[:3], body.mass * dv, atol=1e-9 * body.mass)


def test_merged_model_keeps_the_target_frame_and_dynamics():
    m = ff.models.load("zhang2020_3d")
    mm = m.with_fixed_leaves_merged()
    assert mm.nbodies == m.nbodies - 1 and "target" not in mm.body_names
    q, v = _state(m)
    tau = np.sin(np.arange(m.nv))
    assert np.allclose(ff.aba(m, q, v, tau), ff.aba(mm, q, v, tau), rtol=1e-10, atol=1e-12)
    assert np.allclose(ff.crba(m, q), ff.crba(mm, q), rtol=1e-12, atol=1e-10)


@pytest.fixture(scope="module")
def mission_run():
    return fm.run("zhang2020_3d_capture")


def test_mission_phases_and_comparison(mission_run):
    res = mission_run
    assert res["phases_done"] == ["capture", "identify", "berth"]
    assert res["capture"]["momentum_error_relative"] < 1e-12
    assert res["capture"]["impulse_linear_Ns"] > 0.1
    # before the grasp: two bodies (servicer, free target) whose summed momentum is the grasp's "before"
    a = res["approach"]
    assert a["momentum_drift_relative"] < 1e-12 and a["gap_at_start_m"] > 0.3 and a["gap_at_contact_m"] < 1e-9
    i = res["identify"]
    assert i["converged"] and 5.0 <= i["handover_time_s"] < 60.0
    # at the handover the estimate is as good as the test said (tolerances 1 % mass, 5 mm CoM, 2 % inertia)
    assert i["target_mass_error_relative"] < 0.01
    assert i["target_com_error_m"] < 0.005
    assert i["target_inertia_error_relative"] < 0.02
    b = res["berth"]
    # the identified model berths like the truth and better than the guess, on the same true plant
    assert b["identified"]["position_error_final_m"] < 0.2 * b["nominal"]["position_error_final_m"]
    assert b["identified"]["position_error_final_m"] < 1e-3
    assert abs(b["identified"]["propellant_kg"] - b["truth"]["propellant_kg"]) < 0.01 * b["truth"]["propellant_kg"]
    assert b["identified"]["settling_time_s"] is not None
    # the adaptive berth (MPC re-planning on the estimate its own telemetry refines): the controller took new
    # estimates, and the berth's motion made the target's inertia better than at the handover
    ad = b["adaptive"]
    on = ad["online"]
    assert on["model_updates"] >= 1 and ad["mpc"]["model_updates"] == on["model_updates"]
    assert on["rows"] > 0 and on["segments"] == round(20.0 / on["update_every_s"])
    assert on["target_error_at_handover"]["inertia_relative"] == pytest.approx(i["target_inertia_error_relative"])
    assert on["target_error_at_end"]["inertia_relative"] < 0.5 * on["target_error_at_handover"]["inertia_relative"]
    assert ad["settling_time_s"] is not None and ad["position_error_final_m"] < 5e-3


def test_adaptive_berth_rows_hold_at_the_true_parameters():
    """The berth's momentum rows from true states: the true standard parameters of base and target satisfy them to
    the quadrature's error, and a 1 % heavier target does not. The impulses are trapezoids (the base wrench held
    over each step, the attitude moving under it); the base point's transport term ∫ v_B × P is Simpson's rule on
    the 10 ms record, whose pairs of steps straddle the command's switches every 5 steps (kinks in the integrand):
    4.0e-5 relative, against 3.1e-6 with a 0.04 s command period (switches on pair boundaries)."""
    import dataclasses

    from freefloat.identification import online
    from freefloat.mission import adaptive_berth
    from freefloat.postcapture import equations as eq

    mission = fm.load_mission("zhang2020_3d_capture")
    truth = phases.load_truth(mission)
    q, v = _state(truth)
    sc = dataclasses.replace(phases.detumble_scenario(mission, q, v, truth), sensors=None)
    L = eq.Layout(False)
    target = phases.target_index(truth)
    theta = np.concatenate([eq.standard_vector(*eq.body_truth(truth, b))[L.std_cols] for b in (0, target)])
    ident = {
        "scenario": sc,
        "rls": online.RecursiveLS(theta, np.full(len(theta), 1.0)),
        "std_cols": L.std_cols,
        "truth_physical": adaptive_berth.physical(theta, L.std_cols),
        "handover_time": 0.0,
    }
    est = adaptive_berth.BerthEstimator(truth, ident, {})
    rng = np.random.default_rng(3)
    held = rng.normal(0.0, [20, 20, 20, 5, 5, 5] + [10] * 6, (20, truth.nv))  # 20 control steps of 0.05 s
    us = []

    def law(t, q_, v_):
        return held[min(int(round(t / 0.05)), 19)]

    tr = ff.simulate(truth, q, v, 1.0, 0.01, method="rk4", record_every=1, controller=law, controller_period=0.05)
    t = np.asarray(tr.t)
    us = held[np.minimum(np.floor(t[:-1] / 0.05 + 1e-9).astype(int), 19)]
    rows = est.segment_rows({"t": t, "q": np.asarray(tr.q), "v": np.asarray(tr.v), "u": us})
    phi, y = np.asarray(rows.Phi), np.asarray(rows.y)
    assert len(rows.t) == 10 and np.abs(y).max() > 1.0  # the wrench moved the stack
    res = np.einsum("kri,i->kr", phi, theta) - y
    assert np.abs(res).max() < 1e-4 * np.abs(y).max(), np.abs(res).max()
    wrong = theta.copy()
    wrong[len(L.std_cols) :] *= 1.01
    assert np.abs(np.einsum("kri,i->kr", phi, wrong) - y).max() > 1e-3 * np.abs(y).max()


def test_mission_cli_writes_results(tmp_path):
    out = tmp_path / "m"
    p = subprocess.run(
        [sys.executable, "-m", "freefloat", "mission", "zhang2020_3d_capture", "--out", str(out)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert p.returncode == 0, p.stderr
    d = json.loads((out / "results.json").read_text())
    assert set(d["berth"]) >= {"nominal", "identified", "truth", "controller"}
    assert (out / "mission_timeline.png").stat().st_size > 10_000
    assert "identified" in p.stdout


def _mission_file(tmp_path, **edits) -> str:
    text = ff.io.data.read_text("scenarios", "zhang2020_3d_capture")
    for old, new in edits.items():
        assert old in text
        text = text.replace(old, new)
    p = tmp_path / "m.yaml"
    p.write_text(text)
    return str(p)


def test_unreachable_berth_is_refused_before_simulating(tmp_path):
    f = _mission_file(tmp_path, **{"position: [1.2, 0.8, 0.3]": "position: [6.0, 0.8, 0.3]"})
    with pytest.raises(ff.InputError, match=r"berth\.position.*reach"):
        fm.run(f)


def test_bad_mission_files_name_the_key(tmp_path):
    f = _mission_file(tmp_path, **{"joints_deg: [20.0, 30.0, 60.0, 20.0, 40.0, 10.0]": "joints_deg: [20.0, 30.0]"})
    with pytest.raises(ff.InputError, match=r"capture\.joints_deg.*6 joints"):
        fm.run(f)
    f = _mission_file(tmp_path, **{"max_duration: 60.0": "max_duraton: 60.0"})
    with pytest.raises(ff.InputError, match=r"line \d+.*max_duraton"):
        fm.load_mission(f)
    f = _mission_file(tmp_path, **{"inertia: [45.0, 38.0, 30.0]": "inertia: [45.0, 3.0, 30.0]"})
    with pytest.raises(ff.InputError, match=r"target\.inertia.*not the inertia of a body"):
        fm.load_mission(f)


def test_mission_campaign_kind_and_report(tmp_path):
    """One Monte Carlo draw of the built-in mission campaign through the campaign machinery, and the HTML report of
    a mission's --out folder."""
    from freefloat.campaign import registry

    kind = registry.get("mission")
    base = kind.load("zhang2020_3d_capture")
    base["target"]["mass"] = 150.0
    row = kind.run(kind.normalize(base), 3)
    assert row["capture.target_mass_kg"] == 150.0
    assert row["identify.converged"] is True
    assert row["berth.identified.position_error_final_m"] < row["berth.nominal.position_error_final_m"]
    res = fm.run("zhang2020_3d_capture_heavy")
    fm.write(res, tmp_path / "m")
    from freefloat.report import build_report

    html = build_report(tmp_path / "m")
    assert "Capture mission: zhang2020_3d_capture_heavy" in html and "Berth (policy)" in html


def test_ctrl_c_keeps_the_phases_done(tmp_path):
    """SIGINT once the grasp is reported (the detumble simulation has started): exit 130, and results.json holds the
    capture phase and says where the mission stopped."""
    out = tmp_path / "m"
    p = start_cli(["mission", "zhang2020_3d_capture_heavy", "--out", str(out)])
    r = sigint_when(p, r"(^|\n)capture:", regex=True)
    assert r.code == 130, r.err[-2000:]
    d = json.loads((out / "results.json").read_text())
    assert d["phases_done"][0] == "capture" and "berth" not in d["phases_done"]
    assert d["interrupted"].startswith("stopped after capture")
    assert d["capture"]["momentum_error_relative"] < 1e-12


def test_a_target_too_heavy_for_the_arm_is_run_and_reported(tmp_path):
    """Effort limits on the servicer's joints well below what the berth needs: the mission runs to the end and
    names the joints, with the peak over the limit."""
    text = ff.models.source("zhang2020_3d")
    for j in ("J2", "J3"):
        old = f"joint: {{name: {j}, type: revolute, axis: [0, 0, 1]}}"
        assert old in text
        text = text.replace(old, f"joint: {{name: {j}, type: revolute, axis: [0, 0, 1], limits: {{effort: 50}}}}")
    (tmp_path / "servicer.yaml").write_text(text)
    f = _mission_file(tmp_path, **{"servicer: zhang2020_3d ": f"servicer: {tmp_path / 'servicer.yaml'} "})
    res = fm.run(f)
    assert res["phases_done"] == ["capture", "identify", "berth"]
    for name in ("nominal", "identified", "truth"):
        s = res["berth"][name]
        over = s["planned_torque_over_limit"]
        assert set(over) & {"J2", "J3"} and all(r > 1.0 for r in over.values()), (name, s)
        # clipped at 50 N m the stack is not held: the run is reported as failed, or it ran and says by how much
        assert "failed" in s or s["joint_torque_over_limit"], (name, s)
    assert "berth" in fm.table(res)


def test_grasp_on_a_servicer_without_a_target():
    """Naveen's dual-arm robot carries no target: the mission welds one at arm A's end effector (`grasp:`) and runs
    the post-capture laws from its inline `detumble:` blocks."""
    res = fm.run("naveen_dual_arm_capture")
    assert res["capture"]["momentum_error_relative"] < 1e-12
    assert res["approach"]["momentum_drift_relative"] < 1e-12
    i = res["identify"]
    assert i["converged"] and i["target_mass_error_relative"] < 0.01 and i["target_inertia_error_relative"] < 0.02
    b = res["berth"]
    assert b["identified"]["position_error_final_m"] < 0.1 * b["nominal"]["position_error_final_m"]


def test_grasp_errors_name_the_key(tmp_path):
    text = ff.io.data.read_text("scenarios", "naveen_dual_arm_capture").replace("body: L3", "body: L9")
    (tmp_path / "a.yaml").write_text(text)
    with pytest.raises(ff.InputError, match=r"grasp'\.body.*no body 'L9'"):
        fm.run(str(tmp_path / "a.yaml"))
    text = ff.io.data.read_text("scenarios", "zhang2020_3d_capture").replace(
        "detumble: zhang2020_3d ", "grasp: {body: link6}\ndetumble: zhang2020_3d "
    )
    (tmp_path / "b.yaml").write_text(text)
    with pytest.raises(ff.InputError, match=r"already carries a target"):
        fm.run(str(tmp_path / "b.yaml"))

"""Campaign kinds for the chapter-4, -8 and -9 scenario files (identify_cl, control_ddp, control_adaptive): a spec
over their own keys expands into runs whose scenarios the commands' readers accept, and each run's row holds
the numbers of that command's results.json. The runs are executed directly (what a Dask worker does), so these
tests need no cluster; `tests/test_campaign.py` covers the cluster."""

from __future__ import annotations

import numpy as np
import pytest

from freefloat import campaign as cp
from freefloat import models
from freefloat._core import InputError
from freefloat.campaign import file_kinds


def _runs(d):
    s = cp.spec.parse(d, "test spec")
    kind = cp.registry.get(s.kind)
    return [(r, kind.run(r.scenario, r.seed)) for r in s.runs()]


def test_all_three_kinds_are_registered():
    assert {"identify_cl", "control_ddp", "control_adaptive"} <= set(cp.KINDS)


@pytest.mark.filterwarnings("ignore:the final estimate of:UserWarning")  # the noisy run's, expected
def test_identify_cl_noise_free_converges_and_sensor_noise_spoils_it():
    rows = _runs(
        {
            "name": "cl",
            "kind": "identify_cl",
            "scenario": "valverde_ch9_two_arm",
            "set": {"duration": 6.0},
            "grid": {"noise.wrench": [0.0, 1.0e-3]},
        }
    )
    (r0, clean), (_, noisy) = rows
    assert r0.params["noise.wrench"] == 0.0
    # noise-free: every one of the 77 parameters recovered (chapter 9's claim), each reported by name
    assert clean["max_final_relative_error"] < 1e-6
    assert clean["final_relative_error.base.m"] < 1e-6 and len([k for k in clean if k.startswith("final_rel")]) == 77
    # joint force/torque noise of 1 mN (m) is amplified by the SVD gain: far from the noise-free result
    assert noisy["max_final_relative_error"] > 1e3 * clean["max_final_relative_error"]


def test_identify_cl_unknown_noise_key_is_named():
    # in a spec: refused before any run, with the valid names
    with pytest.raises(InputError, match=r"noise\.wrnch.*noise\.wrench"):
        cp.spec.parse(
            {"name": "cl", "kind": "identify_cl", "scenario": "valverde_ch9_two_arm", "grid": {"noise.wrnch": [1e-3]}},
            "test spec",
        )
    # a run handed a mapping directly (the kind's API) says the same
    base = cp.registry.get("identify_cl").load("valverde_ch9_two_arm")
    with pytest.raises(InputError, match=r"noise\.wrnch.*noise\.wrench"):
        file_kinds.run_identify_cl(base | {"noise": {"wrnch": 1e-3}}, 0)


def test_control_ddp_both_pose_costs_reduce_the_cost():
    rows = _runs(
        {
            "name": "ddp",
            "kind": "control_ddp",
            "scenario": "valverde_ch8_tracking",
            "set": {"solver.max_iter": 3, "horizon": 80},
            "grid": {"cost": ["dq", "log"]},
        }
    )
    finals = []
    for r, out in rows:
        assert out["pose_cost"] == r.params["cost"]
        assert 1 <= out["iterations"] <= 3 and out["final_cost"] < out["initial_cost"]
        assert np.isfinite(out["ee_position_error_final_hold_max_m"]) and out["base_force_peak_N"] > 0
        finals.append(out["final_cost"])
    assert finals[0] != finals[1]  # two different cost functions, not the same run twice


def test_control_adaptive_rows_keep_one_column_name_across_alphas():
    rows = _runs(
        {
            "name": "ad",
            "kind": "control_adaptive",
            "scenario": "valverde_ch4_example_b",
            "set": {"simulation.duration": 1.0},
            "grid": {"learning.alpha": [0.005, 0.02]},
        }
    )
    (_, a), (_, b) = rows
    assert a["cl.alpha"] == 0.005 and b["cl.alpha"] == 0.02 and a["baseline.alpha"] == 0.0
    assert set(a) == set(b)  # same columns whatever alpha is
    # the baseline does not depend on the CL weight: identical in both rows
    assert a["baseline.final_estimate.6"] == b["baseline.final_estimate.6"]
    assert a["cl.final_estimate.6"] != b["cl.final_estimate.6"]


def test_a_scenario_file_with_a_relative_model_path_runs_from_the_campaign(tmp_path):
    (tmp_path / "robots").mkdir()
    (tmp_path / "robots" / "arm.yaml").write_text(models.source("valverde_ch9_two_arm"))
    from freefloat import data

    text = data.read_text("scenarios", "valverde_ch9_two_arm").replace(
        "model: valverde_ch9_two_arm", "model: robots/arm.yaml"
    )
    assert "robots/arm.yaml" in text
    (tmp_path / "mine.yaml").write_text(text.replace("duration: 10.0", "duration: 5.5"))
    spec = {"name": "rel", "kind": "identify_cl", "scenario": str(tmp_path / "mine.yaml")}
    rows = _runs(spec | {"monte_carlo": {"runs": 1, "seed": 0}})
    assert rows[0][1]["max_final_relative_error"] < 1e-6

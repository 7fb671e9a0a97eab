"""The excitation benchmark keeps working: a --quick smoke run whose peer agrees with freefloat (no timing
assertions: speed is measured by the benchmark itself, not in tests)."""

import json
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def test_excitation_bench_quick_runs_and_agrees(tmp_path):
    pytest.importorskip("pinocchio")
    pytest.importorskip("scipy")  # the design step runs SLSQP
    r = subprocess.run([sys.executable, str(ROOT / "benches" / "excitation_bench.py"), "--quick", "--out", str(tmp_path)],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr[-2000:]
    res = json.loads((tmp_path / "excitation_bench.json").read_text())
    # the script aborts on disagreement; check the recorded numbers as well, so a loosened check shows up here
    assert res["agreement_passed"] is True
    agree = res["agreement"]
    for key in ("condition_number_rel", "mean_square_rel", "objective_rel"):
        assert agree[key] <= 1e-6, (key, agree[key])
    assert agree["regressor_max_rel"] <= 1e-9
    assert agree["batch_vs_sequential_max_rel"] <= 1e-9  # Gram blocks summed in another order
    assert res["problem"]["intervals"] == 256 and res["problem"]["regressor_shape"] == [7680, 52]
    assert res["gradient_batch_evaluations"] == 13
    for name, s in res["objective_seconds"].items():
        assert s["n"] == res["repeats"], name
    for table in ("objective_seconds", "gradient_batch_seconds"):
        for name, s in res[table].items():
            assert 0 < s["min"] <= s["median"] <= s["max"], (table, name, s)
    design = res["design"]
    assert design["maxiter"] == 5 and len(design["repeats"]) == 1
    assert 0 < design["kept_intervals"] <= 256 and design["condition_number"] >= 1.0
    assert {"ff_evaluate", "peer_evaluate"} <= set(res["objective_seconds"])
    assert set(res["ratios"]) == {"peer_over_ff_evaluate", "sequential_over_batch"}
    assert (tmp_path / "excitation_bench.md").read_text().startswith("# Exciting-trajectory objective")

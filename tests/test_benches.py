"""The benchmark script keeps working (a smoke run, no timing assertions: speed is measured in
BENCHMARKS.md, not in tests)."""

import json
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def test_compare_pinocchio_quick_runs_and_agrees(tmp_path):
    pytest.importorskip("pinocchio")
    pytest.importorskip("crocoddyl")
    r = subprocess.run([sys.executable, str(ROOT / "benches" / "compare_pinocchio.py"), "--quick", "--out", str(tmp_path)],
                       capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr[-2000:]
    res = json.loads((tmp_path / "compare_pinocchio.json").read_text())
    assert max(res["agreement_max_rel_error"].values()) < 1e-9
    for key in ("aba_core_vs_abaInParallel", "sim_vs_crocoddyl_rollout", "sim_vs_pin_python"):
        assert res["ratios"][key]["median"] > 0
    assert (tmp_path / "compare_pinocchio.md").read_text().startswith("# freefloat vs Pinocchio")

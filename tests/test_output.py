"""Output a person can use: progress in simulated seconds, integration-error warning, CSV export and --out
file names, paths without '//', a short print(trajectory)."""

from __future__ import annotations

import numpy as np
import pytest
from click.testing import CliRunner

import freefloat as ff
from freefloat.cli import main
from freefloat.io.telemetry import Telemetry


def test_trajectory_prints_a_summary():
    m = ff.models.load("naveen_dual_arm")
    traj = ff.simulate(m, m.neutral(), np.zeros(m.nv), 0.2, 1e-3)
    text = repr(traj)
    assert "201 samples" in text and "t = 0 .. 0.2 s" in text and "momentum drift" in text
    assert "array" not in text and len(text) < 400


def test_progress_bar_counts_simulated_seconds(capsys):
    m = ff.models.load("naveen_dual_arm")
    ff.simulate(m, m.neutral(), np.zeros(m.nv), 0.5, 1e-3, progress=True)
    err = capsys.readouterr().err
    assert "s simulated" in err and "‰" not in err
    assert "0.50/0.50 s simulated" in err  # the finished run fills its bar


def test_out_csv_is_a_file_and_reads_back(tmp_path):
    r = CliRunner()
    out = r.invoke(main, ["simulate", "naveen_dual_arm", "--t-final", "0.2", "--out", str(tmp_path / "run.csv")])
    assert out.exit_code == 0, out.output
    assert (tmp_path / "run.csv").is_file()
    for f in ("run.csv", "run.results.json", "run.png"):
        assert str(tmp_path / f) in out.output  # every file written is listed
    m = ff.models.load("naveen_dual_arm")
    tel = Telemetry.from_file(tmp_path / "run.csv", m)
    assert tel.q.shape == (21, m.nq)  # every 10th step (--record-every 10) and np.all(np.isfinite(tel.v))
    bad = r.invoke(main, ["simulate", "naveen_dual_arm", "--t-final", "0.1", "--out", str(tmp_path / "run.txt")])
    assert bad.exit_code != 0 and "expected a trajectory file" in bad.output
    assert not (tmp_path / "run.txt").exists()


def test_paths_have_no_double_slash(tmp_path):
    r = CliRunner()
    out = r.invoke(main, ["simulate", "naveen_dual_arm", "--t-final", "0.1", "--out", str(tmp_path) + "/"])
    assert out.exit_code == 0, out.output
    assert "//" not in out.output and str(tmp_path / "trajectory.parquet") in out.output


@pytest.mark.slow
def test_simulate_warns_when_integration_error_is_visible():
    r = CliRunner()
    out = r.invoke(main, ["simulate", "seed000_3d", "--t-final", "2"])
    assert out.exit_code == 0
    assert "integration error is visible" in out.output and "rk45" in out.output
    quiet = r.invoke(main, ["simulate", "naveen_dual_arm", "--t-final", "1"])
    assert "integration error is visible" not in quiet.output


def test_readme_dual_quaternion_snippet_runs_as_written():
    import re
    from pathlib import Path

    readme = (Path(__file__).parent.parent / "README.md").read_text()
    section = readme[readme.index("## Dual quaternions") :]
    code = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    ns: dict = {}
    exec(compile(code, "README.md (dual quaternions)", "exec"), ns)
    m, q, v, tau = ns["m"], ns["q"], ns["v"], ns["tau"]
    np.testing.assert_allclose(ns["a"], ff.aba(m, q, v, tau), atol=1e-9)


def test_writing_parquet_files_does_not_import_pandas(tmp_path):
    """pyarrow's table constructors import pandas (half a second) to ask whether their input is a DataFrame; the
    write that saves a run after Ctrl-C must not pay that. A fresh interpreter writes a trajectory and a telemetry
    file without importing pandas; both read back unchanged (reading may import it)."""
    import subprocess
    import sys

    code = f"""
import sys, numpy as np, freefloat as ff
from freefloat.io.telemetry import Telemetry
m = ff.models.load("naveen_dual_arm")
tr = ff.simulate(m, m.neutral(), np.full(m.nv, 0.01), 0.01, 1e-3)
tr.to_parquet({str(tmp_path / "t.parquet")!r})
tel = Telemetry.from_trajectory(tr)
tel.to_parquet({str(tmp_path / "tel.parquet")!r})
print("pandas" in sys.modules)
back = ff.Trajectory.from_parquet({str(tmp_path / "t.parquet")!r})
assert np.array_equal(back.q, tr.q) and np.array_equal(back.momentum, tr.momentum)
again = Telemetry.from_file({str(tmp_path / "tel.parquet")!r}, m)
assert np.array_equal(again.t, tel.t) and np.array_equal(again.v, tel.v)
"""
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.strip().splitlines()[0] == "False"

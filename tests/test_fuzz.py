"""A short coverage-guided fuzzing run (atheris) of the four readers: every mutated YAML or URDF model, telemetry
CSV file or post-capture scenario file is either accepted or refused with one of freefloat's errors; a Python
traceback, a Rust panic or a crash fails the run, and libFuzzer writes the input that caused it (its path is in
the failure message). The long run is `sh fuzz/long_run.sh` (docs/reliability.md). The scenario and telemetry
readers run slower (a scenario loads its robot; telemetry goes through a file), so their short runs are shorter."""

import subprocess
import sys
from pathlib import Path

import pytest

FUZZ = Path(__file__).resolve().parents[1] / "fuzz" / "readers.py"
pytest.importorskip("atheris", reason="atheris is a test extra (pip install '.[test]')")


@pytest.mark.slow
@pytest.mark.parametrize(
    "target,runs", [("yaml_model", 50000), ("urdf_model", 50000), ("telemetry", 5000), ("scenario", 1500)]
)
def test_short_fuzz_run_finds_no_crash(target, runs, tmp_path):
    r = subprocess.run(
        [sys.executable, str(FUZZ), target, f"-runs={runs}", "-seed=1", f"-artifact_prefix={tmp_path}/"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        env={"FREEFLOAT_FUZZ_CORPUS": str(tmp_path / "corpus"), "PATH": "/usr/bin:/bin"},
        timeout=600,
    )
    crashes = sorted(p.name for p in tmp_path.glob("crash-*"))
    assert r.returncode == 0 and not crashes, f"fuzzing {target} found {crashes}:\n{r.stderr[-3000:]}"
    assert f"Done {runs} runs" in r.stderr

"""A short coverage-guided fuzzing run (atheris) of the model readers: every mutated YAML or URDF model is either
accepted or refused with one of freefloat's errors; a Python traceback, a Rust panic or a crash fails the run, and
libFuzzer writes the input that caused it (its path is in the failure message). The long run is
`python fuzz/readers.py TARGET -max_total_time=3600`."""

import subprocess
import sys
from pathlib import Path

import pytest

FUZZ = Path(__file__).resolve().parents[1] / "fuzz" / "readers.py"
pytest.importorskip("atheris", reason="atheris is a test extra (pip install '.[test]')")


@pytest.mark.slow
@pytest.mark.parametrize("target", ["yaml_model", "urdf_model"])
def test_short_fuzz_run_finds_no_crash(target, tmp_path):
    r = subprocess.run(
        [sys.executable, str(FUZZ), target, "-runs=50000", "-seed=1", f"-artifact_prefix={tmp_path}/"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        env={"FREEFLOAT_FUZZ_CORPUS": str(tmp_path / "corpus"), "PATH": "/usr/bin:/bin"},
        timeout=600,
    )
    crashes = sorted(p.name for p in tmp_path.glob("crash-*"))
    assert r.returncode == 0 and not crashes, f"fuzzing {target} found {crashes}:\n{r.stderr[-3000:]}"
    assert "Done 50000 runs" in r.stderr

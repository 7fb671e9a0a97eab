"""The fuzzing harness in the test suite (fuzz/readers.py): every input of the regression corpus
(fuzz/regressions/TARGET/, the minimised inputs of past findings and the known-bad cases of each reader) is
accepted or refused with one of freefloat's errors, and a short coverage-guided run (atheris, libFuzzer) of each
of the four readers finds no Python traceback, Rust panic or crash (libFuzzer writes the input that caused one;
its path is in the failure message). Both work on the normal, uninstrumented install and take a few seconds;
the long, Rust-coverage-guided run is `sh fuzz/long_run.sh` with the instrumented build (docs/reliability.md)."""

import importlib.util
import subprocess
import sys
from pathlib import Path

import pytest

FUZZ = Path(__file__).resolve().parents[1] / "fuzz"


def _readers():
    spec = importlib.util.spec_from_file_location("freefloat_fuzz_readers", FUZZ / "readers.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)  # imported, not run: no atheris, no instrumentation
    return mod


R = _readers()
CASES = [(t, p) for t in R.TARGETS for p in R.regression_inputs(t)]


def test_every_reader_has_a_regression_corpus():
    assert {t for t, _ in CASES} == set(R.TARGETS)


@pytest.mark.parametrize("target,path", CASES, ids=[f"{t}/{p.name}" for t, p in CASES])
def test_regression_input_is_accepted_or_refused_clearly(target, path):
    try:
        R.READERS[target](path.read_bytes())
    except R.EXPECTED as e:
        assert len(str(e)) > 10, f"{target}/{path.name}: an error that says nothing: {e!r}"


def test_a_finding_is_not_swallowed():
    """The check the harness applies can fail: an exception other than freefloat's propagates."""
    with pytest.raises(ZeroDivisionError):
        R.check_with(lambda data: 1 / 0, b"")


@pytest.mark.parametrize(
    "target,runs", [("yaml_model", 3000), ("urdf_model", 3000), ("telemetry", 150), ("scenario", 60)]
)
def test_short_fuzz_run_finds_no_crash(target, runs, tmp_path):
    pytest.importorskip("atheris", reason="atheris is a test extra (pip install '.[test]')")
    r = subprocess.run(
        [sys.executable, str(FUZZ / "readers.py"), target, f"-runs={runs}", "-seed=1", f"-artifact_prefix={tmp_path}/"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        env={"FREEFLOAT_FUZZ_CORPUS": str(tmp_path / "corpus"), "PATH": "/usr/bin:/bin"},
        timeout=120,
    )
    crashes = sorted(p.name for p in tmp_path.glob("crash-*"))
    assert r.returncode == 0 and not crashes, f"fuzzing {target} found {crashes}:\n{r.stderr[-3000:]}"
    assert f"Done {runs} runs" in r.stderr

"""Shared fixtures."""

import subprocess
import sys

import pytest


@pytest.fixture(scope="session")
def demo_run(tmp_path_factory):
    """One `freefloat demo --t-final 2` run from an empty folder, shared by the tests that inspect its output (it is
    the suite's longest command: the CLI test checks its results and the browser test opens its report).
    Returns (folder the command ran in, its output folder, the completed process)."""
    cwd = tmp_path_factory.mktemp("demo")
    r = subprocess.run(
        [sys.executable, "-m", "freefloat", "demo", "--t-final", "2", "--out", "demo"],
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=900,
    )
    assert r.returncode == 0, r.stderr[-3000:]
    return cwd, cwd / "demo", r

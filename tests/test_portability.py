"""The installed engine runs on the CPUs its baseline promises and refuses older ones with a clear error.

The processors are emulated with qemu's user mode (`qemu-x86_64 -cpu MODEL`, Debian package qemu-user; CI installs
it): Haswell (2013) is the oldest x86-64-v3 processor; Sandy Bridge (2011) has AVX but no AVX2, FMA or BMI. The older
processor must still run numpy, which the check reads the processor's features from: numpy >= 2.4 is built for
x86-64-v2 and itself dies of an illegal instruction under qemu's Nehalem and Westmere models, so those cannot show
our error. Without qemu the tests skip; CI does not skip them.
"""

from __future__ import annotations

import os
import platform
import shutil
import subprocess
import sys

import pytest

from freefloat import _core

QEMU = shutil.which("qemu-x86_64")
pytestmark = pytest.mark.skipif(platform.machine() != "x86_64", reason="x86-64 baselines only")
needs_qemu = pytest.mark.skipif(QEMU is None, reason="qemu-x86_64 (Debian qemu-user) not installed")

SCRIPT = (
    "import numpy as np, freefloat as ff; m = ff.models.load('naveen_dual_arm'); "
    "a = ff.aba(m, m.neutral(), np.zeros(m.nv), np.ones(m.nv)); print('ok', a.shape[0])"
)


def run_on(cpu: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [QEMU, "-cpu", cpu, sys.executable, "-c", SCRIPT], capture_output=True, text=True, timeout=300
    )


def test_engine_is_built_for_the_documented_baseline():
    # .cargo/config.toml sets x86-64-v3; a build with RUSTFLAGS overrides it on purpose.
    if "RUSTFLAGS" in os.environ or "CARGO_ENCODED_RUSTFLAGS" in os.environ:
        pytest.skip("RUSTFLAGS set: the build baseline is the builder's choice")
    assert {"avx2", "fma", "bmi2"} <= set(_core.COMPILED_CPU_FEATURES)


def test_the_marker_in_the_binary_is_the_compiled_feature_list():
    # what the import-time check reads from the file is what the engine reports about itself
    import importlib.util

    from freefloat import _cpu

    assert _cpu.compiled_features(importlib.util.find_spec("freefloat._core").origin) == list(
        _core.COMPILED_CPU_FEATURES
    )


def test_missing_features_are_judged_by_numpy_names():
    from freefloat import _cpu

    westmere = {"SSE42": True, "POPCNT": True, "AVX": False, "AVX2": False, "FMA3": False}
    assert _cpu.missing_features(["sse4.2", "popcnt", "avx", "avx2", "fma", "fxsr"], westmere) == ["avx", "avx2", "fma"]
    assert _cpu.missing_features(["avx2"], {"AVX2": True}) == []
    assert _cpu.processor_features() is not None  # numpy's dispatch table is readable here


@needs_qemu
def test_runs_on_a_2013_processor():
    features = set(_core.COMPILED_CPU_FEATURES)
    if features & {"avx512f", "avx512vl"}:
        pytest.skip("this engine was built for AVX-512 (target-cpu=native?), not the portable baseline")
    r = run_on("Haswell")
    assert r.returncode == 0 and r.stdout.startswith("ok 15"), r.stdout + r.stderr


@needs_qemu
def test_an_older_processor_gets_a_clear_import_error_not_an_illegal_instruction():
    if not set(_core.COMPILED_CPU_FEATURES) & {"avx2", "fma", "bmi1", "bmi2"}:
        pytest.skip("engine built without AVX2/FMA/BMI: it runs on Sandy Bridge")
    pre = subprocess.run([QEMU, "-cpu", "SandyBridge", sys.executable, "-c", "import numpy"], capture_output=True)
    assert pre.returncode == 0, "numpy itself does not run on the emulated Sandy Bridge: pick an older-but-newer model"
    r = run_on("SandyBridge")
    assert r.returncode == 1, f"exit {r.returncode} (illegal instruction is -4/132): {r.stderr[-500:]}"
    assert "ImportError" in r.stderr and "compiled for CPU features this processor lacks" in r.stderr
    assert "avx2" in r.stderr and "target-cpu=native" in r.stderr

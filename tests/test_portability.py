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


# An identification streamed over threads (4,200 samples: more than one chunk), through the Gram kernel the engine
# picks at run time (AVX-512 where the processor has it, else the x86-64-v3 one); prints the estimate's bits.
IDENTIFY = (
    "import freefloat as ff; from freefloat import estimation as est; m = ff.models.load('naveen_dual_arm'); "
    "mp = ff.minimal_parameters(m, method='closed-form'); J = ['J1', 'J2', 'J3', 'J4', 'J5', 'J6', 'Wx', 'Wy', 'Wz']; "
    "p = ff.trajectories.MultiSine.random(len(J), 1).prescription(m, J); q0, v0, _ = p(0.0); "
    "tr = ff.simulate(m, q0, v0, 4.2, 1e-3, prescribed=J, prescription=p, record_every=1); "
    "r = est.least_squares(m, tr.q[1:], tr.v[1:], tr.momentum[1:] + 0.01, mp); "
    "print(r.method, ' '.join(float(x).hex() for x in r.estimate))"
)


def run_on(cpu: str, script: str = SCRIPT) -> subprocess.CompletedProcess:
    return subprocess.run(
        [QEMU, "-cpu", cpu, sys.executable, "-c", script], capture_output=True, text=True, timeout=600
    )


def identify_here(**env) -> str:
    r = subprocess.run(
        [sys.executable, "-c", IDENTIFY], capture_output=True, text=True, timeout=300, env={**os.environ, **env}
    )
    assert r.returncode == 0, r.stderr
    return r.stdout


def test_the_avx512_and_baseline_kernels_give_the_same_bits():
    # FREEFLOAT_NO_AVX512 forces the x86-64-v3 Gram kernel and the four-sample block builder where the AVX-512 Gram
    # kernel and the eight-sample builder would run (on a processor without AVX-512 both runs take the same path):
    # every entry is the same chain of operations either way
    fast, portable = identify_here(), identify_here(FREEFLOAT_NO_AVX512="1")
    assert fast.startswith("normal equations") and fast == portable


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
    # the identification's run-time choice falls back to the x86-64-v3 kernel and builder there: the same estimate
    r = run_on("Haswell", IDENTIFY)
    assert r.returncode == 0, r.stderr[-2000:]
    assert r.stdout == identify_here(FREEFLOAT_NO_AVX512="1")


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

"""Refuse, with a clear message, to load an engine compiled for CPU features this processor lacks.

The engine is compiled for a CPU baseline (x86-64-v3 by default, `.cargo/config.toml`; or whatever the builder's
RUSTFLAGS chose). On an older processor it would die of an illegal instruction, already while Python initialises
the module, so the check cannot live inside it: the build stores its feature list as a marker string in the binary
(`crates/freefloat-py/src/cpu.rs`), and this module reads it from the file and compares it with the processor's
features before the engine is imported. The processor's features come from numpy's run-time CPU dispatch (which
executes CPUID, so it also sees an emulated processor); where neither list can be read nothing is checked.
"""

from __future__ import annotations

import importlib.util
import mmap
import platform

MARKER = b"FREEFLOAT_CPU_FEATURES="

# cargo's feature names -> numpy's (numpy/_core/src/common/npy_cpu_features.h). Features numpy does not report
# (cargo's `fxsr`, `xsave`, ...) are not checked: every processor with the ones listed here has them.
NUMPY_NAME = {
    "sse": "SSE", "sse2": "SSE2", "sse3": "SSE3", "ssse3": "SSSE3", "sse4.1": "SSE41", "sse4.2": "SSE42",
    "popcnt": "POPCNT", "cmpxchg16b": "CX16", "avx": "AVX", "f16c": "F16C", "fma": "FMA3", "avx2": "AVX2",
    "bmi1": "BMI", "bmi2": "BMI2", "lzcnt": "LZCNT", "movbe": "MOVBE", "avx512f": "AVX512F", "avx512cd": "AVX512CD",
    "avx512vl": "AVX512VL", "avx512bw": "AVX512BW", "avx512dq": "AVX512DQ",
}  # fmt: skip


def compiled_features(path: str) -> list[str] | None:
    """The features the engine at `path` was compiled for, read from its marker string (None if absent)."""
    try:
        with open(path, "rb") as f, mmap.mmap(f.fileno(), 0, access=mmap.ACCESS_READ) as mm:
            i = mm.find(MARKER)
            j = mm.find(b";", i) if i >= 0 else -1
            return mm[i + len(MARKER) : j].decode("ascii").split(",") if j > 0 else None
    except (OSError, ValueError, UnicodeDecodeError):
        return None


def processor_features() -> dict[str, bool] | None:
    """numpy's view of the processor (CPUID at run time): {numpy feature name: present}, or None."""
    try:
        from numpy._core._multiarray_umath import __cpu_features__ as features  # numpy >= 2
    except ImportError:
        try:
            from numpy.core._multiarray_umath import __cpu_features__ as features  # numpy 1.x
        except ImportError:
            return None
    return dict(features)


def missing_features(compiled: list[str], processor: dict[str, bool]) -> list[str]:
    """Compiled-for features (cargo names) that the processor lacks (only those numpy reports are judged)."""
    return [f for f in compiled if NUMPY_NAME.get(f) in processor and not processor[NUMPY_NAME[f]]]


def check() -> None:
    """Raise ImportError naming the missing features if the engine cannot run on this processor."""
    if platform.machine().lower() not in ("x86_64", "amd64"):
        return
    spec = importlib.util.find_spec("freefloat._core")
    if spec is None or not spec.origin:
        return
    compiled, processor = compiled_features(spec.origin), processor_features()
    if compiled is None or processor is None:
        return
    missing = missing_features(compiled, processor)
    if missing:
        raise ImportError(
            f"freefloat's engine ({spec.origin}) was compiled for CPU features this processor lacks: "
            f"{', '.join(missing)}. Build it for this machine from source: "
            'RUSTFLAGS="-C target-cpu=native" pip install --force-reinstall --no-binary freefloat freefloat '
            '(in a source checkout: RUSTFLAGS="-C target-cpu=native" pip install .)'
        )

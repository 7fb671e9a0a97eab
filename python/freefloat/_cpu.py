"""Refuse, with a clear message, to load an engine compiled for CPU features this processor lacks.

The engine is compiled for a CPU baseline (x86-64-v3 by default, `.cargo/config.toml`; or whatever the builder's
RUSTFLAGS chose). On an older processor it would die of an illegal instruction, possibly while Python initialises
the module, so the check cannot live inside it: the build stores its feature list as a marker string in the binary
(`crates/freefloat-py/src/cpu.rs`), and this module reads it from the file and compares it with the processor's
features (Linux: /proc/cpuinfo) before the engine is imported. Elsewhere, or if either list cannot be read, nothing
is checked.
"""

from __future__ import annotations

import importlib.util
import mmap
import platform
import re

MARKER = b"FREEFLOAT_CPU_FEATURES="

# cargo's feature names -> the flag /proc/cpuinfo shows for them (where they differ); features without a cpuinfo
# flag of their own (e.g. cargo's `crt-static`) are not checked.
CPUINFO_NAME = {
    "sse3": "pni",
    "sse4.1": "sse4_1",
    "sse4.2": "sse4_2",
    "cmpxchg16b": "cx16",
    "lzcnt": "abm",
}
CHECKED = {
    "sse", "sse2", "sse3", "ssse3", "sse4.1", "sse4.2", "popcnt", "cmpxchg16b", "avx", "avx2", "fma", "f16c",
    "bmi1", "bmi2", "lzcnt", "movbe", "xsave", "avx512f", "avx512vl", "avx512bw", "avx512dq", "avx512cd",
}  # fmt: skip


def compiled_features(path: str) -> list[str] | None:
    """The features the engine at `path` was compiled for, read from its marker string (None if absent)."""
    try:
        with open(path, "rb") as f, mmap.mmap(f.fileno(), 0, access=mmap.ACCESS_READ) as mm:
            i = mm.find(MARKER)
            if i < 0:
                return None
            j = mm.find(b";", i)
            return mm[i + len(MARKER) : j].decode("ascii").split(",") if j > 0 else None
    except (OSError, ValueError, UnicodeDecodeError):
        return None


def processor_flags() -> set[str] | None:
    """The processor's feature flags from /proc/cpuinfo (None where there is no such file)."""
    try:
        text = open("/proc/cpuinfo", encoding="ascii", errors="replace").read()
    except OSError:
        return None
    m = re.search(r"^flags\s*:(.*)$", text, re.MULTILINE)
    return set(m.group(1).split()) if m else None


def missing_features(compiled: list[str], flags: set[str]) -> list[str]:
    """Compiled-for features (cargo names) the processor does not report."""
    return [f for f in compiled if f in CHECKED and CPUINFO_NAME.get(f, f) not in flags]


def check() -> None:
    """Raise ImportError naming the missing features if the engine cannot run on this processor."""
    if platform.machine().lower() not in ("x86_64", "amd64"):
        return
    spec = importlib.util.find_spec("freefloat._core")
    if spec is None or not spec.origin:
        return
    compiled, flags = compiled_features(spec.origin), processor_flags()
    if compiled is None or flags is None:
        return
    missing = missing_features(compiled, flags)
    if missing:
        raise ImportError(
            f"freefloat's engine ({spec.origin}) was compiled for CPU features this processor lacks: "
            f"{', '.join(missing)}. Build it for this machine from source: "
            'RUSTFLAGS="-C target-cpu=native" pip install --force-reinstall --no-binary freefloat freefloat '
            '(in a source checkout: RUSTFLAGS="-C target-cpu=native" pip install .)'
        )

"""Coverage-guided fuzzing (atheris, libFuzzer) of freefloat's input readers: YAML and URDF models, telemetry CSV
files and scenario files. Each target feeds mutated bytes to one reader; the reader may accept the input or refuse
it with one of freefloat's errors (InputError, ModelError, NumericalError). Anything else is a finding: another
Python exception (a traceback a user would see), a Rust panic surfacing as PanicException, or a crash of the
process (abort, segfault), which libFuzzer reports with the input that caused it.

    python fuzz/readers.py TARGET [libFuzzer options]       # TARGET: yaml_model, urdf_model, telemetry, scenario
    python fuzz/readers.py yaml_model -runs=20000            # a short run
    python fuzz/readers.py urdf_model -max_total_time=900    # a long run (see docs/reliability.md)
    FREEFLOAT_FUZZ_FINDINGS=findings/ python fuzz/readers.py scenario -max_total_time=900   # keep going on findings
    python fuzz/readers.py --replay                          # run every input of fuzz/regressions/ once

Coverage: atheris instruments the freefloat Python package at import. The Rust side (the URDF and YAML model
readers, roxmltree, serde_norway, the engine the telemetry target identifies with) is coverage-guided only with
the instrumented build of the extension (`sh fuzz/build_instrumented.sh VENV`, SanitizerCoverage): run this
script with that venv's Python and it preloads libFuzzer itself (re-executing with LD_PRELOAD) so the
extension's `__sanitizer_cov_*` callbacks resolve; libFuzzer then reports "Loaded N modules (... inline 8-bit
counters)" at start. With a normal install the Rust readers are fuzzed by mutation without coverage feedback.

The seed corpus is built from the built-in robots (their YAML, their URDF export), a telemetry file of a short
simulation and the built-in scenarios, written to `fuzz/corpus/TARGET/` (or `$FREEFLOAT_FUZZ_CORPUS/TARGET/`) on
first use. Minimised inputs of past findings are kept in `fuzz/regressions/TARGET/`; they are added to every
run's corpus and replayed by the test suite (tests/test_fuzz.py).
"""

from __future__ import annotations

import os
import sys
import tempfile
import warnings
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
REGRESSIONS = HERE / "regressions"
PRELOAD = "ubsan_with_fuzzer.so"  # libFuzzer with the UBSan runtime, shipped by atheris


def _import(instrument: bool):
    """Import freefloat, its Python code instrumented by atheris when fuzzing. With the SanitizerCoverage build of
    the extension the import fails (libFuzzer's callbacks are missing) unless libFuzzer is preloaded: re-execute
    this script once with LD_PRELOAD set (atheris then uses that libFuzzer, which also counts the Rust edges)."""
    try:
        if not instrument:
            import freefloat
        else:
            import atheris

            # instrument freefloat's own Python code only (instrumenting numpy's bytecode costs a minute at start-up)
            with atheris.instrument_imports(include=["freefloat"], enable_loader_override=False):
                import freefloat
                import freefloat.io.scenario_files
                import freefloat.postcapture.scenario  # noqa: F401
    except ImportError as e:
        if "__sanitizer_cov" not in str(e) or os.environ.get("FREEFLOAT_FUZZ_PRELOADED"):
            raise
        import atheris

        env = dict(os.environ, FREEFLOAT_FUZZ_PRELOADED="1")
        env["LD_PRELOAD"] = " ".join(filter(None, [str(Path(atheris.path()) / PRELOAD), env.get("LD_PRELOAD")]))
        # UBSan's runtime comes with the preload; the Rust code is not UBSan-instrumented, so it stays quiet
        env.setdefault("UBSAN_OPTIONS", "print_stacktrace=1")
        print(f"freefloat's extension is instrumented (SanitizerCoverage): preloading {PRELOAD}", file=sys.stderr)
        sys.stderr.flush()
        os.execve(sys.executable, [sys.executable, *sys.argv], env)
    return freefloat


ff = _import(instrument=__name__ == "__main__" and "--replay" not in sys.argv)
from freefloat.io import scenario_files  # noqa: E402
from freefloat.postcapture import scenario as pc_scenario  # noqa: E402

EXPECTED = (ff.InputError, ff.ModelError, ff.NumericalError)
TARGETS = ("yaml_model", "urdf_model", "telemetry", "scenario")
TMP = Path(tempfile.mkdtemp(prefix="freefloat-fuzz-"))
SEED_MODELS = ("naveen_dual_arm", "zhang2020_2d_medium", "zhang2020_3d", "valverde_ch7_two_arm")


def _text(data: bytes) -> str | None:
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        return None


def yaml_model(data: bytes) -> None:
    text = _text(data)
    if text is not None:
        ff.Model.from_yaml_string(text)


def urdf_model(data: bytes) -> None:
    text = _text(data)
    if text is not None:
        ff.Model.from_urdf_string(text)


_TELEMETRY_MODEL = None


def telemetry(data: bytes) -> None:
    """The telemetry path: read the CSV file (Python), then, when it is accepted, identify the model's minimal
    parameters from it (the convention check and the least-squares fit, whose regressors are the engine's Rust)."""
    global _TELEMETRY_MODEL
    if _TELEMETRY_MODEL is None:
        _TELEMETRY_MODEL = ff.models.load("zhang2020_2d_medium")
    f = TMP / "telemetry.csv"
    f.write_bytes(data)
    telem = ff.io.Telemetry.from_file(f, _TELEMETRY_MODEL)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # "nothing fits the momentum model" and the like: answers, not findings
        ff.identify_minimal(_TELEMETRY_MODEL, telem, check="warn")


def scenario(data: bytes) -> None:
    f = TMP / "scenario.yaml"
    f.write_bytes(data)
    pc_scenario.load_scenario(f)


def _seed_corpus(target: str) -> Path:
    out = Path(os.environ.get("FREEFLOAT_FUZZ_CORPUS", HERE / "corpus")) / target
    if out.is_dir() and any(out.iterdir()):
        return out
    out.mkdir(parents=True, exist_ok=True)
    if target in ("yaml_model", "urdf_model"):
        for name in SEED_MODELS:
            if target == "yaml_model":
                (out / f"{name}.yaml").write_text(ff.models.source(name))
                continue
            try:
                (out / f"{name}.urdf").write_text(ff.models.load(name).to_urdf())
            except ff.ModelError:  # a joint URDF cannot express (spherical): not a seed
                pass
    elif target == "telemetry":
        import pyarrow.csv as pacsv
        import pyarrow.parquet as pq

        m = ff.models.load("zhang2020_2d_medium")
        v0 = np.linspace(0.05, 0.3, m.nv)  # a drifting, turning motion: identification has something to fit
        tr = ff.simulate(m, m.neutral(), v0, 0.2, 0.01)
        tr.to_parquet(TMP / "seed.parquet")
        pacsv.write_csv(pq.read_table(TMP / "seed.parquet"), out / "seed.csv")  # quoted names, as pyarrow writes
        ff.io.Telemetry.from_trajectory(tr).to_csv(out / "seed_freefloat.csv")  # freefloat's own CSV
    elif target == "scenario":
        for s in scenario_files.listing():
            if s.kind == "postcapture":
                (out / f"{s.name}.yaml").write_text(ff.data.read_text("scenarios", s.name))
    return out


def _record(findings: str, target: str, e: Exception, data: bytes, seen: set[str]) -> None:
    """Keep-going mode (the long run): write each distinct finding once (exception type and the innermost frame
    of the freefloat package, or the innermost frame) to FREEFLOAT_FUZZ_FINDINGS/TARGET/ and go on fuzzing, so
    one known finding does not end an hour's run. A Rust panic or a process crash still stops libFuzzer."""
    import hashlib
    import traceback

    frames = traceback.extract_tb(e.__traceback__)
    own = [f for f in frames if "freefloat" in f.filename] or frames
    where = f"{Path(own[-1].filename).name}:{own[-1].lineno}" if own else "?"
    sig = f"{type(e).__name__} at {where}"
    if sig in seen:
        return
    seen.add(sig)
    out = Path(findings) / target
    out.mkdir(parents=True, exist_ok=True)
    name = hashlib.sha1(sig.encode()).hexdigest()[:12]
    (out / f"{name}.input").write_bytes(data)
    (out / f"{name}.txt").write_text(f"{sig}\n{type(e).__name__}: {e}\n\n{''.join(traceback.format_exception(e))}")
    print(f"FINDING {target}: {sig}: {str(e)[:200]}", file=sys.stderr, flush=True)


READERS = {"yaml_model": yaml_model, "urdf_model": urdf_model, "telemetry": telemetry, "scenario": scenario}


def check_with(reader, data: bytes) -> None:
    """Run one input through a reader: return if it is accepted or refused with one of freefloat's errors, raise
    anything else (another Python exception; a Rust panic is a PanicException, which is a BaseException)."""
    try:
        reader(data)
    except EXPECTED:
        pass


def check(target: str, data: bytes) -> None:
    check_with(READERS[target], data)


def regression_inputs(target: str) -> list[Path]:
    d = REGRESSIONS / target
    return sorted(p for p in d.iterdir() if p.is_file() and not p.name.endswith(".md")) if d.is_dir() else []


def replay() -> None:
    """Run every input of fuzz/regressions/TARGET/ once through its reader (no fuzzing, no atheris)."""
    n = 0
    for target in TARGETS:
        for p in regression_inputs(target):
            check(target, p.read_bytes())
            n += 1
    print(f"replayed {n} regression inputs: all accepted or refused with a freefloat error")


def main(argv: list[str]) -> None:
    if len(argv) == 2 and argv[1] == "--replay":
        return replay()
    if len(argv) < 2 or argv[1] not in TARGETS:
        sys.exit(
            f"usage: python fuzz/readers.py TARGET [libFuzzer options] (TARGET one of {', '.join(TARGETS)}), "
            "or python fuzz/readers.py --replay"
        )
    import atheris

    target = argv[1]
    findings = os.environ.get("FREEFLOAT_FUZZ_FINDINGS")
    seen: set[str] = set()

    def one_input(data: bytes) -> None:
        try:
            check(target, data)
        except Exception as e:  # a finding
            if not findings:
                raise  # libFuzzer stops and writes crash-<hash>
            _record(findings, target, e, data, seen)

    corpus = _seed_corpus(target)  # new inputs go to the first directory; the regressions are read as seeds
    dirs = [str(corpus)] + ([str(REGRESSIONS / target)] if regression_inputs(target) else [])
    atheris.Setup([argv[0], *argv[2:], *dirs], one_input)
    atheris.Fuzz()


if __name__ == "__main__":
    main(sys.argv)

"""Coverage-guided fuzzing (atheris, libFuzzer) of freefloat's input readers: YAML and URDF models, telemetry CSV
files and scenario files. Each target feeds mutated bytes to one reader; the reader may accept the input or refuse
it with one of freefloat's errors (InputError, ModelError, NumericalError). Anything else is a finding: another
Python exception (a traceback a user would see), a Rust panic surfacing as PanicException, or a crash of the
process (abort, segfault), which libFuzzer reports with the input that caused it.

    python fuzz/readers.py TARGET [libFuzzer options]       # TARGET: yaml_model, urdf_model, telemetry, scenario
    python fuzz/readers.py yaml_model -runs=20000            # a short run (the test suite does this)
    python fuzz/readers.py urdf_model -max_total_time=3600   # the long run (see docs/reliability.md)
    FREEFLOAT_FUZZ_FINDINGS=findings/ python fuzz/readers.py scenario -max_total_time=900   # keep going on findings

The seed corpus is built from the built-in robots (their YAML, their URDF export), a telemetry file of a short
simulation and the built-in scenarios, written to `fuzz/corpus/TARGET/` (or `$FREEFLOAT_FUZZ_CORPUS/TARGET/`) on
first use. Coverage guidance covers the Python side only (atheris instruments the freefloat package); the Rust
parsers are exercised by mutation but not instrumented, so for them this is mutation fuzzing without feedback.
"""

from __future__ import annotations

import os
import sys
import tempfile
from pathlib import Path

import atheris
import numpy as np
import pyarrow.csv as pacsv
import pyarrow.parquet as pq

# instrument freefloat's own Python code only (instrumenting numpy's bytecode costs a minute at start-up)
with atheris.instrument_imports(include=["freefloat"], enable_loader_override=False):
    import freefloat as ff
    from freefloat.io import scenario_files
    from freefloat.postcapture import scenario as pc_scenario

EXPECTED = (ff.InputError, ff.ModelError, ff.NumericalError)
TARGETS = ("yaml_model", "urdf_model", "telemetry", "scenario")
HERE = Path(__file__).resolve().parent
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
    global _TELEMETRY_MODEL
    if _TELEMETRY_MODEL is None:
        _TELEMETRY_MODEL = ff.models.load("zhang2020_2d_medium")
    f = TMP / "telemetry.csv"
    f.write_bytes(data)
    ff.io.Telemetry.from_file(f, _TELEMETRY_MODEL)


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
        m = ff.models.load("zhang2020_2d_medium")
        tr = ff.simulate(m, m.neutral(), np.zeros(m.nv), 0.05, 0.01)
        tr.to_parquet(TMP / "seed.parquet")
        pacsv.write_csv(pq.read_table(TMP / "seed.parquet"), out / "seed.csv")
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


def main(argv: list[str]) -> None:
    if len(argv) < 2 or argv[1] not in TARGETS:
        sys.exit(f"usage: python fuzz/readers.py TARGET [libFuzzer options]; TARGET one of {', '.join(TARGETS)}")
    target = argv[1]
    reader = globals()[target]

    findings = os.environ.get("FREEFLOAT_FUZZ_FINDINGS")
    seen: set[str] = set()

    def one_input(data: bytes) -> None:
        try:
            reader(data)
        except EXPECTED:
            pass
        except Exception as e:  # a finding
            if not findings:
                raise  # libFuzzer stops and writes crash-<hash>
            _record(findings, target, e, data, seen)

    corpus = _seed_corpus(target)
    atheris.Setup([argv[0], *argv[2:], str(corpus)], one_input)
    atheris.Fuzz()


if __name__ == "__main__":
    main(sys.argv)

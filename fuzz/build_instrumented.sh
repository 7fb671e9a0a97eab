#!/bin/sh
# Build freefloat's Rust extension with LLVM SanitizerCoverage, so that libFuzzer (the engine inside atheris)
# sees the edges and comparisons of the Rust code (the URDF and YAML model readers, roxmltree, serde_norway, the
# engine), not only the Python layer. Installs it, non-editable, into its own virtual environment, from its own
# Cargo target directory, so a normal (editable, uninstrumented) install of the same checkout is not touched.
#
#     sh fuzz/build_instrumented.sh [VENV]        # default VENV: ./fuzz-venv (created if missing)
#     . VENV/bin/activate && sh fuzz/long_run.sh  # long_run.sh then preloads libFuzzer (see below)
#
# How it works, and what it needs:
# - stable rustc: `-Cpasses=sancov-module` runs LLVM's coverage pass with the options given by `-Cllvm-args`
#   (inline 8-bit edge counters, the PC table libFuzzer uses to count features, and comparison tracing so it
#   learns the constants the parsers compare against). `--cfg fuzzing` is set as cargo-fuzz does.
# - `--target` is given explicitly so that RUSTFLAGS apply to the extension and its dependencies but not to
#   build scripts and proc macros (an instrumented proc macro could not be loaded by rustc).
# - debug assertions and overflow checks are on (as cargo-fuzz does): an arithmetic overflow becomes a panic,
#   which is a finding. Fat LTO is off and 16 codegen units are used to keep the build affordable.
# - The instrumented `_core` module refers to libFuzzer's `__sanitizer_cov_*` callbacks, which must be in the
#   process's global symbol table before it is imported: run Python with
#   LD_PRELOAD=$(python -c 'import atheris; print(atheris.path())')/ubsan_with_fuzzer.so
#   (libFuzzer with the UBSan runtime, which atheris ships; it does not replace malloc as the ASan one does).
#   `fuzz/long_run.sh` and `fuzz/readers.py --instrumented` do this for you.
set -eu
HERE=$(cd "$(dirname "$0")" && pwd)
ROOT=$(cd "$HERE/.." && pwd)
VENV=${1:-$ROOT/fuzz-venv}
if [ ! -x "$VENV/bin/python" ]; then
    python3 -m venv "$VENV"
fi
"$VENV/bin/pip" install -q --upgrade pip maturin atheris
# the runtime dependencies the readers need (not the test oracles)
"$VENV/bin/pip" install -q numpy scipy pyarrow pyyaml pydantic click tqdm matplotlib

export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$ROOT/target-sancov}"
export RUSTFLAGS="-Cpasses=sancov-module -Cllvm-args=-sanitizer-coverage-level=3 \
-Cllvm-args=-sanitizer-coverage-inline-8bit-counters -Cllvm-args=-sanitizer-coverage-pc-table \
-Cllvm-args=-sanitizer-coverage-trace-compares --cfg fuzzing"
export CARGO_PROFILE_RELEASE_LTO=off CARGO_PROFILE_RELEASE_CODEGEN_UNITS=16 CARGO_PROFILE_RELEASE_OPT_LEVEL=2
export CARGO_PROFILE_RELEASE_DEBUG_ASSERTIONS=true CARGO_PROFILE_RELEASE_OVERFLOW_CHECKS=true
TRIPLE=$(rustc -vV | sed -n 's/^host: //p')
WHEELS="$CARGO_TARGET_DIR/wheels"
rm -rf "$WHEELS"
(cd "$ROOT" && nice "$VENV/bin/maturin" build --release --target "$TRIPLE" -o "$WHEELS")
"$VENV/bin/pip" install -q --no-deps --force-reinstall "$WHEELS"/freefloat-*.whl

# check: the module carries coverage counters and refers to libFuzzer's callbacks
SO=$("$VENV/bin/python" -c "import importlib.util as u; print(u.find_spec('freefloat').submodule_search_locations[0])")/_core.abi3.so
n=$(nm -D --undefined-only "$SO" | grep -c '__sanitizer_cov' || true)
echo "instrumented: $SO refers to $n __sanitizer_cov_* callbacks"
[ "$n" -gt 0 ]

#!/bin/sh
# The documented long fuzzing run (docs/reliability.md), coverage-guided on the Rust side too: it uses the
# SanitizerCoverage build of the extension in VENV (made by fuzz/build_instrumented.sh if missing), runs the
# targets one after the other at low priority, in keep-going mode (each distinct Python finding is written once to
# $OUT/findings/TARGET/ and fuzzing goes on; a Rust panic or a crash stops that target and leaves
# $OUT/TARGET-crash-*), and writes a summary of each target's libFuzzer statistics to $OUT/summary.log.
#
#     sh fuzz/long_run.sh [OUT] [PLAN]
#     sh fuzz/long_run.sh fuzz-run "urdf_model:20 yaml_model:20 telemetry:10 scenario:10"   # the documented hour
#     FREEFLOAT_FUZZ_VENV=/path/to/venv sh fuzz/long_run.sh fuzz-run "yaml_model:1"           # a one-minute try
#
# PLAN is a list of TARGET:MINUTES (default: the hour above). MINUTES is libFuzzer's -max_total_time, which starts
# after the target's start-up (atheris instruments the freefloat package at import; the telemetry seed simulates).
set -u
OUT=${1:-fuzz-run}
PLAN=${2:-urdf_model:20 yaml_model:20 telemetry:10 scenario:10}
HERE=$(cd "$(dirname "$0")" && pwd)
VENV=${FREEFLOAT_FUZZ_VENV:-$(cd "$HERE/.." && pwd)/fuzz-venv}
if [ ! -x "$VENV/bin/python" ] || ! "$VENV/bin/python" -c "import freefloat" 2>&1 | grep -q __sanitizer_cov; then
    echo "no instrumented build in $VENV: building it (fuzz/build_instrumented.sh)"
    sh "$HERE/build_instrumented.sh" "$VENV" || exit 1
fi
mkdir -p "$OUT"
OUT=$(cd "$OUT" && pwd)
for item in $PLAN; do
    t=${item%%:*}
    min=${item#*:}
    echo "== $t $(date -u +%H:%M:%S) for $min min" >> "$OUT/summary.log"
    (cd "$OUT" && FREEFLOAT_FUZZ_CORPUS="$OUT/corpus" FREEFLOAT_FUZZ_FINDINGS="$OUT/findings" \
        nice -n 19 "$VENV/bin/python" "$HERE/readers.py" "$t" -max_total_time=$((min * 60)) -print_final_stats=1 \
        -artifact_prefix="$OUT/$t-" > "$OUT/$t.log" 2>&1)
    rc=$?
    echo "   exit $rc $(date -u +%H:%M:%S); $(grep -c '^FINDING' "$OUT/$t.log") findings; corpus $(ls "$OUT/corpus/$t" | wc -l) files" >> "$OUT/summary.log"
    grep -E '^INFO: (Loaded|=+ )|^INFO: +[0-9]+ files found|INITED|^stat::|^Done|^#[0-9]+.*(DONE)' "$OUT/$t.log" >> "$OUT/summary.log"
    grep -E '^#[0-9]+.*pulse' "$OUT/$t.log" | tail -1 >> "$OUT/summary.log"
done

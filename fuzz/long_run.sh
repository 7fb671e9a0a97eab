#!/bin/sh
# The documented long fuzzing run (docs/reliability.md): each of the four readers for MINUTES minutes (default 15,
# so one hour in all), at low priority, in keep-going mode (each distinct Python finding is written once to
# $OUT/findings/TARGET/ and fuzzing goes on; a Rust panic or a crash still stops that target and leaves crash-*).
#     sh fuzz/long_run.sh [MINUTES] [OUT]
set -u
MIN=${1:-15}
OUT=${2:-fuzz-run}
HERE=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$OUT"
OUT=$(cd "$OUT" && pwd)
for t in scenario telemetry yaml_model urdf_model; do
    echo "== $t $(date -u +%H:%M:%S) for $MIN min" >> "$OUT/summary.log"
    (cd "$OUT" && FREEFLOAT_FUZZ_CORPUS="$OUT/corpus" FREEFLOAT_FUZZ_FINDINGS="$OUT/findings" \
        nice -n 19 python "$HERE/readers.py" "$t" -max_total_time=$((MIN * 60)) -print_final_stats=1 \
        -artifact_prefix="$OUT/$t-" > "$OUT/$t.log" 2>&1)
    echo "   exit $? $(date -u +%H:%M:%S); $(grep -c '^FINDING' "$OUT/$t.log") findings; corpus $(ls "$OUT/corpus/$t" | wc -l) files" >> "$OUT/summary.log"
    grep -E '^(stat::|Done|#[0-9]+.*(DONE|pulse))' "$OUT/$t.log" | tail -12 >> "$OUT/summary.log"
done

#!/usr/bin/env bash
# before_after.sh OLD_FRETDYN NEW_FRETDYN [REPS] [PERF_DIR]
#
# Steps per second of two fretdyn binaries and of the C yardstick (PERF_DIR/step_ref.c, built
# here as side_by_side.sh builds it) on case S1, for the four tangential methods, interleaved
# C, old, new, C, old, new, ... REPS times (default 5) per method. Each program's own time-loop
# steps/s (fretdyn: summary.json performance.steps_per_second). Prints a markdown table of the
# medians (min–max) and of the median per-triple ratios old/C and new/C, then the ratios of
# the best runs (max steps/s of each program over the REPS runs: the run least disturbed by
# whatever else shares the machine; steadier than the medians on a noisy machine).
#   bash scripts/before_after.sh /tmp/old/target/release/fretdyn target/release/fretdyn 5
set -euo pipefail
OLD=$(realpath "${1:?usage: before_after.sh OLD NEW [REPS] [PERF_DIR]}")
NEW=$(realpath "${2:?usage: before_after.sh OLD NEW [REPS] [PERF_DIR]}")
REPS=${3:-5}
PERF=$(realpath "${4:-$(dirname "$0")/../../shared/perf}")
base=/dev/shm; [ -d "$base" ] && [ -w "$base" ] || base=${TMPDIR:-/tmp}
WORK=$(mktemp -d "$base/before_after.XXXXXX")
trap 'rm -rf "$WORK"' EXIT
gcc -std=c99 -O3 -march=native -Wall -o "$WORK/step_ref" "$PERF/step_ref.c" -lm
fd() {  # fd BINARY CASE -> steps/s
  rm -rf "$WORK/run"
  "$1" run "$2" -o "$WORK/run" --no-plots --quiet
  python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['performance']['steps_per_second'])" "$WORK/run/summary.json"
}
: > "$WORK/rows.txt"
for method in gs_radial gs_exact active_set penalty; do
  case_file=$PERF/fretdyn_cases/s1/s1_${method}_200000.toml
  for i in $(seq 1 "$REPS"); do
    c=$("$WORK/step_ref" "$PERF/s1_case.bin" 200000 | awk '$1=="steps_per_s"{print $2}')
    o=$(fd "$OLD" "$case_file")
    n=$(fd "$NEW" "$case_file")
    echo "$method $c $o $n" >> "$WORK/rows.txt"
    echo "$method $i/$REPS: C $c old $o new $n" >&2
  done
done
python3 - "$WORK/rows.txt" <<'PY'
import statistics as st, sys
rows = [l.split() for l in open(sys.argv[1]) if l.strip()]
print("| S1, method | C steps/s | before steps/s | after steps/s | before/C | after/C | after/before |")
print("|---|---|---|---|---|---|---|")
for m in dict.fromkeys(r[0] for r in rows):
    c, o, n = ([float(r[k]) for r in rows if r[0] == m] for k in (1, 2, 3))
    med = lambda x: f"{st.median(x):.3g} ({min(x):.3g}–{max(x):.3g})"
    rat = lambda a, b: f"{st.median([x / y for x, y in zip(a, b)]):.3f}"
    print(f"| {m} | {med(c)} | {med(o)} | {med(n)} | {rat(o, c)} | {rat(n, c)} | {rat(n, o)} |")
print()
print("| S1, method | best C steps/s | best before | best after | before/C | after/C | after/before |")
print("|---|---|---|---|---|---|---|")
for m in dict.fromkeys(r[0] for r in rows):
    c, o, n = (max(float(r[k]) for r in rows if r[0] == m) for k in (1, 2, 3))
    print(f"| {m} | {c:.3g} | {o:.3g} | {n:.3g} | {o / c:.3f} | {n / c:.3f} | {n / o:.3f} |")
PY

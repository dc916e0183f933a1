#!/usr/bin/env bash
# pairs.sh REPS CASE OLD_FRETDYN NEW_FRETDYN
#
# Time-loop steps/s of two fretdyn binaries on one case, run alternately on core 1 (`taskset`),
# the order swapped every pair, REPS pairs (output on /dev/shm, no plots); prints the median of
# the per-pair ratios new/old and its quartiles. The steps/s are the runs' own
# (summary.json performance.steps_per_second). On a shared machine read the quartiles: an
# unchanged binary against itself spreads by ±5–10 % here.
#   bash scripts/pairs.sh 30 examples/tube_multispan.toml /tmp/old/fretdyn target/release/fretdyn
set -euo pipefail
REPS=${1:?usage: pairs.sh REPS CASE OLD NEW}
CASE=${2:?usage: pairs.sh REPS CASE OLD NEW}
OLD=${3:?usage: pairs.sh REPS CASE OLD NEW}
NEW=${4:?usage: pairs.sh REPS CASE OLD NEW}
base=/dev/shm; [ -d "$base" ] && [ -w "$base" ] || base=${TMPDIR:-/tmp}
WORK=$(mktemp -d "$base/pairs.XXXXXX")
trap 'rm -rf "$WORK"' EXIT
rate() {
  taskset -c 1 "$1" run "$CASE" -o "$WORK/out" -q --no-plots 2>/dev/null
  python3 -c "import json; print(json.load(open('$WORK/out/summary.json'))['performance']['steps_per_second'])"
}
ratios=""
for r in $(seq "$REPS"); do
  if [ $((r % 2)) = 0 ]; then a=$(rate "$OLD"); b=$(rate "$NEW"); else b=$(rate "$NEW"); a=$(rate "$OLD"); fi
  ratios="$ratios $(python3 -c "print($b / $a)")"
done
python3 -c "
import statistics
x = sorted(float(v) for v in '$ratios'.split())
print('new/old median %.3f  quartiles %.3f-%.3f  pairs %d' % (statistics.median(x), x[len(x) // 4], x[3 * len(x) // 4], len(x)))"

#!/usr/bin/env bash
# states.sh [ROUNDS] [PERF_DIR]
#
# The speed of a shared machine comes and goes: a run of S1 goes at one of two speeds, and may
# switch within the run. This times both programs in chunks of 100 000 steps within runs of
# 2 000 000 (C: step_ref.c with a timer added around every chunk, built here; fretdyn: the
# example `step_rate`), interleaved C, fretdyn radial, exact, Active Set, ROUNDS times
# (default 6), and prints per program the 90th, 50th and 10th percentiles of the chunk rates,
# and the ratios fretdyn/C of the 90th percentiles (both programs undisturbed) and of the 10th
# (both slowed down). Needs gcc, cargo and python3 (standard library only). About 1-2 minutes.
#   bash scripts/states.sh 6
set -euo pipefail
ROUNDS=${1:-6}
HERE=$(cd "$(dirname "$0")" && pwd)
PERF=$(realpath "${2:-$HERE/../../shared/perf}")
WORK=$(mktemp -d "${TMPDIR:-/tmp}/states.XXXXXX")
trap 'rm -rf "$WORK"' EXIT
(cd "$HERE/.." && cargo build --release --locked --example step_rate -p fretdyn 2>&1 | grep -E "^error" -A5 || true)
RATE=$HERE/../target/release/examples/step_rate
# the C step with a timer around every 1/20 of the run (stderr), its results unchanged
python3 - "$PERF/step_ref.c" "$WORK/step_chunks.c" <<'PY'
import sys
s = open(sys.argv[1]).read()
loop = "    for (long long n = 0; n < nsteps; n++) {\n"
assert s.count(loop) == 1, "step_ref.c: the time loop was not found"
s = s.replace(loop, """    struct timespec tc0, tc1; clock_gettime(CLOCK_MONOTONIC, &tc0);
    long long chunk = nsteps / 20;
    for (long long n = 0; n < nsteps; n++) {
        if (n > 0 && n % chunk == 0) {
            clock_gettime(CLOCK_MONOTONIC, &tc1);
            fprintf(stderr, "%.3f ", chunk / ((tc1.tv_sec - tc0.tv_sec) + 1e-9 * (tc1.tv_nsec - tc0.tv_nsec)) / 1e6);
            tc0 = tc1;
        }
""")
open(sys.argv[2], "w").write(s)
PY
gcc -std=c99 -O3 -march=native -o "$WORK/step_chunks" "$WORK/step_chunks.c" -lm
# S1 over 2 000 000 steps: the 200 000-step cases, ten times longer, the basis by its path
for m in gs_radial gs_exact active_set; do
  sed -e "s|^duration = .*|duration = $(python3 -c "import re,sys; t=open('$PERF/fretdyn_cases/s1/s1_${m}_200000.toml').read(); print(repr(10*float(re.search(r'^duration = ([0-9.e+-]+)', t, re.M).group(1))))")|" \
      -e "s|file = \"basis_s1.npz\"|file = \"$PERF/fretdyn_cases/s1/basis_s1.npz\"|" \
      -e "s|^every = .*|every = 2000000|" "$PERF/fretdyn_cases/s1/s1_${m}_200000.toml" > "$WORK/$m.toml"
done
for i in $(seq 1 "$ROUNDS"); do
  echo "C $("$WORK/step_chunks" "$PERF/s1_case.bin" 2000000 2>&1 >/dev/null)" >> "$WORK/rates.txt"
  for m in gs_radial gs_exact active_set; do
    echo "$m $("$RATE" "$WORK/$m.toml" 20)" >> "$WORK/rates.txt"
  done
  echo "round $i/$ROUNDS" >&2
done
python3 - "$WORK/rates.txt" <<'PY'
import sys, collections
rates = collections.defaultdict(list)
for line in open(sys.argv[1]):
    name, *values = line.split()
    rates[name] += [float(v) for v in values]
def pct(v, q):
    v = sorted(v)
    return v[min(len(v) - 1, int(q * len(v)))]
c = rates["C"]
print("| program | chunks | p90 (10⁶ steps/s) | median | p10 | p90 / C p90 | p10 / C p10 |")
print("|---|---|---|---|---|---|---|")
for name in ["C", "gs_radial", "gs_exact", "active_set"]:
    v = rates[name]
    print(f"| {name} | {len(v)} | {pct(v, .9):.2f} | {pct(v, .5):.2f} | {pct(v, .1):.2f} "
          f"| {pct(v, .9) / pct(c, .9):.3f} | {pct(v, .1) / pct(c, .1):.3f} |")
PY

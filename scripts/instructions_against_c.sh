#!/usr/bin/env bash
# instructions_against_c.sh PERF_DIR FRETDYN_PROFILING_BINARY [STEPS]
#
# Instructions per time step of fretdyn and of the plain C step (`PERF_DIR/step_ref.c`) on the
# cases of `PERF_DIR` (S1 with fretdyn's four methods against C's Gauss–Seidel radial, and
# the 16 grid cases with Gauss–Seidel radial), both counted by callgrind over the same first
# STEPS steps (default 10 000) of the same trajectory. Exact and repeatable where timings on a
# shared machine are not (the machine runs at two speeds, docs/dev/PERFORMANCE_LOG.md): the ratio
# C/fretdyn of this table is the time ratio fretdyn/C that a machine running both programs
# at the same instructions per cycle would give.
#   fretdyn: callgrind's inclusive count of `Simulation::steps` (the time loop, every
#     statistic, the energy balance and the diagnostics on; no set-up, no file output),
#     divided by the run's steps;
#   C: (program total over STEPS steps − program total over 1 step) / (STEPS − 1) (its steps
#     2..STEPS: `step_ref` reads 0 steps as its default length), `sin` included
#     (fretdyn forms its harmonic load by a rotation instead).
# Build fretdyn's `profiling` profile first (`cargo build --profile profiling --locked -p
# fretdyn-cli`). Needs gcc, valgrind and python3. About 10 minutes.
#   bash scripts/instructions_against_c.sh ../shared/perf target/profiling/fretdyn
set -euo pipefail
PERF=${1:?usage: instructions_against_c.sh PERF_DIR FRETDYN_BINARY [STEPS]}
FD=${2:?usage: instructions_against_c.sh PERF_DIR FRETDYN_BINARY [STEPS]}
STEPS=${3:-10000}
WORK=$(mktemp -d "${TMPDIR:-/tmp}/iac.XXXXXX")
trap 'rm -rf "$WORK"' EXIT
gcc -std=c99 -O3 -march=native -o "$WORK/step_ref" "$PERF/step_ref.c" -lm
mkdir -p "$WORK/cases"
cp -r "$PERF/fretdyn_cases/." "$WORK/cases/"

total() { # callgrind's program total of a command
  valgrind --tool=callgrind --callgrind-out-file="$WORK/cg.out" "$@" >/dev/null 2>&1
  callgrind_annotate "$WORK/cg.out" 2>/dev/null | grep 'PROGRAM TOTALS' | awk '{gsub(",", "", $1); print $1}'
}
c_per_step() { # C's instructions per step on BIN
  local one full
  one=$(total "$WORK/step_ref" "$1" 1)
  full=$(total "$WORK/step_ref" "$1" "$STEPS")
  python3 -c "print(round(($full - $one) / ($STEPS - 1)))"
}
fretdyn_per_step() { # fretdyn's instructions per step on CASE, shortened to STEPS steps
  local short="${1%.toml}_short.toml"
  python3 - "$1" "$short" "$STEPS" <<'EOF'
import re, sys
src, dst, n = sys.argv[1], sys.argv[2], int(sys.argv[3])
text = open(src).read()
dt = float(re.search(r'^dt\s*=\s*([^\s#]+)', text, re.M).group(1))
text = re.sub(r'^duration\s*=.*$', f'duration = {n * dt!r}', text, count=1, flags=re.M)
text = re.sub(r'^every\s*=.*$', f'every = {n}', text, count=1, flags=re.M)
open(dst, 'w').write(text)
EOF
  valgrind --tool=callgrind --callgrind-out-file="$WORK/cg.out" "$FD" run "$short" \
    -o "$WORK/run" -q --no-plots >/dev/null 2>&1
  local n steps
  n=$(callgrind_annotate --inclusive=yes "$WORK/cg.out" 2>/dev/null |
    grep -E 'Simulation::steps? \[' | head -1 | awk '{gsub(",", "", $1); print $1}')
  steps=$(python3 -c "import json; print(json.load(open('$WORK/run/summary.json'))['time']['steps'])")
  [ "$steps" = "$STEPS" ] || { echo "fretdyn ran $steps steps, not $STEPS" >&2; exit 1; }
  python3 -c "print(round($n / $steps))"
}

echo "| case | fretdyn method | C instructions/step | fretdyn instructions/step | C/fretdyn |"
echo "|---|---|---|---|---|"
c=$(c_per_step "$PERF/s1_case.bin")
for m in gs_radial gs_exact active_set penalty; do
  f=$(fretdyn_per_step "$WORK/cases/s1/s1_${m}_20000.toml")
  echo "| S1 | $m | $c | $f | $(python3 -c "print('%.3f' % ($c / $f))") |"
done
for p in 10 30 100 200; do
  for k in 1 5 20 50; do
    c=$(c_per_step "$PERF/grid/p${p}_c${k}.bin")
    f=$(fretdyn_per_step "$WORK/cases/grid/p${p}_c${k}_gs_radial_50000.toml")
    echo "| p${p}_c${k} | gs_radial | $c | $f | $(python3 -c "print('%.3f' % ($c / $f))") |"
  done
done

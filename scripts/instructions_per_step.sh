#!/usr/bin/env bash
# instructions_per_step.sh FRETDYN_BINARY CASE
#
# Instructions per time step of one run: callgrind's inclusive count of `Simulation::steps`
# (the time loop: no set-up, no file output) divided by the run's steps (summary.json). Exact
# and repeatable where timings on a shared machine are not: the figure for changes of a few
# per cent in docs/dev/PERFORMANCE_LOG.md. Use the `profiling` build (the release build's machine
# code with symbols): `cargo build --profile profiling --locked -p fretdyn-cli`. Needs
# valgrind and python3. A 20 000-step run takes about a minute.
#   bash scripts/instructions_per_step.sh target/profiling/fretdyn examples/tube_multispan.toml
set -euo pipefail
FD=${1:?usage: instructions_per_step.sh FRETDYN_BINARY CASE}
CASE=${2:?usage: instructions_per_step.sh FRETDYN_BINARY CASE}
WORK=$(mktemp -d "${TMPDIR:-/tmp}/ips.XXXXXX")
trap 'rm -rf "$WORK"' EXIT
valgrind --tool=callgrind --callgrind-out-file="$WORK/cg.out" "$FD" run "$CASE" -o "$WORK/run" \
  -q --no-plots >/dev/null 2>&1
n=$(callgrind_annotate --inclusive=yes "$WORK/cg.out" 2>/dev/null |
  grep -E 'Simulation::steps? \[' | head -1 | awk '{gsub(",", "", $1); print $1}')
steps=$(python3 -c "import json; print(json.load(open('$WORK/run/summary.json'))['time']['steps'])")
python3 -c "print(round($n / $steps))"

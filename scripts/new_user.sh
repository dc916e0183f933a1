#!/usr/bin/env bash
# A new user's first hour, as a script: from a clone to a tube's wear depth with its
# uncertainty, each step timed. docs/GETTING_STARTED.md walks through the same steps by hand.
#
#   bash scripts/new_user.sh [WORKDIR]     # everything it writes goes to WORKDIR (default: target/new-user in the clone)
#
# It needs what the README's prerequisites install (Rust, a C compiler, pkg-config, the netCDF
# library, Python >= 3.9 with venv) and the network for PyPI; it checks them first. Steps:
#   1. build the `fretdyn` command (cargo build --release)
#   2. the Python package into a venv of its own (compiled from crates/fretdyn-python; with
#      FRETDYN_WHEEL=path/to/fretdyn-….whl installed from that wheel instead, as on a machine
#      without Rust — .ci/run does that with the wheel scripts/build_wheel.sh built)
#   3. `fretdyn run` of the multi-span tube, then its results read with numpy
#   4. a seeded Monte-Carlo study (clearances drawn per plate, 16 short samples) and its P50/P95
#   5. a service life, `fretdyn life` of the multi-span tube to 40 years
#   6. the same from Python: fretdyn.run, fretdyn.sweep of a dict study, fretdyn.percentiles,
#      fretdyn.life
# and prints the wall time of each step (.ci/run runs it, so CI's log shows them).
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
# WORKDIR and FRETDYN_WHEEL as given, relative to the folder this is called from
work=${1:-$repo/target/new-user}
mkdir -p "$work"
work=$(cd "$work" && pwd)
wheel=${FRETDYN_WHEEL:-}
if [ -n "$wheel" ]; then
  [ -f "$wheel" ] || { echo "new_user.sh: FRETDYN_WHEEL=$wheel: no such wheel" >&2; exit 1; }
  wheel=$(cd "$(dirname "$wheel")" && pwd)/$(basename "$wheel")
fi
cd "$repo"

say() { printf '\n== %s\n' "$*"; }
fail() { echo "new_user.sh: $*" >&2; exit 1; }

# --- prerequisites: say what is missing and how to get it (README, "Prerequisites")
missing=()
command -v cargo >/dev/null || missing+=("cargo (Rust: curl --proto '=https' --tlsv1.2 -sSf https://sh.rustup.rs | sh)")
command -v cc >/dev/null || missing+=("a C compiler, cc (Debian/Ubuntu: build-essential)")
command -v pkg-config >/dev/null || missing+=("pkg-config")
pkg-config --exists netcdf 2>/dev/null || missing+=("the netCDF C library and headers (Debian/Ubuntu: libnetcdf-dev)")
command -v python3 >/dev/null || missing+=("python3 (>= 3.9)")
python3 -c "import venv, ensurepip" 2>/dev/null || missing+=("Python's venv module (Debian/Ubuntu: python3-venv)")
if [ ${#missing[@]} -gt 0 ]; then
  printf 'missing: %s\n' "${missing[@]}" >&2
  fail "install the prerequisites (README, \"Prerequisites\": one line per distribution), then run this again"
fi

# --- each step timed; the table at the end
names=()
seconds=()
timed() {
  local name=$1
  shift
  say "$name"
  local t0 t1
  t0=$(date +%s.%N)
  "$@"
  t1=$(date +%s.%N)
  names+=("$name")
  seconds+=("$(python3 -c "print(f'{$t1 - $t0:.1f}')")")
  echo "-- $name: ${seconds[-1]} s"
}

fd=$repo/target/release/fretdyn
venv=$work/venv
py=$venv/bin/python
examples=$repo/examples

build() {
  cargo build --release --locked -p fretdyn-cli
  "$fd" --version
}

python_package() {
  rm -rf "$venv"
  python3 -m venv "$venv"
  "$venv/bin/pip" install --quiet --disable-pip-version-check --upgrade pip
  if [ -n "$wheel" ]; then
    "$venv/bin/pip" install --quiet --disable-pip-version-check --only-binary=:all: "$wheel[pandas]"
  else
    "$venv/bin/pip" install --quiet --disable-pip-version-check "$repo/crates/fretdyn-python[pandas]"
  fi
  # the installed package, not the source tree
  (cd / && "$py" -c "import fretdyn, sys; assert fretdyn.__file__.startswith(sys.prefix); print('fretdyn from', fretdyn.__file__)")
}

run_tube() {
  rm -rf "$work/run"
  "$fd" run "$examples/tube_multispan.toml" -o "$work/run"
}

read_run() {
  "$py" - "$work/run" <<'PY'
import json, sys
import numpy as np
folder = sys.argv[1]
r = np.load(f"{folder}/results.npz")
s = json.load(open(f"{folder}/summary.json"))
print(f"{len(r['t'])} samples of {r['contact_normal_force'].shape[1]} contacts, t up to {r['t'][-1]:.2f} s")
for c in s["contacts"]:
    w, se = c["wear_work_rate"], c.get("wear_work_rate_se")
    se = f" ± {se * 1e3:.3g}" if se is not None else ""
    print(f"{c['name']:>8}: wear work rate {w * 1e3:.3g}{se} mW, "
          f"max normal force {c['normal_force_max']:.1f} N")
PY
}

study() {
  rm -rf "$work/study"
  # a short study of the README's kind: each plate's clearance drawn from five classes,
  # 16 samples of 0.3 s (examples/study_clearance_probabilistic.toml is the full one)
  cat >"$work/study.toml" <<EOF
base = "$examples/tube_multispan.toml"
samples = 16
seed = 2026

[[parameters]]
key = "contacts.*.obstacle.clearance"
independent = true
distribution = { type = "discrete", values = [1e-4, 1.5e-4, 2e-4, 2.5e-4, 3e-4] }

[[parameters]]
key = "time.duration"
values = [0.3]

[percentiles]
statistics = ["wear_work_rate"]
levels = [50, 95]
EOF
  "$fd" sweep "$work/study.toml" -o "$work/study" -q
  echo "percentiles.csv:"
  cut -d, -f1-8 "$work/study/percentiles.csv" | head -6
}

life() {
  rm -rf "$work/life"
  "$fd" life "$examples/tube_multispan_life.toml" -o "$work/life"
}

from_python() {
  (cd "$repo" && "$py" - "$work" <<'PY'
import sys, time
import fretdyn
work = sys.argv[1]

t0 = time.perf_counter()
case = fretdyn.Case.from_file("examples/tube_multispan.toml")
r = fretdyn.run(case)
print(f"fretdyn.run: {len(r.t)} samples; wear work rates (mW):",
      {name: round(float(w) * 1e3, 3) for name, w in zip(case.contact_names, r.contacts["wear_work_rate"])},
      f"({time.perf_counter() - t0:.1f} s)")

t0 = time.perf_counter()
study = {"base": case.with_(**{"time.duration": 0.3}), "samples": 8, "seed": 7,
         "parameters": [{"key": "contacts.*.friction.mu",
                         "distribution": {"type": "uniform", "low": 0.2, "high": 0.4}}],
         "percentiles": {"statistics": ["wear_work_rate"], "levels": [50, 95]}}
table = f"{work}/python_study.csv"
t = fretdyn.sweep(study, table, fresh=True)
print(f"fretdyn.sweep: {len(t)} runs ({time.perf_counter() - t0:.1f} s)")
p = fretdyn.percentiles(study, table)
for row in p.head(4).itertuples():                 # a DataFrame, as sweep's table
    print(f"  {row.column} P{row.level}: {row.estimate * 1e3:.3g} mW")

t0 = time.perf_counter()
life = fretdyn.life("examples/tube_multispan_life.toml", output=f"{work}/python_life")
print(f"fretdyn.life ({time.perf_counter() - t0:.1f} s): tube depth at the end ± its "
      "standard error, µm")
print((life.summary[["tube_depth", "tube_depth_se"]] * 1e6).round(2).to_string())
PY
  )
}

timed "1. build the fretdyn command" build
if [ -n "$wheel" ]; then from="from the wheel $(basename "$wheel")"; else from="compiled from the clone"; fi
timed "2. the Python package into a venv, $from" python_package
timed "3a. fretdyn run examples/tube_multispan.toml" run_tube
timed "3b. its results, read with numpy" read_run
timed "4. a seeded study, 16 samples, and its percentiles" study
timed "5. fretdyn life examples/tube_multispan_life.toml" life
timed "6. the same from Python (run, sweep, percentiles, life)" from_python

say "wall times ($(nproc) cores, $(date -u +'%Y-%m-%d %H:%M UTC'))"
for i in "${!names[@]}"; do
  printf '%8s s  %s\n' "${seconds[$i]}" "${names[$i]}"
done | tee "$work/timings.txt"

#!/usr/bin/env bash
# Times the README's two commands from a fresh clone with an empty target folder, as a newcomer
# meets them: `cargo run --release -- run`, then `cargo test --release` (which should reuse the
# first build and compile only the test programs). Prints the wall time of each and how many
# crates the second one had to compile.
#   bash scripts/time_commands.sh
set -euo pipefail
src=$(cd "$(dirname "$0")/.." && pwd)
d=$(mktemp -d)
trap 'rm -rf "$d"' EXIT
git clone -q "$src" "$d/p"
cd "$d/p"
cargo fetch --locked >/dev/null 2>&1
t0=$(date +%s.%N)
cargo run --release --locked -q -- run -o "$d/demo" --quiet
t1=$(date +%s.%N)
cargo test --release --locked --no-run 2>"$d/test_build.log"
t2=$(date +%s.%N)
cargo test --release --locked -q >/dev/null 2>&1
t3=$(date +%s.%N)
compiled=$(grep -c '^ *Compiling' "$d/test_build.log" || true)
printf 'cargo run --release -- run : %.0f s (build and demo)\n' "$(echo "$t1 - $t0" | bc)"
printf 'cargo test --release       : %.0f s to build the tests (%s crates compiled: %s), %.0f s to run them\n' \
  "$(echo "$t2 - $t1" | bc)" "$compiled" "$(grep '^ *Compiling' "$d/test_build.log" | awk '{print $2}' | tr '\n' ' ')" \
  "$(echo "$t3 - $t2" | bc)"
echo "(machine: $(nproc) cores, $(uname -m); $(rustc --version))"

#!/usr/bin/env bash
# Builds the Python package as one wheel that installs without Rust:
#
#   bash scripts/build_wheel.sh            # -> target/wheels/fretdyn-<version>-cp39-abi3-manylinux_2_28_<arch>.whl
#   bash scripts/build_wheel.sh DIR        # the wheel in DIR instead
#
# Needs Rust (rustup) and Python >= 3.9 on the machine that builds; the wheel then installs with
# pip on any x86-64 Linux with CPython >= 3.9 and glibc >= 2.28 (RHEL 8, Debian 10, Ubuntu 20.04
# and later), no compiler needed there (README, "The Python package from a wheel").
#
# maturin builds the extension against the stable ABI (abi3: one file for every CPython >= 3.9),
# and links it with zig (the ziglang package) against glibc 2.28's symbols rather than this
# machine's, so that it is a manylinux_2_28 wheel. maturin and ziglang are installed in a venv
# of their own (target/wheel-build-venv), not in your Python. .ci/run builds its wheel with this
# script, so the command documented here is the one CI tests.
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-target/wheels}

venv=target/wheel-build-venv
[ -x "$venv/bin/python" ] || python3 -m venv "$venv"
"$venv/bin/pip" install --quiet --disable-pip-version-check maturin ziglang

# only fretdyn's wheels are removed from DIR (an older version's would make two)
mkdir -p "$out"
rm -f "$out"/fretdyn-*.whl
PATH="$PWD/$venv/bin:$PATH" maturin build --release --locked --zig --compatibility manylinux_2_28 \
  -m crates/fretdyn-python/Cargo.toml -o "$out"

shopt -s nullglob
wheels=("$out"/fretdyn-*.whl)
case "${#wheels[@]}:${wheels[*]}" in
  1:*-cp39-abi3-manylinux_2_28_*.whl) echo "wheel: ${wheels[0]} ($(du -h "${wheels[0]}" | cut -f1))" ;;
  *) echo "expected one cp39-abi3-manylinux_2_28 wheel in $out, got: ${wheels[*]:-none}" >&2; exit 1 ;;
esac

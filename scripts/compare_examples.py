#!/usr/bin/env python3
"""Runs every example case with two fretdyn binaries and compares their results bit for bit.

    python3 scripts/compare_examples.py OLD_BINARY NEW_BINARY [--out DIR] [--only NAME ...]

For each `examples/*.toml` case: `fretdyn run CASE -o DIR --quiet --no-plots` with both binaries,
then every array of `results.npz` must be identical (same shape, dtype and bits; NaN equal to
NaN), and `summary.json` identical but for what measures the machine (wall time, steps/s). For
each study file (`base = ...`): `fretdyn sweep` with both, and `study.csv` identical but for its
wall-time and steps/s columns (and the fingerprint of its inputs). Prints one line per example and exits 1 if any differs.

With `--rtol X`, a change that alters round-off only (a different summation order) is measured
instead: each example prints the largest relative difference of its arrays (max |Δ| / max |x| of
each array) and of the numbers of its summary (|Δ| / max(|a|, |b|)), and passes when it is at
most X.

Use it to show that a refactoring changed no result: build the old revision into one target
folder (`git worktree add /tmp/old REV && cargo build --release --manifest-path /tmp/old/Cargo.toml`)
and compare with the new build.
"""

import argparse
import csv
import json
import pathlib
import subprocess
import sys
import tomllib

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parent.parent
MACHINE_KEYS = {"wall_time_s", "steps_per_second", "wall_time", "performance"}
# the fingerprint of a study row's inputs (from [3.1]; absent from older tables): not a result
INPUT_KEYS = {"fingerprint"}


def strip_machine(value):
    """The summary without what depends on the machine's speed."""
    if isinstance(value, dict):
        return {k: strip_machine(v) for k, v in value.items() if k not in MACHINE_KEYS}
    if isinstance(value, list):
        return [strip_machine(v) for v in value]
    return value


def first_difference(a, b, path="summary"):
    if type(a) is not type(b):
        return f"{path}: {a!r} != {b!r}"
    if isinstance(a, dict):
        for k in sorted(set(a) | set(b)):
            if k not in a or k not in b:
                return f"{path}.{k}: present in one only"
            d = first_difference(a[k], b[k], f"{path}.{k}")
            if d:
                return d
        return None
    if isinstance(a, list):
        if len(a) != len(b):
            return f"{path}: lengths {len(a)} != {len(b)}"
        for i, (x, y) in enumerate(zip(a, b)):
            d = first_difference(x, y, f"{path}[{i}]")
            if d:
                return d
        return None
    return None if a == b else f"{path}: {a!r} != {b!r}"


def worst_relative(a, b, path="summary"):
    """Largest relative difference between two JSON values of the same shape, and where."""
    if isinstance(a, dict) and isinstance(b, dict):
        best = (0.0, None)
        for k in sorted(set(a) & set(b)):
            best = max(best, worst_relative(a[k], b[k], f"{path}.{k}"), key=lambda x: x[0])
        return best
    if isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
        best = (0.0, None)
        for i, (x, y) in enumerate(zip(a, b)):
            best = max(best, worst_relative(x, y, f"{path}[{i}]"), key=lambda x: x[0])
        return best
    if isinstance(a, (int, float)) and isinstance(b, (int, float)) and not isinstance(a, bool):
        scale = max(abs(a), abs(b))
        return ((abs(a - b) / scale if scale > 0 else 0.0), path)
    return (0.0, None) if a == b else (float("inf"), path)


def relative_npz(a, b):
    ra, rb = np.load(a), np.load(b)
    best = (0.0, None)
    for key in ra.files:
        x, y = ra[key].astype(float), rb[key].astype(float)
        if x.shape != y.shape:
            return (float("inf"), key)
        scale = np.nanmax(np.abs(x)) if x.size else 0.0
        d = np.nanmax(np.abs(x - y)) if x.size else 0.0
        best = max(best, ((d / scale) if scale > 0 else 0.0, key), key=lambda t: t[0])
    return best


def compare_npz(a, b):
    ra, rb = np.load(a), np.load(b)
    if sorted(ra.files) != sorted(rb.files):
        return f"keys {sorted(ra.files)} != {sorted(rb.files)}"
    for key in ra.files:
        x, y = ra[key], rb[key]
        if x.shape != y.shape or x.dtype != y.dtype:
            return f"{key}: shape/dtype {x.shape} {x.dtype} != {y.shape} {y.dtype}"
        if x.dtype.kind == "f":
            same = np.array_equal(x.view(np.uint64 if x.itemsize == 8 else np.uint32),
                                  y.view(np.uint64 if y.itemsize == 8 else np.uint32))
            if not same:
                diff = np.nanmax(np.abs(x - y)) if x.size else 0.0
                return f"{key}: differs (max |Δ| = {diff:.3e})"
        elif not np.array_equal(x, y):
            return f"{key}: differs"
    return None


def run(binary, args):
    p = subprocess.run([str(binary), *args], cwd=ROOT, capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError(f"{binary} {' '.join(args)} exited {p.returncode}: {p.stderr.strip()}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("old", type=pathlib.Path)
    ap.add_argument("new", type=pathlib.Path)
    ap.add_argument("--out", type=pathlib.Path, default=ROOT / "target" / "compare_examples")
    ap.add_argument("--only", nargs="*", help="example stems to compare (default: all)")
    ap.add_argument("--rtol", type=float, help="measure relative differences, pass at most this")
    args = ap.parse_args()
    failures = 0
    for case in sorted((ROOT / "examples").glob("*.toml")):
        if args.only and case.stem not in args.only:
            continue
        is_study = "base" in tomllib.loads(case.read_text())
        dirs = [args.out / tag / case.stem for tag in ("old", "new")]
        try:
            for binary, d in zip((args.old, args.new), dirs):
                if is_study:
                    run(binary, ["sweep", str(case), "-o", str(d), "--quiet"])
                else:
                    run(binary, ["run", str(case), "-o", str(d), "--quiet", "--no-plots"])
        except RuntimeError as e:
            print(f"{case.name}: FAILED to run: {e}")
            failures += 1
            continue
        if is_study:
            rows = []
            for d in dirs:
                with open(d / "study.csv", newline="") as f:
                    rows.append([{k: v for k, v in r.items()
                                  if "wall" not in k and k not in MACHINE_KEYS | INPUT_KEYS}
                                 for r in csv.DictReader(f)])
            rows = [sorted(r, key=lambda x: json.dumps(x, sort_keys=True)) for r in rows]
            diff = None if rows[0] == rows[1] else "study.csv differs"
        elif args.rtol is not None:
            s = [strip_machine(json.loads((d / "summary.json").read_text())) for d in dirs]
            arrays = relative_npz(dirs[0] / "results.npz", dirs[1] / "results.npz")
            summary = worst_relative(s[0], s[1])
            worst = max(arrays, summary, key=lambda t: t[0])
            ok = worst[0] <= args.rtol
            print(f"{case.name}: {'ok' if ok else 'DIFFERENT'}: largest relative difference "
                  f"{worst[0]:.1e} ({worst[1]}); arrays {arrays[0]:.1e}, summary {summary[0]:.1e}")
            failures += not ok
            continue
        else:
            diff = compare_npz(dirs[0] / "results.npz", dirs[1] / "results.npz")
            if diff is None:
                s = [strip_machine(json.loads((d / "summary.json").read_text())) for d in dirs]
                diff = first_difference(s[0], s[1])
        print(f"{case.name}: {'identical' if diff is None else 'DIFFERENT: ' + diff}")
        failures += diff is not None
    print(f"{failures} example(s) differ" if failures else "every example identical")
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()

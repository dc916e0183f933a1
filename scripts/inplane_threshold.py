#!/usr/bin/env python3
"""The AVB contact force below which the U-bend column of examples/ubend_column_avb.toml goes
unstable in plane (docs/INPLANE.md), by bisection over runs, per tangential method and
turbulence seed; and the figure and table of examples/study_avb_preload.toml.

    python3 scripts/inplane_threshold.py bisect [--velocity 10] [--seeds 1 2 3 4] [-o DIR]
    python3 scripts/inplane_threshold.py study DIR     # DIR: fretdyn sweep's output folder

Criterion (one run, 3 s): UNSTABLE when any row touches a neighbour in the plane, i.e. the
tube-to-tube contacts (t2t_*, and row1_inner_* / row3_outer_* against the rigid rows) have at
least one impact. A run whose AVB contacts hold moves its apexes by at most 0.25 mm in the
plane near the threshold (micrometres at 10 N), against a gap of 8.38 mm between rows; a run
whose AVBs let go grows to impacts within about a second and swings 20–34 mm (the in-plane
amplitude, from the apex monitors (`[[output.monitors]]`), is printed beside the verdict so that the two populations
can be checked apart).

Bisection: for each (method, seed) the force F = k_N δ per side (δ the interference, `preload.interference`)
is bisected geometrically, F = √(F_lo F_hi), between F_lo (unstable) and F_hi (stable); every
step runs all (method, seed) pairs in one `fretdyn sweep` (combine = "list", one core). A seed
fixes the turbulence of every row (seed, seed + 1000, seed + 2000, as `fretdyn sweep`'s seeds
do), so each (method, seed) is one deterministic function of F; the bisection assumes that it
changes verdict once (checked on the final bracket: F_lo unstable, F_hi stable by construction).
F*_seed = √(F_lo F_hi) of the final bracket; per method the script reports the mean of F*_seed
over the seeds ± its standard error (standard deviation / √n): the seed-to-seed scatter of the
threshold, which the bracket's width (a factor (F_hi/F_lo)^(1/2^steps)) is small against.
"""

import argparse
import csv
import json
import math
import os
import statistics
import subprocess
import sys
import tomllib

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CASE = os.path.join(ROOT, "examples", "ubend_column_avb.toml")


def avb_stiffness(case):
    """k_N of the AVB contacts (all alike in the example)."""
    with open(case, "rb") as f:
        c = tomllib.load(f)
    ks = {k["normal"]["stiffness"] for s in c["structures"] for k in s["contacts"]}
    if len(ks) != 1:
        sys.exit(f"{case}: the AVB contacts have several stiffnesses {sorted(ks)}: give one")
    rows = len(c["structures"])
    turbulence = [len(s.get("turbulence", [])) for s in c["structures"]]
    return ks.pop(), rows, turbulence


def columns(header, prefixes, statistic):
    return [h for h in header if h.endswith("." + statistic) and h.startswith(prefixes)]


TOUCH = ("t2t_", "row1_inner_", "row3_outer_")


def verdicts(table):
    """Per row of a study.csv: (unstable, impacts per second in the plane, in-plane amplitude
    m, tube-to-tube normal wear work rate W (sum), friction wear work rate W (sum))."""
    with open(table) as f:
        rows = list(csv.DictReader(f))
    out = []
    for r in rows:
        if r["status"] != "completed":
            sys.exit(f"{table}: run {r['run']} status {r['status']}")
        header = list(r)
        imp = sum(float(r[c]) for c in columns(header, TOUCH, "impacts_per_second"))
        amp = max(
            float(r[c])
            for c in columns(header, ("row",), "displacement_amplitude")
            if "_in_plane." in c
        )
        wn = sum(float(r[c]) for c in columns(header, ("t2t_",), "normal_wear_work_rate"))
        wf = sum(float(r[c]) for c in columns(header, ("t2t_",), "wear_work_rate"))
        out.append((imp > 0.0, imp, amp, wn, wf, r))
    return out


def sweep(fretdyn, runs, velocity, rows, turbulence, folder):
    """Runs [(method, seed, F, k_N)] as one list study; returns their verdicts in order."""
    os.makedirs(folder, exist_ok=True)
    study = os.path.join(folder, "study.toml")
    lines = [f'base = "{CASE}"', 'combine = "list"', ""]

    def param(key, values):
        lines.extend(["[[parameters]]", f'key = "{key}"', f"values = {json.dumps(values)}", ""])

    param("structures.*.contacts.*.preload.interference", [f / k for (_, _, f, k) in runs])
    param("tangential.method", [m for (m, _, _, _) in runs])
    param("structures.*.flow.zones.0.velocity", [velocity] * len(runs))
    for i in range(rows):
        for j in range(turbulence[i]):
            param(
                f"structures.{i}.turbulence.{j}.seed",
                [s + 1000 * i + j for (_, s, _, _) in runs],
            )
    with open(study, "w") as f:
        f.write("\n".join(lines))
    subprocess.run(
        ["nice", fretdyn, "sweep", study, "-j", "1", "-o", folder, "--fresh", "-q"],
        check=True,
    )
    return verdicts(os.path.join(folder, "study.csv"))


def bisect(args):
    k, rows, turbulence = avb_stiffness(CASE)
    pairs = [(m, s) for m in args.methods for s in args.seeds]
    lo = {p: args.low for p in pairs}
    hi = {p: args.high for p in pairs}
    log = []

    def step(name, force, which):
        runs = [(m, s, force[(m, s)], k) for (m, s) in which]
        res = sweep(args.fretdyn, runs, args.velocity, rows, turbulence,
                    os.path.join(args.output, name))
        for (m, s, f, _), (unstable, imp, amp, wn, wf, _) in zip(runs, res):
            log.append(dict(step=name, method=m, seed=s, force=f, unstable=unstable,
                            inplane_impacts_per_second=imp, inplane_amplitude_m=amp,
                            t2t_normal_wear_work_rate=wn, t2t_wear_work_rate=wf))
            print(f"{name:>8} {m:>12} seed {s:>3} F = {f:9.4g} N: "
                  f"{'UNSTABLE' if unstable else 'stable  '} impacts/s {imp:9.4g} "
                  f"in-plane {amp * 1e3:9.4g} mm", flush=True)
        return {(m, s): r[0] for (m, s, _, _), r in zip(runs, res)}

    censored = {}
    at_lo = step("low", lo, pairs)
    at_hi = step("high", hi, pairs)
    for p in pairs:
        if not at_lo[p]:
            censored[p] = "below"  # stable already at F_lo
        elif at_hi[p]:
            censored[p] = "above"
    active = [p for p in pairs if p not in censored]
    for n in range(args.steps):
        if not active:
            break
        mid = {p: math.sqrt(lo[p] * hi[p]) for p in pairs}
        v = step(f"step{n + 1}", mid, active)  # a censored pair's bracket is not bisected
        for p in active:
            if v[p]:
                lo[p] = mid[p]
            else:
                hi[p] = mid[p]
    result = {"velocity": args.velocity, "avb_stiffness": k, "criterion":
              "unstable = at least one in-plane impact (t2t_*, row1_inner_*, row3_outer_*) in the run",
              "methods": {}}
    for m in args.methods:
        per = []
        for s in args.seeds:
            p = (m, s)
            per.append(dict(seed=s, low=lo[p], high=hi[p],
                            threshold=None if p in censored else math.sqrt(lo[p] * hi[p]),
                            censored=censored.get(p)))
        f = [x["threshold"] for x in per if x["threshold"] is not None]
        mean = statistics.fmean(f) if f else None
        se = statistics.stdev(f) / math.sqrt(len(f)) if len(f) > 1 else None
        result["methods"][m] = dict(seeds=per, mean=mean, standard_error=se, n=len(f))
    with open(os.path.join(args.output, "thresholds.json"), "w") as f:
        json.dump(result, f, indent=1)
    with open(os.path.join(args.output, "runs.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(log[0]))
        w.writeheader()
        w.writerows(log)
    print_table([result])


def print_table(results):
    """The thresholds of one or several bisections (same velocity and k_N; other seeds), pooled
    per method: mean ± standard error over the bracketed seeds."""
    first = results[0]
    if any((r["velocity"], r["avb_stiffness"]) != (first["velocity"], first["avb_stiffness"])
           for r in results):
        sys.exit("the bisections differ in velocity or k_N: not pooled")
    print(f"\nU = {first['velocity']} m/s, k_N = {first['avb_stiffness']:g} N/m; "
          "F* per side (N), bracket per seed:")
    print("| method | F* mean ± SE (N) | seeds bracketed | per seed [F_lo, F_hi] |")
    print("|---|---|---|---|")
    for m in first["methods"]:
        seeds = [x for r in results for x in r["methods"][m]["seeds"]]
        f = [x["threshold"] for x in seeds if x["threshold"] is not None]
        mean = f"{statistics.fmean(f):.3g}" if f else "–"
        se = f" ± {statistics.stdev(f) / math.sqrt(len(f)):.2g}" if len(f) > 1 else ""
        cells = ", ".join(
            f"{x['seed']}: " + (f"stable at {x['low']:g} N" if x["censored"] == "below" else
                                f"unstable at {x['high']:g} N" if x["censored"] == "above" else
                                f"[{x['low']:.3g}, {x['high']:.3g}]")
            for x in seeds)
        print(f"| {m} | {mean}{se} | {len(f)} of {len(seeds)} | {cells} |")


def table(args):
    results = []
    for d in args.folders:
        with open(os.path.join(d, "thresholds.json")) as f:
            results.append(json.load(f))
    print_table(results)


def study(args):
    """Table and figure of examples/study_avb_preload.toml's study.csv."""
    k, _, _ = avb_stiffness(CASE)
    res = verdicts(os.path.join(args.folder, "study.csv"))
    delta_key = "structures.*.contacts.*.preload.interference"
    u_key = "structures.*.flow.zones.0.velocity"
    pts = sorted(((float(r[u_key]), float(r[delta_key]) * k, unstable, imp, amp, wn, wf)
                  for (unstable, imp, amp, wn, wf, r) in res))
    print("| U (m/s) | F (N) | verdict | in-plane impacts/s | apex in-plane max (mm) "
          "| t2t normal wear work rate (W) | t2t friction wear work rate (W) |")
    print("|---|---|---|---|---|---|---|")
    for u, f, unstable, imp, amp, wn, wf in pts:
        print(f"| {u:g} | {f:.3g} | {'unstable' if unstable else 'stable'} | {imp:.4g} "
              f"| {amp * 1e3:.3g} | {wn:.3g} | {wf:.3g} |")
    if args.wear_coefficient:
        # the worst tube's volume per fuel cycle: every t2t contact wears both rows it joins
        # (THEORY §15), each by K × the normal wear work rate (Code_Aster's wear power).
        seconds = args.cycle_years * 365.25 * 86400.0
        print(f"\nWorst tube's tube-to-tube wear volume per fuel cycle ({args.cycle_years:g} years"
              f" = {seconds:.4g} s), K = {args.wear_coefficient:g} Pa^-1 on the normal work:")
        print("| U (m/s) | F (N) | worst row | normal wear work rate on it (W) | volume per cycle (cm³) |")
        print("|---|---|---|---|---|")
        for (unstable, imp, amp, wn, wf, r) in sorted(res, key=lambda x: (float(x[5][u_key]), float(x[5][delta_key]))):
            per_row = {}
            for c in columns(list(r), ("t2t_",), "normal_wear_work_rate"):
                a, b = c.split("_")[1][0], c.split("_")[1][1]  # t2t_<a><b>_<angle>
                for row in (a, b):
                    per_row[row] = per_row.get(row, 0.0) + float(r[c])
            row, w = max(per_row.items(), key=lambda x: x[1])
            if w > 0.0:
                v = args.wear_coefficient * w * seconds * 1e6
                print(f"| {float(r[u_key]):g} | {float(r[delta_key]) * k:.3g} | row{row} | {w:.3g} | {v:.3g} |")
    if args.figure:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, (a, b) = plt.subplots(1, 2, figsize=(10, 4))
        floor = 0.03  # where F = 0 is drawn, N
        for u in sorted({p[0] for p in pts}):
            sel = [p for p in pts if p[0] == u]
            x = [max(p[1], floor) for p in sel]
            a.plot(x, [max(p[4] * 1e3, 1e-4) for p in sel], "o-", label=f"U = {u:g} m/s")
            b.plot(x, [max(p[5], 1e-6) for p in sel], "o-", label=f"U = {u:g} m/s")
        for ax, yl in ((a, "apex in-plane displacement, max over rows (mm)"),
                       (b, "tube-to-tube normal wear work rate, sum (W)")):
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_xlabel(f"AVB contact force per side F = k_N δ (N); F = 0 drawn at {floor} N")
            ax.set_ylabel(yl)
            ax.grid(True, which="both", alpha=0.3)
        a.axhline(8.38, color="k", lw=0.8, ls="--")
        a.text(0.035, 10, "gap between rows 8.38 mm", fontsize=8)
        b.text(0.035, 2e-6, "1e-6: no impact", fontsize=8)
        a.legend(fontsize=8)
        fig.suptitle("examples/study_avb_preload.toml: in-plane instability of the U-bend column")
        fig.tight_layout()
        os.makedirs(os.path.dirname(args.figure) or ".", exist_ok=True)
        fig.savefig(args.figure, dpi=110)
        print(f"wrote {args.figure}")


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--fretdyn", default=os.path.join(ROOT, "target", "release", "fretdyn"))
    sub = p.add_subparsers(dest="command", required=True)
    b = sub.add_parser("bisect", help="the threshold force by bisection over runs")
    b.add_argument("--velocity", type=float, default=10.0, help="gap velocity, m/s")
    b.add_argument("--methods", nargs="+", default=["gauss_seidel", "active_set", "penalty"])
    b.add_argument("--seeds", nargs="+", type=int, default=[1, 2, 3, 4])
    b.add_argument("--low", type=float, default=0.01, help="F_lo, N (expected unstable)")
    b.add_argument("--high", type=float, default=10.0, help="F_hi, N (expected stable)")
    b.add_argument("--steps", type=int, default=5)
    b.add_argument("-o", "--output", default=os.path.join(ROOT, "fretdyn_results", "inplane_threshold"))
    s = sub.add_parser("study", help="table and figure of study_avb_preload's study.csv")
    s.add_argument("folder")
    s.add_argument("--figure", default=None, help="PNG to write (matplotlib)")
    s.add_argument("--wear-coefficient", type=float, default=None,
                   help="K, Pa^-1, on the normal work: print the worst tube's volume per cycle")
    s.add_argument("--cycle-years", type=float, default=1.5)
    t = sub.add_parser("table", help="the thresholds of bisect folders, pooled over their seeds")
    t.add_argument("folders", nargs="+")
    args = p.parse_args()
    {"bisect": bisect, "study": study, "table": table}[args.command](args)


if __name__ == "__main__":
    main()

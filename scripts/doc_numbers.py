#!/usr/bin/env python3
"""Writes the numbers of the docs that come from running an example, or checks them.

    python3 scripts/doc_numbers.py                 # run every block's commands, rewrite the docs
    python3 scripts/doc_numbers.py --check         # CI: run the affordable blocks, compare
    python3 scripts/doc_numbers.py --check --all   # compare every block (the long ones too)
    python3 scripts/doc_numbers.py --only life-convergence [--reuse]

A block of numbers in a doc sits between two markers,

    <!-- numbers: NAME (scripts/doc_numbers.py) -->
    ...
    <!-- /numbers -->

and everything between them is written by this script from the outputs of the commands of
block NAME (below): `fretdyn life`, `fretdyn sweep` or `fretdyn run` on the examples (or on a
copy with one setting changed, written beside the outputs), or the doc's own Python snippet.
Rewriting replaces the text between the markers; `--check` runs the same commands and exits 1,
printing the difference, if a doc says anything else. The commands are deterministic (seeded
studies, seeded turbulence): the same binary gives the same numbers on any run.

Blocks marked `ci` are checked by `--check`: the worked example of the volume split, the life
convergence table (53 windows), the example's life and the flow-velocity study (14 runs) —
about 65 s of CPU; 428 s measured on a 2-core machine shared with other builds (a load of 4–5
per core). The others (a probabilistic life of 40 samples, 4.5 minutes of CPU; the angular
bins; Lim's coefficient, 109 windows; the probabilistic clearance study, 120 runs) by `--check
--all` or when rewriting: about half an hour on that machine. Outputs go to `--out` (default
target/doc_numbers); `--reuse` renders from the outputs already there instead of running the
commands again.
"""

import argparse
import csv
import difflib
import io
import json
import pathlib
import re
import subprocess
import sys
import textwrap
import time
from contextlib import redirect_stdout

ROOT = pathlib.Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"
LIFE_CASE = EXAMPLES / "tube_multispan_life.toml"
PLATES = ["plate1", "plate2", "plate3", "plate4", "plate5"]
START = re.compile(r"<!-- numbers: ([\w-]+) \(scripts/doc_numbers\.py\) -->\n")
END = "<!-- /numbers -->"


class Runner:
    """Runs fretdyn commands into `out` (or only says where their outputs are, with reuse)."""

    def __init__(self, fretdyn, out, reuse):
        self.fretdyn, self.out, self.reuse = fretdyn, out, reuse
        self.seconds = {}

    def variant(self, name, source, replacements):
        """A copy of the case `source` with each (pattern, text) replaced exactly once."""
        text = source.read_text()
        for pattern, new in replacements:
            text, n = re.subn(pattern, new, text, flags=re.M)
            if n != 1:
                sys.exit(f"{source}: '{pattern}' found {n} times, expected once")
        return self.write(name, text)

    def write(self, name, text):
        """The case `text` as OUT/name.toml."""
        path = self.out / f"{name}.toml"
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
        return path

    def __call__(self, name, *args):
        """`fretdyn ARGS -o OUT/name`; returns the output folder."""
        folder = self.out / name
        if (self.reuse and folder.exists()) or name in self.seconds:
            return folder  # two blocks from one command run it once
        start = time.monotonic()
        p = subprocess.run([str(self.fretdyn), *map(str, args), "-o", str(folder)],
                           cwd=ROOT, capture_output=True, text=True)
        if p.returncode != 0:
            sys.exit(f"fretdyn {' '.join(map(str, args))} exited {p.returncode}:\n{p.stderr}")
        self.seconds[name] = time.monotonic() - start
        return folder


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def para(text):
    """A paragraph of prose, wrapped as the docs are (at 95 columns), never between a number
    and its unit."""
    for unit in ("%", "µm", "mW", "mm", "years"):
        text = text.replace(f" {unit}", f"\0{unit}")
    text = textwrap.fill(text, width=95, break_long_words=False, break_on_hyphens=False)
    return text.replace("\0", " ")


def um(x, digits=2):
    return f"{x * 1e6:.{digits}f}"


def pct(a, b):
    """The change from b to a, signed, in per cent."""
    return f"{100 * (a / b - 1):+.1f} %".replace("-", "−")


# ---- WEAR.md: the volume split's worked example (the doc's own Python snippet) ----------

def wear_split(run):
    text = (ROOT / "docs" / "WEAR.md").read_text()
    i = text.index("measured with the script below")
    code = re.search(r"```python\n(.*?)```", text[i:], re.S).group(1)
    out = io.StringIO()
    with redirect_stdout(out):
        exec(compile(code, "WEAR.md snippet", "exec"), {})
    lines = out.getvalue().splitlines()
    f = [[float(x) for x in re.findall(r"[-+]?\d+\.\d+(?:e[-+]?\d+)?", line)] for line in lines]
    t, vt, vs = f[0]
    dt, ds, total = f[1]
    d, behind, _ = f[2]
    ca, ratio = f[3]
    (_, pv1, pd1), (_, pv2, pd2) = f[4], f[5]
    return f"""| quantity | value |
|---|---|
| service time | {t:.4e} s |
| `V_tube`, `V_bar` | {vt:.4e} m³, {vs:.4e} m³ |
| tube depth (flat cut) | {dt:.4f} mm |
| bar depth, tube unworn | {ds:.4f} mm |
| approach (overlap holding both volumes) | {d:.4f} mm (the sum of the two depths: {total:.4f} mm) |
| bar depth behind the tube's flat scar | {behind:.4f} mm (= approach − tube depth) |
| Code_Aster `TUBE_BAV`'s tube depth (shared depth, parabolic) | {ca:.4f} mm; fretdyn's is {100 * ratio:.2f} % deeper |

The parabolic approximation of the circle (Code_Aster's closed forms) overestimates the volume
at a given depth by {100 * pv1:.2f} % at 0.436 mm (40 % of a 1.09 mm wall) and by {100 * pv2:.2f} % at 1.09 mm; the
depth it gives for a volume is {-100 * pd1:.2f} % and {-100 * pd2:.2f} % too small there.""".replace("e+0", "e").replace("e-0", "e-")


# ---- WEAR.md: the multi-span tube over 40 years -------------------------------------------

CONVERGENCE_FROM, HALVINGS = 0.2, 5


def convergence_rows(run):
    case = run.variant("convergence/case", LIFE_CASE,
                       [(r"^max_depth_change = .*$", f"max_depth_change = {CONVERGENCE_FROM}")])
    folder = run("convergence/life", "life", case, "--no-plots", "--halvings", HALVINGS)
    rows = read_csv(folder / "convergence.csv")
    life = read_csv(folder / "life.csv")
    return rows, life


def life_convergence(run):
    rows, life = convergence_rows(run)
    out = ["| `max_depth_change` | life steps | " + " | ".join(PLATES) + " |",
           "|---" * (2 + len(PLATES)) + "|"]
    for r in rows:
        assert r["life_end"] == "completed", r
        out.append(f"| {float(r['max_depth_change']):g} | {r['life_steps']} | "
                   + " | ".join(um(float(r[f"{p}.tube_depth"])) for p in PLATES) + " |")
    last = life[-1]
    out.append("| fixed gap | 1 window | "
               + " | ".join(um(float(last[f"{p}.tube_depth_fixed_gap"])) for p in PLATES) + " |")
    return "\n".join(out)


def window_errors(life):
    """The smallest and largest relative standard error of the windows' wear work rates at
    plates 2 and 3 (the loaded ones) of a life's table."""
    se = [float(r[f"{p}.wear_work_rate_se"]) / float(r[f"{p}.wear_work_rate"])
          for r in life[1:] for p in ("plate2", "plate3")]
    return f"{100 * min(se):.0f}–{100 * max(se):.0f} %"


def life_convergence_text(run):
    rows, _ = convergence_rows(run)
    life, _ = feedback_life(run)
    depth = {p: [float(r[f"{p}.tube_depth"]) for r in rows] for p in PLATES}
    deepest = max(PLATES, key=lambda p: depth[p][-1])
    second = max((p for p in PLATES if p != deepest), key=lambda p: depth[p][-1])
    fractions = [float(r["max_depth_change"]) for r in rows]
    steps = ", ".join(pct(b, a) for a, b in zip(depth[deepest], depth[deepest][1:]))
    finest = fractions[-1]

    def off(f):
        k = fractions.index(f)
        return (f"{pct(depth[second][k], depth[second][-1])} and "
                f"{pct(depth[deepest][k], depth[deepest][-1])}")

    k = fractions.index(0.025)
    return para(f"The most loaded plates converge as the step is halved ({deepest}: {steps} from "
                f"one row to the next). Against the depths at {finest:g}, those of {second} "
                f"and {deepest} are {off(0.1)} off at 0.1 (the library's default before "
                f"issue 3.2), {off(0.05)} at 0.05 (the example's before), and {off(0.025)} "
                f"at 0.025 (the default now, {rows[k]['life_steps']} life steps): within what "
                "one window's noise passes to the life (each window's wear work rate at "
                f"plates 2 and 3 is uncertain by {window_errors(life)}, and a depth goes as "
                "`V^{2/3}`).")


def feedback_life(run):
    folder = run("feedback/life", "life", LIFE_CASE, "--no-plots")
    return read_csv(folder / "life.csv"), json.loads((folder / "life.json").read_text())


def life_feedback(run):
    life, _ = feedback_life(run)
    text = LIFE_CASE.read_text()
    assert text.count("clearance = 2e-4 }") == 5, "the five plates' clearances"
    uniform = run.write("feedback/uniform", text.replace("clearance = 2e-4 }", "clearance = 3e-4 }"))
    contacts = read_csv(run("feedback/run-0.3mm", "run", uniform, "--quiet", "--no-plots")
                        / "contacts.csv")
    wider = float(next(r for r in contacts if r["name"] == "plate2")["normal_wear_work_rate"])
    first, last = life[1], life[-1]
    deeper = {p: float(last[f"{p}.tube_depth"]) / float(last[f"{p}.tube_depth_fixed_gap"]) - 1
              for p in ("plate2", "plate3")}
    opening = {p: float(last[f"{p}.clearance_increase"]) for p in ("plate2", "plate3")}
    rate = {p: (float(first[f"{p}.wear_work_rate"]), float(first[f"{p}.wear_work_rate_se"]),
                float(last[f"{p}.wear_work_rate"]), float(last[f"{p}.wear_work_rate_se"]))
            for p in ("plate2", "plate3")}

    def mw(x):
        return f"{x * 1e3:.1f}"

    return para(f"**The feedback.** With the example's `max_depth_change = 0.025` ({len(life) - 1} "
            "life steps), the "
            f"scars deepen the holes by {um(opening['plate2'], 1)} and "
            f"{um(opening['plate3'], 1)} µm at plates 2 and 3 (the clearance is 200 µm), yet "
            f"the depth at 40 years is **{100 * deeper['plate2']:.0f} % (plate 2) and "
            f"{100 * deeper['plate3']:.0f} % (plate 3) deeper** than the fixed-gap "
            f"extrapolation ({um(float(last['plate2.tube_depth']), 1)} against "
            f"{um(float(last['plate2.tube_depth_fixed_gap']), 1)} µm, "
            f"{um(float(last['plate3.tube_depth']), 1)} against "
            f"{um(float(last['plate3.tube_depth_fixed_gap']), 1)} µm). The normal wear work "
            f"rate at plate 2 goes from {mw(rate['plate2'][0])} ± {mw(rate['plate2'][1])} mW "
            f"(first window) to {mw(rate['plate2'][2])} ± {mw(rate['plate2'][3])} mW (last; "
            f"plate 3 from {mw(rate['plate3'][0])} ± {mw(rate['plate3'][1])} to "
            f"{mw(rate['plate3'][2])} ± {mw(rate['plate3'][3])} mW); each window's rate at "
            f"plates 2 and 3 has a standard error of {window_errors(life)} "
            "(the `wear_work_rate_se` column of `life.csv`). A uniform enlargement does that "
            "only with a much larger opening: with the clearance raised uniformly from 0.2 to "
            f"0.3 mm (+50 %, no scar) the rate at plate 2 is {mw(wider)} mW. Why: the tube "
            "is driven along 31° and strikes the holes at both ends of its stroke; the scars "
            "open the holes exactly there, the stroke lengthens and the tube slides further "
            "along the flanks of the scar.")


def life_bins(run):
    depths = {}
    for bins in (36, 72, 144):
        case = run.variant(f"bins/{bins}", LIFE_CASE,
                           [(r"^(max_depth_change = .*)$", rf"\g<1>\nangular_bins = {bins}")])
        life = read_csv(run(f"bins/life{bins}", "life", case, "--no-plots") / "life.csv")
        depths[bins] = life[-1]
    return para("With 36, 72 and 144 angular bins (the example's life, 72 by default): plate 2 "
            + ", ".join(um(float(depths[b]["plate2.tube_depth"]), 1) for b in depths)
            + " µm, plate 3 "
            + ", ".join(um(float(depths[b]["plate3.tube_depth"]), 1) for b in depths)
            + " µm — the profile does not depend on its resolution (THEORY §14.4).")


def life_lim(run):
    text = LIFE_CASE.read_text()
    assert text.count("coefficient = 6.0e-17") == 10, "the bank coefficient, twice per plate"
    case = run.write("lim/case", text.replace("coefficient = 6.0e-17", "coefficient = 16.2e-15"))
    folder = run("lim/life", "life", case, "--no-plots")
    info = json.loads((folder / "life.json").read_text())["results"]
    life = read_csv(folder / "life.csv")
    names = info["contacts"]
    crit = {n: t for n, t in zip(names, info["time_to_criterion"])}
    year = 365.25 * 86400
    end = info["end"]
    last = life[-1]
    worn = end.get("contact") if isinstance(end, dict) else None
    at = float(last["time_years"])
    fixed = max(float(last[f"{p}.tube_depth_fixed_gap"]) for p in PLATES)
    return para("With Lim, Oh & Lee's laboratory coefficient (16.2e-15 Pa⁻¹, Alloy 690 against 304 "
            "stainless steel), 270 times the bank's: "
            f"plates 2 and 3 reach 40 % of the wall at {crit['plate2'] / year:.2f} and "
            f"{crit['plate3'] / year:.2f} years and the tube at {worn} is worn through at "
            f"{at:.2f} years ({info['windows']} windows), when the fixed-gap extrapolation "
            f"has not reached the criterion ({fixed * 1e3:.2f} mm at {at:.2f} years).")


def life_probabilistic(run):
    folder = run("probabilistic/study", "sweep", EXAMPLES / "study_life_probabilistic.toml",
                 "--quiet")
    rows = read_csv(folder / "percentiles.csv")

    def get(column, level):
        return next(r for r in rows if r["column"] == column and float(r["level"]) == level)

    def cell(column, level):
        r = get(column, level)
        hi = "–" if r["ci_high"] in ("", "inf") else um(float(r["ci_high"]), 1)
        lo = "–" if r["ci_low"] == "" else um(float(r["ci_low"]), 1)
        return f"{um(float(r['estimate']), 1)} [{lo}, {hi}] ({um(float(r['bootstrap_se']), 1)})"

    out = ["| plate | P50 with feedback | P95 with feedback | P50 fixed gap | P95 fixed gap |",
           "|---|---|---|---|---|"]
    for p in ("plate2", "plate3"):
        out.append(f"| {p} | " + " | ".join(
            cell(f"{p}.{c}", lv) for c in ("depth_at_target", "depth_at_target_fixed_gap")
            for lv in (50, 95)) + " |")
    moves, above = {}, True
    for lv in (50, 95):
        pairs = [(get(f"{p}.depth_at_target", lv), get(f"{p}.depth_at_target_fixed_gap", lv))
                 for p in ("plate2", "plate3")]
        moves[lv] = [float(a["estimate"]) / float(b["estimate"]) - 1 for a, b in pairs]
        above &= all(float(a["estimate"]) - float(b["estimate"])
                     > 2 * max(float(a["bootstrap_se"]), float(b["bootstrap_se"]))
                     for a, b in pairs)
    span = {lv: f"{100 * min(m):.0f}–{100 * max(m):.0f} %" for lv, m in moves.items()}
    out += ["", para(
        "(An upper bound of a P95 needs at least 72 samples, docs/STUDIES.md.) The feedback "
        f"moves the median by {span[50]} and the P95 by {span[95]}: "
        + ("more than twice the sampling error of either." if above
           else "not everywhere more than twice the sampling error of either."))]
    return "\n".join(out)


# ---- STUDIES.md: the probabilistic study of the clearances ---------------------------------

def studies_percentiles(run):
    folder = run("studies/clearance", "sweep", EXAMPLES / "study_clearance_probabilistic.toml",
                 "--quiet")
    study = read_csv(folder / "study.csv")
    rows = read_csv(folder / "percentiles.csv")
    missing = sum(any(float(r[f"contacts.{k}.obstacle.clearance"]) >= 1e-2 for k in range(5))
                  for r in study)

    def row(plate, level):
        return next(r for r in rows
                    if r["column"] == f"{plate}.wear_work_rate" and float(r["level"]) == level)

    def mw(x):
        return "–" if x in ("", "inf") else f"{float(x) * 1e3:.2f}"

    out = [para(f"{len(study)} runs; {missing} of the {len(study)} samples have at least one "
                "plate missing. The wear work rate, `percentiles.csv` (mW; interval: 95 % "
                f"distribution-free, coverage {float(row('plate1', 50)['ci_coverage']):.3f} for "
                f"P50, {float(row('plate1', 95)['ci_coverage']):.3f} for P95; ± the bootstrap "
                "standard error):"), "",
           "| plate | P50 [interval] ± SE | P95 [interval] ± SE | P99 [interval] ± SE |",
           "| --- | --- | --- | --- |"]
    for p in PLATES:
        cells = [row(p, lv) for lv in (50, 95, 99)]
        out.append(f"| {p} | " + " | ".join(
            f"{mw(r['estimate'])} [{mw(r['ci_low'])}, {mw(r['ci_high'])}] ± "
            f"{mw(r['bootstrap_se'])}" for r in cells) + " |")
    return "\n".join(out)


# ---- FLOW.md: the wear work rate against the flow velocity --------------------------------

def flow_velocity(run):
    folder = run("flow/study", "sweep", EXAMPLES / "study_flow_velocity.toml", "--quiet")
    rows = read_csv(folder / "study.csv")
    velocity, slope = "flow.zones.0.velocity", "flow.zones.0.fluid_elastic.lift_slope"

    def uw(x):
        x = float(x) * 1e6
        return f"{x:.0f}" if x >= 1000 else f"{x:.3g}"

    out = ["| U (m/s) | C_L' | " + " | ".join(PLATES) + " |", "|---" * 7 + "|"]
    for r in rows:
        out.append(f"| {r[velocity]} | {r[slope]} | "
                   + " | ".join(uw(r[f"{p}.wear_work_rate"]) for p in PLATES) + " |")
    by = {(float(r[velocity]), float(r[slope])): r for r in rows}
    ratios, rattling = [], []
    for (v, c), r in by.items():
        if v < 1.0 or c != 0.0:
            continue
        for p in PLATES:
            alone, fed = float(r[f"{p}.wear_work_rate"]), float(by[(v, -3.0)][f"{p}.wear_work_rate"])
            if alone > 0:
                ratios.append(fed / alone)
                if alone >= 1e-6:
                    rattling.append(fed / alone)
    out += ["", para(
        "With `C_L' = 0` the wear grows with the turbulence (`∝ ρU²` in its spectrum); with the "
        "fluid-elastic forces the flow feeds the tube's motion (`fluid_work > 0`) and the wear "
        f"work rate is {min(ratios):.0f}× to {max(ratios):.0f}× higher from 1 m/s on (at the "
        "plates that the turbulence alone makes rattle, 1 µW or more: "
        f"{min(rattling):.0f}–{max(rattling):.0f}×; where it barely does, more; where it does "
        "not at all, the fluid-elastic forces alone make the plate wear): the jump of the "
        "design curves.")]
    return "\n".join(out)


# ---- VERIFICATION.md: contact forces and wear against the number of modes -----------------

def mode_convergence(run):
    """The table the `mode_convergence` example prints (9 runs of 0.1 s, under a second)."""
    folder = run.out / "verification/mode_convergence"
    p = subprocess.run(["cargo", "run", "--release", "--locked", "-q", "-p", "fretdyn-cli",
                        "--example", "mode_convergence", "--", str(folder)],
                       cwd=ROOT, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"the mode_convergence example exited {p.returncode}:\n{p.stderr}")
    rows = [line for line in p.stdout.splitlines() if line.startswith("|")]
    # the all-mode row's errors are exactly zero
    return "\n".join(re.sub(r"\| 0\.00e0(?= )", "| 0", line) for line in rows)


# name: (file, render, affordable in CI)
BLOCKS = {
    "wear-split": ("docs/WEAR.md", wear_split, True),
    "life-convergence": ("docs/WEAR.md", life_convergence, True),
    "life-convergence-text": ("docs/WEAR.md", life_convergence_text, True),
    "life-feedback": ("docs/WEAR.md", life_feedback, True),
    "life-bins": ("docs/WEAR.md", life_bins, False),
    "life-lim": ("docs/WEAR.md", life_lim, False),
    "life-probabilistic": ("docs/WEAR.md", life_probabilistic, False),
    "studies-percentiles": ("docs/STUDIES.md", studies_percentiles, False),
    "flow-velocity": ("docs/FLOW.md", flow_velocity, True),
    "mode-convergence": ("docs/VERIFICATION.md", mode_convergence, True),
}


def blocks_of(text):
    """{name: (start, end)} of the text between each block's markers."""
    found = {}
    for m in START.finditer(text):
        end = text.find(END, m.end())
        if end < 0:
            sys.exit(f"block {m.group(1)}: no {END} after its start")
        found[m.group(1)] = (m.end(), end)
    return found


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", action="store_true", help="compare instead of rewriting")
    ap.add_argument("--all", action="store_true", help="with --check: the long blocks too")
    ap.add_argument("--only", nargs="*", help="these blocks only")
    ap.add_argument("--reuse", action="store_true", help="render from the outputs in --out")
    ap.add_argument("--fretdyn", type=pathlib.Path, default=ROOT / "target/release/fretdyn")
    ap.add_argument("--out", type=pathlib.Path, default=ROOT / "target/doc_numbers")
    args = ap.parse_args()
    unknown = set(args.only or []) - set(BLOCKS)
    if unknown:
        sys.exit(f"unknown blocks {sorted(unknown)}; blocks: {', '.join(BLOCKS)}")
    if not args.fretdyn.exists():
        sys.exit(f"{args.fretdyn}: build it first (cargo build --release --locked)")
    run = Runner(args.fretdyn.resolve(), args.out.resolve(), args.reuse)
    failures = 0
    started = time.monotonic()
    for name, (doc, render, ci) in BLOCKS.items():
        if args.only and name not in args.only:
            continue
        if args.check and not (ci or args.all or args.only):
            print(f"{name}: skipped (long; --check --all checks it)")
            continue
        path = ROOT / doc
        if name not in blocks_of(path.read_text()):
            sys.exit(f"{doc}: no block '{name}' (<!-- numbers: {name} (scripts/doc_numbers.py) -->)")
        block_start = time.monotonic()
        new = render(run).rstrip("\n") + "\n"
        # read again after the commands: the doc may have been edited meanwhile
        text = path.read_text()
        where = blocks_of(text)[name]
        old = text[where[0]:where[1]]
        took = f"{time.monotonic() - block_start:.0f} s"
        if old == new:
            print(f"{name} ({doc}): as in the doc ({took})")
        elif args.check:
            failures += 1
            print(f"{name} ({doc}): DIFFERENT ({took}):")
            sys.stdout.writelines(difflib.unified_diff(
                old.splitlines(True), new.splitlines(True), "doc", "commands"))
        else:
            path.write_text(text[:where[0]] + new + text[where[1]:])
            print(f"{name} ({doc}): rewritten ({took})")
    print(f"{time.monotonic() - started:.0f} s in all; commands: "
          + ", ".join(f"{k} {v:.0f} s" for k, v in run.seconds.items()))
    if failures:
        print(f"{failures} block(s) differ from what the commands give: "
              "python3 scripts/doc_numbers.py [--only NAME] rewrites them")
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()

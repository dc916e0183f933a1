#!/usr/bin/env bash
# Rewrites every file under docs/figures from the commands that draw it — the one place that
# writes there (the commands themselves write to fretdyn_results/, git-ignored).
#
#   scripts/regenerate_figures.sh            # all of them (several minutes on 2 cores)
#   scripts/regenerate_figures.sh --cheap    # only those checked in CI (about a minute)
#   scripts/regenerate_figures.sh --into DIR # write DIR/<path under docs/figures> instead
#   scripts/regenerate_figures.sh --no-timings  # all but scaling/ (timings: on a quiet machine)
#
# FRETDYN=path/to/fretdyn uses that binary instead of building target/release/fretdyn.
# The scratch folders of the commands are under $SCRATCH (default fretdyn_results/figures).
#
# Cheap, drawn again and compared byte for byte with the committed files by
# crates/fretdyn-cli/tests/figures.rs:
#   fig2a_v1a_friction_force.png, fig2b_v1b_friction_force.png, full_step_variant.png,
#   penalty_kt_dependence.png   fretdyn verify (under a second)
#   flow/study.png              fretdyn sweep examples/study_flow_velocity.toml (14 runs, ~30 s)
#   scaling/scaling.png         fretdyn plot of the committed scaling/scaling.csv (drawn again;
#                               new timings only without --no-timings, below)
# Costly, regenerated here only (not compared in CI):
#   flow/study.csv              the same study's table (its steps_per_second are timings)
#   mode_convergence.png        the mode_convergence example (9 runs of 100 000 steps, up to
#                               114 modes)
#   study_clearance_probabilistic.png
#                               fretdyn sweep examples/study_clearance_probabilistic.toml
#                               (120 runs; its percentiles.png)
#   wear/life.png, wear/life_convergence.png
#                               fretdyn life examples/tube_multispan_life.toml --halvings 3
#   scaling/scaling.csv, scaling/scaling.png
#                               fretdyn bench --scaling (timings of this machine: on a quiet
#                               one; --no-timings keeps the committed ones)
set -euo pipefail
cd "$(dirname "$0")/.."

cheap=0
timings=1
into=docs/figures
while [ $# -gt 0 ]; do
    case "$1" in
        --cheap) cheap=1 ;;
        --no-timings) timings=0 ;;
        --into) into="$2"; shift ;;
        *) echo "usage: $0 [--cheap] [--no-timings] [--into DIR]" >&2; exit 2 ;;
    esac
    shift
done
scratch=${SCRATCH:-fretdyn_results/figures}
if [ -z "${FRETDYN:-}" ]; then
    cargo build --release --locked -p fretdyn-cli
    FRETDYN=target/release/fretdyn
fi
mkdir -p "$into/flow" "$into/wear" "$into/scaling" "$scratch"

"$FRETDYN" verify -q -o "$scratch/verify"
for f in fig2a_v1a_friction_force.png fig2b_v1b_friction_force.png full_step_variant.png \
    penalty_kt_dependence.png; do
    cp "$scratch/verify/$f" "$into/$f"
done

"$FRETDYN" sweep examples/study_flow_velocity.toml -o "$scratch/flow" --fresh -q
cp "$scratch/flow/study.png" "$into/flow/study.png"

# scaling.png drawn again from the committed timings (the timings themselves: below)
rm -rf "$scratch/scaling_redrawn" && mkdir -p "$scratch/scaling_redrawn"
cp docs/figures/scaling/scaling.csv "$scratch/scaling_redrawn/"
"$FRETDYN" plot "$scratch/scaling_redrawn" > /dev/null
cp "$scratch/scaling_redrawn/scaling.png" "$into/scaling/scaling.png"
[ "$cheap" = 1 ] && exit 0
cp "$scratch/flow/study.csv" "$into/flow/study.csv"

cargo run --release --locked -p fretdyn-cli --example mode_convergence -- "$scratch/mode_convergence"
cp "$scratch/mode_convergence/mode_convergence.png" "$into/mode_convergence.png"

"$FRETDYN" sweep examples/study_clearance_probabilistic.toml -o "$scratch/probabilistic" --fresh -q
cp "$scratch/probabilistic/percentiles.png" "$into/study_clearance_probabilistic.png"

rm -rf "$scratch/life"
"$FRETDYN" life examples/tube_multispan_life.toml --halvings 3 -o "$scratch/life"
cp "$scratch/life/life.png" "$into/wear/life.png"
cp "$scratch/life/convergence.png" "$into/wear/life_convergence.png"

[ "$timings" = 0 ] && exit 0
"$FRETDYN" bench --scaling "$scratch/scaling"
cp "$scratch/scaling/scaling.csv" "$scratch/scaling/scaling.png" "$into/scaling/"

"""Wear work rate against the support clearance, for the three tangential methods, on the
multi-span tube (examples/tube_multispan.toml): a study given as a dict, run on every core
(or on a Dask cluster: pass a dask.distributed.Client to fretdyn.sweep), then a plot of the
most worn plate with the standard error of each point.

    pip install "./crates/fretdyn-python[pandas,matplotlib]"
    python examples/python/gap_study.py            # writes gap_study.csv and gap_study.png
    python examples/python/gap_study.py --dask     # the same on a local Dask cluster

Cost: 15 runs of 8 s of vibration (800 000 steps each): 46 s measured on a 2-core machine
shared with other jobs (load average 10; fretdyn 0.1.0, both cores), so expect 30 s to 2
minutes. The runs are that long so that the standard error of a point (batch means over the
statistics window, 3 to 11 % here, drawn as error bars) is small against the trend the figure
shows; 1 s runs (a 0.8 s window) have errors about 3 times larger (√(7.8/0.8)), and a "bump"
between two clearances was noise. Run it again after a crash: the runs already in
gap_study.csv are not done again.
"""

import sys
from pathlib import Path

import numpy as np

import fretdyn

HERE = Path(__file__).resolve().parent
CLEARANCES = [1e-4, 1.5e-4, 2e-4, 3e-4, 4e-4]
METHODS = ["gauss_seidel", "active_set", "penalty"]
# seconds of vibration per run: the statistics window is this minus the case's t_start
DURATION = 8.0
# the plate drawn: the most worn of the five at the case's clearance
PLATE = "plate3"


def pyplot():
    """matplotlib's pyplot (Agg backend), checked before any run is done."""
    try:
        import matplotlib
    except ImportError:
        sys.exit(
            "gap_study.py draws its plot with matplotlib, which is not installed in this "
            f"Python ({sys.executable}): pip install matplotlib"
        )
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def main():
    plt = pyplot()
    out = Path.cwd()
    study = {
        "base": HERE.parent / "tube_multispan.toml",
        "combine": "grid",
        "parameters": [
            {"key": "contacts.*.obstacle.clearance", "values": CLEARANCES},
            {"key": "tangential.method", "values": METHODS},
            {"key": "time.duration", "values": [DURATION]},
        ],
    }
    table = out / "gap_study.csv"
    if "--dask" in sys.argv:
        from dask.distributed import Client, LocalCluster

        with LocalCluster(n_workers=2, threads_per_worker=1) as cluster, Client(cluster) as client:
            t = fretdyn.sweep(study, table, client=client)
    else:
        t = fretdyn.sweep(study, table)
    # the table: a pandas DataFrame (a numpy structured array without pandas), by run
    print(f"{len(t)} runs in {table}")

    x = np.asarray(t["contacts.*.obstacle.clearance"])
    method = np.asarray(t["tangential.method"])
    rate = np.asarray(t[f"{PLATE}.wear_work_rate"])
    se = np.asarray(t[f"{PLATE}.wear_work_rate_se"])
    print(f"largest relative standard error: {np.nanmax(se / rate):.1%}")

    fig, ax = plt.subplots(figsize=(7, 4.5), layout="constrained")
    for m in METHODS:
        sel = method == m
        order = np.argsort(x[sel])
        ax.errorbar(1e6 * x[sel][order], 1e3 * rate[sel][order], yerr=1e3 * se[sel][order],
                    fmt="o-", capsize=4, label=m)
    ax.set_xlabel("radial clearance (µm)")
    ax.set_ylabel(f"wear work rate at {PLATE} (mW)")
    ax.set_title(f"Multi-span tube, {DURATION:g} s runs: wear work rate at {PLATE} "
                 "against clearance (± standard error)", wrap=True)
    ax.legend(title="tangential method")
    fig.savefig(out / "gap_study.png", dpi=120)
    print(f"plot in {out / 'gap_study.png'}")


if __name__ == "__main__":
    main()

"""Wear work rate against the support clearance, for the three tangential methods, on the
multi-span tube (examples/tube_multispan.toml): a study run on every core (or on a Dask
cluster: pass a dask.distributed.Client to fretdyn.sweep), then a plot.

    pip install ./crates/fretdyn-python matplotlib
    python examples/python/gap_study.py            # writes gap_study.csv and gap_study.png
    python examples/python/gap_study.py --dask     # the same on a local Dask cluster

Run it again after a crash: the runs already in gap_study.csv are not done again.
"""

import sys
from pathlib import Path

import numpy as np

import fretdyn

HERE = Path(__file__).resolve().parent
CLEARANCES = [1e-4, 1.5e-4, 2e-4, 3e-4, 4e-4]
METHODS = ["gauss_seidel", "active_set", "penalty"]


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
    study = out / "gap_study.toml"
    base = (HERE.parent / "tube_multispan.toml").as_posix()
    study.write_text(
        f'base = "{base}"\ncombine = "grid"\n\n'
        f'[[parameters]]\nkey = "contacts.*.obstacle.clearance"\nvalues = {CLEARANCES}\n\n'
        f'[[parameters]]\nkey = "tangential.method"\nvalues = {METHODS}\n\n'
        '[[parameters]]\nkey = "time.duration"\nvalues = [1.0]\n'
    )
    table = out / "gap_study.csv"
    if "--dask" in sys.argv:
        from dask.distributed import Client, LocalCluster

        with LocalCluster(n_workers=2, threads_per_worker=1) as cluster, Client(cluster) as client:
            t = fretdyn.sweep(study, table, client=client)
    else:
        t = fretdyn.sweep(study, table)
    # the table: a pandas DataFrame (a numpy structured array without pandas), by run
    print(f"{len(t)} runs in {table}")

    columns = t.columns if hasattr(t, "columns") else t.dtype.names
    contacts = [k.split(".")[0] for k in columns if k.endswith(".wear_work_rate")]
    # total wear work rate over the supports
    total = sum(np.asarray(t[f"{c}.wear_work_rate"]) for c in contacts)
    x = np.asarray(t["contacts.*.obstacle.clearance"])
    method = np.asarray(t["tangential.method"])

    fig, ax = plt.subplots(figsize=(7, 4.5))
    for m in METHODS:
        sel = method == m
        order = np.argsort(x[sel])
        ax.plot(1e3 * x[sel][order], 1e3 * total[sel][order], "o-", label=m)
    ax.set_xlabel("radial clearance (mm)")
    ax.set_ylabel("wear work rate, sum over the 5 plates (mW)")
    ax.set_title("Multi-span tube: wear work rate against clearance")
    ax.legend()
    fig.tight_layout()
    fig.savefig(out / "gap_study.png", dpi=120)
    print(f"plot in {out / 'gap_study.png'}")


if __name__ == "__main__":
    main()

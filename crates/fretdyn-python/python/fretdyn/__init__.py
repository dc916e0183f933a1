"""fretdyn: nonlinear vibration of a structure on a modal basis rattling against obstacles with
Coulomb friction (explicit central differences; penalty, Active Set or projected Gauss–Seidel).

    import fretdyn
    case = fretdyn.Case.from_file("examples/v1a_oblique_impact.toml")
    r = fretdyn.run(case)            # numpy arrays, GIL released, Ctrl-C honoured
    r = fretdyn.run("examples/v1a_oblique_impact.toml")   # the same, from the path
    r["contact_normal_force"][:, 0], r["summary"]["contacts"][0]["wear_work_rate"]
    r["summary"]["energy_balance"]["fluid_work"]   # the energy the flow fed in, J
    s = fretdyn.stability("examples/ubend_flow.toml")   # the Connors check, per mode
    s["ratio"], s["effective_velocity"], s["reference_zone"]

Cases come from a TOML file, TOML text, or a Python dict with the structure of a case file
(numpy arrays are accepted anywhere a list is). Studies (`sweep`) run on every core, or on a
Dask cluster when given a `dask.distributed.Client`.
"""

from __future__ import annotations

import csv
import json
import os
from pathlib import Path
from typing import Any, Mapping, Optional, Sequence, Union

import numpy as np

from . import _native
from ._native import FretdynError
from . import med  # modal bases from Code_Aster's MED files (docs/MED.md)

__all__ = [
    "Case", "FretdynError", "run", "stability", "sweep", "percentiles", "read_table",
    "modal_structure", "__version__",
]
__version__ = _native.__version__

PathLike = Union[str, os.PathLike]


def _plain(value: Any) -> Any:
    """numpy arrays and scalars → lists and Python numbers (for JSON)."""
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, Mapping):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    return value


class Case:
    """A case: model and settings, ready to run. Build it with a class method."""

    def __init__(self, native: "_native.Case"):
        self._native = native

    @classmethod
    def from_file(cls, path: PathLike) -> "Case":
        """Reads a case file (TOML); relative file names are resolved from its folder."""
        return cls(_native.load_case(os.fspath(path)))

    @classmethod
    def from_toml(cls, text: str, base_dir: PathLike = ".") -> "Case":
        """A case from TOML text."""
        return cls(_native.case_from_toml(text, os.fspath(base_dir)))

    @classmethod
    def from_dict(cls, case: Mapping[str, Any], base_dir: PathLike = ".") -> "Case":
        """A case from a dict with the keys of a case file (numpy arrays allowed). Errors name
        the key path in the dict (`time.dt`, `contacts[0].normal.stiffness`)."""
        return cls(_native.case_from_json(json.dumps(_plain(case)), os.fspath(base_dir)))

    title = property(lambda self: self._native.title, doc="Title of the case.")
    dt = property(lambda self: self._native.dt, doc="Time step, s.")
    steps = property(lambda self: self._native.steps, doc="Number of steps.")
    modes = property(lambda self: self._native.modes, doc="Number of modes.")
    contact_names = property(lambda self: self._native.contact_names, doc="Contact names.")
    frequencies_hz = property(
        lambda self: np.array(self._native.frequencies_hz), doc="Natural frequencies, Hz."
    )

    def __repr__(self) -> str:
        return repr(self._native)


def modal_structure(
    frequencies_hz: Sequence[float],
    points: Mapping[str, Any],
    damping_ratio: Optional[Sequence[float]] = None,
    coords: Optional[Mapping[str, Sequence[float]]] = None,
) -> dict:
    """The `[structure]` of a case from numpy arrays: frequencies (p,), damping ratios (p,),
    and for each point name its mass-normalised rows, shape (3, p) (x, y, z translations)."""
    p = len(frequencies_hz)
    structure: dict = {
        "type": "modal",
        "frequencies_hz": _plain(np.asarray(frequencies_hz, dtype=float)),
        "damping_ratio": _plain(
            np.zeros(p) if damping_ratio is None else np.asarray(damping_ratio, dtype=float)
        ),
        "points": [],
    }
    for name, rows in points.items():
        rows = np.asarray(rows, dtype=float)
        if rows.shape != (3, p):
            raise FretdynError(f"structure.points.{name}: rows must have shape (3, {p}), got {rows.shape}")
        point = {"name": name, "rows": _plain(rows)}
        if coords and name in coords:
            point["coords"] = _plain(np.asarray(coords[name], dtype=float))
        structure["points"].append(point)
    return structure


def _case(case: Union[Case, PathLike], function: str) -> Case:
    """`case` itself, or the case file at a path (str or os.PathLike); `function` names the
    caller in the TypeError of anything else."""
    if isinstance(case, (str, os.PathLike)):
        if isinstance(case, str) and "\n" in case:
            raise TypeError(
                f"fretdyn.{function}: a str is the path of a case file; for TOML text use "
                f"fretdyn.{function}(fretdyn.Case.from_toml(text))"
            )
        return Case.from_file(case)
    if not isinstance(case, Case):
        raise TypeError(
            f"fretdyn.{function} takes a Case (Case.from_file, Case.from_toml, Case.from_dict) "
            f"or the path of a case file (str or os.PathLike), not {type(case).__name__}"
        )
    return case


def run(case: Union[Case, PathLike]) -> dict:
    """Runs a case, or the case file at a path (str or os.PathLike), like `fretdyn run` (the
    GIL is released; Ctrl-C raises KeyboardInterrupt). Returns the arrays of `results.npz` as
    numpy arrays and `summary`, the content of `summary.json` as a dict (its
    `energy_balance` includes `fluid_work`, the work of the fluid-elastic forces, J). A
    diverged run returns what it computed; its `summary["termination"]` says where."""
    case = _case(case, "run")
    out = _native.run(case._native)
    out["summary"] = json.loads(out.pop("summary_json"))
    return out


def stability(case: Union[Case, PathLike]) -> dict:
    """The Connors fluid-elastic stability check of every mode of a case with a `[flow]`
    section, or of the case file at a path, like `fretdyn stability` (docs/FLOW.md). Returns
    one numpy array per column of `stability.csv` — `mode`, `frequency_hz` (Hz),
    `damping_ratio`, `reference_density` (kg/m³), `effective_velocity` and
    `critical_velocity` (m/s), `ratio` (U_eff/U_c; NaN where undefined, inf for an undamped
    mode in a flow) — `reference_zone` (list of str), and the scalars `connors_constant`,
    `diameter` (m) and `mass_per_length` (kg/m). A case without `[flow]` raises
    FretdynError."""
    return _native.stability(_case(case, "stability")._native)


def _read_done(table: Path, header: str) -> set:
    if not table.exists() or table.stat().st_size == 0:
        return set()
    text = table.read_text()
    lines = text.splitlines()
    if lines[0] != header:
        raise FretdynError(f"{table}: has another header: it belongs to another study")
    complete = lines[1:] if text.endswith("\n") else lines[1:-1]
    n = len(header.split(","))
    return {int(l.split(",")[0]) for l in complete if len(l.split(",")) == n}


def _row(study: str, index: int) -> str:
    return _native.study_row(study, index)


def sweep(study: PathLike, table: PathLike, client: Any = None, jobs: int = 0) -> int:
    """Runs a study file (see `fretdyn sweep`) into the CSV `table`, one row per finished run,
    skipping the runs already in it. Without `client`, on this machine, `jobs` runs at a time
    (0: one per core). With a `dask.distributed.Client`, each run is a task on the cluster
    (the workers need this package and the study's files) and rows are written as tasks
    finish. Parameters drawn from distributions (`samples = N`, docs/STUDIES.md) take the
    same values on the cluster as here (each draw is a function of the study seed, the sample
    and the parameter); `percentiles(study, table)` then gives P50/P95/P99 with their errors.
    Returns the number of runs done."""
    study = os.fspath(os.path.abspath(study))
    table = Path(table)
    if client is None:
        return _native.study_local(study, os.fspath(table), jobs)
    from dask.distributed import as_completed

    header = _native.study_header(study)
    done = _read_done(table, header)
    if table.exists() and table.stat().st_size > 0 and not table.read_text().endswith("\n"):
        text = table.read_text()
        table.write_text(text[: text.rfind("\n") + 1])
    pending = [i for i in range(_native.study_runs(study)) if i not in done]
    with open(table, "a", newline="") as f:
        if not done and f.tell() == 0:
            f.write(header + "\n")
        futures = [client.submit(_row, study, i, pure=False) for i in pending]
        for future in as_completed(futures):
            f.write(future.result() + "\n")
            f.flush()
    return len(pending)


def percentiles(study: PathLike, table: PathLike, output: Optional[PathLike] = None) -> Optional[dict]:
    """The percentiles (P50, P95, P99 by default) of a study's statistics across its samples,
    from its table, as `fretdyn sweep` writes them in `percentiles.json` (docs/STUDIES.md):
    `{"confidence", "bootstrap_resamples", "seed", "rows": [{"group", "column", "level", "n",
    "excluded", "estimate", "ci_low", "ci_high", "ci_coverage", "bootstrap_se"}, ...]}`; the
    interval is distribution-free (order statistics), `None` for a bound too few samples give.
    A table written on a Dask cluster gives the same report as one written locally. With
    `output` (a folder), `percentiles.csv` and `percentiles.json` are written there too.
    `None` when the study asks for no percentiles (no `samples`, no `[percentiles]`)."""
    out = _native.study_percentiles(
        os.fspath(os.path.abspath(study)), os.fspath(table),
        None if output is None else os.fspath(output),
    )
    return None if out is None else json.loads(out)


def read_table(table: PathLike) -> dict:
    """A study's table as a dict of numpy arrays (numbers) or lists (text), by column."""
    with open(table, newline="") as f:
        rows = list(csv.reader(f))
    header, body = rows[0], [r for r in rows[1:] if len(r) == len(rows[0])]
    out: dict = {}
    for k, name in enumerate(header):
        col = [r[k] for r in body]
        try:
            out[name] = np.array([float(v) if v else np.nan for v in col])
        except ValueError:
            out[name] = col
    return out

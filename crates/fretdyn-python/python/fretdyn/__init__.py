"""fretdyn: nonlinear vibration of a structure on a modal basis rattling against obstacles with
Coulomb friction (explicit central differences; penalty, Active Set or projected Gauss–Seidel).

    import fretdyn
    case = fretdyn.Case.from_file("examples/v1a_oblique_impact.toml")
    r = fretdyn.run(case)            # a Result: numpy arrays, GIL released, Ctrl-C honoured
    r = fretdyn.run("examples/v1a_oblique_impact.toml")   # the same, from the path
    r.contact_normal_force[:, 0], r.summary["contacts"][0]["wear_work_rate"]
    r.impacts, r.blocks, r.contacts  # tables (pandas DataFrames; contacts indexed by name)
    r.to_xarray()                    # an xarray.Dataset with names, dimensions and units
    fretdyn.plot.orbits(r)           # matplotlib plots for notebooks
    wider = case.with_(**{"contacts[0].obstacle.gap": 1e-4})   # a changed copy
    s = fretdyn.stability("examples/ubend_flow.toml")   # the Connors check, per mode
    table = fretdyn.sweep({"base": case, "parameters": [
        {"key": "contacts[0].friction.mu", "values": [0.1, 0.3]}]})   # a DataFrame
    life = fretdyn.life("examples/tube_multispan_life.toml", years=5)   # the service life
    life.summary, life.depths        # depth per contact, years to the plugging limit
    m = fretdyn.modes("examples/tube_clamped_one_support.toml")   # frequencies, shapes

Cases come from a TOML file, TOML text, or a Python dict with the structure of a case file
(numpy arrays are accepted anywhere a list is). Studies (`sweep`) run on every core, or on a
Dask cluster when given a `dask.distributed.Client`. pandas, xarray and matplotlib are
optional (`pip install fretdyn[all]`). docs/PYTHON_API.md lists the API.
"""

from __future__ import annotations

import csv
import json
import math
import os
import tempfile
from collections.abc import Mapping
from pathlib import Path
from typing import Any, Iterator, List, Optional, Sequence, Tuple, Union

import numpy as np

from . import _native
from ._native import FretdynError
from . import med  # modal bases from Code_Aster's MED files (docs/MED.md)

__all__ = [
    "Case", "Result", "FretdynError", "run", "stability", "sweep", "percentiles",
    "read_table", "modal_structure", "variables", "statistics_columns", "life", "modes",
    "LifeResult", "ModesResult", "plot", "__version__",
]
__version__ = _native.__version__


def __dir__() -> List[str]:
    """The package's API (``__all__`` and its modules ``med`` and ``plot``), not the names it
    imports for itself (``np``, ``os``, ``Any``…)."""
    return sorted(set(__all__) | {"med", "plot"})

PathLike = Union[str, os.PathLike]


# The most parts of a key path (fretdyn::case::key_path::MAX_PARTS): no key of a case is deeper,
# and a dict nested deeper is refused (a dict that holds itself, too).
_MAX_PARTS = 64


class _Unfit(Exception):
    """A value a case cannot hold, found under the keys and indices `parts` (innermost
    first): NaN or an infinity (JSON has neither; a case takes neither from a dict), or a
    value nested more than `_MAX_PARTS` deep."""

    def __init__(self, problem: str):
        super().__init__(problem)
        self.problem = problem
        self.parts: List[Union[str, int]] = []


def _number(x: float) -> str:
    """A non-finite float as the Rust messages show it: NaN, inf, -inf."""
    return "NaN" if x != x else ("inf" if x > 0 else "-inf")


def _non_finite(x: float) -> _Unfit:
    return _Unfit(f"{_number(x)} is not a valid value: give a finite number")


def _too_deep() -> _Unfit:
    return _Unfit(
        f"nested more than {_MAX_PARTS} keys and indices deep: no key of a case is that deep "
        f"(a key path has at most {_MAX_PARTS} parts)"
    )


def _plain(value: Any, depth: int = 0) -> Any:
    """numpy arrays and scalars → lists and Python numbers (for JSON). `depth`: the parts of
    the key path of `value`. Raises _Unfit for NaN, ±inf, or a value deeper than
    `_MAX_PARTS`."""
    if depth > _MAX_PARTS:
        raise _too_deep()
    if isinstance(value, np.ndarray):
        if value.dtype.kind == "O":
            return _plain(value.tolist(), depth)
        if value.size and depth + value.ndim > _MAX_PARTS:
            e = _too_deep()  # at its first element, as a list would be
            e.parts = [0] * (_MAX_PARTS + 1 - depth)
            raise e
        if value.dtype.kind == "f" and not np.isfinite(value).all():
            where = tuple(int(i) for i in np.argwhere(~np.isfinite(value))[0])
            e = _non_finite(float(value[where]))
            e.parts = list(reversed(where))
            raise e
        return value.tolist()
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        raise _non_finite(value)
    if isinstance(value, Case):
        return value.to_dict()
    if isinstance(value, Mapping):
        out = {}
        for k, v in value.items():
            try:
                out[str(k)] = _plain(v, depth + 1)
            except _Unfit as e:
                e.parts.append(str(k))
                raise
        return out
    if isinstance(value, (list, tuple)):
        items = []
        for i, v in enumerate(value):
            try:
                items.append(_plain(v, depth + 1))
            except _Unfit as e:
                e.parts.append(i)
                raise
        return items
    return value


def _shown(path: str) -> str:
    """A key path as the messages name it (fretdyn::case::key_path::abbreviated): whole up to
    200 characters, else its first 100 and its length."""
    if len(path) <= 200:
        return path
    return f"{path[:100]}… (a key path of {len(path)} characters, the first 100 shown)"


def _checked(value: Any, path: str = "") -> Any:
    """`_plain(value)` for a case, a study or a value of `Case.with_` at the key path `path`;
    what a case cannot hold is a FretdynError naming its key path
    (``contacts[0].friction.mu: NaN is not a valid value: give a finite number``)."""
    try:
        return _plain(value)
    except _Unfit as e:
        for part in reversed(e.parts):
            path = f"{path}[{part}]" if isinstance(part, int) else (
                f"{path}.{part}" if path else part)
        raise FretdynError(f"{_shown(path)}: {e.problem}") from None


def _pandas():
    """pandas, or None when it is not installed."""
    try:
        import pandas
    except ImportError:
        return None
    return pandas


def _table(columns: Mapping[str, Any]):
    """Columns (name → sequence, all of one length) as a pandas DataFrame when pandas is
    installed, else as a numpy structured array with the same field names."""
    arrays = {k: np.asarray(v) for k, v in columns.items()}
    pd = _pandas()
    if pd is not None:
        return pd.DataFrame(arrays, columns=list(arrays))
    n = len(next(iter(arrays.values()))) if arrays else 0
    out = np.empty(n, dtype=[(k, a.dtype) for k, a in arrays.items()])
    for k, a in arrays.items():
        out[k] = a
    return out


def variables(modal: bool = True) -> Tuple[List[dict], List[dict]]:
    """The names, dimensions, units and long names of a run's time histories and of the
    coordinates along their dimensions.

    One table in the Rust library (``fretdyn::results::variables``) holds them: ``results.nc``
    is written from it, and `Result.to_xarray` and `fretdyn.plot` take their names, units and
    labels from it, so that ``to_xarray()`` is the Dataset ``xarray.open_dataset`` reads from
    ``results.nc``.

    Parameters
    ----------
    modal : bool, default True
        The units of ``q`` and ``qdot`` of a modal model (``kg^0.5 m``, mass-normalised
        modes); False: of a model in physical coordinates (``m``, ``m s-1``).

    Returns
    -------
    variables : list of dict
        One dict per time history, in the order of ``results.npz``, with the keys ``key``
        (of ``results.npz`` and `Result`: ``t``, ``q``, ``qdot``, ``contact_normal_force``,
        …), ``name`` (in ``results.nc`` and ``to_xarray()``: ``t`` is ``time``, the others
        keep their key), ``dims`` (among ``time``, ``mode``, ``contact``, ``tangent`` (t1,
        t2), ``local_axis`` (e1, e2)), ``units`` (UDUNITS, e.g. ``m s-1``), ``long_name``,
        ``flag_meanings`` (the meanings of a code's values 0, 1, 2, …; empty otherwise) and
        ``coordinates`` (its auxiliary coordinates).
    coordinates : list of dict
        The keys ``name``, ``dims``, ``units`` (None for names), ``long_name`` and
        ``flag_meanings`` of the coordinates besides ``time``: ``mode`` (numbers from 1) with
        ``frequency`` (Hz) and ``damping_ratio``; ``contact`` (names) with
        ``contact_point`` and ``contact_obstacle``; ``tangent``, ``local_axis``; ``point``
        (names) with ``point_position`` (m, along ``direction``: x, y, z); and those only
        the results of a model of several structures or with two-body contacts have:
        ``structure`` (names) with ``mode_structure`` and ``point_structure`` (the
        structure of each mode and point), ``contact_other_point`` (point B of a two-body
        contact, empty for an obstacle).

    Examples
    --------
    >>> names, coords = fretdyn.variables()
    >>> {v["key"]: v["units"] for v in names}["contact_slip_velocity"]
    'm s-1'
    """
    return _native.variables(modal)


def statistics_columns() -> List[dict]:
    """The per-contact statistics of a run, with their units and names.

    One table in the Rust library (``fretdyn::accumulate::statistics::columns``) holds them:
    ``summary["contacts"]``, ``contacts.csv`` (and `Result.contacts`), the statistics of a
    study's table (``<contact>.<key>``) and ``blocks.csv`` (`Result.blocks`) are derived from
    it.

    Returns
    -------
    list of dict
        One dict per statistic, in the order of the columns of ``contacts.csv``, with the keys
        ``key`` (e.g. ``wear_work_rate``), ``unit`` (SI; ``1`` for a number without one),
        ``long_name`` (a short readable name, for labels), ``meaning``, ``code_aster`` (its
        name in Code_Aster's ``POST_DYNA_MODA_T``; empty when Code_Aster has none),
        ``count`` (True for an integer), ``se_key`` (the key of its standard error by batch
        means, ``<key>_se``, or None), ``study`` and ``blocks`` (whether a study's table and
        ``blocks.csv`` have it).

    Examples
    --------
    >>> units = {s["key"]: s["unit"] for s in fretdyn.statistics_columns()}
    >>> units["wear_work_rate"]
    'W'
    """
    return _native.statistics_columns()


def _units() -> dict:
    """key or name → the dict of `variables` for every time history and coordinate."""
    names, coords = _native.variables()
    table = {v["name"]: v for v in [*names, *coords]}
    table.update({v["key"]: v for v in names})
    return table


class Case:
    """A case: model and settings, ready to run.

    Build it with a class method (`from_file`, `from_toml`, `from_dict`); `with_` gives a
    changed copy, `to_dict` the case as a dict. A Case is immutable.

    Examples
    --------
    >>> case = fretdyn.Case.from_file("examples/v1a_oblique_impact.toml")
    >>> case.dt, case.steps, case.contact_names
    (1e-06, 4000, ['plane'])
    """

    def __init__(self, native: "_native.Case"):
        self._native = native

    @classmethod
    def from_file(cls, path: PathLike) -> "Case":
        """Reads a case file.

        Parameters
        ----------
        path : str or os.PathLike
            A case file (TOML); its relative file names are resolved from its folder.

        Returns
        -------
        Case

        Raises
        ------
        FretdynError
            The file cannot be read or is not a valid case; the message names the file, the
            field and the fix, as the CLI's.

        Examples
        --------
        >>> case = fretdyn.Case.from_file("examples/tube_multispan.toml")
        """
        return cls(_native.load_case(os.fspath(path)))

    @classmethod
    def from_toml(cls, text: str, base_dir: PathLike = ".") -> "Case":
        """A case from the text of a case file.

        Parameters
        ----------
        text : str
            TOML text with the keys of a case file.
        base_dir : str or os.PathLike, default "."
            Folder its relative file names are resolved from.

        Returns
        -------
        Case

        Examples
        --------
        >>> text = open("examples/v1a_oblique_impact.toml").read()
        >>> case = fretdyn.Case.from_toml(text.replace("mu = 0.3", "mu = 0.5"))
        """
        return cls(_native.case_from_toml(text, os.fspath(base_dir)))

    @classmethod
    def from_dict(cls, case: Mapping[str, Any], base_dir: PathLike = ".") -> "Case":
        """A case from a dict with the keys of a case file.

        Parameters
        ----------
        case : Mapping
            The tables of a case file as dicts, arrays of tables as lists of dicts; numpy
            arrays and numbers are accepted anywhere a list or a number is. Numbers are
            finite (JSON, which carries the dict, has no NaN or infinity), and no value is
            more than 64 keys and indices deep (no key of a case is).
        base_dir : str or os.PathLike, default "."
            Folder its relative file names are resolved from.

        Returns
        -------
        Case

        Raises
        ------
        FretdynError
            The message starts with the key path in the dict (``time.dt``,
            ``contacts[0].normal.stiffness``), for a NaN or an infinity too
            (``contacts[0].friction.mu: NaN is not a valid value: give a finite number``).

        Examples
        --------
        >>> case = fretdyn.Case.from_dict(other.to_dict())
        """
        return cls(_native.case_from_json(json.dumps(_checked(case)), os.fspath(base_dir)))

    def with_(self, changes: Optional[Mapping[str, Any]] = None, /, **values: Any) -> "Case":
        """A copy of the case with some values changed, by the key paths of studies.

        A key path is dotted keys with indices: ``time.dt``, ``contacts[0].friction.mu``
        (or ``contacts.0.friction.mu``), ``contacts.*.obstacle.clearance`` (``*``: every
        element), of at most 64 parts (a longer one, built by mistake, is refused at once).
        Keys missing from a table are added (``output.every``), then the case is read again
        as a whole: a key the case format does not have, or a value it does not take, is an
        error naming the key path.

        Parameters
        ----------
        changes : Mapping, optional
            Key path → value, applied in order (use it for paths that are not Python
            names: ``{"contacts[0].obstacle.clearance": 2e-4}``).
        **values
            More key paths and values, applied after `changes`.

        Returns
        -------
        Case
            A new case; this one is unchanged.

        Raises
        ------
        FretdynError
            The message starts with the key path exactly as given (one of more than 200
            characters: its first 100 and its length), then where it fails when that is a
            part of it: ``contacts[2].obstacle.gap: contacts[2]: no such element; contacts
            has 1 element (index 0)``, ``contacts.*.friction.mu: contacts[1].friction.mu:
            must be a friction coefficient ≥ 0 (got -0.1)``; a NaN or an infinity in a value:
            ``time.dt: NaN is not a valid value: give a finite number``.

        Examples
        --------
        >>> tight = case.with_({"contacts.*.obstacle.clearance": 5e-5})
        >>> fine = case.with_(**{"time.dt": 5e-7, "contacts[0].friction.mu": 0.2})
        """
        items = [*(changes or {}).items(), *values.items()]
        pairs = [[str(k), _checked(v, str(k))] for k, v in items]
        return Case(_native.case_with(self._native, json.dumps(pairs)))

    def to_dict(self) -> dict:
        """The case as a dict with the structure of a case file.

        It is the TOML the case was read from (with the changes of `with_`) and its title;
        file names are absolute, so that ``Case.from_dict(case.to_dict())`` is the same case
        from any folder.

        Returns
        -------
        dict

        Examples
        --------
        >>> d = case.to_dict()
        >>> d["time"]["dt"]
        1e-06
        """
        return json.loads(self._native.to_json())

    @property
    def title(self) -> str:
        """Title of the case (its file's name when it gives none)."""
        return self._native.title

    @property
    def dt(self) -> float:
        """Time step, s."""
        return self._native.dt

    @property
    def steps(self) -> int:
        """Number of steps."""
        return self._native.steps

    @property
    def modes(self) -> int:
        """Number of modes of the basis."""
        return self._native.modes

    @property
    def contact_names(self) -> List[str]:
        """Names of the contacts, in the order of the results' contact axis."""
        return self._native.contact_names

    @property
    def contact_points(self) -> List[str]:
        """Names of the structure points of the contacts, in the order of the contacts."""
        return self._native.contact_points

    @property
    def contact_other_points(self) -> List[str]:
        """Point B of each two-body contact (a contact between two points, of one structure
        or two), empty for a contact with an obstacle, in the order of the contacts. The
        results of a two-body contact (positions, slip) are of its point relative to it."""
        return self._native.contact_other_points

    @property
    def structures(self) -> List[str]:
        """Names of the structures of a model of several (``[[structures]]``; their points
        and contacts are named ``structure.name``), empty for a model of one."""
        return self._native.structures

    @property
    def frequencies_hz(self) -> np.ndarray:
        """Natural frequencies of the basis, Hz, shape (modes,)."""
        return np.array(self._native.frequencies_hz)

    @property
    def base_dir(self) -> Path:
        """Folder the case's relative file names are resolved from."""
        return Path(self._native.base_dir)

    def __repr__(self) -> str:
        return repr(self._native)


def modal_structure(
    frequencies_hz: Sequence[float],
    points: Mapping[str, Any],
    damping_ratio: Optional[Sequence[float]] = None,
    coords: Optional[Mapping[str, Sequence[float]]] = None,
) -> dict:
    """The ``[structure]`` of a case from numpy arrays.

    Parameters
    ----------
    frequencies_hz : array_like, shape (p,)
        Natural frequencies, Hz.
    points : Mapping
        Point name → its mass-normalised mode-shape rows, shape (3, p) (x, y, z
        translations).
    damping_ratio : array_like, shape (p,), optional
        Modal damping ratios (default 0).
    coords : Mapping, optional
        Point name → its reference position (3,), m.

    Returns
    -------
    dict
        A ``type = "modal"`` structure for `Case.from_dict`.

    Raises
    ------
    FretdynError
        Rows of the wrong shape; a NaN or an infinity, named
        (``structure.frequencies_hz[1]: NaN is not a valid value: give a finite number``).

    Examples
    --------
    >>> structure = fretdyn.modal_structure([0.0] * 3, {"mass": np.eye(3)})
    """
    p = len(frequencies_hz)
    structure: dict = {
        "type": "modal",
        "frequencies_hz": _checked(np.asarray(frequencies_hz, dtype=float),
                                   "structure.frequencies_hz"),
        "damping_ratio": _checked(
            np.zeros(p) if damping_ratio is None else np.asarray(damping_ratio, dtype=float),
            "structure.damping_ratio",
        ),
        "points": [],
    }
    for name, rows in points.items():
        rows = np.asarray(rows, dtype=float)
        if rows.shape != (3, p):
            raise FretdynError(f"structure.points.{name}: rows must have shape (3, {p}), got {rows.shape}")
        point = {"name": name, "rows": _checked(rows, f"structure.points.{name}.rows")}
        if coords and name in coords:
            point["coords"] = _checked(np.asarray(coords[name], dtype=float),
                                       f"structure.points.{name}.coords")
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


_ARRAYS = [
    "t", "q", "qdot", "contact_normal_force", "contact_tangential_force",
    "contact_slip_velocity", "contact_penetration", "contact_status", "contact_position",
]


def _flatten(entry: Mapping[str, Any], prefix: str = "") -> dict:
    """The numbers and strings of a (nested) dict, nested keys joined by dots; lists (the
    peak force histogram) are left out."""
    out: dict = {}
    for k, v in entry.items():
        if isinstance(v, Mapping):
            out.update(_flatten(v, f"{prefix}{k}."))
        elif not isinstance(v, (list, tuple)):
            out[f"{prefix}{k}"] = v
    return out


class Result(Mapping):
    """What `run` returns: the time histories, the summary, the tables of a run.

    The arrays are the keys of ``results.npz`` (attributes, or items for code written for
    the dict `run` returned before: ``r["contact_normal_force"]``, ``r["summary"]``); their
    dimensions and units are given by `variables` and kept by `to_xarray`.

    Examples
    --------
    >>> r = fretdyn.run("examples/v1a_oblique_impact.toml")
    >>> r.t.shape, r.contact_normal_force.shape
    ((4001,), (4001, 1))
    >>> r.summary["contacts"][0]["wear_work_rate"] == r.contacts.loc["plane", "wear_work_rate"]
    True
    """

    def __init__(self, native: dict, case: Case):
        self._arrays = {k: native[k] for k in _ARRAYS}
        self._summary = json.loads(native["summary_json"])
        self._impacts = native["impacts"]
        self._blocks = native["blocks"]
        self._case = case

    # the mapping of the dict `run` returned before: the arrays and "summary"
    def __getitem__(self, key: str) -> Any:
        if key == "summary":
            return self._summary
        return self._arrays[key]

    def __iter__(self) -> Iterator[str]:
        return iter([*self._arrays, "summary"])

    def __len__(self) -> int:
        return len(self._arrays) + 1

    # a Mapping compares its items, which numpy arrays cannot do as one bool: identity instead
    __eq__ = object.__eq__
    __hash__ = object.__hash__

    def __repr__(self) -> str:
        status = self._summary["termination"]["status"]
        return (
            f"Result({self._case.title!r}, {len(self.t)} samples, "
            f"{len(self.contact_names)} contacts, {status})"
        )

    @property
    def t(self) -> np.ndarray:
        """Time of the samples, s, shape (N,)."""
        return self._arrays["t"]

    @property
    def q(self) -> np.ndarray:
        """Modal displacements (mass-normalised modes), kg^0.5 m, shape (N, modes)."""
        return self._arrays["q"]

    @property
    def qdot(self) -> np.ndarray:
        """Modal velocities (full step), kg^0.5 m s-1, shape (N, modes)."""
        return self._arrays["qdot"]

    @property
    def contact_normal_force(self) -> np.ndarray:
        """Normal contact force R_N ≥ 0, N, shape (N, contacts)."""
        return self._arrays["contact_normal_force"]

    @property
    def contact_tangential_force(self) -> np.ndarray:
        """Tangential force of the obstacle on the structure in the contact's tangent basis
        (t1, t2), N, shape (N, contacts, 2)."""
        return self._arrays["contact_tangential_force"]

    @property
    def contact_slip_velocity(self) -> np.ndarray:
        """Tangential velocity relative to the obstacle (full step), tangent basis (t1, t2),
        m s-1, shape (N, contacts, 2)."""
        return self._arrays["contact_slip_velocity"]

    @property
    def contact_penetration(self) -> np.ndarray:
        """Penetration δ, m (negative: remaining clearance), shape (N, contacts)."""
        return self._arrays["contact_penetration"]

    @property
    def contact_status(self) -> np.ndarray:
        """Contact status, int8: 0 open, 1 stick, 2 slip, shape (N, contacts)."""
        return self._arrays["contact_status"]

    @property
    def contact_position(self) -> np.ndarray:
        """The point relative to the obstacle, m, shape (N, contacts, 2), along the
        obstacle's axes (e1, e2): in a hole, its offset from the hole's centre in the hole's
        axes (the orbit); for a plane or bars, the distance from the plane (e1) and the
        position along t1 (e2)."""
        return self._arrays["contact_position"]

    @property
    def summary(self) -> dict:
        """The content of ``summary.json``: per-contact statistics, energy balance, solver
        counters, the case as read."""
        return self._summary

    @property
    def case(self) -> Case:
        """The case that was run."""
        return self._case

    @property
    def contact_names(self) -> List[str]:
        """Names of the contacts, in the order of the contact axis of the arrays."""
        return [c["name"] for c in self._summary["contacts"]]

    @property
    def impacts(self):
        """One row per impact, the columns of ``impacts.csv``.

        ``contact`` (index), ``name``, ``start``, ``duration``, ``contact_time``,
        ``peak_time`` (s), ``peak_force`` (N), ``impulse`` (N s), ``impact_speed``,
        ``rebound_speed`` (m/s), ``rebounds``, ``angle_deg``: a pandas DataFrame when pandas
        is installed, else a numpy structured array with these fields.
        """
        return _table(self._impacts)

    @property
    def blocks(self):
        """The statistics of each block (batch) of the statistics window, the columns of
        ``blocks.csv`` (``block``, ``t_start``, ``t_end``, ``name``, ``impacts``, …): a
        pandas DataFrame when pandas is installed, else a numpy structured array."""
        return _table(self._blocks)

    @property
    def contacts(self):
        """The per-contact statistics of the summary, one row per contact.

        The columns are the keys of ``summary["contacts"]`` (``name`` first; nested keys
        joined by dots; the peak force histogram left out), as in ``contacts.csv``: a pandas
        DataFrame indexed by the contact's name (``r.contacts.loc["plate3",
        "wear_work_rate"]``; the index is named ``contact``) when pandas is installed, else
        a numpy structured array.
        """
        rows = [_flatten(c) for c in self._summary["contacts"]]
        keys: List[str] = ["name"]
        for r in rows:
            keys += [k for k in r if k not in keys]
        columns = {}
        for k in keys:
            values = [r.get(k, np.nan) for r in rows]
            if all(isinstance(v, str) for v in values):
                columns[k] = np.array(values, dtype=str)
            else:
                columns[k] = np.array([np.nan if v is None else v for v in values])
        out = _table(columns)
        if hasattr(out, "set_index"):
            out.index = _pandas().Index(columns["name"], name="contact")
        return out

    def to_xarray(self):
        """The time histories as an xarray Dataset with names and units: the Dataset
        ``xarray.open_dataset`` reads from the ``results.nc`` of ``fretdyn run``.

        The same variables, dimensions, coordinates and attributes, from the one table of
        `variables`: dimensions ``time``, ``mode``, ``contact``, ``tangent`` (t1, t2),
        ``local_axis`` (e1, e2), ``point``, ``direction`` (x, y, z); coordinates ``time``
        (s; the key ``t``), ``mode`` (numbers from 1) with ``frequency`` (Hz) and
        ``damping_ratio``, ``contact`` (names) with ``contact_point`` and
        ``contact_obstacle``, ``point`` (names) with ``point_position`` (m), and the labels
        of ``tangent``, ``local_axis`` and ``direction`` (and for a model of several
        structures or with two-body contacts ``structure`` with ``mode_structure``,
        ``point_structure``, and ``contact_other_point``); every other array under its key.
        Every variable has ``units`` (UDUNITS; names have none) and ``long_name``;
        ``contact_status`` has CF ``flag_values`` and ``flag_meanings``. The Dataset's
        attributes are ``title``, ``fretdyn_version``, ``comment`` and ``summary`` (the
        summary as JSON text, the case included; ``results.nc`` has the case file's text as
        ``case`` too), so that ``to_netcdf`` writes it.

        Returns
        -------
        xarray.Dataset

        Raises
        ------
        ImportError
            xarray is not installed (``pip install xarray``).

        Examples
        --------
        >>> ds = r.to_xarray()
        >>> ds.contact_normal_force.sel(contact="plate3").max().item()
        >>> ds.contact_slip_velocity.sel(tangent="t1").attrs["units"]
        'm s-1'
        """
        try:
            import xarray as xr
        except ImportError as e:
            raise ImportError(
                "Result.to_xarray needs xarray: pip install xarray (or fretdyn[xarray])"
            ) from e
        values, modal = _native.coordinates(self._case._native)
        names, coords_table = _native.variables(modal)

        def attrs(v: dict) -> dict:
            a = {} if v["units"] is None else {"units": v["units"]}
            a["long_name"] = v["long_name"]
            if v["flag_meanings"]:
                a["flag_values"] = np.arange(len(v["flag_meanings"]), dtype=np.int8)
                a["flag_meanings"] = " ".join(v["flag_meanings"])
            return a

        coords = {}
        for v in coords_table:
            if v["name"] not in values:  # of several structures, two-body contacts
                continue
            x = values[v["name"]]
            if isinstance(x, list):  # names
                x = np.array(x, dtype=str)
            coords[v["name"]] = (v["dims"], x, attrs(v))
        data = {}
        for v in names:
            entry = (v["dims"], self._arrays[v["key"]], attrs(v))
            if v["name"] in v["dims"]:  # t: the coordinate time
                coords[v["name"]] = entry
            else:
                data[v["name"]] = entry
        return xr.Dataset(
            data,
            coords=coords,
            attrs={
                "title": self._summary.get("title", self._case.title),
                "fretdyn_version": self._summary.get("fretdyn_version", __version__),
                "comment": _native.RESULTS_COMMENT,
                "summary": json.dumps(self._summary),
            },
        )


def run(case: Union[Case, PathLike]) -> Result:
    """Runs a case, like ``fretdyn run``.

    The GIL is released during the run; Ctrl-C raises KeyboardInterrupt. Every sample is kept
    in memory: a run whose time histories would not fit is refused with their size (raise
    ``[output] every``, or use ``fretdyn run``, which streams them to disk).

    Parameters
    ----------
    case : Case, str or os.PathLike
        A case, or the path of a case file.

    Returns
    -------
    Result
        The arrays of ``results.npz``, the summary (``summary.json``; its
        ``energy_balance`` includes ``fluid_work``, the work of the fluid-elastic forces, J),
        the impacts, blocks and per-contact tables. A diverged run returns what it computed;
        its ``summary["termination"]`` says where.

    Raises
    ------
    FretdynError
        The case cannot run (Δt above the stable limit, too large for the memory, …).
    TypeError
        `case` is neither a Case nor a path.

    Examples
    --------
    >>> r = fretdyn.run("examples/v1a_oblique_impact.toml")
    >>> r.summary["termination"]["status"]
    'completed'
    >>> r.impacts["peak_force"].max() == r.contact_normal_force.max()
    """
    case = _case(case, "run")
    return Result(_native.run(case._native), case)


def stability(case: Union[Case, PathLike]) -> dict:
    """The Connors fluid-elastic stability check of every mode, like ``fretdyn stability``.

    Parameters
    ----------
    case : Case, str or os.PathLike
        A case with a ``[flow]`` section (docs/FLOW.md), or the path of its file.

    Returns
    -------
    dict
        One row per mode: the basis's modes (condition ``support_inactive``), then those of
        each support condition of ``[stability]`` (docs/FLOW.md). One numpy array per numeric
        column of ``stability.csv`` — ``mode``, ``frequency_hz`` (Hz), ``damping_ratio``,
        ``reference_density`` (kg/m³), ``effective_velocity`` and ``critical_velocity``
        (m/s), ``ratio`` (U_eff/U_c; NaN where undefined, inf for an undamped mode in a
        flow), ``out_of_plane_share`` (NaN when the structure has no plane) —
        ``reference_zone``, ``condition`` and ``plane`` (``in_plane``, ``out_of_plane``,
        ``mixed``, or ``""`` without a plane) as lists of str, and the scalars
        ``connors_constant``, ``diameter`` (m) and ``mass_per_length`` (kg/m).

    Raises
    ------
    FretdynError
        The case has no ``[flow]``.

    Examples
    --------
    >>> s = fretdyn.stability("examples/ubend_flow.toml")
    >>> s["ratio"] > 1.0
    """
    return _native.stability(_case(case, "stability")._native)


def _study_source(study: Union[PathLike, Mapping[str, Any]], base_dir: Optional[PathLike]):
    """What `_native` takes for a study: the absolute path of a study file, or for a dict,
    ``(JSON, base_dir)`` with its ``base`` as a path (relative to `base_dir`) or a case dict
    (checked here first, so that its errors name ``base.<key path>``)."""
    if not isinstance(study, Mapping):
        if base_dir is not None:
            raise TypeError("base_dir is for a study given as a dict; a study file's base "
                            "is relative to the file")
        return os.fspath(os.path.abspath(study))
    folder = os.path.abspath(base_dir if base_dir is not None else ".")
    study = dict(study)
    base = study.get("base")
    if isinstance(base, Case):
        folder = os.fspath(base.base_dir)
        study["base"] = base.to_dict()
    elif isinstance(base, Mapping):
        try:
            Case.from_dict(base, folder)
        except FretdynError as e:
            raise FretdynError(f"base.{e}") from None
    elif isinstance(base, os.PathLike):
        study["base"] = os.fspath(base)
    return (json.dumps(_checked(study)), folder)


def _row(study: Any, index: int) -> str:
    return _native.study_row(study, index)


def _frame(table: Path):
    """A study table sorted by run: a DataFrame with pandas, else a structured array."""
    columns = read_table(table)
    order = np.argsort(columns["run"], kind="stable") if "run" in columns else None
    out = {}
    for k, v in columns.items():
        a = np.asarray(v) if isinstance(v, np.ndarray) else np.array(v, dtype=str)
        out[k] = a if order is None else a[order]
    return _table(out)


def sweep(
    study: Union[PathLike, Mapping[str, Any]],
    table: Optional[PathLike] = None,
    client: Any = None,
    jobs: int = 0,
    base_dir: Optional[PathLike] = None,
    fresh: bool = False,
):
    """Runs a study, like ``fretdyn sweep``, and returns its table.

    One row per finished run is appended to the CSV `table`; runs already in it are skipped
    (run it again after a crash) — only when they were computed from the inputs the study
    gives them now: each row carries the fingerprint of its run's case as resolved and of
    the files it reads, and a table with a row of other inputs (the base case, a file or a
    parameter's values changed since) is refused, saying what changed (``fresh=True``
    starts afresh). The table is locked while the study writes it: a second study on it is
    refused. Parameters drawn from distributions (``samples = N``,
    docs/STUDIES.md) take the same values on a cluster as here (each draw is a function of
    the study seed, the sample and the parameter); `percentiles` then gives P50/P95/P99 with
    their errors.

    Parameters
    ----------
    study : str, os.PathLike or Mapping
        A study file, or a dict with its structure: ``base`` (the path of a case file,
        relative to `base_dir`; a case as a dict; or a `Case`), ``parameters`` (a list of
        ``{"key": key path, "values": [...]}`` or ``{"key", "distribution", "independent"}``),
        and optionally ``combine``, ``seeds``, ``samples``, ``seed``, ``percentiles``.
    table : str or os.PathLike, optional
        The CSV table the rows go to; without it, a temporary file (removed after it is
        read).
    client : dask.distributed.Client, optional
        Run each run as a task on this Dask cluster (the workers need this package and the
        study's files); rows are written as tasks finish. Without it, on this machine.
    jobs : int, default 0
        Runs at a time on this machine (0: one per core).
    base_dir : str or os.PathLike, optional
        For a dict study: the folder its ``base`` path and the case's file names are
        relative to (default: the current folder).
    fresh : bool, default False
        Replace an existing `table` instead of continuing it.

    Returns
    -------
    pandas.DataFrame or numpy structured array
        The whole table (every run in it, this call's and earlier ones'), sorted by run: a
        DataFrame when pandas is installed (its ``attrs["runs_done"]`` is the number of runs
        this call did), else a structured array.

    Raises
    ------
    FretdynError
        A bad study (naming the key, e.g. ``parameters[0].key``), or a run whose values make
        an invalid case (before any run starts); a `table` of other inputs, or one another
        study is writing; on Dask, a row a worker computed from other files than here.

    Examples
    --------
    >>> t = fretdyn.sweep("examples/study_clearance.toml", "study.csv")
    >>> t = fretdyn.sweep({"base": case, "parameters": [
    ...     {"key": "contacts.*.friction.mu", "values": [0.1, 0.2, 0.3]}]})
    >>> t.plot(x="contacts.*.friction.mu", y="plane.wear_work_rate")
    """
    source = _study_source(study, base_dir)
    if table is None:
        with tempfile.TemporaryDirectory(prefix="fretdyn-sweep-") as tmp:
            return sweep(study, Path(tmp) / "study.csv", client, jobs, base_dir, fresh)
    table = Path(table)
    if client is None:
        done = _native.study_local(source, os.fspath(table), jobs, fresh)
    else:
        done = _sweep_on_dask(source, table, client, fresh)
    out = _frame(table)
    if hasattr(out, "attrs"):
        out.attrs["runs_done"] = done
    return out


def _sweep_on_dask(source: Any, table: Path, client: Any, fresh: bool) -> int:
    from dask.distributed import as_completed

    # the table is checked, locked and appended to by the library, as on this machine: each
    # row a worker returns is checked to be of this study's inputs here
    opened = _native.open_study_table(source, os.fspath(table), fresh)
    try:
        pending = opened.pending()
        futures = [client.submit(_row, source, i, pure=False) for i in pending]
        for future in as_completed(futures):
            opened.append(future.result())
    finally:
        opened.close()
    return len(pending)


def percentiles(
    study: Union[PathLike, Mapping[str, Any]],
    table: PathLike,
    output: Optional[PathLike] = None,
    base_dir: Optional[PathLike] = None,
):
    """The percentiles of a study's statistics across its samples, as ``fretdyn sweep``
    writes them in ``percentiles.csv`` and ``percentiles.json`` (docs/STUDIES.md).

    The interval is distribution-free (order statistics); a table written on a Dask cluster
    gives the same report as one written locally.

    Parameters
    ----------
    study : str, os.PathLike or Mapping
        The study file, or the dict, that `sweep` ran.
    table : str or os.PathLike
        Its table.
    output : str or os.PathLike, optional
        A folder to write ``percentiles.csv`` and ``percentiles.json`` into. A value the
        samples cannot give is an empty cell of ``percentiles.csv``, as in the study table
        (`read_table` and pandas read NaN), and ``null`` in ``percentiles.json``.
    base_dir : str or os.PathLike, optional
        For a dict study, as in `sweep`.

    Returns
    -------
    pandas.DataFrame, numpy structured array or None
        One row per group, column and level, the columns of ``percentiles.csv``: the grid
        parameters that define the group (typed as `read_table` types the study table:
        float64, int64 for ``seed``), then ``column``, ``level``, ``n``, ``excluded``
        (int64), ``estimate``, ``ci_low``, ``ci_high``, ``ci_coverage``, ``bootstrap_se``
        (NaN for what too few samples cannot give: a bound, the bootstrap error of fewer
        than 2 values, the estimate of none). A DataFrame (like `sweep`'s) whose ``attrs``
        hold ``confidence``, ``bootstrap_resamples`` and ``seed``; without pandas a
        structured array. ``None`` when the study asks for no percentiles (no ``samples``,
        no ``[percentiles]``).

    Examples
    --------
    >>> p = fretdyn.percentiles("examples/study_clearance_probabilistic.toml", "study.csv")
    >>> p[["column", "level", "estimate", "ci_low", "ci_high"]]
    >>> p.set_index(["column", "level"]).loc[("plate3.wear_work_rate", 95), "estimate"]
    """
    out = _native.study_percentiles(
        _study_source(study, base_dir), os.fspath(table),
        None if output is None else os.fspath(output),
    )
    if out is None:
        return None
    report = json.loads(out)
    rows = report["rows"]
    groups: List[str] = []
    for r in rows:
        groups += [k for k in r["group"] if k not in groups]
    columns: dict = {k: _typed(k, [r["group"].get(k, "") for r in rows]) for k in groups}
    columns["column"] = np.array([r["column"] for r in rows], dtype=str)
    for k in ("level", "n", "excluded"):
        columns[k] = np.array([r[k] for r in rows], dtype=np.int64)
    for k in ("estimate", "ci_low", "ci_high", "ci_coverage", "bootstrap_se"):
        columns[k] = np.array([np.nan if r[k] is None else r[k] for r in rows], dtype=float)
    frame = _table(columns)
    if hasattr(frame, "attrs"):
        frame.attrs.update({k: v for k, v in report.items() if k != "rows"})
    return frame


def _typed(name: str, cells: List[str]) -> Union[np.ndarray, List[str]]:
    """A column of a study's table from its cells: numbers as float64 (NaN where empty),
    the counts ``run``, ``sample``, ``seed`` (a study's table), ``level``, ``n`` and
    ``excluded`` (``percentiles.csv``) as int64 when every cell is an integer; text (a
    column with a cell that is not a number) as a list of str."""
    try:
        numbers = np.array([float(v) if v else np.nan for v in cells])
    except ValueError:
        return list(cells)
    if name in _INTEGER_COLUMNS and all(v.isdigit() for v in cells):
        return np.array([int(v) for v in cells], dtype=np.int64)
    return numbers


def read_table(table: PathLike) -> dict:
    """A study's table by column.

    Parameters
    ----------
    table : str or os.PathLike
        A CSV table written by `sweep` or ``fretdyn sweep`` (``study.csv``, or its
        ``percentiles.csv``).

    Returns
    -------
    dict
        Column name → numpy array of floats (numbers; NaN where empty) or list of str (text),
        complete rows only, in the order of the file. The counts ``run``, ``sample`` and
        ``seed`` (of ``study.csv``), ``level``, ``n`` and ``excluded`` (of
        ``percentiles.csv``) are arrays of int64 when every row has one.

    Examples
    --------
    >>> t = fretdyn.read_table("study.csv")
    >>> t["plane.wear_work_rate"]
    """
    with open(table, newline="") as f:
        rows = list(csv.reader(f))
    header, body = rows[0], [r for r in rows[1:] if len(r) == len(rows[0])]
    return {name: _typed(name, [r[k] for r in body]) for k, name in enumerate(header)}


# the columns of a study's table that count runs, samples and seeds, and those of
# percentiles.csv that count levels and values: integers
_INTEGER_COLUMNS = ("run", "sample", "seed", "level", "n", "excluded")


from ._life import LifeResult, ModesResult, life, modes  # noqa: E402
from . import plot  # noqa: E402  (matplotlib is imported when a plot is drawn)

"""The service life (`fretdyn.life`) and the modal basis (`fretdyn.modes`) of a case, computed
by the library as ``fretdyn life`` and ``fretdyn modes`` compute them, and their tables."""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any, List, Optional, Union

import numpy as np

from . import _native
from ._native import FretdynError

PathLike = Union[str, os.PathLike]

# Seconds in a year (fretdyn::apps::life::YEAR: 365.25 days).
YEAR = 365.25 * 86_400.0

# The columns of each contact in life.csv, in its order (fretdyn life), with their units.
LIFE_COLUMNS = {
    "wear_work_rate": "W",
    "wear_work_rate_se": "W",
    "tube_volume": "m3",
    "support_volume": "m3",
    "tube_depth": "m",
    "support_depth": "m",
    "clearance_increase": "m",
    "tube_depth_fixed_gap": "m",
}

_LONG_NAMES = {
    "wear_work_rate": "wear work rate of the window that drove the life step",
    "wear_work_rate_se": "standard error of the wear work rate (batch means)",
    "tube_volume": "wear volume of the tube",
    "support_volume": "wear volume of the support",
    "tube_depth": "depth of the tube's scar, scars fed back into the obstacles",
    "tube_depth_se": "first-order standard error of the tube's depth",
    "support_depth": "depth of the support's scar",
    "clearance_increase": "clearance the scars add where they are deepest",
    "tube_depth_fixed_gap": "depth of the tube's scar at fixed gap (the first window's rates)",
}


def _pandas():
    try:
        import pandas
    except ImportError as e:
        raise ImportError(
            "fretdyn.life and fretdyn.modes return pandas DataFrames: pip install pandas "
            "(or fretdyn[pandas])"
        ) from e
    return pandas


def _when(t: float) -> str:
    """A service time in a message, as the CLI writes it: in years, or in seconds below a
    hundredth of a year."""
    if t == 0.0 or t >= 0.01 * YEAR:
        return f"{t / YEAR:.4f} years"
    return f"{t:.4e} s"


def _end_message(end: dict, steps: List[dict], target: float, max_steps: Optional[int]) -> str:
    """The message of a life cut short, the CLI's words (``fretdyn life``)."""
    status = end["status"]
    if status == "step_limit":
        last = steps[-1]["time"] if steps else 0.0
        return (
            f"life: the target was not reached in max_steps = {max_steps} life steps (at "
            f"{_when(last)}): raise life.max_steps or life.max_depth_change"
        )
    if status == "scar_limit":
        return (
            f"life: at {_when(end['time'])} the scar of contact '{end['contact']}' reached the "
            f"limit of its geometry ({end['message']})"
        )
    if status == "step_too_short":
        return (
            f"life: at {_when(end['time'])}, tube depth {end['depth']:.4e} m, the life step that "
            f"keeps the depth change of contact '{end['contact']}' within life.max_depth_change "
            f"is {end['step']:.3e} s, below what the service time resolves there (t + Δt = t): "
            f"the depth grows too fast there to be followed to {target / YEAR:g} years; raise "
            "life.max_depth_change or life.depth_resolution, or shorten life.target_years"
        )
    if status == "diverged":
        contact = f", contact '{end['contact']}'" if end.get("contact") else ""
        return (
            f"life: window {end['window']} (at {_when(end['time'])}) diverged at step "
            f"{end['step']}{contact}"
        )
    return f"life: {status}"


def _depths(results: dict):
    """The life's rows as a tidy DataFrame: one row per life step and contact."""
    pd = _pandas()
    rows = []
    names = results["contacts"]
    for step, s in enumerate(results["steps"]):
        for name, c in zip(names, s["contacts"]):
            row = {"step": step, "time_years": s["time"] / YEAR, "contact": name}
            for k in LIFE_COLUMNS:
                v = c[k]
                row[k] = np.nan if v is None else float(v)
            rows.append(row)
    columns = ["step", "time_years", "contact", *LIFE_COLUMNS]
    out = pd.DataFrame(rows, columns=columns)
    out["step"] = out["step"].astype(np.int64)
    # the first-order standard error of the depth: each life step's depth increment scaled
    # by the relative standard error of the wear work rate that drove it, the steps' errors
    # taken as independent (the windows are independent simulations); the library's, as
    # `fretdyn life` draws it in life.png
    se = np.full(len(out), np.nan)
    for name in names:
        rows_of = np.flatnonzero(out["contact"].to_numpy() == name)

        def column(key):
            return out[key].to_numpy()[rows_of].tolist()

        se[rows_of], _ = _native.life_depth_se(
            column("tube_depth"), column("tube_depth_fixed_gap"), column("wear_work_rate"),
            column("wear_work_rate_se"))
    out.insert(out.columns.get_loc("tube_depth") + 1, "tube_depth_se", se)
    return out


class LifeResult:
    """What `fretdyn.life` returns: the service life of a case (``fretdyn life``).

    Attributes
    ----------
    depths : pandas.DataFrame
        One row per life step and wearing contact: ``step`` (0: the start), ``time_years``,
        ``contact``, ``wear_work_rate`` and ``wear_work_rate_se`` (W, of the window that
        drove the step), ``tube_volume``, ``support_volume`` (m³), ``tube_depth`` (m) and
        ``tube_depth_se`` (its first-order standard error from the windows' wear work rate
        errors, m), ``support_depth``, ``clearance_increase``, ``tube_depth_fixed_gap`` (m).
    table : pandas.DataFrame
        The same numbers in the columns of ``life.csv`` (``time_years``,
        ``<contact>.<column>``), equal to the CLI's bit for bit.
    summary : pandas.DataFrame
        Indexed by contact: ``clearance`` (m at rest), the final ``tube_depth``,
        ``tube_depth_se``, ``tube_depth_fixed_gap``, ``support_depth`` (m),
        ``criterion_depth`` (the plugging limit, m; NaN without one), ``years_to_criterion``
        and ``years_to_criterion_fixed_gap`` (NaN: not reached).
    scars : pandas.DataFrame
        The final scar profiles, the rows of ``scars.csv``: ``contact``, ``kind`` (plane,
        bars, hole), ``bin``, ``angle_deg`` (a hole's bins; NaN otherwise),
        ``clearance_increase``, ``tube_depth``, ``support_depth`` (m; bodies A and B of a
        two-body contact).
    convergence : pandas.DataFrame or None
        With ``halvings``: the rows of ``convergence.csv`` (``max_depth_change``,
        ``life_steps``, ``life_end``, ``end_years``, ``<contact>.tube_depth``), the life
        itself first.
    end : dict
        How it ended: ``{"status": "completed"}`` or ``"perforated"`` (with ``contact`` and
        ``time``, s).
    criterion_depth : float or None
        The plugging depth of ``[life]``, m.
    contact_names : list of str
        The wearing contacts.
    windows : int
        Windows of vibration simulated.
    wall_time : float
        Wall-clock time of the life, s.

    Examples
    --------
    >>> r = fretdyn.life("examples/tube_multispan_life.toml", halvings=1)
    >>> r.summary.loc["plate3", ["tube_depth", "tube_depth_se", "years_to_criterion"]]
    >>> r.depths.pivot(index="time_years", columns="contact", values="tube_depth")
    >>> r.convergence
    """

    def __init__(self, life_json: dict, refined: list, case: Any, max_depth_change: float,
                 files: Optional[List[tuple]] = None):
        self._json = life_json
        # the text of life.csv, scars.csv (convergence.csv), from the library: the CLI's bytes
        self._files = list(files or [])
        self._results = life_json["results"]
        self.criterion_depth: Optional[float] = life_json.get("criterion_depth")
        self.case = case
        self.contact_names: List[str] = list(self._results["contacts"])
        self.end: dict = self._results["end"]
        self.windows: int = self._results["windows"]
        self.wall_time: float = self._results["wall_time"]
        self.depths = _depths(self._results)
        self.convergence = None
        if refined:
            self.convergence = self._convergence([(max_depth_change, self._results), *refined])

    def __repr__(self) -> str:
        last = self._results["steps"][-1]["time"] / YEAR
        return (
            f"LifeResult({self.case.title!r}, {len(self.contact_names)} contacts, "
            f"{len(self._results['steps']) - 1} life steps to {last:.4g} years, "
            f"{self.end['status']})"
        )

    @property
    def table(self):
        """The columns of ``life.csv``: ``time_years``, then for each contact
        ``<contact>.wear_work_rate`` … ``<contact>.tube_depth_fixed_gap`` (SI units)."""
        pd = _pandas()
        steps = self._results["steps"]
        columns = {"time_years": [s["time"] / YEAR for s in steps]}
        for k, name in enumerate(self.contact_names):
            for col in LIFE_COLUMNS:
                columns[f"{name}.{col}"] = [
                    np.nan if s["contacts"][k][col] is None else s["contacts"][k][col]
                    for s in steps
                ]
        return pd.DataFrame(columns)

    @property
    def summary(self):
        """The life by contact (see the class)."""
        pd = _pandas()
        last = self.depths[self.depths["step"] == self.depths["step"].max()].set_index("contact")
        r = self._results

        def years(times):
            return [np.nan if t is None else t / YEAR for t in times]

        out = pd.DataFrame(
            {
                "clearance": r["clearances"],
                "tube_depth": last["tube_depth"].to_numpy(),
                "tube_depth_se": last["tube_depth_se"].to_numpy(),
                "tube_depth_fixed_gap": last["tube_depth_fixed_gap"].to_numpy(),
                "support_depth": last["support_depth"].to_numpy(),
                "criterion_depth": np.nan if self.criterion_depth is None
                else self.criterion_depth,
                "years_to_criterion": years(r["time_to_criterion"]),
                "years_to_criterion_fixed_gap": years(r["time_to_criterion_fixed_gap"]),
            },
            index=pd.Index(self.contact_names, name="contact"),
        )
        return out

    @property
    def scars(self):
        """The final scar profiles (see the class)."""
        pd = _pandas()
        rows = []
        for s in self._results["scars"]:
            n = len(s["clearance_increase"])
            depths = zip(s["clearance_increase"], s["tube_depth"], s["support_depth"])
            for b, (a, t, sd) in enumerate(depths):
                angle = (b + 0.5) * 360.0 / n if s["kind"] == "hole" else np.nan
                rows.append((s["contact"], s["kind"], b, angle, a, t, sd))
        return pd.DataFrame(rows, columns=["contact", "kind", "bin", "angle_deg",
                                           "clearance_increase", "tube_depth", "support_depth"])

    def _convergence(self, lives: list):
        pd = _pandas()
        rows = []
        for fraction, r in lives:
            steps = r["steps"]
            row = {
                "max_depth_change": fraction,
                "life_steps": len(steps) - 1,
                "life_end": r["end"]["status"],
                "end_years": steps[-1]["time"] / YEAR if steps else 0.0,
            }
            for k, name in enumerate(self.contact_names):
                row[f"{name}.tube_depth"] = steps[-1]["contacts"][k]["tube_depth"]
            rows.append(row)
        return pd.DataFrame(rows)

    def to_json(self) -> dict:
        """The content of ``life.json``, as the CLI writes it.

        Returns
        -------
        dict
            ``title`` (the case's), ``criterion_depth`` (m or None) and ``results`` (contacts,
            clearances, steps, times to the criterion in s, scars, end, windows, wall_time).

        Examples
        --------
        >>> r.to_json()["results"]["end"]
        {'status': 'completed'}
        """
        return json.loads(json.dumps(self._json))

    def write(self, folder: PathLike) -> None:
        """Writes ``life.csv``, ``scars.csv`` (and ``convergence.csv`` with halvings) into
        `folder`, byte for byte as ``fretdyn life`` writes them (numbers written to read back
        exactly, an empty cell for a missing value); `fretdyn.life` writes them into its
        `output` already.

        Parameters
        ----------
        folder : str or os.PathLike
            The folder (made if needed).

        Returns
        -------
        None

        Examples
        --------
        >>> r.write("my_life")
        """
        folder = Path(folder)
        folder.mkdir(parents=True, exist_ok=True)
        for name, text in self._files:
            (folder / name).write_bytes(text.encode())

    def to_xarray(self):
        """The life as an xarray Dataset: dimensions ``time`` (service time, years) and
        ``contact`` (names); every column of `depths` a variable with ``units`` and
        ``long_name``; ``years_to_criterion`` per contact; the attributes ``title``,
        ``criterion_depth`` (m) and ``life_end``.

        Returns
        -------
        xarray.Dataset

        Examples
        --------
        >>> ds = r.to_xarray()
        >>> ds.tube_depth.sel(contact="plate3").plot()
        """
        try:
            import xarray as xr
        except ImportError as e:
            raise ImportError("LifeResult.to_xarray needs xarray: pip install xarray") from e
        d = self.depths
        n = len(self.contact_names)
        time = d["time_years"].to_numpy()[::n]
        data = {}
        units = {**LIFE_COLUMNS, "tube_depth_se": "m"}
        for col in [*LIFE_COLUMNS, "tube_depth_se"]:
            values = d[col].to_numpy().reshape(len(time), n)
            data[col] = (("time", "contact"), values,
                         {"units": units[col], "long_name": _LONG_NAMES[col]})
        s = self.summary
        data["years_to_criterion"] = (("contact",), s["years_to_criterion"].to_numpy(),
                                      {"units": "year", "long_name": "service time to the "
                                       "plugging depth (NaN: not reached)"})
        return xr.Dataset(
            data,
            coords={
                "time": ("time", time, {"units": "year", "long_name": "service time"}),
                "contact": ("contact", np.array(self.contact_names, dtype=str)),
            },
            attrs={
                "title": self.case.title,
                "criterion_depth": np.nan if self.criterion_depth is None
                else self.criterion_depth,
                "life_end": self.end["status"],
            },
        )


def life(
    case: Any,
    years: Optional[float] = None,
    max_depth_change: Optional[float] = None,
    halvings: int = 0,
    output: Optional[PathLike] = None,
    resume: bool = False,
    checkpoint_every: float = 60.0,
) -> LifeResult:
    """The service life of a case, like ``fretdyn life``: windows of vibration, scar growth,
    the scars fed back into the obstacles, to the target time (THEORY §14.5, docs/WEAR.md).

    Computed by the library in this process with the GIL released; Ctrl-C stops it after a
    checkpoint (KeyboardInterrupt): with `output`, ``resume=True`` continues it, and the
    results are those of an uninterrupted life.

    Parameters
    ----------
    case : Case, str or os.PathLike
        A case with a ``[life]`` section and contacts with ``wear``, or its file.
    years : float, optional
        The service time to reach, years (``life.target_years`` of the case by default).
    max_depth_change : float, optional
        The largest growth of a contact's depth in one life step, as a fraction of its
        clearance plus depth (``life.max_depth_change`` by default); halve it to check
        convergence.
    halvings : int, default 0
        Also run the life with `max_depth_change` halved 1…`halvings` times (at most 10;
        each about doubles the life steps): `LifeResult.convergence` (``--halvings``).
    output : str or os.PathLike, optional
        A folder for the life's files: ``life.json``, ``life.csv``, ``scars.csv``
        (``convergence.csv``) and, while the life runs, its checkpoint (``-o``). A new life
        there removes the files of an earlier one.
    resume : bool, default False
        Continue the life stopped (Ctrl-C, killed) in `output` from its checkpoint
        (``--resume``); refused when the case changed since. A life ``fretdyn life``
        started is continued too, and ``fretdyn life --resume DIR`` continues one started
        here from a case file without `years` or `max_depth_change`.
    checkpoint_every : float, default 60
        Wall-clock seconds (> 0) between checkpoints inside a window (with `output`;
        ``--checkpoint-every``); one is written after every life step too.

    Returns
    -------
    LifeResult
        Its ``depths`` (a DataFrame: depth per contact and life step with its standard
        error), ``summary`` (by contact: the final depths, the plugging criterion, the years
        to reach it), ``scars``, ``convergence``, ``table`` (``life.csv``), ``to_xarray()``;
        plots: `fretdyn.plot.life`. Its tables are pandas DataFrames: pandas is needed
        (``pip install fretdyn[pandas]``; an ImportError says so).

    Raises
    ------
    FretdynError
        The case has no ``[life]``, no contact wears, a value is out of range (named:
        ``life.max_depth_change: must be a fraction in (0, 1] …``); or the life was cut
        short (the step limit, a scar at the limit of its geometry, a diverged window), with
        the CLI's message; the results so far are the error's ``result`` (and written to
        `output`).

    Examples
    --------
    >>> r = fretdyn.life("examples/tube_multispan_life.toml", years=5)
    >>> r.summary[["tube_depth", "years_to_criterion"]]
    >>> fretdyn.plot.life(r)
    """
    from . import _case

    case_file = os.fspath(case) if isinstance(case, (str, os.PathLike)) else None
    case = _case(case, "life")
    changes = {}
    if years is not None:
        changes["life.target_years"] = years
    if max_depth_change is not None:
        changes["life.max_depth_change"] = max_depth_change
    if changes and "life" in case.to_dict():
        case = case.with_(changes)
        case_file = None  # not the file's case any more
    if isinstance(halvings, bool) or not isinstance(halvings, (int, np.integer)) or halvings < 0:
        raise FretdynError(f"halvings: a number of halvings ≥ 0 (at most 10), got {halvings!r}")
    life_json, refined, files = _native.life(
        case._native, int(halvings), None if output is None else os.fspath(output),
        bool(resume), float(checkpoint_every), case_file,
    )
    data = json.loads(life_json)
    settings = case.to_dict().get("life", {})
    result = LifeResult(
        data, [(f, json.loads(r)) for f, r in refined], case,
        float(settings.get("max_depth_change", np.nan)), files,
    )
    if result.end["status"] not in ("completed", "perforated"):
        target = settings.get("target_years", np.nan) * YEAR
        e = FretdynError(_end_message(result.end, data["results"]["steps"], target,
                                      settings.get("max_steps"))
                         + ("; results so far written" if output is not None
                            else "; the results so far are this error's .result"))
        e.result = result
        raise e
    return result


class ModesResult:
    """What `fretdyn.modes` returns: the modal basis of a case (``fretdyn modes``).

    Attributes
    ----------
    frequencies : pandas.DataFrame
        Indexed by ``mode`` (from 1): ``frequency_hz``, ``damping_ratio`` and, where the
        basis knows its participation factors Γ = ΦᵀMr (a tube), the effective modal masses
        ``effective_mass_x``, ``_y``, ``_z`` (Γ², kg: the mass each mode moves in a base
        motion along that axis).
    points : pandas.DataFrame
        The mass-normalised mode shapes at the case's points: one row per point and mode
        (``point``, ``mode``, ``x``, ``y``, ``z``, kg^-0.5), with the point's position
        (``coords_x`` … m) and abscissa along the tube ``s`` (m; NaN where unknown).
    shapes : pandas.DataFrame or None
        For a tube: every node in every mode (``mode``, ``node``, ``s`` the abscissa along
        the tube, m, ``u_x``, ``u_y``, ``u_z``, kg^-0.5; 0 at a restrained translation);
        None for other structures.
    supports : numpy.ndarray or None
        For a tube: the abscissae of the nodes with a restrained translation, m.
    orthonormality_error : float or None
        For a tube: max |ΦᵀMΦ − I| of the finite-element modes.

    Examples
    --------
    >>> m = fretdyn.modes("examples/tube_clamped_one_support.toml")
    >>> m.frequencies.head()
    >>> m.shapes[m.shapes["mode"] == 1].plot(x="s", y="u_z")
    """

    def __init__(self, native: dict, case: Any):
        pd = _pandas()
        self.case = case
        self._native = native
        hz = native["frequencies_hz"]
        modes = np.arange(1, len(hz) + 1)
        columns = {"frequency_hz": hz, "damping_ratio": native["damping_ratio"]}
        gamma = native["participation"]
        if gamma is not None:
            for d, axis in enumerate("xyz"):
                columns[f"effective_mass_{axis}"] = gamma[d] ** 2
        self.frequencies = pd.DataFrame(columns, index=pd.Index(modes, name="mode"))
        rows = []
        for k, name in enumerate(native["points"]):
            for i in range(len(hz)):
                r = native["rows"][k, :, i]
                c = native["coords"][k]
                rows.append((name, i + 1, r[0], r[1], r[2], c[0], c[1], c[2],
                             native["abscissae"][k]))
        self.points = pd.DataFrame(rows, columns=["point", "mode", "x", "y", "z", "coords_x",
                                                  "coords_y", "coords_z", "s"])
        tube = native["tube"]
        self.shapes = None
        self.supports = None
        self.orthonormality_error = None
        if tube is not None:
            m, nodes, _ = tube["shapes"].shape
            u = tube["shapes"].reshape(m * nodes, 3)
            self.shapes = pd.DataFrame({
                "mode": np.repeat(np.arange(1, m + 1), nodes),
                "node": np.tile(np.arange(nodes), m),
                "s": np.tile(tube["s"], m),
                "u_x": u[:, 0], "u_y": u[:, 1], "u_z": u[:, 2],
            })
            self.supports = tube["supports"]
            self.orthonormality_error = tube["orthonormality_error"]

    def __repr__(self) -> str:
        return f"ModesResult({self.case.title!r}, {len(self.frequencies)} modes)"

    def to_xarray(self):
        """The basis as an xarray Dataset: ``frequency`` (Hz), ``damping_ratio`` and the
        effective masses along ``mode``; ``rows`` (point, direction, mode); for a tube,
        ``shapes`` (mode, node, direction) with the coordinate ``s`` (m) along ``node``.

        Returns
        -------
        xarray.Dataset

        Examples
        --------
        >>> ds = m.to_xarray()
        >>> ds.frequency.sel(mode=1).item()
        """
        try:
            import xarray as xr
        except ImportError as e:
            raise ImportError("ModesResult.to_xarray needs xarray: pip install xarray") from e
        f = self.frequencies
        data = {
            "frequency": ("mode", f["frequency_hz"].to_numpy(),
                          {"units": "Hz", "long_name": "natural frequency"}),
            "damping_ratio": ("mode", f["damping_ratio"].to_numpy(),
                              {"units": "1", "long_name": "modal damping ratio"}),
            "rows": (("point", "direction", "mode"), self._native["rows"],
                     {"units": "kg-0.5", "long_name": "mass-normalised mode shape at the point"}),
        }
        for axis in "xyz":
            if f"effective_mass_{axis}" in f:
                data[f"effective_mass_{axis}"] = (
                    "mode", f[f"effective_mass_{axis}"].to_numpy(),
                    {"units": "kg", "long_name": f"effective modal mass along {axis}"})
        coords = {
            "mode": ("mode", f.index.to_numpy()),
            "point": ("point", np.array(self._native["points"], dtype=str)),
            "direction": ("direction", np.array(["x", "y", "z"])),
        }
        tube = self._native["tube"]
        if tube is not None:
            data["shapes"] = (("mode", "node", "direction"), tube["shapes"],
                              {"units": "kg-0.5", "long_name": "mass-normalised mode shape"})
            coords["s"] = ("node", tube["s"], {"units": "m",
                                               "long_name": "abscissa along the tube"})
        return xr.Dataset(data, coords=coords, attrs={"title": self.case.title})


def modes(case: Any, output: Optional[PathLike] = None) -> ModesResult:
    """The modal basis of a case, like ``fretdyn modes``: natural frequencies, damping,
    effective modal masses and mode shapes.

    Parameters
    ----------
    case : Case, str or os.PathLike
        A case, or its file.
    output : str or os.PathLike, optional
        A folder to write the basis into as ``basis.npz`` (``-o``; keys
        ``frequencies_hz``, ``damping_ratio``, ``rows_<point>``, ``coords_<point>``,
        ``s_<point>``), readable by a case's ``structure.file``.

    Returns
    -------
    ModesResult
        ``frequencies`` (a DataFrame by mode), ``points``, ``shapes`` (a tube's),
        ``to_xarray()``; plots: `fretdyn.plot.modes`. pandas is needed.

    Examples
    --------
    >>> m = fretdyn.modes("examples/tube_clamped_one_support.toml")
    >>> m.frequencies["frequency_hz"].head()
    >>> fretdyn.plot.modes(m, shown=4)
    """
    from . import _case

    case = _case(case, "modes")
    native = _native.modes(case._native, None if output is None else os.fspath(output))
    return ModesResult(native, case)

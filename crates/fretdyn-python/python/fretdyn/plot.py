"""Plots of a run for notebooks, with matplotlib (an optional dependency: ``pip install
matplotlib``, or ``fretdyn[matplotlib]``).

Each function draws on the Axes it is given (``ax=``) or on a new figure, labels the axes
with the quantity and its units (from `fretdyn.variables`), and returns the Axes
(``ax.figure`` is its Figure; ``ax.figure.savefig("orbits.png")`` writes it).

    import fretdyn
    r = fretdyn.run("examples/tube_multispan.toml")
    fretdyn.plot.orbits(r)                     # the tube centre in each hole
    fretdyn.plot.forces(r, contact="plate2")   # normal and tangential force against time
    fretdyn.plot.wear(r)                       # wear work rate per contact, ± its error
    fretdyn.plot.energy(r)                     # the structure's energy against time
"""

from __future__ import annotations

from typing import Any, List, Optional, Sequence, Union

import numpy as np

__all__ = ["orbits", "forces", "wear", "energy"]

Contacts = Union[None, int, str, Sequence[Union[int, str]]]


def _pyplot():
    try:
        import matplotlib.pyplot as plt
    except ImportError as e:
        raise ImportError(
            "fretdyn.plot draws with matplotlib, which is not installed: pip install matplotlib"
        ) from e
    return plt


def _axes(ax: Any):
    if ax is not None:
        return ax
    _, ax = _pyplot().subplots(figsize=(7, 4.5), layout="constrained")
    return ax


def _units(name: str) -> str:
    """The units of a time history or coordinate (by its key or name) in `fretdyn.variables`."""
    from . import _units as table

    return table()[name]["units"]


def _labels(result: Any, dim: str) -> List[str]:
    """The labels along a dimension of the results (``local_axis``: e1, e2; ``tangent``: t1,
    t2), as ``to_xarray()`` and ``results.nc`` have them."""
    from . import _native

    values, _ = _native.coordinates(result.case._native)
    return list(values[dim])


def _select(result: Any, contact: Contacts, default: Optional[List[int]] = None) -> List[int]:
    """The indices of `contact` (an index, a name, or a list of them; None: `default`, or
    every contact)."""
    names = result.contact_names
    if contact is None:
        return list(range(len(names))) if default is None else default
    chosen = [contact] if isinstance(contact, (int, str, np.integer)) else list(contact)
    out = []
    for c in chosen:
        if isinstance(c, str):
            if c not in names:
                raise ValueError(f"no contact {c!r}: the contacts are {names}")
            out.append(names.index(c))
        elif 0 <= int(c) < len(names):
            out.append(int(c))
        else:
            raise ValueError(f"no contact {c}: there are {len(names)} contacts ({names})")
    return out


def orbits(result: Any, contact: Contacts = None, ax: Any = None):
    """The orbit of each contact's point relative to its obstacle.

    In a hole, the offset of the tube centre from the hole's centre in the hole's axes (e1,
    e2), with the hole's outline (its clearance) dashed in the same colour; for a plane or
    bars, the distance from the plane against the position along t1
    (``Result.contact_position``).

    Parameters
    ----------
    result : Result
        What `fretdyn.run` returned.
    contact : int, str or sequence of them, optional
        The contacts (indices or names); default: every contact in a hole, or every contact
        when none is in a hole.
    ax : matplotlib.axes.Axes, optional
        Where to draw; default: a new figure.

    Returns
    -------
    matplotlib.axes.Axes
        Its lines are, for each contact in turn, the orbit (x: ``contact_position`` along
        e1, y: along e2, the ``local_axis`` of ``to_xarray()``), then the outline of a
        hole.

    Examples
    --------
    >>> ax = fretdyn.plot.orbits(r, contact="plate2")
    >>> ax.figure.savefig("orbit.png")
    """
    geometry = result.summary["contact_geometry"]
    holes = [k for k, g in enumerate(geometry) if g.get("outline")]
    chosen = _select(result, contact, holes or None)
    ax = _axes(ax)
    position = result.contact_position
    for k in chosen:
        (line,) = ax.plot(position[:, k, 0], position[:, k, 1], lw=0.8,
                          label=result.contact_names[k])
        outline = geometry[k].get("outline")
        if outline:
            o = np.asarray(outline, dtype=float)
            ax.plot(o[:, 0], o[:, 1], "--", lw=1.0, color=line.get_color(),
                    label=f"{result.contact_names[k]}: hole")
    units = _units("contact_position")
    e1, e2 = _labels(result, "local_axis")
    in_holes = all(geometry[k].get("outline") for k in chosen)
    on_planes = not any(geometry[k].get("outline") for k in chosen)
    if in_holes:
        ax.set_xlabel(f"{e1}, offset from the hole's centre ({units})")
        ax.set_ylabel(f"{e2}, offset from the hole's centre ({units})")
        ax.set_aspect("equal", adjustable="datalim")
    elif on_planes:
        ax.set_xlabel(f"{e1}, distance from the plane ({units})")
        ax.set_ylabel(f"{e2}, position along t1 ({units})")
    else:
        ax.set_xlabel(f"contact_position, {e1} ({units})")
        ax.set_ylabel(f"contact_position, {e2} ({units})")
    ax.set_title(f"{result.case.title}: orbits")
    ax.legend(fontsize="small")
    return ax


def forces(result: Any, contact: Contacts = None, ax: Any = None):
    """The normal and the tangential force of each contact against time.

    Parameters
    ----------
    result : Result
        What `fretdyn.run` returned.
    contact : int, str or sequence of them, optional
        The contacts (indices or names); default: every contact.
    ax : matplotlib.axes.Axes, optional
        Where to draw; default: a new figure.

    Returns
    -------
    matplotlib.axes.Axes
        Its lines are, for each contact in turn, the normal force R_N (solid) and the
        magnitude of the tangential force |R_T| (dashed, same colour) against ``result.t``.

    Examples
    --------
    >>> ax = fretdyn.plot.forces(r, contact=["plate1", "plate2"])
    """
    chosen = _select(result, contact)
    ax = _axes(ax)
    t = result.t
    for k in chosen:
        name = result.contact_names[k]
        (line,) = ax.plot(t, result.contact_normal_force[:, k], lw=0.8, label=f"{name}: R_N")
        tangential = np.hypot(result.contact_tangential_force[:, k, 0],
                              result.contact_tangential_force[:, k, 1])
        ax.plot(t, tangential, "--", lw=0.8, color=line.get_color(), label=f"{name}: |R_T|")
    ax.set_xlabel(f"time ({_units('t')})")
    ax.set_ylabel(f"contact force ({_units('contact_normal_force')})")
    ax.set_title(f"{result.case.title}: contact forces")
    ax.legend(fontsize="small")
    return ax


_WEAR = {
    "wear_work_rate": "wear work rate, friction power",
    "normal_wear_work_rate": "normal wear work rate, mean of R_N |v_T|",
}


def wear(result: Any, statistic: str = "wear_work_rate", ax: Any = None):
    """The wear work rate of each contact, a bar per contact with its standard error.

    Parameters
    ----------
    result : Result
        What `fretdyn.run` returned.
    statistic : {"wear_work_rate", "normal_wear_work_rate"}, default "wear_work_rate"
        The friction power ``(1/T)∫|R_T·v_T|dt`` (THEORY §5), or Code_Aster's
        ``(1/T)∫R_N|v_T|dt``.
    ax : matplotlib.axes.Axes, optional
        Where to draw; default: a new figure.

    Returns
    -------
    matplotlib.axes.Axes
        One bar per contact (in the order of the contacts, x ticks labelled by their names),
        its height ``summary["contacts"][k][statistic]``, W, with an error bar of
        ``<statistic>_se`` where the summary has one.

    Examples
    --------
    >>> ax = fretdyn.plot.wear(r)
    >>> [b.get_height() for b in ax.patches]
    """
    if statistic not in _WEAR:
        raise ValueError(f"statistic must be one of {list(_WEAR)}, not {statistic!r}")
    ax = _axes(ax)
    contacts = result.summary["contacts"]
    names = [c["name"] for c in contacts]
    heights = np.array([c[statistic] for c in contacts], dtype=float)
    errors = np.array([np.nan if c.get(f"{statistic}_se") is None else c[f"{statistic}_se"]
                       for c in contacts], dtype=float)
    x = np.arange(len(names))
    ax.bar(x, heights, yerr=None if np.all(np.isnan(errors)) else np.nan_to_num(errors),
           capsize=4, color="tab:orange")
    ax.set_xticks(x)
    ax.set_xticklabels(names)
    ax.set_xlabel("contact")
    ax.set_ylabel(f"{_WEAR[statistic]} (W)")
    ax.set_title(f"{result.case.title}: wear work rate")
    return ax


def energy(result: Any, ax: Any = None):
    """The energy of the structure against time: modal kinetic, strain and their sum.

    With mass-normalised modes (THEORY §1), the kinetic energy is ``½ Σ q̇ᵢ²`` and the strain
    energy ``½ Σ ωᵢ² qᵢ²`` (ωᵢ = 2π ``case.frequencies_hz``); the energy stored in the
    contact springs is not included. The title gives the relative error of the run's energy
    balance (``summary["energy_balance"]["relative_error"]``).

    Parameters
    ----------
    result : Result
        What `fretdyn.run` returned.
    ax : matplotlib.axes.Axes, optional
        Where to draw; default: a new figure.

    Returns
    -------
    matplotlib.axes.Axes
        Its lines are the kinetic, the strain and the total energy, J, against
        ``result.t``.

    Examples
    --------
    >>> ax = fretdyn.plot.energy(r)
    """
    ax = _axes(ax)
    omega = 2.0 * np.pi * np.asarray(result.case.frequencies_hz, dtype=float)
    kinetic = 0.5 * np.sum(result.qdot ** 2, axis=1)
    strain = 0.5 * np.sum((omega * result.q) ** 2, axis=1)
    t = result.t
    ax.plot(t, kinetic, lw=0.8, label="kinetic")
    ax.plot(t, strain, lw=0.8, label="strain")
    ax.plot(t, kinetic + strain, lw=1.2, color="black", label="total")
    ax.set_xlabel(f"time ({_units('t')})")
    ax.set_ylabel("energy of the structure (J)")
    error = result.summary.get("energy_balance", {}).get("relative_error")
    suffix = "" if error is None else f" (balance error {error:.1e})"
    ax.set_title(f"{result.case.title}: energy{suffix}")
    ax.legend(fontsize="small")
    return ax

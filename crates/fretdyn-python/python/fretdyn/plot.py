"""Plots of a run for notebooks, with matplotlib (an optional dependency: ``pip install
matplotlib``, or ``fretdyn[matplotlib]``).

Each function draws on the Axes it is given (``ax=``) or on a new figure, labels the axes
with the quantity and its units (from `fretdyn.variables`), and returns the Axes
(``ax.figure`` is its Figure; ``ax.figure.savefig("orbits.png")`` writes it).

    import fretdyn
    r = fretdyn.run("examples/tube_multispan.toml")
    fretdyn.plot.orbits(r)                     # the tube centre in the most worn hole
    fretdyn.plot.orbits(r, contact=["plate1", "plate2"])   # a panel each
    fretdyn.plot.forces(r, contact="plate2")   # normal and tangential force against time
    fretdyn.plot.wear(r)                       # wear work rate per contact, ± its error
    fretdyn.plot.energy(r)                     # the structure's energy against time
    fretdyn.plot.life(fretdyn.life(case))      # depth against service time, ± its error
    fretdyn.plot.modes(fretdyn.modes(case))    # a tube's mode shapes

Lengths are drawn in µm and powers in mW, as the CLI's figures; what is not data (a hole's
wall, a support, the plugging criterion) is dark grey. Without ``contact=``, a run's plot
shows the contact with the largest wear work rate and says so in its title.
"""

from __future__ import annotations

from typing import Any, List, Optional, Sequence, Union

import numpy as np

__all__ = ["orbits", "forces", "wear", "energy", "life", "modes"]

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


def _panels(n: int, width: float = 4.2, height: float = 3.6):
    """A new figure of `n` panels (at most 3 a row) with constrained layout: an array of
    Axes, the unused cells removed."""
    cols = min(n, 3)
    rows = -(-n // cols)
    fig, axes = _pyplot().subplots(rows, cols, figsize=(width * cols, height * rows + 0.6),
                                   layout="constrained", squeeze=False)
    for extra in axes.flat[n:]:
        extra.remove()
    return axes.flat[:n]


# the colour of what is not data (an obstacle's wall, a support, a limit): dark grey, which
# no data line of matplotlib's default cycle uses
_FRAME = "0.25"

# µm per m and mW per W: the units of the figures of the CLI
_UM = 1e6
_MW = 1e3


def _title(ax: Any, text: str) -> None:
    """A title wrapped to the width of its Axes (about 6 points a character), so that it is
    not clipped at the figure's edges nor runs into its neighbours'."""
    import textwrap

    width_in = ax.get_position().width * ax.figure.get_figwidth()
    chars = max(20, int(width_in * 72 / 6))
    ax.set_title(textwrap.fill(text, chars), fontsize="medium")


def _legend_outside(ax: Any) -> None:
    """The legend to the right of the Axes, off the data."""
    ax.legend(fontsize="small", loc="upper left", bbox_to_anchor=(1.02, 1.0),
              borderaxespad=0.0)


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


def _worst(result: Any, among: Optional[List[int]] = None) -> int:
    """The contact (among `among`, default every one) with the largest wear work rate."""
    rates = [c.get("wear_work_rate") or 0.0 for c in result.summary["contacts"]]
    among = list(range(len(rates))) if among is None else among
    return max(among, key=lambda k: rates[k])


def _chosen(result: Any, contact: Contacts, ax: Any, default: Optional[List[int]] = None):
    """The contacts to draw and where: `contact` None draws the worst of `default` (largest
    wear work rate) with a note for the title; several contacts without `ax` get a panel
    each. Returns (contacts, list of Axes, note)."""
    if contact is None:
        k = _worst(result, default)
        note = "" if len(result.contact_names) == 1 else (
            " (the largest wear work rate; contact= for the others)")
        return [k], [_axes(ax)], note
    chosen = _select(result, contact)
    if ax is not None or len(chosen) == 1:
        return chosen, [_axes(ax)], ""
    return chosen, list(_panels(len(chosen))), ""


def _finish(ax: Any, result: Any, what: str, note: str, shared: bool) -> None:
    """The title of a run's plot (``<case title>: <what><note>``, wrapped) and its legend:
    outside the data when several contacts share the Axes."""
    _title(ax, f"{result.case.title}: {what}{note}")
    if shared:
        _legend_outside(ax)
    else:
        ax.legend(fontsize="small", loc="best")


def _returned(axes: List[Any]):
    """One Axes, or the array of the panels."""
    return axes[0] if len(axes) == 1 else np.array(axes, dtype=object)


def orbits(result: Any, contact: Contacts = None, ax: Any = None):
    """The orbit of a contact's point relative to its obstacle, µm.

    In a hole, the offset of the tube centre from the hole's centre in the hole's axes (e1,
    e2), with the hole's wall (the radial clearance) dashed in dark grey; for a plane or
    bars, the distance from the plane against the position along t1
    (``Result.contact_position``).

    Parameters
    ----------
    result : Result
        What `fretdyn.run` returned.
    contact : int, str or sequence of them, optional
        The contacts (indices or names). Default: the contact in a hole (any contact when
        none is in a hole) with the largest wear work rate, named in the title. Several
        contacts: a panel each on a new figure, or overlaid on `ax` (legend outside).
    ax : matplotlib.axes.Axes, optional
        Where to draw; default: a new figure.

    Returns
    -------
    matplotlib.axes.Axes or numpy.ndarray of Axes
        The Axes (an array of them, one per contact, for several contacts without `ax`).
        Its lines are, for each contact in turn, the orbit (x: ``contact_position`` along
        e1, y: along e2, the ``local_axis`` of ``to_xarray()``, in µm), then the outline of
        a hole (label ``hole wall (clearance)``, or ``<contact>: hole wall`` when several
        share the Axes).

    Examples
    --------
    >>> ax = fretdyn.plot.orbits(r, contact="plate2")
    >>> ax.figure.savefig("orbit.png")
    """
    geometry = result.summary["contact_geometry"]
    holes = [k for k, g in enumerate(geometry) if g.get("outline")]
    chosen, axes, note = _chosen(result, contact, ax, holes or None)
    position = result.contact_position
    e1, e2 = _labels(result, "local_axis")
    shared = len(axes) == 1 and len(chosen) > 1
    for i, k in enumerate(chosen):
        a = axes[0] if shared else axes[i]
        name = result.contact_names[k]
        a.plot(position[:, k, 0] * _UM, position[:, k, 1] * _UM, lw=0.8, label=name)
        outline = geometry[k].get("outline")
        if outline:
            o = np.asarray(outline, dtype=float) * _UM
            a.plot(o[:, 0], o[:, 1], "--", lw=1.2, color=_FRAME,
                   label=f"{name}: hole wall" if shared else "hole wall (clearance)")
    for i, a in enumerate(axes):
        here = chosen if shared else [chosen[i]]
        in_holes = all(geometry[k].get("outline") for k in here)
        on_planes = not any(geometry[k].get("outline") for k in here)
        if in_holes:
            a.set_xlabel(f"{e1}, offset from the hole's centre (µm)")
            a.set_ylabel(f"{e2}, offset from the hole's centre (µm)")
            a.set_aspect("equal", adjustable="datalim")
        elif on_planes:
            a.set_xlabel(f"{e1}, distance from the plane (µm)")
            a.set_ylabel(f"{e2}, position along t1 (µm)")
        else:
            a.set_xlabel(f"contact_position, {e1} (µm)")
            a.set_ylabel(f"contact_position, {e2} (µm)")
        _finish(a, result, "orbits" if shared else f"orbit at {result.contact_names[here[0]]}",
                note, shared)
    return _returned(axes)


def forces(result: Any, contact: Contacts = None, ax: Any = None):
    """The normal and the tangential force of a contact against time.

    Parameters
    ----------
    result : Result
        What `fretdyn.run` returned.
    contact : int, str or sequence of them, optional
        The contacts (indices or names). Default: the contact with the largest wear work
        rate, named in the title. Several contacts: a panel each on a new figure, or
        overlaid on `ax` (legend outside).
    ax : matplotlib.axes.Axes, optional
        Where to draw; default: a new figure.

    Returns
    -------
    matplotlib.axes.Axes or numpy.ndarray of Axes
        The Axes (an array, one per contact, for several contacts without `ax`). Its lines
        are, for each contact in turn, the normal force R_N (solid) and the magnitude of the
        tangential force |R_T| (dashed, same colour) against ``result.t``, N.

    Examples
    --------
    >>> ax = fretdyn.plot.forces(r, contact="plate2")
    >>> axes = fretdyn.plot.forces(r, contact=["plate1", "plate2"])   # two panels
    """
    chosen, axes, note = _chosen(result, contact, ax)
    shared = len(axes) == 1 and len(chosen) > 1
    t = result.t
    for i, k in enumerate(chosen):
        a = axes[0] if shared else axes[i]
        name = result.contact_names[k]
        (line,) = a.plot(t, result.contact_normal_force[:, k], lw=0.8, label=f"{name}: R_N")
        tangential = np.hypot(result.contact_tangential_force[:, k, 0],
                              result.contact_tangential_force[:, k, 1])
        a.plot(t, tangential, "--", lw=0.8, color=line.get_color(), label=f"{name}: |R_T|")
    for i, a in enumerate(axes):
        a.set_xlabel(f"time ({_units('t')})")
        a.set_ylabel(f"contact force ({_units('contact_normal_force')})")
        what = "contact forces" if shared else f"contact forces at {result.contact_names[chosen[i]]}"
        _finish(a, result, what, note, shared)
    return _returned(axes)


# the statistics `wear` draws; their names and standard errors are the table's
# (fretdyn.statistics_columns)
_WEAR = ("wear_work_rate", "normal_wear_work_rate")


def wear(result: Any, statistic: str = "wear_work_rate", ax: Any = None):
    """The wear work rate of each contact, mW: a bar per contact with its standard error.

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
        its height ``summary["contacts"][k][statistic]`` in mW, with an error bar of
        ``<statistic>_se`` where the summary has one.

    Examples
    --------
    >>> ax = fretdyn.plot.wear(r)
    >>> [b.get_height() for b in ax.patches]   # mW
    """
    if statistic not in _WEAR:
        raise ValueError(f"statistic must be one of {list(_WEAR)}, not {statistic!r}")
    from . import _native

    column = next(c for c in _native.statistics_columns() if c["key"] == statistic)
    se = column["se_key"]
    ax = _axes(ax)
    contacts = result.summary["contacts"]
    names = [c["name"] for c in contacts]
    heights = np.array([c[statistic] for c in contacts], dtype=float) * _MW
    errors = np.array([np.nan if c.get(se) is None else c[se]
                       for c in contacts], dtype=float) * _MW
    x = np.arange(len(names))
    ax.bar(x, heights, yerr=None if np.all(np.isnan(errors)) else np.nan_to_num(errors),
           capsize=4, color="tab:orange", ecolor=_FRAME)
    ax.set_xticks(x)
    ax.set_xticklabels(names)
    ax.set_xlabel("contact")
    ax.set_ylabel(f"{column['long_name']} (m{column['unit']})")
    _title(ax, f"{result.case.title}: wear work rate ± standard error")
    return ax


def energy(result: Any, ax: Any = None):
    """The energy of the structure against time: modal kinetic, strain and their sum.

    With mass-normalised modes (THEORY §1), the kinetic energy is ``½ Σ q̇ᵢ²`` and the strain
    energy ``½ Σ ωᵢ² qᵢ²`` (ωᵢ = 2π ``case.frequencies_hz``); the energy stored in the
    contact springs is not included. The title gives the relative error of the run's energy
    balance (``summary["energy_balance"]["relative_error"]``), wrapped to fit.

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
    _title(ax, f"{result.case.title}: energy{suffix}")
    ax.legend(fontsize="small", loc="best")
    return ax


def life(result: Any, contact: Contacts = None, fixed_gap: bool = False, ax: Any = None):
    """The tube's wear depth of each contact against service time, µm, ± its standard error,
    with the plugging criterion.

    Parameters
    ----------
    result : LifeResult
        What `fretdyn.life` returned.
    contact : str or sequence of str, optional
        The contacts (names); default: every wearing contact.
    fixed_gap : bool, default False
        Also draw the fixed-gap extrapolation (the first window's rates for the whole life),
        dotted in each contact's colour.
    ax : matplotlib.axes.Axes, optional
        Where to draw; default: a new figure.

    Returns
    -------
    matplotlib.axes.Axes
        For each contact: its depth ``tube_depth`` (a line with markers at the life steps,
        labelled by the contact), the band ± ``tube_depth_se`` (a PolyCollection) and, with
        `fixed_gap`, ``tube_depth_fixed_gap`` dotted; the plugging criterion a dash-dotted
        dark-grey line ``plugging criterion (… µm)`` when the depths come within a third of
        it, else named in a note inside the Axes (off the scale). Legend outside the data.

    Examples
    --------
    >>> r = fretdyn.life("examples/tube_multispan_life.toml")
    >>> fretdyn.plot.life(r).figure.savefig("life.png")
    """
    ax = _axes(ax)
    names = result.contact_names
    if contact is None:
        chosen = names
    else:
        chosen = [contact] if isinstance(contact, str) else list(contact)
        for c in chosen:
            if c not in names:
                raise ValueError(f"no wearing contact {c!r}: the contacts are {names}")
    d = result.depths
    deepest = 0.0
    for name in chosen:
        rows = d[d["contact"] == name]
        years = rows["time_years"].to_numpy()
        depth = rows["tube_depth"].to_numpy() * _UM
        se = rows["tube_depth_se"].to_numpy() * _UM
        (line,) = ax.plot(years, depth, marker="o", ms=3, lw=1.0, label=name)
        ax.fill_between(years, depth - se, depth + se, color=line.get_color(), alpha=0.2,
                        lw=0, label=f"{name}: ± standard error")
        deepest = max(deepest, float(np.max(depth + se)))
        if fixed_gap:
            fixed = rows["tube_depth_fixed_gap"].to_numpy() * _UM
            ax.plot(years, fixed, ":", lw=1.0, color=line.get_color(),
                    label=f"{name}: fixed gap")
            deepest = max(deepest, float(np.max(fixed)))
    criterion = result.criterion_depth
    if criterion is not None:
        c = criterion * _UM
        label = f"plugging criterion ({c:.4g} µm)"
        if deepest >= c / 3.0:
            ax.axhline(c, ls="-.", lw=1.2, color=_FRAME, label=label)
        else:
            ax.text(0.02, 0.97, f"{label}: off the scale", transform=ax.transAxes,
                    va="top", ha="left", fontsize="small", color=_FRAME)
    ax.set_xlabel("service time (years)")
    ax.set_ylabel("tube wear depth (µm)")
    ax.set_ylim(bottom=0.0)
    _title(ax, f"{result.case.title}: tube wear depth ({result.end['status']})")
    _legend_outside(ax)
    return ax


def modes(result: Any, shown: int = 4):
    """The first mode shapes of a tube against the abscissa along it, a panel each, with the
    supports marked; for another structure, its frequencies against the mode number.

    Parameters
    ----------
    result : ModesResult
        What `fretdyn.modes` returned.
    shown : int, default 4
        Mode shapes drawn (``fretdyn modes --shown``).

    Returns
    -------
    numpy.ndarray of matplotlib.axes.Axes or matplotlib.axes.Axes
        For a tube, one Axes per mode: the lines ``u_x``, ``u_y``, ``u_z`` (mass-normalised
        displacement, kg^-0.5) against ``s`` (m), the supports as dark-grey triangles on the
        axis (label ``support``), titled ``mode k — f Hz``. Otherwise one Axes: the
        frequencies (Hz) against the mode number.

    Examples
    --------
    >>> m = fretdyn.modes("examples/tube_clamped_one_support.toml")
    >>> fretdyn.plot.modes(m, shown=3)[0].figure.savefig("mode_shapes.png")
    """
    f = result.frequencies
    if result.shapes is None:
        ax = _axes(None)
        ax.plot(f.index, f["frequency_hz"], "o", label="natural frequency")
        ax.set_xlabel("mode")
        ax.set_ylabel("frequency (Hz)")
        _title(ax, f"{result.case.title}: natural frequencies")
        return ax
    n = max(1, min(int(shown), len(f)))
    axes = list(_panels(n, width=4.6, height=3.0))
    s = result.shapes
    for i, a in enumerate(axes):
        rows = s[s["mode"] == i + 1]
        for col in ("u_x", "u_y", "u_z"):
            a.plot(rows["s"], rows[col], lw=1.0, label=col)
        a.plot(result.supports, np.zeros(len(result.supports)), "^", ms=8, color=_FRAME,
               linestyle="none", label="support", clip_on=False)
        a.axhline(0.0, lw=0.5, color=_FRAME)
        a.set_xlabel("abscissa along the tube (m)")
        a.set_ylabel("displacement (kg^-0.5)")
        _title(a, f"mode {i + 1} — {f['frequency_hz'].iloc[i]:.3f} Hz")
    axes[0].figure.suptitle(f"{result.case.title}: mode shapes (mass-normalised)",
                            fontsize="medium", wrap=True)
    axes[0].figure.legend(*axes[0].get_legend_handles_labels(), loc="outside lower center",
                          ncols=4, fontsize="small")
    return np.array(axes, dtype=object)

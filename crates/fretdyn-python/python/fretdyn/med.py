"""Modal bases from Code_Aster: a MED file written by `IMPR_RESU(FORMAT='MED')` read with
`medcoupling` (an optional dependency: `pip install medcoupling`) and converted to fretdyn's
modal basis (docs/MED.md).

    from fretdyn import med
    basis = med.read_modal_basis("modes.rmed", points={"A": "PA", "B": "PB"})
    basis.write_npz("basis.npz")      # [structure] type = "modal", file = "basis.npz"
    fretdyn.Case.from_dict({..., "structure": basis.structure()})   # or inline

What Code_Aster writes for `IMPR_RESU(FORMAT='MED', RESU=_F(RESULTAT=modes, NOM_CHAM='DEPL'))`
(code_aster's sources: `mdnoch.F90`, `irchme.F90`, `irmpar.F90`, `irmpav.F90` and, since
version 15, `code_aster/Commands/impr_resu.py`):

- the mesh of the result, its node groups (`GROUP_NO`) as MED node groups;
- one nodal field named after the result and the field: the result's name (the Python name
  of the concept since version 15, its first 8 characters) padded with `_` to 8 characters,
  then `DEPL`: `modes___DEPL`; components `DX DY DZ` (and `DRX DRY DRZ` for beams and
  shells), one value per node;
- one time step per stored mode: iteration = order = `NUME_ORDRE`, time = `FREQ` (Hz);
- with `NOM_PARA=('FREQ', 'MASS_GENE', …)` in the same `RESU`, MED scalar parameters named
  `<the result's 8-character internal name><NOM_PARA>` (e.g. `MODES   MASS_GENE`, or
  `00000004MASS_GENE` since version 15), one value per mode at the same time steps.

The shapes Code_Aster stores are normalised as `CALC_MODES`' `NORM_MODE` says (by default
`TRAN_ROTA`: the largest displacement or rotation is 1), not to the mass; fretdyn needs
mass-normalised shapes (`Φᵀ M Φ = I`, docs/THEORY.md §1): each mode is divided by the square
root of its generalised mass `MASS_GENE = φᵀ M φ`, taken from the file's parameters, or given
(`generalized_masses=`), or 1 when `mass_normalized=True` (`NORM_MODE=_F(NORME='MASS_GENE')`).
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field as dataclass_field
from pathlib import Path
from typing import Any, Dict, Iterable, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from ._native import FretdynError

__all__ = ["ModalBasis", "MedPoint", "read_modal_basis"]

PathLike = Union[str, os.PathLike]

TRANSLATIONS = ("DX", "DY", "DZ")
ROTATIONS = ("DRX", "DRY", "DRZ")
PARTICIPATION = ("FACT_PARTICI_DX", "FACT_PARTICI_DY", "FACT_PARTICI_DZ")
# |MASS_GENE − 1| beyond which a basis said to be mass-normalised is refused.
NORMALISED_TOLERANCE = 1e-6


@dataclass
class MedPoint:
    """A point of the basis: the node it was taken at and its mass-normalised rows."""

    name: str
    """The point's name in fretdyn (contacts, loads, `[initial]` use it)."""
    node: int
    """The node, numbered from 1 as in the MED file (Code_Aster's and Salome's numbering)."""
    group: Optional[str]
    """The node group (`GROUP_NO`) it was chosen by, or None when chosen by node number."""
    coords: np.ndarray
    """Position at rest, m, shape (3,)."""
    rows: np.ndarray
    """x, y, z translation rows, shape (3, p): `rows[d, i]` = component d of mode i."""
    rotations: Optional[np.ndarray]
    """θx, θy, θz rows, shape (3, p), rad per unit modal coordinate, or None."""


@dataclass
class ModalBasis:
    """A modal basis read from a MED file, in fretdyn's layout (mass-normalised)."""

    path: Path
    """The MED file."""
    field: str
    """The MED field the shapes were read from (e.g. `modes___DEPL`)."""
    mode_numbers: np.ndarray
    """Code_Aster's `NUME_ORDRE` of each mode kept (the MED iteration numbers), shape (p,)."""
    frequencies_hz: np.ndarray
    """Natural frequencies, Hz, shape (p,) (the time values of the MED steps)."""
    damping_ratio: np.ndarray
    """Modal damping ratios, shape (p,)."""
    generalized_masses: np.ndarray
    """`φᵀ M φ` of the shapes in the file (1 for a basis said to be mass-normalised); the
    rows were divided by their square root."""
    mass_source: str
    """Where the generalised masses came from: `"file (<the MASS_GENE parameter's name>)"`,
    `"given"` or `"mass_normalized"`."""
    points: Dict[str, MedPoint] = dataclass_field(default_factory=dict)
    """The points, by name, in the order they were asked for."""
    participation: Optional[np.ndarray] = None
    """`Φᵀ M r` for unit rigid translations along x, y, z, shape (3, p), kg^½, from the
    `FACT_PARTICI_D*` parameters (`φᵀ M r / φᵀ M φ`) times √`MASS_GENE`, or None."""

    @property
    def modes(self) -> int:
        """Number of modes p."""
        return len(self.frequencies_hz)

    def check(self) -> None:
        """Refuses, with a `FretdynError` naming the attribute, what the case file would
        refuse (a basis changed after it was read): frequencies not finite or < 0, damping
        ratios < 0 or not one per mode, rows not finite. `arrays`, `write_npz` and `structure`
        check first, so that no such basis is written."""
        freq = _numbers(self.frequencies_hz, "frequencies_hz", "one frequency per mode, Hz")
        _each(freq.reshape(-1), "frequencies_hz", lambda x: np.isfinite(x) and x >= 0.0,
              "must be a finite frequency ≥ 0 (0 is a rigid-body mode)")
        damping = _damping_ratios(self.damping_ratio)
        if damping.shape != freq.shape:
            raise FretdynError(
                f"damping_ratio: has {damping.size} values for {freq.size} modes: give one per mode"
            )
        for name, pt in self.points.items():
            for what, rows in (("rows", pt.rows), ("rotations", pt.rotations)):
                if rows is not None and not np.isfinite(np.asarray(rows, dtype=float)).all():
                    raise FretdynError(
                        f"points['{name}'].{what}: mode shape is not finite: fix or drop that mode"
                    )

    def arrays(self) -> Dict[str, np.ndarray]:
        """The arrays of fretdyn's `.npz` basis (keys of `crates/fretdyn/src/structure/
        basis_file.rs`): `frequencies_hz`, `damping_ratio`, `rows_<name>`, `coords_<name>`,
        `rotations_<name>` when read, `participation` when read; all float64. Checked first
        (`check`)."""
        self.check()
        out: Dict[str, np.ndarray] = {
            "frequencies_hz": _f64(self.frequencies_hz),
            "damping_ratio": _f64(self.damping_ratio),
        }
        for name, pt in self.points.items():
            out[f"rows_{name}"] = _f64(pt.rows)
            out[f"coords_{name}"] = _f64(pt.coords)
            if pt.rotations is not None:
                out[f"rotations_{name}"] = _f64(pt.rotations)
        if self.participation is not None:
            out["participation"] = _f64(self.participation)
        return out

    def write_npz(self, path: PathLike) -> Path:
        """Writes the basis as fretdyn's `.npz` (`[structure] type = "modal", file = …`).
        Returns the path written."""
        path = Path(path)
        if path.suffix != ".npz":
            raise FretdynError(f"{path}: a modal basis file must end in .npz (numpy adds it otherwise)")
        np.savez(path, **self.arrays())
        return path

    def structure(self) -> dict:
        """The `[structure]` section of a case with this basis inline, for
        `fretdyn.Case.from_dict` (`{"type": "modal", "frequencies_hz": …, "points": […]}`).
        Checked first (`check`)."""
        self.check()
        s: Dict[str, Any] = {
            "type": "modal",
            "frequencies_hz": self.frequencies_hz.tolist(),
            "damping_ratio": self.damping_ratio.tolist(),
            "points": [],
        }
        for name, pt in self.points.items():
            point: Dict[str, Any] = {
                "name": name,
                "coords": pt.coords.tolist(),
                "rows": pt.rows.tolist(),
            }
            if pt.rotations is not None:
                point["rotations"] = pt.rotations.tolist()
            s["points"].append(point)
        if self.participation is not None:
            s["participation"] = self.participation.tolist()
        return s

    def __repr__(self) -> str:
        return (
            f"<fretdyn.med.ModalBasis {self.modes} modes ({self.frequencies_hz.min():.6g}–"
            f"{self.frequencies_hz.max():.6g} Hz) from {self.path.name}:{self.field}, "
            f"points {list(self.points)}, masses from {self.mass_source}>"
        )


def _f64(a: Any) -> np.ndarray:
    return np.ascontiguousarray(np.asarray(a, dtype=np.float64))


def _shown(x: float) -> str:
    """A number as the case file's messages show it: NaN, inf, -inf, or Python's repr."""
    x = float(x)
    return "NaN" if x != x else ("inf" if x == np.inf else ("-inf" if x == -np.inf else repr(x)))


def _numbers(value: Any, name: str, expected: str) -> np.ndarray:
    """`value` — a number or a 1-D sequence of numbers (bool and str are not) — as float64;
    anything else is a FretdynError naming the argument `name` and saying `expected`."""
    raw = None
    if not isinstance(value, (str, bytes)):
        try:
            raw = np.asarray(value)
        except (TypeError, ValueError):
            raw = None
    if raw is None or raw.dtype.kind not in "iuf":
        raise FretdynError(f"{name}: must be {expected}, not {value!r}")
    if raw.ndim > 1:
        raise FretdynError(f"{name}: must be {expected}, not an array of shape {raw.shape}")
    return raw.astype(np.float64)


def _each(values: np.ndarray, name: str, good, message: str) -> None:
    """A FretdynError `name[i]: message (got x)` (`name: …` for one number) for the first
    value that is not `good`."""
    for i, x in enumerate(values.reshape(-1)):
        if not good(x):
            where = name if values.ndim == 0 else f"{name}[{i}]"
            raise FretdynError(f"{where}: {message} (got {_shown(x)})")


def _damping_ratios(value: Any) -> np.ndarray:
    """The `damping_ratio` argument: one number or one per mode, each a damping ratio ≥ 0 as
    the case file takes it (`structure.damping_ratio`, the same words)."""
    d = _numbers(value, "damping_ratio", "a damping ratio, or one per mode (e.g. 0.01 for 1 %)")
    _each(d, "damping_ratio", lambda x: np.isfinite(x) and x >= 0.0,
          "must be a damping ratio ≥ 0, e.g. 0.01 for 1 %")
    return d


def _generalised_masses(value: Any) -> np.ndarray:
    """The `generalized_masses` argument: one `φᵀ M φ` per mode kept, each finite and > 0."""
    m = _numbers(value, "generalized_masses", "one generalised mass φᵀ M φ per mode kept")
    _each(m, "generalized_masses", lambda x: np.isfinite(x) and x > 0.0,
          "must be a generalised mass φᵀ M φ > 0 (finite)")
    return m.reshape(-1)


def _mode_numbers(value: Any) -> Optional[List[int]]:
    """The `modes` argument: None, or NUME_ORDRE (ints), each once, at least one."""
    if value is None:
        return None
    if isinstance(value, (str, bytes, Mapping)) or not isinstance(value, Iterable):
        raise FretdynError(f"modes: must be a list of NUME_ORDRE (ints), not {value!r}")
    numbers = list(value)
    for i, m in enumerate(numbers):
        if isinstance(m, (bool, np.bool_)) or not isinstance(m, (int, np.integer)):
            raise FretdynError(f"modes[{i}]: must be a NUME_ORDRE (an int), not {m!r}")
    if not numbers:
        raise FretdynError("modes is empty: keep at least one mode")
    if len(set(int(m) for m in numbers)) != len(numbers):
        raise FretdynError(f"modes lists a NUME_ORDRE twice: {[int(m) for m in numbers]}")
    return [int(m) for m in numbers]


def _flag(value: Any, name: str, none: bool = False) -> None:
    """A bool argument (or None when `none`): 'yes' or 0 is not silently taken for one."""
    if not (isinstance(value, (bool, np.bool_)) or (none and value is None)):
        allowed = "True, False or None" if none else "True or False"
        raise FretdynError(f"{name}: must be {allowed}, not {value!r}")


def _medcoupling():
    try:
        import medcoupling  # noqa: F401
    except ImportError as e:
        raise ImportError(
            "fretdyn.med needs the medcoupling package to read MED files: "
            "pip install medcoupling (or pip install 'fretdyn[med]')"
        ) from e
    return medcoupling


def _component(info: str) -> str:
    """`DX`, from a medcoupling component info `DX` or `DX [m]`."""
    return info.split("[", 1)[0].strip()


def _points_by_name(points: Any, path: Path) -> List[Tuple[str, Union[str, int]]]:
    if isinstance(points, str):
        points = [points]
    if isinstance(points, Mapping):
        items = list(points.items())
    else:
        try:
            items = [(g, g) for g in points]
        except TypeError:
            items = None
        if items is None or any(not isinstance(g, str) for g, _ in items):
            raise FretdynError(
                f"{path}: points must be a dict {{name: node group or node number}} or a list "
                f"of node group names, not {points!r}"
            )
    if not items:
        raise FretdynError(
            f"{path}: points is empty: name at least one node group (GROUP_NO) or node, "
            f"e.g. points={{'A': 'PA'}}"
        )
    names = [name for name, _ in items]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise FretdynError(f"{path}: point name(s) {twice} given twice: names must be unique")
    for name, where in items:
        if not isinstance(name, str) or not name.strip():
            raise FretdynError(f"{path}: point name {name!r} must be a non-empty str")
        if isinstance(where, (bool, np.bool_)) or not isinstance(where, (str, int, np.integer)):
            raise FretdynError(
                f"{path}: point '{name}': {where!r} is neither a node group name (str) nor a "
                f"node number (int, from 1)"
            )
        if not isinstance(where, str) and where < 1:
            raise FretdynError(
                f"{path}: point '{name}': node {where} is not a node number: nodes are "
                f"numbered from 1, as in Code_Aster and Salome"
            )
    return [(name, where if isinstance(where, str) else int(where)) for name, where in items]


def _choose_field(mc, path: Path, field: Optional[str]) -> str:
    names = [str(n) for n in mc.GetAllFieldNames(str(path))]
    if field is not None:
        if field in names:
            return field
        raise FretdynError(
            f"{path}: no field '{field}' (fields in the file: {names or 'none'}); Code_Aster "
            f"names it after the result, padded with '_' to 8 characters, then the field: "
            f"'modes___DEPL'"
        )
    depl = [n for n in names if len(n) > 8 and n[8:].strip() == "DEPL"]
    if len(depl) == 1:
        return depl[0]
    if not depl:
        raise FretdynError(
            f"{path}: no DEPL field (a field named '<result, 8 characters>DEPL', e.g. "
            f"'modes___DEPL'; fields in the file: {names or 'none'}): write the modes with "
            f"IMPR_RESU(FORMAT='MED', RESU=_F(RESULTAT=modes, NOM_CHAM='DEPL')), or name the "
            f"field with field='…'"
        )
    raise FretdynError(
        f"{path}: several DEPL fields {depl}: choose one with field='…'"
    )


def _parameters(mc, path: Path) -> Dict[str, Any]:
    """The MED scalar parameters of the file, by name ({} when it has none)."""
    try:
        params = mc.MEDFileParameters.New(str(path))
    except mc.InterpKernelException:
        return {}
    return {str(n): params.getParamWithName(n) for n in params.getParamsNames()}


def _parameter(
    params: Dict[str, Any], key: str, steps: Sequence[Tuple[int, int, float]], path: Path
) -> Optional[Tuple[str, np.ndarray]]:
    """The values, one per step of `steps`, of the parameter Code_Aster names
    `<8-character result name><key>`; None when the file has none. Among several (several
    results in one file), the one defined at every step of the field."""
    candidates = [n for n in params if len(n) > 8 and n[8:].strip() == key]
    found = []
    for name in candidates:
        p = params[name]
        have = {(int(it), int(order)) for it, order, _ in p.getTimeSteps()}
        if all((it, order) in have for it, order, _ in steps):
            found.append(name)
    if not candidates:
        return None
    if not found:
        raise FretdynError(
            f"{path}: the parameter(s) {candidates} lack some modes of the field (NUME_ORDRE "
            f"{[it for it, _, _ in steps]}): print the field and its parameters in the same "
            f"IMPR_RESU"
        )
    if len(found) > 1:
        raise FretdynError(
            f"{path}: several results give {key} at these modes ({found}): write one result "
            f"per file, or give the values yourself"
        )
    p = params[found[0]]
    return found[0], np.array([p.getDoubleValue(it, order) for it, order, _ in steps], dtype=float)


def read_modal_basis(
    path: PathLike,
    points: Union[Mapping[str, Union[str, int]], Sequence[str]],
    *,
    field: Optional[str] = None,
    modes: Optional[Iterable[int]] = None,
    generalized_masses: Optional[Sequence[float]] = None,
    mass_normalized: bool = False,
    damping_ratio: Union[float, Sequence[float]] = 0.0,
    rotations: Optional[bool] = None,
) -> ModalBasis:
    """Reads a modal basis exported by Code_Aster with `IMPR_RESU(FORMAT='MED', RESU=_F(
    RESULTAT=modes, NOM_CHAM='DEPL', NOM_PARA=('FREQ', 'MASS_GENE')))` (docs/MED.md).

    - `points`: `{name: node group or node number}` — a `GROUP_NO` of one node, or the node's
      number from 1 (as Code_Aster and Salome number them) — or a list of node group names
      (each point named after its group).
    - `field`: the MED field of the shapes; by default the only `<result>DEPL` field.
    - `modes`: the `NUME_ORDRE` of the modes to keep, in that order (default: every mode).
    - `generalized_masses`: `φᵀ M φ` of each mode kept (p,), when the file does not carry
      `MASS_GENE`; they win over the file's.
    - `mass_normalized`: the shapes are already mass-normalised
      (`NORM_MODE=_F(NORME='MASS_GENE')`); refused if the file's `MASS_GENE` say otherwise.
    - `damping_ratio`: one modal damping ratio for every mode, or one per mode kept.
    - `rotations`: keep the rotation rows (`DRX DRY DRZ`, beams and shells: needed by a contact
      with `radius`); None: when the field has them.

    The frequencies are the time values of the MED steps (Code_Aster writes `FREQ` there);
    each shape is divided by √`MASS_GENE`. An argument out of range (a negative damping ratio,
    a generalised mass ≤ 0, a NaN, a mode number that is not an int, a node number below 1)
    raises `FretdynError` naming it, in the words of the case file's errors, before the file
    is opened; bad input in the file raises `FretdynError` naming the file and what is wrong
    in it; without medcoupling, ImportError."""
    damping = _damping_ratios(damping_ratio)
    given_masses = None if generalized_masses is None else _generalised_masses(generalized_masses)
    modes = _mode_numbers(modes)
    _flag(mass_normalized, "mass_normalized")
    _flag(rotations, "rotations", none=True)
    if field is not None and not isinstance(field, str):
        raise FretdynError(f"field: must be the name of a MED field (a str) or None, not {field!r}")
    path = Path(path)
    wanted = _points_by_name(points, path)
    mc = _medcoupling()
    if not path.is_file():
        raise FretdynError(f"{path}: no such file (a MED file written by IMPR_RESU(FORMAT='MED'))")
    try:
        fname = _choose_field(mc, path, field)
        fts = mc.MEDFileFieldMultiTS.New(str(path), fname, False)
    except mc.InterpKernelException as e:
        raise FretdynError(f"{path}: not a MED file medcoupling can read: {str(e).strip()}") from None
    steps = sorted((int(it), int(order), float(t)) for it, order, t in fts.getTimeSteps())
    if not steps:
        raise FretdynError(f"{path}: field '{fname}' has no time step (one per mode is expected)")
    if modes is not None:
        by_number = {it: (it, order, t) for it, order, t in steps}
        chosen = []
        for m in modes:
            if m not in by_number:
                raise FretdynError(
                    f"{path}: modes: no mode with NUME_ORDRE {m!r} in field '{fname}' "
                    f"(NUME_ORDRE in the file: {sorted(by_number)})"
                )
            chosen.append(by_number[m])
        steps = chosen
    p = len(steps)

    # -- the mesh and the points' nodes
    try:
        mesh = mc.MEDFileMesh.New(str(path), fts.getMeshName())
    except mc.InterpKernelException as e:
        raise FretdynError(
            f"{path}: the mesh '{fts.getMeshName()}' of field '{fname}' cannot be read: {str(e).strip()}"
        ) from None
    coords = mesh.getCoords().toNumPyArray().reshape(mesh.getNumberOfNodes(), -1)
    nnodes, sdim = coords.shape
    coords3 = np.zeros((nnodes, 3))
    coords3[:, : min(sdim, 3)] = coords[:, :3]
    node_groups = {str(g).strip(): str(g) for g in mesh.getGroupsOnSpecifiedLev(1)}
    all_groups = {str(g).strip() for g in mesh.getGroupsNames()}
    nodes: List[Tuple[str, int, Optional[str]]] = []
    for name, where in wanted:
        if isinstance(where, int):
            if not 1 <= where <= nnodes:
                raise FretdynError(
                    f"{path}: point '{name}': node {where} is not in mesh '{fts.getMeshName()}' "
                    f"(nodes 1 to {nnodes})"
                )
            nodes.append((name, where - 1, None))
            continue
        g = where.strip()
        if g not in node_groups:
            if g in all_groups:
                raise FretdynError(
                    f"{path}: point '{name}': '{g}' is a group of cells (GROUP_MA), not of nodes: "
                    f"add DEFI_GROUP(CREA_GROUP_NO=_F(GROUP_MA='{g}')) before IMPR_RESU, or "
                    f"give a node group"
                )
            raise FretdynError(
                f"{path}: point '{name}': no node group (GROUP_NO) '{g}' in mesh "
                f"'{fts.getMeshName()}' (node groups: {sorted(node_groups) or 'none'})"
            )
        ids = mesh.getGroupArr(1, node_groups[g]).toNumPyArray()
        if len(ids) != 1:
            raise FretdynError(
                f"{path}: point '{name}': node group '{g}' has {len(ids)} nodes; a point is one "
                f"node: make a group of one node (DEFI_GROUP(CREA_GROUP_NO=_F(NOM='{g}_1', "
                f"NOEUD=…))) or give its number"
            )
        nodes.append((name, int(ids[0]), g))

    # -- the shapes at the points' nodes, one MED step (one mode) at a time
    raw = {name: np.empty((6, p)) for name, _, _ in nodes}
    components: Optional[List[str]] = None
    for i, (it, order, _) in enumerate(steps):
        f1 = mc.MEDFileField1TS.New(str(path), fname, it, order)
        if mc.ON_NODES not in f1.getTypesOfFieldAvailable():
            raise FretdynError(
                f"{path}: field '{fname}' is not a field on nodes (DEPL is): NUME_ORDRE {it}"
            )
        arr, pfl = f1.getFieldWithProfile(mc.ON_NODES, 0, mesh)
        comps = [_component(c) for c in arr.getInfoOnComponents()]
        if components is None:
            components = comps
            missing = [c for c in TRANSLATIONS[: max(sdim, 2)] if c not in comps]
            if missing:
                raise FretdynError(
                    f"{path}: field '{fname}' has components {comps}, not {missing}: fretdyn "
                    f"needs the displacements DX, DY, DZ (print DEPL without NOM_CMP)"
                )
            has_rot = all(c in comps for c in ROTATIONS)
            if rotations is None:
                rotations = has_rot
            elif rotations and not has_rot:
                raise FretdynError(
                    f"{path}: rotations=True but field '{fname}' has components {comps}, "
                    f"without all of DRX, DRY, DRZ (a model of beams or shells has them)"
                )
        elif comps != components:
            raise FretdynError(
                f"{path}: field '{fname}' changes components at NUME_ORDRE {it}: {comps} "
                f"instead of {components}"
            )
        values = arr.toNumPyArray().reshape(arr.getNumberOfTuples(), -1)
        where_in = np.full(nnodes, -1, dtype=np.int64)
        ids = np.arange(nnodes) if pfl is None else pfl.toNumPyArray()
        where_in[ids] = np.arange(len(ids))
        for name, node, group in nodes:
            k = where_in[node]
            if k < 0:
                raise FretdynError(
                    f"{path}: point '{name}': node {node + 1} has no value in field '{fname}' "
                    f"at NUME_ORDRE {it} (the field covers {len(ids)} of the {nnodes} nodes): "
                    f"choose a node of the model"
                )
            for d, c in enumerate(TRANSLATIONS + ROTATIONS):
                raw[name][d, i] = values[k, components.index(c)] if c in components else 0.0
            used = TRANSLATIONS + (ROTATIONS if rotations else ())
            bad = [c for d, c in enumerate(used)
                   if c in components and not np.isfinite(raw[name][d, i])]
            if bad:
                raise FretdynError(
                    f"{path}: point '{name}' (node {node + 1}"
                    f"{f', group {group}' if group else ''}): mode shape not finite "
                    f"({raw[name][[(TRANSLATIONS + ROTATIONS).index(c) for c in bad], i].tolist()}) "
                    f"in {bad} of field '{fname}' at NUME_ORDRE {it}: fix the model or drop that "
                    f"mode (modes=[…])"
                )

    # -- frequencies, generalised masses, normalisation
    params = _parameters(mc, path)
    freq = np.array([t for _, _, t in steps], dtype=float)
    listed = _parameter(params, "FREQ", steps, path)
    if listed is not None and not np.array_equal(listed[1], freq):
        raise FretdynError(
            f"{path}: the time values of field '{fname}' {freq.tolist()} are not the "
            f"frequencies of parameter '{listed[0]}' {listed[1].tolist()}"
        )
    numbers = np.array([it for it, _, _ in steps], dtype=np.int64)
    for i, f in enumerate(freq):
        if not (np.isfinite(f) and f >= 0.0):
            raise FretdynError(
                f"{path}: mode NUME_ORDRE {numbers[i]} has frequency {f} Hz (the time value of "
                f"its step in field '{fname}'): a mode needs a finite frequency ≥ 0; drop it "
                f"with modes=[…]"
            )
    in_file = _parameter(params, "MASS_GENE", steps, path)
    if given_masses is not None:
        masses = given_masses
        if masses.shape != (p,):
            raise FretdynError(
                f"{path}: generalized_masses has {masses.size} values for the {p} modes kept "
                f"(NUME_ORDRE {numbers.tolist()})"
            )
        source = "given"
    elif mass_normalized:
        if in_file is not None and np.any(np.abs(in_file[1] - 1.0) > NORMALISED_TOLERANCE):
            k = int(np.argmax(np.abs(in_file[1] - 1.0)))
            raise FretdynError(
                f"{path}: mass_normalized=True but parameter '{in_file[0]}' gives MASS_GENE = "
                f"{in_file[1][k]!r} for mode NUME_ORDRE {numbers[k]}: drop mass_normalized to "
                f"normalise the shapes with the file's generalised masses"
            )
        masses = np.ones(p)
        source = "mass_normalized"
    elif in_file is not None:
        masses = in_file[1]
        source = f"file ({in_file[0].strip()})"
    else:
        raise FretdynError(
            f"{path}: no generalised masses (no MASS_GENE parameter in the file): Code_Aster's "
            f"shapes are not mass-normalised unless CALC_MODES has NORM_MODE=_F(NORME="
            f"'MASS_GENE'). Add NOM_PARA=('FREQ', 'MASS_GENE') to IMPR_RESU's RESU, or give "
            f"generalized_masses=[…] (one per mode), or mass_normalized=True"
        )
    for i, m in enumerate(masses):
        if not (np.isfinite(m) and m > 0.0):
            raise FretdynError(
                f"{path}: generalised mass of mode NUME_ORDRE {numbers[i]} is {m!r} "
                f"({source}): it must be finite and > 0"
            )
    scale = np.sqrt(masses)

    damping = np.full(p, float(damping)) if damping.ndim == 0 else damping
    if damping.shape != (p,):
        raise FretdynError(
            f"{path}: damping_ratio has {damping.size} values for the {p} modes kept: give one "
            f"number, or one per mode"
        )

    participation = None
    gamma = [_parameter(params, key, steps, path) for key in PARTICIPATION]
    if all(g is not None for g in gamma):
        # FACT_PARTICI = φᵀ M r / φᵀ M φ (flust2.F90: φᵀ M r = FACT_PARTICI × MASS_GENE),
        # so that the mass-normalised φᵀ M r / √(φᵀ M φ) = FACT_PARTICI × √MASS_GENE
        participation = np.array([g[1] for g in gamma]) * scale

    basis = ModalBasis(
        path=path,
        field=fname,
        mode_numbers=numbers,
        frequencies_hz=freq,
        damping_ratio=damping,
        generalized_masses=masses,
        mass_source=source,
        participation=participation,
    )
    for name, node, group in nodes:
        basis.points[name] = MedPoint(
            name=name,
            node=node + 1,
            group=group,
            coords=coords3[node].copy(),
            rows=raw[name][:3] / scale,
            rotations=raw[name][3:] / scale if rotations else None,
        )
    return basis

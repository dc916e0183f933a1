"""Modal bases from Code_Aster's MED files (fretdyn.med, docs/MED.md): files written here with
medcoupling in the layout Code_Aster's IMPR_RESU(FORMAT='MED') gives a modal result — the mesh
with node groups, one nodal field '<result>___DEPL' with one time step per mode (iteration =
order = NUME_ORDRE, time = FREQ), components DX … DRZ, and NOM_PARA's scalar parameters
'<8-character result name>MASS_GENE' — read back and checked against the analytic modes of a
pinned–pinned beam; a case run on the MED basis equals the same case on the analytic basis
given as .npz, bit for bit."""

import sys

import numpy as np
import pytest

import fretdyn

mc = pytest.importorskip(
    "medcoupling", reason="fretdyn.med reads MED files with medcoupling (pip install medcoupling)"
)
from fretdyn import med  # noqa: E402

from helpers import same_bits  # noqa: E402

# A pinned–pinned Euler–Bernoulli beam along x (the tube of examples/beam_three_supports.toml):
# φ_k(x) = √(2/(ρA L)) sin(kπx/L) in y and in z, f_k = (kπ/L)² √(EI/ρA) / 2π, θz = dφy/dx,
# θy = −dφz/dx; mass-normalised: ∫ ρA φ_k² dx = 1.
L, EI, RHOA, K = 1.5, 498.0, 1.0, 3
X = np.linspace(0.0, L, 31)
GROUPS = {"PA": 6, "PB": 15, "PC": 24, "LOAD": 10}  # node indices from 0: x = 0.3, 0.75, 1.2, 0.5
COMPONENTS = ["DX", "DY", "DZ", "DRX", "DRY", "DRZ"]
# Generalised masses φᵀMφ of the shapes written to the file: powers of 4, so that dividing by
# their square root is exact and the MED basis must equal the analytic one bit for bit.
DYADIC = np.array([4.0, 0.25, 16.0, 2.0 ** -6, 64.0, 1.0])


def analytic():
    """Frequencies (p,), shapes (p, nodes, 6) and participation factors Φᵀ M r (3, p) of
    the beam's 2K modes (y then z for each k), mass-normalised."""
    a = np.sqrt(2.0 / (RHOA * L))
    freq, shapes, gamma = [], [], []
    for k in range(1, K + 1):
        beta = k * np.pi / L
        f = beta ** 2 * np.sqrt(EI / RHOA) / (2.0 * np.pi)
        g = RHOA * a * L * (1.0 - np.cos(k * np.pi)) / (k * np.pi)  # ρA ∫ φ_k dx
        for plane in ("y", "z"):
            s = np.zeros((len(X), 6))
            if plane == "y":
                s[:, 1] = a * np.sin(beta * X)
                s[:, 5] = a * beta * np.cos(beta * X)
                gamma.append([0.0, g, 0.0])
            else:
                s[:, 2] = a * np.sin(beta * X)
                s[:, 4] = -a * beta * np.cos(beta * X)
                gamma.append([0.0, 0.0, g])
            freq.append(f)
            shapes.append(s)
    return np.array(freq), np.array(shapes), np.array(gamma).T


def write_aster_med(path, freq, shapes, masses=None, *, result="modes", internal="00000004",
                    nom_para=("FREQ", "MASS_GENE"), components=COMPONENTS, groups=GROUPS,
                    gamma=None, first_order=1, profile=None):
    """A MED file as Code_Aster's IMPR_RESU(FORMAT='MED', RESU=_F(RESULTAT=modes,
    NOM_CHAM='DEPL', NOM_PARA=nom_para)) writes it: `shapes` (p, nodes, c) are the stored
    (not mass-normalised) shapes, `masses` their MASS_GENE, `gamma` their FACT_PARTICI_D*
    (3, p); `profile`: the nodes the field covers (all without). Field '<result>' padded
    with '_' to 8 + 'DEPL' (mdnoch.F90; the Python name since code_aster 15, impr_resu.py);
    step per mode: iteration = order = NUME_ORDRE, time = FREQ (irchme.F90); parameters
    '<internal name, 8 characters><NOM_PARA>' (irmpar.F90, irmpav.F90)."""
    path = str(path)
    coords = np.zeros((len(X), 3))
    coords[:, 0] = X
    m = mc.MEDCouplingUMesh("MAIL", 1)
    m.setCoords(mc.DataArrayDouble(coords))
    m.allocateCells(len(X) - 1)
    for i in range(len(X) - 1):
        m.insertNextCell(mc.NORM_SEG2, [i, i + 1])
    m.finishInsertingCells()
    mesh = mc.MEDFileUMesh()
    mesh.setMeshAtLevel(0, m)
    node_groups = []
    for name, nodes in groups.items():
        g = mc.DataArrayInt([int(n) for n in np.atleast_1d(nodes)])
        g.setName(name)
        node_groups.append(g)
    mesh.setGroupsAtLevel(1, node_groups)
    beam = mc.DataArrayInt(list(range(len(X) - 1)))
    beam.setName("BEAM")
    mesh.setGroupsAtLevel(0, [beam])
    mesh.write33(path, 2)

    field = mc.MEDFileFieldMultiTS()
    name = result[:8].ljust(8, "_") + "DEPL"
    numbers = range(first_order, first_order + len(freq))
    for nume, f, s in zip(numbers, freq, shapes):
        fd = mc.MEDCouplingFieldDouble(mc.ON_NODES, mc.ONE_TIME)
        fd.setName(name)
        fd.setMesh(m)
        values = s if profile is None else s[profile]
        arr = mc.DataArrayDouble(np.ascontiguousarray(values, dtype=float))
        arr.setInfoOnComponents(list(components))
        fd.setArray(arr)
        fd.setTime(float(f), nume, nume)
        if profile is None:
            field.appendFieldNoProfileSBT(fd)
        else:
            pfl = mc.DataArrayInt([int(n) for n in profile])
            pfl.setName("PFL_MODEL")
            step = mc.MEDFileField1TS()
            step.setFieldProfile(fd, mesh, 0, pfl)
            field.pushBackTimeStep(step)
    field.write33(path, 0)

    values = {"FREQ": freq, "MASS_GENE": masses}
    if gamma is not None:
        values.update(zip(["FACT_PARTICI_DX", "FACT_PARTICI_DY", "FACT_PARTICI_DZ"], gamma))
        nom_para = tuple(nom_para) + ("FACT_PARTICI_DX", "FACT_PARTICI_DY", "FACT_PARTICI_DZ")
    for key in nom_para:
        p = mc.MEDFileParameterMultiTS.New()
        p.setName(internal[:8].ljust(8) + key)
        p.setDescription(key)
        for nume, f, v in zip(numbers, freq, values[key]):
            p.appendValue(nume, nume, float(f), float(v))
        p.write(path, 0)
    return path


def aster_file(tmp_path, masses=DYADIC, **kw):
    """The analytic basis stored with generalised masses `masses` (φ √m), as Code_Aster."""
    freq, shapes, gamma = analytic()
    stored = shapes * np.sqrt(masses)[:, None, None]
    return write_aster_med(tmp_path / "modes.rmed", freq, stored, masses, **kw)


def npz_of_analytic(path, damping=0.01, rotations=True):
    """The analytic basis as fretdyn's .npz, written with numpy (README's keys)."""
    freq, shapes, _ = analytic()
    arrays = {"frequencies_hz": freq, "damping_ratio": np.full(len(freq), damping)}
    for name, node in GROUPS.items():
        arrays[f"rows_{name}"] = np.ascontiguousarray(shapes[:, node, :3].T)
        arrays[f"coords_{name}"] = np.array([X[node], 0.0, 0.0])
        if rotations:
            arrays[f"rotations_{name}"] = np.ascontiguousarray(shapes[:, node, 3:].T)
    np.savez(path, **arrays)
    return path


def case(structure):
    """Three supports and a harmonic force on the beam (examples/beam_three_supports.toml,
    shortened); one contact on the tube surface (radius), which uses the rotations."""
    return {
        "title": "MED basis",
        "time": {"dt": 1e-5, "duration": 0.02},
        "structure": structure,
        "contacts": [
            {"name": "a_below", "point": "PA", "normal": {"stiffness": 1e6},
             "obstacle": {"type": "plane", "origin": [0.3, 0.0, 0.0], "normal": [0.0, 1.0, 0.0],
                          "gap": 1e-4, "tangent": [1.0, 0.0, 0.0]},
             "friction": {"mu": 0.3}},
            {"name": "b_hole", "point": "PB", "radius": 9.525e-3, "normal": {"stiffness": 1e6},
             "obstacle": {"type": "circle", "centre": [0.75, 0.0, 0.0], "axis": [1.0, 0.0, 0.0],
                          "clearance": 1e-4},
             "friction": {"mu": 0.3}},
            {"name": "c_side", "point": "PC", "normal": {"stiffness": 1e6, "damping": 5.0},
             "obstacle": {"type": "plane", "origin": [1.2, 0.0, 0.0], "normal": [0.0, 0.0, 1.0],
                          "gap": 1e-4, "tangent": [1.0, 0.0, 0.0]},
             "friction": {"mu": 0.3}},
        ],
        "loads": [{"point": "LOAD", "force": [0.0, 15.0, 10.0],
                   "history": {"type": "harmonic", "frequency_hz": 55.0, "phase_deg": 0.0}}],
        "tangential": {"method": "gauss_seidel"},
    }


def test_round_trip_gives_the_analytic_mass_normalised_basis(tmp_path):
    freq, shapes, _ = analytic()
    b = med.read_modal_basis(aster_file(tmp_path), points=list(GROUPS))
    assert b.field == "modes___DEPL"
    assert b.mode_numbers.tolist() == [1, 2, 3, 4, 5, 6]
    assert same_bits(b.frequencies_hz, freq)
    assert same_bits(b.generalized_masses, DYADIC)
    assert b.mass_source.startswith("file")
    assert list(b.points) == list(GROUPS)
    for name, node in GROUPS.items():
        pt = b.points[name]
        assert pt.node == node + 1 and pt.group == name
        assert same_bits(pt.coords, np.array([X[node], 0.0, 0.0]))
        # φ √m / √m with m a power of 4: exactly the analytic mass-normalised shape
        assert same_bits(pt.rows, np.ascontiguousarray(shapes[:, node, :3].T)), name
        assert same_bits(pt.rotations, np.ascontiguousarray(shapes[:, node, 3:].T)), name
    # mass normalisation against the closed form: ∫ ρA φ² dx = 1 with φ = a sin(kπx/L)
    a = np.sqrt(2.0 / (RHOA * L))
    x = X[GROUPS["PA"]]
    expected = a * np.sin(np.repeat(np.arange(1, K + 1), 2) * np.pi * x / L)
    got = np.where(np.arange(2 * K) % 2 == 0, b.points["PA"].rows[1], b.points["PA"].rows[2])
    np.testing.assert_allclose(got, expected, rtol=1e-14)
    assert b.participation is None


def test_code_aster_default_normalisation_is_undone_with_mass_gene(tmp_path):
    # CALC_MODES' default NORM_MODE is TRAN_ROTA: the largest component of each mode is 1,
    # and MASS_GENE = 1 / max² (not a power of 4: correct to rounding)
    freq, shapes, _ = analytic()
    peak = np.abs(shapes).reshape(len(freq), -1).max(axis=1)
    stored = shapes / peak[:, None, None]
    masses = 1.0 / peak ** 2
    path = write_aster_med(tmp_path / "tran_rota.rmed", freq, stored, masses)
    b = med.read_modal_basis(path, points={"A": "PA", "middle": 16})
    assert np.abs(stored).reshape(len(freq), -1).max(axis=1).tolist() == [1.0] * len(freq)
    np.testing.assert_allclose(b.points["A"].rows, shapes[:, GROUPS["PA"], :3].T, rtol=1e-15, atol=0.0)
    np.testing.assert_allclose(b.points["middle"].rotations, shapes[:, 15, 3:].T, rtol=1e-15, atol=0.0)
    assert b.points["middle"].node == 16 and b.points["middle"].group is None


def test_a_case_on_the_med_basis_equals_the_npz_basis_bit_for_bit(tmp_path):
    analytic_npz = npz_of_analytic(tmp_path / "analytic.npz")
    b = med.read_modal_basis(aster_file(tmp_path), points=list(GROUPS), damping_ratio=0.01)
    from_med = b.write_npz(tmp_path / "from_med.npz")
    reference = fretdyn.run(fretdyn.Case.from_dict(
        case({"type": "modal", "file": str(analytic_npz)})))
    runs = {
        "npz written from the MED file": fretdyn.run(fretdyn.Case.from_dict(
            case({"type": "modal", "file": str(from_med)}))),
        "structure() inline": fretdyn.run(fretdyn.Case.from_dict(case(b.structure()))),
    }
    assert reference["summary"]["termination"]["status"] == "completed"
    # the beam hits its supports: the contacts (one on the tube surface) take part
    assert sum(c["impacts"] for c in reference["summary"]["contacts"]) > 0
    assert np.max(np.abs(reference["contact_normal_force"][:, 1])) > 0.0
    keys = [k for k, v in reference.items() if isinstance(v, np.ndarray)]
    assert "q" in keys and "contact_normal_force" in keys
    for label, r in runs.items():
        for k in keys:
            assert same_bits(r[k], reference[k]), f"{label}: {k}"
        assert r["summary"]["contacts"] == reference["summary"]["contacts"], label


def test_generalised_masses_given_when_the_file_has_none(tmp_path):
    freq, shapes, _ = analytic()
    path = aster_file(tmp_path, nom_para=())
    with pytest.raises(fretdyn.FretdynError) as e:
        med.read_modal_basis(path, points=["PA"])
    msg = str(e.value)
    assert str(path) in msg and "MASS_GENE" in msg and "generalized_masses" in msg, msg
    b = med.read_modal_basis(path, points=["PA"], generalized_masses=DYADIC)
    assert same_bits(b.points["PA"].rows, np.ascontiguousarray(shapes[:, GROUPS["PA"], :3].T))
    assert b.mass_source == "given"
    # the frequencies are the steps' time values when the FREQ parameter is not printed
    assert same_bits(b.frequencies_hz, freq)


def test_a_basis_said_mass_normalised(tmp_path):
    freq, shapes, _ = analytic()
    ones = np.ones(len(freq))
    path = write_aster_med(tmp_path / "norm.rmed", freq, shapes, ones, nom_para=("FREQ",))
    b = med.read_modal_basis(path, points=["PB"], mass_normalized=True)
    assert same_bits(b.points["PB"].rows, np.ascontiguousarray(shapes[:, GROUPS["PB"], :3].T))
    # the flag contradicted by the file's MASS_GENE
    with pytest.raises(fretdyn.FretdynError) as e:
        med.read_modal_basis(aster_file(tmp_path), points=["PB"], mass_normalized=True)
    assert "modes.rmed" in str(e.value) and "MASS_GENE" in str(e.value), str(e.value)


def test_participation_factors_from_fact_partici(tmp_path):
    # Code_Aster's FACT_PARTICI_D* = φᵀ M r / φᵀ M φ of the stored shape φ √m, that is Γ / √m
    freq, shapes, gamma = analytic()
    path = aster_file(tmp_path, gamma=gamma / np.sqrt(DYADIC))
    b = med.read_modal_basis(path, points=["PA"])
    assert same_bits(b.participation, gamma)
    np.testing.assert_allclose(b.participation[1, 0], 2.0 * np.sqrt(2.0 * RHOA * L) / np.pi, rtol=1e-15)
    out = np.load(b.write_npz(tmp_path / "b.npz"))
    assert same_bits(out["participation"], gamma)


def test_mode_selection_and_translations_only(tmp_path):
    freq, shapes, _ = analytic()
    path = write_aster_med(tmp_path / "solid.rmed", freq,
                           shapes[:, :, :3] * np.sqrt(DYADIC)[:, None, None], DYADIC,
                           components=COMPONENTS[:3])
    b = med.read_modal_basis(path, points={"A": "PA"}, modes=[4, 2])
    assert b.mode_numbers.tolist() == [4, 2]
    assert same_bits(b.frequencies_hz, freq[[3, 1]])
    assert same_bits(b.points["A"].rows, np.ascontiguousarray(shapes[[3, 1], GROUPS["PA"], :3].T))
    assert b.points["A"].rotations is None
    out = np.load(b.write_npz(tmp_path / "sel.npz"))
    assert "rotations_A" not in out.files and same_bits(out["frequencies_hz"], freq[[3, 1]])
    with pytest.raises(fretdyn.FretdynError, match="rotations=True"):
        med.read_modal_basis(path, points={"A": "PA"}, rotations=True)
    with pytest.raises(fretdyn.FretdynError, match=r"NUME_ORDRE 9 .*\[1, 2, 3, 4, 5, 6\]"):
        med.read_modal_basis(path, points={"A": "PA"}, modes=[9])


def test_bad_inputs_name_the_file_and_the_thing(tmp_path):
    path = aster_file(tmp_path, groups={**GROUPS, "TWO": [3, 4]})
    cases = [
        (dict(points=["NOPE"]), ["NOPE", "node group", "PA"]),
        (dict(points=["BEAM"]), ["BEAM", "GROUP_MA", "CREA_GROUP_NO"]),
        (dict(points=["TWO"]), ["TWO", "2 nodes"]),
        (dict(points={"A": 99}), ["node 99", "1 to 31"]),
        (dict(points=["PA"], field="resu____DEPL"), ["resu____DEPL", "modes___DEPL"]),
        (dict(points=["PA"], generalized_masses=[1.0, 2.0]), ["generalized_masses", "2 values"]),
        (dict(points=["PA"], damping_ratio=[0.01, 0.02]), ["damping_ratio", "2 values"]),
        (dict(points={}), ["points is empty"]),
    ]
    for kw, words in cases:
        with pytest.raises(fretdyn.FretdynError) as e:
            med.read_modal_basis(path, **kw)
        msg = str(e.value)
        assert str(path) in msg and all(w in msg for w in words), (kw, msg)
    with pytest.raises(fretdyn.FretdynError, match="no such file"):
        med.read_modal_basis(tmp_path / "missing.rmed", points=["PA"])
    (tmp_path / "text.rmed").write_text("not MED")
    with pytest.raises(fretdyn.FretdynError, match="text.rmed"):
        med.read_modal_basis(tmp_path / "text.rmed", points=["PA"])


def test_a_file_without_a_depl_field(tmp_path):
    freq, shapes, _ = analytic()
    path = write_aster_med(tmp_path / "vite.rmed", freq, shapes, DYADIC, result="modes")
    # rename the field as a VITE field would be named
    f = mc.MEDFileFieldMultiTS.New(path, "modes___DEPL")
    f.setName("modes___VITE")
    mc.MEDFileMesh.New(path).write33(str(tmp_path / "vite2.rmed"), 2)
    f.write33(str(tmp_path / "vite2.rmed"), 0)
    with pytest.raises(fretdyn.FretdynError) as e:
        med.read_modal_basis(tmp_path / "vite2.rmed", points=["PA"])
    msg = str(e.value)
    assert "vite2.rmed" in msg and "no DEPL field" in msg and "modes___VITE" in msg, msg
    assert "NOM_CHAM='DEPL'" in msg, msg


def test_nan_in_a_shape_is_named(tmp_path):
    freq, shapes, _ = analytic()
    stored = shapes * np.sqrt(DYADIC)[:, None, None]
    stored[2, GROUPS["PC"], 2] = np.nan  # mode NUME_ORDRE 3, DZ at PC
    path = write_aster_med(tmp_path / "nan.rmed", freq, stored, DYADIC)
    with pytest.raises(fretdyn.FretdynError) as e:
        med.read_modal_basis(path, points=["PA", "PC"])
    msg = str(e.value)
    assert "nan.rmed" in msg and "'PC'" in msg and "DZ" in msg and "NUME_ORDRE 3" in msg, msg
    # the other points, and the modes without NaN, read
    b = med.read_modal_basis(path, points=["PA", "PC"], modes=[1, 2, 4, 5, 6])
    assert np.isfinite(b.points["PC"].rows).all()


def test_without_medcoupling_the_error_says_how_to_install_it(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "medcoupling", None)  # import medcoupling raises
    with pytest.raises(ImportError, match="pip install medcoupling"):
        med.read_modal_basis(tmp_path / "modes.rmed", points=["PA"])


def test_a_field_on_part_of_the_mesh(tmp_path):
    # a field with a MED profile (nodes outside the model carry no DEPL)
    freq, shapes, _ = analytic()
    path = aster_file(tmp_path, profile=list(range(20)))
    b = med.read_modal_basis(path, points=["PA", "LOAD"])
    assert same_bits(b.points["LOAD"].rows, np.ascontiguousarray(shapes[:, GROUPS["LOAD"], :3].T))
    with pytest.raises(fretdyn.FretdynError) as e:
        med.read_modal_basis(path, points=["PA", "PC"])
    msg = str(e.value)
    assert "modes.rmed" in msg and "'PC'" in msg and "node 25" in msg and "20 of the 31" in msg, msg


def test_names_given_twice_and_unused_rotations(tmp_path):
    freq, shapes, _ = analytic()
    with pytest.raises(fretdyn.FretdynError, match=r"\['PA'\] given twice"):
        med.read_modal_basis(aster_file(tmp_path), points=["PA", "PA"])
    # a NaN in a rotation is refused only when the rotations are read
    stored = shapes * np.sqrt(DYADIC)[:, None, None]
    stored[0, GROUPS["PA"], 4] = np.nan  # DRY of mode 1
    path = write_aster_med(tmp_path / "rot.rmed", freq, stored, DYADIC)
    with pytest.raises(fretdyn.FretdynError, match="DRY"):
        med.read_modal_basis(path, points=["PA"])
    b = med.read_modal_basis(path, points=["PA"], rotations=False)
    assert b.points["PA"].rotations is None and np.isfinite(b.points["PA"].rows).all()


def test_a_dict_case_keeps_every_bit_of_its_floats():
    # basis.structure() goes through Case.from_dict (JSON): every float must come back as it
    # was (serde_json's float_roundtrip; without it about one in ten moved by an ulp)
    v = np.random.default_rng(7).random(2000) * 1e3
    structure = {"type": "modal", "frequencies_hz": v.tolist(), "damping_ratio": 0.0,
                 "points": [{"name": "PA", "rows": np.zeros((3, len(v))).tolist()}]}
    c = case(structure)
    c["contacts"], c["loads"] = c["contacts"][:1], []
    tau = 2.0 * np.pi  # the case holds ω = 2π f and gives back ω / 2π
    assert same_bits(fretdyn.Case.from_dict(c).frequencies_hz, v * tau / tau)

"""The arguments of fretdyn.med (docs/MED.md) checked before any MED file is opened, in the
words of the case file's errors: these run without medcoupling (test_med.py needs it to write
MED files), which is made unimportable here to show that no file is read."""

import sys
from pathlib import Path

import numpy as np
import pytest

import fretdyn
from fretdyn import med


@pytest.fixture
def no_medcoupling(monkeypatch):
    """`import medcoupling` raises: an argument error must come before it."""
    monkeypatch.setitem(sys.modules, "medcoupling", None)


def refused(**kwargs):
    with pytest.raises(fretdyn.FretdynError) as e:
        med.read_modal_basis(Path("no_such_dir") / "modes.rmed", **{"points": ["PA"], **kwargs})
    return str(e.value)


def test_a_damping_ratio_is_checked_as_the_case_file_checks_it(no_medcoupling):
    # -0.5 was accepted and written to the .npz; the case file says
    # "structure.damping_ratio: must be a damping ratio ≥ 0, e.g. 0.01 for 1 % (got -0.5)"
    tail = "must be a damping ratio ≥ 0, e.g. 0.01 for 1 %"
    assert refused(damping_ratio=-0.5) == f"damping_ratio: {tail} (got -0.5)"
    assert refused(damping_ratio=[0.01, -0.02]) == f"damping_ratio[1]: {tail} (got -0.02)"
    assert refused(damping_ratio=np.array([0.01, np.nan])) == f"damping_ratio[1]: {tail} (got NaN)"
    assert refused(damping_ratio=float("inf")) == f"damping_ratio: {tail} (got inf)"
    for bad in ["0.01", None, True, [0.01, "x"], {"a": 0.01}]:
        assert refused(damping_ratio=bad).startswith("damping_ratio: must be a damping ratio, or one per mode")
    assert "shape (2, 2)" in refused(damping_ratio=np.zeros((2, 2)))
    # a damping ratio ≥ 1 (overdamped) is a damping ratio the case file takes: the file is next
    with pytest.raises(ImportError, match="pip install medcoupling"):
        med.read_modal_basis("modes.rmed", points=["PA"], damping_ratio=[0.0, 1.5])


def test_every_numeric_argument_is_checked_before_the_file(no_medcoupling):
    assert refused(generalized_masses=[1.0, -2.0]) == (
        "generalized_masses[1]: must be a generalised mass φᵀ M φ > 0 (finite) (got -2.0)")
    assert refused(generalized_masses=[np.inf]).startswith("generalized_masses[0]: ")
    assert refused(generalized_masses=0.0).startswith("generalized_masses: ")
    assert refused(generalized_masses="1").startswith("generalized_masses: must be one generalised")
    assert refused(modes=[1, 2.5]) == "modes[1]: must be a NUME_ORDRE (an int), not 2.5"
    assert refused(modes=[1, True]) == "modes[1]: must be a NUME_ORDRE (an int), not True"
    assert refused(modes=3) == "modes: must be a list of NUME_ORDRE (ints), not 3"
    assert refused(modes=[]) == "modes is empty: keep at least one mode"
    assert refused(modes=iter([2, 2])) == "modes lists a NUME_ORDRE twice: [2, 2]"
    assert refused(mass_normalized="yes") == "mass_normalized: must be True or False, not 'yes'"
    assert refused(rotations=1) == "rotations: must be True, False or None, not 1"
    assert refused(field=3) == "field: must be the name of a MED field (a str) or None, not 3"
    assert "node 0 is not a node number: nodes are numbered from 1" in refused(points={"A": 0})
    # good arguments go on to the file (here: medcoupling is not there)
    with pytest.raises(ImportError):
        med.read_modal_basis("modes.rmed", points={"A": 3, "B": "PB"}, modes=(np.int64(2), 1),
                             generalized_masses=np.array([1.0, 2.0]), damping_ratio=0.02,
                             mass_normalized=np.bool_(False), rotations=None, field="m___DEPL")


def test_a_basis_changed_after_it_was_read_is_not_written(tmp_path):
    basis = med.ModalBasis(
        path=tmp_path / "modes.rmed", field="modes___DEPL", mode_numbers=np.array([1, 2]),
        frequencies_hz=np.array([10.0, 20.0]), damping_ratio=np.array([0.01, 0.02]),
        generalized_masses=np.ones(2), mass_source="given",
        points={"A": med.MedPoint("A", 1, None, np.zeros(3), np.ones((3, 2)), None)},
    )
    assert basis.write_npz(tmp_path / "ok.npz").exists()
    basis.damping_ratio = np.array([0.01, -0.5])
    for call in (lambda: basis.write_npz(tmp_path / "bad.npz"), basis.structure):
        with pytest.raises(fretdyn.FretdynError) as e:
            call()
        assert str(e.value) == "damping_ratio[1]: must be a damping ratio ≥ 0, e.g. 0.01 for 1 % (got -0.5)"
    assert not (tmp_path / "bad.npz").exists()
    basis.damping_ratio = np.array([0.01])
    with pytest.raises(fretdyn.FretdynError, match="damping_ratio: has 1 values for 2 modes"):
        basis.write_npz(tmp_path / "bad.npz")
    basis.damping_ratio = np.zeros(2)
    basis.frequencies_hz = np.array([10.0, np.nan])
    with pytest.raises(fretdyn.FretdynError, match=r"frequencies_hz\[1\]: must be a finite frequency"):
        basis.write_npz(tmp_path / "bad.npz")
    basis.frequencies_hz = np.array([10.0, 20.0])
    basis.points["A"].rows[2, 1] = np.inf
    with pytest.raises(fretdyn.FretdynError, match=r"points\['A'\].rows: mode shape is not finite"):
        basis.write_npz(tmp_path / "bad.npz")
    assert not (tmp_path / "bad.npz").exists()

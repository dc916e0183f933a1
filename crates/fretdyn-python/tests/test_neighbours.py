"""Several structures and two-body contacts from Python (THEORY §15): the case's structures
and contact points against the case file, the results' structure coordinates against the
model, the contacts table's second point, a study key path into `structures[i]`, and the
package's run against the CLI's, bit for bit."""

import json

import numpy as np
import pytest

import fretdyn

from helpers import EXAMPLES, KEYS, cli, same_bits  # noqa: E402


@pytest.fixture(scope="module")
def two_tubes(tmp_path_factory):
    """examples/tube_to_tube.toml shortened to 1 s, run by the CLI and by the package."""
    tmp = tmp_path_factory.mktemp("tubes")
    text = (EXAMPLES / "tube_to_tube.toml").read_text()
    assert "duration = 10.0" in text
    path = tmp / "tubes.toml"
    path.write_text(text.replace("duration = 10.0", "duration = 1.0"))
    p = cli(["run", str(path), "-o", "out", "-q", "--no-plots"], tmp)
    assert p.returncode == 0, p.stderr
    return tmp / "out", fretdyn.Case.from_file(path), fretdyn.run(path)


def test_the_case_names_its_structures_and_the_second_points(two_tubes):
    _, case, _ = two_tubes
    assert case.structures == ["tube_a", "tube_b"]
    names = case.contact_names
    assert names[-1] == "tube_to_tube"
    assert case.contact_points[-1] == "tube_a.mid"
    assert case.contact_other_points[-1] == "tube_b.mid"
    # every structure's own contacts are with obstacles, named structure.name
    for name, other in zip(names[:-1], case.contact_other_points[:-1]):
        assert name.split(".")[0] in case.structures and other == ""


def test_the_results_are_the_cli_s_bit_for_bit(two_tubes):
    out, _, r = two_tubes
    npz = np.load(out / "results.npz")
    for k in KEYS:
        assert same_bits(r[k], npz[k]), k
    summary = json.loads((out / "summary.json").read_text())
    assert [s["name"] for s in summary["structures"]] == ["tube_a", "tube_b"]
    contacts = r.contacts
    other = list(contacts["other_point"]) if hasattr(contacts, "loc") else list(
        contacts["other_point"])
    assert other[-1] == "tube_b.mid" and all(o == "" for o in other[:-1])


def test_to_xarray_labels_each_mode_and_point_with_its_structure(two_tubes):
    pytest.importorskip("xarray")
    _, case, r = two_tubes
    ds = r.to_xarray()
    modes = list(ds["mode_structure"].values)
    # the union's modes: tube_a's block, then tube_b's
    assert modes == sorted(modes) and set(modes) == {"tube_a", "tube_b"}
    assert modes.count("tube_a") + modes.count("tube_b") == len(case.frequencies_hz)
    for point, structure in zip(ds["point"].values, ds["point_structure"].values):
        assert str(point).split(".")[0] == structure
    assert list(ds["contact_other_point"].values)[-1] == "tube_b.mid"


def test_a_key_path_reaches_into_a_structure(two_tubes):
    _, case, _ = two_tubes
    d = case.to_dict()
    mass = d["structures"][1]["structure"]
    changed = case.with_({"structures[1].contacts[0].friction.mu": 0.45})
    assert changed.to_dict()["structures"][1]["contacts"][0]["friction"]["mu"] == 0.45
    assert changed.to_dict()["structures"][0] == d["structures"][0]
    assert mass == changed.to_dict()["structures"][1]["structure"]

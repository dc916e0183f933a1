"""The notebook plots (fretdyn.plot) looked at: each is saved as a PNG that is read back
(non-empty, not blank), and its axes are checked against the run's arrays and summary: the
lines' data are the arrays, the labels carry the units of fretdyn.variables(), the bars are
the summary's statistics."""

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import fretdyn

mpl = pytest.importorskip("matplotlib")
mpl.use("Agg")
import matplotlib.container  # noqa: E402
import matplotlib.image  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402

from helpers import EXAMPLES, ROOT  # noqa: E402,F401


@pytest.fixture(scope="module")
def tube():
    """The multi-span tube for half a second: five holes, impacts on several of them."""
    text = (EXAMPLES / "tube_multispan.toml").read_text().replace("duration = 2.0", "duration = 0.5")
    return fretdyn.run(fretdyn.Case.from_toml(text, EXAMPLES))


@pytest.fixture(scope="module")
def v1a():
    return fretdyn.run(EXAMPLES / "v1a_oblique_impact.toml")


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close("all")


def units(name):
    return {v["key"]: v["units"] for v in fretdyn.variables()[0]}[name]


def looked_at(ax, path):
    """Saves the figure of `ax` as a PNG, reads it back and checks that it is an image with
    something drawn on it (many colours, not one background)."""
    ax.figure.savefig(path, dpi=80)
    assert path.stat().st_size > 5_000, path
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    image = matplotlib.image.imread(path)
    height, width = image.shape[:2]
    assert height > 200 and width > 300
    colours = np.unique(image[..., :3].reshape(-1, 3), axis=0)
    assert len(colours) > 50, len(colours)
    # not blank: a good share of the pixels are not the white background
    drawn = np.mean(np.any(image[..., :3] < 0.9, axis=-1))
    assert 0.01 < drawn < 0.9, drawn


def test_orbits_are_the_contact_positions_in_the_holes(tube, tmp_path):
    ax = fretdyn.plot.orbits(tube)
    looked_at(ax, tmp_path / "orbits.png")
    geometry = tube.summary["contact_geometry"]
    lines = ax.get_lines()
    # every contact of the tube is in a hole: an orbit and an outline each
    assert len(lines) == 2 * len(tube.contact_names) == 10
    for k, name in enumerate(tube.contact_names):
        orbit, outline = lines[2 * k], lines[2 * k + 1]
        assert orbit.get_label() == name
        assert np.array_equal(orbit.get_xydata(), tube.contact_position[:, k, :])
        assert np.array_equal(outline.get_xydata(), np.array(geometry[k]["outline"]))
        assert outline.get_color() == orbit.get_color() and outline.get_linestyle() == "--"
        # the outline is the clearance circle
        clearance = tube.case.to_dict()["contacts"][k]["obstacle"]["clearance"]
        assert np.allclose(np.hypot(*outline.get_xydata().T), clearance, rtol=1e-12)
    assert ax.get_xlabel() == f"e1, offset from the hole's centre ({units('contact_position')})"
    assert ax.get_ylabel().startswith("e2") and ax.get_ylabel().endswith("(m)")
    # the data limits hold every orbit and outline
    xy = np.vstack([line.get_xydata() for line in lines])
    assert np.allclose(ax.dataLim.min, xy.min(axis=0)) and np.allclose(ax.dataLim.max, xy.max(axis=0))
    assert [t.get_text() for t in ax.get_legend().get_texts()][:2] == ["plate1", "plate1: hole"]


def test_orbits_of_one_contact_on_given_axes(tube, v1a, tmp_path):
    fig, axes = plt.subplots(1, 2, figsize=(9, 4))
    ax = fretdyn.plot.orbits(tube, contact="plate3", ax=axes[0])
    assert ax is axes[0]
    assert len(ax.get_lines()) == 2
    assert np.array_equal(ax.get_lines()[0].get_xydata(), tube.contact_position[:, 2, :])
    assert fretdyn.plot.orbits(tube, contact=[0, "plate5"], ax=axes[1]) is axes[1]
    assert [line.get_label() for line in axes[1].get_lines()] == [
        "plate1", "plate1: hole", "plate5", "plate5: hole"]
    looked_at(axes[0], tmp_path / "two.png")
    # a plane: no outline, the plane's axes
    ax = fretdyn.plot.orbits(v1a)
    assert len(ax.get_lines()) == 1
    assert np.array_equal(ax.get_lines()[0].get_xydata(), v1a.contact_position[:, 0, :])
    assert ax.get_xlabel() == "e1, distance from the plane (m)"
    with pytest.raises(ValueError, match="plate9.*plate1"):
        fretdyn.plot.orbits(tube, contact="plate9")
    with pytest.raises(ValueError, match="no contact 5"):
        fretdyn.plot.orbits(tube, contact=5)


def test_forces_are_the_normal_and_tangential_forces_against_time(tube, tmp_path):
    ax = fretdyn.plot.forces(tube)
    looked_at(ax, tmp_path / "forces.png")
    lines = ax.get_lines()
    assert len(lines) == 2 * len(tube.contact_names)
    for k, name in enumerate(tube.contact_names):
        normal, tangential = lines[2 * k], lines[2 * k + 1]
        assert normal.get_label() == f"{name}: R_N" and tangential.get_label() == f"{name}: |R_T|"
        assert np.array_equal(normal.get_xdata(), tube.t)
        assert np.array_equal(normal.get_ydata(), tube.contact_normal_force[:, k])
        rt = tube.contact_tangential_force[:, k, :]
        assert np.allclose(tangential.get_ydata(), np.sqrt(rt[:, 0] ** 2 + rt[:, 1] ** 2),
                           rtol=1e-15, atol=0)
    assert ax.get_xlabel() == f"time ({units('t')})" == "time (s)"
    assert ax.get_ylabel() == f"contact force ({units('contact_normal_force')})" == "contact force (N)"
    assert ax.dataLim.x0 == tube.t[0] and ax.dataLim.x1 == tube.t[-1]
    assert ax.dataLim.y1 == tube.contact_normal_force.max()
    assert tube.contact_normal_force.max() > 0
    # Coulomb: |R_T| ≤ μ R_N at every sample (μ = 0.3)
    mu = tube.case.to_dict()["contacts"][0]["friction"]["mu"]
    for k in range(5):
        n = lines[2 * k].get_ydata()
        assert np.all(lines[2 * k + 1].get_ydata() <= mu * n * (1 + 1e-9) + 1e-12)
    one = fretdyn.plot.forces(tube, contact="plate2")
    assert len(one.get_lines()) == 2
    assert np.array_equal(one.get_lines()[0].get_ydata(), tube.contact_normal_force[:, 1])


def test_wear_is_a_bar_per_contact_with_its_error(tube, tmp_path):
    ax = fretdyn.plot.wear(tube)
    looked_at(ax, tmp_path / "wear.png")
    contacts = tube.summary["contacts"]
    (bars,) = [c for c in ax.containers if isinstance(c, mpl.container.BarContainer)]
    assert len(bars) == len(contacts) == len(ax.patches)
    assert [b.get_height() for b in bars] == [c["wear_work_rate"] for c in contacts]
    assert [t.get_text() for t in ax.get_xticklabels()] == tube.contact_names
    assert ax.get_ylabel().endswith("(W)") and "wear work rate" in ax.get_ylabel()
    # the error bars: ± the standard error of each contact
    (errorbar,) = bars.errorbar.lines[2]
    segments = errorbar.get_segments()
    for seg, c in zip(segments, contacts):
        low, high = seg[0][1], seg[1][1]
        assert high - low == pytest.approx(2 * c["wear_work_rate_se"], rel=1e-12)
        assert (low + high) / 2 == pytest.approx(c["wear_work_rate"], rel=1e-12)
    normal = fretdyn.plot.wear(tube, statistic="normal_wear_work_rate")
    assert [b.get_height() for b in normal.patches] == [c["normal_wear_work_rate"] for c in contacts]
    with pytest.raises(ValueError, match="statistic"):
        fretdyn.plot.wear(tube, statistic="impacts")


def test_energy_is_the_modal_energy_of_the_structure(v1a, tube, tmp_path):
    ax = fretdyn.plot.energy(tube)
    looked_at(ax, tmp_path / "energy.png")
    kinetic, strain, total = ax.get_lines()
    omega = 2 * np.pi * tube.case.frequencies_hz
    assert np.allclose(kinetic.get_ydata(), 0.5 * (tube.qdot ** 2).sum(axis=1), rtol=1e-14)
    assert np.allclose(strain.get_ydata(), 0.5 * ((omega * tube.q) ** 2).sum(axis=1), rtol=1e-14)
    assert np.allclose(total.get_ydata(), kinetic.get_ydata() + strain.get_ydata(), rtol=1e-15)
    assert np.array_equal(total.get_xdata(), tube.t)
    assert ax.get_ylabel().endswith("(J)") and ax.get_xlabel() == "time (s)"
    # V1a: a unit mass at 1 m/s, no strain energy; ½ m V² before and after the impact
    # (no normal damping; friction took the tangential part: it leaves with V cos α)
    ax = fretdyn.plot.energy(v1a)
    kinetic, strain, total = (line.get_ydata() for line in ax.get_lines())
    assert np.all(strain == 0)
    assert kinetic[0] == pytest.approx(0.5, rel=1e-12)
    assert kinetic[-1] == pytest.approx(0.5 * np.cos(np.radians(20.0)) ** 2, rel=1e-3)


def test_the_plots_say_to_install_matplotlib(tmp_path):
    shadow = tmp_path / "shadow" / "matplotlib"
    shadow.mkdir(parents=True)
    (shadow / "__init__.py").write_text("raise ImportError('No module named matplotlib')\n")
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(shadow.parent), env.get("PYTHONPATH", "")])
    script = (
        "import fretdyn\n"
        f"r = fretdyn.run({str(EXAMPLES / 'v1a_oblique_impact.toml')!r})\n"
        "fretdyn.plot.forces(r)\n"
    )
    p = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True, text=True,
                       timeout=120)
    assert p.returncode != 0
    assert "pip install matplotlib" in p.stderr, p.stderr

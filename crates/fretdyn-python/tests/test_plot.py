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
import matplotlib.colors  # noqa: E402
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


def fits(fig):
    """Every title (and the figure's suptitle) drawn inside the figure, and no two titles
    overlapping, by the renderer's extents."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    box = fig.bbox
    titles = [ax.title for ax in fig.axes if ax.get_title()]
    if fig._suptitle is not None:
        titles.append(fig._suptitle)
    extents = [t.get_window_extent(renderer) for t in titles]
    for t, e in zip(titles, extents):
        assert box.x0 <= e.x0 and e.x1 <= box.x1 and box.y0 <= e.y0 and e.y1 <= box.y1, (
            t.get_text(), e, box)
    for i in range(len(extents)):
        for j in range(i + 1, len(extents)):
            assert not extents[i].overlaps(extents[j]), (titles[i].get_text(), titles[j].get_text())


def legend_off_the_data(ax):
    """The legend of `ax` is outside its data area."""
    fig = ax.figure
    fig.canvas.draw()
    legend = ax.get_legend().get_window_extent(fig.canvas.get_renderer())
    assert not legend.overlaps(ax.get_window_extent(fig.canvas.get_renderer())) or \
        legend.x0 >= ax.bbox.x1, (legend, ax.bbox)


UM = "µm"


def test_orbits_are_the_contact_positions_in_the_holes(tube, tmp_path):
    # no contact given: the most worn hole alone, named in the title
    ax = fretdyn.plot.orbits(tube)
    looked_at(ax, tmp_path / "orbits.png")
    fits(ax.figure)
    rates = [c["wear_work_rate"] for c in tube.summary["contacts"]]
    k = int(np.argmax(rates))
    name = tube.contact_names[k]
    assert name in ax.get_title() and "largest wear work rate" in ax.get_title().replace("\n", " ")
    orbit, outline = ax.get_lines()
    assert orbit.get_label() == name
    assert np.array_equal(orbit.get_xydata(), tube.contact_position[:, k, :] * 1e6)
    geometry = tube.summary["contact_geometry"]
    assert np.array_equal(outline.get_xydata(), np.array(geometry[k]["outline"]) * 1e6)
    # the wall: dashed, dark grey, not the orbit's colour, labelled
    assert outline.get_linestyle() == "--" and outline.get_label() == "hole wall (clearance)"
    assert mpl.colors.to_rgb(outline.get_color()) != mpl.colors.to_rgb(orbit.get_color())
    assert max(mpl.colors.to_rgb(outline.get_color())) < 0.4
    # the outline is the clearance circle, µm
    clearance = tube.case.to_dict()["contacts"][k]["obstacle"]["clearance"]
    assert np.allclose(np.hypot(*outline.get_xydata().T), clearance * 1e6, rtol=1e-12)
    assert ax.get_xlabel() == f"e1, offset from the hole's centre ({UM})"
    assert ax.get_ylabel() == f"e2, offset from the hole's centre ({UM})"
    assert [t.get_text() for t in ax.get_legend().get_texts()] == [name, "hole wall (clearance)"]
    # the data limits hold the orbit and the outline
    xy = np.vstack([line.get_xydata() for line in ax.get_lines()])
    assert np.allclose(ax.dataLim.min, xy.min(axis=0)) and np.allclose(ax.dataLim.max, xy.max(axis=0))


def test_orbits_of_several_contacts_are_a_panel_each(tube, tmp_path):
    axes = fretdyn.plot.orbits(tube, contact=list(range(5)))
    assert len(axes) == 5 and len({a.figure for a in axes}) == 1
    looked_at(axes[0], tmp_path / "panels.png")
    fits(axes[0].figure)
    for k, ax in enumerate(axes):
        orbit, outline = ax.get_lines()
        assert orbit.get_label() == tube.contact_names[k]
        assert np.array_equal(orbit.get_xydata(), tube.contact_position[:, k, :] * 1e6)
        assert len(ax.get_legend().get_texts()) == 2


def test_orbits_of_one_contact_on_given_axes(tube, v1a, tmp_path):
    fig, axes = plt.subplots(1, 2, figsize=(11, 4), layout="constrained")
    ax = fretdyn.plot.orbits(tube, contact="plate3", ax=axes[0])
    assert ax is axes[0]
    assert len(ax.get_lines()) == 2
    assert np.array_equal(ax.get_lines()[0].get_xydata(), tube.contact_position[:, 2, :] * 1e6)
    assert fretdyn.plot.orbits(tube, contact=[0, "plate5"], ax=axes[1]) is axes[1]
    assert [line.get_label() for line in axes[1].get_lines()] == [
        "plate1", "plate1: hole wall", "plate5", "plate5: hole wall"]
    # overlaid on one Axes: the legend outside the data
    legend_off_the_data(axes[1])
    looked_at(axes[0], tmp_path / "two.png")
    fits(fig)
    # a plane: no outline, the plane's axes
    ax = fretdyn.plot.orbits(v1a)
    assert len(ax.get_lines()) == 1
    assert np.array_equal(ax.get_lines()[0].get_xydata(), v1a.contact_position[:, 0, :] * 1e6)
    assert ax.get_xlabel() == f"e1, distance from the plane ({UM})"
    with pytest.raises(ValueError, match="plate9.*plate1"):
        fretdyn.plot.orbits(tube, contact="plate9")
    with pytest.raises(ValueError, match="no contact 5"):
        fretdyn.plot.orbits(tube, contact=5)


def test_forces_are_the_normal_and_tangential_forces_against_time(tube, tmp_path):
    axes = fretdyn.plot.forces(tube, contact=tube.contact_names)
    assert len(axes) == len(tube.contact_names)
    looked_at(axes[0], tmp_path / "forces.png")
    fits(axes[0].figure)
    mu = tube.case.to_dict()["contacts"][0]["friction"]["mu"]
    for k, (ax, name) in enumerate(zip(axes, tube.contact_names)):
        normal, tangential = ax.get_lines()
        assert normal.get_label() == f"{name}: R_N" and tangential.get_label() == f"{name}: |R_T|"
        assert tangential.get_linestyle() == "--"
        assert np.array_equal(normal.get_xdata(), tube.t)
        assert np.array_equal(normal.get_ydata(), tube.contact_normal_force[:, k])
        rt = tube.contact_tangential_force[:, k, :]
        assert np.allclose(tangential.get_ydata(), np.sqrt(rt[:, 0] ** 2 + rt[:, 1] ** 2),
                           rtol=1e-15, atol=0)
        assert ax.get_xlabel() == f"time ({units('t')})" == "time (s)"
        assert ax.get_ylabel() == f"contact force ({units('contact_normal_force')})" == "contact force (N)"
        assert name in ax.get_title()
        # Coulomb: |R_T| ≤ μ R_N at every sample (μ = 0.3)
        n = normal.get_ydata()
        assert np.all(tangential.get_ydata() <= mu * n * (1 + 1e-9) + 1e-12)
    assert tube.contact_normal_force.max() == max(a.dataLim.y1 for a in axes) > 0
    one = fretdyn.plot.forces(tube, contact="plate2")
    assert len(one.get_lines()) == 2
    assert np.array_equal(one.get_lines()[0].get_ydata(), tube.contact_normal_force[:, 1])
    # no contact given: the most worn one, said in the title; two legend entries
    worst = fretdyn.plot.forces(tube)
    k = int(np.argmax([c["wear_work_rate"] for c in tube.summary["contacts"]]))
    assert np.array_equal(worst.get_lines()[0].get_ydata(), tube.contact_normal_force[:, k])
    assert len(worst.get_legend().get_texts()) == 2
    fits(worst.figure)


def test_wear_is_a_bar_per_contact_with_its_error(tube, tmp_path):
    ax = fretdyn.plot.wear(tube)
    looked_at(ax, tmp_path / "wear.png")
    contacts = tube.summary["contacts"]
    (bars,) = [c for c in ax.containers if isinstance(c, mpl.container.BarContainer)]
    assert len(bars) == len(contacts) == len(ax.patches)
    assert [b.get_height() for b in bars] == [c["wear_work_rate"] * 1e3 for c in contacts]
    assert [t.get_text() for t in ax.get_xticklabels()] == tube.contact_names
    assert ax.get_ylabel().endswith("(mW)") and "wear work rate" in ax.get_ylabel()
    fits(ax.figure)
    # the error bars: ± the standard error of each contact
    (errorbar,) = bars.errorbar.lines[2]
    segments = errorbar.get_segments()
    for seg, c in zip(segments, contacts):
        low, high = seg[0][1], seg[1][1]
        assert high - low == pytest.approx(2e3 * c["wear_work_rate_se"], rel=1e-12)
        assert (low + high) / 2 == pytest.approx(1e3 * c["wear_work_rate"], rel=1e-12)
    normal = fretdyn.plot.wear(tube, statistic="normal_wear_work_rate")
    assert [b.get_height() for b in normal.patches] == [c["normal_wear_work_rate"] * 1e3 for c in contacts]
    with pytest.raises(ValueError, match="statistic"):
        fretdyn.plot.wear(tube, statistic="impacts")


def test_energy_is_the_modal_energy_of_the_structure(v1a, tube, tmp_path):
    ax = fretdyn.plot.energy(tube)
    looked_at(ax, tmp_path / "energy.png")
    fits(ax.figure)
    assert "balance error" in ax.get_title().replace("\n", " ")
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


def test_a_long_title_is_wrapped_inside_the_figure(tmp_path):
    """The title of tube_fluid_elastic's length on V1a: every plot's title inside the
    figure (it was clipped on both sides)."""
    import re

    text = (EXAMPLES / "v1a_oblique_impact.toml").read_text()
    long = "A straight tube in a cross flow above its Connors critical velocity, fluid-elastic instability"
    text = re.sub(r'(?m)^title = .*$', f'title = "{long}"', text)
    r = fretdyn.run(fretdyn.Case.from_toml(text, EXAMPLES))
    assert r.case.title == long
    for draw in (fretdyn.plot.energy, fretdyn.plot.orbits, fretdyn.plot.forces, fretdyn.plot.wear):
        ax = draw(r)
        fits(ax.figure)
        assert ax.get_title().replace("\n", " ").startswith(long)
    # two plots side by side on the user's figure: titles apart
    fig, axes = plt.subplots(1, 2, figsize=(10, 4), layout="constrained")
    fretdyn.plot.energy(r, ax=axes[0])
    fretdyn.plot.forces(r, ax=axes[1])
    fits(fig)


@pytest.fixture(scope="module")
def life():
    """The multi-span tube's 40 years with 0.3 s windows (about 0.6 s)."""
    pytest.importorskip("pandas")
    text = (EXAMPLES / "tube_multispan_life.toml").read_text()
    text = text.replace("duration = 2.0", "duration = 0.3").replace("t_start = 0.2", "t_start = 0.1")
    return fretdyn.life(fretdyn.Case.from_toml(text, EXAMPLES))


def test_life_is_the_depth_against_service_time_with_its_error(life, tmp_path):
    ax = fretdyn.plot.life(life, fixed_gap=True)
    looked_at(ax, tmp_path / "life.png")
    fits(ax.figure)
    legend_off_the_data(ax)
    assert ax.get_xlabel() == "service time (years)" and ax.get_ylabel() == "tube wear depth (µm)"
    d = life.depths
    lines = [line for line in ax.get_lines() if line.get_label() in life.contact_names]
    assert [line.get_label() for line in lines] == life.contact_names
    for line, name in zip(lines, life.contact_names):
        rows = d[d["contact"] == name]
        assert np.array_equal(line.get_xdata(), rows["time_years"])
        assert np.array_equal(line.get_ydata(), rows["tube_depth"] * 1e6)
        (fixed,) = [x for x in ax.get_lines() if x.get_label() == f"{name}: fixed gap"]
        assert fixed.get_linestyle() == ":" and fixed.get_color() == line.get_color()
        assert np.array_equal(fixed.get_ydata(), rows["tube_depth_fixed_gap"] * 1e6)
    # the bands: ± the standard error around each depth
    bands = ax.collections
    assert len(bands) == len(life.contact_names)
    for band, name in zip(bands, life.contact_names):
        rows = d[d["contact"] == name]
        top = (rows["tube_depth"] + rows["tube_depth_se"]).to_numpy() * 1e6
        ys = band.get_paths()[0].vertices[:, 1]
        assert np.isclose(ys.max(), top.max(), rtol=1e-12)
    # 40 years of this tube stay far below the criterion (0.4 × 1.09 mm): a note says so
    assert life.criterion_depth == pytest.approx(436e-6)
    (note,) = ax.texts
    assert note.get_text() == "plugging criterion (436 µm): off the scale"
    texts = [t.get_text() for t in ax.get_legend().get_texts()]
    assert texts[0] == life.contact_names[0] and f"{life.contact_names[0]}: fixed gap" in texts


def test_life_draws_the_criterion_when_the_depths_come_near_it(life, tmp_path):
    # the criterion lowered to 2 µm: the depths reach it, a dash-dotted grey line
    life.criterion_depth = 2e-6
    try:
        ax = fretdyn.plot.life(life, contact="plate3")
    finally:
        life.criterion_depth = 436e-6
    looked_at(ax, tmp_path / "criterion.png")
    (criterion,) = [x for x in ax.get_lines() if x.get_label().startswith("plugging criterion")]
    assert criterion.get_label() == "plugging criterion (2 µm)"
    assert criterion.get_linestyle() == "-." and list(criterion.get_ydata()) == [2.0, 2.0]
    assert max(matplotlib.colors.to_rgb(criterion.get_color())) < 0.4
    assert [x.get_label() for x in ax.get_lines()][0] == "plate3"
    with pytest.raises(ValueError, match="no wearing contact 'plate9'"):
        fretdyn.plot.life(life, contact="plate9")


def test_modes_are_the_tube_shapes_with_its_supports(tmp_path):
    pytest.importorskip("pandas")
    m = fretdyn.modes(EXAMPLES / "tube_clamped_one_support.toml")
    axes = fretdyn.plot.modes(m, shown=3)
    assert len(axes) == 3
    looked_at(axes[0], tmp_path / "modes.png")
    fits(axes[0].figure)
    for i, ax in enumerate(axes):
        assert ax.get_title() == f"mode {i + 1} — {m.frequencies['frequency_hz'].iloc[i]:.3f} Hz"
        assert ax.get_xlabel() == "abscissa along the tube (m)"
        assert ax.get_ylabel() == "displacement (kg^-0.5)"
        rows = m.shapes[m.shapes["mode"] == i + 1]
        by_label = {x.get_label(): x for x in ax.get_lines()}
        for col in ("u_x", "u_y", "u_z"):
            assert np.array_equal(by_label[col].get_ydata(), rows[col])
        support = by_label["support"]
        assert support.get_marker() == "^" and support.get_linestyle() == "None"
        assert list(support.get_xdata()) == list(m.supports) == [0.0, 1.0]
    # one legend for the figure, every entry with its line or marker
    (legend,) = axes[0].figure.legends
    assert [t.get_text() for t in legend.get_texts()] == ["u_x", "u_y", "u_z", "support"]
    assert all(h.get_visible() for h in legend.legend_handles)
    # a modal basis without shapes: the frequencies
    ax = fretdyn.plot.modes(fretdyn.modes(EXAMPLES / "v1a_oblique_impact.toml"))
    assert ax.get_ylabel() == "frequency (Hz)"


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

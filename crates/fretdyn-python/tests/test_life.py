"""fretdyn.life and fretdyn.modes against the CLI's `fretdyn life` and `fretdyn modes` on the
same case files (the same numbers, bit for bit), against closed forms (a pinned–pinned tube's
frequencies and effective masses), and their errors (the CLI's messages, as FretdynError).

The life is the multi-span tube of examples/tube_multispan_life.toml with 0.3 s windows
(about 0.6 s for its 40 years on a 2-core machine)."""

import json
import re
import subprocess
import sys

import numpy as np
import pytest

import fretdyn

from helpers import EXAMPLES, FRETDYN, cli

pd = pytest.importorskip("pandas")


def short_life(folder, extra=""):
    """The multi-span tube's life with windows of 0.3 s (statistics from 0.1 s), written in
    `folder` as case.toml."""
    text = (EXAMPLES / "tube_multispan_life.toml").read_text()
    text = text.replace("duration = 2.0", "duration = 0.3").replace("t_start = 0.2", "t_start = 0.1")
    path = folder / "case.toml"
    path.write_text(text + extra)
    return path


def cli_csv(path):
    """A CSV of the CLI as float columns (empty cells NaN) and text columns."""
    return fretdyn.read_table(path)


def same(a, b):
    """The same floats, bit for bit (NaN where NaN)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return a.shape == b.shape and a.tobytes() == b.tobytes()


@pytest.fixture(scope="module")
def lives(tmp_path_factory):
    """The CLI's and Python's life of the same file, each with one halving."""
    folder = tmp_path_factory.mktemp("life")
    path = short_life(folder)
    out = cli(["life", "case.toml", "-o", "cli", "--no-plots", "--halvings", "1"], folder)
    assert out.returncode == 0, out.stderr
    r = fretdyn.life(path, halvings=1, output=folder / "py")
    return folder, r


def test_the_life_is_the_clis_bit_for_bit(lives):
    folder, r = lives
    table = cli_csv(folder / "cli" / "life.csv")
    assert list(r.table.columns) == list(table)
    for column in table:
        assert same(r.table[column], table[column]), column
    # the file Python writes reads back as the CLI's
    written = cli_csv(folder / "py" / "life.csv")
    for column in table:
        assert same(written[column], table[column]), column
    # life.json the same but the wall-clock time
    cli_json = json.loads((folder / "cli" / "life.json").read_text())
    py_json = json.loads((folder / "py" / "life.json").read_text())
    in_memory = r.to_json()
    for j in (cli_json, py_json, in_memory):
        j["results"].pop("wall_time")
    assert py_json == cli_json == in_memory
    assert r.end == {"status": "completed"} and r.contact_names == [f"plate{k}" for k in range(1, 6)]


def test_the_depths_are_tidy_and_the_summary_is_by_contact(lives):
    folder, r = lives
    table = cli_csv(folder / "cli" / "life.csv")
    d = r.depths
    assert d["step"].dtype == np.int64
    assert len(d) == len(table["time_years"]) * 5
    for name in r.contact_names:
        rows = d[d["contact"] == name]
        assert same(rows["time_years"], table["time_years"])
        assert same(rows["tube_depth"], table[f"{name}.tube_depth"])
        assert same(rows["wear_work_rate_se"], table[f"{name}.wear_work_rate_se"])
        # the depth's first-order error: 0 at the start; after the first step, the step's
        # depth scaled by the relative error of the rate that drove it
        se = rows["tube_depth_se"].to_numpy()
        assert se[0] == 0.0
        first = rows.iloc[1]
        assert se[1] == pytest.approx(
            first["tube_depth"] * first["wear_work_rate_se"] / first["wear_work_rate"], rel=1e-12)
        assert np.all(np.diff(se) >= 0)
    s = r.summary
    life = json.loads((folder / "cli" / "life.json").read_text())
    assert list(s.index) == r.contact_names and s.index.name == "contact"
    assert np.all(s["criterion_depth"] == life["criterion_depth"])
    assert life["criterion_depth"] == pytest.approx(0.4 * 1.09e-3)
    for k, name in enumerate(r.contact_names):
        assert s.loc[name, "tube_depth"] == table[f"{name}.tube_depth"][-1]
        t = life["results"]["time_to_criterion"][k]
        assert (np.isnan(s.loc[name, "years_to_criterion"]) if t is None
                else s.loc[name, "years_to_criterion"] == t / fretdyn._life.YEAR)
    assert r.table["time_years"].iloc[-1] == 40.0


def test_the_scars_and_the_convergence_are_the_clis(lives):
    folder, r = lives
    scars = cli_csv(folder / "cli" / "scars.csv")
    assert list(r.scars["contact"]) == scars["contact"]
    for column in ("bin", "angle_deg", "clearance_increase", "tube_depth"):
        assert same(r.scars[column], scars[column]), column
    conv = cli_csv(folder / "cli" / "convergence.csv")
    assert list(r.convergence.columns) == list(conv)
    assert list(r.convergence["life_end"]) == conv["life_end"] == ["completed"] * 2
    for column in conv:
        if column != "life_end":
            assert same(r.convergence[column], conv[column]), column
    m = fretdyn.Case.from_file(folder / "case.toml").to_dict()["life"]["max_depth_change"]
    assert list(r.convergence["max_depth_change"]) == [m, m / 2]


def test_years_and_max_depth_change_are_the_cases_life_settings(tmp_path):
    path = short_life(tmp_path)
    r = fretdyn.life(path, years=5.0, max_depth_change=0.1)
    text = path.read_text()
    for key, value in (("target_years", "5.0"), ("max_depth_change", "0.1")):
        text, n = re.subn(rf"^{key} = .*$", f"{key} = {value}", text, flags=re.M)
        assert n == 1, key
    (tmp_path / "edited.toml").write_text(text)
    out = cli(["life", "edited.toml", "-o", "cli", "--no-plots"], tmp_path)
    assert out.returncode == 0, out.stderr
    table = cli_csv(tmp_path / "cli" / "life.csv")
    for column in table:
        assert same(r.table[column], table[column]), column
    assert r.table["time_years"].iloc[-1] == 5.0


def test_the_life_as_an_xarray_dataset(lives):
    xr = pytest.importorskip("xarray")
    _, r = lives
    ds = r.to_xarray()
    assert isinstance(ds, xr.Dataset)
    assert list(ds.contact.values) == r.contact_names
    assert ds.tube_depth.attrs["units"] == "m" and ds.time.attrs["units"] == "year"
    for name in r.contact_names:
        rows = r.depths[r.depths["contact"] == name]
        assert same(ds.tube_depth.sel(contact=name), rows["tube_depth"])
        assert same(ds.tube_depth_se.sel(contact=name), rows["tube_depth_se"])


def test_bad_lives_are_the_clis_messages(tmp_path):
    path = short_life(tmp_path)

    def message(**kwargs):
        with pytest.raises(fretdyn.FretdynError) as e:
            fretdyn.life(kwargs.pop("case", path), **kwargs)
        return str(e.value)

    assert message(case=EXAMPLES / "v1a_oblique_impact.toml") == (
        "life: the case has no [life] section: add one with target_years (docs/WEAR.md)")
    assert message(max_depth_change=2.0).startswith(
        "life.max_depth_change: must be a fraction in (0, 1] (got 2)")
    assert message(years=-1.0) == "life.target_years: must be a service time > 0 in years"
    assert message(halvings=11).startswith("halvings: at most 10")
    assert message(checkpoint_every=0.0) == (
        "checkpoint_every: must be a positive number of seconds (got 0)")
    assert message(resume=True).startswith("resume: give the folder of the life to continue")
    assert "no checkpoint to resume" in message(output=tmp_path / "none", resume=True) or \
        "changed since the life" in message(output=tmp_path / "none", resume=True)
    unworn = path.read_text().replace("wear = {", "# wear = {")
    assert message(case=fretdyn.Case.from_toml(unworn, EXAMPLES)).startswith(
        "life: no contact has a wear law")
    # a life cut short: the CLI's words, the results so far with the error
    with pytest.raises(fretdyn.FretdynError, match=r"life: the target was not reached in "
                       r"max_steps = 1 life steps") as e:
        fretdyn.life(fretdyn.Case.from_toml(
            path.read_text().replace("[life]\n", "[life]\nmax_steps = 1\n"), EXAMPLES),
            max_depth_change=0.001)
    assert e.value.result.end == {"status": "step_limit"}
    assert len(e.value.result.table) == 2
    with pytest.raises(TypeError, match="fretdyn.life takes a Case"):
        fretdyn.life(3)


def test_a_finished_life_leaves_no_checkpoint_to_resume(lives):
    folder, _ = lives
    assert not (folder / "py" / "life_checkpoint.bin").exists()
    with pytest.raises(fretdyn.FretdynError, match="no checkpoint to resume: the life there is over"):
        fretdyn.life(folder / "case.toml", output=folder / "py", resume=True)
    # another case: refused as changed
    with pytest.raises(fretdyn.FretdynError, match="changed since the life in this folder started"):
        fretdyn.life(folder / "case.toml", years=3.0, output=folder / "py", resume=True)


def test_a_folder_another_program_writes_in_is_refused(tmp_path):
    """A life refuses a folder whose lock another process holds (as `fretdyn run`/`sweep`/
    `life` hold it while they write), and writes nothing there."""
    path = short_life(tmp_path)
    out = tmp_path / "busy"
    out.mkdir()
    holder = subprocess.Popen(
        [sys.executable, "-c",
         "import fcntl, sys, time\n"
         "f = open(sys.argv[1], 'a')\n"
         "fcntl.flock(f, fcntl.LOCK_EX)\n"
         "print('held', flush=True)\n"
         "time.sleep(60)\n",
         str(out / ".fretdyn.lock")],
        stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "held"
        with pytest.raises(fretdyn.FretdynError, match="is writing in this folder"):
            fretdyn.life(path, output=out)
        assert sorted(p.name for p in out.iterdir()) == [".fretdyn.lock"]
    finally:
        holder.kill()
        holder.wait()
    # once the holder is gone, the folder is free
    fretdyn.life(path, years=1.0, output=out)
    assert (out / "life.json").exists()


# a pinned–pinned tube without fluid, 1 m, fine mesh (its twist held at one end: no rigid
# torsion): Euler–Bernoulli closed forms
PINNED = """
title = "pinned tube"
[time]
dt = 1e-5
duration = 0.01
[structure]
type = "tube"
outer_diameter = 19.05e-3
wall_thickness = 1.09e-3
young_modulus = 2.0e11
poisson_ratio = 0.3
density = 8200.0
path = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]
mesh_size = 0.01
modes = 6
damping_ratio = 0.01
[[structure.supports]]
at = [0.0, 0.0, 0.0]
type = "dofs"
fixed = ["ux", "uy", "uz", "rx"]
[[structure.supports]]
at = [1.0, 0.0, 0.0]
type = "pinned"
[[structure.points]]
name = "middle"
at = [0.5, 0.0, 0.0]
"""


def test_the_modes_of_a_pinned_tube_are_the_closed_forms(tmp_path):
    case = fretdyn.Case.from_toml(PINNED)
    m = fretdyn.modes(case, output=tmp_path)
    f = m.frequencies
    assert f.index.name == "mode" and list(f.index) == list(range(1, 7))
    assert same(f["frequency_hz"], case.frequencies_hz)
    # bending in y and z, n = 1, 2, 3: f_n = n²π/(2L²) √(EI/m)
    d, t, E, rho, L = 19.05e-3, 1.09e-3, 2.0e11, 8200.0, 1.0
    di = d - 2 * t
    I = np.pi * (d**4 - di**4) / 64
    mass = rho * np.pi * (d**2 - di**2) / 4
    analytic = np.repeat([n**2 * np.pi / (2 * L**2) * np.sqrt(E * I / mass) for n in (1, 2, 3)], 2)
    assert np.allclose(f["frequency_hz"], analytic, rtol=1e-4)
    # effective masses: 8 mL/(n²π²) for odd n, 0 for even n; in y and z only
    gamma2 = f["effective_mass_y"] + f["effective_mass_z"]
    expected = np.repeat([8 * mass * L / np.pi**2, 0.0, 8 * mass * L / (9 * np.pi**2)], 2)
    assert np.allclose(gamma2, expected, rtol=1e-3, atol=1e-9 * mass)
    assert np.all(f["effective_mass_x"] < 1e-9 * mass)
    # the shapes: 0 at the pinned ends (the supports), the point's rows at its node
    assert list(m.supports) == [0.0, 1.0]
    s = m.shapes
    middle = s[np.isclose(s["s"], 0.5)]
    rows = m.points[m.points["point"] == "middle"]
    assert np.allclose(middle[["u_x", "u_y", "u_z"]].to_numpy(), rows[["x", "y", "z"]].to_numpy(),
                       rtol=1e-12, atol=1e-15)
    first = s[s["mode"] == 1]
    lateral = np.hypot(first["u_y"], first["u_z"]).to_numpy()
    assert lateral[0] == lateral[-1] == 0.0
    # mass-normalised: ∫ m φ² ds = 1 for the sine of the first mode
    assert np.max(lateral) == pytest.approx(np.sqrt(2 / (mass * L)), rel=1e-3)
    assert m.orthonormality_error < 1e-9


def test_the_modes_basis_file_is_the_clis(tmp_path):
    (tmp_path / "tube.toml").write_text(PINNED)
    out = cli(["modes", "tube.toml", "-o", "cli"], tmp_path)
    assert out.returncode == 0, out.stderr
    m = fretdyn.modes(tmp_path / "tube.toml", output=tmp_path / "py")
    a, b = np.load(tmp_path / "cli" / "basis.npz"), np.load(tmp_path / "py" / "basis.npz")
    assert sorted(a.files) == sorted(b.files)
    for k in a.files:
        assert a[k].tobytes() == b[k].tobytes(), k
    assert same(a["frequencies_hz"], m.frequencies["frequency_hz"])
    xr = pytest.importorskip("xarray")
    ds = m.to_xarray()
    assert isinstance(ds, xr.Dataset) and ds.frequency.attrs["units"] == "Hz"
    assert same(ds.rows.sel(point="middle"), a["rows_middle"])


def test_modes_of_a_modal_basis_have_no_tube_shapes():
    m = fretdyn.modes(EXAMPLES / "v1a_oblique_impact.toml")
    assert m.shapes is None and m.supports is None
    assert same(m.frequencies["frequency_hz"],
                fretdyn.Case.from_file(EXAMPLES / "v1a_oblique_impact.toml").frequencies_hz)


def stopped_life(path, out, by_cli=False):
    """A life of the case file `path` run by Python (or the CLI) into `out`, stopped by
    Ctrl-C (SIGINT) once its first checkpoint is written: it stops (KeyboardInterrupt) and
    leaves its checkpoint."""
    import signal
    import subprocess
    import sys
    import time

    script = "import sys, fretdyn\nfretdyn.life(sys.argv[1], output=sys.argv[2], checkpoint_every=0.001)\n"
    command = ([FRETDYN, "life", str(path), "-o", str(out), "--no-plots", "--checkpoint-every", "0.001"]
               if by_cli else [sys.executable, "-c", script, str(path), str(out)])
    # SIGINT as in a terminal: a test run in the background (`cmd &` in a script, as CI may
    # launch it) inherits SIGINT ignored, and Python then installs no KeyboardInterrupt handler
    child = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                             preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    checkpoint = out / "life_checkpoint.bin"
    deadline = time.time() + 120
    while not checkpoint.exists() and child.poll() is None and time.time() < deadline:
        time.sleep(0.02)
    assert checkpoint.exists(), "no checkpoint before the life ended"
    child.send_signal(signal.SIGINT)
    _, stderr = child.communicate(timeout=120)
    assert child.returncode != 0 and ("interrupted" if by_cli else "KeyboardInterrupt") in stderr, stderr
    assert checkpoint.exists()
    assert json.loads((out / "life.json").read_text())["results"]["end"]["status"] == "stopped"


def test_a_life_stopped_by_ctrl_c_resumes_to_the_depths_of_an_uninterrupted_one(tmp_path):
    """Stopped by Python and resumed by Python; stopped by Python and resumed by ``fretdyn
    life --resume`` (the folder records the case file); stopped by the CLI and resumed by
    Python (the same fingerprint of the inputs): each gives the depths of the life never
    stopped, bit for bit.
    Windows of 1.5 s, 10 years, so that the signal comes inside the life."""
    text = (EXAMPLES / "tube_multispan_life.toml").read_text()
    path = tmp_path / "case.toml"
    path.write_text(text.replace("duration = 2.0", "duration = 1.5").replace(
        "target_years = 40.0", "target_years = 10.0"))
    whole = fretdyn.life(path)
    assert whole.end == {"status": "completed"}
    stopped_life(path, tmp_path / "py")
    resumed = fretdyn.life(path, output=tmp_path / "py", resume=True)
    assert resumed.end == {"status": "completed"}
    for column in whole.table.columns:
        assert same(resumed.table[column], whole.table[column]), column
    assert not (tmp_path / "py" / "life_checkpoint.bin").exists()
    stopped_life(path, tmp_path / "cli")
    out = cli(["life", "--resume", "cli", "--no-plots"], tmp_path)
    assert out.returncode == 0, out.stderr
    table = cli_csv(tmp_path / "cli" / "life.csv")
    for column in table:
        assert same(whole.table[column], table[column]), column
    stopped_life(path, tmp_path / "from_cli", by_cli=True)
    resumed = fretdyn.life(path, output=tmp_path / "from_cli", resume=True)
    for column in whole.table.columns:
        assert same(resumed.table[column], whole.table[column]), column

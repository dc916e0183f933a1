"""The files fretdyn writes open in numpy in one call, and a basis written by numpy is read by
fretdyn. Run by .ci/run in a venv with numpy and pytest; FRETDYN is the binary's path."""

import csv
import json
import os
import subprocess
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
FRETDYN = os.environ.get("FRETDYN", str(ROOT / "target" / "release" / "fretdyn"))


def run(args, cwd):
    return subprocess.run([FRETDYN, *args], cwd=cwd, capture_output=True, text=True)


def test_results_open_in_numpy(tmp_path):
    p = run(["run", str(ROOT / "examples" / "v1c_sliding_impact.toml"), "-o", "out", "-q"], tmp_path)
    assert p.returncode == 0, p.stderr
    r = np.load(tmp_path / "out" / "results.npz")
    n = len(r["t"])
    assert r["q"].shape == (n, 3) and r["qdot"].shape == (n, 3)
    assert r["contact_normal_force"].shape == (n, 1)
    assert r["contact_tangential_force"].shape == (n, 1, 2)
    assert r["contact_slip_velocity"].shape == (n, 1, 2)
    assert r["contact_penetration"].shape == (n, 1)
    assert r["contact_status"].dtype == np.int8
    # V1c (THEORY §6): the mass leaves with V sin α − 2 μ V cos α along the plane
    v = r["qdot"][-1]  # a 1 kg point mass: modal velocity = physical velocity
    expected = np.sin(np.radians(60)) - 2 * 0.3 * np.cos(np.radians(60))
    assert abs(np.hypot(v[0], v[1]) - expected) < 1e-4
    s = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert s["contacts"][0]["name"] == "plane"
    assert s["termination"]["status"] == "completed"


def test_a_basis_written_by_numpy_is_read(tmp_path):
    # a 2 kg point mass as a general modal basis: three rigid modes, rows I/√m
    m = 2.0
    phi = np.eye(3) / np.sqrt(m)
    np.savez(
        tmp_path / "basis.npz",
        frequencies_hz=np.zeros(3),
        damping_ratio=np.zeros(3),
        rows_mass=phi,
        coords_mass=np.zeros(3),
        mass_matrix=m * np.eye(3),
        shapes=phi,
    )
    case = (ROOT / "examples" / "v1a_modal_inline.toml").read_text()
    i, j = case.index("[structure]"), case.index("[initial]")
    case = case[:i] + '[structure]\ntype = "modal"\nfile = "basis.npz"\n\n' + case[j:]
    (tmp_path / "case.toml").write_text(case)
    p = run(["run", "case.toml", "-o", "out", "-q"], tmp_path)
    assert p.returncode == 0, p.stderr
    assert "warning" not in p.stderr
    r = np.load(tmp_path / "out" / "results.npz")
    # peak normal force m v_n ω with ω = √(K_N/m)
    vn = np.cos(np.radians(20))
    assert abs(r["contact_normal_force"].max() - m * vn * np.sqrt(1e6 / m)) < 1e-3 * m * vn * np.sqrt(1e6 / m)


def test_a_badly_normalised_basis_is_refused(tmp_path):
    phi = np.eye(3)
    np.savez(
        tmp_path / "basis.npz",
        frequencies_hz=np.zeros(3),
        rows_mass=phi,
        mass_matrix=2.0 * np.eye(3),
        shapes=phi,
    )
    (tmp_path / "case.toml").write_text(
        '[time]\ndt = 1e-6\nduration = 1e-4\n[structure]\ntype = "modal"\nfile = "basis.npz"\n'
    )
    p = run(["run", "case.toml", "-o", "out"], tmp_path)
    assert p.returncode == 2
    assert "not mass-normalised" in p.stderr and len(p.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "out").exists()


def test_streamed_series_impacts_and_blocks_open_in_numpy(tmp_path):
    """The multi-span tube, 0.3 s: the orbit array, the per-impact table and the blocks open
    in numpy; the impacts and blocks agree with the summary."""
    case = (ROOT / "examples" / "tube_multispan.toml").read_text()
    case = case.replace("duration = 2.0", "duration = 0.3")
    case += "\n[statistics]\nblock = 0.1\nrest_duration = 5e-4\n"
    (tmp_path / "case.toml").write_text(case)
    p = run(["run", "case.toml", "-o", "out", "-q", "--no-plots"], tmp_path)
    assert p.returncode == 0, p.stderr
    out = tmp_path / "out"
    r = np.load(out / "results.npz")
    n = len(r["t"])
    pos = r["contact_position"]
    assert pos.shape == (n, 5, 2)
    # the tube centre stays within the clearance + penetration of each hole
    radius = np.hypot(pos[..., 0], pos[..., 1])
    assert np.allclose(radius - 2e-4, r["contact_penetration"], atol=1e-12)
    s = json.loads((out / "summary.json").read_text())
    imp = np.genfromtxt(out / "impacts.csv", delimiter=",", names=True, dtype=None, encoding=None)
    assert len(imp) > 10
    for k, c in enumerate(s["contacts"]):
        mine = imp[imp["contact"] == k]
        assert len(mine) == c["impacts"]
        assert np.all(mine["peak_force"] <= c["normal_force_max"] + 1e-12)
        assert sum(b["count"] for b in c["peak_force_histogram"]) == len(mine)
    blocks = np.genfromtxt(out / "blocks.csv", delimiter=",", names=True, dtype=None, encoding=None)
    assert len(blocks) == 3 * 5
    # the blocks' wear works add up to the window's
    for k, c in enumerate(s["contacts"]):
        mine = blocks[blocks["name"] == c["name"]]
        work = np.sum(mine["wear_work_rate"] * (mine["t_end"] - mine["t_start"]))
        assert abs(work - c["wear_work"]) <= 1e-9 * max(c["wear_work"], 1e-30)


def test_contacts_csv_opens_in_numpy_with_the_summary_numbers(tmp_path):
    """contacts.csv: one row per contact of the case, in order; every cell is summary.json's
    value (Python's float() and json read both exactly: equal floats are equal bits); a
    column empty for a contact is a value summary.json does not have for it."""
    for example in ("tube_three_span.toml", "tube_multispan_life.toml"):
        out = tmp_path / example
        p = run(["run", str(ROOT / "examples" / example), "-o", str(out), "-q", "--no-plots"], tmp_path)
        assert p.returncode == 0, p.stderr
        s = json.loads((out / "summary.json").read_text())
        with open(out / "contacts.csv", newline="") as f:
            rows = list(csv.DictReader(f))
        assert [r["name"] for r in rows] == [c["name"] for c in s["contacts"]]
        assert [r["contact"] for r in rows] == [str(k) for k in range(len(rows))]
        for row, c in zip(rows, s["contacts"]):
            for key, cell in row.items():
                if key == "contact":
                    continue
                value = c.get(key)
                if value is None:
                    assert cell == "", (key, cell)
                elif isinstance(value, bool):
                    assert cell == str(value).lower(), key
                elif isinstance(value, (int, float)):
                    assert float(cell) == value and type(value)(cell) == value, (key, cell, value)
                else:
                    assert cell == value, key
            # every statistic of the summary is a column (the histogram, a list, is not)
            assert {k for k, v in c.items() if not isinstance(v, list)} <= set(row), c.keys()
        # in one numpy call: numbers as floats and integers, names as strings
        a = np.genfromtxt(out / "contacts.csv", delimiter=",", names=True, dtype=None, encoding=None)
        assert a.shape == (len(s["contacts"]),)
        assert list(a["name"]) == [c["name"] for c in s["contacts"]]
        assert a["impacts"].dtype.kind == "i" and a["wear_work_rate"].dtype == np.float64
        assert np.array_equal(a["wear_work_rate"], [c["wear_work_rate"] for c in s["contacts"]])
        if example == "tube_multispan_life.toml":
            # contacts with wear laws: their volume rates
            assert np.all(a["tube_volume_rate"] > 0)
            assert np.array_equal(a["tube_volume_rate"], [c["tube_volume_rate"] for c in s["contacts"]])
    # the columns' units, meanings and Code_Aster names (quoted fields: the csv module)
    with open(out / "contacts_columns.csv", newline="") as f:
        columns = list(csv.DictReader(f))
    assert [c["column"] for c in columns] == list(rows[0])
    aster = {c["column"]: c["code_aster"] for c in columns}
    assert aster["normal_wear_work_rate"] == "PUIS_USURE (PUIS_USURE)"
    assert aster["impacts_per_second"] == "NB_CHOC_S (STAT_CHOC)"


def test_percentiles_of_one_sample_open_in_numpy_with_the_json_nulls(tmp_path):
    """A study of 1 sample: what one sample cannot give (the upper bounds, the bootstrap
    errors) is an empty cell of percentiles.csv, as in study.csv (it was NaN), read as NaN by
    numpy, at the places where percentiles.json has null."""
    (tmp_path / "case.toml").write_text((ROOT / "examples" / "v1a_oblique_impact.toml").read_text())
    (tmp_path / "study.toml").write_text(
        'base = "case.toml"\nsamples = 1\nseed = 4\n\n[[parameters]]\n'
        'key = "contacts.*.friction.mu"\n'
        'distribution = { type = "uniform", low = 0.1, high = 0.5 }\n'
    )
    p = run(["sweep", "study.toml", "-o", "out", "-q"], tmp_path)
    assert p.returncode == 0, p.stderr
    text = (tmp_path / "out" / "percentiles.csv").read_text()
    assert "nan" not in text.lower(), text
    # dtype=float: with dtype=None numpy guesses bool for a column of empty cells only
    table = np.genfromtxt(tmp_path / "out" / "percentiles.csv", delimiter=",", names=True,
                          dtype=float)
    rows = json.loads((tmp_path / "out" / "percentiles.json").read_text())["rows"]
    assert len(table) == len(rows) == 3  # P50, P95, P99 of the one contact
    for line, row in zip(table, rows):
        assert row["n"] == 1 and row["ci_high"] is None and row["bootstrap_se"] is None
        for k in ("estimate", "ci_low", "ci_high", "ci_coverage", "bootstrap_se"):
            assert np.isnan(line[k]) == (row[k] is None), (k, row)
            if row[k] is not None:
                assert line[k] == row[k], k

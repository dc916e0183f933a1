"""The Python API against the CLI's files and against the README: `Result` (arrays, summary,
impacts, blocks, contacts, `to_xarray`), `Case.with_`/`to_dict` against the same change made
in the TOML text, studies given as dicts against the same study file, and the API page in
the docs against the docstrings."""

import csv
import importlib.util
import json
import os
import re
import pickle
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import fretdyn

from helpers import EXAMPLES, FRETDYN, KEYS, ROOT, cli, same_bits  # noqa: E402,F401


def short_tube(tmp_path, duration="0.5"):
    """The multi-span tube, shortened (impacts on several plates in half a second)."""
    text = (EXAMPLES / "tube_multispan.toml").read_text()
    assert "duration = 2.0" in text
    path = tmp_path / "tube.toml"
    path.write_text(text.replace("duration = 2.0", f"duration = {duration}"))
    return path


@pytest.fixture(scope="module")
def tube_run(tmp_path_factory):
    """The short tube run by the CLI (its folder) and by the package (its Result)."""
    tmp = tmp_path_factory.mktemp("tube")
    path = short_tube(tmp)
    p = cli(["run", str(path), "-o", "out", "-q", "--no-plots"], tmp)
    assert p.returncode == 0, p.stderr
    return tmp / "out", fretdyn.run(path)


# --- Result ---------------------------------------------------------------------------------


def test_a_result_has_the_arrays_as_attributes_and_as_items(tube_run):
    out, r = tube_run
    npz = np.load(out / "results.npz")
    assert list(r) == KEYS + ["summary"] and len(r) == len(KEYS) + 1
    for k in KEYS:
        assert getattr(r, k) is r[k]
        assert same_bits(r[k], npz[k]), k
    summary = json.loads((out / "summary.json").read_text())
    assert r.summary is r["summary"]
    assert r.summary["contacts"] == summary["contacts"]
    assert r.contact_names == [c["name"] for c in summary["contacts"]]
    assert r.contact_names == r.case.contact_names
    assert "5 contacts" in repr(r) and "completed" in repr(r)


def test_the_statistics_columns_are_the_tables_columns(tube_run):
    # one table of statistics: the files' columns and the summary's keys are its keys
    out, r = tube_run
    table = fretdyn.statistics_columns()
    keys = [s["key"] for s in table]
    assert keys[:3] == ["duration", "impacts", "impacts_per_second"]
    assert {s["key"]: s["unit"] for s in table}["wear_work_rate"] == "W"
    with open(out / "contacts.csv", newline="") as f:
        header = next(csv.reader(f))
    assert header[2:2 + len(keys)] == keys
    errors = [s["se_key"] for s in table if s["se_key"]]
    assert errors and all(e in header for e in errors)
    assert all(s["se_key"] in (None, s["key"] + "_se") for s in table)
    with open(out / "blocks.csv", newline="") as f:
        blocks = next(csv.reader(f))
    assert blocks[4:] == [s["key"] for s in table if s["blocks"]]
    assert [s["key"] for s in table if s["count"]] == ["impacts"]
    for contact in r.summary["contacts"]:
        assert set(keys) <= set(contact)


def test_impacts_and_blocks_are_the_cli_tables(tube_run):
    pd = pytest.importorskip("pandas")
    out, r = tube_run
    for table, path in ((r.impacts, out / "impacts.csv"), (r.blocks, out / "blocks.csv")):
        assert isinstance(table, pd.DataFrame)
        expected = pd.read_csv(path)
        assert len(expected) > 5, path
        assert list(table.columns) == list(expected.columns), path
        for column in expected.columns:
            a, b = table[column].to_numpy(), expected[column].to_numpy()
            if a.dtype.kind == "f":
                # the CSV has the shortest repr that reads back exactly
                assert same_bits(a, b.astype(float)), (path.name, column)
            else:
                assert list(a) == list(b), (path.name, column)
    i = r.impacts
    k, start = i["contact"].to_numpy(), i["start"].to_numpy()
    assert all(r.contact_names[c] == n for c, n in zip(k, i["name"]))
    # every impact lies in the run; no peak above the contact's largest force (every step)
    assert np.all((start >= 0) & (start + i["duration"] <= r.t[-1] + r.case.dt))
    largest = np.array([c["normal_force_max"] for c in r.summary["contacts"]])
    assert np.all(i["peak_force"].to_numpy() <= largest[k])
    assert np.any(i["peak_force"].to_numpy() == largest[k])


def test_the_contacts_table_is_the_summary_flattened(tube_run, tmp_path):
    pd = pytest.importorskip("pandas")
    out, r = tube_run
    t = r.contacts
    assert isinstance(t, pd.DataFrame)
    assert list(t["name"]) == r.contact_names and t.columns[0] == "name"
    # indexed by the contact's name
    assert list(t.index) == r.contact_names and t.index.name == "contact"
    assert t.loc[r.contact_names[1], "wear_work_rate"] == r.summary["contacts"][1]["wear_work_rate"]
    for k, c in enumerate(r.summary["contacts"]):
        for key, value in c.items():
            if isinstance(value, (list, dict)):
                assert key not in t.columns
            elif isinstance(value, str):
                assert t[key].iloc[k] == value
            else:
                assert t[key].iloc[k] == value, key
    # with the CLI's contacts.csv (when it writes one): the same values in the same columns
    csv = out / "contacts.csv"
    if csv.exists():
        cli_table = pd.read_csv(csv)
        common = [c for c in t.columns if c in cli_table.columns]
        assert "wear_work_rate" in common
        for c in common:
            if t[c].dtype.kind == "f":
                assert np.array_equal(t[c].to_numpy(), cli_table[c].to_numpy(dtype=float),
                                      equal_nan=True), c


def test_without_pandas_the_tables_are_structured_arrays(tmp_path):
    shadow = tmp_path / "shadow" / "pandas"
    shadow.mkdir(parents=True)
    (shadow / "__init__.py").write_text("raise ImportError('No module named pandas')\n")
    script = tmp_path / "tables.py"
    script.write_text(
        "import json, sys, numpy as np, fretdyn\n"
        f"r = fretdyn.run({str(short_tube(tmp_path, '0.2'))!r})\n"
        "out = {}\n"
        "for name in ('impacts', 'blocks', 'contacts'):\n"
        "    t = getattr(r, name)\n"
        "    assert isinstance(t, np.ndarray), type(t)\n"
        "    out[name] = [list(t.dtype.names), len(t)]\n"
        "out['peak'] = r.impacts['peak_force'].tolist()\n"
        "out['names'] = r.contacts['name'].tolist()\n"
        "out['wear'] = r.contacts['wear_work_rate'].tolist()\n"
        "out['summary_wear'] = [c['wear_work_rate'] for c in r.summary['contacts']]\n"
        "print(json.dumps(out))\n"
    )
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(shadow.parent), env.get("PYTHONPATH", "")])
    p = subprocess.run([sys.executable, str(script)], env=env, capture_output=True, text=True,
                       timeout=120)
    assert p.returncode == 0, p.stderr
    out = json.loads(p.stdout)
    assert out["impacts"][0] == [
        "contact", "name", "start", "duration", "contact_time", "peak_time", "peak_force",
        "impulse", "impact_speed", "rebound_speed", "rebounds", "angle_deg",
    ]
    assert out["impacts"][1] == len(out["peak"]) > 0
    assert out["blocks"][0][:4] == ["block", "t_start", "t_end", "name"]
    assert out["contacts"][0][0] == "name" and out["contacts"][1] == 5
    assert out["names"] == [f"plate{k}" for k in range(1, 6)]
    assert out["wear"] == out["summary_wear"]


def readme_table():
    """The README's table of the arrays of results.npz and results.nc: key → (dimensions,
    units), from its columns "dimensions in `results.nc`" and "units"."""
    text = (ROOT / "README.md").read_text()
    table = text.split("`results.npz` (N samples")[1].split("\n\n")[1]
    lines = table.splitlines()
    header = [c.strip() for c in lines[0].strip("|").split("|")]
    assert header[:4] == ["key", "shape", "dimensions in `results.nc`", "units"], header
    out = {}
    for line in lines[2:]:
        cells = [c.strip() for c in line.strip("|").split("|")]
        keys = re.findall(r"`(\w+)`", cells[0])
        dims = tuple(re.findall(r"`(\w+)`", cells[2]))
        units = [u.strip() for u in cells[3].split(",")]
        if len(units) == 1:
            units = units * len(keys)
        for k, u in zip(keys, units):
            out[k] = (dims, u)
    return out


def test_to_xarray_has_the_names_dimensions_and_units_of_the_readme(tube_run):
    xr = pytest.importorskip("xarray")
    _, r = tube_run
    ds = r.to_xarray()
    assert isinstance(ds, xr.Dataset)
    points = [p["name"] for p in r.summary["case"]["structure"]["points"]]
    assert dict(ds.sizes) == {"time": len(r.t), "contact": 5, "mode": r.q.shape[1],
                              "tangent": 2, "local_axis": 2, "direction": 3,
                              "point": len(points)}
    assert list(ds.point.values) == points
    assert list(ds.contact.values) == r.contact_names
    assert list(ds.contact_point.values) == r.case.contact_points
    assert list(ds.contact_obstacle.values) == ["circle"] * 5
    at = {p["name"]: p["at"] for p in r.summary["case"]["structure"]["points"]}
    for name in points:
        assert np.array_equal(ds.point_position.sel(point=name).values, at[name]), name
    assert list(ds.tangent.values) == ["t1", "t2"]
    assert list(ds.local_axis.values) == ["e1", "e2"]
    assert list(ds.direction.values) == ["x", "y", "z"]
    assert ds.point_position.dims == ("point", "direction")
    assert same_bits(ds.time.values, r.t)
    assert np.array_equal(ds.mode.values, np.arange(1, r.q.shape[1] + 1))
    assert np.allclose(ds.frequency.values, r.case.frequencies_hz, rtol=0, atol=0)
    assert "frequency" in ds.coords and "point_position" in ds.coords
    for k in KEYS[1:]:
        assert same_bits(ds[k].values, r[k]), k
    # the dimensions and units are those of the README's table
    table = readme_table()
    assert list(table) == KEYS
    for k, (dims, units) in table.items():
        name = "time" if k == "t" else k
        assert ds[name].dims == dims, k
        assert ds[name].attrs["units"] == units, k
    for name in [*ds.data_vars, *ds.coords]:
        assert ds[name].attrs.get("long_name"), name
        # numbers have units, names have none
        assert ("units" in ds[name].attrs) == (ds[name].dtype.kind in "fiu"), name
    assert ds.contact_status.attrs["flag_meanings"] == "open stick slip"
    assert list(ds.contact_status.attrs["flag_values"]) == [0, 1, 2]
    # selecting by name gives the contact's column
    k = r.contact_names.index("plate3")
    assert same_bits(ds.contact_normal_force.sel(contact="plate3").values,
                     r.contact_normal_force[:, k])
    assert same_bits(ds.contact_slip_velocity.sel(contact="plate3", tangent="t2").values,
                     r.contact_slip_velocity[:, k, 1])
    assert json.loads(ds.attrs["summary"]) == r.summary
    assert ds.attrs["title"] == r.case.title


def test_to_xarray_is_the_dataset_of_the_cli_results_nc(tube_run, tmp_path):
    """to_xarray() and xarray.open_dataset("results.nc") of the same case are the same
    Dataset: variable by variable the same names, dimensions, coordinates, attributes
    (units, long_name, flag_*) and numbers (bit for bit, same dtype); the same global
    attributes but `case` (the case file's text, which a Case need not have) and `summary`
    (the same but for the wall time). And to_netcdf of it reads back as the same."""
    xr = pytest.importorskip("xarray")
    pytest.importorskip("netCDF4")
    out, r = tube_run
    ours = r.to_xarray()
    with xr.open_dataset(out / "results.nc") as theirs:
        theirs = theirs.load()
    assert set(ours.variables) == set(theirs.variables)
    assert set(ours.coords) == set(theirs.coords)
    assert set(ours.data_vars) == set(theirs.data_vars)
    for name in ours.variables:
        a, b = ours[name].variable, theirs[name].variable
        assert a.dims == b.dims, name
        assert a.attrs.keys() == b.attrs.keys(), name
        for key in ("units", "long_name", "flag_meanings"):
            assert a.attrs.get(key) == b.attrs.get(key), (name, key)
        assert a.dtype == b.dtype or a.dtype.kind == b.dtype.kind == "U", name
        if a.dtype.kind == "U":
            assert a.values.tolist() == b.values.tolist(), name
        else:
            assert same_bits(a.values, b.values), name
    # the whole Dataset, coordinates and attributes included
    without = ["case", "summary"]
    xr.testing.assert_identical(ours.drop_attrs(deep=False),
                                theirs.drop_attrs(deep=False))
    assert {k: v for k, v in ours.attrs.items() if k not in without} == {
        k: v for k, v in theirs.attrs.items() if k not in without}
    summary = {k: v for k, v in json.loads(theirs.attrs["summary"]).items()
               if k != "performance"}
    assert summary == {k: v for k, v in json.loads(ours.attrs["summary"]).items()
                       if k != "performance"}
    # to_netcdf writes what open_dataset reads back as the same Dataset
    ours.to_netcdf(tmp_path / "ours.nc")
    with xr.open_dataset(tmp_path / "ours.nc") as again:
        xr.testing.assert_identical(again.load(), ours)


def no_contact_case(tmp_path):
    """The clamped tube with its one contact taken out: zero-length contact arrays."""
    text = (EXAMPLES / "tube_clamped_one_support.toml").read_text()
    i, j = text.index("[[contacts]]"), text.index("[[loads]]")
    path = tmp_path / "no_contact.toml"
    path.write_text(text[:i] + text[j:])
    return path


@pytest.mark.parametrize(
    "case",
    [*sorted(p.name for p in EXAMPLES.glob("*.toml") if not p.name.startswith("study_")),
     "no contact"],
)
def test_to_xarray_is_open_dataset_of_results_nc_for_every_example(case, tmp_path):
    """For every example (and a case without contacts), `fretdyn run`'s results.nc opened by
    xarray and the package's to_xarray() are the same Dataset, attributes but `case` and
    `summary` included, with the numbers of results.npz."""
    xr = pytest.importorskip("xarray")
    pytest.importorskip("netCDF4")
    path = no_contact_case(tmp_path) if case == "no contact" else EXAMPLES / case
    p = cli(["run", str(path), "-o", "out", "-q", "--no-plots"], tmp_path)
    assert p.returncode == 0, p.stderr
    ours = fretdyn.run(path).to_xarray()
    with xr.open_dataset(tmp_path / "out" / "results.nc") as theirs:
        theirs = theirs.load()
    xr.testing.assert_identical(ours.drop_attrs(deep=False), theirs.drop_attrs(deep=False))
    assert {k: ours.attrs[k] for k in ("title", "fretdyn_version", "comment")} == {
        k: theirs.attrs[k] for k in ("title", "fretdyn_version", "comment")}
    npz = np.load(tmp_path / "out" / "results.npz")
    for v in fretdyn.variables()[0]:
        assert ours[v["name"]].dtype == theirs[v["name"]].dtype == npz[v["key"]].dtype
        assert same_bits(ours[v["name"]].values, npz[v["key"]]), (case, v["key"])


def test_the_variables_table_describes_every_array(tube_run):
    _, r = tube_run
    names, coords = fretdyn.variables()
    assert [v["key"] for v in names] == KEYS
    assert [v["name"] for v in names] == ["time", *KEYS[1:]]
    sizes = {"time": len(r.t), "contact": 5, "mode": r.q.shape[1], "tangent": 2,
             "local_axis": 2}
    for v in names:
        assert r[v["key"]].shape == tuple(sizes[d] for d in v["dims"]), v["key"]
    # every dimension has its coordinate
    assert {c["name"] for c in coords} >= set(sizes) - {"time"}
    units = {v["key"]: v["units"] for v in names}
    assert (units["q"], units["qdot"]) == ("kg^0.5 m", "kg^0.5 m s-1")
    # a model in physical coordinates: q in m
    physical = {v["key"]: v["units"] for v in fretdyn.variables(modal=False)[0]}
    assert (physical["q"], physical["qdot"]) == ("m", "m s-1")
    assert {k: u for k, u in physical.items() if k not in ("q", "qdot")} == {
        k: u for k, u in units.items() if k not in ("q", "qdot")}


# --- Case.with_ and Case.to_dict ------------------------------------------------------------


def test_with_equals_the_same_change_in_the_case_file():
    path = EXAMPLES / "v1a_oblique_impact.toml"
    text = path.read_text()
    case = fretdyn.Case.from_file(path)
    changed_text = (
        text.replace("gap = 0.0", "gap = 1e-5").replace("friction = { mu = 0.3 }",
                                                        "friction = { mu = 0.1 }")
        .replace("every = 1 ", "every = 10 ")
    )
    assert changed_text.count("1e-5") == 1 and "mu = 0.1" in changed_text
    assert "every = 10 " in changed_text
    expected = fretdyn.run(fretdyn.Case.from_toml(changed_text))
    forms = [
        case.with_({"contacts[0].obstacle.gap": 1e-5, "contacts[0].friction.mu": 0.1},
                   **{"output.every": 10}),
        case.with_(**{"contacts.0.obstacle.gap": 1e-5, "contacts.*.friction.mu": 0.1,
                      "output.every": np.int64(10)}),
        case.with_({"contacts[0].friction": {"mu": 0.1}, "contacts[0].obstacle.gap": 1e-5,
                    "output": {"every": 10}}),
    ]
    for changed in forms:
        r = fretdyn.run(changed)
        assert len(r.t) == 401
        for k in KEYS:
            assert same_bits(r[k], expected[k]), k
    # the case itself is unchanged
    assert case.to_dict()["contacts"][0]["obstacle"]["gap"] == 0.0
    assert fretdyn.run(case).t.shape == (4001,)


def test_with_adds_a_table_the_case_has_not():
    # v1a has no [statistics]: t_start added, the window starts later
    case = fretdyn.Case.from_file(EXAMPLES / "v1a_oblique_impact.toml")
    assert "statistics" not in case.to_dict()
    later = case.with_(**{"statistics.t_start": 3.5e-3})
    assert later.to_dict()["statistics"] == {"t_start": 3.5e-3}
    r0, r1 = fretdyn.run(case), fretdyn.run(later)
    # the impact (from 0 to half a period of the contact spring, π√(m/K) = 3.14 ms) is
    # before the later window
    assert r0.summary["contacts"][0]["impacts"] == 1
    assert r1.summary["contacts"][0]["impacts"] == 0
    assert same_bits(r0.q, r1.q)


def test_errors_of_with_name_the_key_path_exactly_as_given():
    # the key path as given first, then where it fails when that is a part of it
    case = fretdyn.Case.from_file(EXAMPLES / "v1a_oblique_impact.toml")
    cases = [
        ({"contacts[0].obstacle.clearance": 2e-4},
         "contacts[0].obstacle.clearance: unknown key (check its spelling): the keys of "
         "contacts[0].obstacle are origin, normal, gap, tangent"),
        ({"contacts[1].obstacle.gap": 1e-4},
         "contacts[1].obstacle.gap: contacts[1]: no such element; contacts has 1 element (index 0)"),
        ({"contacts.1": 1e-4}, "contacts.1: no such element; contacts has 1 element (index 0)"),
        ({"contacts.obstacle.gap": 1e-4},
         "contacts.obstacle.gap: contacts.obstacle: contacts is a list of 1: give an index (contacts[0])"),
        ({"time.dt.value": 1e-6}, "time.dt.value: time.dt is a value"),
        ({"time[0]": 1e-6}, "time[0]: time is a table, not a list: give one of its keys"),
        ({"tim.dt": 1e-6}, "tim.dt: tim: unknown key (check its spelling): the keys of the file are"),
        # a table the case has not, however deep the path below it (was named time.a.a)
        ({"time.a.a.a.a": 1.0},
         "time.a.a.a.a: time.a: unknown key (check its spelling): the keys of time are dt, duration"),
        ({"time.dt": "small"}, "time.dt: must be a number (a time step in s), got \"small\""),
        ({"contacts[0].normal.stiffness": -1.0}, "contacts[0].normal.stiffness: must be a positive"),
        ({"contacts.0.normal.stiffness": -1.0}, "contacts.0.normal.stiffness: must be a positive"),
        ({"contacts.*.normal.stiffness": -1.0},
         "contacts.*.normal.stiffness: contacts[0].normal.stiffness: must be a positive"),
        ({"time.dt": None}, "time.dt: None is not a value"),
        ({"contacts[0": 1.0}, "'contacts[0' is not a key path: a [ is not closed"),
        # of two changes, the one the error is at
        ({"time.dt": 1e-6, "contacts[0].friction.nu": 0.2},
         "contacts[0].friction.nu: unknown key (check its spelling)"),
        # a value set at a key path: the path of the value inside it
        ({"contacts[0].friction": {"mu": -1.0}}, "contacts[0].friction.mu: must be a friction"),
    ]
    for changes, message in cases:
        with pytest.raises(fretdyn.FretdynError) as e:
            case.with_(changes)
        assert str(e.value).startswith(message), (changes, str(e.value))
        assert "line " not in str(e.value), str(e.value)


def test_a_long_key_path_is_named_by_its_start_and_its_length():
    case = fretdyn.Case.from_file(EXAMPLES / "v1a_oblique_impact.toml")
    key = "time." + ".".join(["part"] * 60)  # 61 parts, 304 characters: legal
    with pytest.raises(fretdyn.FretdynError) as e:
        case.with_({key: 1.0})
    message = str(e.value)
    assert message.startswith(
        f"{key[:100]}… (a key path of {len(key)} characters, the first 100 shown): "
        "time.part: unknown key (check its spelling): the keys of time are dt, duration"), message
    # up to 200 characters, named whole
    key = "time.dt." + ".".join(["x"] * 60)  # 127 characters
    with pytest.raises(fretdyn.FretdynError) as e:
        case.with_({key: 1.0})
    assert str(e.value) == f"{key}: time.dt.x: time.dt is a value (0.000001), not a table or a list"


def test_a_key_path_deeper_than_64_parts_is_refused_at_once():
    # a path built by mistake (a loop appending to it): 10 000 parts took 24 GB and was killed
    case = fretdyn.Case.from_file(EXAMPLES / "v1a_oblique_impact.toml")
    tail = "a key path has at most 64 parts and this one has more: no key of a case is that deep"
    for key in [".".join(["a"] * 10_000), "time" + ".x" * 10_000, "contacts" + "[0]" * 64,
                ".".join(["a"] * 65)]:
        start = time.perf_counter()
        with pytest.raises(fretdyn.FretdynError) as e:
            case.with_({key: 1.0})
        assert time.perf_counter() - start < 1.0
        message = str(e.value)
        assert tail in message, message
        assert len(message) < 400 and message.startswith(key[:100]), message
        if len(key) > 200:
            assert f"(a key path of {len(key)} characters, the first 100 shown)" in message
    # at the bound the path is read, and the case's parser answers, at once: the time and
    # memory of a path are linear in its length
    for key in [".".join(["a"] * 64), "time" + ".x" * 63, "contacts" + "[0]" * 63]:
        start = time.perf_counter()
        with pytest.raises(fretdyn.FretdynError) as e:
            case.with_({key: 1.0})
        assert time.perf_counter() - start < 1.0
        assert tail not in str(e.value) and "recursion" not in str(e.value), str(e.value)
    # a study's parameter key: the same parser, the same bound
    study = {"base": case, "parameters": [{"key": ".".join(["a"] * 10_000), "values": [1.0]}]}
    with pytest.raises(fretdyn.FretdynError) as e:
        fretdyn.sweep(study)
    assert str(e.value).startswith("parameters[0].key: a.a.a") and tail in str(e.value), str(e.value)


def test_a_dict_nested_deeper_than_a_key_path_is_refused():
    # as deep as Python's recursion allowed: refused at part 65 with its key path (was a
    # RecursionError, JSON's "recursion limit exceeded at line 1 column 1535", or a TOML
    # "recursion limit exceeded" at a path cut at 80 parts)
    case = fretdyn.Case.from_file(EXAMPLES / "v1a_oblique_impact.toml")
    deep = case.to_dict()
    table = deep["time"]
    for _ in range(900):
        table["a"] = {}
        table = table["a"]
    looped = {}
    looped["a"] = looped
    tail = ": nested more than 64 keys and indices deep: no key of a case is that deep"
    for given, start in [(deep, "time" + ".a" * 64), (looped, ".".join(["a"] * 65))]:
        with pytest.raises(fretdyn.FretdynError) as e:
            fretdyn.Case.from_dict(given)
        assert str(e.value).startswith(start[:100]) and tail in str(e.value), str(e.value)
    # a value given to with_ below a key path: the whole path counts
    with pytest.raises(fretdyn.FretdynError) as e:
        case.with_({"time" + ".a" * 40: {"b": np.zeros((1,) * 30).tolist()}})
    assert tail in str(e.value), str(e.value)
    with pytest.raises(fretdyn.FretdynError) as e:
        case.with_({"initial.velocity": np.zeros((1,) * 64)})
    assert str(e.value).startswith(("initial.velocity" + "[0]" * 63)[:100]), str(e.value)
    assert tail in str(e.value), str(e.value)


def test_to_dict_round_trips_every_example():
    examples = [p for p in sorted(EXAMPLES.glob("*.toml")) if not p.name.startswith("study_")]
    assert len(examples) >= 10
    for path in examples:
        case = fretdyn.Case.from_file(path)
        d = case.to_dict()
        again = fretdyn.Case.from_dict(d)
        assert again.to_dict() == d, path.name
        assert again.title == case.title, path.name
        for attr in ("dt", "steps", "modes", "contact_names", "contact_points"):
            assert getattr(again, attr) == getattr(case, attr), (path.name, attr)
        assert same_bits(again.frequencies_hz, case.frequencies_hz), path.name
    # and runs the same, bit for bit
    case = fretdyn.Case.from_file(EXAMPLES / "v1c_sliding_impact.toml")
    a, b = fretdyn.run(case), fretdyn.run(fretdyn.Case.from_dict(case.to_dict()))
    for k in KEYS:
        assert same_bits(a[k], b[k]), k


def test_to_dict_makes_file_names_absolute(tmp_path, monkeypatch):
    """A case reading a .npz basis and a tabulated history next to it: its dict runs the same
    from another folder."""
    folder = tmp_path / "case"
    folder.mkdir()
    np.savez(folder / "basis.npz", frequencies_hz=np.array([0.0, 0.0, 0.0]),
             rows_mass=np.eye(3), coords_mass=np.zeros(3))
    (folder / "push.csv").write_text("t,value\n0.0,0.0\n1e-3,1.0\n4e-3,0.0\n")
    (folder / "case.toml").write_text(
        "[time]\ndt = 1e-6\nduration = 4e-3\n\n[structure]\ntype = \"modal\"\nfile = \"basis.npz\"\n\n"
        "[[loads]]\npoint = \"mass\"\nforce = [0.0, 0.0, -10.0]\n"
        "history = { type = \"table\", file = \"push.csv\" }\n\n"
        "[[contacts]]\nname = \"plane\"\npoint = \"mass\"\n"
        "obstacle = { type = \"plane\", origin = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0], gap = 1e-6 }\n"
        "normal = { stiffness = 1e6, damping = 0.0 }\nfriction = { mu = 0.3 }\n"
    )
    case = fretdyn.Case.from_file(folder / "case.toml")
    assert case.base_dir == folder
    d = case.to_dict()
    assert d["structure"]["file"] == str(folder / "basis.npz")
    assert d["loads"][0]["history"]["file"] == str(folder / "push.csv")
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    with pytest.raises(fretdyn.FretdynError, match="basis.npz"):
        # the relative names do not read from here
        fretdyn.Case.from_dict(json.loads(json.dumps(d).replace(str(folder) + os.sep, "")))
    a, b = fretdyn.run(case), fretdyn.run(fretdyn.Case.from_dict(d))
    assert a.summary["contacts"][0]["impacts"] >= 1
    for k in KEYS:
        assert same_bits(a[k], b[k]), k
    # a changed copy keeps reading them
    c = fretdyn.run(case.with_(**{"contacts[0].friction.mu": 0.3}))
    assert same_bits(c.q, a.q)


# --- studies given as dicts -----------------------------------------------------------------


STUDY = {
    "parameters": [
        {"key": "contacts.*.friction.mu", "values": [0.1, 0.3]},
        {"key": "tangential.method", "values": ["gauss_seidel", "active_set"]},
    ],
}


def table_rows(t):
    """The rows of a study's DataFrame, without the wall-clock column."""
    return t.drop(columns=["steps_per_second"]).astype(str).values.tolist()


def test_a_study_as_a_dict_equals_the_study_file(tmp_path):
    pd = pytest.importorskip("pandas")
    (tmp_path / "v1a.toml").write_text((EXAMPLES / "v1a_oblique_impact.toml").read_text())
    (tmp_path / "study.toml").write_text(
        'base = "v1a.toml"\n\n[[parameters]]\nkey = "contacts.*.friction.mu"\nvalues = [0.1, 0.3]\n\n'
        '[[parameters]]\nkey = "tangential.method"\nvalues = ["gauss_seidel", "active_set"]\n'
    )
    from_file = fretdyn.sweep(tmp_path / "study.toml", tmp_path / "file.csv")
    assert isinstance(from_file, pd.DataFrame)
    assert len(from_file) == 4 and from_file.attrs["runs_done"] == 4
    assert list(from_file["run"]) == [0, 1, 2, 3]
    # the indices are integers, the statistics floats; V1a draws nothing: no seed (NaN)
    assert from_file["run"].dtype == np.int64
    assert from_file["seed"].isna().all() and from_file["seed"].dtype == np.float64
    assert from_file["plane.wear_work_rate"].dtype == np.float64
    assert list(from_file.columns) == (tmp_path / "file.csv").read_text().splitlines()[0].split(",")
    case = fretdyn.Case.from_file(tmp_path / "v1a.toml")
    bases = [
        ("v1a.toml", dict(base_dir=tmp_path)),     # a path, relative to base_dir
        (case, {}),                                 # a Case
        (case.to_dict(), {}),                       # a case as a dict
    ]
    for base, kw in bases:
        t = fretdyn.sweep({**STUDY, "base": base}, jobs=2, **kw)
        assert table_rows(t) == table_rows(from_file), type(base)
    # the table is written where asked, and a second sweep does nothing
    t = fretdyn.sweep({**STUDY, "base": case}, tmp_path / "dict.csv")
    assert t.attrs["runs_done"] == 4 and (tmp_path / "dict.csv").exists()
    again = fretdyn.sweep({**STUDY, "base": case}, tmp_path / "dict.csv")
    assert again.attrs["runs_done"] == 0 and table_rows(again) == table_rows(from_file)
    # the statistic grows with the friction: the rows are those of their runs
    mu = from_file["contacts.*.friction.mu"].to_numpy()
    wear = from_file["plane.wear_work_rate"].to_numpy()
    assert np.all(wear[mu == 0.3] != wear[mu == 0.1])


def test_a_dict_study_on_a_dask_cluster_equals_the_local_one(tmp_path):
    """The workers get the study as (JSON, folder) and build it again."""
    pytest.importorskip("pandas")
    distributed = pytest.importorskip("dask.distributed")
    study = {**STUDY, "base": fretdyn.Case.from_file(EXAMPLES / "v1a_oblique_impact.toml")}
    local = fretdyn.sweep(study, tmp_path / "local.csv")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        remote = fretdyn.sweep(study, tmp_path / "dask.csv", client=client)
    assert remote.attrs["runs_done"] == 4
    assert table_rows(remote) == table_rows(local)


def test_a_probabilistic_dict_study_gives_its_percentiles(tmp_path):
    pd = pytest.importorskip("pandas")
    case = fretdyn.Case.from_file(EXAMPLES / "v1a_oblique_impact.toml")
    study = {
        "base": case, "samples": 5, "seed": 2,
        "parameters": [{"key": "contacts[0].friction.mu",
                        "distribution": {"type": "uniform", "low": 0.1, "high": 0.5}}],
        "percentiles": {"statistics": ["wear_work_rate"], "levels": [50]},
    }
    t = fretdyn.sweep(study, tmp_path / "p.csv")
    mu = t["contacts[0].friction.mu"].to_numpy()
    assert len(t) == 5 and np.all((mu >= 0.1) & (mu < 0.5)) and len(set(mu)) == 5
    p = fretdyn.percentiles(study, tmp_path / "p.csv")
    # a DataFrame, as sweep's; its report's settings in attrs
    assert isinstance(p, pd.DataFrame) and p.attrs["seed"] == 2
    (estimate,) = p.loc[p["column"] == "plane.wear_work_rate", "estimate"]
    assert estimate == pytest.approx(np.percentile(t["plane.wear_work_rate"], 50), rel=1e-12)
    assert p["level"].dtype == np.int64 and p["n"].dtype == np.int64 and list(p["n"]) == [5]


def test_the_groups_of_percentiles_are_numbers(tmp_path):
    """A grid parameter (μ) beside a drawn one: the percentiles are per μ, and μ comes back
    as a float column (it came back as the strings '0.1', '0.3')."""
    pd = pytest.importorskip("pandas")
    case = fretdyn.Case.from_file(EXAMPLES / "v1a_oblique_impact.toml")
    study = {
        "base": case, "samples": 3, "seed": 4,
        "parameters": [
            {"key": "contacts[0].friction.mu", "values": [0.1, 0.3]},
            {"key": "contacts[0].obstacle.gap", "distribution":
             {"type": "uniform", "low": 0.0, "high": 1e-6}},
        ],
        "percentiles": {"statistics": ["wear_work_rate"], "levels": [50]},
    }
    t = fretdyn.sweep(study, tmp_path / "study.csv")
    p = fretdyn.percentiles(study, tmp_path / "study.csv", output=tmp_path)
    assert isinstance(p, pd.DataFrame)
    mu = "contacts[0].friction.mu"
    assert p[mu].dtype == np.float64 and list(p[mu]) == [0.1, 0.3]
    assert p[mu].dtype == t[mu].dtype
    for value, estimate in zip(p[mu], p["estimate"]):
        runs = t.loc[t[mu] == value, "plane.wear_work_rate"]
        assert len(runs) == 3
        assert estimate == pytest.approx(np.percentile(runs, 50), rel=1e-12)
    # the same table as percentiles.csv
    written = fretdyn.read_table(tmp_path / "percentiles.csv")
    assert list(written) == list(p.columns)
    for k in written:
        if isinstance(written[k], list):
            assert written[k] == list(p[k]), k
        else:
            assert np.array_equal(written[k], p[k].to_numpy(), equal_nan=True), k
            assert written[k].dtype == p[k].dtype, k


def test_what_one_sample_cannot_give_is_an_empty_cell_and_null(tmp_path):
    # one sample: no interval, no bootstrap error. percentiles.csv wrote NaN where
    # percentiles.json has null; the study table's convention is an empty cell
    case = fretdyn.Case.from_file(EXAMPLES / "v1a_oblique_impact.toml")
    study = {
        "base": case, "samples": 1, "seed": 2,
        "parameters": [{"key": "contacts[0].friction.mu",
                        "distribution": {"type": "uniform", "low": 0.1, "high": 0.5}}],
        "percentiles": {"statistics": ["wear_work_rate"]},
    }
    fretdyn.sweep(study, tmp_path / "study.csv")
    p = fretdyn.percentiles(study, tmp_path / "study.csv", output=tmp_path)
    text = (tmp_path / "percentiles.csv").read_text()
    assert "nan" not in text.lower(), text
    report = json.loads((tmp_path / "percentiles.json").read_text())
    table = fretdyn.read_table(tmp_path / "percentiles.csv")
    numbers = ["estimate", "ci_low", "ci_high", "ci_coverage", "bootstrap_se"]
    assert [r["level"] for r in report["rows"]] == [50, 95, 99] == list(p["level"])
    for i, row in enumerate(report["rows"]):
        assert row["n"] == 1 and row["ci_high"] is None and row["bootstrap_se"] is None
        for k in numbers:
            # NaN read back exactly where the JSON has null, in the file and the DataFrame
            assert np.isnan(table[k][i]) == (row[k] is None), (k, row)
            assert np.isnan(p[k].iloc[i]) == (row[k] is None), (k, row)
            if row[k] is not None:
                assert table[k][i] == row[k] == p[k].iloc[i]
    pd = pytest.importorskip("pandas")
    frame = pd.read_csv(tmp_path / "percentiles.csv")
    assert frame["bootstrap_se"].isna().all() and frame["estimate"].notna().all()


def test_errors_of_a_dict_study_name_the_key():
    case = fretdyn.Case.from_file(EXAMPLES / "v1a_oblique_impact.toml")
    cases = [
        ({"base": case, "parameters": [{"key": "contacts[0].obstacl.gap", "values": [0.0]}]},
         "parameters[0].key: contacts[0].obstacl: no such key; contacts[0] has friction, name, normal, obstacle, point"),
        ({"base": case, "parameters": [{"key": "time.dt", "valeus": [1e-6]}]},
         "parameters[0].valeus: unknown key (check its spelling): the keys of parameters[0] are"),
        ({"base": case, "parameters": [{"key": "time.dt", "values": ["small"]}]},
         "run 0 (time.dt = \"small\"): parameters[0].values: time.dt = \"small\" does not fit the case"),
        ({"base": {**case.to_dict(), "time": {"dt": "small", "duration": 1e-3}},
          "parameters": [{"key": "time.dt", "values": [1e-6]}]},
         "base.time.dt: must be a number (a time step in s), got \"small\""),
        ({"parameters": [{"key": "time.dt", "values": [1e-6]}]}, "base: missing"),
        ({"base": "nothere.toml", "parameters": []}, "nothere.toml: "),
    ]
    for study, message in cases:
        with pytest.raises(fretdyn.FretdynError) as e:
            fretdyn.sweep(study)
        assert message in str(e.value), (message, str(e.value))
        assert "line " not in str(e.value), str(e.value)


# --- the API page ---------------------------------------------------------------------------


def api_doc():
    spec = importlib.util.spec_from_file_location("python_api_doc", ROOT / "scripts" / "python_api_doc.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_api_page_is_generated_from_the_docstrings():
    doc = api_doc()
    page = (ROOT / "docs" / "PYTHON_API.md").read_text(encoding="utf-8")
    assert page == doc.render(), (
        "docs/PYTHON_API.md is not the page of the docstrings: run python scripts/python_api_doc.py"
    )


def test_everything_public_has_a_numpy_style_docstring():
    doc = api_doc()
    assert doc.undocumented() == []


# --- the namespace ----------------------------------------------------------------------------


def test_the_namespace_is_the_api():
    # dir() lists the API, not what the package imports for itself
    names = dir(fretdyn)
    for own in ["Any", "List", "np", "os", "csv", "json", "tempfile", "Path"]:
        assert own not in names, own
    assert set(fretdyn.__all__) <= set(names) and {"med", "plot"} <= set(names)
    # the error is fretdyn's, and survives pickling (a Dask worker sends it back so)
    assert fretdyn.FretdynError.__module__ == "fretdyn"
    e = pickle.loads(pickle.dumps(fretdyn.FretdynError("time.dt: must be > 0")))
    assert isinstance(e, fretdyn.FretdynError) and str(e) == "time.dt: must be > 0"

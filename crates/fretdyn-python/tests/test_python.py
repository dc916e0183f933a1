"""The Python package against the CLI and against itself: the same arrays bit for bit, errors
as exceptions with the CLI's messages, cases from dicts and numpy arrays, and a study run on a
Dask cluster of 2 worker processes equal to the same study run locally. Run by .ci/run in a
venv where the package is installed (pip install ./crates/fretdyn-python)."""

import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

import fretdyn

from helpers import EXAMPLES, FRETDYN, KEYS, ROOT, cli, same_bits  # noqa: E402,F401


def test_v1a_from_python_equals_the_cli_bit_for_bit(tmp_path):
    case = EXAMPLES / "v1a_oblique_impact.toml"
    p = cli(["run", str(case), "-o", "out", "-q", "--no-plots"], tmp_path)
    assert p.returncode == 0, p.stderr
    npz = np.load(tmp_path / "out" / "results.npz")
    r = fretdyn.run(fretdyn.Case.from_file(case))
    for k in KEYS:
        assert same_bits(r[k], npz[k]), k
    assert r["summary"]["contacts"][0]["name"] == "plane"
    assert r["summary"]["termination"]["status"] == "completed"


def test_a_missing_file_is_named_once(tmp_path):
    with pytest.raises(fretdyn.FretdynError) as e:
        fretdyn.Case.from_file(tmp_path / "nothere.toml")
    assert str(e.value).count("nothere.toml") == 1, str(e.value)


def test_errors_are_exceptions_with_the_cli_message(tmp_path):
    # above the stable limit (2e-3 s) but shorter than the run: refused when the run starts
    text = (EXAMPLES / "v1a_oblique_impact.toml").read_text().replace("dt = 1e-6", "dt = 3e-3")
    (tmp_path / "bad.toml").write_text(text)
    p = cli(["run", "bad.toml", "-o", "out", "-q"], tmp_path)
    assert p.returncode == 2
    with pytest.raises(fretdyn.FretdynError) as e:
        c = fretdyn.Case.from_file(tmp_path / "bad.toml")
        fretdyn.run(c)
    # the CLI prefixes the file name; the message is the same
    assert p.stderr.strip() == f"error: bad.toml: {e.value}"
    assert "time.dt" in str(e.value) and "stable limit" in str(e.value)
    with pytest.raises(fretdyn.FretdynError, match="contacts.0.friction.mu|friction"):
        fretdyn.Case.from_toml(text.replace("friction = { mu = 0.3 }", "friction = { mu = -1 }"))
    with pytest.raises(fretdyn.FretdynError):
        fretdyn.modal_structure([1.0, 2.0], {"a": np.zeros((3, 3))})


def test_a_run_too_large_for_the_memory_is_refused_not_an_abort():
    # 1e10 steps of V1a, every step kept: 1.2 TB of time histories, which would abort the
    # interpreter when allocated
    text = (EXAMPLES / "v1a_oblique_impact.toml").read_text()
    c = fretdyn.Case.from_toml(text.replace("duration = 4e-3", "duration = 1e4"))
    assert c.steps == 10_000_000_000
    with pytest.raises(fretdyn.FretdynError, match="output.every") as e:
        fretdyn.run(c)
    assert "TB" in str(e.value) and "fretdyn run" in str(e.value)
    # and the interpreter is still there to run a case
    assert fretdyn.run(fretdyn.Case.from_toml(text))["t"].shape == (4001,)


def v1a_dict():
    """V1a (examples/v1a_modal_inline.toml) as a dict with numpy arrays."""
    a = np.radians(20.0)
    return {
        "title": "V1a from Python",
        "time": {"dt": 1e-6, "duration": 4e-3},
        "structure": fretdyn.modal_structure(
            np.zeros(3), {"mass": np.eye(3)}, coords={"mass": np.zeros(3)}
        ),
        "initial": {"point": "mass", "velocity": [np.sin(a), 0.0, -np.cos(a)]},
        "contacts": [{
            "name": "plane", "point": "mass",
            "obstacle": {"type": "plane", "origin": [0.0, 0.0, 0.0], "normal": [0.0, 0.0, 1.0],
                         "gap": 0.0, "tangent": [1.0, 0.0, 0.0]},
            "normal": {"stiffness": 1e6, "damping": 0.0},
            "friction": {"mu": 0.3},
        }],
        "tangential": {"method": "gauss_seidel"},
    }


def test_a_case_from_a_dict_and_numpy_arrays_equals_the_file():
    file = fretdyn.Case.from_file(EXAMPLES / "v1a_modal_inline.toml")
    r1, r2 = fretdyn.run(file), fretdyn.run(fretdyn.Case.from_dict(v1a_dict()))
    for k in KEYS:
        assert np.allclose(r1[k], r2[k], rtol=1e-12, atol=1e-15), k


def test_errors_of_a_dict_name_its_key_path():
    def error(change):
        case = v1a_dict()
        change(case)
        with pytest.raises(fretdyn.FretdynError) as e:
            fretdyn.Case.from_dict(case)
        message = str(e.value)
        # a position in the TOML text the dict was written to means nothing to the user
        assert "line" not in message and "column" not in message, message
        return message

    contact = lambda c: c["contacts"][0]
    cases = [
        # (what is broken, the key path the message must start with)
        (lambda c: c["time"].update(dt="1e-6"), "time.dt: "),
        (lambda c: contact(c)["normal"].update(stiffness="stiff"), "contacts[0].normal.stiffness: "),
        (lambda c: contact(c)["normal"].update(stiffnes=1e6), "contacts[0].normal.stiffnes: "),
        (lambda c: contact(c)["normal"].pop("stiffness"), "contacts[0].normal.stiffness: "),
        (lambda c: c["time"].pop("duration"), "time.duration: "),
        (lambda c: c.update(tangential={"method": "coulomb"}), "tangential.method: "),
        # a tagged table (the obstacle) is read whole: still the key
        (lambda c: contact(c)["obstacle"].update(gap="none"), "contacts[0].obstacle.gap: "),
        (lambda c: c.update(title=None), "title: "),
        # after parsing: the validation's own message, unchanged
        (lambda c: contact(c)["normal"].update(stiffness=-1.0), "contacts[0].normal.stiffness: "),
    ]
    for change, path in cases:
        message = error(change)
        assert message.startswith(path), (path, message)
    # the second contact of two
    def second(c):
        c["contacts"].append(dict(contact(c), name="other", normal={"stiffness": "x", "damping": 0.0}))

    assert error(second).startswith("contacts[1].normal.stiffness: ")


def test_nan_and_infinities_in_a_dict_are_named_by_their_key_path():
    # JSON has no NaN: the message was JSON's ("the case is not valid JSON: expected value at
    # line 1 column 35"), the position of a text the user never saw
    def error(call):
        with pytest.raises(fretdyn.FretdynError) as e:
            call()
        message = str(e.value)
        assert "JSON" not in message and "line" not in message and "column" not in message
        return message

    contact = lambda c: c["contacts"][0]
    for x, shown in [(float("nan"), "NaN"), (float("inf"), "inf"), (-np.inf, "-inf")]:
        tail = f": {shown} is not a valid value: give a finite number"
        cases = [
            (lambda c: contact(c)["friction"].update(mu=x), "contacts[0].friction.mu"),
            (lambda c: c["time"].update(dt=np.float64(x)), "time.dt"),
            (lambda c: c["initial"].update(velocity=np.array([0.0, x, 0.0])), "initial.velocity[1]"),
            (lambda c: c["initial"].update(velocity=[0.0, 0.0, np.float32(x)]), "initial.velocity[2]"),
        ]
        for change, path in cases:
            case = v1a_dict()
            change(case)
            assert error(lambda: fretdyn.Case.from_dict(case)) == path + tail
        case = fretdyn.Case.from_dict(v1a_dict())
        # with_, at the key path or inside the value given there
        assert error(lambda: case.with_({"contacts[0].friction.mu": x})) == "contacts[0].friction.mu" + tail
        assert error(lambda: case.with_({"contacts[0].friction": {"mu": x}})) == "contacts[0].friction.mu" + tail
        assert error(lambda: case.with_(**{"initial.velocity": np.array([[0.0, x]])})) == "initial.velocity[0][1]" + tail
        # a study's values, and its base case
        study = {"base": case, "parameters": [{"key": "time.dt", "values": [1e-6, x]}]}
        assert error(lambda: fretdyn.sweep(study)) == "parameters[0].values[1]" + tail
        base = v1a_dict()
        contact(base)["friction"]["mu"] = x
        study = {"base": base, "parameters": [{"key": "time.dt", "values": [1e-6]}]}
        assert error(lambda: fretdyn.sweep(study)) == "base.contacts[0].friction.mu" + tail
        # the arrays of a modal basis
        assert error(lambda: fretdyn.modal_structure([1.0, x], {"A": np.ones((3, 2))})) == (
            "structure.frequencies_hz[1]" + tail)
        assert error(lambda: fretdyn.modal_structure([1.0], {"A": [[1.0], [x], [0.0]]})) == (
            "structure.points.A.rows[1][0]" + tail)


def test_run_takes_the_path_of_a_case_file(tmp_path):
    path = EXAMPLES / "v1a_oblique_impact.toml"
    reference = fretdyn.run(fretdyn.Case.from_file(path))
    for given in (str(path), path):
        r = fretdyn.run(given)
        for k in KEYS:
            assert same_bits(r[k], reference[k]), (type(given), k)
    with pytest.raises(fretdyn.FretdynError, match="missing.toml"):
        fretdyn.run(tmp_path / "missing.toml")
    for wrong in (42, {"time": {}}, None):
        with pytest.raises(TypeError, match="Case.from_dict.*path of a case file"):
            fretdyn.run(wrong)
    with pytest.raises(TypeError, match="Case.from_toml"):
        fretdyn.run(path.read_text())


def test_gap_study_checks_for_matplotlib_before_the_sweep(tmp_path):
    import sys

    # a matplotlib that cannot be imported, whether or not this Python has one
    shadow = tmp_path / "shadow" / "matplotlib"
    shadow.mkdir(parents=True)
    (shadow / "__init__.py").write_text("raise ImportError('No module named matplotlib')\n")
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(shadow.parent), env.get("PYTHONPATH", "")])
    work = tmp_path / "work"
    work.mkdir()
    p = subprocess.run(
        [sys.executable, str(ROOT / "examples" / "python" / "gap_study.py")],
        cwd=work, env=env, capture_output=True, text=True, timeout=120,
    )
    assert p.returncode != 0
    assert "pip install matplotlib" in p.stderr, p.stderr
    # no run was done
    assert not (work / "gap_study.csv").exists()


def study(tmp_path):
    (tmp_path / "v1a.toml").write_text((EXAMPLES / "v1a_oblique_impact.toml").read_text())
    path = tmp_path / "study.toml"
    path.write_text(
        'base = "v1a.toml"\n\n[[parameters]]\nkey = "contacts.*.friction.mu"\n'
        "values = [0.1, 0.2, 0.3, 0.4]\n\n[[parameters]]\nkey = \"tangential.method\"\n"
        'values = ["gauss_seidel", "active_set"]\n'
    )
    return path


def done(table):
    """The runs a sweep did, from the DataFrame it returned."""
    return table.attrs["runs_done"]


def rows(table):
    lines = Path(table).read_text().splitlines()
    body = sorted(lines[1:], key=lambda l: int(l.split(",")[0]))
    # without steps_per_second (column 5): wall-clock dependent
    return lines[0], [[c for i, c in enumerate(l.split(",")) if i != 5] for l in body]


def test_a_sweep_on_a_dask_cluster_equals_the_local_sweep(tmp_path):
    distributed = pytest.importorskip("dask.distributed")
    path = study(tmp_path)
    assert done(fretdyn.sweep(path, tmp_path / "local.csv", jobs=2)) == 8
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        assert done(fretdyn.sweep(path, tmp_path / "dask.csv", client=client)) == 8
        # run again: nothing left to do, the whole table back
        again = fretdyn.sweep(path, tmp_path / "dask.csv", client=client)
        assert done(again) == 0 and len(again) == 8
    local, dask = rows(tmp_path / "local.csv"), rows(tmp_path / "dask.csv")
    assert local == dask
    assert len(local[1]) == 8
    t = fretdyn.read_table(tmp_path / "dask.csv")
    assert np.all(t["plane.wear_work_rate"] > 0)


def long_case():
    """The turbulent tube, 2 s: about a second of computing."""
    return fretdyn.Case.from_toml(
        (EXAMPLES / "tube_turbulence.toml").read_text().replace("duration = 10.0", "duration = 2.0")
        .replace("block = 2.0", "block = 0.25"),
        EXAMPLES,
    )


def test_the_gil_is_released_during_a_run():
    import threading
    import time

    case = long_case()
    done = threading.Event()
    thread = threading.Thread(target=lambda: (fretdyn.run(case), done.set()))
    start = time.perf_counter()
    thread.start()
    ticks = 0
    while not done.is_set():
        ticks += 1  # pure Python: runs only while the run does not hold the GIL
        time.sleep(0.001)
    thread.join()
    elapsed = time.perf_counter() - start
    assert elapsed > 0.2, elapsed
    # the main thread kept running: at least a tick per 10 ms of the run
    assert ticks > 0.1 * elapsed * 1000, (ticks, elapsed)


def test_ctrl_c_stops_a_run_with_keyboard_interrupt(tmp_path):
    import signal
    import sys
    import time

    script = tmp_path / "long.py"
    script.write_text(
        "import sys, fretdyn\n"
        f"text = open({str(EXAMPLES / 'tube_turbulence.toml')!r}).read()\n"
        f"case = fretdyn.Case.from_toml(text.replace('duration = 10.0', 'duration = 100.0'), {str(EXAMPLES)!r})\n"
        "print('running', flush=True)\n"
        "try:\n"
        "    fretdyn.run(case)\n"
        "except KeyboardInterrupt:\n"
        "    print('interrupted', flush=True)\n"
        "    sys.exit(3)\n"
    )
    # the child gets the default SIGINT disposition whatever the test process has (Python
    # turns SIGINT into KeyboardInterrupt only when its parent left it at the default)
    p = subprocess.Popen(
        [sys.executable, str(script)], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
        text=True, preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    assert p.stdout.readline().strip() == "running"
    time.sleep(1.0)
    start = time.perf_counter()
    # Ctrl-C, pressed again every half second as a user would until the run stops (once seen
    # in CI on a loaded machine: the child ended with code 0, its first SIGINT lost)
    presses = 0
    while p.poll() is None and time.perf_counter() - start < 20.0:
        p.send_signal(signal.SIGINT)
        presses += 1
        try:
            p.wait(timeout=0.5)
        except subprocess.TimeoutExpired:
            pass
    out, err = p.communicate(timeout=60)
    assert p.returncode == 3, (p.returncode, presses, out, err)
    assert "interrupted" in out
    assert time.perf_counter() - start < 5.0, presses


STABILITY_COLUMNS = [
    "mode", "frequency_hz", "damping_ratio", "reference_density", "effective_velocity",
    "critical_velocity", "ratio", "out_of_plane_share",
]


def test_stability_equals_the_cli_bit_for_bit(tmp_path):
    case = EXAMPLES / "ubend_flow.toml"
    p = cli(["stability", str(case), "-o", "out"], tmp_path)
    assert p.returncode == 0, p.stderr
    expected = json.loads((tmp_path / "out" / "stability.json").read_text())
    modes = expected["modes"]
    for given in (case, str(case), fretdyn.Case.from_file(case)):
        s = fretdyn.stability(given)
        assert set(s) == set(STABILITY_COLUMNS) | {
            "reference_zone", "condition", "plane", "connors_constant", "diameter",
            "mass_per_length",
        }
        for key in STABILITY_COLUMNS:
            assert isinstance(s[key], np.ndarray) and s[key].shape == (len(modes),), key
            # JSON: null for a ratio that is undefined (NaN here) or infinite (inf here)
            column = [np.nan if m[key] is None else m[key] for m in modes]
            want = np.array(column, dtype=s[key].dtype)
            assert same_bits(s[key], want), key
        assert s["mode"].dtype.kind == "i"
        assert s["reference_zone"] == [m["reference_zone"] for m in modes]
        assert s["condition"] == [m["condition"] for m in modes]
        assert s["plane"] == [m["plane"] or "" for m in modes]
        for key in ("connors_constant", "diameter", "mass_per_length"):
            assert s[key] == expected[key], key
    # the example's 11 lowest modes are above their critical velocity with the supports
    # inactive (docs/FLOW.md); its support conditions follow
    inactive = np.array([c == "support_inactive" for c in s["condition"]])
    assert int((s["ratio"][inactive] > 1.0).sum()) == 11
    assert len(set(s["condition"])) == 3
    assert np.array_equal(s["ratio"], s["effective_velocity"] / s["critical_velocity"])
    with pytest.raises(TypeError, match="fretdyn.stability takes a Case"):
        fretdyn.stability(42)


def test_stability_of_a_case_without_flow_is_an_error(tmp_path):
    case = EXAMPLES / "v1a_oblique_impact.toml"
    p = cli(["stability", str(case), "-o", "out"], tmp_path)
    assert p.returncode == 2
    with pytest.raises(fretdyn.FretdynError, match=r"no \[flow\] section") as e:
        fretdyn.stability(case)
    # the CLI prefixes the file name; the message is the same
    assert p.stderr.strip() == f"error: {case}: {e.value}"


def test_the_run_dict_has_the_fluid_work_of_the_energy_balance(tmp_path):
    text = (
        (EXAMPLES / "tube_fluid_elastic.toml").read_text()
        .replace("duration = 3.0", "duration = 0.05")
        .replace("t_start = 1.0", "t_start = 0.0")
    )
    assert "duration = 0.05" in text and "t_start = 0.0" in text
    for lift in ("-3.0", "0.0"):
        body = text.replace("lift_slope = -3.0", f"lift_slope = {lift}")
        (tmp_path / "case.toml").write_text(body)
        p = cli(["run", "case.toml", "-o", "out", "-q", "--no-plots"], tmp_path)
        assert p.returncode == 0, p.stderr
        summary = json.loads((tmp_path / "out" / "summary.json").read_text())
        r = fretdyn.run(fretdyn.Case.from_toml(body, tmp_path))
        work = r["summary"]["energy_balance"]["fluid_work"]
        assert work == summary["energy_balance"]["fluid_work"]
        assert work != 0.0
        if lift == "0.0":
            # without the delayed lift stiffness the flow only damps: it takes energy out
            assert work < 0.0, work


def probabilistic_study(tmp_path):
    """The multispan tube with its plates' clearances drawn per plate and the friction drawn
    once, 6 samples of 20 ms."""
    (tmp_path / "tube.toml").write_text((EXAMPLES / "tube_multispan.toml").read_text())
    path = tmp_path / "prob.toml"
    path.write_text(
        'base = "tube.toml"\nsamples = 6\nseed = 3\n\n[[parameters]]\n'
        'key = "contacts.*.obstacle.clearance"\nindependent = true\n'
        'distribution = { type = "uniform", low = 1e-5, high = 3e-5 }\n\n[[parameters]]\n'
        'key = "contacts.*.friction.mu"\n'
        'distribution = { type = "log_normal", median = 0.3, sigma = 0.2 }\n\n[[parameters]]\n'
        'key = "time.duration"\nvalues = [0.02]\n\n[percentiles]\n'
        'statistics = ["normal_force_max"]\nlevels = [50, 95]\n'
    )
    return path


def rows_by_name(table):
    """Header and rows by run index, without the wall-clock column steps_per_second."""
    lines = Path(table).read_text().splitlines()
    header = lines[0].split(",")
    speed = header.index("steps_per_second")
    body = sorted(lines[1:], key=lambda l: int(l.split(",")[0]))
    return header, [[c for i, c in enumerate(l.split(",")) if i != speed] for l in body]


def test_a_probabilistic_study_on_a_dask_cluster_equals_the_local_study(tmp_path):
    """The draws depend on the study and the run index only: the rows (drawn values included)
    and the percentiles are the same on 2 Dask workers as on this machine's cores."""
    distributed = pytest.importorskip("dask.distributed")
    path = probabilistic_study(tmp_path)
    assert done(fretdyn.sweep(path, tmp_path / "local.csv", jobs=2)) == 6
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        assert done(fretdyn.sweep(path, tmp_path / "dask.csv", client=client)) == 6
    local, dask = rows_by_name(tmp_path / "local.csv"), rows_by_name(tmp_path / "dask.csv")
    assert local == dask
    header = local[0]
    assert "contacts.4.obstacle.clearance" in header and "sample" in header
    t = fretdyn.read_table(tmp_path / "dask.csv")
    c = t["contacts.0.obstacle.clearance"]
    assert np.all((c >= 1e-5) & (c < 3e-5)) and len(set(c)) == 6
    # the workers' rows, appended as they came back, are in run order once the table is
    # complete; the indices are integers
    assert t["run"].dtype == np.int64 and list(t["run"]) == list(range(6))
    assert t["sample"].dtype == np.int64 and sorted(t["sample"]) == list(range(6))
    p_local = fretdyn.percentiles(path, tmp_path / "local.csv", output=tmp_path)
    p_dask = fretdyn.percentiles(path, tmp_path / "dask.csv")
    assert p_local.equals(p_dask) and p_local.attrs == p_dask.attrs
    assert (tmp_path / "percentiles.csv").exists()
    rows = p_local[p_local["column"] == "plate1.normal_force_max"]
    assert list(rows["level"]) == [50, 95] and all(rows["n"] == 6)
    # the estimate is NumPy's default percentile of the column
    assert rows["estimate"].iloc[0] == pytest.approx(np.percentile(t["plate1.normal_force_max"], 50), rel=1e-12)
    assert rows["estimate"].iloc[1] == pytest.approx(np.percentile(t["plate1.normal_force_max"], 95), rel=1e-12)


def test_a_probabilistic_service_life_study_on_dask_equals_the_local_study(tmp_path):
    """Service lives (the base case has [life]) with the plates' clearances drawn per plate:
    the depth columns and their percentiles are the same on 2 Dask workers as locally."""
    distributed = pytest.importorskip("dask.distributed")
    (tmp_path / "tube.toml").write_text((EXAMPLES / "tube_multispan_life.toml").read_text())
    path = tmp_path / "life.toml"
    path.write_text(
        'base = "tube.toml"\nsamples = 4\nseed = 5\n\n[[parameters]]\n'
        'key = "contacts.*.obstacle.clearance"\nindependent = true\n'
        'distribution = { type = "normal", mean = 2e-4, std = 4e-5, min = 1e-4, max = 3e-4 }\n\n'
        '[[parameters]]\nkey = "time.duration"\nvalues = [0.06]\n\n'
        '[[parameters]]\nkey = "statistics.t_start"\nvalues = [0.01]\n\n'
        '[percentiles]\nstatistics = ["depth_at_target"]\nlevels = [50, 95]\n'
    )
    assert done(fretdyn.sweep(path, tmp_path / "local.csv", jobs=2)) == 4
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        assert done(fretdyn.sweep(path, tmp_path / "dask.csv", client=client)) == 4
    local, dask = rows_by_name(tmp_path / "local.csv"), rows_by_name(tmp_path / "dask.csv")
    assert local == dask
    t = fretdyn.read_table(tmp_path / "dask.csv")
    assert t["life_end"] == ["completed"] * 4
    depth = t["plate2.depth_at_target"]
    assert np.all(depth > 0) and np.all(np.isfinite(depth))
    p_local = fretdyn.percentiles(path, tmp_path / "local.csv")
    assert p_local.equals(fretdyn.percentiles(path, tmp_path / "dask.csv"))
    rows = p_local[p_local["column"] == "plate2.depth_at_target"]
    assert rows["estimate"].iloc[0] == pytest.approx(np.percentile(depth, 50), rel=1e-12)


def v1a_study(tmp_path):
    """V1a with two durations: a study of two quick runs."""
    (tmp_path / "v1a.toml").write_text((EXAMPLES / "v1a_oblique_impact.toml").read_text())
    path = tmp_path / "study.toml"
    path.write_text(
        'base = "v1a.toml"\n\n[[parameters]]\nkey = "time.duration"\nvalues = [2e-3, 4e-3]\n'
        '\n[percentiles]\nstatistics = ["wear_work_rate"]\n'
    )
    return path


def test_a_study_of_changed_inputs_is_refused_and_fresh_starts_afresh(tmp_path):
    """The base case edited (μ 0.3 → 0.6) and the study swept again into the same table:
    refused, saying what changed (it used to return the old rows as the new study's);
    ``fresh=True`` starts afresh."""
    path = v1a_study(tmp_path)
    assert done(fretdyn.sweep(path, tmp_path / "same.csv")) == 2
    assert done(fretdyn.sweep(path, tmp_path / "same.csv")) == 0
    base = (tmp_path / "v1a.toml").read_text()
    (tmp_path / "v1a.toml").write_text(base.replace("mu = 0.3", "mu = 0.6"))
    with pytest.raises(fretdyn.FretdynError, match=r"contacts\.0\.friction\.mu: 0\.3 → 0\.6"):
        fretdyn.sweep(path, tmp_path / "same.csv")
    with pytest.raises(fretdyn.FretdynError, match="other inputs"):
        fretdyn.percentiles(path, tmp_path / "same.csv")
    t = fretdyn.sweep(path, tmp_path / "same.csv", fresh=True)
    assert done(t) == 2
    assert list(t["fingerprint"].str.startswith("fp")) == [True, True]


def test_a_study_table_is_written_by_one_study_and_rows_of_other_inputs_are_refused(tmp_path):
    """What the Dask path relies on: the table is locked while open (a second study on it is
    refused), and a row a worker computed from other files than here is refused."""
    path = v1a_study(tmp_path)
    source = os.fspath(path)
    table = os.fspath(tmp_path / "dask.csv")
    opened = fretdyn._native.open_study_table(source, table)
    try:
        with pytest.raises(fretdyn.FretdynError, match="is writing this table"):
            fretdyn._native.open_study_table(source, table)
        with pytest.raises(fretdyn.FretdynError, match="is writing this table"):
            fretdyn.sweep(path, table)
        assert opened.pending() == [0, 1]
        opened.append(fretdyn._native.study_row(source, 0))
        # a worker whose base case differs
        base = (tmp_path / "v1a.toml").read_text()
        (tmp_path / "v1a.toml").write_text(base.replace("mu = 0.3", "mu = 0.6"))
        foreign = fretdyn._native.study_row(source, 1)
        (tmp_path / "v1a.toml").write_text(base)
        with pytest.raises(fretdyn.FretdynError, match="run 1 was computed from other inputs"):
            opened.append(foreign)
        assert opened.pending() == [1]
    finally:
        opened.close()
    assert done(fretdyn.sweep(path, table)) == 1

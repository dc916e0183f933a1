"""results.nc opens in xarray with the numbers of results.npz, named dimensions, the contacts'
names as a coordinate and units on every variable: for every example case (the study_* files
are studies, run by `fretdyn sweep`). Run by .ci/run in a venv with numpy, xarray, netCDF4
and pytest; FRETDYN is the binary's path."""

import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

ROOT = Path(__file__).resolve().parents[2]
FRETDYN = os.environ.get("FRETDYN", str(ROOT / "target" / "release" / "fretdyn"))
CASES = sorted(
    p for p in (ROOT / "examples").glob("*.toml") if not p.name.startswith("study_")
)

# the dimensions of each key of results.npz in results.nc (README, "Reading the results")
DIMS = {
    "t": ("time",),
    "q": ("time", "mode"),
    "qdot": ("time", "mode"),
    "contact_normal_force": ("time", "contact"),
    "contact_tangential_force": ("time", "contact", "tangent"),
    "contact_slip_velocity": ("time", "contact", "tangent"),
    "contact_penetration": ("time", "contact"),
    "contact_status": ("time", "contact"),
    "contact_position": ("time", "contact", "local_axis"),
}

# SI units of the README's table (UDUNITS spelling)
UNITS = {
    "t": "s",
    "q": "kg^0.5 m",
    "qdot": "kg^0.5 m s-1",
    "contact_normal_force": "N",
    "contact_tangential_force": "N",
    "contact_slip_velocity": "m s-1",
    "contact_penetration": "m",
    "contact_position": "m",
}


def test_every_example_is_checked():
    assert len(CASES) >= 10, CASES


@pytest.mark.parametrize("case", CASES, ids=lambda p: p.stem)
def test_results_nc_opens_in_xarray_with_the_numbers_of_results_npz(case, tmp_path):
    p = subprocess.run(
        [FRETDYN, "run", str(case), "-o", "out", "-q", "--no-plots"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
    )
    assert p.returncode == 0, p.stderr
    out = tmp_path / "out"
    r = np.load(out / "results.npz")
    summary = json.loads((out / "summary.json").read_text())
    with xr.open_dataset(out / "results.nc") as ds:
        assert set(r.files) == set(DIMS)
        for key, dims in DIMS.items():
            name = "time" if key == "t" else key
            v = ds[name]
            assert v.dims == dims, key
            assert v.dtype == r[key].dtype, key
            assert v.shape == r[key].shape, key
            # bit for bit (NaN included)
            assert v.values.tobytes() == r[key].tobytes(), key
            if key in UNITS:
                assert v.attrs["units"] == UNITS[key], key
        # the contacts' names as a coordinate, in the order of summary.json
        names = [c["name"] for c in summary["contacts"]]
        assert list(ds["contact"].values) == names
        if names:
            forces = ds["contact_normal_force"].sel(contact=names[-1])
            assert np.array_equal(forces.values, r["contact_normal_force"][:, -1])
        assert ds.sizes["mode"] == r["q"].shape[1]
        assert list(ds["tangent"].values) == ["t1", "t2"]
        assert list(ds["local_axis"].values) == ["e1", "e2"]
        assert list(ds["direction"].values) == ["x", "y", "z"]
        assert ds["point"].size >= 1
        assert set(ds["contact_point"].values) <= set(ds["point"].values)
        # the auxiliary coordinates are coordinates, not data variables
        for name in ["frequency", "damping_ratio", "contact_point", "contact_obstacle",
                     "point_position"]:
            assert name in ds.coords, name
        assert set(ds.data_vars) == set(DIMS) - {"t"}
        assert ds["contact_status"].attrs["flag_meanings"] == "open stick slip"
        assert list(ds["contact_status"].attrs["flag_values"]) == [0, 1, 2]
        # units and long_name on every numeric variable, a long_name on the name labels
        for name, v in ds.variables.items():
            assert v.attrs.get("long_name"), name
            if v.dtype.kind in "fiu":
                assert "units" in v.attrs, name
        # the case and the summary
        assert ds.attrs["case"] == case.read_text()
        assert json.loads(ds.attrs["summary"]) == summary
        assert ds.attrs["fretdyn_version"] == summary["fretdyn_version"]

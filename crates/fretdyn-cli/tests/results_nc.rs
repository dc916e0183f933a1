//! `results.nc` as a user opens it: every array of `results.npz` with the same numbers (bit for
//! bit) and shapes, named dimensions, the names of the contacts and points as coordinates,
//! `units` and `long_name` on every variable, the case and the summary as attributes; and a
//! run killed and resumed, or interrupted while packing, ends with the `results.nc` of an
//! uninterrupted run. Read with the `netcdf` crate (the C library), independently of the
//! writer's code.

use std::collections::BTreeMap;
use std::path::Path;
use std::process::{Command, Output};

use ndarray_npy::NpzReader;

mod common;
use common::{Scratch, examples, fretdyn, kill_past_checkpoint};

fn assert_ok(out: &Output) {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The values of a variable, as stored.
#[derive(Debug, Clone, PartialEq)]
enum Values {
    F64(Vec<f64>),
    I8(Vec<i8>),
    I32(Vec<i32>),
    Str(Vec<String>),
}

impl Values {
    /// Bit patterns, so that equality is bit for bit (and NaN equals itself).
    fn bits(&self) -> Vec<u64> {
        match self {
            Values::F64(v) => v.iter().map(|x| x.to_bits()).collect(),
            Values::I8(v) => v.iter().map(|&x| x as u8 as u64).collect(),
            Values::I32(v) => v.iter().map(|&x| x as u32 as u64).collect(),
            Values::Str(_) => panic!("strings have no bits"),
        }
    }
}

/// A variable of `results.nc`: its dimensions (name, length), values, text attributes.
#[derive(Debug, Clone, PartialEq)]
struct Var {
    dims: Vec<(String, usize)>,
    values: Values,
    attrs: BTreeMap<String, String>,
}

/// A `results.nc` read whole (the tests' files are small): variables, global text
/// attributes, and which dimensions are unlimited.
#[derive(Debug, Clone, PartialEq)]
struct Nc {
    vars: BTreeMap<String, Var>,
    attrs: BTreeMap<String, String>,
    unlimited: Vec<String>,
}

fn text(value: netcdf::AttributeValue) -> Option<String> {
    match value {
        netcdf::AttributeValue::Str(s) => Some(s),
        netcdf::AttributeValue::Strs(v) if v.len() == 1 => v.into_iter().next(),
        _ => None,
    }
}

fn read_nc(path: &Path) -> Nc {
    use netcdf::types::{FloatType, IntType, NcVariableType};
    // the HDF5 library prints an error stack for each attribute libnetcdf probes and does
    // not find, in every test thread but the first (hundreds of "HDF5-DIAG: Error" blocks)
    fretdyn::output::netcdf::quiet_hdf5_errors();
    let file = netcdf::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut vars = BTreeMap::new();
    for v in file.variables() {
        let dims: Vec<(String, usize)> =
            v.dimensions().iter().map(|d| (d.name(), d.len())).collect();
        let len: usize = dims.iter().map(|d| d.1).product();
        let values = match v.vartype() {
            NcVariableType::Float(FloatType::F64) => Values::F64(if len == 0 {
                vec![]
            } else {
                v.get_values(..).unwrap()
            }),
            NcVariableType::Int(IntType::I8) => Values::I8(if len == 0 {
                vec![]
            } else {
                v.get_values(..).unwrap()
            }),
            NcVariableType::Int(IntType::I32) => Values::I32(if len == 0 {
                vec![]
            } else {
                v.get_values(..).unwrap()
            }),
            NcVariableType::String => {
                Values::Str((0..len).map(|i| v.get_string([i]).unwrap()).collect())
            }
            other => panic!("{}: unexpected type {other:?}", v.name()),
        };
        let attrs = v
            .attributes()
            .filter_map(|a| Some((a.name().to_string(), text(a.value().ok()?)?)))
            .collect();
        vars.insert(
            v.name(),
            Var {
                dims,
                values,
                attrs,
            },
        );
    }
    let attrs = file
        .attributes()
        .filter_map(|a| Some((a.name().to_string(), text(a.value().ok()?)?)))
        .collect();
    let unlimited = file
        .dimensions()
        .filter(|d| d.is_unlimited() && d.len() > 0)
        .map(|d| d.name())
        .collect();
    Nc {
        vars,
        attrs,
        unlimited,
    }
}

/// Every array of a `results.npz`: key → (shape, bit patterns).
fn read_npz(path: &Path) -> BTreeMap<String, (Vec<usize>, Vec<u64>)> {
    let mut npz = NpzReader::new(std::fs::File::open(path).unwrap()).unwrap();
    let names = npz.names().unwrap();
    let mut out = BTreeMap::new();
    for name in names {
        let key = name.trim_end_matches(".npy").to_string();
        let entry = if key == "contact_status" {
            let a: ndarray::ArrayD<i8> = npz.by_name(&name).unwrap();
            (
                a.shape().to_vec(),
                a.iter().map(|&x| x as u8 as u64).collect(),
            )
        } else {
            let a: ndarray::ArrayD<f64> = npz.by_name(&name).unwrap();
            (a.shape().to_vec(), a.iter().map(|x| x.to_bits()).collect())
        };
        out.insert(key, entry);
    }
    out
}

/// The name of a `results.npz` key in `results.nc` (the time samples are the coordinate).
fn nc_name(key: &str) -> &str {
    if key == "t" { "time" } else { key }
}

/// `results.nc` holds every array of `results.npz` bit for bit, with the same shape.
fn assert_nc_equals_npz(dir: &Path) -> Nc {
    let nc = read_nc(&dir.join("results.nc"));
    let npz = read_npz(&dir.join("results.npz"));
    assert_eq!(npz.len(), 9, "{:?}", npz.keys());
    for (key, (shape, bits)) in &npz {
        let var = nc
            .vars
            .get(nc_name(key))
            .unwrap_or_else(|| panic!("{key} missing from results.nc"));
        let nc_shape: Vec<usize> = var.dims.iter().map(|d| d.1).collect();
        assert_eq!(&nc_shape, shape, "{key}: shape");
        assert_eq!(var.dims[0].0, "time", "{key}: time first");
        assert_eq!(&var.values.bits(), bits, "{key}: values");
        let dtype_ok = match key.as_str() {
            "contact_status" => matches!(var.values, Values::I8(_)),
            _ => matches!(var.values, Values::F64(_)),
        };
        assert!(dtype_ok, "{key}: type");
    }
    nc
}

fn summary(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap()
}

/// The multi-span tube (5 plates, 30 modes, 6 named points): `results.nc` against
/// `results.npz`, the case file, `summary.json` and the README's table of units.
#[test]
fn results_nc_has_the_arrays_of_results_npz_with_names_and_units() {
    let s = Scratch::new("names");
    let case = examples().join("tube_multispan.toml");
    let out = fretdyn(
        &[
            "run",
            case.to_str().unwrap(),
            "-o",
            "out",
            "-q",
            "--no-plots",
        ],
        &s.0,
    );
    assert_ok(&out);
    let dir = s.0.join("out");
    let nc = assert_nc_equals_npz(&dir);
    assert!(!dir.join("results.nc.partial").exists());

    // dimensions by name
    let dims =
        |name: &str| -> Vec<String> { nc.vars[name].dims.iter().map(|d| d.0.clone()).collect() };
    assert_eq!(dims("q"), ["time", "mode"]);
    assert_eq!(dims("qdot"), ["time", "mode"]);
    assert_eq!(dims("contact_normal_force"), ["time", "contact"]);
    assert_eq!(dims("contact_penetration"), ["time", "contact"]);
    assert_eq!(dims("contact_status"), ["time", "contact"]);
    assert_eq!(
        dims("contact_tangential_force"),
        ["time", "contact", "tangent"]
    );
    assert_eq!(
        dims("contact_slip_velocity"),
        ["time", "contact", "tangent"]
    );
    assert_eq!(dims("contact_position"), ["time", "contact", "local_axis"]);
    assert_eq!(nc.unlimited, ["time"], "time is the unlimited dimension");

    // coordinates: the names of the case file's contacts and points, as summary.json and the
    // case as read give them
    let s_json = summary(&dir);
    let contacts: Vec<String> = s_json["contacts"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["name"].as_str().unwrap().to_string())
        .collect();
    assert_eq!(contacts, ["plate1", "plate2", "plate3", "plate4", "plate5"]);
    assert_eq!(nc.vars["contact"].values, Values::Str(contacts.clone()));
    assert_eq!(nc.vars["contact_point"].values, Values::Str(contacts));
    assert_eq!(
        nc.vars["contact_obstacle"].values,
        Values::Str(vec!["circle".into(); 5])
    );
    let read = fretdyn::Case::from_file(&case).unwrap();
    let points: Vec<String> = read
        .model
        .basis
        .points
        .iter()
        .map(|p| p.name.clone())
        .collect();
    assert!(points.contains(&"load".to_string()), "{points:?}");
    assert_eq!(nc.vars["point"].values, Values::Str(points));
    let positions: Vec<f64> = read
        .model
        .basis
        .points
        .iter()
        .flat_map(|p| [p.coords.x, p.coords.y, p.coords.z])
        .collect();
    assert_eq!(nc.vars["point_position"].values, Values::F64(positions));
    assert_eq!(
        nc.vars["direction"].values,
        Values::Str(vec!["x".into(), "y".into(), "z".into()])
    );
    assert_eq!(
        nc.vars["tangent"].values,
        Values::Str(vec!["t1".into(), "t2".into()])
    );
    assert_eq!(nc.vars["mode"].values, Values::I32((1..=30).collect()));
    let Values::F64(f) = &nc.vars["frequency"].values else {
        panic!("frequency")
    };
    for (f, w) in f.iter().zip(&read.model.basis.omega) {
        assert!(
            (f * 2.0 * std::f64::consts::PI - w).abs() <= 1e-12 * w,
            "{f} Hz, {w} rad/s"
        );
    }

    // long_name on every variable, units on every number (SI, the README's table)
    for (name, var) in &nc.vars {
        assert!(
            var.attrs.get("long_name").is_some_and(|l| !l.is_empty()),
            "{name}: long_name"
        );
        if !matches!(var.values, Values::Str(_)) {
            assert!(var.attrs.contains_key("units"), "{name}: units");
        }
    }
    for (name, units) in [
        ("time", "s"),
        ("contact_normal_force", "N"),
        ("contact_tangential_force", "N"),
        ("contact_slip_velocity", "m s-1"),
        ("q", "kg^0.5 m"),
        ("qdot", "kg^0.5 m s-1"),
        ("contact_penetration", "m"),
        ("contact_position", "m"),
        ("contact_status", "1"),
        ("frequency", "Hz"),
        ("point_position", "m"),
    ] {
        assert_eq!(nc.vars[name].attrs["units"], units, "{name}");
    }

    // the names, dimensions, units and long names are those of the one table the Python
    // package's to_xarray() takes them from, and nothing else
    let table = fretdyn::output::variables::time_histories(true);
    let described: Vec<(&str, &[&str], Option<&str>, &str)> = table
        .iter()
        .map(|h| &h.variable)
        .chain(
            fretdyn::output::variables::COORDINATES
                .iter()
                .map(|c| &c.variable),
        )
        .map(|v| (v.name, v.dims, v.units, v.long_name))
        .collect();
    assert_eq!(described.len(), nc.vars.len(), "{:?}", nc.vars.keys());
    for (name, dims, units, long_name) in described {
        let var = &nc.vars[name];
        let var_dims: Vec<&str> = var.dims.iter().map(|d| d.0.as_str()).collect();
        assert_eq!(var_dims, dims, "{name}");
        assert_eq!(var.attrs.get("units").map(String::as_str), units, "{name}");
        assert_eq!(var.attrs["long_name"], long_name, "{name}");
    }
    assert_eq!(
        nc.vars["contact_status"].attrs["flag_meanings"],
        "open stick slip"
    );
    // auxiliary coordinates, CF: on the variables along their dimensions, point_position
    // in the global attribute (xarray's convention)
    assert_eq!(nc.vars["q"].attrs["coordinates"], "frequency damping_ratio");
    assert_eq!(
        nc.vars["contact_position"].attrs["coordinates"],
        "contact_point contact_obstacle"
    );
    assert_eq!(nc.attrs["coordinates"], "point_position");

    // the case and the summary
    assert_eq!(
        nc.attrs["case"],
        std::fs::read_to_string(&case).unwrap(),
        "the case file's text"
    );
    let summary_text = std::fs::read_to_string(dir.join("summary.json")).unwrap();
    assert!(summary_text.len() > 65_536, "a summary above 64 kB");
    assert_eq!(nc.attrs["summary"], summary_text);
    assert_eq!(nc.attrs["fretdyn_version"], env!("CARGO_PKG_VERSION"));
    assert_eq!(nc.attrs["title"], "Straight tube in 5 support plates");
}

/// A case without contacts: zero-length contact arrays, still along `time`.
#[test]
fn a_case_without_contacts_has_empty_contact_arrays() {
    let s = Scratch::new("nocontact");
    let text = std::fs::read_to_string(examples().join("tube_clamped_one_support.toml")).unwrap();
    // its one contact, and nothing else, goes
    let (i, j) = (
        text.find("[[contacts]]").unwrap(),
        text.find("[[loads]]").unwrap(),
    );
    let case = format!("{}{}", &text[..i], &text[j..]);
    assert!(!case.contains("[[contacts]]"), "{case}");
    std::fs::write(s.0.join("case.toml"), case).unwrap();
    let out = fretdyn(&["run", "case.toml", "-o", "out", "-q", "--no-plots"], &s.0);
    assert_ok(&out);
    let nc = assert_nc_equals_npz(&s.0.join("out"));
    assert_eq!(nc.vars["contact"].dims, [("contact".to_string(), 0)]);
    assert_eq!(
        nc.vars["contact_normal_force"].dims[1],
        ("contact".into(), 0)
    );
}

/// Two `results.nc` are the same run's: every variable equal bit for bit with its
/// attributes, the same global attributes but the summary's wall time.
fn assert_same_nc(a: &Path, b: &Path) {
    let (a, b) = (read_nc(a), read_nc(b));
    assert_eq!(
        a.vars.keys().collect::<Vec<_>>(),
        b.vars.keys().collect::<Vec<_>>()
    );
    for (name, va) in &a.vars {
        let vb = &b.vars[name];
        assert_eq!(va.dims, vb.dims, "{name}");
        assert_eq!(va.attrs, vb.attrs, "{name}");
        match &va.values {
            Values::Str(_) => assert_eq!(va.values, vb.values, "{name}"),
            _ => assert!(va.values.bits() == vb.values.bits(), "{name} differs"),
        }
    }
    let without_performance = |nc: &Nc| {
        let mut s: serde_json::Value = serde_json::from_str(&nc.attrs["summary"]).unwrap();
        s.as_object_mut().unwrap().remove("performance");
        s
    };
    assert_eq!(without_performance(&a), without_performance(&b));
    for key in ["case", "title", "fretdyn_version"] {
        assert_eq!(a.attrs[key], b.attrs[key], "{key}");
    }
}

/// The turbulence tube (10 simulated seconds) run to the end; run again, `kill -9` once a
/// checkpoint is past a third of the run, resumed: the same `results.nc`.
#[test]
fn a_killed_and_resumed_run_has_the_results_nc_of_an_uninterrupted_one() {
    let s = Scratch::new("resume");
    let case = examples().join("tube_turbulence.toml");
    let case = case.to_str().unwrap();
    assert_ok(&fretdyn(
        &["run", case, "-o", "full", "-q", "--no-plots"],
        &s.0,
    ));
    let mut child = Command::new(env!("CARGO_BIN_EXE_fretdyn"))
        .args([
            "run",
            case,
            "-o",
            "killed",
            "-q",
            "--no-plots",
            "--checkpoint-every",
            "0.1",
        ])
        .current_dir(&s.0)
        .spawn()
        .unwrap();
    let killed = s.0.join("killed");
    kill_past_checkpoint(&mut child, &killed, 300_000);
    assert!(!killed.join("results.nc").exists(), "killed mid-run");
    assert_ok(&fretdyn(
        &["run", "--resume", "killed", "-q", "--no-plots"],
        &s.0,
    ));
    assert_nc_equals_npz(&killed);
    assert_same_nc(&s.0.join("full/results.nc"), &killed.join("results.nc"));
}

/// A run whose `results.nc` cannot be written (here `results.nc.partial` is a folder, as a
/// disk full after `results.npz`): exit 1 naming `results.nc` and `--resume`; the run is not
/// complete until `results.nc` is there, and `--resume` writes it, the same as an
/// uninterrupted run's.
#[test]
fn a_run_that_fails_writing_results_nc_is_finished_by_resume() {
    let s = Scratch::new("packing");
    let case = examples().join("tube_multispan.toml");
    let case = case.to_str().unwrap();
    assert_ok(&fretdyn(
        &["run", case, "-o", "full", "-q", "--no-plots"],
        &s.0,
    ));
    std::fs::create_dir_all(s.0.join("out/results.nc.partial/x")).unwrap();
    let out = fretdyn(&["run", case, "-o", "out", "-q", "--no-plots"], &s.0);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("results.nc") && stderr.contains("fretdyn run --resume out"),
        "{stderr}"
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(s.0.join("out/results.npz").exists());
    assert!(!s.0.join("out/results.nc").exists());
    assert!(s.0.join("out/series").exists(), "kept for the resume");
    std::fs::remove_dir_all(s.0.join("out/results.nc.partial")).unwrap();
    assert_ok(&fretdyn(
        &["run", "--resume", "out", "-q", "--no-plots"],
        &s.0,
    ));
    assert!(!s.0.join("out/series").exists());
    assert_nc_equals_npz(&s.0.join("out"));
    assert_same_nc(&s.0.join("full/results.nc"), &s.0.join("out/results.nc"));
    // and now it is complete
    let out = fretdyn(&["run", "--resume", "out", "-q"], &s.0);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("nothing to resume"));
}

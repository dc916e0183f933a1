//! The outputs of a model of several structures with a two-body contact (THEORY §15), as the
//! command line writes them (`fretdyn::output::stream` with the summary and `contacts.csv` of
//! `fretdyn run`): `results.nc` says the structure of every mode and point and the second
//! point of every contact, `summary.json` lists the structures and `contacts.csv` the
//! contacts' points, all read back and checked against the model (its points are named
//! `structure.point`); and such a run stopped after a checkpoint and resumed gives the files
//! of the run straight through, bit for bit.

use std::collections::BTreeMap;
use std::ops::ControlFlow;
use std::path::Path;

use fretdyn::contact::Contact;
use fretdyn::contact::obstacle::{Obstacle, Plane};
use fretdyn::integrator::simulation::{Progress, RunResults, Termination};
use fretdyn::output::stream::{self, ResultsMetadata, StreamObserver, StreamSettings};
use fretdyn::{Case, Model};

mod common;
use common::{Scratch, examples};

/// Two clamped tubes with their mid-span support (`tube_clamped_one_support.toml`, 12 modes
/// each), `a` and `b`, loaded in opposite directions, with a two-body contact between their
/// load points: `a.load` against `b.load` along y, 20 µm apart (a plane in the relative
/// coordinates, its normal from B to A).
fn two_tubes(steps: u64) -> Case {
    let one = Case::from_file(&examples().join("tube_clamped_one_support.toml")).unwrap();
    let mut b = one.model.clone();
    for l in &mut b.loads {
        l.force = -l.force;
    }
    let mut model = Model::union(vec![("a".into(), one.model.clone()), ("b".into(), b)]).unwrap();
    let points = &model.basis.points;
    let find = |name: &str| points.iter().position(|p| p.name == name).unwrap();
    let (pa, pb) = (find("a.load"), find("b.load"));
    let origin = points[pa].coords - points[pb].coords;
    let (mut x, mut y) = (origin * 0.0, origin * 0.0);
    (x[0], y[1]) = (1.0, 1.0);
    let plane = Plane::new(origin, y, 2e-5, Some(x), "test").unwrap();
    let support = &one.model.contacts[0];
    let pair = Contact::between(
        "a_b",
        pa,
        pb,
        points,
        [0.0, 0.0],
        Obstacle::Plane(plane),
        support.normal,
        support.friction,
    )
    .unwrap();
    model.contacts.push(pair);
    model.wear.push(None);
    let mut settings = one.settings.clone();
    settings.steps = steps;
    settings.output_every = 10;
    settings.statistics.t_start = 0.0;
    settings.statistics.block = Some(0.01);
    Case::from_parts("two tubes", model, settings)
}

/// Writes `summary.json` and `contacts.csv` when the run has ended, as `fretdyn run` does,
/// and gives the summary to `results.nc`; stops at step `stop` (like Ctrl-C).
struct Writer<'a> {
    case: &'a Case,
    dir: &'a Path,
    stop: u64,
    summary: Option<String>,
}

impl StreamObserver for Writer<'_> {
    fn progress(&mut self, p: Progress) -> ControlFlow<()> {
        if p.step >= self.stop {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    }

    fn finished(&mut self, results: &RunResults) -> fretdyn::Result<()> {
        let mut summary = fretdyn::output::summary::summary(self.case, results);
        // the wall time differs from run to run
        summary["performance"] = serde_json::Value::Null;
        let path = fretdyn::output::summary::write_summary(self.dir, &summary)?;
        fretdyn::output::contacts_table::write_contacts_csv(self.dir, &summary)?;
        self.summary = std::fs::read_to_string(path).ok();
        Ok(())
    }

    fn metadata(&self) -> ResultsMetadata {
        ResultsMetadata {
            title: Some(self.case.title.clone()),
            case_toml: None,
            summary_json: self.summary.clone(),
        }
    }
}

fn settings() -> StreamSettings {
    StreamSettings {
        chunk_samples: 200,
        checkpoint_every_steps: Some(2048),
        checkpoint_every_seconds: None,
    }
}

fn run(case: &Case, dir: &Path, stop: u64) -> RunResults {
    let mut w = Writer {
        case,
        dir,
        stop,
        summary: None,
    };
    stream::run(&case.model, &case.settings, dir, &settings(), 1, &mut w).unwrap()
}

fn resume(case: &Case, dir: &Path) -> RunResults {
    let mut w = Writer {
        case,
        dir,
        stop: u64::MAX,
        summary: None,
    };
    stream::resume(&case.model, &case.settings, dir, &settings(), 1, &mut w).unwrap()
}

/// The string variables of `results.nc` and the text attributes (`var:attr`, `:attr` global).
fn read_nc(path: &Path) -> (BTreeMap<String, Vec<String>>, BTreeMap<String, String>) {
    fretdyn::output::netcdf::quiet_hdf5_errors();
    let file = netcdf::open(path).unwrap();
    let text = |v: netcdf::AttributeValue| match v {
        netcdf::AttributeValue::Str(s) => Some(s),
        netcdf::AttributeValue::Strs(v) if v.len() == 1 => v.into_iter().next(),
        _ => None,
    };
    let mut strings = BTreeMap::new();
    let mut attrs = BTreeMap::new();
    for v in file.variables() {
        if matches!(v.vartype(), netcdf::types::NcVariableType::String) {
            let len: usize = v.dimensions().iter().map(|d| d.len()).product();
            let values = (0..len).map(|i| v.get_string([i]).unwrap()).collect();
            strings.insert(v.name(), values);
        }
        for a in v.attributes() {
            if let Some(t) = a.value().ok().and_then(text) {
                attrs.insert(format!("{}:{}", v.name(), a.name()), t);
            }
        }
    }
    for a in file.attributes() {
        if let Some(t) = a.value().ok().and_then(text) {
            attrs.insert(format!(":{}", a.name()), t);
        }
    }
    (strings, attrs)
}

/// Every array of `results.npz`: name → bit patterns.
fn read_npz(dir: &Path) -> BTreeMap<String, Vec<u64>> {
    let mut npz =
        ndarray_npy::NpzReader::new(std::fs::File::open(dir.join("results.npz")).unwrap()).unwrap();
    let mut out = BTreeMap::new();
    for name in npz.names().unwrap() {
        let bits = if name.starts_with("contact_status") {
            let a: ndarray::ArrayD<i8> = npz.by_name(&name).unwrap();
            a.iter().map(|&x| x as u8 as u64).collect()
        } else {
            let a: ndarray::ArrayD<f64> = npz.by_name(&name).unwrap();
            a.iter().map(|x| x.to_bits()).collect()
        };
        out.insert(name, bits);
    }
    assert!(out.len() >= 9);
    out
}

/// The structure a point or contact name belongs to: its prefix (`a.load` → `a`).
fn prefix(name: &str) -> &str {
    name.split_once('.').map_or("", |(s, _)| s)
}

#[test]
fn results_summary_and_table_name_the_structures_and_the_second_point() {
    let case = two_tubes(4000);
    let model = &case.model;
    let scratch = Scratch::new("labels");
    let dir = scratch.0.join("run");
    let r = run(&case, &dir, u64::MAX);
    assert_eq!(r.termination, Termination::Completed);
    let pair = model.contacts.len() - 1;
    assert!(
        r.contacts[pair].impacts > 0,
        "the tubes hit each other: {:?}",
        r.contacts[pair]
    );

    // results.nc
    let (strings, attrs) = read_nc(&dir.join("results.nc"));
    assert_eq!(strings["structure"], ["a", "b"]);
    let points = &strings["point"];
    assert_eq!(points.len(), model.basis.points.len());
    let owners: Vec<&str> = points.iter().map(|p| prefix(p)).collect();
    assert_eq!(strings["point_structure"], owners);
    // 12 modes each, in the order of the structures
    let modes = &strings["mode_structure"];
    assert_eq!(modes.len(), 24);
    assert!(modes[..12].iter().all(|s| s == "a") && modes[12..].iter().all(|s| s == "b"));
    assert_eq!(
        strings["contact"],
        ["a.mid_support", "b.mid_support", "a_b"]
    );
    assert_eq!(
        strings["contact_point"],
        ["a.mid_bottom", "b.mid_bottom", "a.load"]
    );
    assert_eq!(strings["contact_other_point"], ["", "", "b.load"]);
    assert_eq!(
        attrs["q:coordinates"],
        "frequency damping_ratio mode_structure"
    );
    assert_eq!(
        attrs["contact_normal_force:coordinates"],
        "contact_point contact_obstacle contact_other_point"
    );
    assert_eq!(attrs[":coordinates"], "point_position point_structure");
    assert!(attrs["contact_other_point:long_name"].contains("two-body"));

    // summary.json
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    let structures = summary["structures"].as_array().unwrap();
    assert_eq!(structures.len(), 2);
    for (s, name) in structures.iter().zip(["a", "b"]) {
        assert_eq!(s["name"], name);
        assert_eq!(s["modes"], 12);
        let own: Vec<&str> = points
            .iter()
            .map(String::as_str)
            .filter(|p| prefix(p) == name)
            .collect();
        assert_eq!(s["points"], serde_json::json!(own));
        assert_eq!(
            s["contacts"],
            serde_json::json!([format!("{name}.mid_support")])
        );
    }
    let contacts = summary["contacts"].as_array().unwrap();
    for (c, (point, other)) in contacts.iter().zip(
        strings["contact_point"]
            .iter()
            .zip(&strings["contact_other_point"]),
    ) {
        assert_eq!(&c["point"], point);
        assert_eq!(&c["other_point"], other);
    }

    // contacts.csv: the points after the name, empty for an obstacle
    let mut csv = csv::Reader::from_path(dir.join("contacts.csv")).unwrap();
    let header: Vec<String> = csv.headers().unwrap().iter().map(String::from).collect();
    assert_eq!(header[..4], ["contact", "name", "point", "other_point"]);
    let rows: Vec<Vec<String>> = csv
        .records()
        .map(|r| r.unwrap().iter().map(String::from).collect())
        .collect();
    assert_eq!(rows.len(), 3);
    for (row, c) in rows.iter().zip(contacts) {
        assert_eq!(row[1], c["name"].as_str().unwrap());
        assert_eq!(row[2], c["point"].as_str().unwrap());
        assert_eq!(row[3], c["other_point"].as_str().unwrap());
    }
    // described in contacts_columns.csv, in the order of the header
    let described: Vec<Vec<String>> = csv::Reader::from_path(dir.join("contacts_columns.csv"))
        .unwrap()
        .records()
        .map(|r| r.unwrap().iter().map(String::from).collect())
        .collect();
    assert_eq!(described.len(), header.len());
    assert_eq!(described[2][..3], ["point", "", "NOEUD_1"]);
    assert_eq!(described[3][..3], ["other_point", "", "NOEUD_2"]);
    assert!(described[3][3].starts_with("point B of a two-body contact"));
}

#[test]
fn a_run_of_two_structures_stopped_and_resumed_gives_the_same_bits() {
    let case = two_tubes(8000);
    let scratch = Scratch::new("resume");
    let full = scratch.0.join("full");
    let r_full = run(&case, &full, u64::MAX);
    assert_eq!(r_full.termination, Termination::Completed);
    let pair = case.model.contacts.len() - 1;
    let stopped = scratch.0.join("stopped");
    let r = run(&case, &stopped, 5120);
    assert_eq!(r.termination, Termination::Stopped { step: 5120 });
    // the pair has been in contact before the stop and after it
    assert!(r.contacts[pair].impacts > 0);
    assert!(r_full.contacts[pair].impacts > r.contacts[pair].impacts);
    let r = resume(&case, &stopped);
    assert_eq!(r.contacts, r_full.contacts);
    assert_eq!(r.solver, r_full.solver);
    assert_eq!(r.energy, r_full.energy);
    assert_eq!(read_npz(&full), read_npz(&stopped));
    for file in ["impacts.csv", "blocks.csv", "summary.json", "contacts.csv"] {
        let a = std::fs::read(full.join(file)).unwrap();
        let b = std::fs::read(stopped.join(file)).unwrap();
        assert!(a == b, "{file} differs");
    }
    assert_eq!(
        read_nc(&full.join("results.nc")),
        read_nc(&stopped.join("results.nc"))
    );

    // killed at step 7000 (the files hold more than its checkpoint at 6144 saw): resumed from
    // the checkpoint, the same bits
    let killed = scratch.0.join("killed");
    let died = std::panic::catch_unwind(|| {
        let mut w = Die(7000);
        stream::run(&case.model, &case.settings, &killed, &settings(), 1, &mut w)
    });
    assert!(died.is_err());
    let r = resume(&case, &killed);
    assert_eq!(r.contacts, r_full.contacts);
    assert_eq!(read_npz(&full), read_npz(&killed));
    for file in ["impacts.csv", "blocks.csv", "summary.json", "contacts.csv"] {
        let a = std::fs::read(full.join(file)).unwrap();
        let b = std::fs::read(killed.join(file)).unwrap();
        assert!(a == b, "{file} differs");
    }
}

/// Dies (panics, unwinding through the writers) at a step, as a `kill` after a checkpoint.
struct Die(u64);

impl StreamObserver for Die {
    fn progress(&mut self, p: Progress) -> ControlFlow<()> {
        assert!(p.step < self.0, "killed");
        ControlFlow::Continue(())
    }
}

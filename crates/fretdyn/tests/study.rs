//! Studies: every run of a grid is the base case with its overrides (the row equals a run made
//! by hand), runs in parallel give the rows of runs one at a time, and a study cut midway
//! (rows missing, a row cut in two) is finished without redoing the finished runs.

use std::path::Path;

use fretdyn::apps::study::{Study, StudyOptions};
use fretdyn::integrator::simulation::simulate;

fn write_study(dir: &Path, combine: &str) -> std::path::PathBuf {
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    std::fs::copy(
        examples.join("v1a_oblique_impact.toml"),
        dir.join("v1a.toml"),
    )
    .unwrap();
    let path = dir.join("study.toml");
    std::fs::write(
        &path,
        format!(
            "base = \"v1a.toml\"\ncombine = \"{combine}\"\n\n[[parameters]]\nkey = \"contacts.*.friction.mu\"\nvalues = [0.1, 0.3]\n\n[[parameters]]\nkey = \"tangential.method\"\nvalues = [\"gauss_seidel\", \"active_set\"]\n"
        ),
    )
    .unwrap();
    path
}

fn rows(table: &Path) -> Vec<String> {
    let mut r: Vec<String> = std::fs::read_to_string(table)
        .unwrap()
        .lines()
        .skip(1)
        .map(String::from)
        .collect();
    r.sort_by_key(|l| l.split(',').next().unwrap().parse::<usize>().unwrap());
    r
}

/// The columns of a row without its steps/s (wall-clock dependent).
fn physics(row: &str) -> Vec<String> {
    row.split(',')
        .enumerate()
        .filter(|(i, _)| *i != 5)
        .map(|(_, c)| c.to_string())
        .collect()
}

#[test]
fn a_grid_study_runs_in_parallel_and_resumes_without_redoing_runs() {
    let dir = std::env::temp_dir().join(format!("fretdyn-study-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let study = Study::from_file(&write_study(&dir, "grid")).unwrap();
    let runs = study.runs();
    assert_eq!(runs.len(), 4);

    // one at a time, then 2 at a time: the same rows
    let serial = dir.join("serial.csv");
    assert_eq!(study.execute(&serial, 1, &|_, _| {}).unwrap(), 4);
    let parallel = dir.join("parallel.csv");
    assert_eq!(study.execute(&parallel, 2, &|_, _| {}).unwrap(), 4);
    let (a, b) = (rows(&serial), rows(&parallel));
    assert_eq!(a.len(), 4);
    for (x, y) in a.iter().zip(&b) {
        assert_eq!(physics(x), physics(y));
    }

    // a row is the run of the base case with its overrides, made by hand
    let run = &runs[1]; // mu = 0.1, active_set
    let case = study.case(run).unwrap();
    assert_eq!(case.model.contacts[0].friction.mu_dynamic, 0.1);
    assert_eq!(case.settings.method.name(), "active_set");
    let r = simulate(&case.model, &case.settings).unwrap();
    let cols: Vec<&str> = a[1].split(',').collect();
    assert_eq!(cols[1], "0.1");
    assert_eq!(cols[2], "active_set");
    let wear: f64 = cols[6 + 8].parse().unwrap(); // plane.wear_work_rate
    assert_eq!(wear, r.contacts[0].wear_work_rate);
    // and its standard error by batch means, in `<contact>.wear_work_rate_se`
    let header: Vec<String> = std::fs::read_to_string(&serial)
        .unwrap()
        .lines()
        .next()
        .unwrap()
        .split(',')
        .map(String::from)
        .collect();
    let se = header
        .iter()
        .position(|h| h == "plane.wear_work_rate_se")
        .expect("the column of the standard error");
    assert_eq!(header.len(), cols.len());
    let expected = r.contacts[0].errors.wear_work_rate_se.unwrap();
    assert_eq!(cols[se].parse::<f64>().unwrap(), expected);
    assert!(expected > 0.0);

    // a crash: two rows kept, one cut in two; resumed: only the two missing runs are done
    let text = std::fs::read_to_string(&serial).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let cut = format!(
        "{}\n{}\n{}\n{}",
        lines[0],
        lines[1],
        lines[2],
        &lines[3][..10]
    );
    std::fs::write(&serial, cut).unwrap();
    assert_eq!(study.execute(&serial, 2, &|_, _| {}).unwrap(), 2);
    let resumed = rows(&serial);
    assert_eq!(resumed.len(), 4);
    for (x, y) in resumed.iter().zip(&a) {
        assert_eq!(physics(x), physics(y));
    }
    // nothing left to do
    assert_eq!(study.execute(&serial, 2, &|_, _| {}).unwrap(), 0);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn study_errors_name_the_field() {
    let dir = std::env::temp_dir().join(format!("fretdyn-study-err-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = write_study(&dir, "list");
    let text = std::fs::read_to_string(&path)
        .unwrap()
        .replace("values = [0.1, 0.3]", "values = [0.1, 0.2, 0.3]");
    std::fs::write(&path, text).unwrap();
    let err = Study::from_file(&path).unwrap_err().to_string();
    assert!(
        err.contains("combine") && err.contains("one length"),
        "{err}"
    );
    let text = std::fs::read_to_string(&path)
        .unwrap()
        .replace("contacts.*.friction.mu", "contacts.*.friction.nu");
    std::fs::write(&path, text).unwrap();
    let err = Study::from_file(&path).unwrap_err().to_string();
    // the path as far as it exists, and what is there instead
    assert!(
        err.contains("parameters[0].key: contacts[0].friction.nu: no such key")
            && err.contains("contacts[0].friction has mu"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// Every study shipped in `examples/` builds and checks every run's case as `fretdyn sweep`
/// would before it runs anything (a base case edited later can leave a study invalid:
/// `study_seeds.toml` shortened the run below the base case's statistics blocks).
#[test]
fn every_example_study_checks() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let mut studies = 0;
    for entry in std::fs::read_dir(&dir).expect("examples folder") {
        let path = entry.expect("an entry").path();
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        if !(name.starts_with("study_") && name.ends_with(".toml")) {
            continue;
        }
        let study = Study::from_file(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
        study.check(1).unwrap_or_else(|e| panic!("{name}: {e}"));
        studies += 1;
    }
    assert!(studies >= 5, "the examples' studies: {studies}");
}

/// A study with a table load history read from a file, in its own folder.
fn write_study_with_file(dir: &Path) -> std::path::PathBuf {
    write_study(dir, "grid");
    std::fs::write(dir.join("push.csv"), "0,0\n0.004,1\n").unwrap();
    let text = std::fs::read_to_string(dir.join("v1a.toml")).unwrap()
        + "\n[[loads]]\npoint = \"mass\"\nforce = [1.0, 0.0, 0.0]\nhistory = { type = \"table\", file = \"push.csv\" }\n";
    std::fs::write(dir.join("v1a.toml"), text).unwrap();
    dir.join("study.toml")
}

/// A table is tied to the inputs of its rows: after the base case changed (μ of the base
/// case, not a parameter here), after the content of a file it reads changed, or after a
/// parameter's values changed, running the study into the same table is refused, saying what
/// changed and how to start afresh — the old rows are never presented as the new study's
/// (they were: "0 runs, 4 already in the table"). `fresh` starts afresh.
#[test]
fn a_table_of_other_inputs_is_refused_with_what_changed() {
    let dir = std::env::temp_dir().join(format!("fretdyn-study-stale-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = write_study_with_file(&dir);
    let table = dir.join("study.csv");
    let study = Study::from_file(&path).unwrap();
    assert_eq!(study.execute(&table, 2, &|_, _| {}).unwrap(), 4);
    // unchanged: nothing to do
    assert_eq!(study.execute(&table, 2, &|_, _| {}).unwrap(), 0);
    let refused = |needles: &[&str]| {
        let study = Study::from_file(&path).unwrap();
        let e = study
            .execute(&table, 2, &|_, _| {})
            .unwrap_err()
            .to_string();
        for n in needles {
            assert!(e.contains(n), "{n:?} not in: {e}");
        }
        assert!(!e.contains('\n'), "{e}");
    };
    // the base case: its normal stiffness
    let base = std::fs::read_to_string(dir.join("v1a.toml")).unwrap();
    std::fs::write(
        dir.join("v1a.toml"),
        base.replace("stiffness = 1e6", "stiffness = 2e6"),
    )
    .unwrap();
    refused(&[
        "4 of its 4 rows",
        "contacts.0.normal.stiffness: 1000000.0 → 2000000.0",
        "--fresh",
    ]);
    std::fs::write(dir.join("v1a.toml"), &base).unwrap();
    // the content of the load table the case reads (its name unchanged)
    std::fs::write(dir.join("push.csv"), "0,0\n0.004,2\n").unwrap();
    refused(&["the content of push.csv changed"]);
    std::fs::write(dir.join("push.csv"), "0,0\n0.004,1\n").unwrap();
    assert_eq!(study.execute(&table, 2, &|_, _| {}).unwrap(), 0);
    // a parameter's values: run 2 and 3 now have another μ
    let text = std::fs::read_to_string(&path).unwrap();
    std::fs::write(&path, text.replace("[0.1, 0.3]", "[0.1, 0.4]")).unwrap();
    refused(&[
        "2 of its 4 rows",
        "run 2: contacts.*.friction.mu = 0.3 in the table, 0.4 now",
    ]);
    // afresh
    let study = Study::from_file(&path).unwrap();
    let options = StudyOptions {
        jobs: 2,
        fresh: true,
        stop: None,
    };
    let outcome = study.run_checked(&table, &options, &|_, _| {}).unwrap();
    assert_eq!((outcome.done, outcome.already), (4, 0));
    assert_eq!(rows(&table).len(), 4);
    assert!(rows(&table)[2].contains(",0.4,"));
    std::fs::remove_dir_all(&dir).ok();
}

/// One table, one study at a time: a second open of the table is refused while the first
/// holds it; a row made elsewhere from other inputs (a Dask worker with another file), or of
/// a run already in the table, is refused; a table with a run twice (two studies that wrote
/// it at once) is refused; percentiles need every run's row.
#[test]
fn a_table_is_written_by_one_study_and_holds_each_run_once() {
    let dir = std::env::temp_dir().join(format!("fretdyn-study-lock-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = write_study_with_file(&dir);
    let text = std::fs::read_to_string(&path).unwrap()
        + "\n[percentiles]\nstatistics = [\"wear_work_rate\"]\n";
    std::fs::write(&path, text).unwrap();
    let study = Study::from_file(&path).unwrap();
    let table = dir.join("study.csv");
    let mut open = study.open_table(&table, false).unwrap();
    let e = study.open_table(&table, false).unwrap_err().to_string();
    assert!(
        e.contains("a study (process") && e.contains("is writing this table"),
        "{e}"
    );
    let runs = study.runs();
    let row = study.run_row(&runs[1]).unwrap();
    open.append(&row).unwrap();
    assert_eq!(open.pending(), [0, 2, 3]);
    // the same run again
    let e = open.append(&row).unwrap_err().to_string();
    assert!(e.contains("run 1 has a row already"), "{e}");
    // a row computed from another load table
    std::fs::write(dir.join("push.csv"), "0,0\n0.004,3\n").unwrap();
    let foreign = Study::from_file(&path).unwrap().run_row(&runs[2]).unwrap();
    std::fs::write(dir.join("push.csv"), "0,0\n0.004,1\n").unwrap();
    let e = open.append(&foreign).unwrap_err().to_string();
    assert!(e.contains("run 2 was computed from other inputs"), "{e}");
    // percentiles of the incomplete table
    let e = study.percentiles(&table).unwrap_err().to_string();
    assert!(e.contains("1 of the study's 4 runs"), "{e}");
    drop(open);
    assert_eq!(study.execute(&table, 2, &|_, _| {}).unwrap(), 3);
    assert!(study.percentiles(&table).unwrap().is_some());
    // complete, the table lists its runs in order (run 1 was appended first, the others as
    // two threads finished them)
    let order: Vec<String> = std::fs::read_to_string(&table)
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| l.split(',').next().unwrap().to_string())
        .collect();
    assert_eq!(order, ["0", "1", "2", "3"]);
    // a run twice
    let text = std::fs::read_to_string(&table).unwrap();
    std::fs::write(&table, format!("{text}{row}\n")).unwrap();
    let e = study
        .execute(&table, 2, &|_, _| {})
        .unwrap_err()
        .to_string();
    assert!(e.contains("run 1 is in the table twice"), "{e}");
    let e = study.percentiles(&table).unwrap_err().to_string();
    assert!(e.contains("run 1 is in the table twice"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

//! Studies: every run of a grid is the base case with its overrides (the row equals a run made
//! by hand), runs in parallel give the rows of runs one at a time, and a study cut midway
//! (rows missing, a row cut in two) is finished without redoing the finished runs.

use std::path::Path;

use fretdyn::apps::study::Study;
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

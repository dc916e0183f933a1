//! `fretdyn life` (docs/WEAR.md) as a user meets it: a mass sliding on a bar at a constant
//! wear rate, its life.csv against the closed form, scars.csv, life.png, the convergence
//! runs of `--halvings`; one-line errors naming the file and the field (exit code 2).

mod common;
use std::path::Path;
use std::process::{Command, Stdio};

use common::{Scratch, fretdyn};

/// A mass pressed on a bar (10 N) sliding under it at 1 cm/s, μ = 0.3: `W = 0.03 W`.
const CASE: &str = concat!(
    "\ntitle = \"sliding mass\"\n",
    include_str!("../../fretdyn/tests/fixtures/sliding_mass.toml"),
    r#"wear = { tube = { law = "archard", coefficient = 2e-15 }, support = { law = "archard", coefficient = 1e-15 }, scar = { type = "flat_bar", width = 0.02, tube_radius = 0.0095 } }
[statistics]
t_start = 1.0
[life]
target_years = 10.0
max_depth_change = 0.2
criterion_depth = 2e-4
"#
);

/// Circular segment of height `u` in a circle of radius `r`.
fn segment(r: f64, u: f64) -> f64 {
    r * r * ((r - u) / r).acos() - (r - u) * (2.0 * r * u - u * u).sqrt()
}

#[test]
fn a_life_writes_its_depths_against_time_and_converges_under_halvings() {
    let s = Scratch::new("ok");
    std::fs::write(s.0.join("case.toml"), CASE).unwrap();
    let out = fretdyn(&["life", "case.toml", "-o", "out", "--halvings", "1"], &s.0);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("bar: tube depth"), "{stdout}");
    // the depths in µm under their contact's name; the last row's is the final depth printed
    // after the life, read back from life.csv's last row
    let header = stdout
        .lines()
        .find(|l| l.contains("tube depth (µm):"))
        .unwrap_or_else(|| panic!("{stdout}"));
    assert_eq!(header.split_whitespace().last(), Some("bar"), "{header}");
    let csv = std::fs::read_to_string(s.0.join("out/life.csv")).unwrap();
    let last_csv: Vec<&str> = csv.lines().last().unwrap().split(',').collect();
    let depth_column = csv
        .lines()
        .next()
        .unwrap()
        .split(',')
        .position(|c| c == "bar.tube_depth")
        .unwrap();
    let depth_um = last_csv[depth_column].parse::<f64>().unwrap() * 1e6;
    let final_line = stdout
        .lines()
        .find(|l| l.starts_with("bar: tube depth "))
        .unwrap();
    let printed: f64 = final_line["bar: tube depth ".len()..]
        .split(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!(
        (printed / depth_um - 1.0).abs() < 1e-3 && final_line.contains(" µm (fixed gap "),
        "{final_line} against {depth_um} µm"
    );
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(header[0], "time_years");
    let at = |name: &str| header.iter().position(|c| *c == name).unwrap();
    let rows: Vec<Vec<f64>> = lines
        .map(|l| {
            l.split(',')
                .map(|x| x.parse().unwrap_or(f64::NAN))
                .collect()
        })
        .collect();
    assert!(rows.len() > 3);
    let year = 365.25 * 86400.0;
    let w = 0.3 * 10.0 * 0.01;
    for r in &rows[1..] {
        // w A_R(d) = K W t on the tube
        let d = r[at("bar.tube_depth")];
        let v = 2e-15 * w * r[0] * year;
        assert!((0.02 * segment(0.0095, d) - v).abs() < 1e-6 * v, "{d}");
        assert!(r[at("bar.wear_work_rate_se")] >= 0.0);
    }
    assert!((rows[rows.len() - 1][0] - 10.0).abs() < 1e-9);
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(s.0.join("out/life.json")).unwrap()).unwrap();
    assert_eq!(json["results"]["end"]["status"], "completed");
    assert!(json["results"]["time_to_criterion"][0].as_f64().unwrap() > 0.0);
    let scars = std::fs::read_to_string(s.0.join("out/scars.csv")).unwrap();
    assert!(scars.starts_with(
        "contact,kind,bin,angle_deg,clearance_increase,tube_depth,support_depth\nbar,plane,0,,"
    ));
    assert!(std::fs::metadata(s.0.join("out/life.png")).unwrap().len() > 10_000);
    let conv = std::fs::read_to_string(s.0.join("out/convergence.csv")).unwrap();
    assert_eq!(conv.lines().count(), 3, "{conv}");
    assert!(conv.starts_with("max_depth_change,life_steps,life_end,end_years,bar.tube_depth\n"));
    // a constant rate: the depth at the end does not depend on the life step
    let ends: Vec<f64> = conv
        .lines()
        .skip(1)
        .map(|l| {
            let cells: Vec<&str> = l.split(',').collect();
            assert_eq!((cells[2], cells[3]), ("completed", "1e1"), "{l}");
            cells[4].parse().unwrap()
        })
        .collect();
    assert!((ends[0] - ends[1]).abs() < 1e-6 * ends[0]);
    // converged: no warning that the last halving moved the depth
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("not converged"), "{stderr}");
    assert!(
        std::fs::metadata(s.0.join("out/convergence.png"))
            .unwrap()
            .len()
            > 10_000
    );
}

/// Without `-o`, a life writes in `life/` inside the folder `fretdyn run` of the same case
/// writes in: a case named `*_life.toml` gets no doubled `_life_life` suffix, and its run and
/// its life, in either order, leave each other's files in place.
#[test]
fn a_life_without_a_folder_writes_beside_the_run_of_its_case() {
    let s = Scratch::new("default-folder");
    // a short life: 2 life steps of the 1.5 s windows
    let case = CASE.replace("max_depth_change = 0.2", "max_depth_change = 1.0");
    std::fs::write(s.0.join("bar_life.toml"), case).unwrap();
    let out = fretdyn(&["life", "bar_life.toml", "--no-plots"], &s.0);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let life = s.0.join("fretdyn_results/bar_life/life");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains(&format!(
            "wrote {}",
            Path::new("fretdyn_results/bar_life/life").display()
        )),
        "{stdout}"
    );
    let table = std::fs::read_to_string(life.join("life.csv")).unwrap();
    assert!(!s.0.join("fretdyn_results/bar_life_life").exists());
    let out = fretdyn(&["run", "bar_life.toml", "--quiet", "--no-plots"], &s.0);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(s.0.join("fretdyn_results/bar_life/summary.json").exists());
    assert_eq!(
        std::fs::read_to_string(life.join("life.csv")).unwrap(),
        table,
        "the run changed the life's table"
    );
    let out = fretdyn(&["life", "bar_life.toml", "--no-plots"], &s.0);
    assert!(out.status.success());
    assert!(s.0.join("fretdyn_results/bar_life/summary.json").exists());
    assert!(life.join("life.json").exists());
}

#[test]
fn life_errors_are_one_line_naming_the_file_and_the_field() {
    let s = Scratch::new("errors");
    for (text, needle) in [
        (
            CASE.replace("target_years = 10.0", "target_years = 0.0"),
            "life.target_years",
        ),
        (
            CASE.replace(
                "[life]\ntarget_years = 10.0\nmax_depth_change = 0.2\ncriterion_depth = 2e-4\n",
                "",
            ),
            "life: the case has no [life] section",
        ),
        (
            CASE.replace(
                "type = \"flat_bar\"",
                "type = \"drilled_hole\", thickness = 0.02, shape = \"crescent\"",
            )
            .replace(", width = 0.02", ""),
            "contacts[0].wear.scar.type",
        ),
    ] {
        std::fs::write(s.0.join("bad.toml"), text).unwrap();
        let out = fretdyn(&["life", "bad.toml", "-o", "out"], &s.0);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{stderr}");
        assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
        assert!(stderr.starts_with("error: bad.toml: "), "{stderr}");
        assert!(stderr.contains(needle), "'{needle}' not in {stderr}");
    }
}

/// The outputs of a life without its wall-clock time.
fn outputs(dir: &Path) -> (String, String, serde_json::Value) {
    let read = |name: &str| std::fs::read_to_string(dir.join(name)).unwrap();
    let mut json: serde_json::Value = serde_json::from_str(&read("life.json")).unwrap();
    json["results"]["wall_time"] = serde_json::Value::Null;
    (read("life.csv"), read("scars.csv"), json)
}

/// `fretdyn life` in `cwd` with `args`, started in the background.
fn spawn_life(args: &[&str], cwd: &Path) -> std::process::Child {
    Command::new(env!("CARGO_BIN_EXE_fretdyn"))
        .arg("life")
        .args(args)
        .current_dir(cwd)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

/// Waits until the life writing in `dir` has a checkpoint newer than `after` (it must still
/// be running).
fn wait_for_checkpoint(
    child: &mut std::process::Child,
    dir: &Path,
    after: Option<std::time::SystemTime>,
) {
    let start = std::time::Instant::now();
    loop {
        let m = std::fs::metadata(dir.join("life_checkpoint.bin")).and_then(|m| m.modified());
        if let Ok(m) = m
            && after.is_none_or(|a| m > a)
        {
            return;
        }
        assert!(child.try_wait().unwrap().is_none(), "the life ended first");
        assert!(start.elapsed().as_secs() < 300, "no checkpoint");
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
}

/// A life stopped by SIGTERM (it stops after a checkpoint and says how to continue), resumed,
/// killed by SIGKILL (the last checkpoint, inside a window: `--checkpoint-every` is short),
/// resumed again to its end, gives the outputs of an uninterrupted life bit for bit. A second
/// life on the folder while one writes there is refused; a resume after the case changed too.
#[test]
fn a_life_killed_and_resumed_is_the_uninterrupted_life() {
    let s = Scratch::new("resume");
    // windows of 20 s of 1e-4 s steps (~0.2 s of computing each)
    let case = CASE.replace("duration = 1.5", "duration = 20.0");
    std::fs::write(s.0.join("case.toml"), &case).unwrap();
    let out = fretdyn(&["life", "case.toml", "-o", "whole", "--no-plots"], &s.0);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let whole = outputs(&s.0.join("whole"));

    let fast = ["--no-plots", "--checkpoint-every", "0.02"];
    let mut child = spawn_life(&[&["case.toml", "-o", "cut"][..], &fast].concat(), &s.0);
    wait_for_checkpoint(&mut child, &s.0.join("cut"), None);
    // a second life on the same folder, while the first writes there
    let out = fretdyn(&["life", "case.toml", "-o", "cut", "--no-plots"], &s.0);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("another fretdyn life (process"), "{stderr}");
    // SIGTERM: stops after a checkpoint, with the way to continue
    Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("interrupted at") && stderr.contains("fretdyn life --resume cut"),
        "{stderr}"
    );
    // resumed, then killed with SIGKILL after a later checkpoint
    let before = std::fs::metadata(s.0.join("cut/life_checkpoint.bin"))
        .unwrap()
        .modified()
        .unwrap();
    let mut child = spawn_life(&[&["--resume", "cut"][..], &fast].concat(), &s.0);
    wait_for_checkpoint(&mut child, &s.0.join("cut"), Some(before));
    std::thread::sleep(std::time::Duration::from_millis(30));
    Command::new("kill")
        .args(["-9", &child.id().to_string()])
        .status()
        .unwrap();
    child.wait().unwrap();
    // to the end
    let out = fretdyn(&[&["life", "--resume", "cut"][..], &fast].concat(), &s.0);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(String::from_utf8_lossy(&out.stdout).contains("resumed from its checkpoint at"));
    assert_eq!(outputs(&s.0.join("cut")), whole);
    // over: nothing left to resume
    let out = fretdyn(&["life", "--resume", "cut"], &s.0);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("no checkpoint to resume"), "{stderr}");

    // a resume after the case changed is refused
    let mut child = spawn_life(&[&["case.toml", "-o", "changed"][..], &fast].concat(), &s.0);
    wait_for_checkpoint(&mut child, &s.0.join("changed"), None);
    Command::new("kill")
        .args(["-9", &child.id().to_string()])
        .status()
        .unwrap();
    child.wait().unwrap();
    std::fs::write(s.0.join("case.toml"), case.replace("mu = 0.3", "mu = 0.4")).unwrap();
    let out = fretdyn(&["life", "--resume", "changed"], &s.0);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("changed since the life in changed started"),
        "{stderr}"
    );
}

/// `--halvings`: a refined life that does not reach the target (here its life steps exceed
/// `max_steps`) is marked in `convergence.csv` (`life_end`, the years it reached), not written
/// as if it had, and the command fails naming it; more than 10 halvings are refused (32 wrapped
/// the life step to 0 life steps and depth 0).
#[test]
fn halvings_mark_the_lives_that_did_not_reach_the_target() {
    let s = Scratch::new("halvings");
    std::fs::write(
        s.0.join("case.toml"),
        CASE.replace(
            "criterion_depth = 2e-4",
            "criterion_depth = 2e-4\nmax_steps = 50",
        ),
    )
    .unwrap();
    let out = fretdyn(
        &[
            "life",
            "case.toml",
            "-o",
            "out",
            "--no-plots",
            "--halvings",
            "1",
        ],
        &s.0,
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("the convergence check is incomplete: max_depth_change = 0.1 (step_limit)"),
        "{stderr}"
    );
    let conv = std::fs::read_to_string(s.0.join("out/convergence.csv")).unwrap();
    let rows: Vec<Vec<&str>> = conv
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    assert_eq!(rows[0][2], "completed");
    assert_eq!((rows[1][1], rows[1][2]), ("50", "step_limit"));
    assert!(rows[1][3].parse::<f64>().unwrap() < 10.0);
    for n in ["11", "32"] {
        let out = fretdyn(&["life", "case.toml", "-o", "out", "--halvings", n], &s.0);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{stderr}");
        assert!(
            stderr.contains("--halvings") && stderr.contains("0..=10"),
            "{stderr}"
        );
    }
}

/// A full disk while the life's tables are written (a file-size limit, `ulimit -f`, as a full
/// disk: writes fail with EFBIG) never leaves a truncated table under its final name: each
/// is written to a temporary name, then renamed. `life.json`, the largest, fails here; it
/// used to be left cut in the middle.
#[test]
fn a_full_disk_never_leaves_a_truncated_life_table() {
    let s = Scratch::new("full");
    std::fs::write(
        s.0.join("case.toml"),
        CASE.replace("max_depth_change = 0.2", "max_depth_change = 0.05"),
    )
    .unwrap();
    // 100 blocks of 512 bytes: life.json of this life is ~78 kB, its checkpoint and life.csv
    // at most ~31 kB
    let out = Command::new("sh")
        .args([
            "-c",
            "ulimit -f 100; trap '' XFSZ; exec \"$0\" life case.toml -o out --no-plots",
            env!("CARGO_BIN_EXE_fretdyn"),
        ])
        .current_dir(&s.0)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("life.json"), "{stderr}");
    for name in ["life.csv", "scars.csv", "life.json"] {
        let path = s.0.join("out").join(name);
        if let Ok(text) = std::fs::read_to_string(&path) {
            match name {
                "life.json" => {
                    serde_json::from_str::<serde_json::Value>(&text).expect("complete JSON");
                }
                _ => assert!(text.ends_with('\n'), "{name} cut"),
            }
        }
    }
    assert!(!s.0.join("out/life.json").exists());
}

//! An output folder holds one run: the files of an earlier run are
//! cleared (a user's own are kept), two runs never write into one folder
//! at once, and no name in a model file reaches outside the folder.

use std::path::Path;

use crate::common::*;

/// A quick planar model with a free body, whose plot is named after it.
const BALL: &str = r#"
name = "ball"
gravity = [0.0, -9.81, 0.0]
[simulate]
t_end = 0.05
[[body]]
name = "BODY"
shape = "sphere"
radius = 0.05
mass = 1.0
position = [0.0, 0.0, 0.0]
"#;

fn files(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| !n.starts_with(".softarm"))
        .collect();
    names.sort();
    names
}

#[test]
fn a_run_clears_the_files_of_the_run_before_it_and_keeps_the_users() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("ball.toml"), BALL.replace("BODY", "ball")).unwrap();
    std::fs::write(dir.path().join("other.toml"), BALL.replace("BODY", "puck")).unwrap();
    let run = |model: &str, extra: &[&str]| {
        let mut args = vec!["simulate", model, "--out", "o", "--quiet"];
        args.extend(extra);
        let out = softarm(&args, dir.path());
        assert!(out.status.success(), "{}", stderr(&out));
    };
    run("ball.toml", &["--shape-points", "4"]);
    let o = dir.path().join("o");
    std::fs::write(o.join("notes.txt"), "mine").unwrap();
    assert_eq!(
        files(&o),
        [
            "ball.png",
            "notes.txt",
            "shape.csv",
            "summary.json",
            "trajectory.csv"
        ]
    );
    // Another model, no shape: its body's plot, not the first one's, and
    // no shape.csv left from before.
    run("other.toml", &["--shape-points", "0"]);
    assert_eq!(
        files(&o),
        ["notes.txt", "puck.png", "summary.json", "trajectory.csv"]
    );
    assert_eq!(
        std::fs::read_to_string(o.join("notes.txt")).unwrap(),
        "mine"
    );
}

#[test]
fn two_runs_never_write_into_one_folder_at_once() {
    let dir = tempfile::tempdir().unwrap();
    // A run long enough to be caught writing: it holds the folder until
    // it is killed.
    let mut first = long_run(dir.path(), &[]);
    let second = softarm(&["simulate", "chain", "--out", "o", "--quiet"], dir.path());
    first.kill().unwrap();
    first.wait().unwrap();
    assert!(!second.status.success());
    assert!(
        stderr(&second).contains("another softarm run is writing into"),
        "{}",
        stderr(&second)
    );
    // What the folder holds is the killed run's: the rows it wrote as it
    // went (a few at its 18 s output step), no summary; nothing of the
    // refused run's 501 rows.
    let rows = std::fs::read_to_string(dir.path().join("o/trajectory.csv")).unwrap();
    assert!(rows.lines().count() < 100, "{} rows", rows.lines().count());
    assert!(!dir.path().join("o/summary.json").exists());
    // Once the first run is gone (however it ended), the folder is free.
    let third = softarm(&["simulate", "chain", "--out", "o", "--quiet"], dir.path());
    assert!(third.status.success(), "{}", stderr(&third));
    assert!(dir.path().join("o/trajectory.csv").exists());
}

#[test]
fn names_that_become_file_names_cannot_leave_the_folder() {
    let dir = tempfile::tempdir().unwrap();
    let escaped = dir.path().join("escaped");
    for (text, key) in [
        (
            BALL.replace("name = \"ball\"", "name = \"../escaped\""),
            "name",
        ),
        (
            BALL.replace("BODY", &escaped.join("evil").display().to_string()),
            "body.",
        ),
        (BALL.replace("BODY", "a b"), "body.a b.name"),
    ] {
        std::fs::write(dir.path().join("m.toml"), &text).unwrap();
        let out = softarm(
            &["simulate", "m.toml", "--out", "run/o", "--quiet"],
            dir.path(),
        );
        assert!(!out.status.success());
        let err = stderr(&out);
        assert!(
            err.contains(key) && err.contains("letters, digits"),
            "{err}"
        );
        assert!(!dir.path().join("run").exists(), "{err}");
        assert!(!escaped.exists());
    }
}

#[test]
fn an_output_folder_that_is_a_file_is_refused_clearly() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("o"), "a file").unwrap();
    let out = softarm(&["simulate", "chain", "--out", "o", "--quiet"], dir.path());
    assert!(!out.status.success());
    assert!(stderr(&out).contains("is a file"), "{}", stderr(&out));
    assert_eq!(
        std::fs::read_to_string(dir.path().join("o")).unwrap(),
        "a file"
    );
}

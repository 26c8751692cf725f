//! Ctrl-C and SIGTERM stop a run with what it computed written: the
//! trajectory to the time reached, a summary that says so, the shell's
//! exit code; and that trajectory is the uninterrupted run's over the same
//! span.

use std::time::Duration;

use crate::common::*;

/// trajectory.csv's rows as numbers.
fn rows(path: &std::path::Path) -> Vec<Vec<f64>> {
    let text = std::fs::read_to_string(path).unwrap();
    text.lines()
        .skip(1)
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect()
}

#[cfg(unix)]
fn stopped_by(signal: i32, name: &str, code: i32) {
    let dir = tempfile::tempdir().unwrap();
    // Once the run holds its folder it is integrating; let it go on a
    // little (how far does not matter: any time reached is checked).
    let run = long_run(dir.path(), &["--output-dt", "0.01"]);
    std::thread::sleep(Duration::from_millis(500));
    // SAFETY: a plain kill(2) of the child this test started.
    assert_eq!(unsafe { libc::kill(run.id() as i32, signal) }, 0);
    let out = run.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(code), "{err}");
    assert!(err.contains(&format!("stopped by {name}")), "{err}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("o/summary.json")).unwrap())
            .unwrap();
    assert_eq!(summary["status"], "interrupted", "{summary}");
    let reached = summary["failure"]["t_reached"].as_f64().unwrap();
    let stopped = rows(&dir.path().join("o/trajectory.csv"));
    assert!(!stopped.is_empty());
    assert!(stopped.iter().all(|r| r[0] <= reached + 1e-12));
    assert!(stopped.iter().flatten().all(|v| v.is_finite()));
    // The same span uninterrupted: the rows agree to the solver's
    // tolerance (the step sizes near the end differ, nothing else).
    if reached < 0.05 {
        return;
    }
    let t_end = format!("{reached}");
    let whole = softarm(
        &["simulate", "soft_finger", "--output-dt", "0.01", "--quiet"]
            .iter()
            .chain(&["--t-end", t_end.as_str(), "--out", "p"])
            .copied()
            .collect::<Vec<_>>(),
        dir.path(),
    );
    assert!(whole.status.success(), "{}", stderr(&whole));
    let whole = rows(&dir.path().join("p/trajectory.csv"));
    let mut compared = 0;
    for r in stopped.iter().filter(|r| r[0] < reached - 0.02) {
        let w = whole
            .iter()
            .find(|w| (w[0] - r[0]).abs() < 1e-9)
            .unwrap_or_else(|| panic!("no row at t = {} in the whole run", r[0]));
        for (c, (a, b)) in r.iter().zip(w).enumerate() {
            assert!(
                (a - b).abs() <= 1e-4 * (1e-3 + b.abs()),
                "t = {}, column {c}: {a} stopped, {b} whole",
                r[0]
            );
        }
        compared += 1;
    }
    assert!(compared > 0 || reached < 0.03);
}

#[cfg(unix)]
#[test]
fn ctrl_c_stops_a_run_with_its_trajectory_written() {
    stopped_by(libc::SIGINT, "SIGINT", 130);
}

#[cfg(unix)]
#[test]
fn sigterm_stops_a_run_with_its_trajectory_written() {
    stopped_by(libc::SIGTERM, "SIGTERM", 143);
}

/// `--max-wall` stops a run as a signal does, after that much wall time.
fn stopped_by_the_wall_clock(seconds: &str) -> (std::process::Output, serde_json::Value) {
    let dir = tempfile::tempdir().unwrap();
    let out = softarm(
        &[
            "simulate",
            "soft_finger",
            "--t-end",
            "9000",
            "--output-dt",
            "0.1",
            "--max-wall",
            seconds,
            "--out",
            "o",
        ],
        dir.path(),
    );
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("o/summary.json")).unwrap())
            .unwrap();
    (out, summary)
}

#[test]
fn max_wall_stops_a_run_with_its_trajectory_written() {
    let (out, summary) = stopped_by_the_wall_clock("1");
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("stopped by --max-wall"),
        "{}",
        stderr(&out)
    );
    assert_eq!(summary["status"], "interrupted");
    let reached = summary["failure"]["t_reached"].as_f64().unwrap();
    assert!(reached > 0.0 && reached < 1e6, "{reached}");
    let dir = tempfile::tempdir().unwrap();
    let bad = softarm(&["simulate", "chain", "--max-wall", "0"], dir.path());
    assert!(stderr(&bad).contains("--max-wall must be a positive number"));
}

/// A run without a terminal says where it is every ten seconds.
#[test]
#[ignore = "runs 11 s: the long checks"]
fn a_long_run_without_a_terminal_reports_its_progress_on_plain_lines() {
    let (out, _) = stopped_by_the_wall_clock("11");
    let err = stderr(&out);
    let line = err
        .lines()
        .find(|l| l.starts_with("soft_finger: t = ") && l.contains("of 9000 s"))
        .unwrap_or_else(|| panic!("no progress line in {err}"));
    assert!(line.contains("s wall"), "{line}");
}

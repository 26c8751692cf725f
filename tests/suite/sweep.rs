//! `softarm sweep` against closed forms: the cantilever's frequencies
//! scale as sqrt(E) across a log range of E (the linear modes about the
//! straight rod, no gravity), a tip mass lowers them, every combination of
//! a grid is a row, and a run that fails is a row with its failure while
//! the sweep goes on.

use crate::common::*;

fn read_csv(path: &std::path::Path) -> Vec<Vec<String>> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(|l| {
            l.split(',')
                .map(|c| c.trim_matches('"').to_string())
                .collect()
        })
        .collect()
}

#[test]
fn a_modes_sweep_over_e_scales_the_frequencies_as_its_square_root() {
    let dir = tempfile::tempdir().unwrap();
    let out = softarm(
        &[
            "sweep",
            "cantilever",
            "--run",
            "modes",
            "--set",
            "gravity=[0,0,0]",
            "--vary",
            "segment.0.youngs_modulus=log:1e5:1e7:3",
            "--vary",
            "tip.mass=0,0.01,-1",
            "--out",
            "s",
        ],
        dir.path(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let rows = read_csv(&dir.path().join("s/sweep.csv"));
    let head = &rows[0];
    let col = |name: &str| {
        head.iter()
            .position(|h| h == name)
            .unwrap_or_else(|| panic!("{name} in {head:?}"))
    };
    let (e, m, status, f1, f2) = (
        col("segment.0.youngs_modulus"),
        col("tip.mass"),
        col("status"),
        col("f1_hz"),
        col("f2_hz"),
    );
    assert_eq!(rows.len(), 1 + 9, "a row per combination");
    assert_eq!(rows[1][e], "100000");
    assert_eq!(rows[4][e], "1000000");
    // The failed runs (a negative tip mass) are rows with their reason.
    for r in rows[1..].iter().filter(|r| r[m] == "-1") {
        assert!(
            r[status].starts_with("failed:") && r[status].contains("tip.mass"),
            "{r:?}"
        );
    }
    let ok: Vec<&Vec<String>> = rows[1..].iter().filter(|r| r[status] == "ok").collect();
    assert_eq!(ok.len(), 6);
    let num = |s: &String| s.parse::<f64>().unwrap();
    for mass in ["0", "0.01"] {
        let runs: Vec<_> = ok.iter().filter(|r| r[m] == mass).collect();
        for r in &runs[1..] {
            for c in [f1, f2] {
                let ratio = num(&r[c]) / num(&runs[0][c]);
                let want = (num(&r[e]) / num(&runs[0][e])).sqrt();
                assert_close(
                    ratio,
                    want,
                    1e-9,
                    0.0,
                    &format!("f ratio at E = {}, m = {mass}", r[e]),
                );
            }
        }
    }
    // A tip mass lowers every frequency.
    for (a, b) in ok
        .iter()
        .filter(|r| r[m] == "0")
        .zip(ok.iter().filter(|r| r[m] == "0.01"))
    {
        assert!(num(&b[f1]) < num(&a[f1]), "{a:?} vs {b:?}");
    }
    assert!(dir.path().join("s/sweep.png").exists(), "the plot");
    assert!(
        dir.path().join("s/run_0000/modes.json").exists(),
        "each run's result"
    );
}

#[test]
fn a_simulate_sweep_writes_each_runs_summary_and_its_figures() {
    let dir = tempfile::tempdir().unwrap();
    let out = softarm(
        &[
            "sweep",
            "double_pendulum",
            "--t-end",
            "0.2",
            "--q0",
            "0.3,0",
            "--vary",
            "gravity=[0,-9.81,0],[0,-1.62,0]",
            "--out",
            "s",
        ],
        dir.path(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let rows = read_csv(&dir.path().join("s/sweep.csv"));
    // (The bracketed values contain commas: two runs, not six.)
    assert_eq!(rows.len(), 3, "{rows:?}");
    for i in 0..2 {
        let summary = dir.path().join(format!("s/run_{i:04}/summary.json"));
        let s: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(summary).unwrap()).unwrap();
        assert_eq!(s["status"], "ok");
    }
    let bad = softarm(
        &["sweep", "double_pendulum", "--vary", "gravity=lin:1:2"],
        dir.path(),
    );
    assert!(!bad.status.success());
    assert!(stderr(&bad).contains("lin:a:b:n"), "{}", stderr(&bad));
}

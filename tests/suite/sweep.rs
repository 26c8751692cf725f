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
            "tip.mass=0,0.01",
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
    assert_eq!(rows.len(), 1 + 6, "a row per combination");
    assert_eq!(rows[1][e], "100000");
    assert_eq!(rows[3][e], "1000000");
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
                    format_args!("f ratio at E = {}, m = {mass}", r[e]),
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

#[test]
fn a_varied_value_is_checked_before_any_run_as_set_checks_it() {
    let dir = tempfile::tempdir().unwrap();
    for (vary, says) in [
        ("tip.mass=0,-1", "tip.mass"),
        ("nosuch.key=1,2", "nosuch"),
        ("tip.mass=a,b", "tip.mass"),
    ] {
        let out = softarm(
            &[
                "sweep",
                "cantilever",
                "--run",
                "static",
                "--vary",
                vary,
                "--out",
                "s",
            ],
            dir.path(),
        );
        assert!(!out.status.success(), "{vary}");
        let err = stderr(&out);
        assert!(err.contains("--vary"), "{err}");
        assert!(err.contains(says), "{vary}: {err}");
        assert!(!dir.path().join("s").exists(), "{vary}: nothing written");
    }
}

#[test]
fn a_sweep_whose_runs_failed_exits_non_zero_with_every_row() {
    // Each value is valid alone; together the hole is wider than the tube.
    let dir = tempfile::tempdir().unwrap();
    let out = softarm(
        &[
            "sweep",
            "cantilever",
            "--run",
            "static",
            "--vary",
            "segment.0.outer_radius=0.01,0.004",
            "--vary",
            "segment.0.inner_radius=0.0,0.005",
            "--out",
            "s",
        ],
        dir.path(),
    );
    assert!(!out.status.success(), "{}", stderr(&out));
    let rows = read_csv(&dir.path().join("s/sweep.csv"));
    assert_eq!(rows.len(), 1 + 4);
    let status = rows[0].iter().position(|h| h == "status").unwrap();
    let failed: Vec<_> = rows[1..].iter().filter(|r| r[status] != "ok").collect();
    assert_eq!(failed.len(), 1, "{rows:?}");
    assert!(failed[0][status].contains("inner_radius"), "{failed:?}");
}

#[test]
fn a_grid_is_counted_before_it_is_made() {
    let dir = tempfile::tempdir().unwrap();
    for (varies, says) in [
        (
            vec!["tip.mass=lin:0:1:1000000000000"],
            "a range gives at most",
        ),
        (
            vec![
                "tip.mass=lin:0:1:100000",
                "segment.0.length=lin:0.1:0.2:100000",
            ],
            "more than the",
        ),
        (
            vec!["tip.mass=lin:0:1:200", "segment.0.length=lin:0.1:0.2:100"],
            "only with --yes",
        ),
    ] {
        let mut args = vec!["sweep", "cantilever", "--run", "static", "--out", "s"];
        for v in &varies {
            args.extend(["--vary", v]);
        }
        let out = softarm(&args, dir.path());
        assert!(!out.status.success(), "{varies:?}");
        assert!(stderr(&out).contains(says), "{varies:?}: {}", stderr(&out));
        assert!(!dir.path().join("s").exists());
    }
}

#[test]
fn a_resumed_sweep_redoes_only_the_runs_that_did_not_end() {
    let dir = tempfile::tempdir().unwrap();
    let sweep = |resume: bool| {
        let mut args = vec![
            "sweep",
            "cantilever",
            "--run",
            "static",
            "--vary",
            "tip.mass=0,0.01,0.02",
            "--out",
            "s",
        ];
        if resume {
            args.push("--resume");
        }
        let out = softarm(&args, dir.path());
        assert!(out.status.success(), "{}", stderr(&out));
        // Every column but the wall times.
        let rows = read_csv(&dir.path().join("s/sweep.csv"));
        let wall = rows[0].iter().position(|h| h == "wall_s").unwrap();
        rows.into_iter()
            .map(|mut r| {
                r.remove(wall);
                r
            })
            .collect::<Vec<_>>()
    };
    let whole = sweep(false);
    let run = |i: usize, f: &str| dir.path().join(format!("s/run_{i:04}/{f}"));
    // Run 1 as if stopped before it ended; run 0's result marked.
    std::fs::remove_file(run(1, "sweep-row.json")).unwrap();
    std::fs::remove_file(run(1, "static.json")).unwrap();
    std::fs::write(run(0, "static.json"), "kept").unwrap();
    let resumed = sweep(true);
    assert_eq!(resumed, whole, "the same sweep.csv");
    assert_eq!(
        std::fs::read_to_string(run(0, "static.json")).unwrap(),
        "kept"
    );
    assert!(run(1, "static.json").exists(), "run 1 redone");
    // A sweep with other overrides in the folder runs everything again.
    let again = softarm(
        &[
            "sweep",
            "cantilever",
            "--run",
            "static",
            "--set",
            "gravity=[0,-1,0]",
        ]
        .iter()
        .chain(&["--vary", "tip.mass=0,0.01,0.02", "--out", "s", "--resume"])
        .copied()
        .collect::<Vec<_>>(),
        dir.path(),
    );
    assert!(again.status.success(), "{}", stderr(&again));
    assert_ne!(
        std::fs::read_to_string(run(0, "static.json")).unwrap(),
        "kept"
    );
}

/// sweep.csv grows as runs finish: a sweep killed outright (SIGKILL, no
/// chance to write anything) leaves a table in grid order whose finished
/// runs are `ok` with their figures and the rest `pending`, and `--resume`
/// completes it keeping those rows.
#[test]
fn a_killed_sweep_leaves_the_table_of_what_it_finished() {
    let dir = tempfile::tempdir().unwrap();
    let runs = 600;
    let args = |resume: bool| {
        let mut a = vec![
            "sweep".to_string(),
            "cantilever".into(),
            "--run".into(),
            "static".into(),
            "--vary".into(),
            format!("tip.mass=lin:0:0.02:{runs}"),
            "--jobs".into(),
            "1".into(),
            "--out".into(),
            "s".into(),
        ];
        if resume {
            a.push("--resume".into());
        }
        a
    };
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_softarm"))
        .args(args(false))
        .current_dir(dir.path())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let table = dir.path().join("s/sweep.csv");
    let start = std::time::Instant::now();
    while !table.exists() && start.elapsed() < std::time::Duration::from_secs(60) {
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    let running = child.try_wait().unwrap().is_none();
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(running, "sweep.csv appeared only when the sweep had ended");
    let rows = read_csv(&table);
    assert_eq!(rows.len(), runs + 1, "a row a run and the header");
    let status = rows[0].iter().position(|h| h == "status").unwrap();
    let tip_x = rows[0].iter().position(|h| h == "tip_x").unwrap();
    for (i, r) in rows[1..].iter().enumerate() {
        assert_eq!(r[0], i.to_string(), "grid order");
        match r[status].as_str() {
            "ok" => assert!(r[tip_x].parse::<f64>().is_ok(), "run {i}: {r:?}"),
            "pending" => assert!(r[tip_x].is_empty(), "run {i}: {r:?}"),
            other => panic!("run {i}: status {other}"),
        }
    }
    let done: Vec<&Vec<String>> = rows[1..].iter().filter(|r| r[status] == "ok").collect();
    assert!(
        !done.is_empty() && done.len() < runs,
        "{} of {runs} ok",
        done.len()
    );
    let resumed = softarm(
        &args(true).iter().map(String::as_str).collect::<Vec<_>>(),
        dir.path(),
    );
    assert!(resumed.status.success(), "{}", stderr(&resumed));
    let after = read_csv(&table);
    assert!(after[1..].iter().all(|r| r[status] == "ok"));
    for r in done {
        let i: usize = r[0].parse().unwrap();
        assert_eq!(&after[i + 1], r, "a finished run's row is kept as it was");
    }
}

/// A grid past 10,000 runs is refused with the disk and time it would
/// take, from a pilot of its first run (in the system's temporary folder,
/// removed): the disk is the runs times what that run writes when run on
/// its own (its run fits in the pilot's two seconds, so nothing is
/// scaled).
#[test]
fn a_big_grid_is_refused_with_its_disk_and_time_from_a_pilot() {
    let dir = tempfile::tempdir().unwrap();
    let tmp = tempfile::tempdir().unwrap();
    let one = softarm(
        &[
            "simulate",
            "soft_finger",
            "--t-end",
            "0.5",
            "--set",
            "tip.mass=0.01",
            "--set",
            "segment.0.length=0.1",
            "--out",
            "one",
        ],
        dir.path(),
    );
    assert!(one.status.success(), "{}", stderr(&one));
    let bytes: u64 = std::fs::read_dir(dir.path().join("one"))
        .unwrap()
        .map(|e| e.unwrap().metadata().unwrap().len())
        .sum();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_softarm"))
        .args([
            "sweep",
            "soft_finger",
            "--t-end",
            "0.5",
            "--jobs",
            "2",
            "--vary",
            "tip.mass=lin:0.01:1:200",
            "--vary",
            "segment.0.length=lin:0.1:0.2:100",
            "--out",
            "s",
        ])
        .current_dir(dir.path())
        .env("TMPDIR", tmp.path())
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = stderr(&out);
    let figure = |before: &str| -> f64 {
        let at = err
            .find(before)
            .unwrap_or_else(|| panic!("{before:?} in {err}"));
        let head = &err[..at];
        head[head.rfind(' ').unwrap() + 1..].parse().unwrap()
    };
    let (gb, hours) = (figure(" GB and"), figure(" h on 2 threads"));
    let want = bytes as f64 * 20_000.0 / 1e9;
    assert!(
        (gb - want).abs() <= 0.02 * want,
        "{gb} GB against {want}: {err}"
    );
    assert!(hours > 0.0 && hours.is_finite(), "{err}");
    assert!(err.contains("only with --yes"), "{err}");
    assert!(!dir.path().join("s").exists());
    assert_eq!(
        std::fs::read_dir(tmp.path()).unwrap().count(),
        0,
        "the pilot's folder removed"
    );
}

/// `*` in a path is every item of a list: `segment.*.youngs_modulus` as a
/// sweep's variable is the same value set on each segment one by one.
#[test]
fn a_star_sets_every_segment_as_setting_each_does() {
    let model = root().join("benches/tapered_tentacle.toml");
    let model = model.to_str().unwrap();
    let tip = |sets: &[&str]| -> Vec<f64> {
        let dir = tempfile::tempdir().unwrap();
        let mut args = vec!["static", model, "--json"];
        for s in sets {
            args.extend(["--set", s]);
        }
        let out = softarm(&args, dir.path());
        assert!(out.status.success(), "{}", stderr(&out));
        let v: serde_json::Value = serde_json::from_str(&stdout(&out)).unwrap();
        (v["tip_position"].as_array().unwrap().iter())
            .map(|x| x.as_f64().unwrap())
            .collect()
    };
    let star = tip(&["segment.*.youngs_modulus=4e5"]);
    let each = tip(&[
        "segment.0.youngs_modulus=4e5",
        "segment.1.youngs_modulus=4e5",
        "segment.2.youngs_modulus=4e5",
    ]);
    assert_eq!(star, each);
    assert_ne!(star, tip(&[]), "the value took effect");
}

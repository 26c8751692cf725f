//! When an integrator gives up, softarm says when, why and what to try,
//! keeps the trajectory so far and exits non-zero.

use crate::common::*;

#[test]
fn unstable_fixed_step_is_explained_and_the_trajectory_kept() {
    // The chain's fastest mode is about 55 rad/s; rk4 is stable below
    // dt ~ 2.8 / 55 = 0.05 s, so dt = 0.5 s must blow up.
    let dir = tempfile::tempdir().unwrap();
    let out = softarm(
        &[
            "simulate",
            "chain",
            "--solver",
            "rk4",
            "--dt",
            "0.5",
            "--t-end",
            "50",
            "--q0",
            "1,0,0,0,0,0,0,0",
            "--out",
            "o",
        ],
        dir.path(),
    );
    assert!(!out.status.success());
    let err = stderr(&out);
    assert!(err.contains("integration stopped at t ="), "{err}");
    assert!(err.contains("reduce --dt"), "{err}");
    assert!(!err.contains("panicked"));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("o/summary.json")).unwrap())
            .unwrap();
    assert_eq!(summary["status"], "failed");
    let t_reached = summary["failure"]["t_reached"].as_f64().unwrap();
    assert!(t_reached > 0.0 && t_reached < 50.0);
    let csv = std::fs::read_to_string(dir.path().join("o/trajectory.csv")).unwrap();
    assert!(
        csv.lines().count() > 2,
        "the trajectory up to the failure is kept"
    );
    for line in csv.lines().skip(1) {
        assert!(
            !line.contains("NaN") && !line.contains("inf"),
            "only finite rows are written: {line}"
        );
    }
}

#[test]
fn an_impossible_step_budget_is_explained_for_every_adaptive_solver() {
    // 200 steps cannot cover 2 s of the double pendulum at rtol 1e-10.
    for solver in ["dopri5", "bs23", "radau5", "trbdf2", "bdf"] {
        let dir = tempfile::tempdir().unwrap();
        let out = softarm(
            &[
                "simulate",
                "double_pendulum",
                "--solver",
                solver,
                "--rtol",
                "1e-10",
                "--atol",
                "1e-12",
                "--max-steps",
                "200",
                "--t-end",
                "2",
                "--q0",
                "1.2,-0.5",
                "--out",
                "o",
            ],
            dir.path(),
        );
        assert!(!out.status.success(), "{solver}");
        let err = stderr(&out);
        assert!(
            err.contains("step budget of 200 steps ran out"),
            "{solver}: {err}"
        );
        assert!(err.contains("what to try"), "{solver}: {err}");
        assert!(err.contains("last accepted step"), "{solver}: {err}");
        let summary: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(dir.path().join("o/summary.json")).unwrap(),
        )
        .unwrap();
        let t_reached = summary["failure"]["t_reached"].as_f64().unwrap();
        assert!(t_reached > 0.0 && t_reached < 2.0, "{solver}: {t_reached}");
        let csv = std::fs::read_to_string(dir.path().join("o/trajectory.csv")).unwrap();
        let rows = csv.lines().count() - 1;
        let last_t: f64 = csv
            .lines()
            .last()
            .unwrap()
            .split(',')
            .next()
            .unwrap()
            .parse()
            .unwrap();
        // Rows at every output time passed (t_end / 500 apart) are kept,
        // and the last accepted state after them.
        let due = (t_reached / (2.0 / 500.0)).floor() as usize + 1;
        assert!(
            rows == due + 1 && (last_t - t_reached).abs() <= 1e-8,
            "{solver}: {rows} rows kept, {due} due before t = {t_reached}, last at {last_t}"
        );
        // The steps are counted up to the failure, not reported as none.
        let steps = summary["steps"].as_u64().unwrap();
        assert!(steps > 0 && steps <= 200, "{solver}: {steps} steps");
        let rejected = summary["rejected_steps"].as_u64().unwrap();
        assert_eq!(steps + rejected, 200, "{solver}: the budget counts both");
        if solver == "dopri5" {
            // Counted independently: seven right-hand sides a step tried
            // (accepted or not), and the initial step's estimate.
            let rhs = summary["rhs_evaluations"].as_u64().unwrap();
            let tried = steps + rejected;
            assert!(
                (7 * tried..=7 * tried + 4).contains(&rhs),
                "{rhs} rhs, {tried} steps"
            );
        }
    }
}

#[test]
fn summary_reports_the_run() {
    let dir = tempfile::tempdir().unwrap();
    let out = softarm(
        &[
            "simulate",
            "double_pendulum",
            "--t-end",
            "1",
            "--q0",
            "0.5,0",
            "--out",
            "o",
        ],
        dir.path(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("o/summary.json")).unwrap())
            .unwrap();
    for key in [
        "backend",
        "solver",
        "steps",
        "rhs_evaluations",
        "wall_s",
        "final_state",
    ] {
        assert!(!s[key].is_null(), "summary.json lacks {key}");
    }
    assert_eq!(s["backend"], "compiled");
    // The default solver is auto; the double pendulum is not stiff, so it
    // stays explicit (dopri5's seven right-hand sides a step, below).
    assert_eq!(s["solver"], "auto");
    assert!(s["solver_switch"].is_null(), "{}", s["solver_switch"]);
    assert_eq!(s["options"]["solver"]["from"], "default");
    // The effective options and where each came from.
    let o = &s["options"];
    assert_eq!(o["t_end"]["value"], 1.0);
    assert_eq!(o["t_end"]["from"], "command line");
    assert_eq!(o["rtol"]["value"], runtime::SimOptions::default().rtol);
    assert_eq!(o["rtol"]["from"], "default");
    assert_eq!(o["output_dt"]["value"], 1.0 / runtime::DEFAULT_SAMPLES);
    assert!(s["rhs_evaluations"].as_u64().unwrap() >= 6 * s["steps"].as_u64().unwrap());
    let csv = std::fs::read_to_string(dir.path().join("o/trajectory.csv")).unwrap();
    let header = csv.lines().next().unwrap();
    assert_eq!(
        header,
        "t,theta_0_0,theta_1_0,theta_0_0_dot,theta_1_0_dot,tip_x,tip_y,tip_z,kinetic,potential,tip_qw,tip_qx,tip_qy,tip_qz"
    );
}

#[test]
fn options_are_checked_against_each_other_before_anything_is_written() {
    let dir = tempfile::tempdir().unwrap();
    for (args, says) in [
        (
            vec!["--solver", "rk4", "--dt", "10", "--t-end", "0.2"],
            "--dt 10 s is longer than the run (--t-end 0.2 s)",
        ),
        (
            vec!["--output-dt", "1", "--t-end", "0.2"],
            "--output-dt 1 s is longer than the run",
        ),
        (
            vec!["--output-dt", "1e-300", "--t-end", "1"],
            "trajectory rows; a run writes at most 100000000",
        ),
    ] {
        let mut all = vec!["simulate", "double_pendulum", "--out", "o"];
        all.extend(&args);
        let out = softarm(&all, dir.path());
        assert!(!out.status.success(), "{args:?}");
        assert!(stderr(&out).contains(says), "{args:?}: {}", stderr(&out));
        assert!(!dir.path().join("o").exists(), "{args:?}: nothing written");
    }
}

/// Too dense an output is refused before the run with a spacing that
/// fits, which the check then takes.
/// A run returned in memory (Python's `simulate`; the CLI streams its
/// rows to disk) refuses more rows than it keeps, with a spacing that fits.
#[test]
fn too_many_rows_in_memory_are_refused_with_a_spacing_that_fits() {
    let t_end = 3.7;
    let opts = |output_dt: f64| runtime::SimOptions {
        t_end,
        output_dt,
        ..Default::default()
    };
    let err = softarm::run::rows_in_memory(&opts(1e-7))
        .unwrap_err()
        .to_string();
    let fits: f64 = err
        .split("take --output-dt ")
        .nth(1)
        .and_then(|r| r.split(' ').next())
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("no spacing suggested: {err}"));
    let rows = (t_end / fits).floor() as usize + 1;
    assert!(
        rows <= softarm::run::MAX_OUTPUT_ROWS && rows > 900_000,
        "{fits}: {rows} rows"
    );
    assert!(softarm::run::rows_in_memory(&opts(fits)).is_ok());
}

#[test]
fn a_run_that_cannot_start_says_why_in_its_own_terms() {
    let dir = tempfile::tempdir().unwrap();
    let out = softarm(
        &[
            "simulate",
            "double_pendulum",
            "--qd0",
            "1e150,1e150",
            "--t-end",
            "0.1",
            "--out",
            "o",
        ],
        dir.path(),
    );
    assert!(!out.status.success());
    let err = stderr(&out);
    assert!(err.contains("the integrator could not start"), "{err}");
    assert!(err.contains("check --q0 and --qd0"), "{err}");
    assert!(!err.contains("Bad input"), "{err}");
}

/// A chamber pressure of 1e15 Pa (a unit slip) drives finger_free's
/// silicone, E = 5e5 Pa, two billion times past its modulus: the run says
/// so before it starts, naming the input's key, and when it fails, that is
/// the first thing to try; the summary says it too. No bundled model, as
/// given, is out of scale (no false alarm).
#[test]
fn an_input_far_out_of_scale_is_named_before_the_run_and_in_the_hint() {
    let dir = tempfile::tempdir().unwrap();
    let args = [
        "simulate",
        "finger_free",
        "--set",
        "inputs.pressure.to=1e15",
        "--t-end",
        "1",
        "--max-steps",
        "20000",
        "--out",
        "o",
    ];
    let out = softarm(&args, dir.path());
    assert!(!out.status.success());
    let err = stderr(&out);
    let warning = err.find("warning: inputs.pressure reaches 1.000e15 Pa");
    let failure = err.find("integration stopped");
    assert!(
        warning.is_some() && warning < failure,
        "named before the run: {err}"
    );
    assert!(
        err.contains("what to try: bring the inputs into the model's scale: inputs.pressure"),
        "{err}"
    );
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("o/summary.json")).unwrap())
            .unwrap();
    let suggestion = summary["failure"]["suggestion"].as_str().unwrap();
    assert!(suggestion.contains("inputs.pressure"), "{suggestion}");

    for m in softarm::generated::MODELS {
        let l = softarm::backend::load(m.name, &[], softarm::backend::BackendChoice::Auto, None)
            .unwrap();
        let t_end = l.model.simulate.t_end.unwrap_or(1.0);
        let found = softarm::scale::out_of_scale(&l.model, &*l.arm, t_end);
        assert!(found.is_empty(), "{}: {found:?}", m.name);
    }
}

/// A run that fails for a cause other than its step budget reports the
/// rejected steps its method counted up to the failure (our own methods
/// keep the count: trbdf2 rejects steps as the right-hand side turns
/// non-finite), and null rather than 0 where the ODE crate's method lost
/// it with its error (bdf).
#[test]
fn a_failed_run_reports_its_rejected_steps_or_says_they_are_unknown() {
    for (solver, counted) in [("trbdf2", true), ("bdf", false)] {
        let dir = tempfile::tempdir().unwrap();
        let out = softarm(
            &[
                "simulate",
                "finger_free",
                "--set",
                "inputs.pressure.to=1e308",
                "--solver",
                solver,
                "--t-end",
                "1",
                "--out",
                "o",
            ],
            dir.path(),
        );
        assert!(!out.status.success(), "{solver}");
        let summary: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(dir.path().join("o/summary.json")).unwrap(),
        )
        .unwrap();
        assert_eq!(summary["status"], "failed", "{solver}");
        let rejected = &summary["rejected_steps"];
        match counted {
            true => assert!(
                rejected.as_u64().is_some_and(|r| r > 0),
                "{solver}: {rejected}"
            ),
            false => assert!(rejected.is_null(), "{solver}: {rejected}"),
        }
    }
}

/// `[simulate] output_dt` spaces the rows as `--output-dt` does, and the
/// command line's wins.
#[test]
fn the_model_file_sets_the_row_spacing() {
    let dir = tempfile::tempdir().unwrap();
    let rows = |extra: &[&str]| {
        let mut args = vec!["simulate", "double_pendulum", "--t-end", "1", "--set"];
        args.extend_from_slice(&["simulate.output_dt=0.05", "--out", "o", "--quiet"]);
        args.extend_from_slice(extra);
        let out = softarm(&args, dir.path());
        assert!(out.status.success(), "{}", stderr(&out));
        let s: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(dir.path().join("o/summary.json")).unwrap(),
        )
        .unwrap();
        let csv = std::fs::read_to_string(dir.path().join("o/trajectory.csv")).unwrap();
        (
            csv.lines().count() - 1,
            s["options"]["output_dt"]["from"].clone(),
        )
    };
    assert_eq!(rows(&[]), (21, serde_json::json!("model")));
    assert_eq!(
        rows(&["--output-dt", "0.1"]),
        (11, serde_json::json!("command line"))
    );
}

/// Every run plots its tip against time; a run stopped before its first
/// step has no time axis and no plot, and still ends.
#[test]
fn every_run_plots_its_tip() {
    let dir = tempfile::tempdir().unwrap();
    let out = softarm(
        &[
            "simulate",
            "soft_finger",
            "--t-end",
            "0.1",
            "--out",
            "o",
            "--quiet",
        ],
        dir.path(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let png = std::fs::read(dir.path().join("o/tip.png")).unwrap();
    assert_eq!(&png[1..4], b"PNG");
    assert!(dir.path().join("o/tip.svg").exists());
    let out = softarm(
        &[
            "simulate",
            "soft_finger",
            "--max-wall",
            "1e-9",
            "--out",
            "s",
            "--quiet",
        ],
        dir.path(),
    );
    assert!(!out.status.success(), "a run stopped at once");
    assert!(
        dir.path().join("s/summary.json").exists(),
        "{}",
        stderr(&out)
    );
}

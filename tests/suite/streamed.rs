//! A streamed run (`SimOptions::rows`) hands over exactly the samples the
//! same run keeps in memory, contact columns included, on every route a
//! run can take: one method of the ODE crate, one of ours, auto's switch,
//! legs between contact switches, legs held on joints, a failure and an
//! interruption; and keeps only its last sample.

use std::sync::{Arc, Mutex};

use runtime::{RowSink, SimOptions, Solver, Trajectory};

/// A row a sink received: t, x and the contact columns.
type Got = (f64, Vec<f64>, Vec<f64>);
type Received = Arc<Mutex<Vec<Got>>>;

fn sink() -> (RowSink, Received) {
    let got: Received = Arc::default();
    let to = got.clone();
    let sink = RowSink::new(move |_arm, row| {
        to.lock()
            .unwrap()
            .push((row.t, row.x.to_vec(), row.contact.to_vec()));
    });
    (sink, got)
}

/// The model's own start, bent where it has no joints so that it moves.
fn start(l: &softarm::backend::Loaded) -> Vec<f64> {
    let n = l.arm.dof();
    let (mut q, _) = softarm::run::start_coordinates(l, None).unwrap();
    if l.arm.info().constraints.is_empty() && l.arm.contact().is_none() {
        q.iter_mut().for_each(|v| *v += 0.3);
    }
    q.resize(2 * n, 0.0);
    q
}

/// The run kept and the run streamed: (kept trajectory or failure's, the
/// streamed rows, the streamed run's own trajectory).
fn both(
    model: &str,
    sets: &[&str],
    opts: impl Fn() -> SimOptions,
) -> (Trajectory, Vec<Got>, Trajectory) {
    let overrides: Vec<_> = (sets.iter())
        .map(|s| eomgen::model::Override::parse(s).unwrap())
        .collect();
    let l = softarm::backend::load(model, &overrides, Default::default(), None).unwrap();
    let x0 = start(&l);
    // (Each run begins its contacts afresh, whatever the last one left.)
    let run = |opts: &SimOptions| match runtime::simulate(&*l.arm, x0.clone(), opts) {
        Ok((traj, _)) => traj,
        Err(f) => f.trajectory,
    };
    let kept = run(&opts());
    let (rows, got) = sink();
    let tail = run(&SimOptions {
        rows: Some(rows),
        ..opts()
    });
    let got = std::mem::take(&mut *got.lock().unwrap());
    (kept, got, tail)
}

fn assert_same(
    what: &str,
    kept: &Trajectory,
    got: &[(f64, Vec<f64>, Vec<f64>)],
    tail: &Trajectory,
) {
    assert!(
        kept.t.len() > 2,
        "{what}: a run of {} samples",
        kept.t.len()
    );
    assert_eq!(got.len(), kept.t.len(), "{what}: rows streamed");
    for (i, (t, x, contact)) in got.iter().enumerate() {
        assert_eq!(*t, kept.t[i], "{what}: t of row {i}");
        assert_eq!(*x, kept.x[i], "{what}: x of row {i}");
        let kept_contact = kept.contact.get(i).cloned().unwrap_or_default();
        assert_eq!(*contact, kept_contact, "{what}: contact columns of row {i}");
    }
    assert_eq!(
        tail.t.len(),
        1,
        "{what}: the streamed run keeps its last sample"
    );
    assert_eq!(tail.t[0], *kept.t.last().unwrap(), "{what}: its last time");
    assert_eq!(tail.events.len(), kept.events.len(), "{what}: events");
}

fn opts(solver: Solver, t_end: f64) -> SimOptions {
    SimOptions {
        t_end,
        solver,
        output_dt: t_end / 200.0,
        ..Default::default()
    }
}

#[test]
fn a_method_of_the_ode_crate() {
    let (kept, got, tail) = both("chain", &[], || opts(Solver::Dopri5, 1.0));
    assert_same("chain, dopri5", &kept, &got, &tail);
}

#[test]
fn a_method_of_ours_and_a_fixed_step() {
    let (kept, got, tail) = both("soft_finger", &[], || opts(Solver::Radau5, 0.5));
    assert_same("soft_finger, radau5", &kept, &got, &tail);
    let (kept, got, tail) = both("chain", &[], || opts(Solver::Rk4, 0.5));
    assert_same("chain, rk4", &kept, &got, &tail);
}

#[test]
fn autos_switch() {
    let (kept, got, tail) = both("long_arm", &[], || opts(Solver::Auto, 0.5));
    assert_same("long_arm, auto", &kept, &got, &tail);
}

#[test]
fn legs_between_contact_switches_and_contact_without_records() {
    let (kept, got, tail) = both("finger_tap", &[], || opts(Solver::Auto, 0.6));
    assert!(!tail.switches.is_empty(), "the finger touches the table");
    assert_same("finger_tap", &kept, &got, &tail);
    assert!(
        got.iter().any(|r| r.2.iter().any(|f| *f != 0.0)),
        "a contact force"
    );
    let hertz = ["contact.model=hertz"];
    let (kept, got, tail) = both("finger_tap", &hertz, || opts(Solver::Auto, 0.6));
    assert_same("finger_tap, hertz", &kept, &got, &tail);
}

#[test]
fn legs_held_on_joints_with_contact() {
    let (kept, got, tail) = both("ball_drop", &[], || opts(Solver::Auto, 0.4));
    assert_same("ball_drop", &kept, &got, &tail);
    let (kept, got, tail) = both("falling_ball", &[], || opts(Solver::Auto, 0.3));
    assert_same("falling_ball", &kept, &got, &tail);
}

#[test]
fn a_failure_and_an_interruption_keep_what_they_computed() {
    let spent = || SimOptions {
        max_steps: 300,
        ..opts(Solver::Dopri5, 5.0)
    };
    let (kept, got, tail) = both("chain", &[], spent);
    assert_same("chain, out of steps", &kept, &got, &tail);
    // Stopped when asked the 11th time (the check runs every 64 steps).
    let asked = || {
        let calls = std::sync::atomic::AtomicUsize::new(0);
        let stop = move || calls.fetch_add(1, std::sync::atomic::Ordering::Relaxed) >= 10;
        SimOptions {
            interrupt: Some(runtime::Interrupt(Arc::new(stop))),
            ..opts(Solver::Dopri5, 5.0)
        }
    };
    let (kept, got, tail) = both("chain", &[], asked);
    assert_same("chain, interrupted", &kept, &got, &tail);
    assert!(*kept.t.last().unwrap() < 5.0, "stopped before its end");
}

/// The peak resident memory (kB) of `softarm args` in `cwd`, and whether
/// it succeeded.
#[cfg(target_os = "linux")]
#[allow(clippy::zombie_processes)] // reaped by wait4
fn peak_kb(args: &[&str], cwd: &std::path::Path) -> (i64, bool) {
    let child = std::process::Command::new(env!("CARGO_BIN_EXE_softarm"))
        .args(args)
        .current_dir(cwd)
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let mut status = 0;
    // SAFETY: wait4 on the child this test started, with owned buffers.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    let pid = unsafe { libc::wait4(child.id() as i32, &mut status, 0, &mut usage) };
    assert_eq!(pid, child.id() as i32);
    (
        usage.ru_maxrss,
        libc::WIFEXITED(status) && libc::WEXITSTATUS(status) == 0,
    )
}

/// The CLI writes its rows as they come: 200,000 rows take no more memory
/// than 500 (within 4 MB; held in memory they were over 60 MB), and all
/// of them are in trajectory.csv, in time order.
#[cfg(target_os = "linux")]
#[test]
fn the_cli_holds_no_rows_in_memory() {
    let dir = tempfile::tempdir().unwrap();
    let run = |output_dt: &str, out: &str| {
        let args = ["simulate", "chain", "--t-end", "4", "--shape-points", "0"];
        let (kb, ok) = peak_kb(
            &[
                &args[..],
                &["--output-dt", output_dt, "--out", out, "--quiet"],
            ]
            .concat(),
            dir.path(),
        );
        assert!(ok, "{out}");
        kb
    };
    let few = run("0.008", "few");
    let many = run("2e-5", "many");
    assert!(
        many - few < 4096,
        "{few} kB for 501 rows, {many} kB for 200,001"
    );
    let text = std::fs::read_to_string(dir.path().join("many/trajectory.csv")).unwrap();
    let t: Vec<f64> = (text.lines().skip(1))
        .map(|l| l.split(',').next().unwrap().parse().unwrap())
        .collect();
    assert_eq!(t.len(), 200_001);
    assert!(t.windows(2).all(|w| w[0] < w[1]));
}

/// A figure's points from a run of any length: at most `MAX_PLOTTED`, at
/// least half as many, evenly spaced (every k-th row) and ending on the
/// last row.
#[test]
fn figures_keep_a_bounded_even_thinning_that_ends_on_the_last_row() {
    use softarm::run_output::{MAX_PLOTTED, Thinned};
    for rows in [10, MAX_PLOTTED, MAX_PLOTTED + 1, 123_457, 123_458] {
        let mut t = Thinned::default();
        (0..rows).for_each(|i| t.push(i));
        let p = t.points();
        assert!(p.len() <= MAX_PLOTTED + 1, "{rows}: {} points", p.len());
        assert!(
            p.len() >= rows.min(MAX_PLOTTED / 2),
            "{rows}: {} points",
            p.len()
        );
        assert_eq!(*p.last().unwrap(), rows - 1, "{rows}: the last row");
        let step = p[1] - p[0];
        let body = &p[..p.len() - 1];
        assert!(body.windows(2).all(|w| w[1] - w[0] == step), "{rows}: even");
    }
}

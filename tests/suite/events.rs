//! Event location and dense output against closed forms and a second
//! method: the compound pendulum released from the horizontal passes the
//! vertical at odd multiples of K(k) / w0, k = sin(pi/4), w0^2 = 3 g / (2 L)
//! (a uniform rod pivoted at its end).

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

use eomgen::model::Override;
use runtime::{Crossing, Dynamics, Event, SimOptions, Solver, simulate};
use softarm::backend::{BackendChoice, Loaded, load};

/// One rod of the chain (0.8 m, 0.4 kg), hanging along -y, no springs.
fn pendulum() -> Loaded {
    let sets = [
        "segment.0.elements=1",
        "segment.0.joint_stiffness=0",
        "segment.0.joint_damping=0",
    ];
    let overrides: Vec<Override> = sets.iter().map(|s| Override::parse(s).unwrap()).collect();
    let dir = std::env::temp_dir().join("softarm-test-cache");
    load("chain", &overrides, BackendChoice::Auto, Some(dir)).unwrap()
}

/// Complete elliptic integral of the first kind by the arithmetic-geometric mean.
fn elliptic_k(k: f64) -> f64 {
    let (mut a, mut b) = (1.0, (1.0 - k * k).sqrt());
    // Quadratic convergence: eight rounds reach round-off from k < 0.9.
    for _ in 0..8 {
        (a, b) = (0.5 * (a + b), (a * b).sqrt());
    }
    PI / (2.0 * a)
}

fn quarter_period() -> f64 {
    let w0 = (3.0 * 9.81 / (2.0 * 0.8f64)).sqrt();
    elliptic_k(FRAC_PI_4.sin()) / w0
}

#[test]
fn crossings_of_the_vertical_are_located_to_the_closed_form() {
    let l = pendulum();
    let arm: &dyn Dynamics = &*l.arm;
    assert_eq!(arm.dof(), 1);
    let quarter = quarter_period();
    for (solver, rtol, tol) in [
        (Solver::Dopri5, 1e-10, 1e-7),
        (Solver::Dop853, 1e-10, 1e-7),
        (Solver::Bs23, 1e-10, 1e-6),
        (Solver::Radau5, 1e-10, 1e-7),
        (Solver::Bdf, 1e-10, 1e-6),
    ] {
        let opts = SimOptions {
            t_end: 6.0 * quarter,
            solver,
            rtol,
            atol: rtol * 1e-2,
            events: vec![Event::new("vertical", Crossing::Either, false, |_, x| x[0])],
            ..Default::default()
        };
        let (traj, _) = simulate(arm, vec![FRAC_PI_2, 0.0], &opts).unwrap();
        let times: Vec<f64> = traj.events.iter().map(|e| e.t).collect();
        assert_eq!(times.len(), 3, "{solver:?}: crossings at {times:?}");
        for (i, hit) in traj.events.iter().enumerate() {
            let expected = (2 * i + 1) as f64 * quarter;
            assert!(
                (hit.t - expected).abs() < tol * expected,
                "{solver:?}: crossing {i} at {} s, closed form {expected} s",
                hit.t
            );
            assert!(
                hit.x[0].abs() < 1e-6,
                "{solver:?}: q = {} at the event",
                hit.x[0]
            );
        }
        // Falling through zero first (q decreases), then rising.
        assert!(traj.events[0].x[1] < 0.0 && traj.events[1].x[1] > 0.0);
    }
}

#[test]
fn a_terminal_event_ends_the_run_at_the_event() {
    let l = pendulum();
    let opts = SimOptions {
        t_end: 10.0,
        rtol: 1e-10,
        atol: 1e-12,
        events: vec![Event::new("bottom", Crossing::Falling, true, |_, x| x[0])],
        ..Default::default()
    };
    let (traj, _) = simulate(&*l.arm, vec![FRAC_PI_2, 0.0], &opts).unwrap();
    let quarter = quarter_period();
    let t_last = *traj.t.last().unwrap();
    assert!(
        (t_last - quarter).abs() < 1e-7 * quarter,
        "ended at {t_last}, expected {quarter}"
    );
    assert_eq!(traj.events.len(), 1);
    assert!(traj.x.last().unwrap()[0].abs() < 1e-6);
    // A rising-only event is not fooled by the falling crossing.
    let opts = SimOptions {
        t_end: 1.5 * quarter,
        events: vec![Event::new("up", Crossing::Rising, true, |_, x| x[0])],
        ..opts
    };
    let (traj, _) = simulate(&*l.arm, vec![FRAC_PI_2, 0.0], &opts).unwrap();
    assert!(traj.events.is_empty());
    assert!((traj.t.last().unwrap() - 1.5 * quarter).abs() < 1e-12);
}

#[test]
fn dense_output_at_requested_times_matches_a_fixed_step_run() {
    let l = pendulum();
    let times = vec![0.0, 0.0137, 0.2718, 0.5772, 0.9999, 1.4321];
    let run = |solver, rtol: f64| {
        let opts = SimOptions {
            t_end: 1.5,
            solver,
            rtol,
            atol: rtol * 1e-2,
            dt: 1e-4,
            output_times: Some(times.clone()),
            ..Default::default()
        };
        simulate(&*l.arm, vec![FRAC_PI_2, 0.0], &opts).unwrap().0
    };
    let reference = run(Solver::Rk4, 0.0);
    assert_eq!(reference.t, times);
    for (solver, rtol) in [
        (Solver::Dopri5, 1e-9),
        (Solver::Radau5, 1e-9),
        (Solver::Bdf, 1e-10),
    ] {
        let traj = run(solver, rtol);
        assert_eq!(
            traj.t, times,
            "{solver:?} samples exactly the requested times"
        );
        for (x, r) in traj.x.iter().zip(&reference.x) {
            for (a, b) in x.iter().zip(r) {
                assert!((a - b).abs() < 1e-6, "{solver:?}: {a} vs {b}");
            }
        }
    }
}

//! Every integrator of the solver table (`Solver::ALL`, `auto` included)
//! runs through one conformance test: a closed form (a damped linear
//! oscillator) and a tight reference of a nonlinear arm (the double
//! pendulum by dop853 at rtol 1e-12), each to its tolerance; fixed-step
//! methods show their order.

use eomgen::model::Override;
use runtime::{Dynamics, SimOptions, Solver, simulate};
use softarm::backend::{BackendChoice, load};

use crate::common::{assert_close, root, softarm, stderr, stdout};

fn final_state(
    arm: &dyn Dynamics,
    x0: &[f64],
    t_end: f64,
    solver: Solver,
    rtol: f64,
    dt: f64,
) -> Vec<f64> {
    // The absolute tolerance a hundredth of the relative one at the
    // state's initial size.
    let size = x0.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let opts = SimOptions {
        t_end,
        solver,
        rtol,
        atol: rtol * 1e-2 * size,
        dt,
        output_dt: t_end / 10.0,
        ..Default::default()
    };
    let (traj, stats) =
        simulate(arm, x0.to_vec(), &opts).unwrap_or_else(|e| panic!("{solver:?}: {e}"));
    if solver.implicit() {
        assert!(
            stats.jacobian_evaluations > 0,
            "{solver:?} must use the analytic Jacobian"
        );
    }
    traj.x.last().unwrap().clone()
}

fn loaded(name: &str, sets: &[&str]) -> softarm::backend::Loaded {
    let overrides: Vec<Override> = sets.iter().map(|s| Override::parse(s).unwrap()).collect();
    let dir = std::env::temp_dir().join("softarm-test-cache");
    load(name, &overrides, BackendChoice::Auto, Some(dir)).unwrap()
}

/// Largest difference relative to the largest entry of `reference`.
fn relative_error(x: &[f64], reference: &[f64]) -> f64 {
    let scale = reference.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    x.iter()
        .zip(reference)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()))
        / scale
}

/// The fixed step of a fixed-step method on these problems (periods of
/// 0.1 to 1 s): from 1e-5 s at first order to 1e-2 s at fourth and 2e-2 s
/// at fifth, where the error is well above the references' and the method
/// in its asymptotic range (and an implicit one's Newton iteration
/// contracts on the pendulum's wide swing).
fn fixed_dt(solver: Solver) -> f64 {
    match solver.order() {
        p @ 1..=4 => 1e-5 * 10f64.powi(p as i32 - 1),
        _ => 2e-2,
    }
}

/// A solver's error on a problem with a known final state: adaptive
/// methods at rtol 1e-9, fixed-step ones at [`fixed_dt`], and (fixed
/// step) the error's fall when the step halves.
fn conforms(solver: Solver, arm: &dyn Dynamics, x0: &[f64], t_end: f64, exact: &[f64], what: &str) {
    if solver.fixed_step() {
        let dt = fixed_dt(solver);
        let coarse = relative_error(&final_state(arm, x0, t_end, solver, 0.0, dt), exact);
        let fine = relative_error(&final_state(arm, x0, t_end, solver, 0.0, dt / 2.0), exact);
        let expected = 2f64.powi(solver.order() as i32);
        assert!(
            coarse / fine > 0.7 * expected && coarse / fine < 1.4 * expected,
            "{what}, {solver:?}: halving dt = {dt:e} divides the error {coarse:e} by {}, not 2^{}",
            coarse / fine,
            solver.order()
        );
        assert!(
            fine < 1e-3,
            "{what}, {solver:?}: error {fine:e} at dt = {:e}",
            dt / 2.0
        );
    } else {
        let err = relative_error(&final_state(arm, x0, t_end, solver, 1e-9, 0.0), exact);
        // A controller of the local error of an order-p method keeps the
        // global error near rtol^(p / (p + 1)).
        let p = solver.order() as f64;
        let allowed = 100.0 * 1e-9f64.powf(p / (p + 1.0));
        assert!(
            err < allowed,
            "{what}, {solver:?}: error {err:e} at rtol 1e-9 (allowed {allowed:e})"
        );
    }
}

#[test]
fn every_solver_meets_a_closed_form_and_a_tight_reference() {
    // A one-element rod swinging by 1e-4 rad/m: a linear oscillator to
    // 1e-9 (the arc's inertia changes with the curvature squared), damped
    // by its bending damping; M, c and k read off the model at rest.
    let rod = loaded(
        "cantilever",
        &["segment.0.elements=1", "segment.0.bending_damping=2e-4"],
    );
    let arm = &*rod.arm;
    assert_eq!(arm.dof(), 1);
    let mut m = nalgebra::DMatrix::zeros(1, 1);
    arm.mass(0.0, &[0.0], &mut m);
    let mut parts = [0.0; 2];
    arm.jacobian_parts(0.0, &[0.0], &[0.0], &[0.0], &mut parts);
    let (k, c) = (parts[0], parts[1]);
    let omega = (k / m[(0, 0)]).sqrt();
    let zeta = c / (2.0 * (k * m[(0, 0)]).sqrt());
    assert!((0.01..0.5).contains(&zeta), "underdamped, zeta = {zeta}");
    let wd = omega * (1.0 - zeta * zeta).sqrt();
    let (a, t_end) = (1e-4, 4.0 * std::f64::consts::TAU / omega);
    let decay = (-zeta * omega * t_end).exp();
    let (cw, sw) = ((wd * t_end).cos(), (wd * t_end).sin());
    let exact = [
        a * decay * (cw + zeta * omega / wd * sw),
        -a * decay * (omega * omega / wd) * sw,
    ];
    // The double pendulum, swinging wide: dop853 at rtol 1e-12.
    let pendulum = loaded("double_pendulum", &[]);
    let x0 = [0.8, -0.4, 0.0, 1.0];
    let reference = final_state(&*pendulum.arm, &x0, 2.0, Solver::Dop853, 1e-12, 0.0);
    for solver in Solver::ALL {
        conforms(
            solver,
            arm,
            &[a, 0.0],
            t_end,
            &exact,
            "the damped oscillator",
        );
        conforms(
            solver,
            &*pendulum.arm,
            &x0,
            2.0,
            &reference,
            "the double pendulum",
        );
    }
}

#[test]
fn stiffness_analysis_predicts_the_explicit_step() {
    // The eigenvalue analysis at the equilibrium against what dopri5
    // actually does: on a stiff arm its average step sits at the stability
    // limit 3.3 / max |lambda|.
    let sets = [
        "segment.0.youngs_modulus=1e8",
        "segment.0.bending_damping=1e-5",
        "gravity=[0, -9.81, 0]",
    ];
    let overrides: Vec<Override> = sets.iter().map(|s| Override::parse(s).unwrap()).collect();
    let mut l = load("cantilever", &overrides, BackendChoice::Auto, None).unwrap();
    let n = l.arm.dof();
    let eq = runtime::solve_static(
        &mut *l.arm,
        &vec![0.0; n],
        &runtime::StaticOptions::default(),
    )
    .unwrap();
    let x: Vec<f64> = eq.q.iter().copied().chain(vec![0.0; n]).collect();
    let mut jac = nalgebra::DMatrix::zeros(2 * n, 2 * n);
    runtime::rhs_jacobian(&*l.arm, &mut runtime::Workspace::new(n), 0.0, &x, &mut jac).unwrap();
    let report = runtime::analyse_stiffness(&jac).unwrap();
    assert!(
        report.stiffness_ratio > 1000.0,
        "ratio {}",
        report.stiffness_ratio
    );
    assert_eq!(report.class, "stiff");
    assert_eq!(report.recommended_solver, "radau5");
    let t_end = 0.05;
    let opts = SimOptions {
        t_end,
        output_dt: t_end,
        solver: Solver::Dopri5,
        ..Default::default()
    };
    let (_, stats) = simulate(&*l.arm, x, &opts).unwrap();
    let mean_step = t_end / stats.steps as f64;
    let ratio = mean_step / report.stable_explicit_step_s;
    assert!(
        (0.5..2.0).contains(&ratio),
        "dopri5 mean step {mean_step:e} vs predicted {:e}",
        report.stable_explicit_step_s
    );
    // The double pendulum is not stiff: dopri5 is recommended.
    let l = load("double_pendulum", &[], BackendChoice::Auto, None).unwrap();
    let mut jac = nalgebra::DMatrix::zeros(4, 4);
    runtime::rhs_jacobian(
        &*l.arm,
        &mut runtime::Workspace::new(2),
        0.0,
        &[0.0; 4],
        &mut jac,
    )
    .unwrap();
    assert_eq!(
        runtime::analyse_stiffness(&jac).unwrap().recommended_solver,
        "dopri5"
    );
}

/// The steel rod (undamped, modes from 35 to 1.5e5 rad/s, every real part
/// zero) is stiff by the spread of its time scales, which a ratio of decay
/// rates missed: `auto` takes generalized-alpha from the start at an
/// engineer's tolerance (rtol 1e-3), radau5 at a tight one, and radau5
/// once its bending is damped (the fast modes' damping ratio past 0.05).
/// Each puts the tip where dopri5 run alone does, to its tolerance (the
/// modes generalized-alpha damps are those the step does not resolve).
#[test]
fn auto_takes_generalized_alpha_for_a_lightly_damped_stiff_structure() {
    let example = root().join("examples/steel_rod.toml");
    let example = example.to_string_lossy();
    let run = |sets: &[&str], rtol: f64, solver: Solver| {
        let l = loaded(&example, sets);
        let n = l.arm.dof();
        let mut x0 = vec![0.0; 2 * n];
        x0[0] = 0.05; // a uniform bend: the rod swings
        let opts = SimOptions {
            t_end: 0.02,
            solver,
            rtol,
            atol: 1e-9,
            output_dt: 0.02,
            ..Default::default()
        };
        let (traj, stats) = simulate(&*l.arm, x0, &opts).unwrap();
        let x = traj.x.last().unwrap();
        let o = l.arm.outputs(0.02, &x[..n], &x[n..]);
        // The tip's deflection from the straight rod.
        (vec![o[0] - 0.5, o[1], o[2]], stats)
    };
    let damped = "segment.0.bending_damping=1e-2";
    for (sets, rtol, want) in [
        (&[][..], 1e-3, Solver::GenAlpha),
        (&[][..], 1e-6, Solver::Radau5),
        (&[damped][..], 1e-3, Solver::Radau5),
    ] {
        let (q, stats) = run(sets, rtol, Solver::Auto);
        let switch = stats.switched.expect("the steel rod is stiff");
        assert_eq!(
            (switch.to, switch.at_s),
            (want, 0.0),
            "{sets:?} at rtol {rtol}: {}",
            switch.reason
        );
        // Where the report recommends generalized-alpha and radau5 runs,
        // the reason says why.
        let recommended = switch
            .reason
            .contains("generalized-alpha steps with the motion");
        let instead = switch
            .reason
            .contains("radau5 instead at rtol 1e-6, tighter than 1e-4");
        assert_eq!(
            instead,
            recommended && want == Solver::Radau5,
            "{sets:?} at rtol {rtol}: {}",
            switch.reason
        );
        let (reference, _) = run(sets, 1e-9, Solver::Dopri5);
        let err = relative_error(&q, &reference);
        eprintln!("{sets:?} at rtol {rtol}: the tip {err:.2e} from dopri5's");
        let what = format!("{sets:?} at rtol {rtol}: the tip {err:.2e} from dopri5's");
        assert!(err < 10.0 * rtol, "{what}");
    }
}

#[test]
fn auto_stays_explicit_on_the_pendulum_and_switches_on_the_stiff_arm() {
    let opts = SimOptions {
        t_end: 0.5,
        solver: Solver::Auto,
        output_dt: 0.05,
        ..Default::default()
    };
    let l = load("double_pendulum", &[], BackendChoice::Auto, None).unwrap();
    let (_, stats) = simulate(&*l.arm, vec![0.5, 0.0, 0.0, 0.0], &opts).unwrap();
    assert_eq!(stats.solver, Solver::Auto);
    assert!(stats.switched.is_none(), "the double pendulum is not stiff");
    assert_eq!(stats.jacobian_evaluations, 0, "dopri5 ran throughout");

    let sets = [
        "segment.0.youngs_modulus=1e8",
        "segment.0.bending_damping=1e-5",
        "gravity=[0, -9.81, 0]",
    ];
    let overrides: Vec<Override> = sets.iter().map(|s| Override::parse(s).unwrap()).collect();
    let l = load("cantilever", &overrides, BackendChoice::Auto, None).unwrap();
    let n = l.arm.dof();
    let opts = SimOptions {
        t_end: 0.2,
        solver: Solver::Auto,
        output_dt: 0.01,
        ..Default::default()
    };
    let (traj, stats) = simulate(&*l.arm, vec![0.0; 2 * n], &opts).unwrap();
    let switch = stats
        .switched
        .expect("the stiff arm switches to an implicit method");
    assert_eq!(switch.to, Solver::Radau5);
    assert!(switch.reason.contains("stiffness ratio"));
    assert!(stats.jacobian_evaluations > 0);
    // The same answer as dopri5 on its own, to the tolerance.
    let explicit = SimOptions {
        solver: Solver::Dopri5,
        ..opts.clone()
    };
    let (reference, _) = simulate(&*l.arm, vec![0.0; 2 * n], &explicit).unwrap();
    let (a, b) = (traj.x.last().unwrap(), reference.x.last().unwrap());
    let scale = b[..n].iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for i in 0..n {
        assert!(
            (a[i] - b[i]).abs() < 1e-3 * scale,
            "q[{i}]: {} vs {}",
            a[i],
            b[i]
        );
    }
}

/// A fixed-step run ends at t_end although its summed steps land there
/// only up to rounding (10,000 steps of 1e-6 s make 0.00999...): its last
/// row is t_end's state, and a run started at t0 (a controller's step)
/// continues the same run. Reference: one rk4 run over the whole span.
#[test]
fn a_fixed_step_run_records_its_end_and_restarts_at_t0() {
    let l = load("double_pendulum", &[], BackendChoice::Auto, None).unwrap();
    let x0 = vec![0.3, -0.2, 0.0, 0.0];
    let opts = |t0: f64, t_end: f64| SimOptions {
        t0,
        t_end,
        solver: Solver::Rk4,
        dt: 1e-6,
        output_times: Some(vec![t_end]),
        ..SimOptions::default()
    };
    let (whole, _) = simulate(&*l.arm, x0.clone(), &opts(0.0, 0.02)).unwrap();
    assert_eq!(whole.t, vec![0.02]);
    let (first, _) = simulate(&*l.arm, x0, &opts(0.0, 0.01)).unwrap();
    assert_eq!(first.t, vec![0.01], "the end's sample is there");
    let (second, _) = simulate(&*l.arm, first.x[0].clone(), &opts(0.01, 0.02)).unwrap();
    assert_eq!(second.t, vec![0.02]);
    for (a, b) in second.x[0].iter().zip(&whole.x[0]) {
        assert!((a - b).abs() <= 1e-12 * b.abs().max(1.0), "{a} vs {b}");
    }
}

/// `softarm fixed-step`: the step it picks keeps the tip within the
/// tolerance of a tight run by another method (radau5 at rtol 1e-10), and
/// the step twice as large does not; for an explicit method and an
/// implicit one.
#[test]
fn the_fixed_step_chosen_holds_the_tolerance_and_twice_it_does_not() {
    let l = loaded("soft_finger", &[]);
    let n = l.arm.dof();
    let x0 = vec![0.0; 2 * n];
    // radau5-fixed's largest step tried (T / 200) meets 1e-4 already.
    for (solver, tol) in [(Solver::Rk4, 1e-4), (Solver::Radau5Fixed, 1e-7)] {
        fixed_step_holds(&l, &x0, (0.5, tol), solver);
    }
}

fn fixed_step_holds(
    l: &softarm::backend::Loaded,
    x0: &[f64],
    (t_end, tol): (f64, f64),
    solver: Solver,
) {
    let choice = softarm::fixed_step::choose(l, x0, t_end, solver, tol).unwrap();
    let tips = |solver: Solver, dt: f64, rtol: f64| {
        let opts = SimOptions {
            t_end,
            solver,
            dt,
            rtol,
            atol: rtol * 1e-3,
            output_dt: t_end / 200.0,
            ..Default::default()
        };
        let (traj, _) = simulate(&*l.arm, x0.to_vec(), &opts).unwrap();
        softarm::run::tips(l, &traj)
    };
    let reference = tips(Solver::Radau5, 0.0, 1e-10);
    let distance = |dt: f64| {
        (tips(solver, dt, 1e-6).iter().zip(&reference))
            .map(|((_, a), (_, b))| (0..3).map(|c| (a[c] - b[c]).powi(2)).sum::<f64>().sqrt())
            .fold(0.0, f64::max)
    };
    assert!(distance(choice.dt) <= 1.01 * tol, "{choice:?}");
    let coarser = choice.coarser_dt.expect("a larger step was tried");
    assert!((coarser - 2.0 * choice.dt).abs() < 1e-15);
    let e = choice.coarser_error_m.unwrap_or(f64::INFINITY);
    assert!(e > tol, "{choice:?}");
}

/// Gauss-Legendre on the undamped steel rod (examples/steel_rod.toml),
/// released from its static bend, at a 2 ms step for 2 s (90 steps of its
/// first period): symplectic, without numerical damping, it keeps the
/// rod's energy after the release, the unexcited modes far above the step
/// (twist, the basis' highest bends) bounded: to 1e-4 of the largest
/// kinetic energy with its stages solved to rtol 1e-6 (2.1e-5 measured),
/// to 1e-3 at the file's rtol 1e-3 (1.8e-4).
#[test]
fn gauss_keeps_an_undamped_rods_energy_at_a_large_step() {
    let example = root().join("examples/steel_rod.toml");
    let l = loaded(&example.to_string_lossy(), &[]);
    let n = l.arm.dof();
    let q0 = runtime::solve_static(
        &mut *loaded(&example.to_string_lossy(), &[]).arm,
        &vec![0.0; n],
        &Default::default(),
    )
    .unwrap()
    .q;
    let drift = |solver: Solver, rtol: f64| {
        let opts = SimOptions {
            t_end: 2.0,
            solver,
            dt: 2e-3,
            rtol,
            atol: 1e-7,
            output_dt: 0.01,
            ..Default::default()
        };
        let x0: Vec<f64> = q0.iter().copied().chain(vec![0.0; n]).collect();
        let (traj, _) = simulate(&*l.arm, x0, &opts).unwrap();
        // After the release (the tip weight's ramp ends at 0.1 ms).
        let energy: Vec<(f64, f64)> = (traj.t.iter().zip(&traj.x))
            .filter(|(t, _)| **t >= 0.01)
            .map(|(t, x)| {
                let o = l.arm.outputs(*t, &x[..n], &x[n..2 * n]);
                (o[3], o[3] + o[4])
            })
            .collect();
        let ke = energy.iter().fold(0.0f64, |m, e| m.max(e.0));
        let e0 = energy[0].1;
        energy.iter().fold(0.0f64, |m, e| m.max((e.1 - e0).abs())) / ke
    };
    // The stages solved to rtol (Newton's tolerance at a fixed step): the
    // energy is kept to about the tolerance it is solved to.
    for (rtol, bound) in [(1e-6, 1e-4), (1e-3, 1e-3)] {
        let gauss = drift(Solver::Gauss, rtol);
        eprintln!(
            "rtol {rtol}: energy drift after the release {gauss:.2e} of the largest kinetic energy"
        );
        assert!(gauss < bound, "gauss at rtol {rtol}: {gauss:e}");
    }
}

/// The steel rod of Till, Aloi and Rucker as its files run it, released
/// from its static bend, 25 s (140 periods of the first mode): its tip
/// within 1 mm of a converged run over the whole run, and that mode,
/// unloaded and without gravity, within 0.1 % of the cantilever's closed
/// form 1.8751^2 / (2 pi L^2) sqrt(E I / rho A), rotary inertia aside.
/// examples/steel_rod.toml (gauss at 2 ms, ten slices, bending and twist)
/// against the twenty-slice rod by radau5 at rtol 1e-10;
/// examples/steel_rod_shear.toml (radau5-fixed at 3 ms, ten slices, all
/// six strains) against the thirty-slice rod at 0.5 ms.
#[test]
fn the_steel_rod_rings_for_25_s_within_a_millimetre_of_its_converged_run() {
    for (example, reference) in [
        ("steel_rod", "steel_rod_reference_tip"),
        ("steel_rod_shear", "steel_rod_shear_reference_tip"),
    ] {
        let dir = tempfile::tempdir().unwrap();
        let example = root().join(format!("examples/{example}.toml"));
        let example = example.to_string_lossy();
        let reference = format!("tests/data/{reference}.csv");
        let worst = tip_distance(dir.path(), &example, &reference, 25.0);
        eprintln!(
            "{example}: the tip's largest distance from the reference: {:.3} mm",
            1e3 * worst
        );
        assert!(worst < 1e-3, "{example}: {:.3} mm", 1e3 * worst);
        let modes = softarm(
            &[
                "modes",
                &example,
                "--set",
                "gravity=[0,0,0]",
                "--set",
                "inputs.weight.from=0",
                "--json",
            ],
            dir.path(),
        );
        assert!(modes.status.success(), "{}", stderr(&modes));
        let v: serde_json::Value = serde_json::from_str(&stdout(&modes)).unwrap();
        let first = v["frequencies_hz"][0].as_f64().unwrap();
        let (e, r, rho, l): (f64, f64, f64, f64) = (200e9, 1e-3, 8000.0, 0.5);
        let pi = std::f64::consts::PI;
        let closed = 1.875104f64.powi(2) / (2.0 * pi * l * l) * (e * r * r / 4.0 / rho).sqrt();
        assert_close(
            first,
            closed,
            1e-3,
            0.0,
            format_args!("{example}: the first bending mode"),
        );
    }
}

/// The steel rod thrown onto a support by its tip weight
/// (examples/steel_rod_stop.toml: contact through the link cells,
/// radau5-fixed at 1 ms, ten slices), 5 s: it strikes, rebounds and
/// settles pressed on the plane, its tip within 1 mm of the twenty-slice
/// rod at 0.1 ms over the whole run (0.64 mm measured; the ten slices at
/// 0.1 ms are 0.18 mm from it), and its tip at rest on the plane at the
/// end, the tube's radius above it.
#[test]
fn the_steel_rod_thrown_onto_a_support_settles_within_a_millimetre_of_its_converged_run() {
    let dir = tempfile::tempdir().unwrap();
    let example = root().join("examples/steel_rod_stop.toml");
    let reference = "tests/data/steel_rod_stop_reference_tip.csv";
    let worst = tip_distance(dir.path(), &example.to_string_lossy(), reference, 5.0);
    eprintln!(
        "the tip's largest distance from the reference: {:.3} mm",
        1e3 * worst
    );
    assert!(worst < 1e-3, "{:.3} mm", 1e3 * worst);
    let summary = std::fs::read_to_string(dir.path().join("run/summary.json")).unwrap();
    let v: serde_json::Value = serde_json::from_str(&summary).unwrap();
    let switches = v["contact"]["switches"].as_array().unwrap();
    assert!(
        switches.len() > 4,
        "it strikes and rebounds: {} switches",
        switches.len()
    );
    let tip_z = v["final_state"]["tip_position"][2].as_f64().unwrap();
    assert!(
        (tip_z + 0.029).abs() < 5e-4,
        "pressed on the plane: tip z {tip_z}"
    );
}

/// The largest distance of `example`'s tip over `t_end` from the
/// reference file's (t, x, z every 10 ms), the run as the file sets it;
/// the rows of the 10 ms grid (a run with contact writes its switches'
/// rows between them).
fn tip_distance(dir: &std::path::Path, example: &str, reference: &str, t_end: f64) -> f64 {
    let out = dir.join("run");
    let t_end_s = t_end.to_string();
    let args = [
        "simulate",
        example,
        "--t-end",
        &t_end_s,
        "--output-dt",
        "0.01",
    ];
    let run = softarm(
        &[
            &args[..],
            &["--shape-points", "0", "--out", &out.to_string_lossy()],
        ]
        .concat(),
        dir,
    );
    assert!(run.status.success(), "{}", stderr(&run));
    let text = std::fs::read_to_string(out.join("trajectory.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (ct, cx, cz) = (col("t"), col("tip_x"), col("tip_z"));
    let ours: std::collections::HashMap<i64, (f64, f64)> = lines
        .map(|l| {
            l.split(',')
                .map(|v| v.parse::<f64>().unwrap())
                .collect::<Vec<_>>()
        })
        .filter(|v| (v[ct] * 100.0 - (v[ct] * 100.0).round()).abs() < 1e-6)
        .map(|v| ((v[ct] * 100.0).round() as i64, (v[cx], v[cz])))
        .collect();
    let reference = std::fs::read_to_string(root().join(reference)).unwrap();
    let (mut worst, mut compared) = (0.0f64, 0);
    for line in reference.lines().filter(|l| !l.starts_with('#')) {
        let v: Vec<f64> = line.split(',').map(|v| v.parse().unwrap()).collect();
        let (x, z) = ours[&((v[0] * 100.0).round() as i64)];
        worst = worst.max((x - v[1]).hypot(z - v[2]));
        compared += 1;
    }
    let grid = (t_end * 100.0).round() as usize + 1;
    assert_eq!(compared, grid, "every 10 ms of {t_end} s");
    worst
}

//! Each integrator reproduces a reference solution (dop853 at rtol 1e-12,
//! a different method) of the double pendulum and of a damped pcc
//! cantilever to its tolerance.

use eomgen::model::Override;
use runtime::{Dynamics, SimOptions, Solver, simulate};
use softarm::backend::{BackendChoice, load};

fn final_state(
    arm: &dyn Dynamics,
    x0: &[f64],
    t_end: f64,
    solver: Solver,
    rtol: f64,
    dt: f64,
) -> Vec<f64> {
    let opts = SimOptions {
        t_end,
        solver,
        rtol,
        atol: rtol * 1e-2,
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

fn check(name: &str, sets: &[&str], x0: Vec<f64>, t_end: f64, cases: &[(Solver, f64, f64, f64)]) {
    let overrides: Vec<Override> = sets.iter().map(|s| Override::parse(s).unwrap()).collect();
    let dir = std::env::temp_dir().join("softarm-test-cache");
    let l = load(name, &overrides, BackendChoice::Auto, Some(dir)).unwrap();
    let arm = &*l.arm;
    let reference = final_state(arm, &x0, t_end, Solver::Dop853, 1e-12, 0.0);
    let scale = reference.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for &(solver, rtol, dt, tol) in cases {
        let x = final_state(arm, &x0, t_end, solver, rtol, dt);
        let err = x
            .iter()
            .zip(&reference)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()))
            / scale;
        assert!(
            err < tol,
            "{name}, {solver:?}: error {err:e} relative to the reference (allowed {tol:e})"
        );
    }
}

#[test]
fn double_pendulum_with_every_integrator() {
    check(
        "double_pendulum",
        &[],
        vec![0.8, -0.4, 0.0, 1.0],
        2.0,
        &[
            (Solver::Dopri5, 1e-9, 0.0, 1e-6),
            (Solver::Dop853, 1e-9, 0.0, 1e-6),
            (Solver::Bs23, 1e-9, 0.0, 1e-6),
            (Solver::Bs23, 1e-5, 0.0, 1e-3),
            (Solver::Radau5, 1e-9, 0.0, 1e-6),
            (Solver::Bdf, 1e-9, 0.0, 1e-5),
            (Solver::Trbdf2, 1e-8, 0.0, 1e-4),
            (Solver::Esdirk, 1e-8, 0.0, 1e-5),
            (Solver::Rk4, 0.0, 1e-3, 1e-6),
            (Solver::Euler, 0.0, 1e-5, 1e-2),
        ],
    );
}

#[test]
fn damped_pcc_cantilever_with_every_integrator() {
    check(
        "cantilever",
        &[
            "segment.0.elements=6",
            "segment.0.bending_damping=1e-4",
            "gravity=[0, -9.81, 0]",
        ],
        vec![0.0; 12],
        0.5,
        &[
            (Solver::Dopri5, 1e-9, 0.0, 1e-6),
            (Solver::Bs23, 1e-8, 0.0, 1e-5),
            (Solver::Bdf, 1e-9, 0.0, 1e-5),
            (Solver::Radau5, 1e-9, 0.0, 1e-6),
            (Solver::Radau5, 1e-6, 0.0, 1e-4),
            (Solver::Trbdf2, 1e-7, 0.0, 1e-4),
            (Solver::Dop853, 1e-9, 0.0, 1e-6),
            (Solver::Esdirk, 1e-8, 0.0, 1e-4),
            (Solver::Rk4, 0.0, 2e-5, 1e-6),
            (Solver::Euler, 0.0, 1e-5, 1e-2),
        ],
    );
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
    let report = runtime::analyse_stiffness(&jac);
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
        runtime::analyse_stiffness(&jac).recommended_solver,
        "dopri5"
    );
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

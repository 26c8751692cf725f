//! Time integration of an arm, on the `differential-equations` crate.
//!
//! The state is x = [q, qd]; the right-hand side solves M qdd = -h (see
//! `accelerations`), and implicit methods get the analytic Jacobian
//! (`rhs_jacobian`). Failures are explained: where, why, and what to try.
//!
//! Explicit methods carry the state as a `Vec`. The crate's implicit methods
//! (Radau5, BDF, DIRK) only work with fixed-size states (their buffers start
//! as `Y::zeros()`, which is empty for a `Vec`), so implicit runs use an
//! array `[f64; P]` with P the next size of [`IMPLICIT_SIZES`]; the extra
//! components are inert (x' = 0, zero Jacobian rows) and cost no accuracy.
//!
//! One concern a file: [`options`] (what a run is asked, with the CLI's
//! defaults), `methods` (one file per integration method behind one trait,
//! and the table from solver to method), `drivers` (how a method is fed
//! through the recorder), `record` (samples, events, counts), `outcome`
//! (what a run gives back), `failure` (the explained failure), `ode` (the
//! arm as x' = f(t, x)), [`stepper`] (the interface of our own steppers),
//! [`events`] (zero crossings), [`sensitivity`] (a run's derivatives
//! in its parameters); `projected` (joints held) and `touch`
//! (legs between contact switches) run the methods in legs. The solver
//! names are `crate::solver`'s.

mod drivers;
pub mod events;
mod failure;
mod methods;
mod ode;
pub mod options;
mod outcome;
mod projected;
mod record;
mod rows;
pub mod sensitivity;
pub mod state;
pub mod stepper;
mod touch;

pub use crate::solver::Solver;
pub use drivers::IMPLICIT_SIZES;
pub use failure::SimFailure;
pub use methods::{bs23, radau5, trbdf2};
pub use options::{DEFAULT_SAMPLES, DEFAULT_T_END, INTERRUPTED, Interrupt, SimOptions};
pub use outcome::{
    ConstraintStats, ContactMeter, MeterSample, SimStats, SolverSwitch, SwitchRecord, Trajectory,
};
pub use record::AUTO_CHECK_STEPS;
pub use rows::{Row, RowFn, RowSink};
pub use state::StateVec;

use crate::arm::Dynamics;

/// Integrate from x0 = [q0, qd0] over [0, t_end].
pub fn simulate(
    arm: &dyn Dynamics,
    x0: Vec<f64>,
    opts: &SimOptions,
) -> Result<(Trajectory, SimStats), Box<SimFailure>> {
    let n = arm.dof();
    let internal = arm.internal_len();
    assert!(
        x0.len() == 2 * n || x0.len() == 2 * n + internal,
        "state must be [q, qd], or with a viscoelastic arm's relaxed forces"
    );
    // A viscoelastic arm given [q, qd] starts relaxed at q0.
    let mut x0 = x0;
    if x0.len() < 2 * n + internal {
        let z0 = crate::relaxed_forces::relaxed(arm, opts.t0, &x0[..n]);
        x0.extend(z0);
    }
    arm.set_internal(&x0[2 * n..]);
    if internal > 0 && opts.solver == Solver::GenAlpha {
        return Err(Box::new(SimFailure {
            t_reached: opts.t0,
            last_step_s: None,
            reason: "generalized-alpha integrates the second-order form M qdd + h = 0; a \
                     viscoelastic arm's relaxing forces are first-order states"
                .into(),
            suggestion: "use --solver radau5 (or auto, which takes it for stiff arms)".into(),
            state: x0,
            trajectory: Trajectory::default(),
            stats: SimStats::none(opts.solver),
        }));
    }
    // A start whose accelerations cannot be computed fails now, with the
    // reason, rather than after a solver has shrunk its step to nothing.
    let mut qdd = vec![0.0; n];
    let mut ws = crate::arm::Workspace::new(n);
    let t0 = opts.t0;
    if let Err(e) = crate::arm::accelerations(arm, &mut ws, t0, &x0[..n], &x0[n..2 * n], &mut qdd) {
        return Err(Box::new(SimFailure {
            t_reached: t0,
            last_step_s: None,
            reason: format!("at the initial state: {e}"),
            suggestion:
                "check the initial state (--q0) and the model's masses, inertias and joints".into(),
            state: x0,
            trajectory: Trajectory::default(),
            stats: SimStats {
                rhs_evaluations: 1,
                ..SimStats::none(opts.solver)
            },
        }));
    }
    if let (Some(set), false) = (arm.contact(), opts.continues) {
        set.clear_records();
    }
    match arm.contact() {
        Some(set) if set.keeps_records() => touch::run(arm, x0, opts),
        Some(set) => {
            let (mut traj, stats) = run_leg(arm, t0, x0, opts)?;
            if opts.rows.is_none() {
                crate::contact::record_columns(arm, set, &mut traj, 0);
            }
            Ok((traj, stats))
        }
        None => run_leg(arm, t0, x0, opts),
    }
}

/// From (t0, x0) to `opts.t_end` or a terminal event: with the joints
/// held (`projected`) or by the solver alone.
fn run_leg(
    arm: &dyn Dynamics,
    t0: f64,
    x0: Vec<f64>,
    opts: &SimOptions,
) -> Result<(Trajectory, SimStats), Box<SimFailure>> {
    if !arm.info().constraints.is_empty() {
        return projected::run(arm, t0, x0, opts);
    }
    run_from(arm, t0, x0, opts)
}

/// Integrate from (t0, x0) to `opts.t_end` by the chosen solver.
fn run_from(
    arm: &dyn Dynamics,
    t0: f64,
    x0: Vec<f64>,
    opts: &SimOptions,
) -> Result<(Trajectory, SimStats), Box<SimFailure>> {
    methods::of(opts.solver).run(arm, t0, x0, opts)
}

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
//! One concern a file: [`options`] (what a run is
//! asked, with the CLI's defaults), `dispatch` (solver to run), `auto` (the
//! stiffness switch), `record` (samples, events, counts), `failure` (the
//! explained failure), `ode` (the arm as x' = f(t, x)); beside them the
//! in-house steppers `bs23`, `radau5`, `trbdf2` on `stepper`, and
//! [`events`] (zero crossings); `projected` (joints held) and `touch`
//! (legs between contact switches) run those in legs. The solver names
//! are `crate::solver`'s.

mod auto;
pub mod bs23;
mod dispatch;
pub mod events;
mod failure;
mod ode;
pub mod options;
mod projected;
pub mod radau5;
mod record;
pub mod state;
pub mod stepper;
mod touch;
pub mod trbdf2;

pub use crate::solver::Solver;
pub use dispatch::IMPLICIT_SIZES;
pub use failure::SimFailure;
pub use options::{DEFAULT_SAMPLES, DEFAULT_T_END, INTERRUPTED, Interrupt, SimOptions};
pub use projected::ConstraintStats;
pub use record::{
    AUTO_CHECK_STEPS, ContactMeter, MeterSample, SimStats, SolverSwitch, SwitchRecord, Trajectory,
};
pub use state::StateVec;

use std::cell::RefCell;

use crate::arm::Dynamics;

/// Integrate from x0 = [q0, qd0] over [0, t_end].
pub fn simulate<D: Dynamics + ?Sized>(
    arm: &D,
    x0: Vec<f64>,
    opts: &SimOptions,
) -> Result<(Trajectory, SimStats), Box<SimFailure>> {
    let n = arm.dof();
    assert_eq!(x0.len(), 2 * n, "state must be [q, qd]");
    // A start whose accelerations cannot be computed fails now, with the
    // reason, rather than after a solver has shrunk its step to nothing.
    let mut qdd = vec![0.0; n];
    let mut ws = crate::arm::Workspace::new(n);
    let t0 = opts.t0;
    if let Err(e) = crate::arm::accelerations(arm, &mut ws, t0, &x0[..n], &x0[n..], &mut qdd) {
        return Err(Box::new(SimFailure {
            t_reached: t0,
            last_step_s: None,
            reason: format!("at the initial state: {e}"),
            suggestion:
                "check the initial state (--q0) and the model's masses, inertias and joints".into(),
            state: x0,
            trajectory: Trajectory::default(),
            stats: SimStats {
                solver: opts.solver,
                steps: 0,
                rejected_steps: 0,
                rhs_evaluations: 1,
                jacobian_evaluations: 0,
                wall_s: 0.0,
                switched: None,
                constraints: None,
                contact: None,
            },
        }));
    }
    match arm.contact() {
        Some(set) if set.keeps_records() => touch::run(arm, x0, opts),
        Some(set) => {
            let (mut traj, stats) = run_leg(arm, t0, x0, opts)?;
            crate::contact::record_columns(arm, set, &mut traj, 0);
            Ok((traj, stats))
        }
        None => run_leg(arm, t0, x0, opts),
    }
}

/// From (t0, x0) to `opts.t_end` or a terminal event: with the joints
/// held (`projected`) or by the solver alone.
fn run_leg<D: Dynamics + ?Sized>(
    arm: &D,
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
fn run_from<D: Dynamics + ?Sized>(
    arm: &D,
    t0: f64,
    x0: Vec<f64>,
    opts: &SimOptions,
) -> Result<(Trajectory, SimStats), Box<SimFailure>> {
    match opts.solver {
        Solver::Auto => auto::run_auto(arm, t0, x0, opts),
        Solver::Bs23 => dispatch::run_own(arm, t0, x0, opts, bs23::integrate),
        s if s.implicit() => dispatch::simulate_implicit(arm, t0, x0, opts),
        _ => dispatch::run_explicit(arm, t0, x0, opts, None, &RefCell::new(None)),
    }
}

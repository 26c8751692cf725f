//! An integration that gave up, explained: when, why, and what to try.

use std::time::Instant;

use differential_equations::prelude::*;

use super::ode::ArmOde;
use super::options::SimOptions;
use super::outcome::{SimStats, Trajectory};
use super::record::Recorded;
use super::state::StateVec;
use crate::arm::Dynamics;

pub(super) type Outcome<Y> = Result<Solution<f64, Y>, Error<f64, Y>>;

/// An integration that gave up, with what was computed up to then.
#[derive(Debug)]
pub struct SimFailure {
    pub t_reached: f64,
    /// The last accepted step (s); None if none was accepted.
    pub last_step_s: Option<f64>,
    pub reason: String,
    pub suggestion: String,
    pub state: Vec<f64>,
    pub trajectory: Trajectory,
    pub stats: SimStats,
}

impl std::fmt::Display for SimFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "integration stopped at t = {:.6} s", self.t_reached)?;
        if let Some(h) = self.last_step_s {
            write!(f, " (last accepted step {h:.3e} s)")?;
        }
        write!(f, ": {}\n  what to try: {}", self.reason, self.suggestion)
    }
}

/// Turn the crate's outcome into a trajectory (padding dropped) or an
/// explained failure.
pub(super) fn finish<D: Dynamics + ?Sized, Y: StateVec>(
    result: Outcome<Y>,
    ode: &ArmOde<'_, D>,
    blown_up: Option<f64>,
    x0: &[f64],
    opts: &SimOptions,
    start: Instant,
    recorded: Recorded,
) -> Result<(Trajectory, SimStats), Box<SimFailure>> {
    let Recorded {
        kept,
        last_step_s,
        contact,
        interrupted,
        accepted,
    } = recorded;
    let hits = kept.events.clone();
    let wall_s = start.elapsed().as_secs_f64();
    let m = ode.len;
    let stats_of = |steps: usize, rejected: Option<usize>| SimStats {
        solver: opts.solver,
        steps,
        rejected_steps: rejected,
        rhs_evaluations: ode.evals.get(),
        jacobian_evaluations: ode.jac_evals.get(),
        wall_s,
        switched: None,
        constraints: None,
        contact,
    };
    let cause = ode.first_error.borrow().clone();
    let explain = |fallback: String| match &cause {
        Some(e) => e.to_string(),
        None => fallback,
    };
    let unpad = |y: &Y| y.as_ref()[..m].to_vec();
    match result {
        Ok(sol) => {
            let stats = stats_of(sol.steps.accepted, Some(sol.steps.rejected));
            // A streamed run's samples are gone from the solution: its
            // last is kept.
            let traj = match opts.rows {
                Some(_) => Trajectory {
                    events: hits,
                    ..kept
                },
                None => Trajectory {
                    t: sol.t.clone(),
                    x: sol.y.iter().map(unpad).collect(),
                    events: hits,
                    ..Default::default()
                },
            };
            if let Some(t_stop) = interrupted {
                let state = traj.x.last().cloned().unwrap_or_else(|| x0.to_vec());
                return Err(Box::new(SimFailure {
                    t_reached: t_stop,
                    last_step_s,
                    reason: super::options::INTERRUPTED.into(),
                    suggestion: "the run was asked to stop; run it again to finish".into(),
                    state,
                    trajectory: traj,
                    stats,
                }));
            }
            if let Some(t_bad) = blown_up {
                let state = traj.x.last().cloned().unwrap_or_else(|| x0.to_vec());
                return Err(Box::new(SimFailure {
                    t_reached: t_bad,
                    last_step_s,
                    reason: explain("the state became non-finite (NaN or infinite)".into()),
                    suggestion: format!(
                        "the fixed step dt = {} is probably above the stability limit: reduce --dt, \
                         or use an adaptive solver (dopri5, or radau5 for stiff arms)",
                        opts.dt
                    ),
                    state,
                    trajectory: traj,
                    stats,
                }));
            }
            Ok((traj, stats))
        }
        Err(e) => {
            let budget_spent = matches!(e, Error::MaxSteps { .. });
            let (t_reached, state, reason, suggestion) =
                why(e, opts, x0, &explain, |y: &Y| unpad(y));
            // The last accepted state is what the run computed last: kept
            // beside the samples, which a long output step may not reach.
            let mut trajectory = kept;
            if accepted > 0 && trajectory.t.last().is_none_or(|&t| t < t_reached) {
                trajectory.t.push(t_reached);
                trajectory.x.push(state.clone());
            }
            // A spent budget counts both kinds (ours and the crate's); our
            // own methods keep their count; the crate's dies with its error.
            let rejected = match budget_spent {
                true => Some(opts.max_steps.saturating_sub(accepted)),
                false => ode.rejected.get(),
            };
            Err(Box::new(SimFailure {
                t_reached,
                last_step_s,
                reason,
                suggestion,
                state,
                trajectory,
                stats: stats_of(accepted, rejected),
            }))
        }
    }
}

/// An error of the ODE crate as when, where, why and what to try.
fn why<Y: StateVec>(
    e: Error<f64, Y>,
    opts: &SimOptions,
    x0: &[f64],
    explain: &dyn Fn(String) -> String,
    unpad: impl Fn(&Y) -> Vec<f64>,
) -> (f64, Vec<f64>, String, String) {
    match e {
        // A fixed step is not shrunk: an implicit one whose stages do
        // not converge stops there.
        Error::StepSize { t, y } if opts.solver.fixed_step() => (
            t,
            unpad(&y),
            explain(format!(
                "the implicit stages did not converge at the fixed step dt = {:e} s",
                opts.dt
            )),
            "reduce --dt, or use an adaptive implicit solver (radau5)".to_string(),
        ),
        Error::StepSize { t, y } => (
            t,
            unpad(&y),
            explain("the step size fell below the smallest allowed step".into()),
            if opts.solver.implicit() {
                "relax --rtol/--atol, or reduce the element count".to_string()
            } else {
                "the arm may be stiff: try --solver radau5 or bdf, relax --rtol/--atol, \
                 or reduce the element count"
                    .to_string()
            },
        ),
        Error::MaxSteps { t, y } => (
            t,
            unpad(&y),
            format!("the step budget of {} steps ran out", opts.max_steps),
            if opts.solver.implicit() {
                "raise --max-steps, shorten --t-end or relax --rtol/--atol".to_string()
            } else {
                "raise --max-steps, shorten --t-end, relax --rtol/--atol, or use an \
                 implicit solver (radau5) if the arm is stiff"
                    .to_string()
            },
        ),
        Error::Stiffness { t, y } => (
            t,
            unpad(&y),
            explain("the method detected stiffness".into()),
            "use an implicit solver: --solver radau5, bdf or esdirk".to_string(),
        ),
        // The ODE crate's own words, said as what they mean here.
        Error::BadInput { msg } => (
            0.0,
            x0.to_vec(),
            explain(format!("the integrator could not start ({msg})")),
            start_hint(x0),
        ),
        Error::LinearAlgebra { t, y, msg } => (
            t,
            unpad(&y),
            explain(format!("a linear solve failed ({msg})")),
            "the arm may be singular here (a massless part, a locked joint): check the \
             model's masses and inertias"
                .to_string(),
        ),
        other => (
            0.0,
            x0.to_vec(),
            explain(format!("the integrator stopped ({other:?})")),
            start_hint(x0),
        ),
    }
}

/// What to check when a run cannot start: a state far out of scale, or
/// the step options against the run.
fn start_hint(x0: &[f64]) -> String {
    let largest = x0.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if !largest.is_finite() || largest > 1e6 {
        format!(
            "the initial state holds {largest:e}: check --q0 and --qd0 (or the model's [simulate] q0)"
        )
    } else {
        "check --dt, --rtol and --atol against --t-end".to_string()
    }
}

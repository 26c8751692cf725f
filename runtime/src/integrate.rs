//! Time integration of an arm, on the `differential-equations` crate.
//!
//! The state is x = [q, qd]; the right-hand side solves M qdd = -h by
//! Cholesky. Failures are explained: where, why, and what to try.

use std::cell::{Cell, RefCell};
use std::time::Instant;

use differential_equations::prelude::*;
use differential_equations::solout::EvenSolout;
use serde::Serialize;

use crate::arm::{AccelError, Dynamics, Workspace, accelerations};

/// Integrators available now. Names are the CLI's and the model files'.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Solver {
    /// Adaptive Dormand-Prince 5(4).
    Dopri5,
    /// Classic fixed-step Runge-Kutta 4.
    Rk4,
}

impl Solver {
    pub const NAMES: [&'static str; 2] = ["dopri5", "rk4"];

    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "dopri5" => Some(Self::Dopri5),
            "rk4" => Some(Self::Rk4),
            _ => None,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Self::Dopri5 => "dopri5",
            Self::Rk4 => "rk4",
        }
    }
}

#[derive(Clone, Debug)]
pub struct SimOptions {
    pub t_end: f64,
    pub solver: Solver,
    pub rtol: f64,
    pub atol: f64,
    /// Step of fixed-step solvers (s).
    pub dt: f64,
    /// Spacing of the written trajectory (s).
    pub output_dt: f64,
    /// Give up after this many steps.
    pub max_steps: usize,
}

impl Default for SimOptions {
    fn default() -> Self {
        Self {
            t_end: 1.0,
            solver: Solver::Dopri5,
            rtol: 1e-6,
            atol: 1e-9,
            dt: 1e-3,
            output_dt: 1e-2,
            max_steps: 10_000_000,
        }
    }
}

/// Sampled states x = [q, qd] at times t.
#[derive(Clone, Debug, Default)]
pub struct Trajectory {
    pub t: Vec<f64>,
    pub x: Vec<Vec<f64>>,
}

#[derive(Clone, Debug, Serialize)]
pub struct SimStats {
    pub solver: Solver,
    pub steps: usize,
    pub rejected_steps: usize,
    pub rhs_evaluations: usize,
    pub wall_s: f64,
}

/// An integration that gave up, with what was computed up to then.
#[derive(Debug)]
pub struct SimFailure {
    pub t_reached: f64,
    pub reason: String,
    pub suggestion: String,
    pub state: Vec<f64>,
    pub trajectory: Trajectory,
    pub stats: SimStats,
}

impl std::fmt::Display for SimFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "integration stopped at t = {:.6} s: {}\n  what to try: {}",
            self.t_reached, self.reason, self.suggestion
        )
    }
}

/// The first-order system x' = f(t, x) of an arm.
struct ArmOde<'a, D: ?Sized> {
    arm: &'a D,
    n: usize,
    ws: RefCell<Workspace>,
    qdd: RefCell<Vec<f64>>,
    evals: Cell<usize>,
    first_error: RefCell<Option<AccelError>>,
    /// Set when a right-hand side failed since the last accepted step.
    failed_in_step: Cell<bool>,
}

impl<D: Dynamics + ?Sized> ODE<f64, Vec<f64>> for ArmOde<'_, D> {
    fn diff(&self, t: f64, x: &Vec<f64>, dx: &mut Vec<f64>) {
        self.evals.set(self.evals.get() + 1);
        let n = self.n;
        let (q, qd) = x.split_at(n);
        dx[..n].copy_from_slice(qd);
        let mut qdd = self.qdd.borrow_mut();
        match accelerations(self.arm, &mut self.ws.borrow_mut(), t, q, qd, &mut qdd) {
            Ok(()) => dx[n..].copy_from_slice(&qdd),
            Err(e) => {
                // NaN makes an adaptive method reject the step; the record
                // explains the failure if the method then gives up.
                self.first_error.borrow_mut().get_or_insert(e);
                self.failed_in_step.set(true);
                dx[n..].fill(f64::NAN);
            }
        }
    }
}

/// Samples evenly and stops on a non-finite accepted state. A fixed-step
/// method has no error estimate to reject a step whose right-hand side
/// failed, so for those a failure anywhere in the step stops it too (its
/// dense output would be NaN); adaptive methods reject such steps.
struct Recorder<'a> {
    even: EvenSolout<f64>,
    blown_up: &'a Cell<Option<f64>>,
    failed_in_step: &'a Cell<bool>,
    fixed_step: bool,
}

impl Solout<f64, Vec<f64>> for Recorder<'_> {
    fn solout<I>(
        &mut self,
        t_curr: f64,
        t_prev: f64,
        y_curr: &Vec<f64>,
        y_prev: &Vec<f64>,
        interpolator: &mut I,
        solution: &mut Solution<f64, Vec<f64>>,
    ) -> ControlFlag<f64, Vec<f64>>
    where
        I: Interpolation<f64, Vec<f64>> + ?Sized,
    {
        let rhs_failed = self.failed_in_step.replace(false) && self.fixed_step;
        if rhs_failed || y_curr.iter().any(|v| !v.is_finite()) {
            self.blown_up.set(Some(t_prev));
            return ControlFlag::Terminate;
        }
        self.even
            .solout(t_curr, t_prev, y_curr, y_prev, interpolator, solution)
    }
}

/// Integrate from x0 = [q0, qd0] over [0, t_end].
pub fn simulate<D: Dynamics + ?Sized>(
    arm: &D,
    x0: Vec<f64>,
    opts: &SimOptions,
) -> Result<(Trajectory, SimStats), Box<SimFailure>> {
    let n = arm.dof();
    assert_eq!(x0.len(), 2 * n, "state must be [q, qd]");
    let ode = ArmOde {
        arm,
        n,
        ws: RefCell::new(Workspace::new(n)),
        qdd: RefCell::new(vec![0.0; n]),
        evals: Cell::new(0),
        first_error: RefCell::new(None),
        failed_in_step: Cell::new(false),
    };
    let blown_up = Cell::new(None);
    let recorder = Recorder {
        even: EvenSolout::new(opts.output_dt, 0.0, opts.t_end),
        blown_up: &blown_up,
        failed_in_step: &ode.failed_in_step,
        fixed_step: matches!(opts.solver, Solver::Rk4),
    };
    let start = Instant::now();
    let problem = IVP::ode(&ode, 0.0, opts.t_end, x0.clone());
    let result = match opts.solver {
        Solver::Dopri5 => problem
            .method(
                ExplicitRungeKutta::dopri5()
                    .rtol(opts.rtol)
                    .atol(opts.atol)
                    .max_steps(opts.max_steps),
            )
            .solout(recorder)
            .solve(),
        Solver::Rk4 => problem
            .method(
                ExplicitRungeKutta::rk4(opts.dt).max_steps(
                    opts.max_steps
                        .max((opts.t_end / opts.dt).ceil() as usize + 2),
                ),
            )
            .solout(recorder)
            .solve(),
    };
    let wall_s = start.elapsed().as_secs_f64();
    let stats_of = |steps: usize, rejected: usize| SimStats {
        solver: opts.solver,
        steps,
        rejected_steps: rejected,
        rhs_evaluations: ode.evals.get(),
        wall_s,
    };
    let cause = ode.first_error.borrow().clone();
    let explain = |fallback: String| match &cause {
        Some(e) => e.to_string(),
        None => fallback,
    };
    match result {
        Ok(sol) => {
            let stats = stats_of(sol.steps.accepted, sol.steps.rejected);
            let (t, x) = sol.into_tuple();
            let traj = Trajectory { t, x };
            if let Some(t_bad) = blown_up.get() {
                let state = traj.x.last().cloned().unwrap_or(x0);
                return Err(Box::new(SimFailure {
                    t_reached: t_bad,
                    reason: explain("the state became non-finite (NaN or infinite)".into()),
                    suggestion: format!(
                        "the fixed step dt = {} is probably above the stability limit: reduce --dt, \
                         or use the adaptive --solver dopri5",
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
            let (t_reached, state, reason, suggestion) = match e {
                Error::StepSize { t, y } => (
                    t,
                    y,
                    explain("the step size fell below the smallest allowed step".into()),
                    "the problem may be stiff or the tolerances too tight: relax --rtol/--atol, \
                     or reduce the element count"
                        .to_string(),
                ),
                Error::MaxSteps { t, y } => (
                    t,
                    y,
                    format!("the step budget of {} steps ran out", opts.max_steps),
                    "shorten --t-end, relax --rtol/--atol, or reduce the element count".to_string(),
                ),
                Error::Stiffness { t, y } => (
                    t,
                    y,
                    "the method detected stiffness".into(),
                    "relax --rtol/--atol or reduce the element count".to_string(),
                ),
                other => (
                    0.0,
                    x0.clone(),
                    explain(format!("{other:?}")),
                    "check the model and the solver options".to_string(),
                ),
            };
            Err(Box::new(SimFailure {
                t_reached,
                reason,
                suggestion,
                state,
                trajectory: Trajectory::default(),
                stats: stats_of(0, 0),
            }))
        }
    }
}

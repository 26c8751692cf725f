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

use std::cell::{Cell, RefCell};
use std::time::Instant;

use differential_equations::prelude::*;
use differential_equations::solout::EvenSolout;
use nalgebra::DMatrix;
use serde::Serialize;

use crate::arm::{AccelError, Dynamics, Workspace, accelerations};
use crate::events::{Event, EventHit, EventWatch};
use crate::jacobian::rhs_jacobian;
use crate::stepper::{self, Counts, OdeSystem, StepFn};
use crate::{bs23, radau5, trbdf2};

/// The signature of our integrators' entry points.
type OwnIntegrator = fn(
    &mut dyn OdeSystem,
    f64,
    Vec<f64>,
    &stepper::Options,
    &mut StepFn<'_>,
    &mut Counts,
) -> Result<(), Error<f64, Vec<f64>>>;

/// Integrators. Names are the CLI's and the model files'.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Solver {
    /// Adaptive Dormand-Prince 5(4), explicit.
    Dopri5,
    /// Adaptive Dormand-Prince 8(5,3), explicit.
    Dop853,
    /// Adaptive Bogacki-Shampine 3(2), explicit (the ode23 family).
    Bs23,
    /// Classic fixed-step Runge-Kutta 4, explicit.
    Rk4,
    /// Fixed-step explicit Euler.
    Euler,
    /// Radau IIA order 5, implicit, L-stable, adaptive (stiff systems).
    Radau5,
    /// Variable-order BDF 1-5, implicit, adaptive (the ode15s family).
    Bdf,
    /// TR-BDF2, L-stable, second order, adaptive (MATLAB's ode23tb).
    Trbdf2,
    /// ESDIRK 3(2) 4-stage, L-stable, adaptive (the crate's).
    Esdirk,
    /// dopri5, switching to radau5 when the arm turns out stiff (checked
    /// from the Jacobian's eigenvalues at the start and every
    /// [`AUTO_CHECK_STEPS`] accepted steps).
    Auto,
}

/// How often `auto` re-checks stiffness (accepted explicit steps).
pub const AUTO_CHECK_STEPS: usize = 200;

/// A change of solver made by `auto`.
#[derive(Clone, Debug, Serialize)]
pub struct SolverSwitch {
    pub at_s: f64,
    pub to: Solver,
    pub reason: String,
}

impl Solver {
    pub const NAMES: [&'static str; 10] = crate::SOLVER_NAMES;

    pub fn parse(s: &str) -> Option<Self> {
        Some(match s {
            "dopri5" => Self::Dopri5,
            "dop853" => Self::Dop853,
            "bs23" => Self::Bs23,
            "rk4" => Self::Rk4,
            "euler" => Self::Euler,
            "radau5" => Self::Radau5,
            "bdf" => Self::Bdf,
            "trbdf2" => Self::Trbdf2,
            "esdirk" => Self::Esdirk,
            "auto" => Self::Auto,
            _ => return None,
        })
    }

    pub fn name(self) -> &'static str {
        match self {
            Self::Dopri5 => "dopri5",
            Self::Dop853 => "dop853",
            Self::Bs23 => "bs23",
            Self::Rk4 => "rk4",
            Self::Euler => "euler",
            Self::Radau5 => "radau5",
            Self::Bdf => "bdf",
            Self::Trbdf2 => "trbdf2",
            Self::Esdirk => "esdirk",
            Self::Auto => "auto",
        }
    }

    /// Fixed-step methods (no error estimate: `dt` sets the step).
    pub fn fixed_step(self) -> bool {
        matches!(self, Self::Rk4 | Self::Euler)
    }

    /// Implicit methods (they use the analytic Jacobian).
    pub fn implicit(self) -> bool {
        matches!(self, Self::Radau5 | Self::Bdf | Self::Trbdf2 | Self::Esdirk)
    }
}

/// State lengths (2 x DOF, padded) the implicit methods are compiled for.
pub const IMPLICIT_SIZES: [usize; 10] = [4, 8, 12, 16, 24, 32, 48, 64, 96, 128];

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
    /// Sample at these times instead (ascending; from the methods' dense
    /// output, so they cost no extra steps).
    pub output_times: Option<Vec<f64>>,
    /// Zero crossings to locate (and to stop at, if terminal).
    pub events: Vec<Event>,
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
            output_times: None,
            events: Vec::new(),
            max_steps: 10_000_000,
        }
    }
}

/// Sampled states x = [q, qd] at times t.
#[derive(Clone, Debug, Default)]
pub struct Trajectory {
    pub t: Vec<f64>,
    pub x: Vec<Vec<f64>>,
    /// The located events, in time order.
    pub events: Vec<EventHit>,
}

#[derive(Clone, Debug, Serialize)]
pub struct SimStats {
    pub solver: Solver,
    pub steps: usize,
    pub rejected_steps: usize,
    pub rhs_evaluations: usize,
    pub jacobian_evaluations: usize,
    pub wall_s: f64,
    /// Set when `auto` switched solvers.
    pub switched: Option<SolverSwitch>,
}

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

/// A state the integrators can carry: a `Vec` or a fixed-size array.
pub trait StateVec:
    differential_equations::traits::State<f64> + AsRef<[f64]> + AsMut<[f64]>
{
}
impl<Y: differential_equations::traits::State<f64> + AsRef<[f64]> + AsMut<[f64]>> StateVec for Y {}

/// The first-order system x' = f(t, x) of an arm; components past 2 n are
/// padding.
struct ArmOde<'a, D: ?Sized> {
    arm: &'a D,
    n: usize,
    ws: RefCell<Workspace>,
    qdd: RefCell<Vec<f64>>,
    evals: Cell<usize>,
    jac_evals: Cell<usize>,
    jac: RefCell<DMatrix<f64>>,
    first_error: RefCell<Option<AccelError>>,
    /// Set when a right-hand side failed since the last accepted step.
    failed_in_step: Cell<bool>,
}

impl<'a, D: Dynamics + ?Sized> ArmOde<'a, D> {
    fn new(arm: &'a D) -> Self {
        let n = arm.dof();
        Self {
            arm,
            n,
            ws: RefCell::new(Workspace::new(n)),
            qdd: RefCell::new(vec![0.0; n]),
            evals: Cell::new(0),
            jac_evals: Cell::new(0),
            jac: RefCell::new(DMatrix::zeros(2 * n, 2 * n)),
            first_error: RefCell::new(None),
            failed_in_step: Cell::new(false),
        }
    }

    fn rhs(&self, t: f64, x: &[f64], dx: &mut [f64]) {
        self.evals.set(self.evals.get() + 1);
        let n = self.n;
        let (q, rest) = x.split_at(n);
        let qd = &rest[..n];
        dx[..n].copy_from_slice(qd);
        dx[2 * n..].fill(0.0);
        let mut qdd = self.qdd.borrow_mut();
        match accelerations(self.arm, &mut self.ws.borrow_mut(), t, q, qd, &mut qdd) {
            Ok(()) => dx[n..2 * n].copy_from_slice(&qdd),
            Err(e) => {
                // NaN makes an adaptive method reject the step; the record
                // explains the failure if the method then gives up.
                self.first_error.borrow_mut().get_or_insert(e);
                self.failed_in_step.set(true);
                dx[n..2 * n].fill(f64::NAN);
            }
        }
    }

    /// The Jacobian of the unpadded system into `j` (NaN if it fails).
    fn jacobian_dense(&self, t: f64, x: &[f64], j: &mut DMatrix<f64>) {
        self.jac_evals.set(self.jac_evals.get() + 1);
        if let Err(e) = rhs_jacobian(self.arm, &mut self.ws.borrow_mut(), t, x, j) {
            self.first_error.borrow_mut().get_or_insert(e);
            j.fill(f64::NAN);
        }
    }

    fn jacobian_into(&self, t: f64, x: &[f64], j: &mut Matrix<f64>) {
        self.jac_evals.set(self.jac_evals.get() + 1);
        let m = 2 * self.n;
        let mut jac = self.jac.borrow_mut();
        let ok = match rhs_jacobian(self.arm, &mut self.ws.borrow_mut(), t, &x[..m], &mut jac) {
            Ok(_) => true,
            Err(e) => {
                self.first_error.borrow_mut().get_or_insert(e);
                false
            }
        };
        for r in 0..x.len() {
            for c in 0..x.len() {
                j[(r, c)] = match (r < m && c < m, ok) {
                    (true, true) => jac[(r, c)],
                    (true, false) => f64::NAN,
                    (false, _) => 0.0,
                };
            }
        }
    }
}

impl<D: Dynamics + ?Sized> OdeSystem for &ArmOde<'_, D> {
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) {
        ArmOde::rhs(self, t, y, dy);
    }

    fn jacobian(&mut self, t: f64, y: &[f64], j: &mut DMatrix<f64>) {
        self.jacobian_dense(t, y, j);
    }
}

impl<D: Dynamics + ?Sized, Y: StateVec> ODE<f64, Y> for ArmOde<'_, D> {
    fn diff(&self, t: f64, x: &Y, dx: &mut Y) {
        self.rhs(t, x.as_ref(), dx.as_mut());
    }

    fn jacobian(&self, t: f64, x: &Y, j: &mut Matrix<f64>) {
        self.jacobian_into(t, x.as_ref(), j);
    }
}

/// Samples evenly and stops on a non-finite accepted state. A fixed-step
/// method has no error estimate to reject a step whose right-hand side
/// failed, so for those a failure anywhere in the step stops it too (its
/// dense output would be NaN); adaptive methods reject such steps.
struct Recorder<'a> {
    sampler: Sampler,
    /// The samples so far, unpadded, kept outside the crate's solution so
    /// that a run that fails still returns them.
    kept: &'a RefCell<Trajectory>,
    m: usize,
    /// The last accepted step, for failure reports.
    last_step: &'a Cell<Option<f64>>,
    events: &'a RefCell<EventWatch>,
    blown_up: &'a Cell<Option<f64>>,
    failed_in_step: &'a Cell<bool>,
    fixed_step: bool,
    /// `auto`: called every AUTO_CHECK_STEPS accepted steps with the state
    /// and the last step; Some(reason) stops the run for a switch.
    watch: Option<&'a Watch<'a>>,
    switch: &'a RefCell<Option<(f64, Vec<f64>, String)>>,
    accepted: usize,
}

type Watch<'a> = dyn Fn(&[f64], f64) -> Option<String> + 'a;

impl Recorder<'_> {
    fn keep<Y: StateVec>(&self, solution: &Solution<f64, Y>) {
        let mut kept = self.kept.borrow_mut();
        for k in kept.t.len()..solution.t.len() {
            kept.t.push(solution.t[k]);
            kept.x.push(solution.y[k].as_ref()[..self.m].to_vec());
        }
    }
}

impl<Y: StateVec> Solout<f64, Y> for Recorder<'_> {
    fn solout<I>(
        &mut self,
        t_curr: f64,
        t_prev: f64,
        y_curr: &Y,
        y_prev: &Y,
        interpolator: &mut I,
        solution: &mut Solution<f64, Y>,
    ) -> ControlFlag<f64, Y>
    where
        I: Interpolation<f64, Y> + ?Sized,
    {
        if t_curr > t_prev {
            self.last_step.set(Some(t_curr - t_prev));
        }
        let rhs_failed = self.failed_in_step.replace(false) && self.fixed_step;
        if rhs_failed || y_curr.as_ref().iter().any(|v| !v.is_finite()) {
            self.blown_up.set(Some(t_prev));
            return ControlFlag::Terminate;
        }
        let hit = self
            .events
            .borrow_mut()
            .check(t_prev, t_curr, y_prev, y_curr, interpolator);
        if let Some((t_event, y_event)) = hit {
            self.sampler
                .sample(t_event, t_prev, &y_event, y_prev, interpolator, solution);
            if solution.t.last() != Some(&t_event) {
                solution.push(t_event, y_event);
            }
            self.keep(solution);
            return ControlFlag::Terminate;
        }
        let flag = self
            .sampler
            .sample(t_curr, t_prev, y_curr, y_prev, interpolator, solution);
        self.keep(solution);
        self.accepted += 1;
        if let Some(watch) = self.watch
            && self.accepted.is_multiple_of(AUTO_CHECK_STEPS)
            && let Some(reason) = watch(y_curr.as_ref(), t_curr - t_prev)
        {
            *self.switch.borrow_mut() = Some((t_curr, y_curr.as_ref().to_vec(), reason));
            return ControlFlag::Terminate;
        }
        flag
    }
}

/// Where the trajectory is sampled.
enum Sampler {
    Even(EvenSolout<f64>),
    /// Ascending times, and the index of the next one due.
    At(Vec<f64>, usize),
}

impl Sampler {
    fn new(opts: &SimOptions) -> Self {
        match &opts.output_times {
            Some(times) => {
                // In time order, whatever order they were given in.
                let mut times = times.clone();
                times.sort_by(f64::total_cmp);
                Self::At(times, 0)
            }
            None => Self::Even(EvenSolout::new(opts.output_dt, 0.0, opts.t_end)),
        }
    }

    fn sample<Y: StateVec, I: Interpolation<f64, Y> + ?Sized>(
        &mut self,
        t_curr: f64,
        t_prev: f64,
        y_curr: &Y,
        y_prev: &Y,
        interpolator: &mut I,
        solution: &mut Solution<f64, Y>,
    ) -> ControlFlag<f64, Y> {
        match self {
            Self::Even(even) => even.solout(t_curr, t_prev, y_curr, y_prev, interpolator, solution),
            Self::At(times, next) => {
                while let Some(&t) = times.get(*next) {
                    if t > t_curr {
                        break;
                    }
                    *next += 1;
                    if t < t_prev {
                        continue;
                    }
                    let y = if t == t_curr {
                        y_curr.clone()
                    } else if t == t_prev {
                        y_prev.clone()
                    } else {
                        match interpolator.interpolate(t) {
                            Ok(y) => y,
                            Err(_) => continue,
                        }
                    };
                    solution.push(t, y);
                }
                ControlFlag::Continue
            }
        }
    }
}

type Outcome<Y> = Result<Solution<f64, Y>, Error<f64, Y>>;

/// Integrate from x0 = [q0, qd0] over [0, t_end].
pub fn simulate<D: Dynamics + ?Sized>(
    arm: &D,
    x0: Vec<f64>,
    opts: &SimOptions,
) -> Result<(Trajectory, SimStats), Box<SimFailure>> {
    let n = arm.dof();
    assert_eq!(x0.len(), 2 * n, "state must be [q, qd]");
    match opts.solver {
        Solver::Auto => run_auto(arm, x0, opts),
        Solver::Bs23 => run_own(arm, 0.0, x0, opts, bs23::integrate),
        s if s.implicit() => simulate_implicit(arm, 0.0, x0, opts),
        _ => run_explicit(arm, 0.0, x0, opts, None, &RefCell::new(None)),
    }
}

/// An implicit run from (t0, x0), on the smallest fixed-size state that fits.
fn simulate_implicit<D: Dynamics + ?Sized>(
    arm: &D,
    t0: f64,
    x0: Vec<f64>,
    opts: &SimOptions,
) -> Result<(Trajectory, SimStats), Box<SimFailure>> {
    let n = arm.dof();
    match opts.solver {
        Solver::Radau5 => return run_own(arm, t0, x0, opts, radau5::integrate),
        Solver::Trbdf2 => return run_own(arm, t0, x0, opts, trbdf2::integrate),
        _ => {}
    }
    macro_rules! sized {
        ($($p:literal),*) => {
            $(if x0.len() <= $p {
                return run_implicit::<D, $p>(arm, t0, x0, opts);
            })*
        };
    }
    sized!(4, 8, 12, 16, 24, 32, 48, 64, 96, 128);
    Err(Box::new(SimFailure {
        t_reached: t0,
        last_step_s: None,
        reason: format!(
            "the implicit solvers are compiled for up to {} coordinates, this arm has {n}",
            IMPLICIT_SIZES[IMPLICIT_SIZES.len() - 1] / 2
        ),
        suggestion: "use --solver dopri5, or fewer elements".into(),
        state: x0,
        trajectory: Trajectory::default(),
        stats: SimStats {
            solver: opts.solver,
            steps: 0,
            rejected_steps: 0,
            rhs_evaluations: 0,
            jacobian_evaluations: 0,
            wall_s: 0.0,
            switched: None,
        },
    }))
}

/// dopri5 while the arm is not stiff, radau5 once it is.
fn run_auto<D: Dynamics + ?Sized>(
    arm: &D,
    x0: Vec<f64>,
    opts: &SimOptions,
) -> Result<(Trajectory, SimStats), Box<SimFailure>> {
    let n = arm.dof();
    let analyse_at = |t: f64, x: &[f64]| {
        let mut jac = DMatrix::zeros(2 * n, 2 * n);
        rhs_jacobian(arm, &mut Workspace::new(n), t, &x[..2 * n], &mut jac)
            .ok()
            .map(|_| crate::stiffness::analyse(&jac))
    };
    let implicit_opts = SimOptions {
        solver: Solver::Radau5,
        ..opts.clone()
    };
    let as_auto = |mut stats: SimStats, switch: SolverSwitch| {
        stats.solver = Solver::Auto;
        stats.switched = Some(switch);
        stats
    };
    if let Some(r) = analyse_at(0.0, &x0)
        && r.stiffness_ratio > 1000.0
    {
        let (traj, stats) = simulate_implicit(arm, 0.0, x0, &implicit_opts)?;
        let reason = format!("stiff from the start: {}", r.reason);
        return Ok((
            traj,
            as_auto(
                stats,
                SolverSwitch {
                    at_s: 0.0,
                    to: Solver::Radau5,
                    reason,
                },
            ),
        ));
    }
    let watch = |x: &[f64], h: f64| -> Option<String> {
        let r = analyse_at(0.0, x)?;
        (r.stiffness_ratio > 1000.0 && h > 0.5 * r.stable_explicit_step_s).then(|| {
            format!(
                "dopri5 held at the stability limit ({h:.2e} s steps) of a stiff arm: {}",
                r.reason
            )
        })
    };
    let switch = RefCell::new(None);
    let explicit_opts = SimOptions {
        solver: Solver::Dopri5,
        ..opts.clone()
    };
    let (mut traj, mut stats) = run_explicit(arm, 0.0, x0, &explicit_opts, Some(&watch), &switch)?;
    stats.solver = Solver::Auto;
    let Some((t_switch, x_switch, reason)) = switch.take() else {
        return Ok((traj, stats));
    };
    let (rest, more) = simulate_implicit(arm, t_switch, x_switch, &implicit_opts)?;
    traj.events.extend(rest.events);
    for (t, x) in rest.t.into_iter().zip(rest.x) {
        if traj.t.last().is_none_or(|&last| t > last) {
            traj.t.push(t);
            traj.x.push(x);
        }
    }
    let merged = SimStats {
        solver: Solver::Auto,
        steps: stats.steps + more.steps,
        rejected_steps: stats.rejected_steps + more.rejected_steps,
        rhs_evaluations: stats.rhs_evaluations + more.rhs_evaluations,
        jacobian_evaluations: stats.jacobian_evaluations + more.jacobian_evaluations,
        wall_s: stats.wall_s + more.wall_s,
        switched: None,
    };
    Ok((
        traj,
        as_auto(
            merged,
            SolverSwitch {
                at_s: t_switch,
                to: Solver::Radau5,
                reason,
            },
        ),
    ))
}

fn run_explicit<D: Dynamics + ?Sized>(
    arm: &D,
    t0: f64,
    x0: Vec<f64>,
    opts: &SimOptions,
    watch: Option<&Watch<'_>>,
    switch: &RefCell<Option<(f64, Vec<f64>, String)>>,
) -> Result<(Trajectory, SimStats), Box<SimFailure>> {
    let ode = ArmOde::new(arm);
    let log = RunLog::new(opts, ode.n);
    let recorder = log.recorder(opts, &ode, opts.solver.fixed_step(), watch, switch);
    let start = Instant::now();
    let problem = IVP::ode(&ode, t0, opts.t_end, x0.clone());
    // (dt only matters for fixed-step methods; t_end / 0 saturates.)
    let fixed_steps = opts
        .max_steps
        .max(((opts.t_end / opts.dt).ceil() as usize).saturating_add(2));
    let (rtol, atol, max) = (opts.rtol, opts.atol, opts.max_steps);
    let result: Outcome<Vec<f64>> = match opts.solver {
        Solver::Dopri5 => problem
            .method(
                ExplicitRungeKutta::dopri5()
                    .rtol(rtol)
                    .atol(atol)
                    .max_steps(max),
            )
            .solout(recorder)
            .solve(),
        Solver::Dop853 => problem
            .method(
                ExplicitRungeKutta::dop853()
                    .rtol(rtol)
                    .atol(atol)
                    .max_steps(max),
            )
            .solout(recorder)
            .solve(),
        Solver::Rk4 => problem
            .method(ExplicitRungeKutta::rk4(opts.dt).max_steps(fixed_steps))
            .solout(recorder)
            .solve(),
        Solver::Euler => problem
            .method(ExplicitRungeKutta::euler(opts.dt).max_steps(fixed_steps))
            .solout(recorder)
            .solve(),
        Solver::Radau5
        | Solver::Bdf
        | Solver::Trbdf2
        | Solver::Esdirk
        | Solver::Auto
        | Solver::Bs23 => {
            unreachable!("implicit methods run on arrays, bs23 is ours, auto dispatches")
        }
    };
    finish(
        result,
        &ode,
        log.blown_up.get(),
        &x0,
        opts,
        start,
        log.finish(),
    )
}

/// An integrator of ours (`radau5`, `bs23`), fed through the same recorder
/// as the crate's methods.
fn run_own<D: Dynamics + ?Sized>(
    arm: &D,
    t0: f64,
    x0: Vec<f64>,
    opts: &SimOptions,
    integrate: OwnIntegrator,
) -> Result<(Trajectory, SimStats), Box<SimFailure>> {
    let ode = ArmOde::new(arm);
    let log = RunLog::new(opts, ode.n);
    let no_switch = RefCell::new(None);
    let mut recorder = log.recorder(opts, &ode, false, None, &no_switch);
    let mut solution: Solution<f64, Vec<f64>> = Solution::new();
    let mut counts = Counts::default();
    let own_opts = stepper::Options {
        t_end: opts.t_end,
        rtol: opts.rtol,
        atol: opts.atol,
        max_steps: opts.max_steps,
    };
    let start = Instant::now();
    let result = integrate(
        &mut &ode,
        t0,
        x0.clone(),
        &own_opts,
        &mut |t_prev, t_curr, y_prev, y_curr, dense| {
            let flag = recorder.solout(
                t_curr,
                t_prev,
                &y_curr.to_vec(),
                &y_prev.to_vec(),
                dense,
                &mut solution,
            );
            !matches!(flag, ControlFlag::Terminate)
        },
        &mut counts,
    );
    let outcome: Outcome<Vec<f64>> = result.map(|_| {
        solution.steps.accepted = counts.accepted;
        solution.steps.rejected = counts.rejected;
        solution
    });
    finish(
        outcome,
        &ode,
        log.blown_up.get(),
        &x0,
        opts,
        start,
        log.finish(),
    )
}

fn run_implicit<D: Dynamics + ?Sized, const P: usize>(
    arm: &D,
    t0: f64,
    x0: Vec<f64>,
    opts: &SimOptions,
) -> Result<(Trajectory, SimStats), Box<SimFailure>> {
    let ode = ArmOde::new(arm);
    let log = RunLog::new(opts, ode.n);
    let no_switch = RefCell::new(None);
    let recorder = log.recorder(opts, &ode, false, None, &no_switch);
    let mut y0 = [0.0; P];
    y0[..x0.len()].copy_from_slice(&x0);
    let start = Instant::now();
    let problem = IVP::ode(&ode, t0, opts.t_end, y0);
    let (rtol, atol, max) = (opts.rtol, opts.atol, opts.max_steps);
    let result: Outcome<[f64; P]> = match opts.solver {
        Solver::Radau5 => problem
            .method(
                ImplicitRungeKutta::radau5()
                    .rtol(rtol)
                    .atol(atol)
                    .max_steps(max),
            )
            .solout(recorder)
            .solve(),
        // The crate's initial-step estimate fails for a state at rest (it
        // returns a step below the minimum): start small, the controller grows it.
        Solver::Bdf => problem
            .method(
                BackwardDifferentiationFormula::adaptive()
                    .rtol(rtol)
                    .atol(atol)
                    .max_steps(max)
                    .h0(1e-6 * opts.t_end),
            )
            .solout(recorder)
            .solve(),
        Solver::Esdirk => problem
            .method(
                DiagonallyImplicitRungeKutta::esdirk324l2sa()
                    .rtol(rtol)
                    .atol(atol)
                    .max_steps(max),
            )
            .solout(recorder)
            .solve(),
        _ => unreachable!("explicit methods run on vectors"),
    };
    finish(
        result,
        &ode,
        log.blown_up.get(),
        &x0,
        opts,
        start,
        log.finish(),
    )
}

/// What a run's recorder saw: the samples with the events, and the last
/// accepted step.
struct Recorded {
    kept: Trajectory,
    last_step_s: Option<f64>,
}

/// The shared state a run's `Recorder` writes to.
struct RunLog {
    blown_up: Cell<Option<f64>>,
    events: RefCell<EventWatch>,
    kept: RefCell<Trajectory>,
    last_step: Cell<Option<f64>>,
}

impl RunLog {
    fn new(opts: &SimOptions, dof: usize) -> Self {
        Self {
            blown_up: Cell::new(None),
            events: RefCell::new(EventWatch::new(&opts.events, 2 * dof)),
            kept: RefCell::new(Trajectory::default()),
            last_step: Cell::new(None),
        }
    }

    fn recorder<'a, D: ?Sized>(
        &'a self,
        opts: &SimOptions,
        ode: &'a ArmOde<'_, D>,
        fixed_step: bool,
        watch: Option<&'a Watch<'a>>,
        switch: &'a RefCell<Option<(f64, Vec<f64>, String)>>,
    ) -> Recorder<'a> {
        Recorder {
            sampler: Sampler::new(opts),
            kept: &self.kept,
            m: 2 * ode.n,
            last_step: &self.last_step,
            events: &self.events,
            blown_up: &self.blown_up,
            failed_in_step: &ode.failed_in_step,
            fixed_step,
            watch,
            switch,
            accepted: 0,
        }
    }

    fn finish(&self) -> Recorded {
        Recorded {
            kept: Trajectory {
                events: std::mem::take(&mut self.events.borrow_mut().hits),
                ..self.kept.take()
            },
            last_step_s: self.last_step.get(),
        }
    }
}

/// Turn the crate's outcome into a trajectory (padding dropped) or an
/// explained failure.
fn finish<D: Dynamics + ?Sized, Y: StateVec>(
    result: Outcome<Y>,
    ode: &ArmOde<'_, D>,
    blown_up: Option<f64>,
    x0: &[f64],
    opts: &SimOptions,
    start: Instant,
    recorded: Recorded,
) -> Result<(Trajectory, SimStats), Box<SimFailure>> {
    let Recorded { kept, last_step_s } = recorded;
    let hits = kept.events.clone();
    let wall_s = start.elapsed().as_secs_f64();
    let m = 2 * ode.n;
    let stats_of = |steps: usize, rejected: usize| SimStats {
        solver: opts.solver,
        steps,
        rejected_steps: rejected,
        rhs_evaluations: ode.evals.get(),
        jacobian_evaluations: ode.jac_evals.get(),
        wall_s,
        switched: None,
    };
    let cause = ode.first_error.borrow().clone();
    let explain = |fallback: String| match &cause {
        Some(e) => e.to_string(),
        None => fallback,
    };
    let unpad = |y: &Y| y.as_ref()[..m].to_vec();
    match result {
        Ok(sol) => {
            let stats = stats_of(sol.steps.accepted, sol.steps.rejected);
            let traj = Trajectory {
                t: sol.t.clone(),
                x: sol.y.iter().map(unpad).collect(),
                events: hits,
            };
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
            let (t_reached, state, reason, suggestion) = match e {
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
                    "shorten --t-end, relax --rtol/--atol, or use an implicit solver for stiff arms"
                        .to_string(),
                ),
                Error::Stiffness { t, y } => (
                    t,
                    unpad(&y),
                    explain("the method detected stiffness".into()),
                    "use an implicit solver: --solver radau5, bdf or esdirk".to_string(),
                ),
                other => (
                    0.0,
                    x0.to_vec(),
                    explain(format!("{other:?}")),
                    "check the model and the solver options".to_string(),
                ),
            };
            Err(Box::new(SimFailure {
                t_reached,
                last_step_s,
                reason,
                suggestion,
                state,
                trajectory: kept,
                stats: stats_of(0, 0),
            }))
        }
    }
}

//! How an integration method is fed through the run's recorder: the
//! `differential-equations` crate's methods on vectors ([`run_crate`]) or,
//! for its implicit ones, on the smallest array state that fits
//! ([`run_sized`]), and our own steppers ([`run_own`]). Each method's file
//! under `methods/` picks one of these.

use std::cell::RefCell;
use std::time::Instant;

use differential_equations::interpolate::Interpolation;
use differential_equations::ode::{OrdinaryNumericalMethod, solve_ode};
use differential_equations::prelude::*;

use super::failure::{Outcome, SimFailure, finish};
use super::ode::ArmOde;
use super::options::SimOptions;
use super::outcome::{SimStats, Trajectory};
use super::record::{RunLog, Watch};
use super::state::StateVec;
use super::stepper::{self, Counts, OdeSystem, StepFn};
use crate::arm::Dynamics;

/// What every integration method returns.
pub(super) type RunResult = Result<(Trajectory, SimStats), Box<SimFailure>>;

/// Calls `$callback!` with the state lengths (2 x DOF, padded) the crate's
/// implicit methods are compiled for: the one list that [`IMPLICIT_SIZES`]
/// and the dispatch on array sizes both expand. Powers of two: each size
/// compiles both methods and the run's recorder once more (ten sizes were
/// a third of the runtime crate's build), and these are the alternatives
/// to our radau5, which works on any length.
macro_rules! with_implicit_sizes {
    ($callback:ident) => {
        $callback! { 8, 16, 32, 64, 128 }
    };
}

macro_rules! sizes_const {
    ($($p:literal),*) => {
        /// State lengths (2 x DOF, padded) the implicit methods are compiled for.
        pub const IMPLICIT_SIZES: &[usize] = &[$($p),*];
    };
}
with_implicit_sizes!(sizes_const);

/// The signature of our integrators' entry points.
pub(super) type OwnIntegrator = fn(
    &mut dyn OdeSystem,
    f64,
    Vec<f64>,
    &stepper::Options,
    &mut StepFn<'_>,
    &mut Counts,
) -> Result<(), Error<f64, Vec<f64>>>;

/// A method of the crate on vectors, from (t0, x0) to `opts.t_end`;
/// `watch` (auto's stiffness check) may stop it for a switch, which it
/// leaves in `switch`.
pub(super) fn run_crate<S>(
    arm: &dyn Dynamics,
    t0: f64,
    x0: Vec<f64>,
    opts: &SimOptions,
    method: S,
    watch: Option<&Watch<'_>>,
    switch: &RefCell<Option<(f64, Vec<f64>, String)>>,
) -> RunResult
where
    S: OrdinaryNumericalMethod<f64, Vec<f64>> + Interpolation<f64, Vec<f64>>,
{
    let start = Start {
        t0,
        y0: x0.clone(),
        x0,
    };
    run_on(arm, start, opts, method, watch, switch)
}

/// A crate's implicit method, which works only on fixed-size states (its
/// buffers start as `Y::zeros()`, empty for a `Vec`): run on the array
/// `[f64; P]` of the smallest P in [`IMPLICIT_SIZES`] that holds the state,
/// the extra components inert (x' = 0, zero Jacobian rows).
pub(super) trait SizedMethod {
    /// The method for states of length P.
    fn sized<const P: usize>(
        &self,
        opts: &SimOptions,
    ) -> impl OrdinaryNumericalMethod<f64, [f64; P]> + Interpolation<f64, [f64; P]>;
}

/// Run a [`SizedMethod`] on the smallest array that fits.
pub(super) fn run_sized<M: SizedMethod>(
    method: &M,
    arm: &dyn Dynamics,
    t0: f64,
    x0: Vec<f64>,
    opts: &SimOptions,
) -> RunResult {
    macro_rules! sized {
        ($($p:literal),*) => {
            $(if x0.len() <= $p {
                return run_array::<$p>(method.sized::<$p>(opts), arm, t0, x0, opts);
            })*
        };
    }
    with_implicit_sizes!(sized);
    Err(Box::new(SimFailure {
        t_reached: t0,
        last_step_s: None,
        reason: format!(
            "the implicit solvers are compiled for up to {} coordinates, this arm has {}",
            IMPLICIT_SIZES[IMPLICIT_SIZES.len() - 1] / 2,
            arm.dof()
        ),
        suggestion: "use --solver dopri5, or fewer elements".into(),
        state: x0,
        trajectory: Trajectory::default(),
        stats: SimStats::none(opts.solver),
    }))
}

fn run_array<const P: usize>(
    method: impl OrdinaryNumericalMethod<f64, [f64; P]> + Interpolation<f64, [f64; P]>,
    arm: &dyn Dynamics,
    t0: f64,
    x0: Vec<f64>,
    opts: &SimOptions,
) -> RunResult {
    let mut y0 = [0.0; P];
    y0[..x0.len()].copy_from_slice(&x0);
    let start = Start { t0, x0, y0 };
    run_on(arm, start, opts, method, None, &RefCell::new(None))
}

/// Where a run starts: at `t0` from `x0`, carried as the method's state
/// `y0` (`x0`, padded for an array state).
struct Start<Y> {
    t0: f64,
    x0: Vec<f64>,
    y0: Y,
}

/// A method of the crate on the state `Y`, through the run's recorder.
fn run_on<Y: StateVec, S>(
    arm: &dyn Dynamics,
    start: Start<Y>,
    opts: &SimOptions,
    mut method: S,
    watch: Option<&Watch<'_>>,
    switch: &RefCell<Option<(f64, Vec<f64>, String)>>,
) -> RunResult
where
    S: OrdinaryNumericalMethod<f64, Y> + Interpolation<f64, Y>,
{
    let Start { t0, x0, y0 } = start;
    let ode = ArmOde::new(arm);
    let log = RunLog::new(opts, ode.n);
    let mut recorder = log.recorder(opts, &ode, arm, opts.solver.fixed_step(), watch, switch);
    let clock = Instant::now();
    let result: Outcome<Y> = solve_ode(&mut method, &ode, t0, opts.t_end, &y0, &mut recorder);
    let run = finish(
        result,
        &ode,
        log.blown_up.get(),
        &x0,
        opts,
        clock,
        log.finish(),
    );
    stream_tail(arm, opts, run)
}

/// A streamed run's end: its last sample (which the recorder holds back)
/// and, after a failure, the last accepted state are handed over.
fn stream_tail(arm: &dyn Dynamics, opts: &SimOptions, mut run: RunResult) -> RunResult {
    if let Some(sink) = &opts.rows {
        let traj = match &mut run {
            Ok((traj, _)) => traj,
            Err(f) => &mut f.trajectory,
        };
        (traj.t.iter().zip(&traj.x)).for_each(|(t, x)| sink.push(arm, *t, x));
        super::rows::keep_last(traj);
    }
    run
}

/// An integrator of ours (`methods::bs23`, `radau5`, `trbdf2`), fed
/// through the same recorder as the crate's methods.
pub(super) fn run_own(
    arm: &dyn Dynamics,
    t0: f64,
    x0: Vec<f64>,
    opts: &SimOptions,
    integrate: OwnIntegrator,
) -> RunResult {
    let ode = ArmOde::new(arm);
    let log = RunLog::new(opts, ode.n);
    let no_switch = RefCell::new(None);
    let mut recorder = log.recorder(opts, &ode, arm, false, None, &no_switch);
    let mut solution: Solution<f64, Vec<f64>> = Solution::new();
    let mut counts = Counts::default();
    let own_opts = stepper::Options {
        t_end: opts.t_end,
        rtol: opts.rtol,
        atol: opts.atol,
        max_steps: opts.max_steps,
        rho_inf: opts.rho_inf,
        dt: opts.dt,
        positions: ode.n,
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
    ode.rejected.set(Some(counts.rejected));
    let outcome: Outcome<Vec<f64>> = result.map(|_| {
        solution.steps.accepted = counts.accepted;
        solution.steps.rejected = counts.rejected;
        solution
    });
    let run = finish(
        outcome,
        &ode,
        log.blown_up.get(),
        &x0,
        opts,
        start,
        log.finish(),
    );
    stream_tail(arm, opts, run)
}

#[cfg(test)]
mod tests {
    /// Sizes ascend, so the dispatch picks the smallest that fits.
    #[test]
    fn implicit_sizes_ascend() {
        assert!(super::IMPLICIT_SIZES.windows(2).all(|w| w[0] < w[1]));
    }
}

//! From a solver to a run: the crate's explicit methods on vectors, its
//! implicit ones on the smallest array state that fits, our own steppers
//! (bs23, radau5, trbdf2) through the same recorder, `auto` by its own
//! module.

use std::cell::RefCell;
use std::time::Instant;

use differential_equations::prelude::*;

use super::failure::{Outcome, SimFailure, finish};
use super::ode::ArmOde;
use super::options::SimOptions;
use super::record::{RunLog, SimStats, Trajectory, Watch};
use super::stepper::{self, Counts, OdeSystem, StepFn};
use super::{radau5, trbdf2};
use crate::arm::Dynamics;
use crate::solver::Solver;

/// Calls `$callback!` with the state lengths (2 x DOF, padded) the crate's
/// implicit methods are compiled for: the one list that [`IMPLICIT_SIZES`]
/// and the dispatch on array sizes both expand.
macro_rules! with_implicit_sizes {
    ($callback:ident) => {
        $callback! { 4, 8, 12, 16, 24, 32, 48, 64, 96, 128 }
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
type OwnIntegrator = fn(
    &mut dyn OdeSystem,
    f64,
    Vec<f64>,
    &stepper::Options,
    &mut StepFn<'_>,
    &mut Counts,
) -> Result<(), Error<f64, Vec<f64>>>;

/// An implicit run from (t0, x0), on the smallest fixed-size state that fits.
pub(super) fn simulate_implicit<D: Dynamics + ?Sized>(
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
    with_implicit_sizes!(sized);
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
            constraints: None,
            contact: None,
        },
    }))
}

pub(super) fn run_explicit<D: Dynamics + ?Sized>(
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
pub(super) fn run_own<D: Dynamics + ?Sized>(
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
        _ => unreachable!("explicit methods run on vectors, radau5 and trbdf2 are ours"),
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

#[cfg(test)]
mod tests {
    /// Sizes ascend, so the dispatch picks the smallest that fits.
    #[test]
    fn implicit_sizes_ascend() {
        assert!(super::IMPLICIT_SIZES.windows(2).all(|w| w[0] < w[1]));
    }
}

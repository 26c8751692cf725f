//! The integration methods: one trait, one file per method, and the one
//! table ([`of`]) that maps each [`Solver`] to its method. A new method is
//! a file here, a variant with its name in `crate::solver`, and a line in
//! the table; `tests/suite/integrators.rs` runs every solver of that table
//! through the same conformance checks.

mod auto;
mod bdf;
pub mod bs23;
mod dop853;
mod dopri5;
mod esdirk;
mod euler;
pub mod gauss;
pub mod genalpha;
pub mod radau5;
mod rk4;
pub mod trbdf2;

use super::drivers::{OwnIntegrator, RunResult, run_own};
use super::options::SimOptions;
use crate::arm::Dynamics;
use crate::solver::Solver;

/// A method that integrates an arm from (t0, x0) to `opts.t_end`,
/// sampling as `opts` asks and explaining a failure.
pub(super) trait Integrator: Sync {
    fn run(&self, arm: &dyn Dynamics, t0: f64, x0: Vec<f64>, opts: &SimOptions) -> RunResult;
}

/// A stepper written here (`bs23`, `radau5`, `trbdf2`, `genalpha`), run through the
/// recorder by `drivers::run_own`.
pub(super) struct Own(pub OwnIntegrator);

impl Integrator for Own {
    fn run(&self, arm: &dyn Dynamics, t0: f64, x0: Vec<f64>, opts: &SimOptions) -> RunResult {
        run_own(arm, t0, x0, opts, self.0)
    }
}

/// The method of each solver.
pub(super) fn of(solver: Solver) -> &'static dyn Integrator {
    match solver {
        Solver::Dopri5 => &dopri5::Dopri5,
        Solver::Dop853 => &dop853::Dop853,
        Solver::Bs23 => &Own(bs23::integrate),
        Solver::Rk4 => &rk4::Rk4,
        Solver::Euler => &euler::Euler,
        Solver::Radau5 => &Own(radau5::integrate),
        Solver::Bdf => &bdf::Bdf,
        Solver::Trbdf2 => &Own(trbdf2::integrate),
        Solver::Esdirk => &esdirk::Esdirk,
        Solver::GenAlpha => &Own(genalpha::integrate),
        Solver::Gauss => &Own(gauss::integrate),
        Solver::Auto => &auto::Auto,
    }
}

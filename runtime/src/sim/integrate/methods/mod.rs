//! The integration methods: one trait, one file per method, and the one
//! table ([`of`]) that maps each [`Solver`] to its method. A new method is
//! a file here, a variant with its name in `crate::solver`, and a line in
//! the table; `tests/integrators.rs` runs every solver of that table
//! through the same conformance checks.

mod auto;
mod bdf;
pub mod bs23;
mod dop853;
mod dopri5;
mod esdirk;
mod euler;
pub mod radau5;
mod rk4;
pub mod trbdf2;

use super::drivers::RunResult;
use super::options::SimOptions;
use crate::arm::Dynamics;
use crate::solver::Solver;

/// A method that integrates an arm from (t0, x0) to `opts.t_end`,
/// sampling as `opts` asks and explaining a failure.
pub(super) trait Integrator: Sync {
    fn run(&self, arm: &dyn Dynamics, t0: f64, x0: Vec<f64>, opts: &SimOptions) -> RunResult;
}

/// The method of each solver.
pub(super) fn of(solver: Solver) -> &'static dyn Integrator {
    match solver {
        Solver::Dopri5 => &dopri5::Dopri5,
        Solver::Dop853 => &dop853::Dop853,
        Solver::Bs23 => &bs23::Bs23,
        Solver::Rk4 => &rk4::Rk4,
        Solver::Euler => &euler::Euler,
        Solver::Radau5 => &radau5::Radau5,
        Solver::Bdf => &bdf::Bdf,
        Solver::Trbdf2 => &trbdf2::Trbdf2,
        Solver::Esdirk => &esdirk::Esdirk,
        Solver::Auto => &auto::Auto,
    }
}

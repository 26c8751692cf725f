//! Variable-order BDF 1-5, implicit and adaptive (the ode15s family): the
//! crate's, on a fixed-size state.

use differential_equations::interpolate::Interpolation;
use differential_equations::ode::OrdinaryNumericalMethod;
use differential_equations::prelude::*;

use super::super::drivers::{RunResult, SizedMethod, run_sized};
use super::super::options::SimOptions;
use super::Integrator;
use crate::arm::Dynamics;

pub(super) struct Bdf;

impl Integrator for Bdf {
    fn run(&self, arm: &dyn Dynamics, t0: f64, x0: Vec<f64>, opts: &SimOptions) -> RunResult {
        run_sized(self, arm, t0, x0, opts)
    }
}

impl SizedMethod for Bdf {
    fn sized<const P: usize>(
        &self,
        opts: &SimOptions,
    ) -> impl OrdinaryNumericalMethod<f64, [f64; P]> + Interpolation<f64, [f64; P]> {
        // The crate's initial-step estimate fails for a state at rest (it
        // returns a step below the minimum): start small, the controller
        // grows it.
        BackwardDifferentiationFormula::adaptive()
            .rtol(opts.rtol)
            .atol(opts.atol)
            .max_steps(opts.max_steps)
            .h0(1e-6 * opts.t_end)
    }
}

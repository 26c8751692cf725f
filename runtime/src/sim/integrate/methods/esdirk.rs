//! ESDIRK 3(2) with four stages, L-stable and adaptive: the crate's, on a
//! fixed-size state.

use differential_equations::interpolate::Interpolation;
use differential_equations::ode::OrdinaryNumericalMethod;
use differential_equations::prelude::*;

use super::super::drivers::{RunResult, SizedMethod, run_sized};
use super::super::options::SimOptions;
use super::Integrator;
use crate::arm::Dynamics;

pub(super) struct Esdirk;

impl Integrator for Esdirk {
    fn run(&self, arm: &dyn Dynamics, t0: f64, x0: Vec<f64>, opts: &SimOptions) -> RunResult {
        run_sized(self, arm, t0, x0, opts)
    }
}

impl SizedMethod for Esdirk {
    fn sized<const P: usize>(
        &self,
        opts: &SimOptions,
    ) -> impl OrdinaryNumericalMethod<f64, [f64; P]> + Interpolation<f64, [f64; P]> {
        DiagonallyImplicitRungeKutta::esdirk324l2sa()
            .rtol(opts.rtol)
            .atol(opts.atol)
            .max_steps(opts.max_steps)
    }
}

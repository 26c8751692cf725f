//! Dormand-Prince 8(5,3), explicit and adaptive: the crate's.

use std::cell::RefCell;

use differential_equations::prelude::*;

use super::super::drivers::{RunResult, run_crate};
use super::super::options::SimOptions;
use super::Integrator;
use crate::arm::Dynamics;

pub(super) struct Dop853;

impl Integrator for Dop853 {
    fn run(&self, arm: &dyn Dynamics, t0: f64, x0: Vec<f64>, opts: &SimOptions) -> RunResult {
        let method = ExplicitRungeKutta::dop853()
            .rtol(opts.rtol)
            .atol(opts.atol)
            .max_steps(opts.max_steps);
        run_crate(arm, t0, x0, opts, method, None, &RefCell::new(None))
    }
}

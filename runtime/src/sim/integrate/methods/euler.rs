//! Explicit Euler at the fixed step `dt`: the crate's.

use std::cell::RefCell;

use differential_equations::prelude::*;

use super::super::drivers::{RunResult, run_crate};
use super::super::options::SimOptions;
use super::Integrator;
use super::rk4::fixed_steps;
use crate::arm::Dynamics;

pub(super) struct Euler;

impl Integrator for Euler {
    fn run(&self, arm: &dyn Dynamics, t0: f64, x0: Vec<f64>, opts: &SimOptions) -> RunResult {
        let method = ExplicitRungeKutta::euler(opts.dt).max_steps(fixed_steps(opts));
        run_crate(arm, t0, x0, opts, method, None, &RefCell::new(None))
    }
}

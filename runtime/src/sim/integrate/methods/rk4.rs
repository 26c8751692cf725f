//! The classic Runge-Kutta 4 at the fixed step `dt`: the crate's.

use std::cell::RefCell;

use differential_equations::prelude::*;

use super::super::drivers::{RunResult, run_crate};
use super::super::options::SimOptions;
use super::Integrator;
use crate::arm::Dynamics;

pub(super) struct Rk4;

impl Integrator for Rk4 {
    fn run(&self, arm: &dyn Dynamics, t0: f64, x0: Vec<f64>, opts: &SimOptions) -> RunResult {
        let method = ExplicitRungeKutta::rk4(opts.dt).max_steps(fixed_steps(opts));
        run_crate(arm, t0, x0, opts, method, None, &RefCell::new(None))
    }
}

/// The step budget of a fixed-step method: the steps to t_end and two
/// more, or `max_steps` if larger (t_end / 0 saturates).
pub(super) fn fixed_steps(opts: &SimOptions) -> usize {
    opts.max_steps
        .max(((opts.t_end / opts.dt).ceil() as usize).saturating_add(2))
}

//! Dormand-Prince 5(4), explicit and adaptive: the crate's.

use std::cell::RefCell;

use differential_equations::prelude::*;

use super::super::drivers::{RunResult, run_crate};
use super::super::options::SimOptions;
use super::super::record::Watch;
use super::Integrator;
use crate::arm::Dynamics;

pub(super) struct Dopri5;

impl Integrator for Dopri5 {
    fn run(&self, arm: &dyn Dynamics, t0: f64, x0: Vec<f64>, opts: &SimOptions) -> RunResult {
        watched(arm, t0, x0, opts, None, &RefCell::new(None))
    }
}

/// dopri5 with auto's stiffness watch, which may stop it for a switch.
pub(super) fn watched(
    arm: &dyn Dynamics,
    t0: f64,
    x0: Vec<f64>,
    opts: &SimOptions,
    watch: Option<&Watch<'_>>,
    switch: &RefCell<Option<(f64, Vec<f64>, String)>>,
) -> RunResult {
    let method = ExplicitRungeKutta::dopri5()
        .rtol(opts.rtol)
        .atol(opts.atol)
        .max_steps(opts.max_steps);
    run_crate(arm, t0, x0, opts, method, watch, switch)
}

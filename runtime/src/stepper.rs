//! The interface of the integrators written here (where no crate fits):
//! the system, the options, and the per-step callback through which
//! `integrate` samples, locates events and stops them.

use differential_equations::interpolate::Interpolation;
use nalgebra::DMatrix;

/// y' = f(t, y), with its Jacobian df/dy for implicit methods.
pub trait OdeSystem {
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]);
    fn jacobian(&mut self, t: f64, y: &[f64], j: &mut DMatrix<f64>);
}

pub struct Options {
    pub t_end: f64,
    pub rtol: f64,
    pub atol: f64,
    pub max_steps: usize,
}

/// Sees every accepted step (t_prev, t, y_prev, y, dense output over the
/// step); returns false to stop the run.
pub type StepFn<'a> =
    dyn FnMut(f64, f64, &[f64], &[f64], &mut dyn Interpolation<f64, Vec<f64>>) -> bool + 'a;

/// Counters of a run.
#[derive(Default)]
pub struct Counts {
    pub accepted: usize,
    pub rejected: usize,
}

/// RMS of e_i / (atol + rtol max(|a_i|, |b_i|)).
pub fn error_norm(e: &[f64], a: &[f64], b: &[f64], rtol: f64, atol: f64) -> f64 {
    let sum: f64 = e
        .iter()
        .zip(a.iter().zip(b))
        .map(|(e, (a, b))| (e / (atol + rtol * a.abs().max(b.abs()))).powi(2))
        .sum();
    (sum / e.len().max(1) as f64).sqrt()
}

//! The interface of the integrators written here (where no crate fits):
//! the system, the options, and the per-step callback through which
//! `integrate` samples, locates events and stops them.

use differential_equations::error::Error;
use differential_equations::interpolate::Interpolation;
use nalgebra::DMatrix;

/// Keep the Jacobian for the next step when the Newton iteration contracted
/// faster than this (Hairer's THET; 0.1 is his advice for Jacobians that
/// cost much more than a right-hand side, as an arm's, assembled from 2n
/// directional derivatives, does). radau5 and trbdf2 share it.
pub const REUSE_JACOBIAN_BELOW: f64 = 0.1;

/// The fixed-step implicit methods (gauss, radau5-fixed): Newton stops when
/// the update it expects next is below the user's
/// rtol, relative to the state (gauss's `update_norm`): at a fixed step, rtol
/// says how finely the stages are solved; within limits: tighter than
/// round-off cannot be met, and looser than 1e-4 leaves the stages
/// unsolved whatever rtol says. On the steel rod (rtol 1e-3) Newton
/// contracts by 1e-3 an iteration: two iterations where 1e-6 took three,
/// the tip the same to 0.01 mm over 25 s.
pub const STAGE_TOL: (f64, f64) = (1e-10, 1e-4);

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
    /// generalized-alpha's spectral radius at infinity.
    pub rho_inf: f64,
    /// The step of a fixed-step method (s).
    pub dt: f64,
    /// The state starts with this many positions followed by their rates
    /// (an arm's [q, qd, ...]); 0 when the state has no such split.
    pub positions: usize,
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

/// Checks before a step from (t, y) of size `h`: the step budget and the
/// step-size floor. Clamps `h` to end on `t_end`; true for the last step.
pub fn begin_step(
    counts: &Counts,
    opts: &Options,
    t: f64,
    h: &mut f64,
    y: &[f64],
) -> Result<bool, Error<f64, Vec<f64>>> {
    if counts.accepted + counts.rejected >= opts.max_steps {
        return Err(Error::MaxSteps { t, y: y.to_vec() });
    }
    // A NaN step counts as too small.
    if h.is_nan() || *h < 1e-14 * t.abs().max(1.0) {
        return Err(Error::StepSize { t, y: y.to_vec() });
    }
    let last = t + *h >= opts.t_end;
    if last {
        *h = opts.t_end - t;
    }
    Ok(last)
}

/// The next step size of a method with a third-order-accurate estimate:
/// h 0.9 err^(-1/3) within [h/5, 5h]; no growth right after a rejection, a
/// cut below 0.9 h on one, and a quarter of h when the estimate is not
/// finite (a failed right-hand side).
pub fn next_step(h: f64, err: f64, accepted: bool, rejected_last: bool) -> f64 {
    if !err.is_finite() {
        return 0.25 * h;
    }
    let factor = (0.9 * err.max(1e-10).powf(-1.0 / 3.0)).clamp(0.2, 5.0);
    h * match (accepted, rejected_last) {
        (true, false) => factor,
        (true, true) => factor.min(1.0),
        (false, _) => factor.min(0.9),
    }
}

/// A simplified Newton iteration's convergence (Hairer and Wanner's test,
/// as radau5 has it): the contraction rate between iterates, the
/// slowest seen, and when the next iterate is within the tolerance.
#[derive(Default)]
pub struct Contraction {
    previous: f64,
    slowest: f64,
    iterations: usize,
}

/// What an iterate's scaled norm says.
pub enum Converging {
    /// Go on iterating.
    Continue,
    /// Converged: the slowest contraction seen (the Jacobian is kept for
    /// the next step below `REUSE_JACOBIAN_BELOW`).
    Done(f64),
    /// Diverging, or not a number: a smaller step or a new Jacobian.
    Failed,
}

impl Contraction {
    /// The iterate's update had scaled norm `norm`; `tol` the Newton
    /// tolerance.
    pub fn after(&mut self, norm: f64, tol: f64) -> Converging {
        if !norm.is_finite() {
            return Converging::Failed;
        }
        let first = self.iterations == 0;
        self.iterations += 1;
        let rate = if first { 0.5 } else { norm / self.previous };
        if rate >= 0.9 {
            return Converging::Failed;
        }
        if !first {
            self.slowest = self.slowest.max(rate);
        }
        self.previous = norm;
        if rate / (1.0 - rate) * norm <= tol || norm <= 1e-3 * tol {
            return Converging::Done(self.slowest);
        }
        Converging::Continue
    }
}

/// The first step of an adaptive method of order `order` from (t0, y0),
/// whose rate is `f0`: Hairer, Norsett and Wanner's estimate (Solving
/// ODEs I, II.4), from the sizes of the state and its rate and, by one
/// trial Euler step, of its second derivative. A start at rest in
/// equilibrium has no rate to measure; the trial step then sees what
/// moves it (a load ramped on over 0.1 ms), where a step from the rate
/// alone leapt the whole span and, its error measured from accelerations
/// equal at both ends, was accepted.
pub fn initial_step(
    sys: &mut dyn OdeSystem,
    (t0, y0, f0): (f64, &[f64], &[f64]),
    order: u32,
    opts: &Options,
) -> f64 {
    let (rtol, atol) = (opts.rtol, opts.atol);
    let span = opts.t_end - t0;
    let d0 = error_norm(y0, y0, y0, rtol, atol);
    let d1 = error_norm(f0, y0, y0, rtol, atol);
    let h0 = if d0 < 1e-5 || d1 < 1e-5 {
        1e-6
    } else {
        0.01 * d0 / d1
    }
    .min(span);
    let y1: Vec<f64> = y0.iter().zip(f0).map(|(y, f)| y + h0 * f).collect();
    let mut f1 = vec![0.0; y0.len()];
    sys.rhs(t0 + h0, &y1, &mut f1);
    let df: Vec<f64> = f1.iter().zip(f0).map(|(a, b)| (a - b) / h0).collect();
    let d2 = error_norm(&df, y0, y0, rtol, atol);
    let h1 = if d1.max(d2) <= 1e-15 {
        (h0 * 1e-3).max(1e-6)
    } else {
        (0.01 / d1.max(d2)).powf(1.0 / (order as f64 + 1.0))
    };
    (100.0 * h0).min(h1).clamp(1e-10 * span, span)
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

/// Cubic Hermite interpolation over one step from values and slopes.
pub struct Hermite<'a> {
    pub t0: f64,
    pub h: f64,
    pub y0: &'a [f64],
    pub y1: &'a [f64],
    pub f0: &'a [f64],
    pub f1: &'a [f64],
}

impl Interpolation<f64, Vec<f64>> for Hermite<'_> {
    fn interpolate(&mut self, t: f64) -> Result<Vec<f64>, Error<f64, Vec<f64>>> {
        let s = (t - self.t0) / self.h;
        if !(-1e-12..=1.0 + 1e-12).contains(&s) {
            return Err(Error::OutOfBounds {
                t_interp: t,
                t_prev: self.t0,
                t_curr: self.t0 + self.h,
            });
        }
        let (s2, s3) = (s * s, s * s * s);
        let (h00, h10) = (2.0 * s3 - 3.0 * s2 + 1.0, s3 - 2.0 * s2 + s);
        let (h01, h11) = (-2.0 * s3 + 3.0 * s2, s3 - s2);
        Ok((0..self.y0.len())
            .map(|i| {
                h00 * self.y0[i]
                    + self.h * h10 * self.f0[i]
                    + h01 * self.y1[i]
                    + self.h * h11 * self.f1[i]
            })
            .collect())
    }
}

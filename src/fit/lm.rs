//! Levenberg-Marquardt with bounds: minimise 1/2 |r(theta)|^2 for
//! lo <= theta <= hi, given r and its Jacobian.
//!
//! Written here rather than taken from the `levenberg-marquardt` crate:
//! that crate is built on another nalgebra (0.34; a second copy costs
//! about 19 s of compile time on every fresh build) and has no bounds.
//! A fit has a handful of parameters, so the damped normal equations are
//! small and solved directly; bounds are kept by projection, with a
//! parameter held at its bound while the gradient presses it outward
//! (Kanzow, Yamashita and Fukushima's projected LM). Marquardt's scaling
//! (the damping on diag(J^T J)) makes the step independent of the
//! parameters' units, and Nielsen's update sets the damping from the gain
//! ratio.

use nalgebra::{DMatrix, DVector};

/// Residuals and their Jacobian (rows: residuals, columns: parameters) at
/// theta, or why they could not be computed there (a run that failed).
pub type Evaluate<'a> = dyn FnMut(&[f64]) -> Result<(DVector<f64>, DMatrix<f64>), String> + 'a;

#[derive(Clone, Copy)]
pub struct Options {
    pub max_iterations: usize,
    /// Stop when an accepted step lowers the cost by less than this
    /// fraction.
    pub ftol: f64,
    /// Stop when every parameter moves by less than this fraction of its
    /// value (or of its scale).
    pub xtol: f64,
    /// Asked before each evaluation: true stops the search where it is
    /// (Ctrl-C), with the best values so far.
    pub stop: Option<fn() -> bool>,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            max_iterations: 40,
            ftol: 1e-6,
            xtol: 1e-8,
            stop: None,
        }
    }
}

/// Where the search ended.
pub struct Outcome {
    pub theta: Vec<f64>,
    pub residuals: DVector<f64>,
    pub jacobian: DMatrix<f64>,
    pub initial_cost: f64,
    pub cost: f64,
    pub iterations: usize,
    pub evaluations: usize,
    /// Why it stopped.
    pub status: String,
    pub converged: bool,
    /// Stopped by `Options::stop`.
    pub interrupted: bool,
}

/// Minimise from `theta0` within [lo, hi]; `progress(iteration, theta)`
/// after each accepted step.
pub fn minimise(
    evaluate: &mut Evaluate<'_>,
    theta0: &[f64],
    lo: &[f64],
    hi: &[f64],
    opts: &Options,
    progress: &mut dyn FnMut(usize, &[f64]),
) -> Result<Outcome, String> {
    let m = theta0.len();
    let mut theta: Vec<f64> = (0..m).map(|j| theta0[j].clamp(lo[j], hi[j])).collect();
    let (mut r, mut jac) = evaluate(&theta).map_err(|e| format!("at the start values: {e}"))?;
    let mut evaluations = 1;
    let cost_of = |r: &DVector<f64>| 0.5 * r.norm_squared();
    let initial_cost = cost_of(&r);
    let mut cost = initial_cost;
    let mut lambda = 1e-3;
    let mut nu = 2.0;
    // A value's size for the step test: its start, else its bounds' width.
    let scale: Vec<f64> = (0..m)
        .map(|j| match (theta0[j].abs(), hi[j] - lo[j]) {
            (v, _) if v > 0.0 => v,
            (_, w) if w.is_finite() => w,
            _ => 1.0,
        })
        .collect();
    let mut status = format!("stopped after {} iterations", opts.max_iterations);
    let mut converged = false;
    let mut iterations = 0;
    let mut interrupted = false;
    while iterations < opts.max_iterations {
        if opts.stop.is_some_and(|stop| stop()) {
            status = format!("interrupted after {iterations} iterations");
            interrupted = true;
            break;
        }
        let g = jac.transpose() * &r;
        // Held: at a bound with the descent direction -g pointing out.
        let free: Vec<usize> = (0..m)
            .filter(|&j| !(theta[j] <= lo[j] && g[j] > 0.0 || theta[j] >= hi[j] && g[j] < 0.0))
            .collect();
        if free.is_empty() {
            status = "every parameter is held at a bound".into();
            converged = true;
            break;
        }
        let jf = DMatrix::from_fn(jac.nrows(), free.len(), |i, k| jac[(i, free[k])]);
        let a = jf.transpose() * &jf;
        let gf = DVector::from_fn(free.len(), |k, _| g[free[k]]);
        if gf.amax() <= 1e-14 * cost.max(f64::MIN_POSITIVE).sqrt() * a.diagonal().amax().sqrt() {
            status = "the gradient vanishes".into();
            converged = true;
            break;
        }
        let mut damped = a.clone();
        let diag_floor = 1e-12 * a.diagonal().amax().max(f64::MIN_POSITIVE);
        for k in 0..free.len() {
            damped[(k, k)] += lambda * a[(k, k)].max(diag_floor);
        }
        let Some(step) = damped.clone().cholesky().map(|c| c.solve(&-&gf)) else {
            lambda *= nu;
            nu *= 2.0;
            continue;
        };
        let mut trial = theta.clone();
        for (k, &j) in free.iter().enumerate() {
            trial[j] = (theta[j] + step[k]).clamp(lo[j], hi[j]);
        }
        let moved = DVector::from_fn(free.len(), |k, _| trial[free[k]] - theta[free[k]]);
        // The model's predicted decrease for the projected step.
        let predicted = -(gf.dot(&moved) + 0.5 * moved.dot(&(&a * &moved)));
        let evaluated = evaluate(&trial);
        evaluations += 1;
        let accepted = match evaluated {
            Ok((r_new, j_new)) => {
                let c_new = cost_of(&r_new);
                let rho = (cost - c_new) / predicted.max(f64::MIN_POSITIVE);
                if c_new.is_finite() && c_new < cost && rho > 1e-4 {
                    let drop = (cost - c_new) / cost.max(f64::MIN_POSITIVE);
                    (theta, r, jac, cost) = (trial.clone(), r_new, j_new, c_new);
                    lambda *= (1.0 - (2.0 * rho - 1.0).powi(3)).max(1.0 / 3.0);
                    nu = 2.0;
                    iterations += 1;
                    progress(iterations, &theta);
                    Some(drop)
                } else {
                    None
                }
            }
            Err(_) => None,
        };
        match accepted {
            Some(drop) => {
                let small = free
                    .iter()
                    .enumerate()
                    .all(|(k, &j)| moved[k].abs() <= opts.xtol * theta[j].abs().max(scale[j]));
                if drop < opts.ftol {
                    status = format!("the cost fell by less than {:e} of itself", opts.ftol);
                    converged = true;
                    break;
                }
                if small {
                    status = format!("the parameters moved by less than {:e}", opts.xtol);
                    converged = true;
                    break;
                }
            }
            None => {
                lambda *= nu;
                nu *= 2.0;
                if lambda > 1e16 {
                    status = "no step lowers the cost (damping at its limit)".into();
                    converged = true;
                    break;
                }
            }
        }
    }
    Ok(Outcome {
        theta,
        residuals: r,
        jacobian: jac,
        initial_cost,
        cost,
        iterations,
        evaluations,
        status,
        converged,
        interrupted,
    })
}

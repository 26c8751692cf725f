//! `softarm fit`: a model's numeric values fitted to its `[compare]`
//! record, least squares on the tip over the samples of a window.
//!
//! Each value is named by the path `--set` takes. An evaluation loads the
//! model with the values set (the same structure, so the same kernels),
//! and one perturbed pair per value, and runs the staggered forward
//! sensitivities (`runtime::sensitivity`): the tip's derivatives in every
//! value come with the run, at the cost of the Jacobians along it, not of
//! a run per value. The search is `lm`'s bounded Levenberg-Marquardt;
//! `report` writes what it found.

pub mod lm;
mod problem;
pub mod report;
mod uncertainty;

use std::cell::RefCell;
use std::time::Instant;

use std::path::PathBuf;

use anyhow::{Result, bail};
use eomgen::model::Override;
use nalgebra::DMatrix;

use crate::run::RunRequest;

pub use problem::{Evaluation, Problem};
pub use uncertainty::uncertainty;

/// One value to fit: `PATH` or `PATH=LO:HI`.
#[derive(Clone, Debug, PartialEq)]
pub struct Free {
    pub path: String,
    pub lo: f64,
    pub hi: f64,
}

impl Free {
    pub fn parse(s: &str) -> Result<Self> {
        let (path, bounds) = match s.split_once('=') {
            Some((p, b)) => (p.trim(), Some(b.trim())),
            None => (s.trim(), None),
        };
        if path.is_empty() || path.split('.').any(|k| k.trim().is_empty()) {
            bail!("--free {s}: expected PATH or PATH=LO:HI, e.g. segment.0.youngs_modulus=5e4:5e5");
        }
        let (lo, hi) = match bounds {
            None => (f64::NEG_INFINITY, f64::INFINITY),
            Some(b) => {
                let bound = |v: &str, inf: f64| -> Result<f64> {
                    match v.trim() {
                        "" => Ok(inf),
                        v => v.parse::<f64>().map_err(|_| {
                            anyhow::anyhow!("--free {s}: the bound `{v}` is not a number (LO:HI, either may be empty)")
                        }),
                    }
                };
                let Some((lo, hi)) = b.split_once(':') else {
                    bail!(
                        "--free {s}: bounds are LO:HI, e.g. {path}=1e4:1e6 (either may be empty)"
                    );
                };
                (bound(lo, f64::NEG_INFINITY)?, bound(hi, f64::INFINITY)?)
            }
        };
        if lo.is_nan() || hi.is_nan() || lo >= hi {
            bail!("--free {s}: LO must be below HI, got {lo} and {hi}");
        }
        Ok(Self {
            path: path.to_string(),
            lo,
            hi,
        })
    }
}

/// Where the fit is checked on data it did not see.
#[derive(Clone, Debug)]
pub enum Validation {
    /// Another window of the same record.
    Window([f64; 2]),
    /// Another model file (another record of the same arm), with the
    /// fitted values set on it.
    Model(String),
}

impl Validation {
    /// `A:B` (seconds), or a model file or name.
    pub fn parse(s: &str) -> Result<Self> {
        let is_file = std::path::Path::new(s).exists();
        match s.contains(':') && !is_file {
            true => Ok(Self::Window(parse_window("--validate", s)?)),
            false => Ok(Self::Model(s.to_string())),
        }
    }
}

/// `A:B` in seconds, 0 <= A < B; `flag` names it in the error.
pub fn parse_window(flag: &str, s: &str) -> Result<[f64; 2]> {
    let parsed = s
        .split_once(':')
        .and_then(|(a, b)| Some([a.trim().parse::<f64>().ok()?, b.trim().parse::<f64>().ok()?]));
    match parsed {
        Some([a, b]) if a < b && a >= 0.0 && b.is_finite() => Ok([a, b]),
        _ => bail!("{flag} {s}: expected A:B in seconds with 0 <= A < B, e.g. 7:30"),
    }
}

/// A fit as asked, by the command line or Python.
pub struct Request {
    pub model: String,
    pub overrides: Vec<Override>,
    pub free: Vec<Free>,
    /// The fit window [default: the record's].
    pub window: Option<[f64; 2]>,
    pub validate: Option<Validation>,
    pub run: RunRequest,
    pub cache_dir: Option<PathBuf>,
    pub lm: lm::Options,
}

/// A request checked: its problems and windows, nothing run yet.
pub struct Prepared {
    pub problem: Problem,
    pub window: [f64; 2],
    /// Another model's problem and its window, for `Validation::Model`.
    other: Option<(Problem, [f64; 2])>,
    /// A validation window of the same record.
    same: Option<[f64; 2]>,
}

/// Check a request: the model, its record, every free value.
pub fn prepare(req: &Request) -> Result<Prepared> {
    let problem = Problem::new(
        &req.model,
        req.overrides.clone(),
        req.free.clone(),
        req.run.clone(),
        req.cache_dir.clone(),
    )?;
    let window = req.window.unwrap_or_else(|| problem.record_window());
    let m = req.free.len();
    check_window(&problem, "--window", window, (m + 2).div_ceil(3).max(2))?;
    let (other, same) = match &req.validate {
        None => (None, None),
        Some(Validation::Window(w)) => (None, Some(*w)),
        Some(Validation::Model(spec)) => {
            let p = Problem::new(
                spec,
                req.overrides.clone(),
                req.free.clone(),
                req.run.clone(),
                req.cache_dir.clone(),
            )?;
            let w = p.record_window();
            check_window(&p, "--validate", w, 1)?;
            (Some((p, w)), None)
        }
    };
    if let Some(w) = same {
        check_window(&problem, "--validate", w, 1)?;
    }
    Ok(Prepared {
        problem,
        window,
        other,
        same,
    })
}

/// A window must hold `least` of the record's samples: an empty one
/// would be fitted trivially, or report an error of nothing.
fn check_window(p: &Problem, flag: &str, w: [f64; 2], least: usize) -> Result<()> {
    let n = p.samples_in(w);
    if n < least {
        let r = p.record_window();
        bail!(
            "{flag} {}:{}: {} has {n} samples there, and needs at least {least}; its record spans {} to {} s",
            w[0],
            w[1],
            p.label(),
            r[0],
            r[1]
        );
    }
    Ok(())
}

impl Prepared {
    /// A validation window of the fitted record itself, to shade.
    pub fn shaded(&self) -> Option<[f64; 2]> {
        self.same
    }

    pub fn fit(&self, opts: &lm::Options, progress: &mut dyn FnMut(usize, f64)) -> Result<Fitted> {
        let validation = match (&self.other, self.same) {
            (Some((p, w)), _) => Some((p, *w)),
            (None, Some(w)) => Some((&self.problem, w)),
            (None, None) => None,
        };
        fit(&self.problem, self.window, validation, opts, progress)
    }
}

/// Mean tip error (m) before and after.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct Costs {
    pub initial: f64,
    #[serde(rename = "final")]
    pub fitted: f64,
    pub window_s: [f64; 2],
    pub samples: usize,
}

/// What a fit found.
pub struct Fitted {
    pub names: Vec<String>,
    pub initial: Vec<f64>,
    pub values: Vec<f64>,
    pub std_error: Vec<f64>,
    pub correlation: DMatrix<f64>,
    pub fit_cost: Costs,
    pub validation_cost: Option<Costs>,
    pub iterations: usize,
    pub evaluations: usize,
    pub wall_s: f64,
    pub status: String,
    pub converged: bool,
    /// Stopped by a signal: the values are the best so far.
    pub interrupted: bool,
    /// Values that ended on a bound.
    pub at_bound: Vec<String>,
    /// Pairs the data cannot separate: |correlation| above 0.99.
    pub inseparable: Vec<(String, String, f64)>,
    /// The runs at the start and at the fitted values, for the plot.
    pub start_run: Evaluation,
    pub fitted_run: Evaluation,
}

/// Correlation above which two values are reported as inseparable.
pub const INSEPARABLE: f64 = 0.99;

/// Fit `problem`'s free values to its record over `window`, checking on
/// `validation` (`problem` itself for another window of its record, or
/// another model's); `progress(iteration, mean tip error in window)`.
pub fn fit(
    problem: &Problem,
    window: [f64; 2],
    validation: Option<(&Problem, [f64; 2])>,
    opts: &lm::Options,
    progress: &mut dyn FnMut(usize, f64),
) -> Result<Fitted> {
    let start = Instant::now();
    let theta0 = problem.start_values();
    let (lo, hi) = problem.bounds();
    // Every run is kept: the start's and the optimum's are reported.
    let runs: RefCell<Vec<(Vec<f64>, Evaluation)>> = RefCell::new(Vec::new());
    let mut evaluate = |theta: &[f64]| {
        let e = problem
            .evaluate(theta, true, window[1])
            .map_err(|e| format!("{e:#}"))?;
        let out = e.residuals(window);
        runs.borrow_mut().push((theta.to_vec(), e));
        Ok(out)
    };
    let run_at = |theta: &[f64]| {
        (runs.borrow().iter())
            .find(|(t, _)| t == theta)
            .map(|(_, e)| e.clone())
    };
    let mut report = |k: usize, theta: &[f64]| {
        if let Some(e) = run_at(theta) {
            progress(k, e.mean_error(window));
        }
    };
    let out = lm::minimise(&mut evaluate, &theta0, &lo, &hi, opts, &mut report)
        .map_err(|e| anyhow::anyhow!("{}: {e}", problem.label()))?;
    // The start and the optimum again, without derivatives, as far as
    // the validation window reaches.
    let end = match validation {
        Some((p, w)) if std::ptr::eq(p, problem) => problem.end_of(window).max(p.end_of(w)),
        _ => problem.end_of(window),
    };
    let start_run = problem.evaluate(&theta0, false, end)?;
    let fitted_run = problem.evaluate(&out.theta, false, end)?;
    let fit_cost = Costs {
        initial: start_run.mean_error(window),
        fitted: fitted_run.mean_error(window),
        window_s: window,
        samples: fitted_run.samples(window),
    };
    let validation_cost = match validation {
        None => None,
        Some((p, w)) => {
            let (a, b) = match std::ptr::eq(p, problem) {
                true => (start_run.clone(), fitted_run.clone()),
                false => (
                    p.evaluate(&theta0, false, p.end_of(w))?,
                    p.evaluate(&out.theta, false, p.end_of(w))?,
                ),
            };
            Some(Costs {
                initial: a.mean_error(w),
                fitted: b.mean_error(w),
                window_s: w,
                samples: b.samples(w),
            })
        }
    };
    let (std_error, correlation) = uncertainty(&out.residuals, &out.jacobian);
    let names = problem.names();
    let m = names.len();
    let at_bound = (0..m)
        .filter(|&j| out.theta[j] <= lo[j] || out.theta[j] >= hi[j])
        .map(|j| names[j].clone())
        .collect();
    let mut inseparable = Vec::new();
    for a in 0..m {
        for b in a + 1..m {
            let c = correlation[(a, b)];
            if c.abs() > INSEPARABLE || c.is_nan() {
                inseparable.push((names[a].clone(), names[b].clone(), c));
            }
        }
    }
    Ok(Fitted {
        names,
        initial: theta0,
        values: out.theta,
        std_error,
        correlation,
        fit_cost,
        validation_cost,
        iterations: out.iterations,
        evaluations: out.evaluations,
        wall_s: start.elapsed().as_secs_f64(),
        status: out.status,
        converged: out.converged,
        interrupted: out.interrupted,
        at_bound,
        inseparable,
        start_run,
        fitted_run,
    })
}

/// The residual rows of the samples in `window`: 3 a sample (x, y, z).
pub fn rows_in(times: &[f64], window: [f64; 2]) -> Vec<usize> {
    (0..times.len())
        .filter(|&i| times[i] >= window[0] && times[i] <= window[1])
        .collect()
}

//! The largest fixed step that keeps a run within a tolerance (the
//! chapter's step-size procedure for fixed-step use, as a controller
//! needs): a tight variable-step reference (dop853, or radau5 for the
//! implicit gauss and radau5-fixed), then fixed steps of T / 2^k
//! until the tip stays within the tolerance of the reference at every
//! sample.

use anyhow::{Result, bail};
use runtime::{SimOptions, Solver, simulate};
use serde::Serialize;

use crate::backend::Loaded;

/// What the search found.
#[derive(Debug, Serialize)]
pub struct StepChoice {
    pub solver: &'static str,
    /// The largest step tried whose tip error is within the tolerance (s).
    pub dt: f64,
    /// Its largest tip distance from the reference over the run (m).
    pub error_m: f64,
    /// The next larger step tried and its error (None: the run failed, or
    /// the first step tried already held).
    pub coarser_dt: Option<f64>,
    pub coarser_error_m: Option<f64>,
    /// The reference's steps: dop853 at rtol 1e-10, or radau5 for an
    /// implicit method (whose arm may be stiff).
    pub reference_steps: usize,
    pub tolerance_m: f64,
}

/// The tips of a run of `solver` (step `dt` for a fixed-step one) at the
/// `samples` + 1 even times of [0, t_end]; None if it fails.
fn tips(loaded: &Loaded, x0: &[f64], opts: SimOptions) -> Option<(Vec<[f64; 3]>, usize)> {
    let (traj, stats) = simulate(&*loaded.arm, x0.to_vec(), &opts).ok()?;
    let tips = crate::run::tips(loaded, &traj)
        .into_iter()
        .map(|(_, p)| p)
        .collect();
    Some((tips, stats.steps))
}

/// The largest fixed step of `solver` (a fixed-step one) from `x0` over
/// `t_end` whose tip stays within `tolerance` (m) of the reference.
pub fn choose(
    loaded: &Loaded,
    x0: &[f64],
    t_end: f64,
    solver: Solver,
    tolerance: f64,
) -> Result<StepChoice> {
    if !solver.fixed_step() {
        bail!(
            "--solver {}: not a fixed-step solver (rk4, euler, gauss or radau5-fixed)",
            solver.name()
        );
    }
    if !(tolerance > 0.0 && tolerance.is_finite()) {
        bail!("--tol must be a positive distance (m), got {tolerance}");
    }
    const SAMPLES: f64 = 200.0;
    let base = SimOptions {
        t_end,
        output_dt: t_end / SAMPLES,
        ..Default::default()
    };
    // An implicit method's arm may be stiff: its reference is implicit too.
    let reference = SimOptions {
        solver: match solver.implicit() {
            true => Solver::Radau5,
            false => Solver::Dop853,
        },
        rtol: 1e-10,
        atol: 1e-13,
        ..base.clone()
    };
    let by = reference.solver.name();
    let Some((want, reference_steps)) = tips(loaded, x0, reference) else {
        bail!(
            "the reference run ({by} at rtol 1e-10) failed: the arm cannot be run over {t_end} s"
        );
    };
    let error = |dt: f64| -> f64 {
        let opts = SimOptions {
            solver,
            dt,
            ..base.clone()
        };
        match tips(loaded, x0, opts) {
            Some((got, _)) if got.len() == want.len() => (got.iter().zip(&want))
                .map(|(a, b)| (0..3).map(|c| (a[c] - b[c]).powi(2)).sum::<f64>().sqrt())
                .fold(0.0, f64::max),
            _ => f64::INFINITY,
        }
    };
    // Steps that divide the samples' spacing: T / (200 2^k).
    let mut coarser: Option<(f64, f64)> = None;
    for k in 0..24 {
        let dt = t_end / SAMPLES / 2f64.powi(k);
        let e = error(dt);
        if e <= tolerance {
            return Ok(StepChoice {
                solver: solver.name(),
                dt,
                error_m: e,
                coarser_dt: coarser.map(|c| c.0),
                coarser_error_m: coarser.and_then(|c| c.1.is_finite().then_some(c.1)),
                reference_steps,
                tolerance_m: tolerance,
            });
        }
        coarser = Some((dt, e));
    }
    let (dt, e) = coarser.expect("steps were tried");
    bail!(
        "no step down to {dt:.1e} s keeps the tip within {tolerance} m (at that step: {e:.2e} m); try a looser --tol or an implicit solver"
    )
}

//! TR-BDF2 (Hosea and Shampine 1996, MATLAB's ode23tb): a trapezoidal
//! stage to t + gamma h, then BDF2 to t + h, gamma = 2 - sqrt(2), so both
//! implicit stages share the Newton matrix I - d h J. L-stable, second
//! order, with a third-order embedded estimate filtered through that matrix
//! (so stiff components do not inflate it), and cubic Hermite dense output.
//! The moderate-accuracy stiff solver: one factorisation per step of size
//! m, where Radau IIA needs one of size 3m.
//!
//! Ours because the crate's ESDIRK gives up on stiff arms ("stiffness
//! detected" at t = 0.021 s on the stiff cantilever of BENCHMARKS.md).

use differential_equations::error::Error;
use nalgebra::{DMatrix, DVector};

use super::super::stepper::{
    Contraction, Converging, Counts, Hermite, OdeSystem, Options, REUSE_JACOBIAN_BELOW, StepFn,
    begin_step, error_norm, initial_step, next_step,
};

const SQRT2: f64 = std::f64::consts::SQRT_2;
const GAMMA: f64 = 2.0 - SQRT2;
const D: f64 = GAMMA / 2.0;
const W: f64 = SQRT2 / 4.0;
/// y_new - y_hat = h (E0 k1 + E1 k2 + E2 k3), the embedded pair's difference.
const E0: f64 = (4.0 * W - 1.0) / 3.0;
const E1: f64 = -1.0 / 3.0;
const E2: f64 = 2.0 * D / 3.0;
const MAX_NEWTON: usize = 6;

/// Solve x = base + d h f(t, x) by simplified Newton from `x` (in place);
/// `k` receives f(t, x). False if it does not converge.
#[allow(clippy::too_many_arguments)]
fn newton(
    sys: &mut dyn OdeSystem,
    lu: &nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn>,
    t: f64,
    dh: f64,
    base: &[f64],
    x: &mut [f64],
    k: &mut [f64],
    scale: &[f64],
    tol: f64,
) -> Option<f64> {
    let m = x.len();
    let mut contraction = Contraction::default();
    for _ in 0..MAX_NEWTON {
        sys.rhs(t, x, k);
        let r = DVector::from_iterator(m, (0..m).map(|i| base[i] + dh * k[i] - x[i]));
        let dx = lu.solve(&r)?;
        let norm = (dx
            .iter()
            .zip(scale)
            .map(|(v, s)| (v / s).powi(2))
            .sum::<f64>()
            / m as f64)
            .sqrt();
        if norm.is_finite() {
            for i in 0..m {
                x[i] += dx[i];
            }
        }
        match contraction.after(norm, tol) {
            Converging::Continue => {}
            Converging::Failed => return None,
            Converging::Done(slowest) => {
                sys.rhs(t, x, k);
                return Some(slowest);
            }
        }
    }
    None
}

/// Integrate from (t0, y0) to `opts.t_end`.
pub fn integrate(
    sys: &mut dyn OdeSystem,
    t0: f64,
    y0: Vec<f64>,
    opts: &Options,
    step: &mut StepFn<'_>,
    counts: &mut Counts,
) -> Result<(), Error<f64, Vec<f64>>> {
    let m = y0.len();
    let t_end = opts.t_end;
    let (rtol, atol) = (opts.rtol, opts.atol);
    let newton_tol = 0.03f64.min(rtol.sqrt()).max(10.0 * f64::EPSILON / rtol);
    let (mut t, mut y) = (t0, y0);
    let mut k1 = vec![0.0; m];
    sys.rhs(t, &y, &mut k1);
    let (mut k2, mut k3) = (vec![0.0; m], vec![0.0; m]);
    let (mut z, mut y_new, mut base) = (vec![0.0; m], vec![0.0; m], vec![0.0; m]);
    let mut j = DMatrix::zeros(m, m);
    // Whether J must be evaluated before the next attempt, and whether the J
    // in hand was evaluated at the current point (kept while Newton
    // contracts fast, as radau5 does).
    let (mut need_jacobian, mut fresh) = (true, false);
    let mut h = initial_step(sys, (t0, &y, &k1), 2, opts);
    let mut rejected_last = false;
    while t < t_end {
        let last = begin_step(counts, opts, t, &mut h, &y)?;
        if need_jacobian {
            sys.jacobian(t, &y, &mut j);
            (need_jacobian, fresh) = (false, true);
        }
        let mut e = -(&j) * (D * h);
        for i in 0..m {
            e[(i, i)] += 1.0;
        }
        let lu = e.lu();
        let scale: Vec<f64> = y.iter().map(|v| atol + rtol * v.abs()).collect();
        // Trapezoidal stage: z = y + d h (k1 + f(t + gamma h, z)).
        for i in 0..m {
            base[i] = y[i] + D * h * k1[i];
            z[i] = y[i] + GAMMA * h * k1[i];
        }
        let ok = newton(
            sys,
            &lu,
            t + GAMMA * h,
            D * h,
            &base,
            &mut z,
            &mut k2,
            &scale,
            newton_tol,
        );
        // BDF2 stage: y_new = y + w h (k1 + k2) + d h f(t + h, y_new).
        let ok = ok.and_then(|first| {
            for i in 0..m {
                base[i] = y[i] + W * h * (k1[i] + k2[i]);
                y_new[i] = y[i] + h * k2[i];
            }
            let t_new = if last { t_end } else { t + h };
            newton(
                sys,
                &lu,
                t_new,
                D * h,
                &base,
                &mut y_new,
                &mut k3,
                &scale,
                newton_tol,
            )
            .map(|second| first.max(second))
        });
        let Some(contraction) = ok else {
            // A stale Jacobian may be why: take a new one as well.
            counts.rejected += 1;
            rejected_last = true;
            need_jacobian = !fresh;
            h *= 0.25;
            continue;
        };
        // The estimate, filtered by (I - d h J)^-1 as in ode23tb.
        let raw = DVector::from_iterator(
            m,
            (0..m).map(|i| h * (E0 * k1[i] + E1 * k2[i] + E2 * k3[i])),
        );
        let filtered: Vec<f64> = lu
            .solve(&raw)
            .map(|v| v.iter().copied().collect())
            .unwrap_or_else(|| vec![f64::INFINITY; m]);
        let err = error_norm(&filtered, &y, &y_new, rtol, atol);
        if err <= 1.0 {
            counts.accepted += 1;
            let t_new = if last { t_end } else { t + h };
            let mut dense = Hermite {
                t0: t,
                h: t_new - t,
                y0: &y,
                y1: &y_new,
                f0: &k1,
                f1: &k3,
            };
            let keep_going = step(t, t_new, &y, &y_new, &mut dense);
            t = t_new;
            std::mem::swap(&mut y, &mut y_new);
            std::mem::swap(&mut k1, &mut k3);
            need_jacobian = contraction > REUSE_JACOBIAN_BELOW;
            fresh = false;
            h = next_step(h, err, true, rejected_last);
            rejected_last = false;
            if !keep_going {
                return Ok(());
            }
        } else {
            counts.rejected += 1;
            h = next_step(h, err, false, rejected_last);
            rejected_last = true;
        }
    }
    Ok(())
}

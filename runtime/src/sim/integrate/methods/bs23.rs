//! Bogacki-Shampine 3(2), explicit and adaptive (MATLAB's ode23): three
//! new stages per step thanks to first-same-as-last, a second-order
//! embedded estimate, and cubic Hermite dense output. For loose tolerances
//! and mildly stiff arms, where dopri5's higher order buys little. Written
//! here because `differential-equations` 0.7 has no such tableau and its
//! explicit methods cannot take one from outside the crate.

use differential_equations::error::Error;

use super::super::stepper::{
    Counts, Hermite, OdeSystem, Options, StepFn, begin_step, error_norm, initial_step, next_step,
};

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
    let (mut t, mut y) = (t0, y0);
    let mut k1 = vec![0.0; m];
    sys.rhs(t, &y, &mut k1);
    let (mut k2, mut k3, mut k4) = (vec![0.0; m], vec![0.0; m], vec![0.0; m]);
    let (mut stage, mut y_new, mut err) = (vec![0.0; m], vec![0.0; m], vec![0.0; m]);
    let mut h = initial_step(sys, (t0, &y, &k1), 3, opts);
    let mut rejected_last = false;
    while t < t_end {
        let last = begin_step(counts, opts, t, &mut h, &y)?;
        for i in 0..m {
            stage[i] = y[i] + 0.5 * h * k1[i];
        }
        sys.rhs(t + 0.5 * h, &stage, &mut k2);
        for i in 0..m {
            stage[i] = y[i] + 0.75 * h * k2[i];
        }
        sys.rhs(t + 0.75 * h, &stage, &mut k3);
        for i in 0..m {
            y_new[i] = y[i] + h * (2.0 / 9.0 * k1[i] + 1.0 / 3.0 * k2[i] + 4.0 / 9.0 * k3[i]);
        }
        let t_new = if last { t_end } else { t + h };
        sys.rhs(t_new, &y_new, &mut k4);
        for i in 0..m {
            err[i] =
                h * (-5.0 / 72.0 * k1[i] + 1.0 / 12.0 * k2[i] + 1.0 / 9.0 * k3[i] - 0.125 * k4[i]);
        }
        let e = error_norm(&err, &y, &y_new, opts.rtol, opts.atol);
        if e <= 1.0 {
            counts.accepted += 1;
            let mut dense = Hermite {
                t0: t,
                h: t_new - t,
                y0: &y,
                y1: &y_new,
                f0: &k1,
                f1: &k4,
            };
            let keep_going = step(t, t_new, &y, &y_new, &mut dense);
            t = t_new;
            std::mem::swap(&mut y, &mut y_new);
            std::mem::swap(&mut k1, &mut k4);
            h = next_step(h, e, true, rejected_last);
            rejected_last = false;
            if !keep_going {
                return Ok(());
            }
        } else {
            counts.rejected += 1;
            h = next_step(h, e, false, rejected_last);
            rejected_last = true;
        }
    }
    Ok(())
}

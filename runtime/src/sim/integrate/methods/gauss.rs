//! Gauss-Legendre with two stages (order 4) at a fixed step: the implicit
//! Runge-Kutta method of the highest order for its stages, A-stable and
//! symplectic, without numerical damping (|R(i w h)| = 1). An undamped
//! structure keeps its energy and every mode its amplitude at any step,
//! and the modes the step resolves their periods to O((w h)^4): over the
//! hundreds of periods a lightly damped rod rings, generalized-alpha's
//! second-order phase error adds up where this one's does not, while the
//! unexcited modes far above the step (twist, a basis' highest bends)
//! stay bounded instead of holding the step as they hold an explicit
//! method's. The step is the user's (`dt`; `softarm fixed-step` chooses
//! one); each solves its two stages together by simplified Newton on
//! I - h (A x J), J kept across steps while the iteration contracts fast.

use differential_equations::error::Error;
use nalgebra::{DMatrix, DVector};

use differential_equations::interpolate::Interpolation;

use super::super::stepper::{
    Contraction, Converging, Counts, OdeSystem, Options, REUSE_JACOBIAN_BELOW, STAGE_TOL, StepFn,
    begin_step,
};

const S3: f64 = 1.732_050_807_568_877_2;
/// Nodes and coefficients.
const C: [f64; 2] = [0.5 - S3 / 6.0, 0.5 + S3 / 6.0];
const A: [[f64; 2]; 2] = [[0.25, 0.25 - S3 / 6.0], [0.25 + S3 / 6.0, 0.25]];
/// y_new = y + D1 Z1 + D2 Z2 (b^T A^-1 on the stage increments Z_i =
/// Y_i - y): no right-hand side at the converged stages.
const D: [f64; 2] = [-S3, S3];
const MAX_NEWTON: usize = 10;

/// The Newton matrix I - h (A x J) of step `h`, factored.
fn factor(j: &DMatrix<f64>, h: f64) -> nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn> {
    let m = j.nrows();
    let mut n = DMatrix::identity(2 * m, 2 * m);
    for (r, row) in A.iter().enumerate() {
        for (c, a) in row.iter().enumerate() {
            let mut block = n.view_mut((r * m, c * m), (m, m));
            block -= j * (h * a);
        }
    }
    n.lu()
}

/// The stage increments Z = [Z1; Z2] of the step from (t, y), from the
/// guess in `z`; the slowest contraction, or None if Newton fails.
fn stages(
    sys: &mut dyn OdeSystem,
    lu: &nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn>,
    (t, h): (f64, f64),
    y: &[f64],
    z: &mut [f64],
    (positions, tol): (usize, f64),
) -> Option<f64> {
    let m = y.len();
    let mut f = [vec![0.0; m], vec![0.0; m]];
    let mut at = vec![0.0; m];
    let mut contraction = Contraction::default();
    for _ in 0..MAX_NEWTON {
        for (i, fi) in f.iter_mut().enumerate() {
            for k in 0..m {
                at[k] = y[k] + z[i * m + k];
            }
            sys.rhs(t + C[i] * h, &at, fi);
        }
        let r = DVector::from_iterator(
            2 * m,
            (0..2 * m).map(|p| {
                let (i, k) = (p / m, p % m);
                h * (A[i][0] * f[0][k] + A[i][1] * f[1][k]) - z[p]
            }),
        );
        let dz = lu.solve(&r)?;
        let norm = update_norm(dz.as_slice(), y, z, positions);
        if norm.is_finite() {
            for (zp, d) in z.iter_mut().zip(dz.iter()) {
                *zp += d;
            }
        }
        match contraction.after(norm, tol) {
            Converging::Continue => {}
            Converging::Failed => return None,
            Converging::Done(slowest) => return Some(slowest),
        }
    }
    None
}

/// The size of Newton's update `dz` of the stage increments `z` from
/// `y`. With the state's first `positions` entries positions and the next
/// as many their rates: the positions' update against the positions'
/// scale, and any further state (relaxing forces) against its own. A
/// rate's update is measured by what it moves: after the first iteration
/// the positions' rows, linear, hold exactly, Z_q = h A (v + Z_v), so the
/// positions' update is the rates' integrated over the stages. Measured
/// against the rates themselves, an undamped structure's modes far above
/// the step, whose rates swing by their size from step to step, held
/// Newton to iterations that moved no position. Each scale is the
/// state's, or the step's change where the state is zero (a start at rest
/// in the rest shape). Without positions, the whole state.
fn update_norm(dz: &[f64], y: &[f64], z: &[f64], positions: usize) -> f64 {
    let m = y.len();
    let n = positions.min(m / 2);
    let part = |range: std::ops::Range<usize>| {
        let of = |v: &[f64], stages: usize| {
            (0..stages)
                .flat_map(|i| v[i * m + range.start..i * m + range.end].iter())
                .fold(0.0f64, |s, x| s.max(x.abs()))
        };
        of(dz, 2) / of(y, 1).max(of(z, 2)).max(f64::MIN_POSITIVE)
    };
    match n {
        0 => part(0..m),
        _ => part(0..n).max(part(2 * n..m)),
    }
}

/// Lagrange weights of the collocation polynomial at tau (in steps from
/// the step's start) on its nodes 0, c1, c2, for the stage increments.
fn weights(tau: f64) -> [f64; 2] {
    [
        tau * (tau - C[1]) / (C[0] * (C[0] - C[1])),
        tau * (tau - C[0]) / (C[1] * (C[1] - C[0])),
    ]
}

/// The step's dense output: its collocation polynomial, through y0 and
/// the stages, which ends on the new state (order 2 inside the step).
struct Collocation<'a> {
    t0: f64,
    h: f64,
    y0: &'a [f64],
    z: &'a [f64],
}

impl Interpolation<f64, Vec<f64>> for Collocation<'_> {
    fn interpolate(&mut self, t: f64) -> Result<Vec<f64>, Error<f64, Vec<f64>>> {
        let tau = (t - self.t0) / self.h;
        if !(-1e-12..=1.0 + 1e-12).contains(&tau) {
            return Err(Error::OutOfBounds {
                t_interp: t,
                t_prev: self.t0,
                t_curr: self.t0 + self.h,
            });
        }
        let [w1, w2] = weights(tau);
        let m = self.y0.len();
        Ok((0..m)
            .map(|k| self.y0[k] + w1 * self.z[k] + w2 * self.z[m + k])
            .collect())
    }
}

/// Integrate from (t0, y0) to `opts.t_end` at the step `opts.dt`.
pub fn integrate(
    sys: &mut dyn OdeSystem,
    t0: f64,
    y0: Vec<f64>,
    opts: &Options,
    step: &mut StepFn<'_>,
    counts: &mut Counts,
) -> Result<(), Error<f64, Vec<f64>>> {
    let m = y0.len();
    let tol = opts.rtol.clamp(STAGE_TOL.0, STAGE_TOL.1);
    let (mut t, mut y) = (t0, y0);
    let mut jac = DMatrix::zeros(m, m);
    let mut lu: Option<(f64, nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn>)> = None;
    let mut fresh = false;
    // The first step's stages from the derivative at the start; each
    // later one's from the last step's collocation polynomial.
    let mut f0 = vec![0.0; m];
    sys.rhs(t, &y, &mut f0);
    let mut predicted: Option<(f64, Vec<f64>)> = None;
    let mut y1 = vec![0.0; m];
    loop {
        let mut h = opts.dt;
        let last = begin_step(counts, opts, t, &mut h, &y)?;
        if lu.as_ref().is_none_or(|(hl, _)| *hl != h) {
            if !fresh {
                sys.jacobian(t, &y, &mut jac);
                fresh = true;
            }
            lu = Some((h, factor(&jac, h)));
        }
        let mut z = match &predicted {
            Some((h_old, z_old)) => extrapolate(z_old, h / h_old),
            None => (0..2 * m).map(|p| C[p / m] * h * f0[p % m]).collect(),
        };
        let lu_now = &lu.as_ref().expect("factored above").1;
        let slowest = match stages(sys, lu_now, (t, h), &y, &mut z, (opts.positions, tol)) {
            Some(s) => s,
            None if !fresh => {
                // A Jacobian from an earlier state: a new one, and again
                // from the start's derivative.
                sys.jacobian(t, &y, &mut jac);
                lu = Some((h, factor(&jac, h)));
                sys.rhs(t, &y, &mut f0);
                z = (0..2 * m).map(|p| C[p / m] * h * f0[p % m]).collect();
                let lu_now = &lu.as_ref().expect("factored above").1;
                stages(sys, lu_now, (t, h), &y, &mut z, (opts.positions, tol))
                    .ok_or(Error::StepSize { t, y: y.clone() })?
            }
            None => return Err(Error::StepSize { t, y: y.clone() }),
        };
        for k in 0..m {
            y1[k] = y[k] + D[0] * z[k] + D[1] * z[m + k];
        }
        counts.accepted += 1;
        let mut dense = Collocation {
            t0: t,
            h,
            y0: &y,
            z: &z,
        };
        if !step(t, t + h, &y, &y1, &mut dense) {
            return Ok(());
        }
        t = if last { opts.t_end } else { t + h };
        std::mem::swap(&mut y, &mut y1);
        predicted = Some((h, z));
        // Keep J while Newton contracts fast; else a new one next step.
        if slowest > REUSE_JACOBIAN_BELOW {
            sys.jacobian(t, &y, &mut jac);
            lu = Some((h, factor(&jac, h)));
            fresh = true;
        } else {
            fresh = false;
        }
        if last {
            return Ok(());
        }
    }
}

/// The next step's stage increments from the last step's collocation
/// polynomial (increments `z`), the new step `ratio` times the last.
fn extrapolate(z: &[f64], ratio: f64) -> Vec<f64> {
    let m = z.len() / 2;
    let end = weights(1.0);
    (0..2 * m)
        .map(|p| {
            let (i, k) = (p / m, p % m);
            let [w1, w2] = weights(1.0 + C[i] * ratio);
            (w1 - end[0]) * z[k] + (w2 - end[1]) * z[m + k]
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::super::oscillate;
    use super::*;

    /// A mode far above the step (w h = 50) keeps its amplitude and turns
    /// by the method's own phase a step, arg R(i w h), with the stability
    /// function R(z) = (1 + z/2 + z^2/12) / (1 - z/2 + z^2/12): no
    /// numerical damping, where generalized-alpha takes rho_inf of it a
    /// step.
    #[test]
    fn a_mode_far_above_the_step_keeps_its_amplitude() {
        let (w, h, steps) = (1.0e4, 5e-3, 7);
        let (last, counts) = oscillate(integrate, (w, h, steps), 1e-6);
        let wh = w * h;
        let phase = 2.0 * (wh / 2.0).atan2(1.0 - wh * wh / 12.0);
        let n = counts.accepted as f64;
        assert_eq!(counts.accepted, steps);
        let (x, v) = ((n * phase).cos(), -w * (n * phase).sin());
        assert!((last[0] - x).abs() < 1e-9, "x {} against {x}", last[0]);
        assert!((last[1] - v).abs() < 1e-9 * w, "v {} against {v}", last[1]);
    }
}

//! Radau IIA of order 5 (three stages), after Hairer and Wanner's RADAU5
//! (Solving ODEs II, section IV.8): simplified Newton on the stage
//! increments with the analytic Jacobian, the embedded error estimate
//! filtered through (gamma/h - J)^-1, and the collocation polynomial as
//! dense output.
//!
//! Ours rather than the `differential-equations` crate's because that one
//! stalls at about 1e-6 on nonlinear problems whatever the tolerance (a
//! plain pendulum at rtol 1e-12: 31 steps, error 1.4e-6; measured
//! 2026-11-21), which an accurate reference solver cannot afford. The
//! Newton system is solved in Hairer's transformed form: A^-1 = T Lambda
//! T^-1 with one real eigenvalue and a complex pair, so the 3m x 3m
//! matrix I - h (A (x) J) becomes one real m x m matrix (u1/h - J) and
//! one complex one ((alpha + i beta)/h - J), about a fifth of the work of
//! factoring it whole (which was half the run time of the STIFF-FLOP
//! record by rom). The real one is also the error estimate's filter.

use differential_equations::error::Error;
use differential_equations::interpolate::Interpolation;
use nalgebra::{Complex, DMatrix, DVector};

use super::super::stepper::{Counts, OdeSystem, Options, REUSE_JACOBIAN_BELOW, StepFn, begin_step};

/// sqrt(6)
const SQ6: f64 = 2.449_489_742_783_178;
/// Collocation nodes.
pub(super) const C: [f64; 3] = [(4.0 - SQ6) / 10.0, (4.0 + SQ6) / 10.0, 1.0];
/// The Butcher matrix of Radau IIA, order 5 (the Newton iteration uses
/// its inverse's eigendecomposition, [`T`]).
#[cfg_attr(not(test), allow(dead_code))]
const A: [[f64; 3]; 3] = [
    [
        (88.0 - 7.0 * SQ6) / 360.0,
        (296.0 - 169.0 * SQ6) / 1800.0,
        (-2.0 + 3.0 * SQ6) / 225.0,
    ],
    [
        (296.0 + 169.0 * SQ6) / 1800.0,
        (88.0 + 7.0 * SQ6) / 360.0,
        (-2.0 - 3.0 * SQ6) / 225.0,
    ],
    [(16.0 - SQ6) / 36.0, (16.0 + SQ6) / 36.0, 1.0 / 9.0],
];
/// The real eigenvalue of A^-1 and the error estimate's weights.
const GAMMA: f64 = 3.637_834_252_744_496;
/// The complex pair alpha +- i beta of A^-1's eigenvalues (Hairer's
/// ALPH, BETA after division by ALPH^2 + BETA^2).
const ALPHA: f64 = 2.681_082_873_627_752;
const BETA: f64 = 3.050_430_199_247_411;
/// T and T^-1 (Hairer's RADAU5): T^-1 A^-1 T = [[gamma, 0, 0], [0, alpha,
/// -beta], [0, beta, alpha]].
const T: [[f64; 3]; 3] = [
    [
        9.123_239_487_089_294e-2,
        -0.141_255_295_020_954_2,
        -3.002_919_410_514_742e-2,
    ],
    [
        0.241_717_932_707_107,
        0.204_129_352_293_8,
        0.382_942_112_757_261_9,
    ],
    [0.966_048_182_615_093, 1.0, 0.0],
];
const TI: [[f64; 3]; 3] = [
    [
        4.325_579_890_063_155,
        0.339_199_251_815_809_9,
        0.541_770_539_935_874_9,
    ],
    [
        -4.178_718_591_551_905,
        -0.327_682_820_761_062_4,
        0.476_623_554_500_550_5,
    ],
    [
        -0.502_872_634_945_786_9,
        2.571_926_949_855_605,
        -0.596_039_204_828_225,
    ],
];
const DD: [f64; 3] = [
    -(13.0 + 7.0 * SQ6) / 3.0,
    (-13.0 + 7.0 * SQ6) / 3.0,
    -1.0 / 3.0,
];
const MAX_NEWTON: usize = 7;

/// The dense output of the last accepted step.
pub struct Dense {
    pub(super) t_prev: f64,
    pub(super) t_curr: f64,
    pub(super) h: f64,
    pub(super) y_curr: Vec<f64>,
    /// Newton divided differences of the collocation polynomial.
    pub(super) cont: [Vec<f64>; 3],
}

impl Interpolation<f64, Vec<f64>> for Dense {
    fn interpolate(&mut self, t: f64) -> Result<Vec<f64>, Error<f64, Vec<f64>>> {
        if t < self.t_prev - 1e-12 * self.h.abs() || t > self.t_curr + 1e-12 * self.h.abs() {
            return Err(Error::OutOfBounds {
                t_interp: t,
                t_prev: self.t_prev,
                t_curr: self.t_curr,
            });
        }
        let s = (t - self.t_curr) / self.h;
        let (c1m1, c2m1) = (C[0] - 1.0, C[1] - 1.0);
        Ok((0..self.y_curr.len())
            .map(|i| {
                let c = &self.cont;
                self.y_curr[i] + s * (c[0][i] + (s - c2m1) * (c[1][i] + (s - c1m1) * c[2][i]))
            })
            .collect())
    }
}

/// The scaled tolerances (rtol, atol) and the Newton tolerance in their
/// units. Hairer's transformation: the estimate is of order 3, so rtol' =
/// 0.1 rtol^(2/3) makes the global error track rtol.
pub(super) fn tolerances(rtol: f64, atol: f64) -> (f64, f64, f64) {
    let (rtol, atol) = (
        0.1 * rtol.powf(2.0 / 3.0),
        0.1 * rtol.powf(2.0 / 3.0) * (atol / rtol),
    );
    let newton_tol = (10.0 * f64::EPSILON / rtol).max(0.03f64.min(rtol.sqrt()));
    (rtol, atol, newton_tol)
}

/// Integrate from (t0, y0) to `opts.t_end`. Errors carry the time and
/// state reached.
pub fn integrate(
    sys: &mut dyn OdeSystem,
    t0: f64,
    y0: Vec<f64>,
    opts: &Options,
    step: &mut StepFn<'_>,
    counts: &mut Counts,
) -> Result<(), Error<f64, Vec<f64>>> {
    let t_end = opts.t_end;
    let m = y0.len();
    let (rtol, atol, newton_tol) = tolerances(opts.rtol, opts.atol);
    let (mut t, mut y) = (t0, y0);
    let mut f0 = vec![0.0; m];
    sys.rhs(t, &y, &mut f0);
    let mut j = DMatrix::zeros(m, m);
    let span = t_end - t0;
    let mut h = (1e-6 * span).max(1e-12).min(span);
    let mut first = true;
    let mut last_rejected = false;
    let mut z = vec![vec![0.0; m]; 3];
    let mut fz = vec![vec![0.0; m]; 3];
    let mut dense: Option<Dense> = None;
    // Whether J must be evaluated before the next attempt, and whether the J
    // in hand was evaluated at the current point.
    let (mut need_jacobian, mut fresh) = (true, false);
    // The Newton matrices, factored for the J in hand at step size `.0`:
    // reused while neither changes (Hairer's RADAU5 keeps h when the new
    // one is within 1 to 1.2 times it, for this).
    let mut factored: Option<(f64, Lu, ComplexLu)> = None;
    while t < t_end {
        let last = begin_step(counts, opts, t, &mut h, &y)?;
        if need_jacobian {
            sys.jacobian(t, &y, &mut j);
            (need_jacobian, fresh) = (false, true);
            factored = None;
        }
        let scale: Vec<f64> = y.iter().map(|v| atol + rtol * v.abs()).collect();
        if factored.as_ref().is_none_or(|f| f.0 != h) {
            let (real, complex) = newton_matrices(&j, h, m);
            factored = Some((h, real, complex));
        }
        let (_, real, complex) = factored.as_ref().expect("factored above");
        // Start from the last step's collocation polynomial, extrapolated.
        match &mut dense {
            Some(d) if !first => {
                for (k, zk) in z.iter_mut().enumerate() {
                    let tk = t + C[k] * h;
                    let yk = d.extrapolate(tk);
                    for i in 0..m {
                        zk[i] = yk[i] - y[i];
                    }
                }
            }
            _ => z.iter_mut().for_each(|zk| zk.fill(0.0)),
        }
        let stage = StagePoint { t, y: &y, h };
        let (converged, iterations, theta) = simplified_newton(
            sys,
            (real, complex),
            &stage,
            &mut z,
            &mut fz,
            &scale,
            newton_tol,
        )?;
        if !converged {
            // A stale Jacobian may be why: take a new one as well.
            counts.rejected += 1;
            last_rejected = true;
            need_jacobian = !fresh;
            h *= 0.5;
            continue;
        }
        // Error estimate: (gamma/h - J)^-1 (f(t, y) + sum dd_k Z_k / h).
        let mut err = estimate(real, h, &f0, &z, &scale, m);
        if err.1 >= 1.0 && (first || last_rejected) {
            // Hairer's second estimate, better near stiff transients.
            let perturbed: Vec<f64> = (0..m).map(|i| y[i] + err.0[i]).collect();
            let mut fp = vec![0.0; m];
            sys.rhs(t, &perturbed, &mut fp);
            err = estimate(real, h, &fp, &z, &scale, m);
        }
        if !err.1.is_finite() {
            // A failed right-hand side or a singular matrix: retry smaller.
            counts.rejected += 1;
            last_rejected = true;
            need_jacobian = !fresh;
            h *= 0.25;
            continue;
        }
        let err = err.1.max(1e-10);
        let safety = 0.9 * (2 * MAX_NEWTON + 1) as f64 / (2 * MAX_NEWTON + iterations) as f64;
        let quot = (err.powf(0.25) / safety).clamp(1.0 / 8.0, 5.0);
        let mut h_new = h / quot;
        if err < 1.0 {
            let y_new: Vec<f64> = (0..m).map(|i| y[i] + z[2][i]).collect();
            let t_new = if last { t_end } else { t + h };
            let cont = divided_differences(&z);
            let d = dense.insert(Dense {
                t_prev: t,
                t_curr: t_new,
                h,
                y_curr: y_new.clone(),
                cont,
            });
            counts.accepted += 1;
            if y_new.iter().any(|v| !v.is_finite()) {
                return Err(Error::StepSize { t, y });
            }
            let keep_going = step(t, t_new, &y, &y_new, d);
            t = t_new;
            y = y_new;
            sys.rhs(t, &y, &mut f0);
            // One Newton iteration measures no contraction: J was good.
            let contraction = if iterations > 1 { theta } else { 0.0 };
            need_jacobian = contraction > REUSE_JACOBIAN_BELOW;
            fresh = false;
            first = false;
            if !need_jacobian && (1.0..=1.2).contains(&(h_new / h)) {
                // Keep h, and with it the factorisations.
                h_new = h;
            }
            h = if last_rejected { h_new.min(h) } else { h_new };
            last_rejected = false;
            if !keep_going {
                return Ok(());
            }
        } else {
            counts.rejected += 1;
            last_rejected = true;
            h = if first { 0.1 * h } else { h_new };
        }
    }
    Ok(())
}

impl Dense {
    /// The collocation polynomial past its step (the next step's Newton guess).
    pub(super) fn extrapolate(&self, t: f64) -> Vec<f64> {
        let s = (t - self.t_curr) / self.h;
        let (c1m1, c2m1) = (C[0] - 1.0, C[1] - 1.0);
        let c = &self.cont;
        (0..self.y_curr.len())
            .map(|i| self.y_curr[i] + s * (c[0][i] + (s - c2m1) * (c[1][i] + (s - c1m1) * c[2][i])))
            .collect()
    }
}

/// Divided differences of the collocation polynomial through y (s = -1)
/// and y + Z_k (s = c_k - 1), in the variable s = (t - t_new) / h.
pub(super) fn divided_differences(z: &[Vec<f64>]) -> [Vec<f64>; 3] {
    let m = z[0].len();
    let (c1, c2) = (C[0], C[1]);
    let (c1m1, c2m1) = (c1 - 1.0, c2 - 1.0);
    let mut d = [vec![0.0; m], vec![0.0; m], vec![0.0; m]];
    for i in 0..m {
        let first = (z[1][i] - z[2][i]) / c2m1;
        let ak = (z[0][i] - z[1][i]) / (c1 - c2);
        let acont3 = (ak - z[0][i] / c1) / c2;
        let second = (ak - first) / c1m1;
        d[0][i] = first;
        d[1][i] = second;
        d[2][i] = second - acont3;
    }
    d
}

pub(super) type Lu = nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn>;

/// The filtered error vector and its scaled RMS norm, `filter` the real
/// Newton matrix gamma/h - J at `h` ([`newton_matrices`]).
fn estimate(
    filter: &Lu,
    h: f64,
    f0: &[f64],
    z: &[Vec<f64>],
    scale: &[f64],
    m: usize,
) -> (Vec<f64>, f64) {
    let rhs = DVector::from_iterator(
        m,
        (0..m).map(|i| f0[i] + (DD[0] * z[0][i] + DD[1] * z[1][i] + DD[2] * z[2][i]) / h),
    );
    let e: Vec<f64> = filter
        .solve(&rhs)
        .map(|e| e.iter().copied().collect())
        .unwrap_or_else(|| vec![f64::INFINITY; m]);
    let norm = (e
        .iter()
        .zip(scale)
        .map(|(v, s)| (v / s).powi(2))
        .sum::<f64>()
        / m as f64)
        .sqrt();
    (e, norm)
}

pub(super) type ComplexLu = nalgebra::LU<Complex<f64>, nalgebra::Dyn, nalgebra::Dyn>;

/// The transformed Newton matrices gamma/h - J and (alpha + i beta)/h - J,
/// factored.
pub(super) fn newton_matrices(j: &DMatrix<f64>, h: f64, m: usize) -> (Lu, ComplexLu) {
    let mut real = -j.clone();
    let mut complex = j.map(|v| Complex::new(-v, 0.0));
    for i in 0..m {
        real[(i, i)] += GAMMA / h;
        complex[(i, i)] += Complex::new(ALPHA / h, BETA / h);
    }
    (real.lu(), complex.lu())
}

/// Where a step starts: time, state and step size.
pub(super) struct StagePoint<'a> {
    pub(super) t: f64,
    pub(super) y: &'a [f64],
    pub(super) h: f64,
}

/// Simplified Newton on G(Z) = Z - h (A (x) I) F(Z) from the given Z, in
/// the transformed variables W = T^-1 Z, with the matrices of
/// [`newton_matrices`]: whether it converged, the iterations taken and
/// the last contraction rate theta.
pub(super) fn simplified_newton(
    sys: &mut dyn OdeSystem,
    (real, complex): (&Lu, &ComplexLu),
    at: &StagePoint,
    z: &mut [Vec<f64>],
    fz: &mut [Vec<f64>],
    scale: &[f64],
    newton_tol: f64,
) -> Result<(bool, usize, f64), Error<f64, Vec<f64>>> {
    let StagePoint { t, y, h } = *at;
    let m = y.len();
    let mut yi = vec![0.0; m];
    let mut converged = false;
    let mut previous_norm = f64::INFINITY;
    let mut theta = 0.5;
    let mut iterations = 0;
    let transform = |mat: &[[f64; 3]; 3], v: &[Vec<f64>], k: usize, i: usize| {
        mat[k][0] * v[0][i] + mat[k][1] * v[1][i] + mat[k][2] * v[2][i]
    };
    let mut w: Vec<Vec<f64>> = (0..3)
        .map(|k| (0..m).map(|i| transform(&TI, z, k, i)).collect())
        .collect();
    let (gamma, alpha, beta) = (GAMMA / h, ALPHA / h, BETA / h);
    let singular = || Error::LinearAlgebra {
        t,
        y: y.to_vec(),
        msg: "the Newton matrix I - h (A x J) is singular".into(),
    };
    for it in 0..MAX_NEWTON {
        iterations = it + 1;
        for k in 0..3 {
            for i in 0..m {
                yi[i] = y[i] + z[k][i];
            }
            sys.rhs(t + C[k] * h, &yi, &mut fz[k]);
        }
        // T^-1 F - (Lambda / h) W, then the increments of W.
        let mut r1 = DVector::<f64>::zeros(m);
        let mut r23 = DVector::<Complex<f64>>::zeros(m);
        for i in 0..m {
            let tf = [0, 1, 2].map(|k| transform(&TI, fz, k, i));
            r1[i] = tf[0] - gamma * w[0][i];
            r23[i] = Complex::new(
                tf[1] - alpha * w[1][i] + beta * w[2][i],
                tf[2] - alpha * w[2][i] - beta * w[1][i],
            );
        }
        let dw1 = real.solve(&r1).ok_or_else(singular)?;
        let dw23 = complex.solve(&r23).ok_or_else(singular)?;
        let mut sum = 0.0;
        for i in 0..m {
            let d = [dw1[i], dw23[i].re, dw23[i].im];
            for k in 0..3 {
                w[k][i] += d[k];
                sum += (d[k] / scale[i]).powi(2);
            }
        }
        let norm = (sum / (3 * m) as f64).sqrt();
        if !norm.is_finite() {
            break;
        }
        for (k, zk) in z.iter_mut().enumerate() {
            for (i, v) in zk.iter_mut().enumerate() {
                *v = transform(&T, &w, k, i);
            }
        }
        if it > 0 {
            theta = norm / previous_norm;
            if theta >= 0.99 {
                break;
            }
        }
        previous_norm = norm;
        if theta / (1.0 - theta) * norm <= newton_tol || norm <= 1e-3 * newton_tol {
            converged = true;
            break;
        }
    }
    Ok((converged, iterations, theta))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn product(a: &[[f64; 3]; 3], b: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
        std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
    }

    /// T^-1 A^-1 T = [[gamma, 0, 0], [0, alpha, -beta], [0, beta, alpha]],
    /// checked as A T Lambda = T (no inverse of A needed).
    #[test]
    fn transformation_diagonalises_the_inverse_butcher_matrix() {
        let id = product(&T, &TI);
        for (i, row) in id.iter().enumerate() {
            for (j, v) in row.iter().enumerate() {
                let want = if i == j { 1.0 } else { 0.0 };
                assert!((v - want).abs() < 1e-14, "T T^-1 [{i}][{j}] = {v}");
            }
        }
        let lambda = [[GAMMA, 0.0, 0.0], [0.0, ALPHA, -BETA], [0.0, BETA, ALPHA]];
        let lhs = product(&product(&A, &T), &lambda);
        for i in 0..3 {
            for j in 0..3 {
                assert!(
                    (lhs[i][j] - T[i][j]).abs() < 1e-14,
                    "A T Lambda [{i}][{j}] = {} vs T {}",
                    lhs[i][j],
                    T[i][j]
                );
            }
        }
    }
}

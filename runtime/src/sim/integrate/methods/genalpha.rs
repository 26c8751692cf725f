//! The generalized-alpha method for structural dynamics (Chung and Hulbert
//! 1993), in the form Arnold and Bruls (2007) give for nonlinear
//! second-order systems: the equations of motion hold at every step's
//! end, qdd_{n+1} = f(q_{n+1}, v_{n+1}), and a pseudo-acceleration a
//! carries the method's memory,
//!
//!   q_{n+1} = q_n + h v_n + h^2 ((1/2 - beta) a_n + beta a_{n+1})
//!   v_{n+1} = v_n + h ((1 - gamma) a_n + gamma a_{n+1})
//!   (1 - alpha_m) a_{n+1} + alpha_m a_n = (1 - alpha_f) qdd_{n+1} + alpha_f qdd_n
//!
//! with alpha_m = (2 rho - 1) / (rho + 1), alpha_f = rho / (rho + 1),
//! gamma = 1/2 + alpha_f - alpha_m, beta = (gamma + 1/2)^2 / 4: second
//! order, unconditionally stable, and damping modes far above the step's
//! resolution to the spectral radius rho = `rho_inf` (1: none, the
//! trapezoidal rule; 0: annihilated in one step) while those it resolves
//! keep their energy to second order. Newton on a_{n+1} uses the arm's
//! exact Jacobian blocks d qdd / dq, d qdd / dv (n x n, where the
//! first-order solvers factor 2n x 2n).
//!
//! The step follows the positions' local error, h^2 (beta - 1/6)
//! (a_{n+1} - a_n), filtered through the Newton matrix as ode23tb filters
//! its estimate: a mode the step does not resolve is damped by the method,
//! not counted as error, so the step is set by the motion, not by stiff
//! modes it does not excite.

use differential_equations::error::Error;
use nalgebra::{DMatrix, DVector};

use super::super::stepper::{
    Contraction, Converging, Counts, Hermite, OdeSystem, Options, REUSE_JACOBIAN_BELOW, StepFn,
    begin_step, error_norm, initial_step, next_step,
};

const MAX_NEWTON: usize = 8;

/// The method's parameters for a spectral radius at infinity `rho`.
#[derive(Clone, Copy, Debug)]
pub struct Alpha {
    pub alpha_m: f64,
    pub alpha_f: f64,
    pub gamma: f64,
    pub beta: f64,
}

impl Alpha {
    pub fn of(rho: f64) -> Self {
        let rho = rho.clamp(0.0, 1.0);
        let alpha_m = (2.0 * rho - 1.0) / (rho + 1.0);
        let alpha_f = rho / (rho + 1.0);
        let gamma = 0.5 + alpha_f - alpha_m;
        Self {
            alpha_m,
            alpha_f,
            gamma,
            beta: 0.25 * (gamma + 0.5).powi(2),
        }
    }
}

/// One step's state: positions and velocities (the ODE's state), the
/// true acceleration there and the pseudo-acceleration, with the step
/// that made it.
struct Point {
    y: Vec<f64>,
    f: Vec<f64>,
    a: Vec<f64>,
    h: Option<f64>,
}

/// The pseudo-acceleration a step of size h starts from. a_n tracks
/// qdd(t_n + (alpha_m - alpha_f) h): second order in q and v only if it
/// starts so, qdd_0 + (alpha_m - alpha_f) h qddd_0 (qddd from the
/// Jacobian: J_q v + J_v qdd), and when the step changes its lead over
/// qdd scales with it.
fn started(al: &Alpha, p: &Point, h: f64, j: &DMatrix<f64>) -> Vec<f64> {
    let n = p.a.len();
    let acc = &p.f[n..];
    match p.h {
        Some(h0) => (0..n)
            .map(|i| acc[i] + (p.a[i] - acc[i]) * h / h0)
            .collect(),
        None => (0..n)
            .map(|i| {
                let jerk: f64 = (0..n)
                    .map(|k| j[(n + i, k)] * p.y[n + k] + j[(n + i, n + k)] * acc[k])
                    .sum();
                acc[i] + (al.alpha_m - al.alpha_f) * h * jerk
            })
            .collect(),
    }
}

/// The step's end for the pseudo-acceleration `a1`, from `p`.
fn advance(al: &Alpha, p: &Point, h: f64, a1: &[f64], y1: &mut [f64]) {
    let n = a1.len();
    for i in 0..n {
        let (q, v, a) = (p.y[i], p.y[n + i], p.a[i]);
        y1[i] = q + h * v + h * h * ((0.5 - al.beta) * a + al.beta * a1[i]);
        y1[n + i] = v + h * ((1.0 - al.gamma) * a + al.gamma * a1[i]);
    }
}

/// Newton on a_{n+1} (in `a1`, from its guess) with the factored matrix
/// `lu`; `y1` and `f1` receive the step's end and the rate there. Returns
/// the slowest contraction seen, or None if it does not converge.
#[allow(clippy::too_many_arguments)]
fn newton(
    sys: &mut dyn OdeSystem,
    al: &Alpha,
    lu: &nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn>,
    (p, t1, h): (&Point, f64, f64),
    a1: &mut [f64],
    y1: &mut [f64],
    f1: &mut [f64],
    scale: &[f64],
    tol: f64,
) -> Option<f64> {
    let n = a1.len();
    let mut contraction = Contraction::default();
    for _ in 0..MAX_NEWTON {
        advance(al, p, h, a1, y1);
        sys.rhs(t1, y1, f1);
        let r = DVector::from_iterator(
            n,
            (0..n).map(|i| {
                -((1.0 - al.alpha_m) * a1[i] + al.alpha_m * p.a[i]
                    - (1.0 - al.alpha_f) * f1[n + i]
                    - al.alpha_f * p.f[n + i])
            }),
        );
        let da = lu.solve(&r)?;
        // The change it makes to the positions, scaled.
        let norm = ((0..n)
            .map(|i| (h * h * al.beta * da[i] / scale[i]).powi(2))
            .sum::<f64>()
            / n as f64)
            .sqrt();
        for i in 0..n {
            a1[i] += da[i];
        }
        match contraction.after(norm, tol) {
            Converging::Continue => {}
            Converging::Failed => return None,
            Converging::Done(slowest) => {
                advance(al, p, h, a1, y1);
                sys.rhs(t1, y1, f1);
                return Some(slowest);
            }
        }
    }
    None
}

/// Integrate from (t0, y0) to `opts.t_end`; y = (q, v).
pub fn integrate(
    sys: &mut dyn OdeSystem,
    t0: f64,
    y0: Vec<f64>,
    opts: &Options,
    step: &mut StepFn<'_>,
    counts: &mut Counts,
) -> Result<(), Error<f64, Vec<f64>>> {
    let (m, al) = (y0.len(), Alpha::of(opts.rho_inf));
    let n = m / 2;
    let (t_end, rtol, atol) = (opts.t_end, opts.rtol, opts.atol);
    let newton_tol = 0.03f64.min(rtol.sqrt()).max(10.0 * f64::EPSILON / rtol);
    let mut f = vec![0.0; m];
    sys.rhs(t0, &y0, &mut f);
    let a = f[n..].to_vec();
    let mut p = Point {
        y: y0,
        f,
        a,
        h: None,
    };
    let mut t = t0;
    let (mut y1, mut f1, mut a1) = (vec![0.0; m], vec![0.0; m], vec![0.0; n]);
    let mut j = DMatrix::zeros(m, m);
    let (mut need_jacobian, mut fresh) = (true, false);
    let mut h = initial_step(sys, (t0, &p.y, &p.f), 2, opts);
    let mut rejected_last = false;
    while t < t_end {
        let last = begin_step(counts, opts, t, &mut h, &p.y)?;
        if need_jacobian {
            sys.jacobian(t, &p.y, &mut j);
            (need_jacobian, fresh) = (false, true);
        }
        // S = (1 - alpha_m) I - (1 - alpha_f) (h^2 beta dqdd/dq + h gamma dqdd/dv).
        let (kq, kv) = (
            (1.0 - al.alpha_f) * h * h * al.beta,
            (1.0 - al.alpha_f) * h * al.gamma,
        );
        let s = DMatrix::from_fn(n, n, |r, c| {
            let diag = if r == c { 1.0 - al.alpha_m } else { 0.0 };
            diag - kq * j[(n + r, c)] - kv * j[(n + r, n + c)]
        });
        let lu = s.lu();
        let scale: Vec<f64> = p.y[..n].iter().map(|v| atol + rtol * v.abs()).collect();
        let t1 = if last { t_end } else { t + h };
        p.a = started(&al, &p, t1 - t, &j);
        p.h = Some(t1 - t);
        a1.copy_from_slice(&p.a);
        let converged = newton(
            sys,
            &al,
            &lu,
            (&p, t1, t1 - t),
            &mut a1,
            &mut y1,
            &mut f1,
            &scale,
            newton_tol,
        );
        let Some(contraction) = converged else {
            counts.rejected += 1;
            rejected_last = true;
            need_jacobian = !fresh;
            h *= 0.25;
            continue;
        };
        // The positions' local error, filtered by (1 - alpha_m) S^-1.
        let hs = t1 - t;
        let raw = DVector::from_iterator(
            n,
            (0..n).map(|i| (1.0 - al.alpha_m) * hs * hs * (al.beta - 1.0 / 6.0) * (a1[i] - p.a[i])),
        );
        let filtered: Vec<f64> = lu
            .solve(&raw)
            .map(|v| v.iter().copied().collect())
            .unwrap_or_else(|| vec![f64::INFINITY; n]);
        let err = error_norm(&filtered, &p.y[..n], &y1[..n], rtol, atol);
        if err <= 1.0 {
            counts.accepted += 1;
            let mut dense = Hermite {
                t0: t,
                h: hs,
                y0: &p.y,
                y1: &y1,
                f0: &p.f,
                f1: &f1,
            };
            let keep_going = step(t, t1, &p.y, &y1, &mut dense);
            t = t1;
            std::mem::swap(&mut p.y, &mut y1);
            std::mem::swap(&mut p.f, &mut f1);
            std::mem::swap(&mut p.a, &mut a1);
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

#[cfg(test)]
mod tests {
    use super::*;

    /// x'' = -w^2 x - 2 zeta w x', as a first-order system (x, v).
    struct Oscillator {
        w: f64,
        zeta: f64,
    }

    impl OdeSystem for Oscillator {
        fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) {
            dy[0] = y[1];
            dy[1] = -self.w * self.w * y[0] - 2.0 * self.zeta * self.w * y[1];
        }

        fn jacobian(&mut self, _t: f64, _y: &[f64], j: &mut DMatrix<f64>) {
            *j = DMatrix::from_row_slice(
                2,
                2,
                &[0.0, 1.0, -self.w * self.w, -2.0 * self.zeta * self.w],
            );
        }
    }

    /// `steps` fixed steps of size h from x = 1, v = 0.
    fn run(sys: &mut Oscillator, rho: f64, h: f64, steps: usize) -> Vec<f64> {
        let al = Alpha::of(rho);
        let mut f = vec![0.0; 2];
        sys.rhs(0.0, &[1.0, 0.0], &mut f);
        let mut p = Point {
            y: vec![1.0, 0.0],
            a: vec![f[1]],
            f,
            h: None,
        };
        let mut j = DMatrix::zeros(2, 2);
        sys.jacobian(0.0, &p.y, &mut j);
        p.a = started(&al, &p, h, &j);
        p.h = Some(h);
        let kq = (1.0 - al.alpha_f) * h * h * al.beta;
        let kv = (1.0 - al.alpha_f) * h * al.gamma;
        let s = DMatrix::from_element(1, 1, 1.0 - al.alpha_m - kq * j[(1, 0)] - kv * j[(1, 1)]);
        let lu = s.lu();
        let (mut y1, mut f1, mut a1) = (vec![0.0; 2], vec![0.0; 2], vec![0.0; 1]);
        for k in 0..steps {
            a1.copy_from_slice(&p.a);
            let t1 = (k + 1) as f64 * h;
            newton(
                sys,
                &al,
                &lu,
                (&p, t1, h),
                &mut a1,
                &mut y1,
                &mut f1,
                &[1.0],
                1e-14,
            )
            .expect("a linear system converges");
            std::mem::swap(&mut p.y, &mut y1);
            std::mem::swap(&mut p.f, &mut f1);
            std::mem::swap(&mut p.a, &mut a1);
        }
        p.y
    }

    #[test]
    fn second_order_on_a_damped_oscillator() {
        let (w, zeta, t): (f64, f64, f64) = (2.0 * std::f64::consts::PI, 0.05, 1.0);
        let wd = w * (1.0 - zeta * zeta).sqrt();
        let exact = (-zeta * w * t).exp() * ((wd * t).cos() + zeta * w / wd * (wd * t).sin());
        for rho in [1.0, 0.8, 0.0] {
            let err = |steps: usize| {
                let h = t / steps as f64;
                (run(&mut Oscillator { w, zeta }, rho, h, steps)[0] - exact).abs()
            };
            let (coarse, fine) = (err(800), err(1600));
            let ratio = coarse / fine;
            assert!(
                (3.6..4.4).contains(&ratio),
                "rho_inf {rho}: halving h divides the error by {ratio}, not 4 ({coarse:e}, {fine:e})"
            );
        }
    }

    #[test]
    fn a_mode_far_above_the_step_loses_amplitude_by_rho_inf_a_step() {
        // w h = 1e5: the step does not resolve the mode at all. Its
        // position falls by the spectral radius a step (a double
        // eigenvalue -rho_inf: about k rho^k, so measured between steps
        // 100 and 200, where the factor 2 is a 100th root).
        let (w, h) = (1e5, 1.0);
        for rho in [0.5f64, 0.8] {
            let q = |steps| run(&mut Oscillator { w, zeta: 0.0 }, rho, h, steps)[0].abs();
            let measured = (q(200) / q(100) / 2.0).powf(1.0 / 100.0);
            assert!(
                (measured - rho).abs() < 1e-2,
                "rho_inf {rho}: the mode falls by {measured} a step"
            );
        }
        let gone = run(&mut Oscillator { w, zeta: 0.0 }, 0.0, h, 3)[0];
        assert!(gone.abs() < 1e-9, "rho_inf 0 leaves {gone:e}");
    }

    #[test]
    fn without_numerical_damping_an_oscillator_keeps_its_energy() {
        // rho_inf = 1: the average-acceleration rule, which conserves a
        // linear oscillator's energy exactly, at any step.
        let w = 3.0;
        for h in [1e-3, 0.1, 10.0] {
            let y = run(&mut Oscillator { w, zeta: 0.0 }, 1.0, h, 1000);
            let energy = y[0] * y[0] + (y[1] / w).powi(2);
            assert!((energy - 1.0).abs() < 1e-10, "h {h}: energy {energy}");
        }
    }
}

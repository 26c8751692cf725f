//! Radau IIA of order 5 at a fixed step (`dt`): radau5's stages, Newton
//! and collocation polynomial (`radau5.rs`) without its error control.
//! L-stable, where gauss is not: a mode far above the step is gone in one
//! step (R(infinity) = 0), while those the step resolves keep their
//! amplitude and period to O((w h)^5). It is for stiff, lightly damped
//! structures whose stiffest modes the motion excites but nothing reads
//! (the stretch and shear of a steel rod, 10^5 rad/s): gauss keeps them
//! ringing undamped, and as the motion feeds them its Newton iteration
//! slows; adaptive radau5's estimate counts them and takes 40 us steps.
//!
//! Newton measures its updates on the positions alone (as gauss does): a
//! position's stage rows are linear in the rates, so the rates' updates
//! show through them, while the rates of modes far above the step swing by
//! their size each step and held the iteration to updates that moved no
//! position.
//!
//! Steps land on the grid t0 + k dt. Where Newton fails on a fresh
//! Jacobian (a contact that begins inside the step: the Jacobian of the
//! step's start has no contact stiffness, its stages do), the step is taken
//! in halves, down to dt / 1024, and the steps double back to the grid.

use differential_equations::error::Error;
use nalgebra::DMatrix;

use super::super::stepper::{Counts, OdeSystem, Options, STAGE_TOL, StepFn, begin_step};
use super::radau5::{
    C, ComplexLu, Dense, Lu, StagePoint, divided_differences, newton_matrices, simplified_newton,
    tolerances,
};

/// Keep the Jacobian while Newton contracts faster than this. At a fixed
/// step a Jacobian kept costs only iterations, never a refactorisation for
/// a new step nor a rejected one, and an arm's Jacobian costs 2n
/// directional derivatives: on examples/steel_rod_shear.toml (30
/// coordinates, 3 ms, 25 s) 0.3 takes 23 Jacobians where radau5's 0.1
/// took 220 (2.08 against 2.45 s), with 1 % fewer right-hand sides and
/// the tip 0.65 against 0.57 mm from the converged rod.
const REUSE_JACOBIAN_BELOW: f64 = 0.3;

/// The smallest part of dt a step is halved to where Newton fails.
const MAX_HALVING: f64 = 1024.0;

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
    // radau5's scaled tolerances, rtol no tighter than round-off allows.
    let tol = tolerances(opts.rtol.max(STAGE_TOL.0), opts.atol);
    let (mut t, mut y) = (t0, y0);
    let mut j = DMatrix::zeros(m, m);
    let (mut z, mut fz) = (vec![vec![0.0; m]; 3], vec![vec![0.0; m]; 3]);
    let mut dense: Option<Dense> = None;
    // The Newton matrices of the Jacobian in hand at step `.0`.
    let mut factored: Option<(f64, Lu, ComplexLu)> = None;
    let (mut need_jacobian, mut fresh) = (true, false);
    let n = opts.positions.min(m / 2);
    // Steps land on the grid t0 + k dt; where Newton fails even on a
    // fresh Jacobian (a contact beginning inside the step), the step is
    // taken in halves, then doubles back up to dt.
    let (mut grid, mut h_sub) = (1u64, opts.dt);
    loop {
        let t_grid = t0 + grid as f64 * opts.dt;
        // A step to the grid point ends on it exactly, whatever the sum's
        // rounding.
        let mut to_grid = h_sub >= (t_grid - t) * (1.0 - 1e-9);
        let mut h = if to_grid { t_grid - t } else { h_sub };
        let mut last = begin_step(counts, opts, t, &mut h, &y)?;
        let mut retried = false;
        let (iterations, theta) = loop {
            if std::mem::take(&mut need_jacobian) {
                sys.jacobian(t, &y, &mut j);
                (fresh, factored) = (true, None);
            }
            if factored.as_ref().is_none_or(|f| f.0 != h) {
                let (real, complex) = newton_matrices(&j, h, m);
                factored = Some((h, real, complex));
            }
            predict(dense.as_ref(), (t, h), &y, &mut z);
            let scale = scale(&y, &z, n, tol);
            let (_, real, complex) = factored.as_ref().expect("factored above");
            let stage = StagePoint { t, y: &y, h };
            let (converged, iterations, theta) =
                simplified_newton(sys, (real, complex), &stage, &mut z, &mut fz, &scale, tol.2)?;
            if converged {
                break (iterations, theta);
            }
            counts.rejected += 1;
            match fresh {
                // A Jacobian from an earlier state: a new one, once.
                false if !retried => (need_jacobian, retried) = (true, true),
                _ if h > opts.dt / MAX_HALVING => {
                    (h, h_sub, last, to_grid) = (0.5 * h, 0.5 * h, false, false)
                }
                _ => return Err(Error::StepSize { t, y }),
            }
        };
        let y_new: Vec<f64> = (0..m).map(|i| y[i] + z[2][i]).collect();
        if y_new.iter().any(|v| !v.is_finite()) {
            return Err(Error::StepSize { t, y });
        }
        let t_new = match last {
            true => opts.t_end,
            false if to_grid => {
                grid += 1;
                t_grid
            }
            false => t + h,
        };
        let d = dense.insert(Dense {
            t_prev: t,
            t_curr: t_new,
            h,
            y_curr: y_new.clone(),
            cont: divided_differences(&z),
        });
        counts.accepted += 1;
        if !step(t, t_new, &y, &y_new, d) || last {
            return Ok(());
        }
        (t, y) = (t_new, y_new);
        h_sub = (2.0 * h_sub).min(opts.dt);
        // One Newton iteration measures no contraction: J was good.
        need_jacobian = iterations > 1 && theta > REUSE_JACOBIAN_BELOW;
        fresh = false;
    }
}

/// Newton's scale of each state component, radau5's atol + rtol |y_i|
/// (`tol`: the scaled rtol, atol), the rates' infinite (read through the
/// positions, above). Each is at least 1e-3 rtol of the largest of its
/// part of the state (the positions, the further states such as relaxing
/// forces, or without positions the whole state) or of the step's
/// predicted change: a start at rest in the rest shape with no atol has a
/// scale.
fn scale(y: &[f64], z: &[Vec<f64>], n: usize, (rtol, atol, _): (f64, f64, f64)) -> Vec<f64> {
    let m = y.len();
    let floor = |range: std::ops::Range<usize>| {
        let of = |v: &[f64]| v[range.clone()].iter().fold(0.0f64, |s, x| s.max(x.abs()));
        let change = z.iter().fold(0.0f64, |s, zk| s.max(of(zk)));
        (1e-3 * rtol * of(y).max(change)).max(f64::MIN_POSITIVE)
    };
    let (positions, rest) = match n {
        0 => (floor(0..m), 0.0),
        _ => (floor(0..n), if 2 * n < m { floor(2 * n..m) } else { 0.0 }),
    };
    (0..m)
        .map(|i| {
            let own = atol + rtol * y[i].abs();
            match (n, i) {
                (0, _) => own.max(positions),
                (_, i) if i < n => own.max(positions),
                (_, i) if i < 2 * n => f64::INFINITY,
                _ => own.max(rest),
            }
        })
        .collect()
}

/// The stage increments' guess: the last step's collocation polynomial,
/// extrapolated; at the start none (as radau5: the derivative there times
/// each stage's time threw a stiff start far off).
fn predict(dense: Option<&Dense>, (t, h): (f64, f64), y: &[f64], z: &mut [Vec<f64>]) {
    for (k, zk) in z.iter_mut().enumerate() {
        match dense {
            Some(d) => {
                let yk = d.extrapolate(t + C[k] * h);
                for (i, zi) in zk.iter_mut().enumerate() {
                    *zi = yk[i] - y[i];
                }
            }
            None => zk.fill(0.0),
        }
    }
}

#[cfg(test)]
mod tests {
    use differential_equations::interpolate::Interpolation;
    use nalgebra::Complex;

    use super::super::oscillate;
    use super::*;

    /// Radau IIA's stability function (1 + 2z/5 + z^2/20) / (1 - 3z/5 +
    /// 3z^2/20 - z^3/60): from x = 1, v = 0, k steps give x = Re R(i w h)^k
    /// and v = Re(i w R(i w h)^k). A mode the step resolves (w h = 0.5)
    /// keeps its amplitude to 2e-6 a step; one far above it (w h = 100) is
    /// divided by about w h / 3 each step.
    #[test]
    fn each_step_multiplies_a_mode_by_the_stability_function() {
        for (w, h, steps) in [(1.0f64, 0.5, 40usize), (100.0, 1.0, 3)] {
            let (last, counts) = oscillate(integrate, (w, h, steps), 1e-12);
            assert_eq!(counts.accepted, steps);
            let z = Complex::new(0.0, w * h);
            let r =
                (1.0 + z * 0.4 + z * z / 20.0) / (1.0 - z * 0.6 + z * z * 0.15 - z * z * z / 60.0);
            let rk = r.powu(steps as u32);
            let (x, v) = (rk.re, (Complex::new(0.0, w) * rk).re);
            assert!(
                (last[0] - x).abs() < 1e-9,
                "w h {}: x {} against {x}",
                w * h,
                last[0]
            );
            assert!(
                (last[1] - v).abs() < 1e-9 * w,
                "w h {}: v {} against {v}",
                w * h,
                last[1]
            );
            match w * h {
                wh if wh < 1.0 => assert!((1.0 - r.norm()).abs() < 1e-5, "|R| {}", r.norm()),
                wh => assert!(r.norm() < 4.0 / wh, "|R| {}", r.norm()),
            }
        }
    }

    /// A ball dropped on a stiff floor: x'' = -g + k max(-x, 0). The
    /// Jacobian of a step's start above the floor has no spring, and a
    /// stage below it meets one of k = 1e6 (w h = 50 at the grid's 0.05 s):
    /// Newton cannot converge there, so the step is taken in halves; once
    /// the ball touches, the Jacobian has the spring and the grid's steps
    /// go on. The run lands on every grid point, falls as the closed form
    /// says until it touches, and is pushed back up. (The kink lies inside
    /// a step here; softarm's runs stop at a contact switch and go on in a
    /// new leg, so that within a step the forces are smooth.)
    struct Drop {
        k: f64,
    }

    const G: f64 = 9.81;

    impl OdeSystem for Drop {
        fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) {
            dy[0] = y[1];
            dy[1] = -G + self.k * (-y[0]).max(0.0);
        }
        fn jacobian(&mut self, _t: f64, y: &[f64], j: &mut DMatrix<f64>) {
            j.fill(0.0);
            j[(0, 1)] = 1.0;
            j[(1, 0)] = if y[0] < 0.0 { -self.k } else { 0.0 };
        }
    }

    #[test]
    fn a_step_newton_cannot_take_is_taken_in_halves_on_the_same_grid() {
        let (h, steps, x0) = (0.05, 20, 0.1);
        let opts = Options {
            t_end: steps as f64 * h,
            rtol: 1e-8,
            atol: 1e-12,
            max_steps: 10_000,
            rho_inf: 1.0,
            dt: h,
            positions: 1,
        };
        let mut states = vec![];
        let mut on_step =
            |_: f64, t1: f64, _: &[f64], y: &[f64], _: &mut dyn Interpolation<f64, Vec<f64>>| {
                let k = (t1 / h).round();
                if (t1 - k * h).abs() < 1e-12 {
                    states.push((k as usize, y.to_vec()));
                }
                true
            };
        let mut counts = Counts::default();
        integrate(
            &mut Drop { k: 1e6 },
            0.0,
            vec![x0, 0.0],
            &opts,
            &mut on_step,
            &mut counts,
        )
        .unwrap();
        assert!(counts.rejected > 0, "no step was halved");
        assert!(counts.accepted > steps, "{} steps", counts.accepted);
        let grid: Vec<usize> = states.iter().map(|s| s.0).collect();
        assert_eq!(grid, (1..=steps).collect::<Vec<_>>());
        // Free fall to the floor, touching at sqrt(2 x0 / g) = 0.143 s.
        for (k, y) in &states[..2] {
            let t = *k as f64 * h;
            assert!((y[0] - (x0 - 0.5 * G * t * t)).abs() < 1e-12, "{t}: {y:?}");
        }
        // Pushed back out: the floor turns it upwards.
        assert!(states.iter().any(|(_, y)| y[1] > 0.1), "{states:?}");
    }
}

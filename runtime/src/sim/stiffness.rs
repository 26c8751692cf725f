//! Stiffness analysis of the linearised first-order system at a state:
//! eigenvalues of the analytic Jacobian and the stiffness ratio: the larger
//! of Lambert's ratio of decay rates max |Re l| / min |Re l| and the
//! spread of the time scales max |l| / min |l| over the modes that move
//! (|l| above round-off), oscillating or decaying alike. An explicit
//! method's step is held by the largest |l| (on the imaginary axis as on
//! the real one) while the motion evolves over the slowest: a ratio of
//! real parts alone calls an undamped structure with modes from 1 to 1e4
//! rad/s "not stiff" though dopri5 takes thousands of steps a period.
//! Then Lambert's classification (not stiff below 20, moderately stiff up
//! to 1000, stiff above), the fastest time scale, the step an explicit
//! method can take, and a recommended solver: generalized-alpha for a
//! stiff structure whose fast modes barely decay (it damps what the step
//! does not resolve), radau5 for other stiff systems, else dopri5.

use nalgebra::DMatrix;
use serde::Serialize;

/// Radius of dopri5's stability region along the negative real axis.
pub const DOPRI5_STABILITY_RADIUS: f64 = 3.3;

/// Fast modes whose damping ratio -Re l / |l| is below this barely decay:
/// a lightly damped structure, for generalized-alpha.
pub const LIGHT_DAMPING: f64 = 0.05;

#[derive(Clone, Debug, Serialize)]
pub struct StiffnessReport {
    /// [re, im] pairs, sorted by real part (most negative first).
    pub eigenvalues: Vec<[f64; 2]>,
    pub stiffness_ratio: f64,
    pub class: &'static str,
    pub fastest_time_scale_s: f64,
    pub stable_explicit_step_s: f64,
    /// The damping ratio -Re l / |l| of the fastest mode (1 when it does
    /// not oscillate).
    pub fastest_damping_ratio: f64,
    pub recommended_solver: &'static str,
    pub reason: String,
}

/// Analyse the Jacobian `jac` of x' = f(x); None when it is not finite
/// or its eigenvalues do not converge (a state blowing up: nalgebra's
/// unbounded iteration would never return).
pub fn analyse(jac: &DMatrix<f64>) -> Option<StiffnessReport> {
    if jac.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let schur =
        nalgebra::linalg::Schur::try_new(jac.clone(), f64::EPSILON, 100 * jac.nrows().max(10))?;
    let mut eig: Vec<[f64; 2]> = schur
        .complex_eigenvalues()
        .iter()
        .map(|c| [c.re, c.im])
        .collect();
    eig.sort_by(|a, b| a[0].total_cmp(&b[0]));
    let modulus = |e: &[f64; 2]| e[0].hypot(e[1]);
    let max_mod = eig.iter().map(modulus).fold(0.0, f64::max);
    // Modes that move; moduli and decay rates at round-off level count as
    // zero (rigid modes, held coordinates, an undamped mode's real part):
    // the eigenvalues are computed to about eps |J|.
    let noise = 1e2 * f64::EPSILON * jac.norm();
    let floor = (1e-10 * max_mod).max(noise).max(f64::MIN_POSITIVE);
    let moving: Vec<&[f64; 2]> = eig.iter().filter(|e| modulus(e) > floor).collect();
    let lo = moving
        .iter()
        .map(|e| modulus(e))
        .fold(f64::INFINITY, f64::min);
    let spread = if moving.is_empty() { 1.0 } else { max_mod / lo };
    // Lambert's ratio of decay rates, which damped arms have always been
    // judged by; the spread adds what it misses, undamped fast modes.
    let decaying: Vec<f64> = eig.iter().map(|e| -e[0]).filter(|&r| r > floor).collect();
    let (slow, fast) = (decaying.iter()).fold((f64::INFINITY, 0.0f64), |(lo, hi), &r| {
        (lo.min(r), hi.max(r))
    });
    let decay = if decaying.is_empty() {
        1.0
    } else {
        fast / slow
    };
    let ratio = spread.max(decay);
    // The slowest time scale the ratio compares against.
    let lo = if decay > spread { slow } else { lo };
    let class = if ratio > 1000.0 {
        "stiff"
    } else if ratio >= 20.0 {
        "moderately stiff"
    } else {
        "not stiff"
    };
    let fastest = if max_mod > 0.0 {
        1.0 / max_mod
    } else {
        f64::INFINITY
    };
    // The fastest mode's damping ratio: the least damped among those
    // within a factor 2 of the largest |l| (a structure's top modes).
    let zeta = (moving.iter())
        .filter(|e| modulus(e) > 0.5 * max_mod)
        .map(|e| (-e[0] / modulus(e)).clamp(0.0, 1.0))
        .fold(1.0, f64::min);
    let stable = DOPRI5_STABILITY_RADIUS * fastest;
    let spread = format!(
        "stiffness ratio {ratio:.3e} (fastest mode |l| = {max_mod:.3e} 1/s, damping ratio {zeta:.2}; slowest {lo:.3e} 1/s)"
    );
    let (recommended_solver, reason) = if ratio <= 1000.0 {
        (
            "dopri5",
            format!(
                "{spread} <= 1000: an explicit method is efficient (stable steps up to {stable:.2e} s)"
            ),
        )
    } else {
        let held = format!(
            "an explicit method is held to steps of {stable:.2e} s by the fastest mode while the slowest evolves over {:.2e} s",
            1.0 / lo
        );
        match zeta < LIGHT_DAMPING {
            true => (
                "genalpha",
                format!(
                    "{spread} > 1000 with its fast modes barely damped: {held}; generalized-alpha steps with the motion and damps what the step does not resolve"
                ),
            ),
            false => ("radau5", format!("{spread} > 1000: {held}")),
        }
    };
    Some(StiffnessReport {
        eigenvalues: eig,
        stiffness_ratio: ratio,
        class,
        fastest_time_scale_s: fastest,
        stable_explicit_step_s: stable,
        fastest_damping_ratio: zeta,
        recommended_solver,
        reason,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn classifies_the_chapters_example() {
        // y1' = -1000 y1, y2' = -0.001 y2: ratio 1e6, stiff (the chapter's
        // section on stiffness).
        let j = DMatrix::from_row_slice(2, 2, &[-1000.0, 0.0, 0.0, -0.001]);
        let r = analyse(&j).unwrap();
        assert!((r.stiffness_ratio - 1e6).abs() < 1e-3);
        assert_eq!(r.class, "stiff");
        assert_eq!(r.recommended_solver, "radau5");
        assert!((r.fastest_time_scale_s - 1e-3).abs() < 1e-12);
    }

    #[test]
    fn a_lightly_damped_oscillator_is_not_stiff() {
        // x'' + 0.2 x' + x = 0: eigenvalues -0.1 +- 0.995i, ratio 1.
        let j = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -1.0, -0.2]);
        let r = analyse(&j).unwrap();
        assert!((r.stiffness_ratio - 1.0).abs() < 1e-9);
        assert_eq!(r.class, "not stiff");
        assert!((r.eigenvalues[0][0] + 0.1).abs() < 1e-12);
    }

    /// Two undamped oscillators at 1 and 1e4 rad/s: every real part is
    /// zero, yet dopri5 is held to 3.3e-4 s steps over a 6.3 s period.
    /// The ratio counts them (1e4: stiff), and generalized-alpha is
    /// recommended; with the fast one damped (zeta 0.5), radau5.
    #[test]
    fn undamped_fast_modes_make_a_structure_stiff() {
        let oscillators = |zeta: f64| {
            let mut j = DMatrix::zeros(4, 4);
            for (k, w) in [1.0f64, 1e4].into_iter().enumerate() {
                let c = if k == 1 { 2.0 * zeta * w } else { 0.0 };
                j[(2 * k, 2 * k + 1)] = 1.0;
                j[(2 * k + 1, 2 * k)] = -w * w;
                j[(2 * k + 1, 2 * k + 1)] = -c;
            }
            analyse(&j).unwrap()
        };
        let r = oscillators(0.0);
        assert!(
            (r.stiffness_ratio - 1e4).abs() < 1e-6,
            "{}",
            r.stiffness_ratio
        );
        assert_eq!(r.class, "stiff");
        assert_eq!(r.recommended_solver, "genalpha");
        assert!(r.fastest_damping_ratio < 1e-12);
        assert!((r.stable_explicit_step_s - 3.3e-4).abs() < 1e-12);
        let r = oscillators(0.5);
        assert!((r.fastest_damping_ratio - 0.5).abs() < 1e-9);
        assert_eq!(r.recommended_solver, "radau5");
    }

    /// A Jacobian that is not finite (a state blowing up) has no report,
    /// at once: nalgebra's unbounded eigenvalue iteration never returned.
    #[test]
    fn a_jacobian_that_is_not_finite_has_no_report() {
        let j = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, f64::NAN, 1e300]);
        assert!(analyse(&j).is_none());
        let j = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, f64::INFINITY, 0.0]);
        assert!(analyse(&j).is_none());
    }
}

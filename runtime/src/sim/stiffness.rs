//! Stiffness analysis of the linearised first-order system at a state:
//! eigenvalues of the analytic Jacobian, the stiffness ratio
//! max |Re l| / min |Re l| over the decaying eigenvalues, Lambert's
//! classification (not stiff below 20, moderately stiff up to 1000, stiff
//! above), the fastest time scale, the step an explicit method can take, and
//! a recommended solver.

use nalgebra::DMatrix;
use serde::Serialize;

/// Radius of dopri5's stability region along the negative real axis.
pub const DOPRI5_STABILITY_RADIUS: f64 = 3.3;

#[derive(Clone, Debug, Serialize)]
pub struct StiffnessReport {
    /// [re, im] pairs, sorted by real part (most negative first).
    pub eigenvalues: Vec<[f64; 2]>,
    pub stiffness_ratio: f64,
    pub class: &'static str,
    pub fastest_time_scale_s: f64,
    pub stable_explicit_step_s: f64,
    pub recommended_solver: &'static str,
    pub reason: String,
}

/// Analyse the Jacobian `jac` of x' = f(x).
pub fn analyse(jac: &DMatrix<f64>) -> StiffnessReport {
    let mut eig: Vec<[f64; 2]> = jac
        .complex_eigenvalues()
        .iter()
        .map(|c| [c.re, c.im])
        .collect();
    eig.sort_by(|a, b| a[0].total_cmp(&b[0]));
    let max_mod = eig.iter().map(|e| e[0].hypot(e[1])).fold(0.0, f64::max);
    // Decaying eigenvalues; real parts at round-off level count as zero.
    let floor = 1e-10 * max_mod.max(f64::MIN_POSITIVE);
    let decaying: Vec<f64> = eig.iter().map(|e| -e[0]).filter(|&r| r > floor).collect();
    let (lo, hi) = decaying
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), &r| {
            (lo.min(r), hi.max(r))
        });
    let ratio = if decaying.is_empty() { 1.0 } else { hi / lo };
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
    let stable = DOPRI5_STABILITY_RADIUS * fastest;
    let (recommended_solver, reason) = if ratio > 1000.0 {
        (
            "radau5",
            format!(
                "stiffness ratio {ratio:.3e} > 1000: an explicit method is held to steps of {stable:.2e} s by the \
                 fastest decaying mode while the slowest evolves over {:.2e} s",
                1.0 / lo
            ),
        )
    } else {
        (
            "dopri5",
            format!(
                "stiffness ratio {ratio:.3e} <= 1000: an explicit method is efficient (stable steps up to \
                 {stable:.2e} s)"
            ),
        )
    };
    StiffnessReport {
        eigenvalues: eig,
        stiffness_ratio: ratio,
        class,
        fastest_time_scale_s: fastest,
        stable_explicit_step_s: stable,
        recommended_solver,
        reason,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn classifies_the_chapters_example() {
        // y1' = -1000 y1, y2' = -0.001 y2: ratio 1e6, stiff (the chapter's
        // section on stiffness).
        let j = DMatrix::from_row_slice(2, 2, &[-1000.0, 0.0, 0.0, -0.001]);
        let r = analyse(&j);
        assert!((r.stiffness_ratio - 1e6).abs() < 1e-3);
        assert_eq!(r.class, "stiff");
        assert_eq!(r.recommended_solver, "radau5");
        assert!((r.fastest_time_scale_s - 1e-3).abs() < 1e-12);
    }

    #[test]
    fn a_lightly_damped_oscillator_is_not_stiff() {
        // x'' + 0.2 x' + x = 0: eigenvalues -0.1 +- 0.995i, ratio 1.
        let j = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -1.0, -0.2]);
        let r = analyse(&j);
        assert!((r.stiffness_ratio - 1.0).abs() < 1e-9);
        assert_eq!(r.class, "not stiff");
        assert!((r.eigenvalues[0][0] + 0.1).abs() < 1e-12);
    }
}

//! How well the data determine the fitted values: standard errors and
//! correlations from the residuals' Jacobian at the optimum.

use nalgebra::{DMatrix, DVector};

/// Standard errors and correlations of the values from the Jacobian at the
/// optimum: covariance s^2 (J^T J)^-1 with s^2 = |r|^2 / (N - m), the
/// residual's variance (Gauss-Newton's; samples taken as independent).
/// A value the data do not determine has an infinite error.
pub fn uncertainty(r: &DVector<f64>, j: &DMatrix<f64>) -> (Vec<f64>, DMatrix<f64>) {
    let (n, m) = j.shape();
    let s2 = r.norm_squared() / (n.saturating_sub(m)).max(1) as f64;
    // Columns scaled to unit norm first: J^T J of moduli and lengths spans
    // twenty decades otherwise.
    let norms: Vec<f64> = (0..m).map(|k| j.column(k).norm()).collect();
    let scaled = DMatrix::from_fn(n, m, |i, k| j[(i, k)] / norms[k].max(f64::MIN_POSITIVE));
    let a = scaled.transpose() * &scaled;
    let svd = a.svd(true, true);
    let cutoff = 1e-12 * svd.singular_values.max();
    let inv = (svd.clone())
        .pseudo_inverse(cutoff)
        .unwrap_or_else(|_| DMatrix::from_element(m, m, f64::NAN));
    let rank = svd.singular_values.iter().filter(|&&s| s > cutoff).count();
    let cov = DMatrix::from_fn(m, m, |a, b| {
        s2 * inv[(a, b)] / (norms[a] * norms[b]).max(f64::MIN_POSITIVE)
    });
    // A value with a share in a direction the data leave free (a singular
    // value below the cutoff) is not determined: its error is infinite.
    let v_t = svd.v_t.as_ref().expect("asked for V");
    let undetermined = |k: usize| {
        norms[k] == 0.0
            || (0..m).any(|s| svd.singular_values[s] <= cutoff && v_t[(s, k)].abs() > 1e-3)
    };
    let std: Vec<f64> = (0..m)
        .map(|k| match undetermined(k) {
            true => f64::INFINITY,
            false => cov[(k, k)].max(0.0).sqrt(),
        })
        .collect();
    let corr = DMatrix::from_fn(m, m, |a, b| {
        if a == b {
            1.0
        } else if rank < m {
            // Rank lost: the pseudo-inverse hides the dependence; read it
            // off the scaled columns' cosine instead.
            let c = scaled.column(a).dot(&scaled.column(b));
            c.clamp(-1.0, 1.0)
        } else {
            cov[(a, b)] / (cov[(a, a)] * cov[(b, b)]).sqrt()
        }
    });
    (std, corr)
}

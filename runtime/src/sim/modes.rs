//! Small vibrations about an equilibrium: the generalised eigenproblem
//! K v = w^2 M v with the analytic tangent stiffness (`Dynamics::stiffness`)
//! and the mass matrix, reduced to a symmetric standard one through the
//! Cholesky factor of M.

use nalgebra::{DMatrix, DVector, SymmetricEigen};
use serde::Serialize;

use crate::arm::Dynamics;

#[derive(Clone, Debug, Serialize)]
pub struct Modes {
    /// Natural frequencies (Hz), ascending. A negative value -f marks an
    /// unstable direction (w^2 < 0): the equilibrium is not a minimum.
    pub frequencies_hz: Vec<f64>,
    /// Mode shapes in generalised coordinates, one per frequency, scaled to
    /// a largest component of 1.
    pub shapes: Vec<Vec<f64>>,
}

#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ModesError {
    #[error("the mass matrix is not positive definite at this configuration")]
    Mass,
    #[error("non-finite stiffness or mass at this configuration")]
    NonFinite,
}

/// Modes of the linearisation at `q` (normally a static equilibrium).
pub fn modes(d: &dyn Dynamics, q: &[f64]) -> Result<Modes, ModesError> {
    let n = q.len();
    let mut kbuf = vec![0.0; n * n];
    d.stiffness(0.0, q, &mut kbuf);
    let k = DMatrix::from_row_slice(n, n, &kbuf);
    // Conservative loads give a symmetric K; symmetrise the round-off.
    let k = (&k + k.transpose()) * 0.5;
    let mut m = DMatrix::zeros(n, n);
    d.mass(0.0, q, &mut m);
    if k.iter().chain(m.iter()).any(|v| !v.is_finite()) {
        return Err(ModesError::NonFinite);
    }
    let chol = m.cholesky().ok_or(ModesError::Mass)?;
    let l = chol.l();
    let l_inv = l.clone().try_inverse().ok_or(ModesError::Mass)?;
    let a = &l_inv * &k * l_inv.transpose();
    let a = (&a + a.transpose()) * 0.5;
    let eig = SymmetricEigen::new(a);
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&i, &j| eig.eigenvalues[i].total_cmp(&eig.eigenvalues[j]));
    let lt_inv = l_inv.transpose();
    let mut frequencies_hz = Vec::with_capacity(n);
    let mut shapes = Vec::with_capacity(n);
    for i in order {
        let w2 = eig.eigenvalues[i];
        let f = w2.abs().sqrt() / (2.0 * std::f64::consts::PI);
        frequencies_hz.push(if w2 < 0.0 { -f } else { f });
        let v: DVector<f64> = &lt_inv * eig.eigenvectors.column(i);
        let scale = v
            .iter()
            .fold(0.0f64, |a, &b| if b.abs() > a.abs() { b } else { a });
        shapes.push(
            v.iter()
                .map(|x| if scale != 0.0 { x / scale } else { *x })
                .collect(),
        );
    }
    Ok(Modes {
        frequencies_hz,
        shapes,
    })
}

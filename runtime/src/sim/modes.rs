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
    if !d.info().constraints.is_empty() {
        return constrained(d, q, k, m);
    }
    reduced_modes(&k, &m, None)
}

/// With joints: the motions the joints allow, q = N y with N an
/// orthonormal basis of J's null space, and the stiffness of the joint
/// forces that hold q at rest added to K: N^T (K + d(J^T lambda)/dq) N y
/// = w^2 N^T M N y.
fn constrained(
    d: &dyn Dynamics,
    q: &[f64],
    k: DMatrix<f64>,
    m: DMatrix<f64>,
) -> Result<Modes, ModesError> {
    let n = q.len();
    let mut packed = vec![0.0; n * (n + 1) / 2 + n];
    d.eval_kernel(
        crate::kernels::KernelKind::MassBias,
        0.0,
        q,
        &vec![0.0; n],
        &mut packed,
    );
    let h = &mut packed[n * (n + 1) / 2..];
    crate::contact::subtract_from_bias(d, 0.0, q, &vec![0.0; n], h);
    let h = &*h;
    let lambda = crate::constraints::static_forces(d, q, h);
    let k = k + crate::constraints::geometric_stiffness(d, q, &lambda);
    let k = (&k + k.transpose()) * 0.5;
    let jac = crate::constraints::evaluate(d, 0.0, q, &vec![0.0; n]).jac;
    // Right singular vectors of J past its rank span its null space.
    let svd = jac.clone().svd(false, true);
    let vt = svd.v_t.ok_or(ModesError::NonFinite)?;
    let top = svd.singular_values.max().max(f64::MIN_POSITIVE);
    let rank = svd
        .singular_values
        .iter()
        .filter(|&&s| s > 1e-10 * top)
        .count();
    let mut basis = DMatrix::zeros(n, n - rank);
    // v_t is min(m, n) x n; complete it to n x n by the null space of its
    // rows through a QR of their orthogonal complement.
    let rows = vt.rows(0, rank).transpose();
    let mut filled = 0;
    for e in 0..n {
        if filled == n - rank {
            break;
        }
        let mut v = DVector::zeros(n);
        v[e] = 1.0;
        for c in 0..rank {
            let r = rows.column(c);
            v -= r * r.dot(&v);
        }
        for c in 0..filled {
            let b = basis.column(c).clone_owned();
            v -= &b * b.dot(&v);
        }
        let norm = v.norm();
        if norm > 1e-8 {
            basis.set_column(filled, &(v / norm));
            filled += 1;
        }
    }
    let basis = basis.columns(0, filled).clone_owned();
    let kr = basis.transpose() * &k * &basis;
    let mr = basis.transpose() * &m * &basis;
    reduced_modes(&kr, &mr, Some(&basis))
}

/// K v = w^2 M v through the Cholesky factor of M; shapes mapped back to
/// the coordinates by `basis` when given.
fn reduced_modes(
    k: &DMatrix<f64>,
    m: &DMatrix<f64>,
    basis: Option<&DMatrix<f64>>,
) -> Result<Modes, ModesError> {
    let n = k.nrows();
    let chol = m.clone().cholesky().ok_or(ModesError::Mass)?;
    let l = chol.l();
    let l_inv = l.clone().try_inverse().ok_or(ModesError::Mass)?;
    let a = &l_inv * k * l_inv.transpose();
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
        let y: DVector<f64> = &lt_inv * eig.eigenvectors.column(i);
        let v = match basis {
            Some(b) => b * y,
            None => y,
        };
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

//! An arm: a kernel set plus its parameter values, with the physics on top
//! (full mass matrix, Cholesky solve for accelerations, energies).

use std::cell::RefCell;

use nalgebra::{DMatrix, DVector};

use crate::kernels::{KernelKind, Kernels, ModelInfo};
use crate::tape::Inputs;

/// The equations of motion `M(q) qdd + h(q, qd, t) = 0` of one arm.
///
/// Both backends implement it through [`Arm`]; integrators, statics and the
/// CLI see only this trait.
pub trait Dynamics {
    fn info(&self) -> &ModelInfo;
    fn backend(&self) -> &'static str;
    fn dof(&self) -> usize {
        self.info().dof()
    }
    /// Full symmetric M(q) into `m` (dof x dof).
    fn mass(&self, t: f64, q: &[f64], m: &mut DMatrix<f64>);
    /// h(q, qd, t) into `h`.
    fn bias(&self, t: f64, q: &[f64], qd: &[f64], h: &mut DVector<f64>);
    /// Both at once, sharing subexpressions.
    fn mass_bias(&self, t: f64, q: &[f64], qd: &[f64], m: &mut DMatrix<f64>, h: &mut DVector<f64>);
    /// Tip position and energies, laid out as [`crate::OUTPUT_NAMES`].
    fn outputs(&self, t: f64, q: &[f64], qd: &[f64]) -> [f64; 5];
}

/// Why the accelerations could not be computed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum AccelError {
    #[error(
        "mass matrix is not positive definite at t = {t} (estimated condition number {condition:.3e}); \
         check masses and lengths for zero or negative values"
    )]
    SingularMass { t: f64, condition: f64 },
    #[error("non-finite {what} at t = {t}: the state has left the model's valid range")]
    NonFinite { t: f64, what: &'static str },
}

/// A model's kernels with numeric parameter values bound.
pub struct Arm<K> {
    kernels: K,
    params: Vec<f64>,
    packed: RefCell<Vec<f64>>,
}

impl<K: Kernels> Arm<K> {
    /// `params` must follow `kernels.info().parameters`.
    pub fn new(kernels: K, params: Vec<f64>) -> Self {
        assert_eq!(
            params.len(),
            kernels.info().parameters.len(),
            "parameter vector does not match the model's layout"
        );
        Self {
            kernels,
            params,
            packed: RefCell::new(Vec::new()),
        }
    }

    pub fn params(&self) -> &[f64] {
        &self.params
    }

    pub fn kernels(&self) -> &K {
        &self.kernels
    }

    fn eval_packed(&self, kind: KernelKind, t: f64, q: &[f64], qd: &[f64], f: impl FnOnce(&[f64])) {
        let n = self.kernels.info().dof();
        let mut packed = self.packed.borrow_mut();
        packed.resize(kind.output_len(n), 0.0);
        let inp = Inputs {
            t,
            q,
            qd,
            p: &self.params,
        };
        self.kernels.eval(kind, &inp, &mut packed);
        f(&packed);
    }
}

/// Unpack the upper triangle (row by row) into a full symmetric matrix.
fn unpack_symmetric(packed: &[f64], m: &mut DMatrix<f64>) {
    let n = m.nrows();
    let mut k = 0;
    for i in 0..n {
        for j in i..n {
            m[(i, j)] = packed[k];
            m[(j, i)] = packed[k];
            k += 1;
        }
    }
}

impl<K: Kernels> Dynamics for Arm<K> {
    fn info(&self) -> &ModelInfo {
        self.kernels.info()
    }
    fn backend(&self) -> &'static str {
        self.kernels.backend()
    }
    fn mass(&self, t: f64, q: &[f64], m: &mut DMatrix<f64>) {
        let zeros = vec![0.0; q.len()];
        self.eval_packed(KernelKind::Mass, t, q, &zeros, |p| unpack_symmetric(p, m));
    }
    fn bias(&self, t: f64, q: &[f64], qd: &[f64], h: &mut DVector<f64>) {
        self.eval_packed(KernelKind::Bias, t, q, qd, |p| h.copy_from_slice(p));
    }
    fn mass_bias(&self, t: f64, q: &[f64], qd: &[f64], m: &mut DMatrix<f64>, h: &mut DVector<f64>) {
        let tri = KernelKind::Mass.output_len(q.len());
        self.eval_packed(KernelKind::MassBias, t, q, qd, |p| {
            unpack_symmetric(&p[..tri], m);
            h.copy_from_slice(&p[tri..]);
        });
    }
    fn outputs(&self, t: f64, q: &[f64], qd: &[f64]) -> [f64; 5] {
        let mut out = [0.0; 5];
        self.eval_packed(KernelKind::Outputs, t, q, qd, |p| out.copy_from_slice(p));
        out
    }
}

impl<K: Kernels + ?Sized> Kernels for Box<K> {
    fn info(&self) -> &ModelInfo {
        (**self).info()
    }
    fn eval(&self, kind: KernelKind, inp: &Inputs, out: &mut [f64]) {
        (**self).eval(kind, inp, out)
    }
    fn backend(&self) -> &'static str {
        (**self).backend()
    }
}

/// Reusable buffers for [`accelerations`].
pub struct Workspace {
    m: DMatrix<f64>,
    h: DVector<f64>,
}

impl Workspace {
    pub fn new(dof: usize) -> Self {
        Self {
            m: DMatrix::zeros(dof, dof),
            h: DVector::zeros(dof),
        }
    }
}

/// In-place Cholesky factorisation M = L L^T into the lower triangle of `m`
/// (column-major, as nalgebra stores it). nalgebra's `Cholesky` allocates
/// on every call, which cost more than the whole EOM evaluation of an
/// 8-link chain (measured: 400 ns of a 615 ns right-hand side); this is the
/// same algorithm without allocation. Returns false unless M is positive
/// definite.
fn cholesky_in_place(m: &mut DMatrix<f64>) -> bool {
    let n = m.nrows();
    for j in 0..n {
        let mut d = m[(j, j)];
        for k in 0..j {
            d -= m[(j, k)] * m[(j, k)];
        }
        if !(d > 0.0) {
            return false;
        }
        let d = d.sqrt();
        m[(j, j)] = d;
        for i in j + 1..n {
            let mut s = m[(i, j)];
            for k in 0..j {
                s -= m[(i, k)] * m[(j, k)];
            }
            m[(i, j)] = s / d;
        }
    }
    true
}

/// Solve L L^T x = b in place (b becomes x), L in the lower triangle.
fn cholesky_solve(l: &DMatrix<f64>, b: &mut [f64]) {
    let n = l.nrows();
    for i in 0..n {
        let mut s = b[i];
        for k in 0..i {
            s -= l[(i, k)] * b[k];
        }
        b[i] = s / l[(i, i)];
    }
    for i in (0..n).rev() {
        let mut s = b[i];
        for k in i + 1..n {
            s -= l[(k, i)] * b[k];
        }
        b[i] = s / l[(i, i)];
    }
}

/// qdd = -M(q)^-1 h(q, qd, t), by Cholesky (M is symmetric positive definite).
pub fn accelerations<D: Dynamics + ?Sized>(
    d: &D,
    ws: &mut Workspace,
    t: f64,
    q: &[f64],
    qd: &[f64],
    qdd: &mut [f64],
) -> Result<(), AccelError> {
    d.mass_bias(t, q, qd, &mut ws.m, &mut ws.h);
    if ws.h.iter().any(|v| !v.is_finite()) {
        return Err(AccelError::NonFinite {
            t,
            what: "bias (generalised force)",
        });
    }
    if ws.m.iter().any(|v| !v.is_finite()) {
        return Err(AccelError::NonFinite {
            t,
            what: "mass matrix",
        });
    }
    if !cholesky_in_place(&mut ws.m) {
        let mut m = DMatrix::zeros(q.len(), q.len());
        d.mass(t, q, &mut m);
        let sv = m.singular_values();
        let condition = sv.max() / sv.min().max(f64::MIN_POSITIVE);
        return Err(AccelError::SingularMass { t, condition });
    }
    for (a, b) in qdd.iter_mut().zip(ws.h.iter()) {
        *a = -b;
    }
    cholesky_solve(&ws.m, qdd);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn in_place_cholesky_solves_like_nalgebra() {
        // A random SPD matrix: A^T A + n I.
        let n = 7;
        let a = DMatrix::from_fn(n, n, |i, j| ((i * 7 + j * 3) as f64 * 0.37).sin());
        let m = a.transpose() * &a + DMatrix::identity(n, n) * n as f64;
        let b = DVector::from_fn(n, |i, _| (i as f64).cos());
        let reference = m.clone().cholesky().unwrap().solve(&b);
        let mut l = m.clone();
        assert!(cholesky_in_place(&mut l));
        let mut x: Vec<f64> = b.iter().copied().collect();
        cholesky_solve(&l, &mut x);
        for i in 0..n {
            assert!((x[i] - reference[i]).abs() < 1e-13 * (1.0 + reference[i].abs()));
        }
    }

    #[test]
    fn indefinite_matrix_is_rejected() {
        let mut m = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 1.0]);
        assert!(!cholesky_in_place(&mut m));
    }
}

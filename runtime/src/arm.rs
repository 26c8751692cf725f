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
    /// A kernel's raw output (layouts in [`KernelKind`]); the hot path of
    /// the integrators, free of matrix copies.
    fn eval_kernel(&self, kind: KernelKind, t: f64, q: &[f64], qd: &[f64], out: &mut [f64]);
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
    /// `params` must follow `kernels.info().parameters`; the derived
    /// parameters are computed from them here, once.
    pub fn new(kernels: K, params: Vec<f64>) -> Self {
        let info = kernels.info();
        assert_eq!(
            params.len(),
            info.parameters.len(),
            "parameter vector does not match the model's layout"
        );
        let n_base = params.len();
        let mut extended = params;
        extended.resize(info.extended_params(), 0.0);
        let zeros = vec![0.0; info.dof()];
        let mut derived = vec![0.0; info.derived];
        let inp = Inputs {
            t: 0.0,
            q: &zeros,
            qd: &zeros,
            p: &extended,
        };
        kernels.eval(KernelKind::Derived, &inp, &mut derived);
        extended[n_base..].copy_from_slice(&derived);
        Self {
            kernels,
            params: extended,
            packed: RefCell::new(Vec::new()),
        }
    }

    /// Base parameters followed by the derived ones.
    pub fn params(&self) -> &[f64] {
        &self.params
    }

    pub fn kernels(&self) -> &K {
        &self.kernels
    }

    fn eval_packed(&self, kind: KernelKind, t: f64, q: &[f64], qd: &[f64], f: impl FnOnce(&[f64])) {
        let mut packed = self.packed.borrow_mut();
        packed.resize(kind.output_len(self.kernels.info()), 0.0);
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
        let tri = q.len() * (q.len() + 1) / 2;
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
    fn eval_kernel(&self, kind: KernelKind, t: f64, q: &[f64], qd: &[f64], out: &mut [f64]) {
        self.kernels.eval(
            kind,
            &Inputs {
                t,
                q,
                qd,
                p: &self.params,
            },
            out,
        );
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
    n: usize,
    /// `MassBias` kernel output: packed upper triangle of M, then h.
    packed: Vec<f64>,
    /// Unit lower factor L of M = L D L^T, row-major n x n.
    l: Vec<f64>,
    /// W = L D row by row (W[i][k] = L[i][k] D[k]): plain dot products.
    w: Vec<f64>,
    /// 1 / D[j].
    inv_d: Vec<f64>,
}

impl Workspace {
    pub fn new(dof: usize) -> Self {
        Self {
            n: dof,
            packed: vec![0.0; dof * (dof + 1) / 2 + dof],
            l: vec![0.0; dof * dof],
            w: vec![0.0; dof * dof],
            inv_d: vec![0.0; dof],
        }
    }
}

/// M = L D L^T (the square-root-free Cholesky factorisation), reading M from
/// the packed upper triangle (row j of it is column j of M) and writing L
/// and W = L D row-major, so every inner product runs over contiguous rows.
/// nalgebra's `Cholesky` allocates and copies on every call, which cost more
/// than the whole EOM of an 8-link chain (measured: 400 ns of a 615 ns
/// right-hand side), and its square roots sit on the critical path; this
/// does neither. Returns false unless M is positive definite (all D > 0).
fn ldlt_packed(n: usize, packed: &[f64], l: &mut [f64], w: &mut [f64], inv_d: &mut [f64]) -> bool {
    // Row j of the packed upper triangle starts at j n - j (j - 1) / 2.
    let start = |j: usize| j * n - j * j.saturating_sub(1) / 2;
    for i in 0..n {
        let (l_done, l_rest) = l.split_at_mut(i * n);
        let (_, w_rest) = w.split_at_mut(i * n);
        let (l_i, w_i) = (&mut l_rest[..i], &mut w_rest[..i]);
        for j in 0..i {
            let l_j = &l_done[j * n..j * n + j];
            // v = M[i][j] - sum_k L[i][k] D[k] L[j][k]
            let dot: f64 = w_i[..j].iter().zip(l_j).map(|(a, b)| a * b).sum();
            let v = packed[start(j) + (i - j)] - dot;
            w_i[j] = v;
            l_i[j] = v * inv_d[j];
        }
        let dot: f64 = w_i.iter().zip(l_i.iter()).map(|(a, b)| a * b).sum();
        let d = packed[start(i)] - dot;
        if d.is_nan() || d <= 0.0 {
            return false;
        }
        inv_d[i] = 1.0 / d;
    }
    true
}

/// Solve L D L^T x = b in place (b becomes x).
fn ldlt_solve(n: usize, l: &[f64], inv_d: &[f64], b: &mut [f64]) {
    for i in 0..n {
        let dot: f64 = l[i * n..i * n + i]
            .iter()
            .zip(&b[..i])
            .map(|(a, x)| a * x)
            .sum();
        b[i] -= dot;
    }
    for (x, d) in b.iter_mut().zip(inv_d) {
        *x *= d;
    }
    for i in (0..n).rev() {
        let mut s = b[i];
        for k in i + 1..n {
            s -= l[k * n + i] * b[k];
        }
        b[i] = s;
    }
}

/// qdd = -M(q)^-1 h(q, qd, t), by the L D L^T Cholesky factorisation (M is
/// symmetric positive definite).
pub fn accelerations<D: Dynamics + ?Sized>(
    d: &D,
    ws: &mut Workspace,
    t: f64,
    q: &[f64],
    qd: &[f64],
    qdd: &mut [f64],
) -> Result<(), AccelError> {
    let n = ws.n;
    d.eval_kernel(KernelKind::MassBias, t, q, qd, &mut ws.packed);
    let (mass, bias) = ws.packed.split_at(n * (n + 1) / 2);
    if !ldlt_packed(n, mass, &mut ws.l, &mut ws.w, &mut ws.inv_d) {
        if mass.iter().any(|v| !v.is_finite()) {
            return Err(AccelError::NonFinite {
                t,
                what: "mass matrix",
            });
        }
        let mut m = DMatrix::zeros(n, n);
        d.mass(t, q, &mut m);
        let sv = m.singular_values();
        let condition = sv.max() / sv.min().max(f64::MIN_POSITIVE);
        return Err(AccelError::SingularMass { t, condition });
    }
    for (a, b) in qdd.iter_mut().zip(bias) {
        *a = -b;
    }
    ldlt_solve(n, &ws.l, &ws.inv_d, qdd);
    // A NaN or infinity in M or h reaches qdd; only then look closer.
    if qdd.iter().any(|v| !v.is_finite()) {
        let what = if mass.iter().all(|v| v.is_finite()) {
            "bias (generalised force)"
        } else {
            "mass matrix"
        };
        return Err(AccelError::NonFinite { t, what });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pack(m: &DMatrix<f64>) -> Vec<f64> {
        let n = m.nrows();
        let mut p = Vec::new();
        for i in 0..n {
            for j in i..n {
                p.push(m[(i, j)]);
            }
        }
        p
    }

    #[test]
    fn packed_ldlt_solves_like_nalgebra() {
        // A random SPD matrix: A^T A + n I.
        let n = 7;
        let a = DMatrix::from_fn(n, n, |i, j| ((i * 7 + j * 3) as f64 * 0.37).sin());
        let m = a.transpose() * &a + DMatrix::identity(n, n) * n as f64;
        let b = DVector::from_fn(n, |i, _| (i as f64).cos());
        let reference = m.clone().cholesky().unwrap().solve(&b);
        let (mut l, mut w, mut inv) = (vec![0.0; n * n], vec![0.0; n * n], vec![0.0; n]);
        assert!(ldlt_packed(n, &pack(&m), &mut l, &mut w, &mut inv));
        let mut x: Vec<f64> = b.iter().copied().collect();
        ldlt_solve(n, &l, &inv, &mut x);
        for i in 0..n {
            assert!((x[i] - reference[i]).abs() < 1e-13 * (1.0 + reference[i].abs()));
        }
    }

    #[test]
    fn indefinite_matrix_is_rejected() {
        let m = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 1.0]);
        let (mut l, mut w, mut inv) = (vec![0.0; 4], vec![0.0; 4], vec![0.0; 2]);
        assert!(!ldlt_packed(2, &pack(&m), &mut l, &mut w, &mut inv));
    }
}

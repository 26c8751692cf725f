//! Solving M x = b for the symmetric positive definite mass matrix, by the
//! square-root-free Cholesky factorisation M = L D L^T.
//!
//! M arrives as the packed upper triangle the kernels produce (row j of it
//! is column j of M). L and W = L D are stored row-major so every inner
//! product runs over contiguous memory. nalgebra's `Cholesky` allocates and
//! copies on every call, which cost more than the whole EOM of an 8-link
//! chain (measured: 400 ns of a 615 ns right-hand side), and its square
//! roots sit on the critical path; this does neither. Small arms do not come
//! here: their solve is generated with the EOM (`KernelKind::Accel`).

/// Start of row j of a packed upper triangle of size n: j n - j (j - 1) / 2.
#[inline(always)]
fn row_start(n: usize, j: usize) -> usize {
    j * n - j * j.saturating_sub(1) / 2
}

/// Factorisation workspace for any size.
#[derive(Clone, Debug)]
pub struct Ldlt {
    n: usize,
    /// Unit lower factor L, row-major n x n.
    l: Vec<f64>,
    /// W[i][k] = L[i][k] D[k].
    w: Vec<f64>,
    /// 1 / D[j].
    inv_d: Vec<f64>,
}

impl Ldlt {
    pub fn new(n: usize) -> Self {
        Self {
            n,
            l: vec![0.0; n * n],
            w: vec![0.0; n * n],
            inv_d: vec![0.0; n],
        }
    }

    /// Factor the packed matrix; false unless it is positive definite.
    pub fn factor(&mut self, packed: &[f64]) -> bool {
        let n = self.n;
        for i in 0..n {
            let (l_done, l_rest) = self.l.split_at_mut(i * n);
            let (_, w_rest) = self.w.split_at_mut(i * n);
            let (l_i, w_i) = (&mut l_rest[..i], &mut w_rest[..i]);
            for j in 0..i {
                let l_j = &l_done[j * n..j * n + j];
                let dot: f64 = w_i[..j].iter().zip(l_j).map(|(a, b)| a * b).sum();
                let v = packed[row_start(n, j) + (i - j)] - dot;
                w_i[j] = v;
                l_i[j] = v * self.inv_d[j];
            }
            let dot: f64 = w_i.iter().zip(l_i.iter()).map(|(a, b)| a * b).sum();
            let d = packed[row_start(n, i)] - dot;
            if d.is_nan() || d <= 0.0 {
                return false;
            }
            self.inv_d[i] = 1.0 / d;
        }
        true
    }

    /// Solve L D L^T x = b in place, after a successful [`Ldlt::factor`].
    #[allow(clippy::needless_range_loop)] // triangular index ranges read clearer
    pub fn solve(&self, b: &mut [f64]) {
        let n = self.n;
        for i in 0..n {
            let dot: f64 = self.l[i * n..i * n + i]
                .iter()
                .zip(&b[..i])
                .map(|(a, x)| a * x)
                .sum();
            b[i] -= dot;
        }
        for (x, d) in b.iter_mut().zip(&self.inv_d) {
            *x *= d;
        }
        for i in (0..n).rev() {
            let mut s = b[i];
            for k in i + 1..n {
                s -= self.l[k * n + i] * b[k];
            }
            b[i] = s;
        }
    }
}

#[cfg(all(test, feature = "simulate"))]
mod tests {
    use super::*;
    use nalgebra::{DMatrix, DVector};

    fn pack(m: &DMatrix<f64>) -> Vec<f64> {
        let n = m.nrows();
        (0..n)
            .flat_map(|i| (i..n).map(move |j| (i, j)))
            .map(|(i, j)| m[(i, j)])
            .collect()
    }

    /// A random SPD matrix A^T A + n I and a right-hand side.
    fn problem(n: usize) -> (DMatrix<f64>, DVector<f64>) {
        let a = DMatrix::from_fn(n, n, |i, j| ((i * 7 + j * 3) as f64 * 0.37).sin());
        let m = a.transpose() * &a + DMatrix::identity(n, n) * n as f64;
        (m, DVector::from_fn(n, |i, _| (i as f64).cos()))
    }

    #[test]
    fn solve_matches_nalgebra() {
        for n in [1, 2, 7] {
            let (m, b) = problem(n);
            let reference = m.clone().cholesky().unwrap().solve(&b);
            let mut ldlt = Ldlt::new(n);
            assert!(ldlt.factor(&pack(&m)));
            let mut x: Vec<f64> = b.iter().copied().collect();
            ldlt.solve(&mut x);
            for i in 0..n {
                assert!((x[i] - reference[i]).abs() < 1e-13 * (1.0 + reference[i].abs()));
            }
        }
    }

    #[test]
    fn indefinite_and_nan_matrices_are_rejected() {
        let bad = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 1.0]);
        assert!(!Ldlt::new(2).factor(&pack(&bad)));
        let nan = DMatrix::from_row_slice(2, 2, &[f64::NAN, 0.0, 0.0, 1.0]);
        assert!(!Ldlt::new(2).factor(&pack(&nan)));
    }
}

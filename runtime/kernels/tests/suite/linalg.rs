//! The packed L D L^T solve against nalgebra's, dense and by envelope (`linalg`).

use nalgebra::{DMatrix, DVector};
use runtime_kernels::linalg::*;

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

/// M x = b solved as nalgebra's Cholesky solves it; the factors.
fn solved_as_nalgebra(m: &DMatrix<f64>, b: &DVector<f64>) -> Ldlt {
    let n = m.nrows();
    let reference = m.clone().cholesky().unwrap().solve(b);
    let mut ldlt = Ldlt::new(n);
    assert!(ldlt.factor(&pack(m)));
    let mut x: Vec<f64> = b.iter().copied().collect();
    ldlt.solve(&mut x);
    for i in 0..n {
        assert!((x[i] - reference[i]).abs() < 1e-13 * (1.0 + reference[i].abs()));
    }
    ldlt
}

#[test]
fn solve_matches_nalgebra() {
    for n in [1, 2, 7, 40] {
        let (m, b) = problem(n);
        solved_as_nalgebra(&m, &b);
    }
}

/// A block-diagonal matrix with an envelope (rows starting late) is
/// solved as the dense one is.
#[test]
fn envelope_matrices_solve_as_dense_ones() {
    let n = 9;
    let (full, b) = problem(n);
    // Blocks 0..4 and 4..9, the second with its row 6 starting at 5.
    let m = DMatrix::from_fn(n, n, |i, j| {
        let same = (i < 4) == (j < 4);
        let inside = !(i.max(j) == 6 && i.min(j) == 4);
        if same && inside { full[(i, j)] } else { 0.0 }
    });
    let ldlt = solved_as_nalgebra(&m, &b);
    let (dense, first, end) = ldlt.envelope();
    assert!(!dense);
    assert_eq!(first, [0, 0, 0, 0, 4, 4, 5, 4, 4]);
    assert_eq!(end, [4, 4, 4, 4, 9, 9, 9, 9, 9]);
}

#[test]
fn a_block_lands_in_its_place() {
    let (n, first, m) = (6, 2, 3);
    let dense_m = |i: usize, j: usize| (10 * i.min(j) + i.max(j)) as f64;
    let mut block = Vec::new();
    for i in 0..m {
        for j in i..m {
            block.push(dense_m(i, j));
        }
    }
    block.extend([100.0, 200.0, 300.0]);
    let mut out = vec![0.0; n * (n + 1) / 2 + n];
    add_block(n, first, m, &block, &mut out);
    let mut k = 0;
    for i in 0..n {
        for j in i..n {
            let inside = (first..first + m).contains(&i) && (first..first + m).contains(&j);
            let want = if inside {
                dense_m(i - first, j - first)
            } else {
                0.0
            };
            assert_eq!(out[k], want, "M[{i}][{j}]");
            k += 1;
        }
    }
    let h = &out[n * (n + 1) / 2..];
    assert_eq!(h, &[0.0, 0.0, 100.0, 200.0, 300.0, 0.0]);
}

#[test]
fn indefinite_and_nan_matrices_are_rejected() {
    let bad = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 1.0]);
    assert!(!Ldlt::new(2).factor(&pack(&bad)));
    let nan = DMatrix::from_row_slice(2, 2, &[f64::NAN, 0.0, 0.0, 1.0]);
    assert!(!Ldlt::new(2).factor(&pack(&nan)));
}

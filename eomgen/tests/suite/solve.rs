//! The symbolic linear solve of the TMT derivation.

use eomgen::cas::SymKind;
use eomgen::cas::{Cas, ExprId};
use eomgen::tmt::*;

/// On a random symmetric positive definite M (as symbols, so nothing
/// folds), the generated solve's qdd satisfies M qdd + h = 0, and its
/// factors give back M = L D L^T.
#[test]
fn the_symbolic_solve_solves_and_factors() {
    let n = 6;
    // M = A A^T + n I from a fixed pseudo-random A; h likewise.
    let mut seed = 12345u64;
    let mut next = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let a: Vec<Vec<f64>> = (0..n).map(|_| (0..n).map(|_| next()).collect()).collect();
    let m = |i: usize, j: usize| {
        (0..n).map(|k| a[i][k] * a[j][k]).sum::<f64>() + if i == j { n as f64 } else { 0.0 }
    };
    let h: Vec<f64> = (0..n).map(|_| next()).collect();
    let mut cas = Cas::new();
    let mut values = Vec::new();
    let mut upper = Vec::new();
    for i in 0..n {
        for j in i..n {
            upper.push(cas.symbol(&format!("m{i}{j}"), SymKind::Param(values.len() as u32)));
            values.push(m(i, j));
        }
    }
    let bias: Vec<ExprId> = (0..n)
        .map(|i| {
            let s = cas.symbol(&format!("h{i}"), SymKind::Param(values.len() as u32));
            values.push(h[i]);
            s
        })
        .collect();
    let solve = solve_accelerations(&mut cas, &upper, &bias);
    let value = |s| match cas.sym_kind(s) {
        SymKind::Param(i) => Some(values[i as usize]),
        _ => None,
    };
    let qdd = cas.eval_many(&solve.qdd, &value).unwrap();
    let d = cas.eval_many(&solve.pivots, &value).unwrap();
    let low = cas.eval_many(&solve.lower, &value).unwrap();
    for (i, hi) in h.iter().enumerate() {
        let r: f64 = (qdd.iter().enumerate())
            .map(|(j, a)| m(i, j) * a)
            .sum::<f64>()
            + hi;
        assert!(r.abs() < 1e-13, "row {i}: residual {r}");
    }
    // L below its unit diagonal, row by row.
    let l = |i: usize, j: usize| match i.cmp(&j) {
        std::cmp::Ordering::Equal => 1.0,
        std::cmp::Ordering::Less => 0.0,
        std::cmp::Ordering::Greater => low[i * (i - 1) / 2 + j],
    };
    for i in 0..n {
        for j in 0..n {
            let ldl: f64 = (0..n).map(|k| l(i, k) * d[k] * l(j, k)).sum();
            assert!(
                (ldl - m(i, j)).abs() < 1e-13,
                "M[{i}][{j}]: {ldl} against {}",
                m(i, j)
            );
        }
    }
}

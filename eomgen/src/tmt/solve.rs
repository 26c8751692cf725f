//! The mass solve qdd = -M^-1 h as expressions: L D L^T run symbolically on
//! the entries of M and h, each intermediate bound so nothing expands. Emitted
//! with the EOM, the solve becomes straight-line code on values already in
//! registers (no matrix buffers, no loops). Its cost grows as n^3 / 3, so it
//! is only generated for small arms ([`SYMBOLIC_SOLVE_MAX_DOF`]).

use crate::cas::{Cas, ExprId};

/// Largest DOF whose mass solve is generated.
pub const SYMBOLIC_SOLVE_MAX_DOF: usize = 24;

/// The generated mass solve: the accelerations, and the factors of
/// M = L D L^T, which solve M x = f for a further force at run time (the
/// contact forces, found after the kernel ran).
pub struct MassSolve {
    pub qdd: Vec<ExprId>,
    /// The pivots D.
    pub pivots: Vec<ExprId>,
    /// L below its unit diagonal, row by row: (1,0), (2,0), (2,1), ...
    pub lower: Vec<ExprId>,
}

/// qdd = -M^-1 h and the factors. `mass_upper` is the upper triangle row
/// by row.
pub fn solve_accelerations(cas: &mut Cas, mass_upper: &[ExprId], bias: &[ExprId]) -> MassSolve {
    let n = bias.len();
    let m = |i: usize, j: usize| {
        let (a, b) = (i.min(j), i.max(j));
        mass_upper[a * n - a * a.saturating_sub(1) / 2 - a + b]
    };
    let zero = cas.zero();
    let mut l = vec![vec![zero; n]; n];
    let mut d = vec![zero; n];
    let mut inv_d = vec![zero; n];
    for i in 0..n {
        // Row i of W = L D, needed only while row i of L is formed.
        let mut w = vec![zero; i];
        for j in 0..i {
            let dot = cas.dot(&w[..j], &l[j][..j]);
            let v = cas.sub(m(i, j), dot);
            w[j] = cas.bind(v);
            let lij = cas.mul(w[j], inv_d[j]);
            l[i][j] = cas.bind(lij);
        }
        let dot = cas.dot(&w, &l[i][..i]);
        let di = cas.sub(m(i, i), dot);
        d[i] = cas.bind(di);
        let inv = cas.powi(d[i], -1);
        inv_d[i] = cas.bind(inv);
    }
    // L y = -h, z = D^-1 y, L^T x = z.
    let mut y = vec![zero; n];
    for i in 0..n {
        let dot = cas.dot(&l[i][..i], &y[..i]);
        let s = cas.add(bias[i], dot);
        let yi = cas.neg(s);
        y[i] = cas.bind(yi);
    }
    let mut x = vec![zero; n];
    for i in (0..n).rev() {
        let col: Vec<ExprId> = (i + 1..n).map(|k| l[k][i]).collect();
        let dot = cas.dot(&col, &x[i + 1..]);
        let z = cas.mul(y[i], inv_d[i]);
        let xi = cas.sub(z, dot);
        x[i] = cas.bind(xi);
    }
    let lower = (1..n).flat_map(|i| l[i][..i].to_vec()).collect();
    MassSolve {
        qdd: x,
        pivots: d,
        lower,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cas::SymKind;

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
}

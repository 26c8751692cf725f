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

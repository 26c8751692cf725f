//! Solving M x = b for the symmetric positive definite mass matrix, by the
//! square-root-free Cholesky factorisation M = L D L^T.
//!
//! M arrives as the packed upper triangle the kernels produce (row j of it
//! is column j of M). L is stored row-major and factored right-looking, so
//! every update runs over a contiguous run of a row. nalgebra's `Cholesky` allocates and
//! copies on every call, which cost more than the whole EOM of an 8-link
//! chain (measured: 400 ns of a 615 ns right-hand side), and its square
//! roots sit on the critical path; this does neither. Small arms do not come
//! here: their solve is generated with the EOM (`KernelKind::Accel`).

/// Start of row j of a packed upper triangle of size n: j n - j (j - 1) / 2.
#[inline(always)]
fn row_start(n: usize, j: usize) -> usize {
    j * n - j * j.saturating_sub(1) / 2
}

/// sum a_i b_i in four independent sums: a chain of dependent additions
/// would wait out every one's latency. With `FMA`, the products fused into
/// the sums: for callers built for FMA (elsewhere `mul_add` is a library
/// call).
#[inline(always)]
fn dot<const FMA: bool>(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    let mut s = [0.0; 4];
    let (ac, bc) = (a.chunks_exact(4), b.chunks_exact(4));
    let (ar, br) = (ac.remainder(), bc.remainder());
    for (x, y) in ac.zip(bc) {
        for k in 0..4 {
            s[k] = if FMA {
                x[k].mul_add(y[k], s[k])
            } else {
                s[k] + x[k] * y[k]
            };
        }
    }
    let tail: f64 = ar.iter().zip(br).map(|(x, y)| x * y).sum();
    (s[0] + s[1]) + (s[2] + s[3]) + tail
}

/// Rows of an arm's point kernels (`head` values, then a 3 x m Jacobian
/// row-major over its `m` coordinates) into the assembly's rows (`head`,
/// then 3 x n over its `n`): the arm's columns from `first`, the others
/// zero (an arm on a fixed base moves with its own coordinates alone).
#[inline(always)]
pub fn place_point_rows(
    head: usize,
    n: usize,
    first: usize,
    m: usize,
    rows: &[f64],
    out: &mut [f64],
) {
    for (r, o) in rows
        .chunks_exact(head + 3 * m)
        .zip(out.chunks_exact_mut(head + 3 * n))
    {
        o[..head].copy_from_slice(&r[..head]);
        for c in 0..3 {
            let row = &mut o[head + c * n..head + (c + 1) * n];
            row.fill(0.0);
            row[first..first + m].copy_from_slice(&r[head + c * m..head + (c + 1) * m]);
        }
    }
}

/// [`place_point_rows`] for the `ContactJacobian` groups an arm's kernel
/// evaluated (`groups`: points per group; group k when `all` or
/// `dir[k] != 0`), rows of `6 + 3 m` into rows of `6 + 3 n`; the others'
/// rows are left as they were.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn place_groups(
    all: bool,
    dir: &[f64],
    groups: &[usize],
    n: usize,
    first: usize,
    m: usize,
    rows: &[f64],
    out: &mut [f64],
) {
    let (wa, w) = (6 + 3 * m, 6 + 3 * n);
    let mut point = 0;
    for (k, &len) in groups.iter().enumerate() {
        if all || dir[k] != 0.0 {
            let (a, b) = (point, point + len);
            place_point_rows(
                6,
                n,
                first,
                m,
                &rows[a * wa..b * wa],
                &mut out[a * w..b * w],
            );
        }
        point += len;
    }
}

/// Add an arm's packed M and h (`block`, `m` coordinates) into the
/// assembly's (`out`, `n` coordinates), its coordinates from `first`.
#[inline(always)]
pub fn add_block(n: usize, first: usize, m: usize, block: &[f64], out: &mut [f64]) {
    let row = |size: usize, j: usize| j * size - j * j.saturating_sub(1) / 2;
    for a in 0..m {
        let (src, dst) = (row(m, a), row(n, first + a));
        for (o, b) in out[dst..dst + m - a]
            .iter_mut()
            .zip(&block[src..src + m - a])
        {
            *o += b;
        }
    }
    let (tri_n, tri_m) = (n * (n + 1) / 2, m * (m + 1) / 2);
    for (o, b) in out[tri_n + first..tri_n + first + m]
        .iter_mut()
        .zip(&block[tri_m..tri_m + m])
    {
        *o += b;
    }
}

/// Factorisation workspace for any size.
#[derive(Clone, Debug)]
pub struct Ldlt {
    n: usize,
    /// Unit lower factor L below the diagonal, row-major n x n (the
    /// factorisation's working matrix while it runs).
    l: Vec<f64>,
    /// Column j of L D while step j updates the rows below it.
    col: Vec<f64>,
    /// 1 / D[j].
    inv_d: Vec<f64>,
    /// Per row, its first nonzero column (M's envelope, which L keeps).
    first: Vec<usize>,
    /// Per column j, one past the last row whose envelope reaches it: L
    /// is zero from there down.
    end: Vec<usize>,
    /// Every row starts at column 0: the plain loops.
    dense: bool,
}

impl Ldlt {
    /// Whether the last factorisation ran dense, and the envelope it kept
    /// otherwise: per row its first nonzero column, per column one past
    /// its last nonzero row.
    #[doc(hidden)] // white-box tests (tests/suite)
    pub fn envelope(&self) -> (bool, &[usize], &[usize]) {
        (self.dense, &self.first, &self.end)
    }

    pub fn new(n: usize) -> Self {
        Self {
            n,
            l: vec![0.0; n * n],
            col: vec![0.0; n],
            inv_d: vec![0.0; n],
            first: vec![0; n],
            end: vec![0; n],
            dense: true,
        }
    }

    /// Factor the packed matrix; false unless it is positive definite.
    pub fn factor(&mut self, packed: &[f64]) -> bool {
        self.factor_with::<false>(packed)
    }

    /// [`Ldlt::factor`] with fused multiply-adds, inlined into a caller
    /// built for FMA.
    #[inline(always)]
    pub fn factor_fma(&mut self, packed: &[f64]) -> bool {
        self.factor_with::<true>(packed)
    }

    /// Right-looking: step j takes pivot j and subtracts its column's
    /// outer product from the rows below, each update a contiguous run of
    /// a row (vector instructions; the dot-product form's short dots of
    /// dependent sums took three times as long at 40 coordinates).
    ///
    /// A matrix with an envelope (rows that start late: an assembly's M,
    /// block diagonal over its arms and bodies; eba's, banded) is factored
    /// within it, where L's nonzeros are, at the cost of its blocks; a
    /// dense one by the plain loops (their bounds constants: the envelope's
    /// bounds cost a dense 20-coordinate arm 5 % of its right-hand side).
    #[inline(always)]
    fn factor_with<const FMA: bool>(&mut self, packed: &[f64]) -> bool {
        let n = self.n;
        let a = &mut self.l;
        for k in 0..n {
            let row = &packed[row_start(n, k)..row_start(n, k) + (n - k)];
            for (i, &m) in (k..n).zip(row) {
                a[i * n + k] = m;
            }
        }
        // A corner that is not zero: dense (no envelope to find).
        if n == 0 || packed[n - 1] != 0.0 {
            self.dense = true;
            return self.factor_loops::<FMA, true>();
        }
        for (i, first) in self.first.iter_mut().enumerate() {
            *first = (0..i).find(|&k| a[i * n + k] != 0.0).unwrap_or(i);
        }
        for j in 0..n {
            self.end[j] = 1 + (j..n).rev().find(|&i| self.first[i] <= j).unwrap_or(j);
        }
        // The envelope's loops where they save a quarter of the work.
        let (mut within, mut full) = (0, 0);
        for (j, &end) in self.end.iter().enumerate() {
            within += (end - j) * (end - j);
            full += (n - j) * (n - j);
        }
        self.dense = 4 * within > 3 * full;
        match self.dense {
            true => self.factor_loops::<FMA, true>(),
            false => self.factor_loops::<FMA, false>(),
        }
    }

    /// The factorisation's loops, over each column's rows down to its
    /// envelope's end (`DENSE`: n).
    #[inline(always)]
    fn factor_loops<const FMA: bool, const DENSE: bool>(&mut self) -> bool {
        let n = self.n;
        let a = &mut self.l;
        for j in 0..n {
            let d = a[j * n + j];
            if d.is_nan() || d <= 0.0 {
                return false;
            }
            let inv = 1.0 / d;
            self.inv_d[j] = inv;
            let end = if DENSE { n } else { self.end[j] };
            for i in j + 1..end {
                self.col[i] = a[i * n + j];
            }
            for i in j + 1..end {
                let l = self.col[i] * inv;
                let row = &mut a[i * n..i * n + i + 1];
                row[j] = l;
                for (x, c) in row[j + 1..].iter_mut().zip(&self.col[j + 1..=i]) {
                    *x = if FMA {
                        (-l).mul_add(*c, *x)
                    } else {
                        *x - l * c
                    };
                }
            }
        }
        true
    }

    /// Solve L D L^T x = b in place, after a successful [`Ldlt::factor`].
    pub fn solve(&self, b: &mut [f64]) {
        self.solve_with::<false>(b)
    }

    /// [`Ldlt::solve`] with fused multiply-adds, inlined into a caller
    /// built for FMA.
    #[inline(always)]
    pub fn solve_fma(&self, b: &mut [f64]) {
        self.solve_with::<true>(b)
    }

    #[allow(clippy::needless_range_loop)] // triangular index ranges read clearer
    #[inline(always)]
    fn solve_with<const FMA: bool>(&self, b: &mut [f64]) {
        match self.dense {
            true => self.solve_loops::<FMA, true>(b),
            false => self.solve_loops::<FMA, false>(b),
        }
    }

    #[allow(clippy::needless_range_loop)] // triangular index ranges read clearer
    #[inline(always)]
    fn solve_loops<const FMA: bool, const DENSE: bool>(&self, b: &mut [f64]) {
        let n = self.n;
        for i in 0..n {
            let f = if DENSE { 0 } else { self.first[i] };
            b[i] -= dot::<FMA>(&self.l[i * n + f..i * n + i], &b[f..i]);
        }
        for (x, d) in b.iter_mut().zip(&self.inv_d) {
            *x *= d;
        }
        for i in (0..n).rev() {
            let mut s = b[i];
            let end = if DENSE { n } else { self.end[i] };
            for k in i + 1..end {
                s -= self.l[k * n + i] * b[k];
            }
            b[i] = s;
        }
    }
}

//! Joints that close loops: the constraint equations phi(q) = 0 of the
//! `Constraints` kernel, held by Lagrange multipliers (docs/design.md
//! section 7).
//!
//! The accelerations solve
//!
//!   [M J^T; J 0] [qdd; lambda] = [-h; -gamma],   gamma = (d/dt J) qd,
//!
//! by the range-space method, without forming an inverse: M = L D L^T
//! once (block by block: an assembly's arms and bodies are independent
//! blocks of M), X = M^-1 J^T (m solves, each on the blocks its row
//! touches), the Schur complement S = J X (m x m,
//! symmetric positive definite while the joints are independent),
//! S lambda = J a0 + gamma with a0 = -M^-1 h, qdd = a0 - X lambda. The
//! generalised joint force on the system is -J^T lambda; for the rows of a
//! joint (point gap of frame a minus frame b, then b's angle minus a's),
//! lambda is the force (N) and moment (N m) the joint applies to frame b,
//! in the world frame.
//!
//! The drift off phi = 0 and phi' = J qd = 0 that integration leaves is
//! removed by projection (`project`), never by a stabilising gain.

use nalgebra::{DMatrix, DVector};

use crate::arm::{AccelError, Dynamics};
use crate::kernels::KernelKind;
use crate::linalg::Ldlt;

/// The `Constraints` kernel's output split: phi, J (row-major), gamma.
pub struct ConstraintEval {
    pub phi: Vec<f64>,
    pub jac: DMatrix<f64>,
    pub gamma: Vec<f64>,
}

/// phi, J and gamma at (t, q, qd).
pub fn evaluate<D: Dynamics + ?Sized>(d: &D, t: f64, q: &[f64], qd: &[f64]) -> ConstraintEval {
    let (m, n) = (d.info().constraints.len(), d.dof());
    let mut out = vec![0.0; m * (n + 2)];
    d.eval_kernel(KernelKind::Constraints, t, q, qd, &mut out);
    ConstraintEval {
        phi: out[..m].to_vec(),
        jac: DMatrix::from_row_slice(m, n, &out[m..m + m * n]),
        gamma: out[m + m * n..].to_vec(),
    }
}

/// Buffers of the constrained solve, reused between evaluations.
pub struct KktWorkspace {
    m: usize,
    out: Vec<f64>,
    /// The independent blocks of M: first coordinate, size, the block's
    /// packed upper triangle and its factorisation.
    blocks: Vec<(usize, usize, Vec<f64>, Ldlt)>,
    /// X = M^-1 J^T, column by column (m columns of n).
    x: Vec<f64>,
    /// Per row, the blocks its J row touches.
    touches: Vec<Vec<bool>>,
    /// S = J X, packed upper triangle.
    s: Vec<f64>,
    schur: Ldlt,
    pub lambda: Vec<f64>,
}

impl KktWorkspace {
    /// For `n` coordinates in blocks of the given sizes (empty: one), `m`
    /// constraint rows.
    pub fn new(n: usize, m: usize, blocks: &[usize]) -> Self {
        let sizes = if blocks.iter().sum::<usize>() == n && !blocks.is_empty() {
            blocks.to_vec()
        } else {
            vec![n]
        };
        let mut first = 0;
        let blocks = sizes
            .iter()
            .map(|&nb| {
                let b = (first, nb, vec![0.0; nb * (nb + 1) / 2], Ldlt::new(nb));
                first += nb;
                b
            })
            .collect::<Vec<_>>();
        Self {
            m,
            out: vec![0.0; m * (n + 2)],
            touches: vec![vec![false; blocks.len()]; m],
            blocks,
            x: vec![0.0; n * m],
            s: vec![0.0; m * (m + 1) / 2],
            schur: Ldlt::new(m),
            lambda: vec![0.0; m],
        }
    }

    /// Factor M block by block from its packed upper triangle (n x n);
    /// false unless every block is positive definite.
    fn factor(&mut self, n: usize, packed: &[f64]) -> bool {
        for (first, nb, tri, ldlt) in &mut self.blocks {
            let mut k = 0;
            for i in 0..*nb {
                let row = *first + i;
                // Row `row` of the big triangle starts at row n - row (row - 1) / 2.
                let start = row * n - row * row.saturating_sub(1) / 2;
                for j in i..*nb {
                    tri[k] = packed[start + (j - i)];
                    k += 1;
                }
            }
            if !ldlt.factor(tri) {
                return false;
            }
        }
        true
    }

    /// b = M^-1 b on the blocks `only` marks (all when None).
    fn solve(&self, b: &mut [f64], only: Option<&[bool]>) {
        for (k, (first, nb, _, ldlt)) in self.blocks.iter().enumerate() {
            if only.is_none_or(|o| o[k]) {
                ldlt.solve(&mut b[*first..*first + *nb]);
            }
        }
    }
}

/// qdd of the constrained system from the packed `MassBias` output
/// (M's upper triangle, then h); lambda left in `ws.lambda`. M is factored
/// block by block, and each row's X column is solved only on the blocks
/// its J row touches (a joint's row touches two subsystems). Ok(false)
/// when M is not positive definite.
pub(crate) fn solve_constrained<D: Dynamics + ?Sized>(
    d: &D,
    ws: &mut KktWorkspace,
    packed: &[f64],
    t: f64,
    q: &[f64],
    qd: &[f64],
    qdd: &mut [f64],
) -> Result<bool, AccelError> {
    let (m, n) = (ws.m, q.len());
    let (_, bias) = packed.split_at(n * (n + 1) / 2);
    for (a, b) in qdd.iter_mut().zip(bias) {
        *a = -b;
    }
    if !ws.factor(n, packed) {
        return Ok(false);
    }
    ws.solve(qdd, None);
    d.eval_kernel(KernelKind::Constraints, t, q, qd, &mut ws.out);
    let (jac, gamma) = ws.out[m..].split_at(m * n);
    for r in 0..m {
        let row = &jac[r * n..(r + 1) * n];
        for (k, (first, nb, _, _)) in ws.blocks.iter().enumerate() {
            ws.touches[r][k] = row[*first..*first + *nb].iter().any(|&v| v != 0.0);
        }
        let mut col = std::mem::take(&mut ws.x);
        col[r * n..(r + 1) * n].copy_from_slice(row);
        ws.solve(&mut col[r * n..(r + 1) * n], Some(&ws.touches[r]));
        ws.x = col;
    }
    let mut k = 0;
    for r in 0..m {
        let row = &jac[r * n..(r + 1) * n];
        for c in r..m {
            ws.s[k] = dot(row, &ws.x[c * n..(c + 1) * n]);
            k += 1;
        }
        ws.lambda[r] = dot(row, qdd) + gamma[r];
    }
    if !ws.schur.factor(&ws.s) {
        return Err(AccelError::DependentJoints { t });
    }
    ws.schur.solve(&mut ws.lambda);
    for (r, l) in ws.lambda.iter().enumerate() {
        for (a, x) in qdd.iter_mut().zip(&ws.x[r * n..(r + 1) * n]) {
            *a -= l * x;
        }
    }
    Ok(true)
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The joint forces lambda at a state (rows as `info().constraints`).
pub fn forces<D: Dynamics + ?Sized>(
    d: &D,
    t: f64,
    q: &[f64],
    qd: &[f64],
) -> Result<Vec<f64>, AccelError> {
    let n = d.dof();
    let mut ws = crate::arm::Workspace::new(n);
    let mut qdd = vec![0.0; n];
    crate::arm::accelerations(d, &mut ws, t, q, qd, &mut qdd)?;
    Ok(ws.lambda().to_vec())
}

/// How far a state is off the joints: the largest point gap (m), angle gap
/// (rad; also a free body's quaternion off unit norm) and velocity gap
/// |J qd| (m/s or rad/s).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Drift {
    pub position_m: f64,
    pub angle_rad: f64,
    pub velocity: f64,
}

pub fn drift<D: Dynamics + ?Sized>(d: &D, t: f64, q: &[f64], qd: &[f64]) -> Drift {
    let c = evaluate(d, t, q, qd);
    let rows = &d.info().constraints;
    let v = &c.jac * DVector::from_column_slice(qd);
    let mut out = Drift::default();
    for (i, name) in rows.iter().enumerate() {
        let gap = c.phi[i].abs();
        if [".x", ".y", ".z"].iter().any(|s| name.ends_with(s)) {
            out.position_m = out.position_m.max(gap);
        } else {
            out.angle_rad = out.angle_rad.max(gap);
        }
        out.velocity = out.velocity.max(v[i].abs());
    }
    out
}

/// Why a state could not be put on the joints.
#[derive(Clone, Debug, PartialEq)]
pub struct AssemblyFailure {
    /// The row with the largest residual and the residual.
    pub row: String,
    pub residual: f64,
    pub iterations: usize,
}

/// The state moved onto phi = 0, J qd = 0 by the least change of its
/// coordinates (Gauss-Newton on the minimum-norm correction
/// dq = -J^T (J J^T)^-1 phi; then qd projected on the null space of J),
/// with the distance |dq| it moved. Rows whose J J^T is singular
/// (dependent joints) are handled by the pseudo-inverse.
pub fn project<D: Dynamics + ?Sized>(
    d: &D,
    t: f64,
    q: &mut [f64],
    qd: &mut [f64],
    tol: f64,
) -> Result<f64, AssemblyFailure> {
    let start = q.to_vec();
    let mut iterations = 0;
    loop {
        let c = evaluate(d, t, q, qd);
        let (worst, residual) = c
            .phi
            .iter()
            .enumerate()
            .map(|(i, v)| (i, v.abs()))
            .fold((0, 0.0), |a, b| if b.1 > a.1 { b } else { a });
        if residual <= tol || iterations == 50 || !residual.is_finite() {
            if residual > tol || !residual.is_finite() {
                return Err(AssemblyFailure {
                    row: d.info().constraints[worst].clone(),
                    residual,
                    iterations,
                });
            }
            let v = min_norm(&c.jac, &(&c.jac * DVector::from_column_slice(qd)));
            for (a, b) in qd.iter_mut().zip(v.iter()) {
                *a -= b;
            }
            let moved = q
                .iter()
                .zip(&start)
                .map(|(a, b)| (a - b) * (a - b))
                .sum::<f64>()
                .sqrt();
            return Ok(moved);
        }
        let dq = min_norm(&c.jac, &DVector::from_column_slice(&c.phi));
        for (a, b) in q.iter_mut().zip(dq.iter()) {
            *a -= b;
        }
        iterations += 1;
    }
}

/// J^T (J J^T)^+ r: the least-norm dq with J dq = r (pseudo-inverse, so
/// dependent rows do no harm).
fn min_norm(jac: &DMatrix<f64>, r: &DVector<f64>) -> DVector<f64> {
    let jjt = jac * jac.transpose();
    let scale = jjt.diagonal().max().max(f64::MIN_POSITIVE);
    let y = jjt
        .pseudo_inverse(1e-12 * scale)
        .map(|p| p * r)
        .unwrap_or_else(|_| DVector::zeros(r.len()));
    jac.transpose() * y
}

/// Groups of constraint rows that depend on each other at q: the rows that
/// carry each null vector of J^T (redundant or conflicting joints), by
/// name. Empty when J has full row rank.
pub fn dependent_rows<D: Dynamics + ?Sized>(d: &D, t: f64, q: &[f64]) -> Vec<Vec<String>> {
    let n = d.dof();
    let c = evaluate(d, t, q, &vec![0.0; n]);
    let rows = &d.info().constraints;
    let m = rows.len();
    if m == 0 {
        return Vec::new();
    }
    // Null vectors of J^T: eigenvectors of J J^T with (numerically) zero
    // eigenvalues.
    let jjt = &c.jac * c.jac.transpose();
    let eig = jjt.symmetric_eigen();
    let top = eig.eigenvalues.amax().max(f64::MIN_POSITIVE);
    let mut groups = Vec::new();
    for k in 0..m {
        if eig.eigenvalues[k] > 1e-10 * top {
            continue;
        }
        let v = eig.eigenvectors.column(k);
        let big = v.amax();
        let group: Vec<String> = (0..m)
            .filter(|&i| v[i].abs() > 1e-6 * big)
            .map(|i| rows[i].clone())
            .collect();
        groups.push(group);
    }
    groups
}

/// The joints of a set of row names (`JOINT.x` -> `JOINT`), in order.
pub fn joints_of(rows: &[String]) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for r in rows {
        let j = r
            .rsplit_once('.')
            .map_or(r.as_str(), |(j, _)| j)
            .to_string();
        if !out.contains(&j) {
            out.push(j);
        }
    }
    out
}

/// d(J^T lambda)/dq at fixed lambda (n x n): the joint forces' stiffness,
/// by central differences of the constraint kernel.
pub fn geometric_stiffness<D: Dynamics + ?Sized>(d: &D, q: &[f64], lambda: &[f64]) -> DMatrix<f64> {
    let n = q.len();
    let zeros = vec![0.0; n];
    let l = DVector::from_column_slice(lambda);
    let mut k = DMatrix::zeros(n, n);
    let mut qp = q.to_vec();
    for j in 0..n {
        let step = f64::EPSILON.cbrt() * q[j].abs().max(1.0);
        qp[j] = q[j] + step;
        let plus = evaluate(d, 0.0, &qp, &zeros).jac.transpose() * &l;
        qp[j] = q[j] - step;
        let minus = evaluate(d, 0.0, &qp, &zeros).jac.transpose() * &l;
        qp[j] = q[j];
        for i in 0..n {
            k[(i, j)] = (plus[i] - minus[i]) / (2.0 * step);
        }
    }
    k
}

/// The joint forces that hold a configuration at rest against the static
/// forces h(q, 0): the least-squares lambda of J^T lambda = -h.
pub fn static_forces<D: Dynamics + ?Sized>(d: &D, q: &[f64], h: &[f64]) -> Vec<f64> {
    let c = evaluate(d, 0.0, q, &vec![0.0; q.len()]);
    let jt = c.jac.transpose();
    let rhs = -DVector::from_column_slice(h);
    jt.svd(true, true)
        .solve(&rhs, 1e-12)
        .map(|v| v.as_slice().to_vec())
        .unwrap_or_else(|_| vec![0.0; c.phi.len()])
}

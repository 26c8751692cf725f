//! The chapter's impact stage (section 8.3): a contact of `impulse` law
//! that begins changes the velocities at once, without moving the
//! configuration,
//!
//!   qd+ = qd- - M^-1 A^T (A M^-1 A^T)^-1 (A qd- - b),
//!
//! with A the contact's rows (and the joints' rows, held at zero) and b
//! their velocities after impact: the normal velocity reversed by the
//! restitution e (frictionless), or the whole point velocity stopped (no
//! slip: the chapter's case, when the law has friction). With e = 0 the
//! contact then holds as a unilateral constraint, its rows added to the
//! joints' in the accelerations' saddle-point solve, until its normal force
//! would pull (the contact switch ends the leg there).

use super::distance::Distance;
use nalgebra::{DMatrix, DVector};
use num_dual::Dual64;

use super::{Against, ContactSet, Normal, PointKinematics};
use crate::arm::{AccelError, Dynamics};
use crate::kernels::KernelKind;

/// The rows of some pairs: A (rows x n), gamma (A' qd), and for each pair
/// its normal row.
pub struct ContactRows {
    pub jac: DMatrix<f64>,
    pub gamma: Vec<f64>,
    /// Per pair (in the order asked): its first row, the world axes its
    /// rows hold when it holds the whole point (else none: the normal
    /// alone), and its unit normal.
    pub pairs: Vec<(usize, Vec<usize>, [f64; 3])>,
    /// Per row, the relative velocity it measures now (A qd).
    pub velocity: Vec<f64>,
}

/// The pair's law holds the whole point (no slip) rather than its normal.
fn sticks(set: &ContactSet, pair: usize) -> bool {
    set.pairs[pair].law.friction > 0.0
}

/// The restitution of an impulse pair.
pub fn restitution(set: &ContactSet, pair: usize) -> Option<f64> {
    match set.pairs[pair].law.normal {
        Normal::Impulse { e } => Some(e),
        _ => None,
    }
}

/// The rows of `pairs` at (t, q, qd): the relative velocity of the point
/// and the other side (normal, or all three components), as A qd, and
/// gamma = A' qd from the `ContactJvp` kernel along qd and the turning of
/// the normal (dual numbers along the velocity).
pub fn rows<D: Dynamics + ?Sized>(
    d: &D,
    set: &ContactSet,
    t: f64,
    q: &[f64],
    qd: &[f64],
    pairs: &[usize],
) -> ContactRows {
    let n = q.len();
    let k = PointKinematics::with_jacobian(d, t, q, qd);
    let mut tangent = vec![0.0; KernelKind::ContactJvp.output_len(d.info())];
    let mut dir = vec![0.0; 2 * n];
    dir[..n].copy_from_slice(qd);
    d.eval_direction(KernelKind::ContactJvp, t, q, qd, &dir, &[], &mut tangent);
    let width = 3 + 3 * n;
    // J, J' qd of a point, and the other side's (zero for an obstacle).
    let point = |i: usize| -> (Vec<[f64; 3]>, [f64; 3]) {
        let jac = (0..n)
            .map(|j| [0, 1, 2].map(|c| k.jacobian_row(i, c)[j]))
            .collect();
        let jd = [0, 1, 2].map(|c| tangent[i * width + c]);
        (jac, jd)
    };
    let (mut rows, mut gamma, mut starts, mut velocity) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for &i in pairs {
        let pair = &set.pairs[i];
        let (ja, jda) = point(pair.point);
        let (p, v) = (k.position(pair.point), k.velocity(pair.point));
        // The relative point's J (by column), J' qd and velocity, and the
        // normal with its rate.
        let (jac, jd, v_rel, nd): (Vec<[f64; 3]>, [f64; 3], [f64; 3], [Dual64; 3]) = match pair
            .other
        {
            Against::Obstacle(o) => {
                let ob = &set.obstacles[o];
                let (offset, speed) = ob.motion.as_ref().map_or(([0.0; 3], [0.0; 3]), |m| m.at(t));
                let v_rel = [0, 1, 2].map(|c| v[c] - speed[c]);
                let pd = [0, 1, 2].map(|c| Dual64::new(p[c], v_rel[c]));
                let (_, nd) = ob.shape.distance(pd, offset);
                (ja, jda, v_rel, nd)
            }
            Against::Point(b) => {
                let (jb, jdb) = point(b);
                let (pb, vb) = (k.position(b), k.velocity(b));
                let v_rel = [0, 1, 2].map(|c| v[c] - vb[c]);
                let rel = [0, 1, 2].map(|c| Dual64::new(p[c] - pb[c], v_rel[c]));
                let nd = super::distance::unit(rel, [0.0, 0.0, 1.0]);
                let jac = ja
                    .iter()
                    .zip(&jb)
                    .map(|(a, b)| [0, 1, 2].map(|c| a[c] - b[c]))
                    .collect();
                let jd = [0, 1, 2].map(|c| jda[c] - jdb[c]);
                (jac, jd, v_rel, nd)
            }
        };
        let (normal, normal_dot) = (nd.map(|x| x.re), nd.map(|x| x.eps));
        if sticks(set, i) {
            // A direction the point cannot move in (z in the plane) is no
            // row: it would make A M^-1 A^T singular.
            let axes: Vec<usize> = (0..3)
                .filter(|&c| jac.iter().any(|col| col[c] != 0.0))
                .collect();
            starts.push((rows.len(), axes.clone(), normal));
            for c in axes {
                rows.push(jac.iter().map(|col| col[c]).collect::<Vec<f64>>());
                gamma.push(jd[c]);
                velocity.push(v_rel[c]);
            }
        } else {
            starts.push((rows.len(), Vec::new(), normal));
            rows.push(jac.iter().map(|col| dot(col, &normal)).collect());
            gamma.push(dot(&jd, &normal) + dot(&normal_dot, &v_rel));
            velocity.push(dot(&v_rel, &normal));
        }
    }
    let r = rows.len();
    let flat: Vec<f64> = rows.into_iter().flatten().collect();
    ContactRows {
        jac: DMatrix::from_row_slice(r, n, &flat),
        gamma,
        pairs: starts,
        velocity,
    }
}

fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// What an impact did: the velocities after it, and each pair's normal
/// impulse (N s, pushing out: positive).
pub struct Jump {
    pub qd: Vec<f64>,
    pub impulses: Vec<(usize, f64)>,
}

/// The velocities after the pairs `began` hit: the joints' rows kept at
/// zero velocity, each impact's as its law says.
pub fn jump<D: Dynamics + ?Sized>(
    d: &D,
    set: &ContactSet,
    t: f64,
    q: &[f64],
    qd: &[f64],
    began: &[usize],
) -> Result<Jump, AccelError> {
    let n = q.len();
    let c = rows(d, set, t, q, qd, began);
    let mut targets: Vec<f64> = Vec::with_capacity(c.velocity.len());
    for (&i, (first, axes, normal)) in began.iter().zip(&c.pairs) {
        let e = restitution(set, i).unwrap_or(0.0);
        if axes.is_empty() {
            targets.push(-e * c.velocity[*first]);
            continue;
        }
        // No slip: the normal part reversed by e, the tangential stopped.
        let v: Vec<f64> = (0..axes.len()).map(|k| c.velocity[first + k]).collect();
        let v_n: f64 = axes.iter().zip(&v).map(|(&a, v)| normal[a] * v).sum();
        targets.extend(axes.iter().map(|&a| -e * v_n * normal[a]));
    }
    let (mut a, mut b) = (c.jac, targets);
    let mut offset = 0;
    if !d.info().constraints.is_empty() {
        let joints = crate::constraints::evaluate(d, t, q, qd);
        offset = joints.jac.nrows();
        a = stack(&joints.jac, &a);
        let mut zeros = vec![0.0; joints.jac.nrows()];
        zeros.extend(b);
        b = zeros;
    }
    let mut m = DMatrix::zeros(n, n);
    d.mass(t, q, &mut m);
    let chol = m.cholesky().ok_or(AccelError::SingularMass {
        t,
        condition: f64::INFINITY,
    })?;
    let minv_at = chol.solve(&a.transpose());
    let s = &a * &minv_at;
    let qd_v = DVector::from_column_slice(qd);
    let rhs = &a * &qd_v - DVector::from_vec(b);
    let mu = s
        .clone()
        .cholesky()
        .map(|c| c.solve(&rhs))
        .or_else(|| s.pseudo_inverse(1e-12).ok().map(|p| p * &rhs))
        .ok_or(AccelError::DependentJoints { t })?;
    // The rows' impulses are -mu (qd+ = qd- + M^-1 A^T (-mu)); a pair's
    // normal impulse is its rows' along the normal.
    let impulses = began
        .iter()
        .zip(&c.pairs)
        .map(|(&i, (first, axes, normal))| {
            let row = |k: usize| -mu[offset + first + k];
            let along = if axes.is_empty() {
                row(0)
            } else {
                axes.iter()
                    .enumerate()
                    .map(|(k, &a)| row(k) * normal[a])
                    .sum()
            };
            (i, along)
        })
        .collect();
    let out = qd_v - minv_at * mu;
    Ok(Jump {
        qd: out.iter().copied().collect(),
        impulses,
    })
}

fn stack(a: &DMatrix<f64>, b: &DMatrix<f64>) -> DMatrix<f64> {
    let mut out = DMatrix::zeros(a.nrows() + b.nrows(), a.ncols());
    out.view_mut((0, 0), (a.nrows(), a.ncols())).copy_from(a);
    out.view_mut((a.nrows(), 0), (b.nrows(), b.ncols()))
        .copy_from(b);
    out
}

/// The accelerations with held contacts (and the joints): the dense
/// saddle-point solve by the Schur complement. Returns qdd and each held
/// pair's normal force (N, pushing out: positive).
pub fn held_accelerations<D: Dynamics + ?Sized>(
    d: &D,
    set: &ContactSet,
    t: f64,
    q: &[f64],
    qd: &[f64],
    held: &[usize],
) -> Result<(Vec<f64>, Vec<f64>), AccelError> {
    let n = q.len();
    let c = rows(d, set, t, q, qd, held);
    let (mut a, mut gamma) = (c.jac, c.gamma);
    let offset = if d.info().constraints.is_empty() {
        0
    } else {
        let joints = crate::constraints::evaluate(d, t, q, qd);
        let m = joints.jac.nrows();
        a = stack(&joints.jac, &a);
        let mut g = joints.gamma;
        g.extend(gamma);
        gamma = g;
        m
    };
    let mut m = DMatrix::zeros(n, n);
    let mut h = DVector::zeros(n);
    d.mass_bias(t, q, qd, &mut m, &mut h);
    let chol = m.cholesky().ok_or(AccelError::SingularMass {
        t,
        condition: f64::INFINITY,
    })?;
    let a0 = chol.solve(&(-h));
    let minv_at = chol.solve(&a.transpose());
    let s = &a * &minv_at;
    let rhs = &a * &a0 + DVector::from_vec(gamma);
    let lambda = s
        .cholesky()
        .map(|c| c.solve(&rhs))
        .ok_or(AccelError::DependentJoints { t })?;
    let qdd = a0 - minv_at * &lambda;
    // The generalised force is -A^T lambda: on a normal row the contact
    // pushes the point out with -lambda.
    let forces = c
        .pairs
        .iter()
        .map(|(r, axes, normal)| {
            let l = |k: usize| -lambda[offset + r + k];
            if axes.is_empty() {
                l(0)
            } else {
                axes.iter()
                    .enumerate()
                    .map(|(k, &a)| l(k) * normal[a])
                    .sum()
            }
        })
        .collect();
    Ok((qdd.iter().copied().collect(), forces))
}

//! A viscoelastic arm's relaxed forces in a run (`crate::relaxation`
//! says what they are): their rates, their state when relaxed, their rows
//! of the state Jacobian, and the whole state's rate.

use nalgebra::DMatrix;

use crate::arm::{AccelError, Dynamics, Workspace, accelerations};
use crate::relaxation::Relaxation;

/// x' at (t, x) = [qd, qdd, z'], x = [q, qd, z] with z the relaxed forces
/// ([`Dynamics::internal_len`] values: none for an elastic arm).
pub fn state_rate<D: Dynamics + ?Sized>(
    d: &D,
    ws: &mut Workspace,
    t: f64,
    x: &[f64],
    dx: &mut [f64],
) -> Result<(), AccelError> {
    let n = d.dof();
    let len = 2 * n + d.internal_len();
    let (q, rest) = x.split_at(n);
    let (qd, z) = (&rest[..n], &rest[n..len - n]);
    d.set_internal(z);
    dx[..n].copy_from_slice(qd);
    accelerations(d, ws, t, q, qd, &mut dx[n..2 * n])?;
    rates(d, t, q, z, &mut dx[2 * n..len]);
    Ok(())
}

/// The relaxed forces' rates z' at (t, q, z) into `dz` (z as
/// [`Dynamics::internal_len`] lays it out).
pub fn rates<D: Dynamics + ?Sized>(d: &D, t: f64, q: &[f64], z: &[f64], dz: &mut [f64]) {
    let Some(relax) = d.relaxation() else {
        return;
    };
    let n = q.len();
    let forces = group_forces(d, relax, t, q);
    for (k, (g, b)) in relax.branches().enumerate() {
        for i in 0..n {
            dz[k * n + i] = (b.ratio * forces[g][i] - z[k * n + i]) / b.time;
        }
    }
}

/// The relaxed state at q: each branch's force in equilibrium with the
/// strain held there, ratio_k f_g(q).
pub fn relaxed<D: Dynamics + ?Sized>(d: &D, t: f64, q: &[f64]) -> Vec<f64> {
    let Some(relax) = d.relaxation() else {
        return Vec::new();
    };
    let forces = group_forces(d, relax, t, q);
    (relax.branches())
        .flat_map(|(g, b)| forces[g].iter().map(move |f| b.ratio * f))
        .collect()
}

fn group_forces<D: Dynamics + ?Sized>(
    d: &D,
    relax: &Relaxation,
    t: f64,
    q: &[f64],
) -> Vec<Vec<f64>> {
    (0..relax.groups.len())
        .map(|g| {
            let mut f = vec![0.0; q.len()];
            d.group_force(t, q, g, &mut f);
            f
        })
        .collect()
}

/// The rows of the state Jacobian for z, and the columns the accelerations
/// take from z: `jac` is (2n + m) square, its [q, qd] block already in
/// place; `m_inv` is M^-1 at q.
pub fn fill_jacobian<D: Dynamics + ?Sized>(
    d: &D,
    t: f64,
    q: &[f64],
    m_inv: &DMatrix<f64>,
    jac: &mut DMatrix<f64>,
) {
    let Some(relax) = d.relaxation() else {
        return;
    };
    let n = q.len();
    let mut stiffness: Vec<Option<DMatrix<f64>>> = vec![None; relax.groups.len()];
    for (k, (g, b)) in relax.branches().enumerate() {
        let row = 2 * n + k * n;
        // qdd = M^-1 (sum_k r_k - h): each branch's block is M^-1.
        jac.view_mut((n, row), (n, n)).copy_from(m_inv);
        let kg = stiffness[g].get_or_insert_with(|| {
            let mut buf = vec![0.0; n * n];
            d.group_stiffness(t, q, g, &mut buf);
            DMatrix::from_row_slice(n, n, &buf)
        });
        jac.view_mut((row, 0), (n, n))
            .copy_from(&(&*kg * (b.ratio / b.time)));
        for i in 0..n {
            jac[(row + i, row + i)] = -1.0 / b.time;
        }
    }
}

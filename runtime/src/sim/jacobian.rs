//! The analytic Jacobian of the first-order system x = [q, qd],
//! x' = [qd, qdd(q, qd, t)]:
//!
//!   J = [[0, I], [J_q, J_qd]],  J_q = -M^-1 d tau/dq,  J_qd = -M^-1 d tau/dqd,
//!
//! tau = M qdd + h (= 0 along solutions), from the generated `Jvp` kernel's
//! directional derivatives (`Dynamics::jacobian_parts`). No finite differences: implicit
//! integrators and stiffness analysis use this. A system with joints is
//! the exception (`constrained_jacobian`).

use nalgebra::DMatrix;

use crate::arm::{AccelError, Dynamics, Workspace, accelerations};

/// J of the whole state at t, x = [q, qd] and a viscoelastic arm's
/// relaxed forces z (`crate::relaxation`, whose rows and columns it adds);
/// also returns qdd.
pub fn state_jacobian<D: Dynamics + ?Sized>(
    d: &D,
    ws: &mut Workspace,
    t: f64,
    x: &[f64],
    jac: &mut DMatrix<f64>,
) -> Result<Vec<f64>, AccelError> {
    let n = d.dof();
    if d.internal_len() == 0 {
        return rhs_jacobian(d, ws, t, x, jac);
    }
    d.set_internal(&x[2 * n..2 * n + d.internal_len()]);
    let mut top = DMatrix::zeros(2 * n, 2 * n);
    let qdd = rhs_jacobian(d, ws, t, &x[..2 * n], &mut top)?;
    jac.fill(0.0);
    jac.view_mut((0, 0), (2 * n, 2 * n)).copy_from(&top);
    let mut m = DMatrix::zeros(n, n);
    d.mass(t, &x[..n], &mut m);
    let m_inv = m.cholesky().ok_or(AccelError::SingularMass {
        t,
        condition: f64::INFINITY,
    })?;
    let m_inv = m_inv.inverse();
    crate::relaxed_forces::fill_jacobian(d, t, &x[..n], &m_inv, jac);
    Ok(qdd)
}

/// J (2n x 2n) at t, x = [q, qd] (a viscoelastic arm's relaxed forces as
/// last set); also returns qdd.
pub fn rhs_jacobian<D: Dynamics + ?Sized>(
    d: &D,
    ws: &mut Workspace,
    t: f64,
    x: &[f64],
    jac: &mut DMatrix<f64>,
) -> Result<Vec<f64>, AccelError> {
    let holds = d.contact().is_some_and(|c| !c.held_pairs().is_empty());
    if !d.info().constraints.is_empty() || holds {
        return constrained_jacobian(d, ws, t, x, jac);
    }
    let n = d.dof();
    let (q, qd) = x.split_at(n);
    let mut qdd = vec![0.0; n];
    accelerations(d, ws, t, q, qd, &mut qdd)?;
    let mut parts = vec![0.0; 2 * n * n];
    d.jacobian_parts(t, q, qd, &qdd, &mut parts);
    let dtau_dq = DMatrix::from_row_slice(n, n, &parts[..n * n]);
    let dtau_dqd = DMatrix::from_row_slice(n, n, &parts[n * n..]);
    let mut m = DMatrix::zeros(n, n);
    d.mass(t, q, &mut m);
    let chol = m.cholesky().ok_or(AccelError::SingularMass {
        t,
        condition: f64::INFINITY,
    })?;
    let jq = -chol.solve(&dtau_dq);
    let jqd = -chol.solve(&dtau_dqd);
    jac.fill(0.0);
    for i in 0..n {
        jac[(i, n + i)] = 1.0;
        for j in 0..n {
            jac[(n + i, j)] = jq[(i, j)];
            jac[(n + i, n + j)] = jqd[(i, j)];
        }
    }
    Ok(qdd)
}

/// J of a system with joints (or held contacts) by central differences of the constrained
/// accelerations: the multipliers' own dependence on the state (through J,
/// gamma and the Schur complement) has no kernel, and 4 n solves of a
/// few-dozen-coordinate assembly cost less than deriving one. Implicit
/// methods reuse J across steps, so this is off the hot path.
fn constrained_jacobian<D: Dynamics + ?Sized>(
    d: &D,
    ws: &mut Workspace,
    t: f64,
    x: &[f64],
    jac: &mut DMatrix<f64>,
) -> Result<Vec<f64>, AccelError> {
    let n = d.dof();
    let mut qdd = vec![0.0; n];
    accelerations(d, ws, t, &x[..n], &x[n..2 * n], &mut qdd)?;
    let (mut xp, mut plus, mut minus) = (x[..2 * n].to_vec(), vec![0.0; n], vec![0.0; n]);
    jac.fill(0.0);
    for i in 0..n {
        jac[(i, n + i)] = 1.0;
    }
    for j in 0..2 * n {
        let step = f64::EPSILON.cbrt() * x[j].abs().max(1.0);
        xp[j] = x[j] + step;
        accelerations(d, ws, t, &xp[..n], &xp[n..], &mut plus)?;
        xp[j] = x[j] - step;
        accelerations(d, ws, t, &xp[..n], &xp[n..], &mut minus)?;
        xp[j] = x[j];
        for i in 0..n {
            jac[(n + i, j)] = (plus[i] - minus[i]) / (2.0 * step);
        }
    }
    Ok(qdd)
}

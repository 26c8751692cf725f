//! The analytic Jacobian of the first-order system x = [q, qd],
//! x' = [qd, qdd(q, qd, t)]:
//!
//!   J = [[0, I], [J_q, J_qd]],  J_q = -M^-1 d tau/dq,  J_qd = -M^-1 d tau/dqd,
//!
//! tau = M qdd + h (= 0 along solutions), from the generated `Jvp` kernel's
//! directional derivatives (`Dynamics::jacobian_parts`). No finite differences: implicit
//! integrators and stiffness analysis use this.

use nalgebra::DMatrix;

use crate::arm::{AccelError, Dynamics, Workspace, accelerations};

/// J (2n x 2n) at t, x = [q, qd]; also returns qdd.
pub fn rhs_jacobian<D: Dynamics + ?Sized>(
    d: &D,
    ws: &mut Workspace,
    t: f64,
    x: &[f64],
    jac: &mut DMatrix<f64>,
) -> Result<Vec<f64>, AccelError> {
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

//! TMT assembly (DESIGN.md section 2):
//!
//!   T_i = [dv_i/dqd ; dw_i/dqd],  M = sum_i T_i^T Mbar_i T_i,
//!   h = sum_i T_i^T (Mbar_i a_i + [0; w_i x I_i w_i] - [m_i g; 0])
//!       + dV_e/dq + dR/dqd - sum_f J_f^T F_f,
//!
//! with v_i and the convective accelerations a_i = (d/dt T_i) qd taken as
//! symbolic time derivatives (qdd = 0) of the positions and angular velocities.

use crate::cas::{Cas, ExprId};

use super::system::System;

/// The derived equations, as expressions.
pub struct Equations {
    /// Upper triangle of M, row by row.
    pub mass_upper: Vec<ExprId>,
    pub bias: Vec<ExprId>,
    /// tip x, y, z, kinetic energy, potential energy.
    pub outputs: Vec<ExprId>,
}

fn cross(cas: &mut Cas, a: &[ExprId; 3], b: &[ExprId; 3]) -> [ExprId; 3] {
    let mut c = [a[0]; 3];
    for (k, ck) in c.iter_mut().enumerate() {
        let (i, j) = ((k + 1) % 3, (k + 2) % 3);
        let p = cas.mul(a[i], b[j]);
        let m = cas.mul(a[j], b[i]);
        *ck = cas.sub(p, m);
    }
    c
}

pub fn assemble(cas: &mut Cas, sys: &System) -> Equations {
    let n = sys.coords.len();
    let pairs = sys.coords.rate_pairs();

    // Velocities and convective accelerations, one memo per batch so the
    // chain structure is shared between bodies.
    let positions: Vec<ExprId> = sys.bodies.iter().flat_map(|b| b.position).collect();
    let velocities = cas.time_derivatives(&positions, &pairs);
    let conv_lin = cas.time_derivatives(&velocities, &pairs);
    let omegas: Vec<ExprId> = sys.bodies.iter().flat_map(|b| b.omega).collect();
    let conv_ang = cas.time_derivatives(&omegas, &pairs);

    let zero = cas.zero();
    let mut mass = vec![zero; n * (n + 1) / 2];
    let mut bias_terms: Vec<Vec<ExprId>> = vec![Vec::new(); n];
    let mut kinetic = Vec::new();
    let mut gravity_pe = Vec::new();

    for (b, body) in sys.bodies.iter().enumerate() {
        let v: [ExprId; 3] = velocities[3 * b..3 * b + 3].try_into().unwrap();
        let a: [ExprId; 3] = conv_lin[3 * b..3 * b + 3].try_into().unwrap();
        let alpha: [ExprId; 3] = conv_ang[3 * b..3 * b + 3].try_into().unwrap();
        let w = body.omega;
        let inertia = body.inertia;

        // Columns of T for this body.
        let tv: Vec<[ExprId; 3]> = sys
            .coords
            .qd
            .iter()
            .map(|&qd| v.map(|vk| cas.diff(vk, qd)))
            .collect();
        let tw: Vec<[ExprId; 3]> = sys
            .coords
            .qd
            .iter()
            .map(|&qd| w.map(|wk| cas.diff(wk, qd)))
            .collect();
        let zero_col = |c: &[ExprId; 3], cas: &Cas| c.iter().all(|&e| cas.is_zero(e));
        let active: Vec<usize> = (0..n)
            .filter(|&i| !zero_col(&tv[i], cas) || !zero_col(&tw[i], cas))
            .collect();

        // Mass matrix contribution Tv_i . (m Tv_j) + Tw_i . (I Tw_j): the
        // weighted columns are formed once per body, not once per pair.
        let weighted: Vec<([ExprId; 3], [ExprId; 3])> = (0..n)
            .map(|j| {
                let mv = tv[j].map(|e| cas.mul(body.mass, e));
                let iw: [ExprId; 3] = std::array::from_fn(|k| cas.mul(inertia[k], tw[j][k]));
                (mv.map(|e| cas.bind(e)), iw)
            })
            .collect();
        for (ai, &i) in active.iter().enumerate() {
            for &j in &active[ai..] {
                let lin = cas.dot(&tv[i], &weighted[j].0);
                let ang = cas.dot(&tw[i], &weighted[j].1);
                let k = i * n - i * (i + 1) / 2 + j;
                mass[k] = cas.add_all(&[mass[k], lin, ang]);
            }
        }

        // Generalised bias force of this body.
        // Linear: m a - m g.  Angular: I alpha + w x (I w).
        let lin_force: [ExprId; 3] = std::array::from_fn(|k| {
            let d = cas.sub(a[k], sys.gravity[k]);
            cas.mul(body.mass, d)
        });
        let iw: [ExprId; 3] = std::array::from_fn(|k| cas.mul(inertia[k], w[k]));
        let gyro = cross(cas, &w, &iw);
        let ang_force: [ExprId; 3] = std::array::from_fn(|k| {
            let ia = cas.mul(inertia[k], alpha[k]);
            cas.add(ia, gyro[k])
        });
        let lin_force = lin_force.map(|e| cas.bind(e));
        let ang_force = ang_force.map(|e| cas.bind(e));
        for &i in &active {
            let l = cas.dot(&tv[i], &lin_force);
            let r = cas.dot(&tw[i], &ang_force);
            bias_terms[i].push(l);
            bias_terms[i].push(r);
        }

        // Energies.
        let vv = cas.dot(&v, &v);
        let lin_ke = cas.mul(body.mass, vv);
        let ang_ke = cas.dot(&iw, &w);
        let ke = cas.add(lin_ke, ang_ke);
        kinetic.push(cas.scaled(0.5, ke));
        let gr = cas.dot(&sys.gravity, &body.position);
        let pe = cas.mul(body.mass, gr);
        gravity_pe.push(cas.neg(pe));
    }

    // Elastic, dissipative and applied forces.
    let mut potential = gravity_pe;
    potential.push(sys.elastic);
    for i in 0..n {
        let de = cas.diff(sys.elastic, sys.coords.q[i]);
        let dr = cas.diff(sys.rayleigh, sys.coords.qd[i]);
        bias_terms[i].push(de);
        bias_terms[i].push(dr);
    }
    for f in &sys.point_forces {
        for i in 0..n {
            let j = f.point.map(|p| cas.diff(p, sys.coords.q[i]));
            let work = cas.dot(&j, &f.force);
            bias_terms[i].push(cas.neg(work));
        }
        let fp = cas.dot(&f.force, &f.point);
        potential.push(cas.neg(fp));
    }

    let bias = bias_terms.iter().map(|t| cas.add_all(t)).collect();
    let ke = cas.add_all(&kinetic);
    let pe = cas.add_all(&potential);
    let outputs = vec![sys.tip[0], sys.tip[1], sys.tip[2], ke, pe];
    Equations {
        mass_upper: mass,
        bias,
        outputs,
    }
}

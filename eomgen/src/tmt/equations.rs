//! TMT assembly (docs/design.md section 2):
//!
//!   M = sum_i T_i^T Mbar_i T_i,
//!   h = sum_i T_i^T (Mbar_i a_i + [0; w_i x I_i w_i] - [m_i g; 0])
//!       + dV_e/dq + dR/dqd - sum_f J_f^T F_f,
//!
//! with T_i = [dv_i/dqd ; dw_i/dqd], the velocities v_i the symbolic time
//! derivatives of the positions, and the convective accelerations
//! a_i = (d/dt T_i) qd their time derivatives at qdd = 0.
//!
//! The transpose products are vector-Jacobian products (`Cas::vjp`) rather
//! than explicit columns of T: h in O(n) operations for a chain, and
//! M = d/dqd (sum_i T_i^T Mbar_i T_i qd), the Jacobian of the generalised
//! momentum, in O(n^2) (the composite-body recursion falls out of the
//! reverse sweep). The matrix is the same; only the order of evaluation
//! differs.
//!
//! A lumped body whose inertia changes with the configuration (a bent pcc
//! element) gets the exact Lagrangian terms T_w^T (dI/dt w) - (1/2) w^T
//! (dI/dq) w on top; for rigid bodies they fold to zero.
//!
//! The Jacobians come from one kernel: the directional derivative of the
//! inverse dynamics tau = M qdd + h along (dq, dqd) (`jvp`). The runtime
//! takes the right-hand side's Jacobian and the static stiffness
//! K = d h(q, 0) / dq (= d tau / dq at qd = qdd = 0: the inertial and
//! damping forces vanish there to first order) from its columns.

use runtime::output;

use crate::cas::{Cas, ExprId, SymKind, Variables};

use super::chain::{ChainKinematics, MomentItem, PointItem};
use super::system::System;

/// The derived equations, as expressions.
pub struct Equations {
    /// Upper triangle of M, row by row.
    pub mass_upper: Vec<ExprId>,
    pub bias: Vec<ExprId>,
    /// tip x, y, z, kinetic energy, potential energy, tip quaternion.
    pub outputs: Vec<ExprId>,
    /// d tau along the direction (dq, dqd) (`SymKind::Dir` symbols),
    /// tau = M qdd + h: n values.
    pub jvp: Vec<ExprId>,
}

fn triple(v: &[ExprId], i: usize) -> [ExprId; 3] {
    [v[3 * i], v[3 * i + 1], v[3 * i + 2]]
}

pub fn assemble(cas: &mut Cas, sys: &System) -> Equations {
    let n = sys.coords.len();
    let nb = sys.bodies.len();
    let mut pairs = sys.coords.rate_pairs();
    pairs.extend(&sys.seeds);

    // Velocities (bodies, then force points) and convective accelerations;
    // one memo per batch, so chains are shared between bodies.
    let mut points: Vec<ExprId> = sys.bodies.iter().flat_map(|b| b.position).collect();
    points.extend(sys.point_forces.iter().flat_map(|f| f.point));
    let n_points = points.len();
    if let Some(chain) = &sys.chain {
        points.extend(chain.links.iter().flat_map(|l| l.end));
    }
    let all_velocities = cas.kinematic_rates(&points, &pairs);
    let (velocities, link_velocities) = all_velocities.split_at(n_points);
    let conv_lin = cas.kinematic_rates(&velocities[..3 * nb], &pairs);
    let omegas: Vec<ExprId> = sys.bodies.iter().flat_map(|b| b.omega).collect();
    let conv_ang = cas.kinematic_rates(&omegas, &pairs);

    // The velocity outputs whose Jacobian in qd is T.
    let mut outs: Vec<ExprId> = velocities[..3 * nb].to_vec();
    outs.extend(&omegas);
    let mut momentum_cot = Vec::with_capacity(outs.len());
    let mut force_cot = Vec::with_capacity(outs.len() + 3 * sys.point_forces.len());
    for (b, body) in sys.bodies.iter().enumerate() {
        let (v, a) = (triple(velocities, b), triple(&conv_lin, b));
        for k in 0..3 {
            momentum_cot.push(cas.mul(body.mass, v[k]));
            let d = cas.sub(a[k], sys.gravity[k]);
            force_cot.push(cas.mul(body.mass, d));
        }
    }
    let mut angular_force = Vec::new();
    let mut inertia_rate_force = Vec::new(); // -(1/2) w^T (dJ/dq)_shape w, per coordinate
    for (b, body) in sys.bodies.iter().enumerate() {
        let (w, alpha) = (body.omega, triple(&conv_ang, b));
        let iw = body.inertia.apply(cas, &w);
        let ia = body.inertia.apply(cas, &alpha);
        let gyro = body.inertia.gyroscopic(cas, &w);
        let id = body.inertia.shape_rate(cas, &pairs, &w);
        for k in 0..3 {
            momentum_cot.push(iw[k]);
            angular_force.push(cas.add_all(&[ia[k], gyro[k], id[k]]));
        }
        inertia_rate_force.push(body.inertia.shape_force(cas, &w, &sys.coords.q));
    }
    force_cot.extend(angular_force);
    for (f, force) in sys.point_forces.iter().enumerate() {
        let v = triple(velocities, nb + f);
        outs.extend(v);
        force_cot.extend(force.force.map(|c| cas.neg(c)));
    }
    for moment in &sys.moments {
        outs.extend(moment.omega);
        force_cot.extend(moment.moment.map(|c| cas.neg(c)));
    }

    // M: by composite bodies for a chain, else the Jacobian of the
    // generalised momentum T^T Mbar T qd (which the Jvp kernel needs
    // anyway).
    let momentum = cas.vjp(&outs[..6 * nb], &momentum_cot, &sys.coords.qd);
    let kinematics = sys
        .chain
        .as_ref()
        .map(|chain| ChainKinematics::new(cas, sys, chain, velocities, link_velocities));
    let mass = match &kinematics {
        Some(k) => k.mass(cas),
        None => mass_by_bodies(cas, sys, velocities),
    };

    // h: inertial, gravity and applied forces by one transpose product,
    // then the elastic and dissipative forces.
    let forces = match (&kinematics, &sys.chain) {
        (Some(k), Some(chain)) => {
            let body_forces: Vec<([ExprId; 3], [ExprId; 3])> = (0..nb)
                .map(|b| (triple(&force_cot, b), triple(&force_cot, nb + b)))
                .collect();
            let points: Vec<PointItem> = sys
                .point_forces
                .iter()
                .enumerate()
                .map(|(f, force)| PointItem {
                    link: chain.point_force_link[f],
                    position: force.point,
                    velocity: triple(velocities, nb + f),
                    force: triple(&force_cot, 2 * nb + f),
                })
                .collect();
            let moments: Vec<MomentItem> = sys
                .moments
                .iter()
                .enumerate()
                .map(|(i, m)| MomentItem {
                    link: chain.moment_link[i].0,
                    omega: chain.moment_link[i].1.then_some(m.omega),
                    moment: m.moment.map(|c| cas.neg(c)),
                })
                .collect();
            k.generalized_forces(cas, &body_forces, &points, &moments)
        }
        _ => cas.vjp(&outs, &force_cot, &sys.coords.qd),
    };
    // Elastic and actuator potentials act alike on the coordinates.
    let stored = cas.add(sys.elastic, sys.actuation);
    let bias: Vec<ExprId> = (0..n)
        .map(|i| {
            let de = cas.diff(stored, sys.coords.q[i]);
            let dr = cas.diff(sys.rayleigh, sys.coords.qd[i]);
            let mut terms = vec![forces[i], de, dr];
            terms.extend(inertia_rate_force.iter().map(|f| f[i]));
            cas.add_all(&terms)
        })
        .collect();

    let outputs = energy_outputs(cas, sys, velocities, &momentum_cot);
    let jvp = jacobian_parts(cas, sys, &momentum, &bias);
    Equations {
        mass_upper: mass,
        bias,
        outputs,
        jvp,
    }
}

/// M body by body from the columns of T: sum_b m v_bi . v_bj + w_bi^T J_b
/// w_bj (differentiating the momentum instead costs a derivative of the
/// whole reverse sweep per entry); entries whose columns vanish skipped.
fn mass_by_bodies(cas: &mut Cas, sys: &System, velocities: &[ExprId]) -> Vec<ExprId> {
    let (n, nb) = (sys.coords.len(), sys.bodies.len());
    let zero = cas.zero();
    let columns: Vec<Vec<([ExprId; 3], [ExprId; 3])>> = (0..nb)
        .map(|b| {
            let v = triple(velocities, b);
            let w = sys.bodies[b].omega;
            sys.coords
                .qd
                .iter()
                .map(|&qd| (v.map(|e| cas.diff(e, qd)), w.map(|e| cas.diff(e, qd))))
                .collect()
        })
        .collect();
    let mut mass = Vec::with_capacity(n * (n + 1) / 2);
    for i in 0..n {
        for j in i..n {
            let mut terms = Vec::new();
            for (b, body) in sys.bodies.iter().enumerate() {
                let ((vi, wi), (vj, wj)) = (columns[b][i], columns[b][j]);
                let none = |v: &[ExprId; 3], w: &[ExprId; 3]| v.iter().chain(w).all(|&e| e == zero);
                if none(&vi, &wi) || none(&vj, &wj) {
                    continue;
                }
                let vv = cas.dot(&vi, &vj);
                terms.push(cas.mul(body.mass, vv));
                terms.push(body.inertia.quadratic(cas, &wi, &wj));
            }
            mass.push(cas.add_all(&terms));
        }
    }
    mass
}

/// The outputs: tip position, kinetic and potential energy, tip
/// orientation.
fn energy_outputs(
    cas: &mut Cas,
    sys: &System,
    velocities: &[ExprId],
    momentum_cot: &[ExprId],
) -> Vec<ExprId> {
    let nb = sys.bodies.len();
    // Energies: KE = (v . m v + w . I w) / 2 = qd . momentum / 2 would hide
    // the bodies; sum them directly.
    let mut kinetic = Vec::new();
    let mut potential = vec![sys.elastic];
    for (b, body) in sys.bodies.iter().enumerate() {
        let v = triple(velocities, b);
        let mv = triple(momentum_cot, b);
        let iw = triple(momentum_cot, nb + b);
        let lin = cas.dot(&v, &mv);
        let ang = cas.dot(&body.omega, &iw);
        let ke = cas.add(lin, ang);
        kinetic.push(cas.scaled(0.5, ke));
        let gr = cas.dot(&sys.gravity, &body.position);
        let pe = cas.mul(body.mass, gr);
        potential.push(cas.neg(pe));
    }
    // A constant force has the potential -F . p; a follower force (turning
    // with the tip) has none.
    for f in &sys.point_forces {
        if f.force.iter().any(|&c| cas.variables(c) != Variables::None) {
            continue;
        }
        let fp = cas.dot(&f.force, &f.point);
        potential.push(cas.neg(fp));
    }
    let ke = cas.add_all(&kinetic);
    let pe = cas.add_all(&potential);
    let mut outputs = vec![ke; output::COUNT];
    outputs[output::TIP].copy_from_slice(&sys.tip);
    outputs[output::KINETIC] = ke;
    outputs[output::POTENTIAL] = pe;
    outputs[output::ORIENTATION].copy_from_slice(&sys.tip_orientation);
    outputs
}

/// The `Jvp` kernel's outputs: d tau = dh/dq dq + dh/dqd dqd + d(M qdd)/dq
/// dq, one directional derivative (the runtime takes the Jacobian's columns
/// along unit directions), not n^2 partials.
fn jacobian_parts(
    cas: &mut Cas,
    sys: &System,
    momentum: &[ExprId],
    bias: &[ExprId],
) -> Vec<ExprId> {
    let n = sys.coords.len();
    // Jacobian parts. M qdd is the derivative of the momentum along qdd in
    // qd-space: one directional derivative, shared structure.
    let accel_pairs: Vec<(ExprId, ExprId)> = sys
        .coords
        .qd
        .iter()
        .copied()
        .zip(sys.coords.qdd.iter().copied())
        .collect();
    let m_qdd = cas.time_derivatives(momentum, &accel_pairs);
    // One directional derivative each, not n^2 partials: the runtime takes
    // the Jacobian's columns along unit directions.
    let names = &sys.coords.names;
    let dq: Vec<ExprId> = (0..n)
        .map(|i| cas.symbol(&format!("{}_dir", names[i]), SymKind::Dir(i as u32)))
        .collect();
    let dqd: Vec<ExprId> = (0..n)
        .map(|i| {
            let k = (n + i) as u32;
            cas.symbol(&format!("{}_dot_dir", names[i]), SymKind::Dir(k))
        })
        .collect();
    let along_q: Vec<(ExprId, ExprId)> = sys.coords.q.iter().copied().zip(dq).collect();
    let mut along_both = along_q.clone();
    along_both.extend(sys.coords.qd.iter().copied().zip(dqd));
    let dh = cas.time_derivatives(bias, &along_both);
    let dmq = cas.time_derivatives(&m_qdd, &along_q);
    dh.into_iter()
        .zip(dmq)
        .map(|(a, b)| cas.add(a, b))
        .collect()
}

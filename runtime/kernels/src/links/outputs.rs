//! The `Outputs` of a link chain (tip position, kinetic and potential
//! energy, tip orientation) by one sweep out over the links' *pose cells*:
//! the world frame composed link by link, as `mass_bias` does, with each
//! link's quaternion composed alongside its rotation and its body's
//! energies summed. The flat `Outputs` kernel of a chain of shared
//! coordinates (rom) sums every body's velocity over all coordinates, its
//! size the slices times the coordinates; this is one pose cell per
//! distinct cell.

use super::{
    CELL_PARAMS, Cells, LinkLayout, M3, MAX_LINK_DOF, V3, add, cell_params, cross, dot, local,
    mat_mat, mat_vec, pose, scale,
};
use crate::output;
use crate::rotation::quat_mul;

/// Kinetic energy of a body of mass m, moving at (v, w), its inertia
/// `lateral` normal to `axis` and `axial` about it, and `extra` more
/// about a y axis of its own where its section bends unequally.
fn kinetic(
    m: f64,
    (lateral, axial, axis): (f64, f64, V3),
    extra: Option<(f64, V3)>,
    v: V3,
    w: V3,
) -> f64 {
    let aw = dot(axis, w);
    let iw = add(scale(lateral, w), scale((axial - lateral) * aw, axis));
    let more = extra.map_or(0.0, |(extra, y)| extra * dot(y, w) * dot(y, w));
    0.5 * (m * dot(v, v) + dot(w, iw) + more)
}

/// The outputs (`runtime::OUTPUT_NAMES`: tip x, y, z, kinetic energy,
/// potential energy, tip quaternion w, x, y, z) of a chain the link
/// recursion covers, into `out`. The potential energy is gravity's, the
/// springs' (the actuators' work is not stored energy) and a world-frame
/// tip force's -F . p (and a load's along the arm); a force turning with
/// the tip has none.
pub fn outputs<C: Cells>(
    layout: &LinkLayout,
    cells: &mut C,
    q: &[f64],
    qd: &[f64],
    p: &[f64],
    out: &mut [f64],
) {
    let gravity: V3 = layout.gravity.map(|i| p[i]);
    let (mut r, mut quat) = super::base_orientation(layout, p);
    let (mut pos, mut v, _) = super::base_motion(layout, p);
    let mut omega = super::base_rates(layout, p).0;
    let (mut ke, mut pe) = (0.0, 0.0);
    let mut params: Vec<[f64; CELL_PARAMS]> = Vec::new();
    cell_params(layout, cells, p, &mut params);
    let mut o = [0.0; pose::PRINCIPAL_LEN];
    for (spec, params) in layout.links.iter().zip(&params) {
        let nc = spec.map.len();
        debug_assert!(nc <= MAX_LINK_DOF);
        let (x, xd) = (local(spec, p, q), local(spec, p, qd));
        let len = match spec.principal {
            Some(_) => pose::PRINCIPAL_LEN,
            None => pose::LEN,
        };
        cells.pose(spec.cell, &x[..nc], &xd[..nc], params, &mut o[..len]);
        let v3 = |i: usize| [o[i], o[i + 1], o[i + 2]];
        let rel: M3 = std::array::from_fn(|i| v3(pose::ROTATION + 3 * i));
        let turn = |at: usize| mat_vec(&r, v3(at));
        let (d, dd, w_rel) = (turn(pose::END), turn(pose::END_RATE), turn(pose::OMEGA));
        let (cen, cend) = (turn(pose::CENTROID), turn(pose::CENTROID_RATE));
        let (w_b, axis) = (turn(pose::BODY_OMEGA), turn(pose::AXIS));
        let m = o[pose::MASS];
        let body_v = add(add(v, cross(omega, cen)), cend);
        let body_w = add(omega, w_b);
        let extra = (spec.principal.is_some())
            .then(|| (o[pose::LATERAL_Y] - o[pose::LATERAL], turn(pose::Y_AXIS)));
        let rotary = (o[pose::LATERAL], o[pose::AXIAL], axis);
        ke += kinetic(m, rotary, extra, body_v, body_w);
        // Weight, less an immersed body's buoyancy.
        let g = super::link_gravity(layout, spec, p, gravity);
        pe += o[pose::ENERGY] - m * dot(g, add(pos, cen));
        v = add(add(v, cross(omega, d)), dd);
        omega = add(omega, w_rel);
        pos = add(pos, d);
        r = mat_mat(&r, &rel);
        quat = quat_mul(quat, std::array::from_fn(|k| o[pose::QUAT + k]));
    }
    let axis = [r[0][0], r[1][0], r[2][0]];
    let length = layout.tip_length.map_or(0.0, |i| p[i]);
    if let Some(m) = layout.tip_mass.map(|i| p[i]) {
        let offset = scale(0.5 * length, axis);
        let (lateral, axial) = layout.tip_inertia.map_or((0.0, 0.0), |[l, a]| (p[l], p[a]));
        let v_c = add(v, cross(omega, offset));
        ke += kinetic(m, (lateral, axial, axis), None, v_c, omega);
        pe -= m * dot(gravity, add(pos, offset));
    }
    // The tip point: the far end of a tip body with a length.
    let point = add(pos, scale(length, axis));
    if let (Some(f), false) = (layout.tip_force, layout.tip_frame) {
        pe -= dot(f.map(|i| p[i]), point);
    }
    if layout.forces {
        pe += cells.energy();
    }
    if !layout.along.is_empty() {
        pe += super::loads_potential(layout, cells, (q, qd, p));
    }
    out[output::TIP].copy_from_slice(&point);
    out[output::KINETIC] = ke;
    out[output::POTENTIAL] = pe;
    out[output::ORIENTATION].copy_from_slice(&quat);
}

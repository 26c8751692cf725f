//! The inverse dynamics of a link chain, tau(q, qd, qdd) = M qdd + h, and
//! its directional derivative along (dq, dqd), in dual numbers through the
//! cells.
//!
//! One sweep out (each link's frame, velocity and acceleration, qdd
//! included, its body's inertial and gravity forces) and one back (the
//! wrench past each link projected on its coordinates' twists): Newton-Euler
//! in the world frame, the same sums `mass_bias_owned` and
//! `mass_bias_shared` make, in O(links). Each cell's *tangent* kernel gives
//! its outputs with their derivatives along the cell coordinates' (dx, dxd),
//! and every value of the recursion carries its derivative with it. The
//! right-hand side's Jacobian is 2n such sweeps and the static stiffness n;
//! the generated code holds one tangent kernel per distinct cell instead of
//! an unrolled Jacobian of the whole arm (which grew with arm length times
//! coordinates).

use super::num::{Num, add, cell_v3, cross, dot, mat_mat, mat_vec, scale, sub};
use super::{Cells, LinkLayout, MAX_LINK_DOF, cell, local};
use crate::dual::Dual;

type V3 = [Dual; 3];
type M3 = [[Dual; 3]; 3];
const V0: V3 = [Dual::ZERO; 3];

/// A body's rotary inertia applied to a vector, as `links::Rotary`'s:
/// lateral 1 + (axial - lateral) a a^T, and `extra` y y^T more about
/// its y axis for a section that bends unequally.
#[inline(always)]
fn apply_body(lateral: Dual, axial: Dual, axis: V3, extra: Option<(Dual, V3)>, w: V3) -> V3 {
    let j = add(
        scale(lateral, w),
        scale((axial - lateral) * dot(axis, w), axis),
    );
    match extra {
        Some((extra, y)) => add(j, scale(extra * dot(y, w), y)),
        None => j,
    }
}
/// The rate of a point at `r` of a frame moving with (w, alpha) and origin
/// acceleration `a`, plus its own motion in the frame (`rate`, `accel`):
/// a + alpha x r + w x (w x r) + 2 w x rate + accel.
#[inline(always)]
fn point_accel(a: V3, alpha: V3, w: V3, r: V3, rate: V3, accel: V3) -> V3 {
    let two = Dual::constant(2.0);
    add(
        add(add(a, cross(alpha, r)), cross(w, cross(w, r))),
        add(scale(two, cross(w, rate)), accel),
    )
}

/// What the sweep back needs of a link: its body's centroid, force and
/// torque; per cell coordinate the twist it gives the links past, the
/// velocity it gives the body, its elastic and dissipative force.
struct LinkForces {
    centroid: V3,
    force: V3,
    torque: V3,
    twist: [(V3, V3); MAX_LINK_DOF],
    own: [(V3, V3); MAX_LINK_DOF],
    local_force: [Dual; MAX_LINK_DOF],
}

/// The frame a link starts from: rotation, origin, angular velocity and
/// acceleration, origin acceleration.
struct Frame {
    r: M3,
    pos: V3,
    omega: V3,
    alpha: V3,
    acc: V3,
}

/// tau = M qdd + h of a chain the link recursion covers into `tau`, and
/// its directional derivative along `dir` = (dq, dqd) into `dtau` (n
/// values each): the `Jvp` kernel of compiled chains. Shared coordinates
/// (rom slices) and the non-local forces are handled as
/// `mass_bias_shared` handles them.
/// Always inlined: a compiled model's kernel calls it from a function
/// built for FMA (`mul_add` elsewhere is a library call).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn inverse_dynamics_tangent<C: Cells>(
    layout: &LinkLayout,
    cells: &mut C,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    dir: &[f64],
    p: &[f64],
    tau: &mut [f64],
    dtau: &mut [f64],
) {
    let n = layout.dof;
    assert!(q.len() == n && qd.len() == n && qdd.len() == n && dir.len() == 2 * n);
    assert!(layout.links.iter().all(|l| l.map.len() <= MAX_LINK_DOF));
    let (dq, dqd) = dir.split_at(n);
    let gravity: V3 = super::felt_gravity(layout, p).map(Dual::constant);
    let base = super::base_orientation(layout, p).0;
    let (omega, alpha) = super::base_rates(layout, p);
    let mut frame = Frame {
        r: base.map(|row| row.map(Dual::constant)),
        pos: super::base_motion(layout, p).0.map(Dual::constant),
        omega: omega.map(Dual::constant),
        alpha: alpha.map(Dual::constant),
        acc: V0,
    };
    let mut params = Vec::new();
    super::cell_params(layout, cells, p, &mut params);
    let mut links = Vec::with_capacity(layout.links.len());
    let mut out = vec![0.0; 2 * cell::len_of(MAX_LINK_DOF, true)];
    for (spec, params) in layout.links.iter().zip(&params) {
        let nc = spec.map.len();
        let [x, xd, xdd, dx, dxd] = [q, qd, qdd, dq, dqd].map(|v| local(spec, p, v));
        let len = spec.cell_len();
        let (x, xd, dx, dxd) = (&x[..nc], &xd[..nc], &dx[..nc], &dxd[..nc]);
        let out = &mut out[..2 * len];
        if dx.iter().chain(dxd).all(|&v| v == 0.0) {
            // The direction does not move this link's coordinates.
            cells.one(spec.cell, x, xd, params, &mut out[..len]);
            out[len..].fill(0.0);
        } else {
            cells.tangent(spec.cell, x, xd, dx, dxd, params, out);
        }
        let xd: [Dual; MAX_LINK_DOF] = std::array::from_fn(|f| Dual {
            v: xd.get(f).copied().unwrap_or(0.0),
            d: dxd.get(f).copied().unwrap_or(0.0),
        });
        let inertia_rates = layout.variable_inertia.then_some(&xd);
        let felt = super::link_gravity(layout, spec, p, gravity.map(|g| g.v));
        links.push(link_forward(
            &mut frame,
            out,
            (nc, spec.principal.is_some()),
            &xdd,
            inertia_rates,
            felt.map(Dual::constant),
        ));
    }
    let mut wrench = tip_wrench(layout, &frame, p, gravity);

    let mut t = vec![Dual::ZERO; n];
    for (k, spec) in layout.links.iter().enumerate().rev() {
        let l = &links[k];
        for (f, c) in spec.map.iter().enumerate() {
            let (tw, tv) = l.twist[f];
            let (ow, ov) = l.own[f];
            let g = dot(tw, wrench.0)
                + dot(tv, wrench.1)
                + dot(ov, l.force)
                + dot(ow, l.torque)
                + l.local_force[f];
            let sc = c.scale.map_or(1.0, |i| p[i]);
            for &(a, w) in &c.terms {
                t[a] = t[a] + Dual::constant(sc * w) * g;
            }
        }
        wrench = (
            add(wrench.0, add(l.torque, cross(l.centroid, l.force))),
            add(wrench.1, l.force),
        );
    }
    for i in 0..n {
        tau[i] = t[i].v;
        dtau[i] = t[i].d;
    }
    if layout.forces {
        let mut f = vec![0.0; 2 * n];
        cells.forces_tangent(dir, &mut f);
        for i in 0..n {
            tau[i] += f[i];
            dtau[i] += f[n + i];
        }
    }
    if layout.loaded() {
        super::subtract_loads_tangent(layout, cells, (q, qd, p), (dq, dqd), (tau, dtau));
    }
}

/// One link of the sweep out: its cell's outputs (`out`: values, then
/// derivatives) under `frame`, its coordinates' accelerations `xdd` added to
/// the cell's convective ones; `frame` becomes the link's end frame.
#[inline(always)]
fn link_forward(
    frame: &mut Frame,
    out: &[f64],
    (nc, principal): (usize, bool),
    xdd: &[f64; MAX_LINK_DOF],
    inertia_rates: Option<&[Dual; MAX_LINK_DOF]>,
    gravity: V3,
) -> LinkForces {
    let len = cell::len_of(nc, principal);
    let o = |i: usize| <Dual as Num>::of_cell(out, len, i);
    let v3 = |i: usize| cell_v3(out, len, i);
    let rel: M3 = std::array::from_fn(|i| v3(cell::ROTATION + 3 * i));
    let Frame {
        r,
        pos,
        omega,
        alpha,
        acc,
    } = *frame;
    let turn = |at: usize| mat_vec(&r, cell_v3(out, len, at));
    let (d, dd) = (turn(cell::END), turn(cell::END_RATE));
    let (cen, cend) = (turn(cell::CENTROID), turn(cell::CENTROID_RATE));
    let (w_rel, w_b) = (turn(cell::OMEGA), turn(cell::BODY_OMEGA));
    let axis = turn(cell::AXIS);
    let (m, lateral, axial) = (o(cell::MASS), o(cell::LATERAL), o(cell::AXIAL));
    let y = cell::len(nc);
    let extra = principal.then(|| (o(y + 3) - lateral, turn(y)));
    // Convective accelerations (the cell's, at qdd = 0), then each cell
    // coordinate's acceleration along its columns.
    let (mut ddd, mut w_rel_d) = (turn(cell::END_ACCEL), turn(cell::OMEGA_RATE));
    let (mut cendd, mut w_b_d) = (turn(cell::CENTROID_ACCEL), turn(cell::BODY_OMEGA_RATE));
    let end = add(pos, d);
    let mut twist = [(V0, V0); MAX_LINK_DOF];
    let mut own = [(V0, V0); MAX_LINK_DOF];
    let mut local_force = [Dual::ZERO; MAX_LINK_DOF];
    for f in 0..nc {
        let col = cell::COLUMNS + 12 * f;
        let (s_w, v_end) = (turn(col), turn(col + 3));
        let (own_w, own_v) = (turn(col + 6), turn(col + 9));
        let xdd = Dual::constant(xdd[f]);
        ddd = add(ddd, scale(xdd, v_end));
        w_rel_d = add(w_rel_d, scale(xdd, s_w));
        cendd = add(cendd, scale(xdd, own_v));
        w_b_d = add(w_b_d, scale(xdd, own_w));
        twist[f] = (s_w, sub(v_end, cross(s_w, end)));
        own[f] = (own_w, own_v);
        local_force[f] = o(cell::forces(nc) + f);
    }

    let body_a = point_accel(acc, alpha, omega, cen, cend, cendd);
    let body_w = add(omega, w_b);
    let body_alpha = add(add(alpha, cross(omega, w_b)), w_b_d);
    let iw = apply_body(lateral, axial, axis, extra, body_w);
    let mut torque = add(
        apply_body(lateral, axial, axis, extra, body_alpha),
        cross(body_w, iw),
    );
    if let Some(xd) = inertia_rates {
        // As `forward` in `links`: the torque I' w and -|w|^2 dI/dx / 2.
        let rates = cell::inertia_rates(nc);
        let mut i_dot = Dual::ZERO;
        for (f, &xd) in xd.iter().enumerate().take(nc) {
            i_dot = i_dot + o(rates + f) * xd;
        }
        let half_w2 = Dual::constant(0.5) * dot(body_w, body_w);
        torque = add(torque, scale(i_dot, body_w));
        for (f, force) in local_force.iter_mut().enumerate().take(nc) {
            *force = *force - half_w2 * o(rates + f);
        }
    }
    let forces = LinkForces {
        centroid: add(pos, cen),
        force: scale(m, sub(body_a, gravity)),
        torque,
        twist,
        own,
        local_force,
    };
    *frame = Frame {
        r: mat_mat(&r, &rel),
        pos: end,
        omega: add(omega, w_rel),
        alpha: add(add(alpha, cross(omega, w_rel)), w_rel_d),
        acc: point_accel(acc, alpha, omega, d, dd, ddd),
    };
    forces
}

/// The wrench (about the world origin: moment, force) of what hangs on
/// the end frame: the tip body's inertial and gravity forces and the tip
/// loads, as forces of the opposite sign.
#[inline(always)]
fn tip_wrench(layout: &LinkLayout, frame: &Frame, p: &[f64], gravity: V3) -> (V3, V3) {
    let Frame {
        r,
        pos,
        omega,
        alpha,
        acc,
    } = frame;
    let c = |i: usize| Dual::constant(p[i]);
    let axis = [r[0][0], r[1][0], r[2][0]];
    let length = layout.tip_length.map_or(Dual::ZERO, c);
    let point = add(*pos, scale(length, axis));
    let mut wrench = (V0, V0);
    if let Some(m) = layout.tip_mass.map(c) {
        let offset = scale(Dual::constant(0.5) * length, axis);
        let centre = add(*pos, offset);
        let (lateral, axial) = layout
            .tip_inertia
            .map_or((Dual::ZERO, Dual::ZERO), |[l, a]| (c(l), c(a)));
        let a_c = point_accel(*acc, *alpha, *omega, offset, V0, V0);
        let force = scale(m, sub(a_c, gravity));
        let iw = apply_body(lateral, axial, axis, None, *omega);
        let torque = add(
            apply_body(lateral, axial, axis, None, *alpha),
            cross(*omega, iw),
        );
        wrench = (add(torque, cross(centre, force)), force);
    }
    let load = |idx: Option<[usize; 3]>| -> V3 {
        idx.map_or(V0, |i| {
            let v = i.map(|i| -c(i));
            if layout.tip_frame { mat_vec(r, v) } else { v }
        })
    };
    let (tip_f, tip_m) = (load(layout.tip_force), load(layout.tip_moment));
    (
        add(wrench.0, add(cross(point, tip_f), tip_m)),
        add(wrench.1, tip_f),
    )
}

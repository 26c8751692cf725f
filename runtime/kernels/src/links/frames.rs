//! The frames of a chain that an assembly's joints hold (a segment's end,
//! the tip), with what the joints' rows need of them: each frame's pose,
//! its velocity, its acceleration at qdd = 0 and its columns d/dq, by one
//! sweep out over the links' cells in `f64` (the forward pass of
//! `mass_bias`: the cells' convective accelerations carried from frame to
//! frame, the twists each coordinate's rate gives the frames, as the
//! contact points' sweep composes them). The joints' rows are derived on
//! these frame variables (`eomgen`'s assembly; the kernel layer's `joints`
//! module), not on the links: an assembly's constraint kernels are then
//! the size of its joints, not of its elements times its joints.
//!
//! A frame's variables ([`frame`]) are its origin, its planar angle and its
//! quaternion, as the generator's joints read them. The angle is the sum
//! of the base's and every link's turn, and the quaternion the product of
//! the base's and every link's (w >= 0), as the generator composes them:
//! a link turns by less than a half turn.

use serde::{Deserialize, Serialize};

use super::{
    CELL_PARAMS, Cells, LinkLayout, Loads, M3, MAX_LINK_DOF, V3, add, base_motion,
    base_orientation, base_rates, cell, cross, link_params, local, mat_mat, mat_vec, scale, sub,
};
use crate::rotation::{quat_mul, to_unit_quaternion};

/// A frame of an arm that a joint may hold.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum ArmFrame {
    /// The end of segment k (of its last element).
    SegmentEnd(usize),
    /// The tip: the last segment's end, or the far end of a tip body with a
    /// length.
    Tip,
}

/// One frame's motion as [`frames`] writes it: its variables x (origin,
/// planar angle, quaternion w, x, y, z), their rates, their accelerations
/// at qdd = 0, then their columns d x / d q (a row of the arm's
/// coordinates per variable).
pub mod frame {
    /// Variables a frame has.
    pub const VARS: usize = 8;
    pub const POINT: usize = 0;
    pub const ANGLE: usize = 3;
    pub const QUAT: usize = 4;
    /// Where the rates start, and the accelerations.
    pub const RATE: usize = VARS;
    pub const ACCEL: usize = 2 * VARS;
    /// What a joint's rows read of a frame: x, its rate and acceleration.
    pub const STATE: usize = 3 * VARS;
    pub const COLUMNS: usize = STATE;
    /// A frame's values on an arm of `dof` coordinates.
    pub const fn len(dof: usize) -> usize {
        COLUMNS + VARS * dof
    }
}

/// The link whose end frame `f` is.
fn link_of(layout: &LinkLayout, f: ArmFrame) -> usize {
    match f {
        ArmFrame::SegmentEnd(s) => layout.segment_ends[s],
        ArmFrame::Tip => layout.links.len() - 1,
    }
}

/// A frame's motion as the sweep reaches it: the world's.
struct Motion {
    r: M3,
    point: V3,
    v: V3,
    acc: V3,
    w: V3,
    alpha: V3,
    angle: f64,
    quat: [f64; 4],
}

/// The frames `which` of the chain at (q, qd, p), [`frame::len`] values
/// each, into `out` in their order.
#[inline(always)]
pub fn frames<C: Cells + ?Sized>(
    layout: &LinkLayout,
    cells: &mut C,
    q: &[f64],
    qd: &[f64],
    p: &[f64],
    which: &[ArmFrame],
    out: &mut [f64],
) {
    let n = layout.dof;
    let len = frame::len(n);
    assert_eq!(out.len(), which.len() * len, "a frame's values each");
    let Some(last) = which.iter().map(|&f| link_of(layout, f)).max() else {
        return;
    };
    let planar = layout.base_angle.is_some();
    let loads = Loads::of(layout, cells);
    let mut params = [0.0; CELL_PARAMS];
    let (r, quat) = base_orientation(layout, p);
    let (point, v, acc) = base_motion(layout, p);
    let (w, alpha) = base_rates(layout, p);
    // A planar chain's turns are about z: its angle is their sum.
    let turned: f64 = layout.base_turns.iter().map(|t| p[t.angle[0]]).sum();
    let mut m = Motion {
        r,
        point,
        v,
        acc,
        w,
        alpha,
        angle: layout.base_angle.map_or(0.0, |i| p[i]) + turned,
        quat,
    };
    // Per arm coordinate, the twist (W, V) its rate gives the frame the
    // sweep has reached, about the world origin.
    let mut twists = vec![([0.0; 3], [0.0; 3]); n];
    let mut c = [0.0; cell::len_of(MAX_LINK_DOF, true)];
    for (k, spec) in layout.links.iter().enumerate().take(last + 1) {
        let nc = spec.map.len();
        let (x, xd) = (local(spec, p, q), local(spec, p, qd));
        link_params(&mut params, spec, p, loads.values());
        cells.one(
            spec.cell,
            &x[..nc],
            &xd[..nc],
            &params,
            &mut c[..spec.cell_len()],
        );
        let v3 = |i: usize| [c[i], c[i + 1], c[i + 2]];
        let turn = |i: usize| mat_vec(&m.r, v3(i));
        let rel: M3 = std::array::from_fn(|i| v3(cell::ROTATION + 3 * i));
        let (d, dd, ddd) = (turn(cell::END), turn(cell::END_RATE), turn(cell::END_ACCEL));
        let (w_rel, w_rel_d) = (turn(cell::OMEGA), turn(cell::OMEGA_RATE));
        let end = add(m.point, d);
        for f in 0..nc {
            let col = cell::COLUMNS + 12 * f;
            let s_w = turn(col);
            let twist = (s_w, sub(turn(col + 3), cross(s_w, end)));
            let map = &spec.map[f];
            let sc = map.scale.map_or(1.0, |i| p[i]);
            for &(a, weight) in &map.terms {
                let (tw, tv) = &mut twists[a];
                *tw = add(*tw, scale(sc * weight, twist.0));
                *tv = add(*tv, scale(sc * weight, twist.1));
            }
        }
        let (w, alpha) = (m.w, m.alpha);
        m.acc = add(
            add(add(m.acc, cross(alpha, d)), cross(w, cross(w, d))),
            add(scale(2.0, cross(w, dd)), ddd),
        );
        m.alpha = add(add(alpha, cross(w, w_rel)), w_rel_d);
        m.v = add(add(m.v, cross(w, d)), dd);
        m.w = add(w, w_rel);
        m.point = end;
        // The plane's joints read the angle, space's the quaternion.
        match planar {
            true => m.angle += rel[1][0].atan2(rel[0][0]),
            false => m.quat = quat_mul(m.quat, to_unit_quaternion(&rel)),
        }
        m.r = mat_mat(&m.r, &rel);
        for (f, &at) in which.iter().enumerate() {
            if link_of(layout, at) == k {
                let tip = at == ArmFrame::Tip;
                write(
                    layout,
                    tip,
                    &m,
                    &twists,
                    p,
                    &mut out[f * len..(f + 1) * len],
                );
            }
        }
    }
}

/// A link end's motion `m` and the coordinates' twists there as a frame's
/// values, moved out along the tip body where `tip` and the chain has one
/// with a length.
fn write(
    layout: &LinkLayout,
    tip: bool,
    m: &Motion,
    twists: &[(V3, V3)],
    p: &[f64],
    o: &mut [f64],
) {
    use frame::*;
    let n = layout.dof;
    let (w, alpha) = (m.w, m.alpha);
    let (mut point, mut v, mut a) = (m.point, m.v, m.acc);
    // A tip body's far end: carried rigidly by the tip's frame.
    let offset = match (tip, layout.tip_length) {
        (true, Some(i)) => Some([m.r[0][0], m.r[1][0], m.r[2][0]].map(|c| p[i] * c)),
        _ => None,
    };
    if let Some(d) = offset {
        point = add(point, d);
        v = add(v, cross(w, d));
        a = add(add(a, cross(alpha, d)), cross(w, cross(w, d)));
    }
    let quat = m.quat;
    // q' = (0, w) q / 2 for the world's angular velocity w.
    let turn = |w: V3, q: [f64; 4]| quat_mul([0.0, w[0], w[1], w[2]], q).map(|c| 0.5 * c);
    let quat_rate = turn(w, quat);
    let quat_accel = add4(turn(alpha, quat), turn(w, quat_rate));
    o[POINT..POINT + 3].copy_from_slice(&point);
    o[ANGLE] = m.angle;
    o[QUAT..QUAT + 4].copy_from_slice(&quat);
    o[RATE + POINT..RATE + POINT + 3].copy_from_slice(&v);
    o[RATE + ANGLE] = w[2];
    o[RATE + QUAT..RATE + QUAT + 4].copy_from_slice(&quat_rate);
    o[ACCEL + POINT..ACCEL + POINT + 3].copy_from_slice(&a);
    o[ACCEL + ANGLE] = alpha[2];
    o[ACCEL + QUAT..ACCEL + QUAT + 4].copy_from_slice(&quat_accel);
    let columns = &mut o[COLUMNS..];
    for (k, &(s, vel)) in twists.iter().enumerate() {
        // The point's column: the twist's velocity there.
        let c = add(vel, cross(s, point));
        let dq = turn(s, quat);
        for i in 0..3 {
            columns[(POINT + i) * n + k] = c[i];
        }
        columns[ANGLE * n + k] = s[2];
        for i in 0..4 {
            columns[(QUAT + i) * n + k] = dq[i];
        }
    }
}

fn add4(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    std::array::from_fn(|i| a[i] + b[i])
}

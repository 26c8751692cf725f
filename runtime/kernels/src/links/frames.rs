//! The frames of a chain that an assembly's joints hold (a segment's end,
//! the tip), with what the joints' rows need of them: by the sweep out to
//! points (`points.rs`) on dual numbers along qd, so that one sweep gives
//! each frame's pose, its velocity, its acceleration at qdd = 0 and its
//! columns d/dq. The joints' rows are derived on these frame variables
//! (`eomgen`'s assembly; the kernel layer's `joints` module), not on the links: an
//! assembly's constraint kernels are then the size of its joints, not of
//! its elements times its joints.
//!
//! A frame's variables ([`frame`]) are its origin, its planar angle and its
//! quaternion, as the generator's joints read them. The angle is the sum
//! of the base's and every link's turn, and the quaternion their product
//! (`PointMotion::angle`), as the generator composes them: a link turns
//! by less than a half turn.

use serde::{Deserialize, Serialize};

use super::num::{add, cross};
use super::points::{Asked, ContactPoint, PointMotion, sweep};
use super::{Cells, LinkLayout};
use crate::dual::Dual;
use crate::rotation::quat_mul;

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

/// The frames `which` of the chain at (q, qd, p), [`frame::len`] values
/// each, into `out` in their order.
pub fn frames<C: Cells + ?Sized>(
    layout: &LinkLayout,
    cells: &mut C,
    q: &[f64],
    qd: &[f64],
    p: &[f64],
    which: &[ArmFrame],
    out: &mut [f64],
) {
    let len = frame::len(layout.dof);
    assert_eq!(out.len(), which.len() * len, "a frame's values each");
    // The sweep meets points in the links' order.
    let mut order: Vec<usize> = (0..which.len()).collect();
    order.sort_by_key(|&i| link_of(layout, which[i]));
    let points: Vec<ContactPoint> = (order.iter())
        .map(|&i| ContactPoint {
            link: link_of(layout, which[i]),
            at: 1.0,
        })
        .collect();
    let asked = Asked {
        columns: true,
        spin: true,
        turns: true,
    };
    let at = (q, qd, Some(qd), p);
    sweep::<Dual, C>(
        layout,
        cells,
        at,
        (&points, |_| true),
        (asked, None),
        |j, m| {
            let f = order[j];
            let tip = which[f] == ArmFrame::Tip;
            write(layout, tip, m, (qd, p), &mut out[f * len..(f + 1) * len]);
        },
    );
}

/// A link end's motion `m` (on duals along qd) as a frame's values, moved
/// out along the tip body where `tip` and the chain has one with a length.
fn write(
    layout: &LinkLayout,
    tip: bool,
    m: &PointMotion<Dual>,
    (qd, p): (&[f64], &[f64]),
    o: &mut [f64],
) {
    use frame::*;
    let n = layout.dof;
    let value = |v: [Dual; 3]| v.map(|x| x.v);
    let rate = |v: [Dual; 3]| v.map(|x| x.d);
    // The angular velocity and its rate at qdd = 0 from the angular
    // columns (and their derivatives along qd).
    let (mut w, mut alpha) = ([0.0; 3], [0.0; 3]);
    for (col, &r) in m.spin.iter().zip(qd) {
        w = add(w, value(*col).map(|c| c * r));
        alpha = add(alpha, rate(*col).map(|c| c * r));
    }
    let (mut point, mut v, mut a) = (value(m.p), value(m.v), rate(m.v));
    // A tip body's far end: carried rigidly by the tip's frame.
    let offset = match (tip, layout.tip_length) {
        (true, Some(i)) => {
            let r = m.rotation.map(|row| row.map(|x| x.v));
            Some([r[0][0], r[1][0], r[2][0]].map(|c| p[i] * c))
        }
        _ => None,
    };
    if let Some(d) = offset {
        point = add(point, d);
        v = add(v, cross(w, d));
        a = add(add(a, cross(alpha, d)), cross(w, cross(w, d)));
    }
    let quat = m.quat;
    // q' = (0, w) q / 2 for the world's angular velocity w.
    let turn = |w: [f64; 3], q: [f64; 4]| quat_mul([0.0, w[0], w[1], w[2]], q).map(|c| 0.5 * c);
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
    for (k, (col, spin)) in m.columns.iter().zip(m.spin).enumerate() {
        let (mut c, s) = (value(*col), value(*spin));
        if let Some(d) = offset {
            c = add(c, cross(s, d));
        }
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

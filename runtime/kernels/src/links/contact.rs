//! The contact kernels of a link chain (`Contact`, `ContactJacobian`,
//! `ContactJvp`) by one sweep out over the links' cells, so that a chain
//! with contact needs no flat kernel of its points: the generated or
//! interpreted size grows with the distinct cells, not with the points
//! times the coordinates.
//!
//! Each point lies on a link's arc (`points.rs`: the sweep and how a
//! point is cut from its link's cell).
//!
//! The sweep runs in dual numbers along dq (the cells' tangents), which
//! gives `ContactJvp`'s dv and d(dp/dq) from the same sums.

use serde::{Deserialize, Serialize};

use super::num::{add, cell_v3, mat_mat, mat_vec};
use super::points::{Asked, LinkOutputs, PointMotion, sweep};
use super::{CELL_PARAMS, Cells, LinkLayout, MAX_LINK_DOF, cell, local};
use crate::dual::Dual;

/// Values per group at the head of the contact frames (`ModelInfo::
/// contact_frames`): A (3), B (3), L.
pub const CONTACT_BOUND: usize = 7;

/// The links an element's contact points lie on (first and last), and
/// where its centreline cannot stretch or shear, the parameter that is its
/// length: the broad phase's bound ([`contact_bounds`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ContactElement {
    pub first: usize,
    pub last: usize,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub length: Option<usize>,
}

const POSITIONS: Asked = Asked {
    columns: false,
    spin: false,
};
const COLUMNS: Asked = Asked {
    columns: true,
    spin: false,
};

/// The `Contact` kernel: every point's position (3 each).
#[inline(always)]
pub fn contact_points<C: Cells>(
    layout: &LinkLayout,
    (cells, kept): (&mut C, &mut LinkOutputs),
    (q, qd, p): (&[f64], &[f64], &[f64]),
    out: &mut [f64],
) {
    kept.at(q, qd, p);
    sweep(
        layout,
        cells,
        (q, qd, None, p),
        (&layout.contact, |_| true),
        (POSITIONS, Some(kept)),
        |i, m: &PointMotion<f64>| out[3 * i..3 * i + 3].copy_from_slice(&m.p),
    );
}

/// The `ContactJacobian` kernel for the points `want` asks for: per point
/// p (3), v (3), dp/dq (3 x n, row-major); the other points' outputs are
/// left as they were.
#[inline(always)]
pub fn contact_jacobian<C: Cells>(
    layout: &LinkLayout,
    (cells, kept): (&mut C, &mut LinkOutputs),
    (q, qd, p): (&[f64], &[f64], &[f64]),
    want: impl Fn(usize) -> bool,
    out: &mut [f64],
) {
    kept.at(q, qd, p);
    let n = layout.dof;
    let width = 6 + 3 * n;
    sweep(
        layout,
        cells,
        (q, qd, None, p),
        (&layout.contact, want),
        (COLUMNS, Some(kept)),
        |i, m: &PointMotion<f64>| {
            let o = &mut out[i * width..(i + 1) * width];
            for c in 0..3 {
                o[c] = m.p[c];
                o[3 + c] = m.v[c];
                for (a, col) in m.columns.iter().enumerate() {
                    o[6 + c * n + a] = col[c];
                }
            }
        },
    );
}

/// The `ContactJvp` kernel: per point dv (3) and d(dp/dq) (3 x n,
/// row-major) along `dq`.
#[inline(always)]
pub fn contact_jvp<C: Cells>(
    layout: &LinkLayout,
    cells: &mut C,
    (q, qd, p): (&[f64], &[f64], &[f64]),
    dq: &[f64],
    out: &mut [f64],
) {
    let n = layout.dof;
    let width = 3 + 3 * n;
    sweep(
        layout,
        cells,
        (q, qd, Some(dq), p),
        (&layout.contact, |_| true),
        (COLUMNS, None),
        |i, m: &PointMotion<Dual>| {
            let o = &mut out[i * width..(i + 1) * width];
            for c in 0..3 {
                o[c] = m.v[c].d;
                for (a, col) in m.columns.iter().enumerate() {
                    o[3 + c * n + a] = col[c].d;
                }
            }
        },
    );
}

/// Whether [`contact_bounds`] gives the bounds of `groups` (points per
/// group): every element's centreline of known length, and every group
/// whole elements.
pub fn has_contact_bounds(layout: &LinkLayout, groups: &[usize]) -> bool {
    let elements = &layout.contact_elements;
    let points = layout.contact.len();
    !elements.is_empty()
        && points.is_multiple_of(elements.len())
        && elements.iter().all(|e| e.length.is_some())
        && groups
            .iter()
            .all(|&g| g.is_multiple_of(points / elements.len()))
        && groups.iter().sum::<usize>() == points
}

/// The broad phase's bound of each group of `groups` (points per group;
/// [`has_contact_bounds`]), [`CONTACT_BOUND`] values each: the
/// origin A its first element starts from, the end B of its last, and
/// the centreline's length L between them (every point of the group lies
/// in the ellipsoid of foci A and B and major axis L). One sweep over the
/// links' frames, no point computed.
#[inline(always)]
pub fn contact_bounds<C: Cells>(
    layout: &LinkLayout,
    (cells, kept): (&mut C, &mut LinkOutputs),
    (q, qd, p): (&[f64], &[f64], &[f64]),
    groups: &[usize],
    out: &mut [f64],
) {
    kept.at(q, qd, p);
    let elements = &layout.contact_elements;
    let per = layout.contact.len() / elements.len();
    let mut params: Vec<[f64; CELL_PARAMS]> = Vec::new();
    kept.params(layout, cells, p, &mut params);
    let mut r = super::base_orientation(layout, p).0;
    let mut pos = super::base_motion(layout, p).0;
    // Each link's base origin and end, as far as the last element's.
    let reach = elements.last().map_or(0, |e| e.last + 1);
    let mut ends = Vec::with_capacity(reach + 1);
    ends.push(pos);
    let mut o = vec![0.0; cell::len_of(MAX_LINK_DOF, true)];
    for (k, spec) in layout.links.iter().enumerate().take(reach) {
        let nc = spec.map.len();
        let len = spec.cell_len();
        let (x, xd) = (local(spec, p, q), local(spec, p, qd));
        kept.link(
            cells,
            (k, spec.cell),
            &x[..nc],
            &xd[..nc],
            &params[k],
            &mut o[..len],
        );
        let rel: [[f64; 3]; 3] = std::array::from_fn(|i| cell_v3(&o, len, cell::ROTATION + 3 * i));
        pos = add(pos, mat_vec(&r, cell_v3(&o, len, cell::END)));
        r = mat_mat(&r, &rel);
        ends.push(pos);
    }
    let mut e = 0;
    for (g, &points) in groups.iter().enumerate() {
        let count = points / per;
        let span = &elements[e..e + count];
        let b = &mut out[CONTACT_BOUND * g..CONTACT_BOUND * (g + 1)];
        b[..3].copy_from_slice(&ends[span[0].first]);
        b[3..6].copy_from_slice(&ends[span[count - 1].last + 1]);
        b[6] = span.iter().map(|e| e.length.map_or(0.0, |i| p[i])).sum();
        e += count;
    }
}

//! The contact kernels of a link chain (`Contact`, `ContactJacobian`,
//! `ContactJvp`) by one sweep out over the links' cells, so that a chain
//! with contact needs no flat kernel of its points: the generated or
//! interpreted size grows with the distinct cells, not with the points
//! times the coordinates.
//!
//! A contact point lies on a constant-strain link at a fraction `at` of
//! its arc (`ContactPoint`). A constant-strain arc cut at `at` is the same
//! arc with every strain coordinate and the length scaled by `at` (the
//! strain's `part`, as the methods sample their points), so the point in
//! its link's base frame is the end point of the link's own cell at
//! (at x, at xd, length at l), and its columns in the cell coordinates are
//! `at` times that cell's end-point columns. Composed with the link's
//! world frame (R, O) and the twists (W_a, V_a) that each arm coordinate's
//! rate gives the frames before it (about the world origin):
//!
//! * p = O + R l;
//! * dp/dq_a = V_a + W_a x p + R sum_f w_fa at dl/dx'_f (its own link's
//!   cell coordinates f, with their weights);
//! * v = (dp/dq) qd.
//!
//! The sweep runs in dual numbers along dq (the cells' tangents), which
//! gives `ContactJvp`'s dv and d(dp/dq) from the same sums.

use serde::{Deserialize, Serialize};

use super::num::{Num, add, cell_v3, cross, mat_mat, mat_vec, scale, sub};
use super::{CELL_PARAMS, Cells, LinkLayout, MAX_LINK_DOF, cell, cell_params, local};
use crate::dual::Dual;

/// Values per group at the head of the contact frames (`ModelInfo::
/// contact_frames`): A (3), B (3), L.
pub const CONTACT_BOUND: usize = 7;

/// A contact point of a chain: on link `link`, at the fraction `at` of the
/// link's arc (in (0, 1]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ContactPoint {
    pub link: usize,
    pub at: f64,
}

/// The state a sweep runs at: q, qd, the direction dq its duals move along
/// (None: the sweep runs on `f64`), p.
type At<'a> = (&'a [f64], &'a [f64], Option<&'a [f64]>, &'a [f64]);

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

/// Each link's cell outputs at the state the contact kernels last ran at
/// (q, qd, p), so that the kernels a right-hand side asks for at one state
/// (the bounds, then the groups the broad phase keeps) evaluate each link's
/// cell once.
#[derive(Default)]
pub struct LinkOutputs {
    state: Vec<f64>,
    outs: Vec<Vec<f64>>,
}

impl LinkOutputs {
    /// Keep what is kept only if it is of (q, qd, p).
    #[inline(always)]
    fn at(&mut self, q: &[f64], qd: &[f64], p: &[f64]) {
        let same = self.state.len() == q.len() + qd.len() + p.len()
            && (q.iter().chain(qd).chain(p))
                .zip(&self.state)
                .all(|(a, b)| a.to_bits() == b.to_bits());
        if !same {
            self.state.clear();
            self.state.extend(q.iter().chain(qd).chain(p));
            self.outs.iter_mut().for_each(Vec::clear);
        }
    }

    /// Link k's cell (`c`, at x, xd, with `params`) into `out[..len]`:
    /// kept, or evaluated and kept.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn link<C: Cells>(
        &mut self,
        cells: &mut C,
        (k, c): (usize, usize),
        x: &[f64],
        xd: &[f64],
        params: &[f64; CELL_PARAMS],
        out: &mut [f64],
    ) {
        if self.outs.len() <= k {
            self.outs.resize(k + 1, Vec::new());
        }
        let kept = &mut self.outs[k];
        if kept.len() == out.len() {
            out.copy_from_slice(kept);
        } else {
            cells.one(c, x, xd, params, out);
            kept.clear();
            kept.extend_from_slice(out);
        }
    }
}

/// A point's kinematics as the sweep gives them: position, velocity and
/// dp/dq (one column per arm coordinate), each with its derivative along
/// the sweep's direction where it runs on duals.
struct PointMotion<'a, N> {
    p: [N; 3],
    v: [N; 3],
    columns: &'a [[N; 3]],
}

/// One cell at (x, xd) moving along dx (all `nc` long; None: not moving)
/// with parameters `params`, into `out`: its values ([`cell::len`]), then
/// where dx is given their derivatives (zero where dx does not move it).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn cell_at<C: Cells>(
    cells: &mut C,
    c: usize,
    (x, xd, dx): (&[f64], &[f64], Option<&[f64]>),
    len: usize,
    params: &[f64; CELL_PARAMS],
    out: &mut [f64],
) {
    match dx {
        Some(dx) if dx.iter().any(|&v| v != 0.0) => {
            let dxd = [0.0; MAX_LINK_DOF];
            cells.tangent(c, x, xd, dx, &dxd[..x.len()], params, &mut out[..2 * len]);
        }
        Some(_) => {
            cells.one(c, x, xd, params, &mut out[..len]);
            out[len..2 * len].fill(0.0);
        }
        None => cells.one(c, x, xd, params, &mut out[..len]),
    }
}

/// The sweep out: for every point `want` asks for (in the chain's order),
/// `emit(i, motion)`; with `columns` false only the positions are
/// computed (the columns and velocity are left zero). Stops past the last link a
/// wanted point is on.
#[inline(always)]
fn sweep<N: Num, C: Cells>(
    layout: &LinkLayout,
    cells: &mut C,
    (q, qd, dq, p): At,
    want: impl Fn(usize) -> bool,
    (columns, mut kept): (bool, Option<&mut LinkOutputs>),
    mut emit: impl FnMut(usize, &PointMotion<N>),
) {
    let n = layout.dof;
    let points = &layout.contact;
    // The sweep meets each point on its link, in the links' order.
    debug_assert!(points.windows(2).all(|w| w[0].link <= w[1].link));
    let Some(last) = (0..points.len()).rev().find(|&i| want(i)) else {
        return;
    };
    let last_link = points[last].link;
    let v0 = [N::ZERO; 3];
    let base = super::base_orientation(layout, p).0;
    let mut r = base.map(|row| row.map(N::constant));
    let mut pos: [N; 3] = layout.base_position.map(|i| N::constant(p[i]));
    // Per arm coordinate, the twist (W, V) its rate gives the frame the
    // sweep has reached, about the world origin.
    let mut twists = vec![(v0, v0); if columns { n } else { 0 }];
    let mut own = vec![v0; if columns { n } else { 0 }];
    let mut params: Vec<[f64; CELL_PARAMS]> = Vec::new();
    cell_params(layout, cells, p, &mut params);
    let mut out = vec![0.0; 2 * cell::len(MAX_LINK_DOF)];
    let mut next = 0;
    for (k, spec) in layout.links.iter().enumerate().take(last_link + 1) {
        let nc = spec.map.len();
        let len = cell::len(nc);
        let (x, xd) = (local(spec, p, q), local(spec, p, qd));
        let dx = dq.map(|dq| local(spec, p, dq));
        // Each cell coordinate's weight on each arm coordinate.
        let weight = |f: usize| {
            let c = &spec.map[f];
            let sc = c.scale.map_or(1.0, |i| p[i]);
            c.terms.iter().map(move |&(a, w)| (a, sc * w))
        };
        while next < points.len() && points[next].link == k {
            let i = next;
            next += 1;
            if !want(i) {
                continue;
            }
            let at = points[i].at;
            let cut = |v: &[f64; MAX_LINK_DOF]| -> [f64; MAX_LINK_DOF] { v.map(|v| at * v) };
            let mut cut_params = params[k];
            cut_params[0] *= at;
            let (xa, xda, dxa) = (cut(&x), cut(&xd), dx.as_ref().map(cut));
            let moving = (&xa[..nc], &xda[..nc], dxa.as_ref().map(|d| &d[..nc]));
            cell_at(cells, spec.cell, moving, len, &cut_params, &mut out);
            let point = add(pos, mat_vec(&r, cell_v3(&out, len, cell::END)));
            let mut v = v0;
            if columns {
                for (a, col) in own.iter_mut().enumerate() {
                    let (w, v) = twists[a];
                    *col = add(v, cross(w, point));
                }
                for f in 0..nc {
                    let turned = mat_vec(&r, cell_v3(&out, len, cell::COLUMNS + 12 * f + 3));
                    for (a, w) in weight(f) {
                        own[a] = add(own[a], scale(N::constant(at * w), turned));
                    }
                }
                for (col, &rate) in own.iter().zip(qd) {
                    v = add(v, scale(N::constant(rate), *col));
                }
            }
            let motion = PointMotion {
                p: point,
                v,
                columns: &own,
            };
            emit(i, &motion);
        }
        // The frame past the link, and the twists its coordinates give it.
        match kept.as_deref_mut() {
            Some(kept) if dx.is_none() => {
                let (x, xd) = (&x[..nc], &xd[..nc]);
                kept.link(cells, (k, spec.cell), x, xd, &params[k], &mut out[..len]);
            }
            _ => {
                let moving = (&x[..nc], &xd[..nc], dx.as_ref().map(|d| &d[..nc]));
                cell_at(cells, spec.cell, moving, len, &params[k], &mut out);
            }
        }
        let rel: [[N; 3]; 3] = std::array::from_fn(|i| cell_v3(&out, len, cell::ROTATION + 3 * i));
        let end = add(pos, mat_vec(&r, cell_v3(&out, len, cell::END)));
        if columns {
            for f in 0..nc {
                let col = cell::COLUMNS + 12 * f;
                let s_w = mat_vec(&r, cell_v3(&out, len, col));
                let v_end = mat_vec(&r, cell_v3(&out, len, col + 3));
                let twist = (s_w, sub(v_end, cross(s_w, end)));
                for (a, w) in weight(f) {
                    let w = N::constant(w);
                    let (tw, tv) = &mut twists[a];
                    *tw = add(*tw, scale(w, twist.0));
                    *tv = add(*tv, scale(w, twist.1));
                }
            }
        }
        r = mat_mat(&r, &rel);
        pos = end;
    }
}

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
        |_| true,
        (false, Some(kept)),
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
        want,
        (true, Some(kept)),
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
        |_| true,
        (true, None),
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
    cell_params(layout, cells, p, &mut params);
    let mut r = super::base_orientation(layout, p).0;
    let mut pos = layout.base_position.map(|i| p[i]);
    // Each link's base origin and end, as far as the last element's.
    let reach = elements.last().map_or(0, |e| e.last + 1);
    let mut ends = Vec::with_capacity(reach + 1);
    ends.push(pos);
    let mut o = vec![0.0; cell::len(MAX_LINK_DOF)];
    for (k, spec) in layout.links.iter().enumerate().take(reach) {
        let nc = spec.map.len();
        let len = cell::len(nc);
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

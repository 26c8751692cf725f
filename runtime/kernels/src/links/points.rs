//! The sweep out over a chain's links to points on their arcs: each
//! point's position, velocity and columns dp/dq (and where asked, its
//! section's rotation and angular columns), on `f64` or on dual numbers
//! along a direction dq. The contact kernels (`contact.rs`) and the loads
//! along the arm (`along.rs`) are its two uses.
//!
//! A point lies on a constant-strain link at a fraction `at` of its arc
//! (`ContactPoint`). A constant-strain arc cut at `at` is the same arc
//! with every strain coordinate and the length scaled by `at` (the
//! strain's `part`, as the methods sample their points), so the point in
//! its link's base frame is the end point of the link's own cell at
//! (at x, at xd, length at l), and its columns in the cell coordinates are
//! `at` times that cell's end-point columns. Composed with the link's
//! world frame (R, O) and the twists (W_a, V_a) that each arm coordinate's
//! rate gives the frames before it (about the world origin):
//!
//! * p = O + R l, the section's rotation R R_cut;
//! * dp/dq_a = V_a + W_a x p + R sum_f w_fa at dl/dx'_f (its own link's
//!   cell coordinates f, with their weights), its angular column
//!   W_a + R sum_f w_fa at dw/dx'_f;
//! * v = (dp/dq) qd.
//!
//! A link that turns at its start and is straight past it (a rigid link
//! past its joint: `ContactPoint::straight`) is not cut: the point is
//! `at` times its whole cell's end point, its columns `at` times the end
//! point's, and its section turns as the end, by the whole angular
//! columns.

use serde::{Deserialize, Serialize};

use super::num::{Num, add, cell_v3, cross, mat_mat, mat_vec, scale, sub};
use super::{CELL_PARAMS, Cells, LinkLayout, MAX_LINK_DOF, cell, cell_params, local};

/// A point of a chain (a contact point, where a load acts): on link
/// `link`, at the fraction `at` of the link's arc (in [0, 1]), or where
/// `straight`, of its straight line past its turn at the start.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ContactPoint {
    pub link: usize,
    pub at: f64,
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub straight: bool,
}

/// The state a sweep runs at: q, qd, the direction dq its duals move along
/// (None: the sweep runs on `f64`), p.
pub(super) type At<'a> = (&'a [f64], &'a [f64], Option<&'a [f64]>, &'a [f64]);

/// Each link's cell outputs at the state the contact kernels last ran at
/// (q, qd, p), so that the kernels a right-hand side asks for at one state
/// (the bounds, then the groups the broad phase keeps) evaluate each link's
/// cell once.
#[derive(Default)]
pub struct LinkOutputs {
    state: Vec<f64>,
    outs: Vec<Vec<f64>>,
    /// The links' cell parameters at that state, once taken.
    params: Vec<[f64; CELL_PARAMS]>,
}

impl LinkOutputs {
    /// Keep what is kept only if it is of (q, qd, p). Compared slice by
    /// slice, bit for bit, without branching per value: every contact
    /// kernel of a right-hand side asks, and a chained comparison cost a
    /// quarter of the bounds' sweep.
    #[inline(always)]
    pub(super) fn at(&mut self, q: &[f64], qd: &[f64], p: &[f64]) {
        let (nq, nqd) = (q.len(), qd.len());
        let same = self.state.len() == nq + nqd + p.len()
            && bits_equal(&self.state[..nq], q)
            && bits_equal(&self.state[nq..nq + nqd], qd)
            && bits_equal(&self.state[nq + nqd..], p);
        if !same {
            self.state.clear();
            self.state.extend_from_slice(q);
            self.state.extend_from_slice(qd);
            self.state.extend_from_slice(p);
            self.outs.iter_mut().for_each(Vec::clear);
            self.params.clear();
        }
    }

    /// The links' cell parameters at the kept state into `params`: kept,
    /// or taken and kept.
    #[inline(always)]
    pub(super) fn params<C: Cells + ?Sized>(
        &mut self,
        layout: &LinkLayout,
        cells: &mut C,
        p: &[f64],
        params: &mut Vec<[f64; CELL_PARAMS]>,
    ) {
        if self.params.len() != layout.links.len() {
            cell_params(layout, cells, p, &mut self.params);
        }
        params.clear();
        params.extend_from_slice(&self.params);
    }

    /// Link k's cell (`c`, at x, xd, with `params`) into `out[..len]`:
    /// kept, or evaluated and kept.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(super) fn link<C: Cells + ?Sized>(
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

/// Whether two slices of equal length hold the same bits: or-ed
/// differences, so that the loop runs in vector lanes.
#[inline(always)]
pub(crate) fn bits_equal(a: &[f64], b: &[f64]) -> bool {
    a.iter()
        .zip(b)
        .fold(0u64, |acc, (x, y)| acc | (x.to_bits() ^ y.to_bits()))
        == 0
}

/// A point's kinematics as the sweep gives them: position, velocity and
/// dp/dq (one column per arm coordinate), and where asked ([`Asked::
/// spin`]) its section's rotation (rows: world from section) and angular
/// columns; each with its derivative along the sweep's direction where it
/// runs on duals.
pub(super) struct PointMotion<'a, N> {
    pub p: [N; 3],
    pub v: [N; 3],
    pub columns: &'a [[N; 3]],
    pub rotation: [[N; 3]; 3],
    pub spin: &'a [[N; 3]],
}

/// What a sweep computes besides the points' positions.
#[derive(Clone, Copy)]
pub(super) struct Asked {
    /// The columns dp/dq and the velocity (else left zero).
    pub columns: bool,
    /// The section's rotation and angular columns (with `columns`; else
    /// the rotation is the link's base frame's and no angular columns).
    pub spin: bool,
}

/// One cell at (x, xd) moving along dx (all `nc` long; None: not moving)
/// with parameters `params`, into `out`: its values ([`cell::len`]), then
/// where dx is given their derivatives (zero where dx does not move it).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn cell_at<C: Cells + ?Sized>(
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

/// The sweep out: for every point of `points` (in the chain's order)
/// that `want` asks for, `emit(i, motion)` with what `asked` asks. Stops
/// past the last link a wanted point is on.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(super) fn sweep<N: Num, C: Cells + ?Sized>(
    layout: &LinkLayout,
    cells: &mut C,
    (q, qd, dq, p): At,
    (points, want): (&[ContactPoint], impl Fn(usize) -> bool),
    (asked, mut kept): (Asked, Option<&mut LinkOutputs>),
    mut emit: impl FnMut(usize, &PointMotion<N>),
) {
    let n = layout.dof;
    let columns = asked.columns;
    let spin = columns && asked.spin;
    // The sweep meets each point on its link, in the links' order.
    debug_assert!(points.windows(2).all(|w| w[0].link <= w[1].link));
    let Some(last) = (0..points.len()).rev().find(|&i| want(i)) else {
        return;
    };
    let last_link = points[last].link;
    let v0 = [N::ZERO; 3];
    let base = super::base_orientation(layout, p).0;
    let mut r = base.map(|row| row.map(N::constant));
    // A driven base's velocity moves every point; it does not move along
    // dq.
    let (base_pos, base_v, _) = super::base_motion(layout, p);
    let mut pos: [N; 3] = base_pos.map(N::constant);
    let moving_base = base_v.map(N::constant);
    // A turning base carries every point about its origin.
    let spinning = (!layout.base_turns.is_empty())
        .then(|| (super::base_rates(layout, p).0.map(N::constant), pos));
    // Per arm coordinate, the twist (W, V) its rate gives the frame the
    // sweep has reached, about the world origin.
    let mut twists = vec![(v0, v0); if columns { n } else { 0 }];
    let mut own = vec![v0; if columns { n } else { 0 }];
    let mut own_spin = vec![v0; if spin { n } else { 0 }];
    let mut params: Vec<[f64; CELL_PARAMS]> = Vec::new();
    match kept.as_deref_mut() {
        Some(kept) => kept.params(layout, cells, p, &mut params),
        None => cell_params(layout, cells, p, &mut params),
    }
    let mut out = vec![0.0; 2 * cell::len_of(MAX_LINK_DOF, true)];
    let mut next = 0;
    for (k, spec) in layout.links.iter().enumerate().take(last_link + 1) {
        let nc = spec.map.len();
        let len = spec.cell_len();
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
            let ContactPoint { at, straight, .. } = points[i];
            // An arc cut at `at`; a straight link whole (and its end
            // point scaled below).
            let cut_by = if straight { 1.0 } else { at };
            let cut = |v: &[f64; MAX_LINK_DOF]| -> [f64; MAX_LINK_DOF] { v.map(|v| cut_by * v) };
            let mut cut_params = params[k];
            cut_params[0] *= cut_by;
            let (xa, xda, dxa) = (cut(&x), cut(&xd), dx.as_ref().map(cut));
            let moving = (&xa[..nc], &xda[..nc], dxa.as_ref().map(|d| &d[..nc]));
            cell_at(cells, spec.cell, moving, len, &cut_params, &mut out);
            let end_by = N::constant(if straight { at } else { 1.0 });
            let local_point = scale(end_by, cell_v3(&out, len, cell::END));
            let point = add(pos, mat_vec(&r, local_point));
            let mut v = match spinning {
                Some((w, origin)) => add(moving_base, cross(w, sub(point, origin))),
                None => moving_base,
            };
            let mut rotation = r;
            if columns {
                for (a, col) in own.iter_mut().enumerate() {
                    let (w, v) = twists[a];
                    *col = add(v, cross(w, point));
                }
                for (a, col) in own_spin.iter_mut().enumerate() {
                    *col = twists[a].0;
                }
                for f in 0..nc {
                    let at_f = cell::COLUMNS + 12 * f;
                    let turned = mat_vec(&r, cell_v3(&out, len, at_f + 3));
                    let turned_w = spin.then(|| mat_vec(&r, cell_v3(&out, len, at_f)));
                    for (a, w) in weight(f) {
                        let s = N::constant(at * w);
                        own[a] = add(own[a], scale(s, turned));
                        if let Some(tw) = turned_w {
                            let s = N::constant(cut_by * w);
                            own_spin[a] = add(own_spin[a], scale(s, tw));
                        }
                    }
                }
                for (col, &rate) in own.iter().zip(qd) {
                    v = add(v, scale(N::constant(rate), *col));
                }
                if spin {
                    let rel: [[N; 3]; 3] =
                        std::array::from_fn(|i| cell_v3(&out, len, cell::ROTATION + 3 * i));
                    rotation = mat_mat(&r, &rel);
                }
            }
            let motion = PointMotion {
                p: point,
                v,
                columns: &own,
                rotation,
                spin: &own_spin,
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

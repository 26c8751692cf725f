//! `pcc`: piecewise constant curvature. Each element is an arc of
//! constant strain: in the plane one bending angle, by the chapter's chord
//! construction; in 3D a rotation vector (bend about y and z, optional
//! twist) and an optional stretch, R = exp([rho]x), with one body at the
//! arc's exact centroid turning with the mid-arc frame.

use super::{ModellingMethod, needs_bending_stiffness, strain_coordinate_names};
use crate::cas::{Cas, ExprId, Func};
use crate::model::{Check, ModelError, Segment, SegmentShape};
use crate::tmt::cell_kind::{CellKind, PointsOn};
use crate::tmt::planar::{self, Element2, Frame, PlanarArm};
use crate::tmt::spatial::{SpatialArm, arc, bind3, in_halves, mid_arc_rotation};

pub(super) struct Pcc;

impl ModellingMethod for Pcc {
    /// A stretching or shearing arc carries its mass as two half-arcs.
    fn cell_kind(&self, g: &SegmentShape, spatial: bool) -> CellKind {
        if spatial && in_halves(g) {
            CellKind::HalfArc
        } else {
            CellKind::Arc
        }
    }

    fn check_keys(&self, ck: &Check, i: usize, s: &Segment) -> Result<(), ModelError> {
        needs_bending_stiffness(ck, i, s)
    }

    fn coordinate_names(&self, g: &SegmentShape, s: usize) -> Vec<String> {
        strain_coordinate_names(g, s)
    }

    fn place_planar(&self, cas: &mut Cas, arm: &mut PlanarArm, _g: &SegmentShape, el: &Element2) {
        if arm.points > 0 {
            let points = arc_points(cas, arm.f, el.l, el.q, arm.points);
            arm.sample_all(cas, Some(el.l), points);
        }
        let (f, l, q, qd) = (arm.f, el.l, el.q, el.qd);
        arm.apply_loads(cas, &|cas: &mut Cas, s: f64| arc_frame(cas, f, l, q, qd, s));
        let (c, chord_rate, arc_inertia, end) = pcc_element(cas, arm.f, el.l, el.m, el.q, el.qd);
        let total = cas.add(arc_inertia, el.inertia);
        arm.body(cas, c, chord_rate, el.m, total);
        arm.f = end;
    }

    fn build_spatial(&self, cas: &mut Cas, arm: &mut SpatialArm, g: &SegmentShape, s: usize) {
        for _ in 0..g.elements {
            let el = arm.element();
            let first = arm.c;
            let st = arm.strain_element(cas, g, s, &el);
            let strain = st.arc();
            let f = arm.f;
            // The centreline's length: |(len, shear y, shear z)|, constant
            // strain.
            let length = match strain.shear {
                None => strain.len,
                Some([y, z]) => {
                    let sq = [strain.len, y, z].map(|c| cas.mul(c, c));
                    let sum = cas.add_all(&sq);
                    cas.sqrt(sum)
                }
            };
            arm.sample(cas, Some(length), |cas, s| {
                let part = strain.part(cas, s);
                arc(cas, &f, &part).3
            });
            let (pieces, part, body) = match in_halves(g) {
                true => (2, strain.part(cas, 0.5), el.half(cas)),
                false => (1, strain, el),
            };
            for _ in 0..pieces {
                let (centroid, axis, omega, end) = arc(cas, &arm.f, &part);
                let centroid = bind3(cas, centroid);
                let turn = (axis, mid_arc_rotation(&arm.f, &part));
                arm.bodies.push(body.body(cas, turn, centroid, omega, body.m));
                arm.f = end;
            }
            arm.close_link(first);
        }
    }

    fn link_cells(&self) -> bool {
        true
    }

    fn points_on_links(&self, _g: &SegmentShape, _spatial: bool) -> Option<PointsOn> {
        Some(PointsOn::Arcs)
    }
}

/// A pcc element of length l bent by theta, by the chord construction:
/// turn theta/2, go the chord l sinc(theta/2), turn theta/2. Returns the
/// centroid of the arc, the chord's angular rate (the body's orientation),
/// the arc's rotational inertia about its centroid, and the end frame.
///
/// In the base frame's (axis, normal) coordinates, with S = sinc(theta/2)
/// and R = (theta - sin theta)/theta^3:
///
/// * centroid: l (1 - cos theta)/theta^2 = l S^2/2 along the axis,
///   l (theta - sin theta)/theta^2 = l theta R along the normal;
/// * mean squared distance of the arc from its base: 2 l^2 R;
///
/// so the inertia is m l^2 (2 R - S^4/4 - theta^2 R^2). Only sinc and
/// sinc_rem appear: theta = 0 is an ordinary point.
fn pcc_element(
    cas: &mut Cas,
    f: Frame,
    l: ExprId,
    m: ExprId,
    theta: ExprId,
    rate: ExprId,
) -> ([ExprId; 2], ExprId, ExprId, Frame) {
    let half_theta = cas.scaled(0.5, theta);
    let half_rate = cas.scaled(0.5, rate);
    let s = cas.sinc(half_theta);
    let s = cas.bind(s);
    let r = cas.func(Func::SincRem(0), theta);
    let r = cas.bind(r);
    // Centroid.
    let s2 = cas.powi(s, 2);
    let axis = cas.scaled(0.5, s2);
    let normal = cas.mul(theta, r);
    // Bound functions of theta alone: their rates are f'(theta) theta_dot.
    let (a, b) = (cas.mul(l, axis), cas.mul(l, normal));
    let (a, b) = (cas.bind(a), cas.bind(b));
    let c = planar::local(cas, &f, a, b);
    // Inertia of the arc about its centroid.
    let two_r = cas.scaled(2.0, r);
    let (a2, b2) = (cas.powi(axis, 2), cas.powi(normal, 2));
    let shape = cas.sub(two_r, a2);
    let shape = cas.sub(shape, b2);
    let l2 = cas.powi(l, 2);
    let arc = cas.mul_all(&[m, l2, shape]);
    // Chord and end frame.
    let chord = planar::rotate(cas, f, half_theta, half_rate);
    let len = cas.mul(l, s);
    let moved = planar::advance(cas, chord, len);
    let end = planar::rotate(cas, moved, half_theta, half_rate);
    (c, chord.w, cas.bind(arc), end)
}

/// The points at s = j/P (j = 1..P) of a planar arc, with the section's
/// angle there, of length l bent by
/// theta from frame f: the arc's first fraction s is the arc of length s l
/// bent by s theta, whose chord is s l sinc(s theta / 2) at the angle
/// phi + s theta / 2. With a = theta / (2P), c = cos a and u = e^{i a},
/// the chord directions are e^{i phi} u^j and
/// sinc(j a) = sinc(a) U_{j-1}(c) / j (Chebyshev's U: sin(j a) =
/// sin(a) U_{j-1}(cos a)), so the P points cost one sin_cos of phi, one of
/// a and one sinc, not P of each; theta = 0 is an ordinary point.
/// The frame at the fraction s of an arc of length l turning by theta
/// from frame f: at the chord s l sinc(s theta / 2) along the angle
/// phi + s theta / 2, turned by s theta.
fn arc_frame(cas: &mut Cas, f: Frame, l: ExprId, theta: ExprId, rate: ExprId, s: f64) -> Frame {
    let half = cas.scaled(0.5 * s, theta);
    let sinc = cas.sinc(half);
    let chord = cas.mul_all(&[l, sinc]);
    let chord = cas.scaled(s, chord);
    let dir = cas.add(f.phi, half);
    let (c, sn) = (cas.cos(dir), cas.sin(dir));
    let (dx, dy) = (cas.mul(chord, c), cas.mul(chord, sn));
    let turn = cas.scaled(s, theta);
    let turn_rate = cas.scaled(s, rate);
    Frame {
        x: cas.add(f.x, dx),
        y: cas.add(f.y, dy),
        phi: cas.add(f.phi, turn),
        w: cas.add(f.w, turn_rate),
    }
}

fn arc_points(
    cas: &mut Cas,
    f: Frame,
    l: ExprId,
    theta: ExprId,
    points: usize,
) -> Vec<([ExprId; 2], ExprId)> {
    let a = cas.scaled(0.5 / points as f64, theta);
    let (ca, sa) = (cas.cos(a), cas.sin(a));
    let (ca, sa) = (cas.bind(ca), cas.bind(sa));
    let sinc_a = cas.sinc(a);
    let sinc_a = cas.bind(sinc_a);
    let (cp, sp) = (cas.cos(f.phi), cas.sin(f.phi));
    let (cp, sp) = (cas.bind(cp), cas.bind(sp));
    // u^j = (re, im), U_{j-1}(c): running products.
    let (mut re, mut im) = (cp, sp);
    let one = cas.one();
    let two_c = cas.scaled(2.0, ca);
    let (mut u_prev, mut u) = (cas.zero(), one);
    let mut out = Vec::with_capacity(points);
    for j in 1..=points {
        // Direction e^{i (phi + j a)}, j = 1, 2, ...
        let (r1, r2) = (cas.mul(re, ca), cas.mul(im, sa));
        let (i1, i2) = (cas.mul(re, sa), cas.mul(im, ca));
        let next_re = cas.sub(r1, r2);
        let next_im = cas.add(i1, i2);
        re = cas.bind(next_re);
        im = cas.bind(next_im);
        // Chord length s l sinc(j a) = l sinc(a) U_{j-1}(c) / P.
        let len = cas.mul_all(&[l, sinc_a, u]);
        let len = cas.scaled(1.0 / points as f64, len);
        let len = cas.bind(len);
        let (dx, dy) = (cas.mul(len, re), cas.mul(len, im));
        // The section there is turned by s theta.
        let turn = cas.scaled(j as f64 / points as f64, theta);
        let angle = cas.add(f.phi, turn);
        out.push(([cas.add(f.x, dx), cas.add(f.y, dy)], angle));
        // U_j = 2 c U_{j-1} - U_{j-2}.
        let t = cas.mul(two_c, u);
        let next = cas.sub(t, u_prev);
        u_prev = u;
        u = cas.bind(next);
    }
    out
}

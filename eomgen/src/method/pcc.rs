//! `pcc`: piecewise constant curvature. Each element is an arc of
//! constant strain: in the plane one bending angle, by the chapter's chord
//! construction; in 3D a rotation vector (bend about y and z, optional
//! twist) and an optional stretch, R = exp([rho]x), with one body at the
//! arc's exact centroid turning with the mid-arc frame.

use super::{ModellingMethod, needs_bending_stiffness, strain_coordinate_names};
use crate::cas::{Cas, ExprId, Func};
use crate::model::{Check, ModelError, Segment, SegmentShape};
use crate::tmt::planar::{self, Element2, Frame, PlanarArm};
use crate::tmt::spatial::{SpatialArm, arc, bind3};

pub(super) struct Pcc;

impl ModellingMethod for Pcc {
    fn check_keys(&self, ck: &Check, i: usize, s: &Segment) -> Result<(), ModelError> {
        needs_bending_stiffness(ck, i, s)
    }

    fn coordinate_names(&self, g: &SegmentShape, s: usize) -> Vec<String> {
        strain_coordinate_names(g, s)
    }

    fn place_planar(&self, cas: &mut Cas, arm: &mut PlanarArm, _g: &SegmentShape, el: &Element2) {
        // The arc's first fraction s is the arc of length s l bent by s theta.
        let (f, l, m, q, qd) = (arm.f, el.l, el.m, el.q, el.qd);
        arm.sample(cas, |cas, s| {
            let [sl, sq, sqd] = [l, q, qd].map(|e| cas.scaled(s, e));
            let end = pcc_element(cas, f, sl, m, sq, sqd).3;
            [end.x, end.y]
        });
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
            let f = arm.f;
            arm.sample(cas, |cas, s| {
                let rho = st.rho.map(|e| cas.scaled(s, e));
                let rate = st.rate.map(|e| cas.scaled(s, e));
                let len = cas.scaled(s, st.len);
                arc(cas, &f, &rho, &rate, len).3.p
            });
            let (centroid, axis, omega, end) = arc(cas, &arm.f, &st.rho, &st.rate, st.len);
            let centroid = bind3(cas, centroid);
            arm.bodies.push(el.body(axis, centroid, omega, el.m));
            arm.f = end;
            arm.close_link(first);
        }
    }

    fn link_cells(&self) -> bool {
        true
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

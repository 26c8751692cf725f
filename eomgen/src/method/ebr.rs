//! `ebr`: Euler-Bernoulli elements with relative states. Each element is
//! half a rigid element, a joint that turns by exp([rho]x) (bend about y
//! and z, optional twist) and stretches, and the other half: two bodies
//! an element. 3D only.

use super::{
    Carried, ModellingMethod, half_links_inertia, needs_bending_stiffness, strain_coordinate_names,
};
use crate::cas::Cas;
use crate::cas::ExprId;
use crate::model::{Check, Joints, ModelError, Segment, SegmentShape};
use crate::tmt::cell_kind::CellKind;
use crate::tmt::spatial::{Frame, SpatialArm, V3, advance, compose, exp_turn};

pub(super) struct Ebr;

impl ModellingMethod for Ebr {
    fn joints(&self, _s: &Segment) -> Joints {
        Joints::Midpoint
    }

    fn shear(&self) -> Carried {
        Carried::Never
    }

    /// Two half links about the joint.
    fn element_inertia(
        &self,
        _s: &Segment,
        mass: f64,
        l: f64,
        section: f64,
        _dimensions: u8,
    ) -> (f64, f64) {
        half_links_inertia(mass, l, section)
    }

    fn cell_kind(&self, _g: &SegmentShape, _spatial: bool) -> CellKind {
        CellKind::PastJoint
    }

    fn spatial_only(&self) -> bool {
        true
    }

    fn check_keys(&self, ck: &Check, i: usize, s: &Segment) -> Result<(), ModelError> {
        needs_bending_stiffness(ck, i, s)
    }

    fn coordinate_names(&self, g: &SegmentShape, s: usize) -> Vec<String> {
        strain_coordinate_names(g, s)
    }

    /// Each element is two links of the recursion: the half before the
    /// joint (no coordinates) and the joint with the half past it.
    fn link_cells(&self) -> bool {
        true
    }

    fn build_spatial(&self, cas: &mut Cas, arm: &mut SpatialArm, g: &SegmentShape, s: usize) {
        for _ in 0..g.elements {
            let el = arm.element();
            let first = arm.c;
            let st = arm.strain_element(cas, g, s, &el);
            let (rho, rate) = (st.rho, st.rate);
            let (quarter, half) = (cas.scaled(0.25, el.l), cas.scaled(0.5, el.l));
            let half_m = cas.scaled(0.5, el.m);
            let f = arm.f;
            arm.sample(cas, None, |cas, s| {
                if s <= 0.5 {
                    let d = cas.scaled(s, el.l);
                    return advance(cas, &f, d);
                }
                // Past the joint: the turned half, stretched.
                let at_joint = advance(cas, &f, half);
                let (r, q, w) = exp_turn(cas, &rho, &rate);
                let joint = compose(cas, &at_joint, Some((&r, &q)), None, Some(&w));
                let b_len = cas.add(half, st.stretch);
                let d = cas.scaled(2.0 * (s - 0.5), b_len);
                advance(cas, &joint, d)
            });
            let (b, end) = before_joint(cas, &arm.f, quarter, half);
            arm.bodies.push(el.body(cas, arm.f.orientation(), b, arm.f.w, half_m));
            arm.f = end;
            let (b, joint, end) = past_joint(cas, &arm.f, &rho, &rate, half, st.stretch);
            arm.bodies.push(el.body(cas, joint.orientation(), b, joint.w, half_m));
            arm.f = end;
            arm.close_link(first);
        }
    }
}

/// The half of an ebr element before its joint, from frame `f`: its body's
/// centroid (a quarter element along) and the joint's frame (a half).
pub(crate) fn before_joint(cas: &mut Cas, f: &Frame, quarter: ExprId, half: ExprId) -> (V3, Frame) {
    let b = advance(cas, f, quarter);
    (b.p, advance(cas, f, half))
}

/// The part of an ebr element past its joint, from the joint's frame `f`:
/// the turn exp([rho]x), then the half element of length `half +
/// stretch`: its body's centroid, the joint's frame (the body turns with
/// it) and the end frame (as `spatial::arc` gives them for a pcc element).
pub(crate) fn past_joint(
    cas: &mut Cas,
    f: &Frame,
    rho: &V3,
    rate: &V3,
    half: ExprId,
    stretch: ExprId,
) -> (V3, Frame, Frame) {
    let (r_rel, q_rel, w_rel) = exp_turn(cas, rho, rate);
    let joint = compose(cas, f, Some((&r_rel, &q_rel)), None, Some(&w_rel));
    let b_len = cas.add(half, stretch);
    let half_b = cas.scaled(0.5, b_len);
    let b = advance(cas, &joint, half_b);
    let end = advance(cas, &joint, b_len);
    (b.p, joint, end)
}

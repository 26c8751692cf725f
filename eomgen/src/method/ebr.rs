//! `ebr`: Euler-Bernoulli elements with relative states. Each element is
//! half a rigid element, a joint that turns by exp([rho]x) (bend about y
//! and z, optional twist) and stretches, and the other half: two bodies
//! an element. 3D only.

use super::{ModellingMethod, needs_bending_stiffness, strain_coordinate_names};
use crate::cas::Cas;
use crate::model::{Check, ModelError, Segment, SegmentShape};
use crate::tmt::spatial::{
    SpatialArm, advance, coefficients, compose, left_jacobian, rotation, rotation_quat,
};

pub(super) struct Ebr;

impl ModellingMethod for Ebr {
    fn spatial_only(&self) -> bool {
        true
    }

    fn check_keys(&self, ck: &Check, i: usize, s: &Segment) -> Result<(), ModelError> {
        needs_bending_stiffness(ck, i, s)
    }

    fn coordinate_names(&self, g: &SegmentShape, s: usize) -> Vec<String> {
        strain_coordinate_names(g, s)
    }

    fn build_spatial(&self, cas: &mut Cas, arm: &mut SpatialArm, g: &SegmentShape, s: usize) {
        for _ in 0..g.elements {
            let el = arm.element();
            let first = arm.c;
            let st = arm.strain_element(cas, g, s, &el);
            let (rho, rate) = (st.rho, st.rate);
            let (quarter, half) = (cas.scaled(0.25, el.l), cas.scaled(0.5, el.l));
            let half_m = cas.scaled(0.5, el.m);
            let b = advance(cas, &arm.f, quarter);
            arm.bodies.push(el.body(arm.f.axis(), b.p, arm.f.w, half_m));
            arm.advance(cas, half);
            let wsq = cas.dot(&rho, &rho);
            let wsq = cas.bind(wsq);
            let [c0, c1, c2, c3] = coefficients(cas, wsq, [0, 1, 2, 3]);
            let r_rel = rotation(cas, &rho, [c0, c1, c2]);
            let w_rel = left_jacobian(cas, &rho, &rate, [c1, c2, c3]);
            let q_rel = rotation_quat(cas, &rho, wsq);
            arm.f = compose(cas, &arm.f, Some((&r_rel, &q_rel)), None, Some(&w_rel));
            let b_len = cas.add(half, st.stretch);
            let half_b = cas.scaled(0.5, b_len);
            let b = advance(cas, &arm.f, half_b);
            arm.bodies.push(el.body(arm.f.axis(), b.p, arm.f.w, half_m));
            arm.advance(cas, b_len);
            arm.close_link(first);
        }
    }
}

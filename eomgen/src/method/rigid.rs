//! `rigid`: a chain of rigid links joined by revolute joints, at the base
//! of each link (a pendulum chain) or at its middle (Hencky's
//! pseudo-rigid-body model of a rod: half a link at the clamp and the
//! tip). In 3D each joint turns about the element frame's axes in
//! sequence (a universal or spherical joint).

use super::{Carried, ModellingMethod, half_links_inertia};
use crate::cas::{Cas, ExprId};
use crate::model::{Axis, Check, ElementParam, Joints, ModelError, Segment, SegmentShape};
use crate::tmt::actuation::Strain;
use crate::tmt::planar::{self, Element2, PlanarArm};
use crate::tmt::spatial::{Frame, SpatialArm, advance, compose, exp_turn, half_k_sq, revolute};

pub(super) struct Rigid;

impl ModellingMethod for Rigid {
    fn joints(&self, s: &Segment) -> Joints {
        s.joint_placement()
    }

    fn joint_axes(&self, s: &Segment) -> Vec<Axis> {
        s.axes()
    }

    fn coordinates_per_element(&self, g: &SegmentShape) -> usize {
        g.axes.len()
    }

    /// Its twist is a joint axis, not a strain coordinate.
    fn twist(&self) -> Carried {
        Carried::Never
    }

    fn stretch(&self) -> Carried {
        Carried::Never
    }

    fn shear(&self) -> Carried {
        Carried::Never
    }

    fn twisting(&self, s: &Segment) -> bool {
        s.axes().contains(&Axis::X)
    }

    /// The whole link, or two half links at midpoint joints.
    fn element_inertia(
        &self,
        s: &Segment,
        mass: f64,
        l: f64,
        section: f64,
        _dimensions: u8,
    ) -> (f64, f64) {
        match s.joint_placement() {
            Joints::Midpoint => half_links_inertia(mass, l, section),
            Joints::Base => (mass * l * l / 12.0 + section, 2.0 * section),
        }
    }

    fn own_keys(&self) -> &'static [&'static str] {
        &["joint_stiffness", "joint_damping", "joints", "joint_axes"]
    }

    fn check_keys(&self, ck: &Check, i: usize, s: &Segment) -> Result<(), ModelError> {
        let p = |k: &str| format!("segment[{i}].{k}");
        if let Some(k) = s.joint_stiffness {
            ck.non_negative(&p("joint_stiffness"), k)?;
            if s.ei().is_some() {
                return ck.err(
                    p("joint_stiffness"),
                    "give either `joint_stiffness` or the continuum's `youngs_modulus`/`bending_stiffness` (joint stiffness E I / l_e), not both".into(),
                );
            }
        }
        if let Some(c) = s.joint_damping {
            ck.non_negative(&p("joint_damping"), c)?;
            if s.bending_damping.is_some() {
                return ck.err(
                    p("joint_damping"),
                    "give either `joint_damping` or `bending_damping`, not both".into(),
                );
            }
        }
        Ok(())
    }

    fn coordinate_names(&self, g: &SegmentShape, s: usize) -> Vec<String> {
        let mut names = Vec::new();
        for e in 0..g.elements {
            for a in &g.axes {
                names.push(format!("joint_{a:?}_{s}_{e}").to_lowercase());
            }
        }
        names
    }

    fn place_planar(&self, cas: &mut Cas, arm: &mut PlanarArm, g: &SegmentShape, el: &Element2) {
        let (l, m) = (el.l, el.m);
        match g.joints {
            Joints::Base => {
                arm.f = planar::rotate(cas, arm.f, el.q, el.qd);
                let f = arm.f;
                arm.sample(cas, None, |cas, s| {
                    let d = cas.scaled(s, l);
                    planar::advance(cas, f, d)
                });
                let half = cas.scaled(0.5, l);
                let c = planar::along(cas, &arm.f, half);
                arm.body(cas, c, arm.f.w, m, el.inertia);
                arm.f = planar::advance(cas, arm.f, l);
            }
            Joints::Midpoint => {
                let (quarter, half) = (cas.scaled(0.25, l), cas.scaled(0.5, l));
                let half_m = cas.scaled(0.5, m);
                let f = arm.f;
                arm.sample(cas, None, |cas, s| {
                    if s <= 0.5 {
                        let d = cas.scaled(s, l);
                        return planar::advance(cas, f, d);
                    }
                    let mid = planar::advance(cas, f, half);
                    let turned = planar::rotate(cas, mid, el.q, el.qd);
                    let d = cas.scaled(s - 0.5, l);
                    planar::advance(cas, turned, d)
                });
                let c = planar::along(cas, &arm.f, quarter);
                arm.body(cas, c, arm.f.w, half_m, el.inertia);
                arm.f = planar::advance(cas, arm.f, half);
                arm.f = planar::rotate(cas, arm.f, el.q, el.qd);
                let c = planar::along(cas, &arm.f, quarter);
                arm.body(cas, c, arm.f.w, half_m, el.inertia);
                arm.f = planar::advance(cas, arm.f, half);
            }
        }
    }

    fn build_spatial(&self, cas: &mut Cas, arm: &mut SpatialArm, g: &SegmentShape, s: usize) {
        for _ in 0..g.elements {
            let el = arm.element();
            let first = arm.c;
            let (l, m) = (el.l, el.m);
            match g.joints {
                Joints::Base => {
                    arm.f = joint(cas, arm, g, s);
                    let f = arm.f;
                    arm.sample(cas, None, |cas, s| {
                        let d = cas.scaled(s, l);
                        advance(cas, &f, d)
                    });
                    let half = cas.scaled(0.5, l);
                    let mid = advance(cas, &arm.f, half);
                    arm.bodies.push(el.body(cas, arm.f.orientation(), mid.p, arm.f.w, m));
                    arm.advance(cas, l);
                }
                Joints::Midpoint => {
                    let (quarter, half) = (cas.scaled(0.25, l), cas.scaled(0.5, l));
                    let half_m = cas.scaled(0.5, m);
                    let b = advance(cas, &arm.f, quarter);
                    arm.bodies.push(el.body(cas, arm.f.orientation(), b.p, arm.f.w, half_m));
                    let f = arm.f;
                    arm.advance(cas, half);
                    arm.f = joint(cas, arm, g, s);
                    let turned = arm.f;
                    arm.sample(cas, None, |cas, s| {
                        let (from, d) = if s <= 0.5 {
                            (&f, s)
                        } else {
                            (&turned, s - 0.5)
                        };
                        let d = cas.scaled(d, l);
                        advance(cas, from, d)
                    });
                    let b = advance(cas, &arm.f, quarter);
                    arm.bodies.push(el.body(cas, arm.f.orientation(), b.p, arm.f.w, half_m));
                    arm.advance(cas, half);
                }
            }
            arm.close_link(first);
        }
    }
}

/// The rotation vector of turns about coordinate axes in sequence, to
/// second order in the angles: sum q_i e_i + 1/2 sum_{i<j} q_i q_j e_i x e_j.
fn rotation_vector(cas: &mut Cas, turns: &[(usize, ExprId)], zero: ExprId) -> [ExprId; 3] {
    let mut theta = [zero; 3];
    for (i, &(a, q)) in turns.iter().enumerate() {
        theta[a] = cas.add(theta[a], q);
        for &(b, r) in &turns[i + 1..] {
            // e_a x e_b = +-e_c for a != b (c the third axis), 0 for a == b.
            if a == b {
                continue;
            }
            let c = 3 - a - b;
            let sign = if (a + 1) % 3 == b { 0.5 } else { -0.5 };
            let qr = cas.mul(q, r);
            let term = cas.scaled(sign, qr);
            theta[c] = cas.add(theta[c], term);
        }
    }
    theta
}

/// The end frame turned by the element's joint: first by its rest angle
/// about z, then by its angles about their axes in sequence. Its springs
/// (twist about x, bend about y and z) and dampers act on the rotation
/// vector of the turn from rest, to second order (Baker-Campbell-Hausdorff:
/// theta = sum q_i e_i + 1/2 sum_{i<j} q_i q_j e_i x e_j), about the axes
/// the joint has. Springs on the angles themselves, with the rest angle
/// taken from the angle about z, made the chain converge at first order,
/// to an answer that depended on the order of the axes. The joint's lumped
/// strain is its angles (exact for one axis, first order for several).
fn joint(cas: &mut Cas, arm: &mut SpatialArm, g: &SegmentShape, s: usize) -> Frame {
    let e = |p| arm.symbols.element(arm.k, p);
    let (stiff, twist) = (
        e(ElementParam::BendStiffness),
        e(ElementParam::TwistStiffness),
    );
    let (damp, rest) = (e(ElementParam::BendDamping), e(ElementParam::Rest));
    let stiff_y = (arm.symbols).element_or(arm.k, ElementParam::BendStiffnessY, stiff);
    let zero = arm.zero;
    // Half the rest turn before the joint and half after: its angles are
    // then measured in the frame midway between its links, as a rod's
    // strains are at that point (measured in the incoming link's frame,
    // the twist and bend of a curved rod mixed at first order).
    // A 3D rest shape turns it by the rotation vector (twist, bend y, bend
    // z) at rest, as a whole.
    let rest_3d = g
        .rest_3d
        .then(|| [ElementParam::RestTwist, ElementParam::RestY, ElementParam::Rest].map(e));
    let half_turn = |cas: &mut Cas, f: &Frame| -> Frame {
        let Some(rho) = rest_3d else {
            let half_rest = cas.scaled(0.5, rest);
            return revolute(cas, f, 2, half_rest, zero);
        };
        let rho = rho.map(|r| cas.scaled(0.5, r));
        let (r, q, _) = exp_turn(cas, &rho, &[zero; 3]);
        compose(cas, f, Some((&r, &q)), None, None)
    };
    let mut f = half_turn(cas, &arm.f);
    let mut rho = [zero; 3];
    let mut turns: Vec<(usize, ExprId)> = Vec::new();
    for &a in &g.axes {
        let (q, qd) = arm.take();
        rho[a.index()] = cas.add(rho[a.index()], q);
        f = revolute(cas, &f, a.index(), q, qd);
        arm.rayleigh.push(half_k_sq(cas, damp, qd));
        turns.push((a.index(), q));
    }
    f = half_turn(cas, &f);
    let theta = rotation_vector(cas, &turns, zero);
    for (k, &th) in theta.iter().enumerate() {
        if turns.iter().any(|&(a, _)| a == k) {
            let kq = match k {
                0 => twist,
                1 => stiff_y,
                _ => stiff,
            };
            arm.elastic.push(half_k_sq(cas, kq, th));
        }
    }
    arm.strains.push(Strain {
        segment: s,
        element: arm.k,
        stretch: zero,
        rho,
        offset_scale: None,
    });
    f
}

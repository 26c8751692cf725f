//! `rigid`: a chain of rigid links joined by revolute joints, at the base
//! of each link (a pendulum chain) or at its middle (Hencky's
//! pseudo-rigid-body model of a rod: half a link at the clamp and the
//! tip). In 3D each joint turns about the element frame's axes in
//! sequence (a universal or spherical joint).

use super::{Carried, ModellingMethod, half_links_inertia};
use crate::cas::{Cas, ExprId};
use crate::model::{Axis, Check, ElementParam, Joints, ModelError, Segment, SegmentShape};
use crate::tmt::actuation::Strain;
use crate::tmt::cell_kind::{CellKind, PointsOn};
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

    /// Each element's joint and the link past it are one link cell, after
    /// a cell of its first half at a midpoint joint.
    fn link_cells(&self) -> bool {
        true
    }

    /// A joint and the link past it, in space and in the plane (there
    /// about z alone).
    fn cell_kind(&self, g: &SegmentShape, _spatial: bool) -> CellKind {
        let mut axes = [None; 3];
        for (slot, &a) in axes.iter_mut().zip(&g.axes) {
            *slot = Some(a);
        }
        CellKind::Revolute {
            axes,
            whole: g.joints == Joints::Base,
        }
    }

    /// Each link turns at its joint and is straight past it.
    fn points_on_links(&self, _g: &SegmentShape, _spatial: bool) -> Option<PointsOn> {
        Some(PointsOn::Straight)
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
                let half = cas.scaled(0.5, l);
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
                planar_half(cas, arm, el, false);
                planar_half(cas, arm, el, true);
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

/// Half a planar element about its midpoint joint: the joint's turn
/// first where `past`, then the half link, its body (half the element's
/// mass, its centroid a quarter of the element along) and its end. The
/// arm's elements and the link cells of the halves (`build::planar_cell`)
/// are these two.
pub(crate) fn planar_half(cas: &mut Cas, arm: &mut PlanarArm, el: &Element2, past: bool) {
    if past {
        arm.f = planar::rotate(cas, arm.f, el.q, el.qd);
    }
    let (quarter, half) = (cas.scaled(0.25, el.l), cas.scaled(0.5, el.l));
    let half_m = cas.scaled(0.5, el.m);
    let c = planar::along(cas, &arm.f, quarter);
    arm.body(cas, c, arm.f.w, half_m, el.inertia);
    arm.f = planar::advance(cas, arm.f, half);
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

/// The end frame turned by the element's joint (`joint_turn`), its
/// springs, dampers and lumped strain added to the arm.
fn joint(cas: &mut Cas, arm: &mut SpatialArm, g: &SegmentShape, s: usize) -> Frame {
    let e = |p| arm.symbols.element(arm.k, p);
    let stiff = e(ElementParam::BendStiffness);
    let springs = JointSprings {
        twist: e(ElementParam::TwistStiffness),
        bend_y: (arm.symbols).element_or(arm.k, ElementParam::BendStiffnessY, stiff),
        bend: stiff,
        damping: e(ElementParam::BendDamping),
    };
    let rest = match g.rest_3d {
        true => RestTurn::Vector([ElementParam::RestTwist, ElementParam::RestY, ElementParam::Rest].map(e)),
        false => RestTurn::AboutZ(e(ElementParam::Rest)),
    };
    let angles: Vec<(ExprId, ExprId)> = g.axes.iter().map(|_| arm.take()).collect();
    let turn = joint_turn(cas, &arm.f, (&g.axes, &angles), rest, springs);
    arm.rayleigh.extend(turn.rayleigh);
    arm.elastic.extend(turn.elastic);
    let zero = arm.zero;
    arm.strains.push(Strain {
        segment: s,
        element: arm.k,
        stretch: zero,
        rho: turn.rho,
        offset_scale: None,
    });
    turn.frame
}

/// A rigid joint's rest turn: about z by an angle, or (a 3D rest shape)
/// by the rotation vector (twist, bend y, bend z).
pub(crate) enum RestTurn {
    AboutZ(ExprId),
    Vector([ExprId; 3]),
}

/// A rigid joint's springs (about x, y and z) and the damping on each of
/// its angles' rates.
pub(crate) struct JointSprings {
    pub twist: ExprId,
    pub bend_y: ExprId,
    pub bend: ExprId,
    pub damping: ExprId,
}

/// A rigid joint's turned frame, its strain energy and Rayleigh function
/// (as terms) and its lumped strain (the angles summed by axis).
pub(crate) struct JointTurn {
    pub frame: Frame,
    pub elastic: Vec<ExprId>,
    pub rayleigh: Vec<ExprId>,
    pub rho: [ExprId; 3],
}

/// Frame `f` turned by a joint: half its rest turn, then its angles
/// (`angles`, each with its rate) about their `axes` in sequence, then the
/// other half. Its springs (twist about x, bend about y and z) and
/// dampers act on the rotation vector of the turn from rest, to second
/// order (Baker-Campbell-Hausdorff: theta = sum q_i e_i + 1/2 sum_{i<j}
/// q_i q_j e_i x e_j), about the axes the joint has. Springs on the angles
/// themselves, with the rest angle taken from the angle about z, made the
/// chain converge at first order, to an answer that depended on the order
/// of the axes. The joint's lumped strain is its angles (exact for one
/// axis, first order for several). The arm's elements and a link cell
/// (`build::cell`) turn by this one joint.
pub(crate) fn joint_turn(
    cas: &mut Cas,
    f: &Frame,
    (axes, angles): (&[Axis], &[(ExprId, ExprId)]),
    rest: RestTurn,
    springs: JointSprings,
) -> JointTurn {
    let zero = cas.zero();
    // Half the rest turn before the joint and half after: its angles are
    // then measured in the frame midway between its links, as a rod's
    // strains are at that point (measured in the incoming link's frame,
    // the twist and bend of a curved rod mixed at first order).
    let half_turn = |cas: &mut Cas, f: &Frame| -> Frame {
        match rest {
            RestTurn::AboutZ(rest) => {
                let half_rest = cas.scaled(0.5, rest);
                revolute(cas, f, 2, half_rest, zero)
            }
            RestTurn::Vector(rho) => {
                let rho = rho.map(|r| cas.scaled(0.5, r));
                let (r, q, _) = exp_turn(cas, &rho, &[zero; 3]);
                compose(cas, f, Some((&r, &q)), None, None)
            }
        }
    };
    let mut frame = half_turn(cas, f);
    let mut rho = [zero; 3];
    let mut turns: Vec<(usize, ExprId)> = Vec::new();
    let mut rayleigh = Vec::new();
    for (&a, &(q, qd)) in axes.iter().zip(angles) {
        rho[a.index()] = cas.add(rho[a.index()], q);
        frame = revolute(cas, &frame, a.index(), q, qd);
        rayleigh.push(half_k_sq(cas, springs.damping, qd));
        turns.push((a.index(), q));
    }
    let frame = half_turn(cas, &frame);
    let theta = rotation_vector(cas, &turns, zero);
    let mut elastic = Vec::new();
    for (k, &th) in theta.iter().enumerate() {
        if turns.iter().any(|&(a, _)| a == k) {
            let kq = match k {
                0 => springs.twist,
                1 => springs.bend_y,
                _ => springs.bend,
            };
            elastic.push(half_k_sq(cas, kq, th));
        }
    }
    JointTurn {
        frame,
        elastic,
        rayleigh,
        rho,
    }
}

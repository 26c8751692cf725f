//! `eba`: Euler-Bernoulli elements with absolute states.
//!
//! Element i is a rigid straight slice with six coordinates of its own: the
//! displacement u_i of its centre from the straight arm and the rotation
//! vector psi_i of its orientation, R_i = R0 exp([psi_i]x) (components in
//! the base frame), so q = 0 is the straight arm and its Jacobian has full
//! rank there. Nothing is chained: each body depends on its own six
//! coordinates only, M is block diagonal, and the elements hold together by
//! beam springs between neighbours (the clamp counting as element -1):
//!
//! * rotation: v = 2 tan(theta / 2) n of R_rel = R_a^T R_b (theta, n its
//!   angle and axis; a rational function of R_rel), with E I / span about the two
//!   section axes and G J / span about the element, span = l_e between
//!   centres (l_e / 2 from the clamp to the first);
//! * translation: the gap from the end of one element to the start of the
//!   next, in the first one's frame, with E A / l_e along it and G A / l_e
//!   across: the rod's axial and shear compliance.
//!
//! A finite-difference rod (strains between element centres) that converges
//! to the extensible, shearable Cosserat rod as l_e -> 0.
//!
//! A rest shape (curvature, twist, stretch) is placed rather than measured:
//! element k sits turned by A_k = A_{k-1} exp(rho_{k-1} / 2) exp(rho_k / 2)
//! (rho_k its rest turn, the rest strains times l_e), R_k = R0 A_k
//! exp([psi_k]x), its centre at the rest centre plus u_k, so q = 0 is the
//! rest shape still. The springs measure the turn from rest in the frame
//! midway between two elements, exp(-rho_a / 2) R_a^T R_b exp(-rho_b / 2)
//! (the clamp turning by nothing), and the gap from its rest length
//! (rho_a's and rho_b's half stretches) along the previous axis.

use runtime::Tape;
use runtime::parts::{PartKernels, PartLayout, PartSpec};

use super::{Carried, Method, ModellingMethod, needs_bending_stiffness};
use crate::cas::{Cas, ExprId, SymKind};
use crate::model::{
    Check, ElementParam, FluidParam, ModelError, Param, ParamLayout, Segment, SegmentShape,
    Structure, Xyz,
};
use crate::tmt::actuation::{ActuationLoads, Strain, actuation, strain_work, thinning};
use crate::tmt::along::{self, Applied, Drag, along_loads};
use crate::tmt::assemble;
use crate::tmt::spatial::{
    Element3,
    M3, Quat, V3, add3, base_frame, bind3, coefficients, exp_turn, half_k_sq, left_jacobian,
    quat_mul, rotation, rotation_quat,
};
use crate::tmt::system::{
    Body, Coordinates, Inertia, ParamSymbols, PointForce, Sample, System, TipMount, tip_loads,
};

pub(super) struct Eba;

impl ModellingMethod for Eba {
    fn twist(&self) -> Carried {
        Carried::Always
    }

    fn stretch(&self) -> Carried {
        Carried::Always
    }

    fn shear(&self) -> Carried {
        Carried::Always
    }

    fn segment_end_frames(&self) -> bool {
        false
    }

    /// Element e's springs join it to element e - 1, from centre to centre:
    /// they sit at its start (the first element's, from the base to its
    /// centre, a quarter along it).
    fn spring_at(&self, e: usize) -> f64 {
        if e == 0 { 0.25 } else { 0.0 }
    }

    fn spatial_only(&self) -> bool {
        true
    }

    /// Its coordinates are measured from the placed rest shape.
    fn rest_always_3d(&self) -> bool {
        true
    }

    fn check_keys(&self, ck: &Check, i: usize, s: &Segment) -> Result<(), ModelError> {
        let p = |k: &str| format!("segment[{i}].{k}");
        needs_bending_stiffness(ck, i, s)?;
        if ck.m.segments.iter().any(|o| o.method != Method::Eba) {
            return ck.err(
                p("method"),
                "eba segments take absolute coordinates: every segment of the arm must be eba"
                    .into(),
            );
        }
        if s.kinked() {
            return ck.err(
                p(if s.turn.is_some() { "turn" } else { "offset" }),
                "eba segments meet tangent: kinks are for the chain methods (pcc, vc, pcs, ebr, rom, rigid)".into(),
            );
        }
        if s.ea().is_none() || s.ga().is_none() {
            return ck.err(
                p("youngs_modulus"),
                "missing: eba couples elements by axial and shear springs: give `youngs_modulus` with `outer_radius`".into(),
            );
        }
        Ok(())
    }

    fn coordinate_names(&self, g: &SegmentShape, s: usize) -> Vec<String> {
        let mut names = Vec::new();
        for e in 0..g.elements {
            for c in ["ux", "uy", "uz", "rx", "ry", "rz"] {
                names.push(format!("{c}_{s}_{e}"));
            }
        }
        names
    }

    /// Every segment of an eba arm is eba (validated): the arm is built
    /// here whole, its elements held by beam springs instead of chained.
    fn whole_arm(&self, cas: &mut Cas, st: &Structure, symbols: &ParamSymbols) -> Option<System> {
        Some(absolute_system(cas, st, symbols))
    }
}

/// An element's (or the clamp's) frame: rotation, centre and half length.
struct Slab {
    r: M3,
    centre: V3,
    half: ExprId,
}

impl Slab {
    /// The point at `sign` half lengths along the axis from the centre.
    fn end(&self, cas: &mut Cas, sign: f64) -> V3 {
        let d = cas.scaled(sign, self.half);
        let axis = [self.r[0][0], self.r[1][0], self.r[2][0]];
        std::array::from_fn(|k| {
            let t = cas.mul(d, axis[k]);
            cas.add(self.centre[k], t)
        })
    }
}

fn transpose_mul(cas: &mut Cas, a: &M3, b: &M3) -> M3 {
    std::array::from_fn(|i| {
        std::array::from_fn(|j| {
            let ai = [a[0][i], a[1][i], a[2][i]];
            let bj = [b[0][j], b[1][j], b[2][j]];
            cas.dot(&ai, &bj)
        })
    })
}

/// a b.
fn mul3(cas: &mut Cas, a: &M3, b: &M3) -> M3 {
    std::array::from_fn(|i| {
        std::array::from_fn(|j| {
            let bj = [b[0][j], b[1][j], b[2][j]];
            let e = cas.dot(&a[i], &bj);
            cas.bind(e)
        })
    })
}

/// a b^T.
fn mul3_t(cas: &mut Cas, a: &M3, b: &M3) -> M3 {
    std::array::from_fn(|i| {
        std::array::from_fn(|j| {
            let e = cas.dot(&a[i], &b[j]);
            cas.bind(e)
        })
    })
}

/// Half an element's rest turn, exp(rho / 2) (rho its rest twist and bends
/// times its length), and half its rest stretch (times its length).
#[derive(Clone, Copy)]
struct HalfRest {
    r: M3,
    quat: Quat,
    stretch: ExprId,
}

impl HalfRest {
    fn of(cas: &mut Cas, symbols: &ParamSymbols, k: usize, shaped: bool) -> Self {
        if !shaped {
            return Self::none(cas);
        }
        let e = |p| symbols.element(k, p);
        let rho = [
            ElementParam::RestTwist,
            ElementParam::RestY,
            ElementParam::Rest,
        ]
        .map(|p| cas.scaled(0.5, e(p)));
        let zero = cas.zero();
        let (r, quat, _) = exp_turn(cas, &rho, &[zero; 3]);
        let stretch = cas.scaled(0.5, e(ElementParam::RestStretch));
        Self { r, quat, stretch }
    }

    /// A straight element's (and the clamp's).
    fn none(cas: &mut Cas) -> Self {
        let (zero, one) = (cas.zero(), cas.one());
        let r = std::array::from_fn(|i| std::array::from_fn(|j| if i == j { one } else { zero }));
        Self {
            r,
            quat: [one, zero, zero, zero],
            stretch: zero,
        }
    }
}

/// The rest shape placed element by element, in the base frame.
struct RestPlacement {
    /// The rest frame at the previous joint (A_{k-1} exp(rho_{k-1} / 2);
    /// the clamp's: I), and its quaternion.
    joint: M3,
    joint_quat: Quat,
    /// The previous element's axis, half length and half rest turn.
    axis: V3,
    half: ExprId,
    turn: Option<HalfRest>,
    /// The previous element's rest centre (the clamp point first).
    centre: V3,
}

/// Element k's rest placement.
struct Placed {
    /// Its rest orientation A_k and its quaternion.
    a: M3,
    quat: Quat,
    /// Its rest centre, and the offset from the previous one.
    centre: V3,
    step: V3,
    /// What its springs to the previous element measure from.
    joint: RestJoint,
}

/// The rest of the springs between two elements: the previous element's
/// half turn (none at the clamp), this one's, and the gap's rest length.
struct RestJoint {
    before: Option<M3>,
    after: M3,
    gap: ExprId,
}

impl RestPlacement {
    fn new(cas: &mut Cas) -> Self {
        let (zero, one) = (cas.zero(), cas.one());
        let none = HalfRest::none(cas);
        Self {
            joint: none.r,
            joint_quat: none.quat,
            axis: [one, zero, zero],
            half: zero,
            turn: None,
            centre: [zero; 3],
        }
    }

    /// Places the next element, of half length `half`, turned `turn`.
    fn next(&mut self, cas: &mut Cas, turn: HalfRest, half: ExprId) -> Placed {
        let a = mul3(cas, &self.joint, &turn.r);
        let quat = quat_mul(cas, &self.joint_quat, &turn.quat);
        let gap = match self.turn {
            Some(t) => cas.add(t.stretch, turn.stretch),
            None => turn.stretch,
        };
        let reach = cas.add(self.half, gap);
        let step: V3 = std::array::from_fn(|i| {
            let before = cas.mul(reach, self.axis[i]);
            let after = cas.mul(half, a[i][0]);
            cas.add(before, after)
        });
        let step = bind3(cas, step);
        let centre = add3(cas, &self.centre, &step);
        let centre = bind3(cas, centre);
        let joint = RestJoint {
            before: self.turn.map(|t| t.r),
            after: turn.r,
            gap,
        };
        self.joint = mul3(cas, &a, &turn.r);
        self.joint_quat = quat_mul(cas, &quat, &turn.quat);
        self.axis = [a[0][0], a[1][0], a[2][0]];
        self.half = half;
        self.turn = Some(turn);
        self.centre = centre;
        Placed {
            a,
            quat,
            centre,
            step,
            joint,
        }
    }
}

/// Where element k rests, from the base frame (rotation `r0`, quaternion
/// `q0`): its centre's offset from the previous one's (from the clamp
/// point for the first) and from the clamp point, and the frame its
/// rotation vector turns (R0 A_k) with its quaternion. Straight, or placed
/// on the rest shape.
struct RestPose {
    step: V3,
    centre: V3,
    r: M3,
    quat: Quat,
}

impl RestPose {
    fn of(
        cas: &mut Cas,
        (r0, q0): (&M3, &Quat),
        placed: Option<&Placed>,
        [prev_half, half]: [ExprId; 2],
        along: ExprId,
    ) -> Self {
        let base_axis = [r0[0][0], r0[1][0], r0[2][0]];
        let Some(p) = placed else {
            let gap = cas.add(prev_half, half);
            let step = base_axis.map(|a| cas.mul(gap, a));
            let s_mid = cas.add(along, half);
            let centre = base_axis.map(|a| cas.mul(s_mid, a));
            return Self {
                step,
                centre,
                r: *r0,
                quat: *q0,
            };
        };
        let turned = |cas: &mut Cas, v: &V3| {
            let w = std::array::from_fn(|i| cas.dot(&r0[i], v));
            bind3(cas, w)
        };
        Self {
            step: turned(cas, &p.step),
            centre: turned(cas, &p.centre),
            r: mul3(cas, r0, &p.a),
            quat: quat_mul(cas, q0, &p.quat),
        }
    }
}

fn absolute_system(cas: &mut Cas, structure: &Structure, symbols: &ParamSymbols) -> System {
    let coords = Coordinates::new(cas, super::coordinate_names(structure));
    let zero = cas.zero();
    // The base frame, moving when prescribed: the absolute states are then
    // measured from the moving base's straight arm.
    let base = symbols.base_motion(cas);
    let frame = base_frame(cas, symbols, &base);
    let (r0, p0, w0) = (frame.r, frame.p, frame.w);
    // Rates (of the damping) relative to a moving base, too.
    let mut pairs = coords.rate_pairs();
    pairs.extend(&base.seeds);

    let (mut bodies, mut elastic, mut rayleigh) = (Vec::new(), Vec::new(), Vec::new());
    let mut prev = Slab {
        r: r0,
        centre: p0,
        half: zero,
    };
    let mut along = zero; // arc length to the current element's start
    let mut omega = [zero; 3];
    let q0 = frame.quat;
    let mut quat = q0;
    let segment_of: Vec<usize> = structure
        .segments
        .iter()
        .enumerate()
        .flat_map(|(s, g)| std::iter::repeat_n(s, g.elements))
        .collect();
    let (mut strains, mut samples) = (Vec::new(), Vec::new());
    let curved = structure.segments.iter().any(|g| g.rest_3d);
    let mut placed = curved.then(|| RestPlacement::new(cas));
    let mut slab_loads = SlabLoads::of(cas, structure, symbols);
    for (k, &segment) in segment_of.iter().enumerate() {
        let c = 6 * k;
        let u: V3 = std::array::from_fn(|i| coords.q[c + i]);
        let psi: V3 = std::array::from_fn(|i| coords.q[c + 3 + i]);
        let psi_d: V3 = std::array::from_fn(|i| coords.qd[c + 3 + i]);
        let l = symbols.element(k, ElementParam::Length);
        let half = cas.scaled(0.5, l);
        // The rest centre's offset from the previous one (from the clamp
        // point for the first), in the base frame: straight, or placed.
        let rest = placed.as_mut().map(|p| {
            let turn = HalfRest::of(cas, symbols, k, structure.segments[segment].rest_3d);
            p.next(cas, turn, half)
        });
        let at = RestPose::of(cas, (&r0, &q0), rest.as_ref(), [prev.half, half], along);
        let centre: V3 = std::array::from_fn(|i| cas.add_all(&[p0[i], at.centre[i], u[i]]));
        let centre = bind3(cas, centre);
        along = cas.add(along, l);
        let (step, r_rest) = (at.step, at.r);
        let (r, element_omega, q_rel) = element_frame(cas, &r_rest, &w0, &psi, &psi_d);
        quat = quat_mul(cas, &at.quat, &q_rel);
        omega = element_omega;
        let axis = [r[0][0], r[1][0], r[2][0]];
        slab_samples(cas, structure.contact_points, l, centre, axis, quat, &mut samples);
        let e = |p| symbols.element(k, p);
        let lateral = e(ElementParam::Inertia);
        let el = Element3 {
            l,
            m: e(ElementParam::Mass),
            lateral,
            lateral_y: symbols.element_or(k, ElementParam::InertiaY, lateral),
            axial: e(ElementParam::AxialInertia),
        };
        bodies.push(el.body(cas, (axis, move |_: &mut Cas| r), centre, omega, el.m));
        let slab = Slab { r, centre, half };
        slab_loads.on(cas, (k, &slab, omega), &pairs, symbols);

        // Beam springs to the previous element (or the clamp), on centres
        // relative to the previous element's rest centre: the gap between
        // element ends is then no difference of positions along the whole
        // arm (whose round-off grows with the arm's length), and the same
        // expression as the joint's part (`joint_part`).
        let incompressible = structure.segments[segment].incompressible;
        let mut jp = JointParams::of(symbols, k);
        jp.kb_y = symbols.element_or(k, ElementParam::BendStiffnessY, jp.kb);
        jp.ks_z = symbols.element_or(k, ElementParam::ShearStiffnessZ, jp.ks);
        let prev_rel = Slab {
            r: prev.r,
            centre: if k == 0 {
                [zero; 3]
            } else {
                bind3(cas, std::array::from_fn(|i| coords.q[c - 6 + i]))
            },
            half: prev.half,
        };
        let rel_centre: V3 = std::array::from_fn(|i| cas.add(step[i], u[i]));
        let slab_rel = Slab {
            r: slab.r,
            centre: bind3(cas, rel_centre),
            half,
        };
        let joint = beam_springs(
            cas,
            &jp,
            k == 0,
            (&prev_rel, &slab_rel),
            rest.as_ref().map(|r| &r.joint),
            incompressible,
            &pairs,
        );
        strains.push(Strain {
            segment,
            element: k,
            ..joint.strain
        });
        elastic.extend(joint.elastic);
        rayleigh.extend(joint.rayleigh);
        prev = slab;
    }

    let tip = prev.end(cas, 1.0);
    let tip = bind3(cas, tip);
    let elastic = cas.add_all(&elastic);
    let rayleigh = cas.add_all(&rayleigh);
    let actuation = actuation(cas, symbols, structure, &strains);
    let mut sys = System {
        coords,
        bodies,
        gravity: symbols.gravity(),
        elastic,
        rayleigh,
        actuation,
        point_forces: Vec::new(),
        moments: Vec::new(),
        tip,
        tip_orientation: quat,
        chain: None,
        seeds: base.seeds,
        segment_ends: Vec::new(),
        end_frames: Vec::new(),
        samples,
        bases: (structure.contact_points > 0)
            .then(|| Sample::spatial(p0, q0))
            .into_iter()
            .collect(),
        planar: None,
    };
    slab_loads.attach(cas, &mut sys, symbols);
    let mount = TipMount {
        point: tip,
        axis: prev.r.map(|row| row[0]),
        omega,
        rotation: prev.r,
    };
    let loads = tip_loads(cas, symbols, structure, &mount);
    sys.attach_tip(loads, 0);
    sys
}

/// Loads along the arm (`[[load]]`, `[fluid]`) on eba's elements: each
/// acts on its element's rigid slab, where the slab's contact points sit;
/// the fluid drags each slab's centre.
struct SlabLoads {
    loads: Vec<along::AlongLoad>,
    applied: Applied,
}

impl SlabLoads {
    fn of(cas: &mut Cas, structure: &Structure, symbols: &ParamSymbols) -> Self {
        let mut applied = Applied::default();
        applied.drag = Drag::of(structure, symbols);
        applied.buoyancy = (structure.fluid.is_some())
            .then(|| symbols.get(Param::Fluid(FluidParam::Density)));
        Self {
            loads: along_loads(cas, structure, symbols),
            applied,
        }
    }

    /// The loads on element k, its slab turning at `omega`.
    fn on(
        &mut self,
        cas: &mut Cas,
        (k, slab, omega): (usize, &Slab, V3),
        pairs: &[(ExprId, ExprId)],
        symbols: &ParamSymbols,
    ) {
        self.applied.element(
            cas,
            &self.loads,
            (k, k),
            &mut |cas, fraction| along::Placed {
                point: slab.end(cas, 2.0 * fraction - 1.0),
                rotation: slab.r,
                omega,
            },
            pairs,
            symbols,
        );
    }

    /// Into `sys`, whose body k is element k's (the tip's, attached
    /// after, displaces nothing).
    fn attach(self, cas: &mut Cas, sys: &mut System, symbols: &ParamSymbols) {
        let body_link: Vec<usize> = (0..sys.bodies.len()).collect();
        self.applied.attach(cas, sys, symbols, &body_link);
    }
}

/// A slab's `points` contact points, on its centreline straight through
/// its centre.
fn slab_samples(
    cas: &mut Cas,
    points: usize,
    l: ExprId,
    centre: V3,
    axis: V3,
    quat: [ExprId; 4],
    samples: &mut Vec<Sample>,
) {
    for j in 1..=points {
        let d = cas.scaled(j as f64 / points as f64 - 0.5, l);
        let point = std::array::from_fn(|i| {
            let a = cas.mul(d, axis[i]);
            cas.add(centre[i], a)
        });
        let point = bind3(cas, point);
        samples.push(Sample::spatial(point, quat));
    }
}

/// An element's orientation R = R0 exp([psi]x) (rows), its angular
/// velocity (the base's w0 plus R0 times the left Jacobian's rate) and the
/// relative quaternion exp([psi]x).
fn element_frame(cas: &mut Cas, r0: &M3, w0: &V3, psi: &V3, psi_d: &V3) -> (M3, V3, [ExprId; 4]) {
    let w = cas.dot(psi, psi);
    let w = cas.bind(w);
    let [c0, c1, c2, c3] = coefficients(cas, w, [0, 1, 2, 3]);
    let rel = rotation(cas, psi, [c0, c1, c2]);
    let r: M3 = std::array::from_fn(|i| {
        std::array::from_fn(|j| {
            let col = [rel[0][j], rel[1][j], rel[2][j]];
            let e = cas.dot(&r0[i], &col);
            cas.bind(e)
        })
    });
    let w_local = left_jacobian(cas, psi, psi_d, [c1, c2, c3]);
    let q_rel = rotation_quat(cas, psi, w);
    let turned = cas.turn(r0, w0, &w_local);
    let omega = add3(cas, w0, &turned);
    (r, bind3(cas, omega), q_rel)
}

/// The beam springs between element k and the previous one (or the clamp):
/// bending and twist on the relative rotation measure, axial and shear on
/// the gap in the previous frame, thinned with the stretch if
/// incompressible; and the joint's lumped strain (its segment left to the
/// caller).
struct BeamJoint {
    strain: Strain,
    elastic: Vec<ExprId>,
    rayleigh: Vec<ExprId>,
}

/// The parameters of the beam springs to element k, in this order (as a
/// joint part reads them after the previous element's length).
#[derive(Clone, Copy)]
struct JointParams {
    l: ExprId,
    kb: ExprId,
    kt: ExprId,
    /// E I_y / l and k G A_z / l: `kb` and `ks` but for anisotropic
    /// sections.
    kb_y: ExprId,
    ks_z: ExprId,
    db: ExprId,
    dt: ExprId,
    ka: ExprId,
    da: ExprId,
    ks: ExprId,
}

impl JointParams {
    const ORDER: [ElementParam; 8] = [
        ElementParam::Length,
        ElementParam::BendStiffness,
        ElementParam::TwistStiffness,
        ElementParam::BendDamping,
        ElementParam::TwistDamping,
        ElementParam::StretchStiffness,
        ElementParam::StretchDamping,
        ElementParam::ShearStiffness,
    ];

    fn of(symbols: &ParamSymbols, k: usize) -> Self {
        Self::from(Self::ORDER.map(|e| symbols.element(k, e)))
    }

    fn from([l, kb, kt, db, dt, ka, da, ks]: [ExprId; 8]) -> Self {
        Self {
            l,
            kb,
            kb_y: kb,
            ks_z: ks,
            kt,
            db,
            dt,
            ka,
            da,
            ks,
        }
    }
}

fn beam_springs(
    cas: &mut Cas,
    jp: &JointParams,
    first: bool,
    (prev, slab): (&Slab, &Slab),
    rest: Option<&RestJoint>,
    incompressible: bool,
    pairs: &[(ExprId, ExprId)],
) -> BeamJoint {
    let span = if first { 2.0 } else { 1.0 }; // stiffness factor l_e / span
    let JointParams {
        l,
        kb,
        kb_y,
        kt,
        db,
        dt,
        ka,
        da,
        ks,
        ks_z,
    } = *jp;
    let mut r_rel = transpose_mul(cas, &prev.r, &slab.r);
    // From rest: in the frame midway between the two elements.
    if let Some(rest) = rest {
        if let Some(before) = &rest.before {
            r_rel = transpose_mul(cas, before, &r_rel);
        }
        r_rel = mul3_t(cas, &r_rel, &rest.after);
    }
    // 2 tan(theta / 2) n = 2 vee(R - R^T) / (1 + tr R): the relative
    // rotation to second order, and stiffening up to a half turn, so
    // that equilibria exist under any load.
    let tr = cas.add_all(&[r_rel[0][0], r_rel[1][1], r_rel[2][2]]);
    let one = cas.one();
    let denom = cas.add(one, tr);
    let inv = cas.powi(denom, -1);
    let inv = cas.bind(inv);
    let v: V3 = [(2, 1), (0, 2), (1, 0)].map(|(a, b)| {
        let d = cas.sub(r_rel[a][b], r_rel[b][a]);
        let h = cas.mul(d, inv);
        let h = cas.scaled(2.0, h);
        cas.bind(h)
    });
    let end_a = prev.end(cas, 1.0);
    let start_b = slab.end(cas, -1.0);
    let gap: V3 = std::array::from_fn(|i| cas.sub(start_b[i], end_a[i]));
    // In the previous frame: R_a^T gap.
    let mut local: V3 = std::array::from_fn(|i| {
        let col = [prev.r[0][i], prev.r[1][i], prev.r[2][i]];
        let e = cas.dot(&col, &gap);
        cas.bind(e)
    });
    if let Some(rest) = rest {
        let e = cas.sub(local[0], rest.gap);
        local[0] = cas.bind(e);
    }
    // Incompressible: a stretch lambda = (l + gap) / l thins the section
    // (as in `SpatialArm::strain_element`).
    let thin = incompressible.then(|| {
        let len = cas.add(l, local[0]);
        thinning(cas, l, len)
    });
    // The joint's lumped strain: the gap along the previous axis and
    // the relative rotation measure.
    let strain = Strain {
        segment: 0,
        element: 0,
        stretch: local[0],
        rho: v,
        offset_scale: thin.map(|t| t.1),
    };
    let (mut elastic, mut rayleigh) = (Vec::new(), Vec::new());
    let v_d = cas.time_derivatives(&v, pairs);
    for (i, (&x, &xd)) in v.iter().zip(&v_d).enumerate() {
        let (kk, dd) = match i {
            0 => (kt, dt),
            1 => (kb_y, db),
            _ => (kb, db),
        };
        let kk = cas.scaled(span, kk);
        let kk = match thin {
            Some((soft, _)) => cas.mul(kk, soft),
            None => kk,
        };
        let dd = cas.scaled(span, dd);
        elastic.push(half_k_sq(cas, kk, x));
        rayleigh.push(half_k_sq(cas, dd, xd));
    }
    let local_d = cas.time_derivatives(&local[..1], pairs);
    elastic.push(half_k_sq(cas, ka, local[0]));
    rayleigh.push(half_k_sq(cas, da, local_d[0]));
    for (&x, k) in local[1..].iter().zip([ks, ks_z]) {
        elastic.push(half_k_sq(cas, k, x));
    }
    BeamJoint {
        strain,
        elastic,
        rayleigh,
    }
}

/// The kernels of an eba arm as a sum of parts (`runtime::parts`): every
/// element's body (one kernel for all), the beam springs between
/// neighbours (one) and to the clamp (one), and the tip's loads and body
/// (one, reading the model's parameters). Centres are taken relative to a
/// common point, which changes neither M nor h, so a part does not depend
/// on the arc length to its element. The chambers' and tendons' loads
/// act on the joints' strains, a driven torque on its coordinate, loads
/// along the arm and a fluid's buoyancy and drag on their elements. None
/// for an arm on a moving base (terms not split into parts yet).
pub(crate) fn part_kernels(st: &Structure, layout: &ParamLayout) -> Option<PartKernels> {
    if not_parts(st).is_some() {
        return None;
    }
    let index = |p: Param| layout.index(p);
    let r0: Vec<usize> = (0..9)
        .map(|i| index(Param::BaseRotation((i / 3) as u8, (i % 3) as u8)))
        .collect();
    let joint = |k: usize| JointParams::ORDER.map(|e| index(Param::Element(k, e)));
    let incompressible: Vec<bool> = st
        .segments
        .iter()
        .flat_map(|g| std::iter::repeat_n(g.incompressible, g.elements))
        .collect();
    let segment_of: Vec<usize> = (st.segments.iter().enumerate())
        .flat_map(|(s, g)| std::iter::repeat_n(s, g.elements))
        .collect();
    // The chambers' and tendons' loads, read past the model's parameters
    // by the joints they act across.
    let actuation = ActuationLoads::of(layout, st);
    let mut kernels = PartKernels::default();
    // Kernel keys: 0 body; 1 + (incompressible) clamp joint; 3 + (..)
    // joint; 5 torque.
    let mut keys: Vec<usize> = Vec::new();
    let mut kernel =
        |kernels: &mut PartKernels, key: usize, make: &dyn Fn() -> [Tape; 2]| match keys
            .iter()
            .position(|&x| x == key)
        {
            Some(k) => k,
            None => {
                let [t, d] = make();
                kernels.kernels.push(t);
                kernels.tangents.push(d);
                keys.push(key);
                keys.len() - 1
            }
        };
    let n = st.elements();
    let mut parts = Vec::new();
    for (k, &inc) in incompressible.iter().enumerate() {
        let coords: Vec<usize> = (6 * k..6 * k + 6).collect();
        let mut params: Vec<usize> = [ElementParam::Mass, ElementParam::Inertia]
            .into_iter()
            .chain([ElementParam::AxialInertia])
            .map(|e| index(Param::Element(k, e)))
            .collect();
        params.extend(Xyz::ALL.map(|c| index(Param::Gravity(c))));
        params.extend(&r0);
        let b = kernel(&mut kernels, 0, &body_part);
        parts.push(PartSpec {
            kernel: b,
            coords,
            params,
        });
        let (coords, mut params, key) = match k {
            0 => ((0..6).collect(), Vec::new(), 1 + inc as usize),
            _ => (
                (6 * k - 6..6 * k + 6).collect(),
                vec![index(Param::Element(k - 1, ElementParam::Length))],
                3 + inc as usize,
            ),
        };
        params.extend(joint(k));
        params.extend(&r0);
        // Its segment's loads; a bare segment's the zero triple past
        // them, so that actuated and bare arms share their joints' kernels.
        let load = (actuation.find(segment_of[k], k)).unwrap_or(actuation.owners.len());
        params.extend((0..3).map(|i| layout.len() + 3 * load + i));
        let j = kernel(&mut kernels, key, &|| joint_part(k == 0, inc));
        parts.push(PartSpec {
            kernel: j,
            coords,
            params,
        });
    }
    // The loads along the arm on each element's slab.
    for k in 0..n {
        if let Some((tapes, reads)) = load_part(st, layout, k) {
            let [t, d] = tapes;
            kernels.kernels.push(t);
            kernels.tangents.push(d);
            parts.push(PartSpec {
                kernel: kernels.kernels.len() - 1,
                coords: (6 * k..6 * k + 6).collect(),
                params: reads.iter().map(|&p| index(p)).collect(),
            });
        }
    }
    // A driven torque: a part of its coordinate alone.
    let names = crate::method::coordinate_names(st);
    for (i, name) in st.torques.iter().enumerate() {
        let c = (names.iter().position(|n| n == name)).expect("validated coordinate name");
        let t = kernel(&mut kernels, 5, &torque_part);
        parts.push(PartSpec {
            kernel: t,
            coords: vec![c],
            params: vec![index(Param::Torque(i))],
        });
    }
    if let Some((tip, reads)) = tip_part(st, layout) {
        kernels.kernels.push(tip[0].clone());
        kernels.tangents.push(tip[1].clone());
        parts.push(PartSpec {
            kernel: kernels.kernels.len() - 1,
            coords: (6 * n - 6..6 * n).collect(),
            params: reads.iter().map(|&p| index(p)).collect(),
        });
    }
    kernels.layout = PartLayout {
        dof: 6 * n,
        parts,
        pose_coords: (6 * n - 6..6 * n).collect(),
        loads: 3 * actuation.owners.len() + 3,
        params: layout.len(),
    };
    kernels.loads = actuation.tape;
    kernels.pose = Some(pose_tape(st, layout));
    kernels.offsets = Some(offsets_tape(st, layout));
    Some(kernels)
}

/// Why an arm is no system of parts ([`part_kernels`]); None where it is.
pub(crate) fn not_parts(st: &Structure) -> Option<&'static str> {
    if !st.segments.iter().all(|g| g.method == Method::Eba) {
        return Some("its eba segments share the arm with other methods");
    }
    if st.base_translates || st.base_turns > 0 {
        return Some("its eba elements sit on a moving base");
    }
    if st.segments.iter().any(|g| g.anisotropic || g.rest_3d) {
        return Some("its eba elements have an anisotropic section or a rest shape");
    }
    None
}

/// An element's coordinates (u, psi) in a fresh CAS.
fn element_coordinates(cas: &mut Cas, prefix: &str) -> Coordinates {
    let names = ["ux", "uy", "uz", "rx", "ry", "rz"]
        .map(|c| format!("{c}{prefix}"))
        .to_vec();
    Coordinates::new(cas, names)
}

/// Parameter symbols p0, p1, ... of a part.
fn part_params(cas: &mut Cas, n: usize) -> Vec<ExprId> {
    (0..n)
        .map(|i| cas.symbol(&format!("p{i}"), SymKind::Param(i as u32)))
        .collect()
}

fn rows(p: &[ExprId]) -> M3 {
    std::array::from_fn(|i| std::array::from_fn(|j| p[3 * i + j]))
}

/// A part's [M block, h block, potential energy] and its tangent, from a
/// system of its coordinates (positions relative to its first element's
/// straight-arm centre: `offsets` adds what that leaves out).
fn part_tapes(cas: &mut Cas, sys: &System) -> [Tape; 2] {
    let eq = assemble(cas, sys);
    let mut out: Vec<ExprId> = eq.mass_upper.iter().chain(&eq.bias).copied().collect();
    out.push(eq.outputs[4]);
    [
        cas.to_tape(&out),
        crate::tmt::with_tangent(cas, &out, &sys.coords.q, &sys.coords.qd),
    ]
}

/// A system of `coords` with nothing in it yet.
fn empty_system(cas: &mut Cas, coords: Coordinates, gravity: V3) -> System {
    let (zero, one) = (cas.zero(), cas.one());
    System {
        coords,
        bodies: Vec::new(),
        gravity,
        elastic: zero,
        rayleigh: zero,
        actuation: zero,
        point_forces: Vec::new(),
        moments: Vec::new(),
        tip: [zero; 3],
        tip_orientation: [one, zero, zero, zero],
        chain: None,
        seeds: Vec::new(),
        segment_ends: Vec::new(),
        end_frames: Vec::new(),
        samples: Vec::new(),
        bases: Vec::new(),
        planar: None,
    }
}

/// One element's body: parameters mass, inertia, axial inertia, gravity
/// (3), base rotation rows (9).
fn body_part() -> [Tape; 2] {
    let mut cas = Cas::new();
    let cas = &mut cas;
    let coords = element_coordinates(cas, "");
    let p = part_params(cas, 15);
    let zero = cas.zero();
    let r0 = rows(&p[6..15]);
    let u: V3 = std::array::from_fn(|i| coords.q[i]);
    let psi: V3 = std::array::from_fn(|i| coords.q[3 + i]);
    let psi_d: V3 = std::array::from_fn(|i| coords.qd[3 + i]);
    let (r, omega, _) = element_frame(cas, &r0, &[zero; 3], &psi, &psi_d);
    let body = Body {
        mass: p[0],
        inertia: Inertia::Axisymmetric {
            axis: [r[0][0], r[1][0], r[2][0]],
            axial: p[2],
            lateral: p[1],
        },
        position: bind3(cas, u),
        omega,
    };
    let mut sys = empty_system(cas, coords, [p[3], p[4], p[5]]);
    sys.bodies.push(body);
    part_tapes(cas, &sys)
}

/// The loads along the arm on element k (`[[load]]`: forces and moments
/// at fractions of it, a force per length at its middle) on its slab, as
/// `SlabLoads` applies them, and the parameters they read; None where
/// none acts.
fn load_part(st: &Structure, layout: &ParamLayout, k: usize) -> Option<([Tape; 2], Vec<Param>)> {
    let reads: Vec<Param> = (layout.params().iter().copied())
        .filter(|p| {
            matches!(
                p,
                Param::Load(..)
                    | Param::Element(
                        _,
                        ElementParam::Length | ElementParam::Volume | ElementParam::Width
                    )
                    | Param::BaseRotation(..)
                    | Param::Gravity(_)
                    | Param::Fluid(_)
            )
        })
        .collect();
    let mut cas = Cas::new();
    let cas = &mut cas;
    let symbols = ParamSymbols::new(cas, &ParamLayout::local(&reads));
    let loads = along_loads(cas, st, &symbols);
    if st.fluid.is_none() && !loads.iter().any(|l| l.element == k) {
        return None;
    }
    let coords = element_coordinates(cas, "");
    let zero = cas.zero();
    let r0: M3 = symbols.base_rotation();
    let psi: V3 = std::array::from_fn(|i| coords.q[3 + i]);
    let psi_d: V3 = std::array::from_fn(|i| coords.qd[3 + i]);
    let (r, omega, _) = element_frame(cas, &r0, &[zero; 3], &psi, &psi_d);
    let slab = Slab {
        r,
        centre: bind3(cas, std::array::from_fn(|i| coords.q[i])),
        half: cas.scaled(0.5, symbols.element(k, ElementParam::Length)),
    };
    let pairs = coords.rate_pairs();
    let mut applied = Applied::default();
    applied.drag = Drag::of(st, &symbols);
    applied.element(
        cas,
        &loads,
        (k, 0),
        &mut |cas, fraction| along::Placed {
            point: slab.end(cas, 2.0 * fraction - 1.0),
            rotation: slab.r,
            omega,
        },
        &pairs,
        &symbols,
    );
    let mut sys = empty_system(cas, coords, [zero; 3]);
    applied.attach(cas, &mut sys, &symbols, &[]);
    // Immersed: the weight of the fluid it displaces, up through its
    // centre (its body's, as `along::buoyancy` lifts the flat arm's).
    if st.fluid.is_some() {
        let rho = symbols.get(Param::Fluid(FluidParam::Density));
        let displaced = cas.mul(rho, symbols.element(k, ElementParam::Volume));
        let lift = cas.neg(displaced);
        let force = symbols.gravity().map(|c| cas.mul(lift, c));
        sys.point_forces.push(PointForce {
            point: slab.centre,
            force,
        });
    }
    Some((part_tapes(cas, &sys), reads))
}

/// A driven generalised force Q on one coordinate q (parameter: Q), as
/// the flat arm takes it: the potential -Q q among the actuators'.
fn torque_part() -> [Tape; 2] {
    let mut cas = Cas::new();
    let cas = &mut cas;
    let coords = Coordinates::new(cas, vec!["q".to_string()]);
    let p = part_params(cas, 1);
    let zero = cas.zero();
    let work = cas.mul(p[0], coords.q[0]);
    let mut sys = empty_system(cas, coords, [zero; 3]);
    sys.actuation = cas.neg(work);
    part_tapes(cas, &sys)
}

/// The beam springs to an element from the previous one (coordinates of
/// both, parameters: the previous length, `JointParams`, base rotation) or
/// from the clamp (`first`: its coordinates, `JointParams`, base
/// rotation); then its segment's actuation loads on the joint's strain
/// (c_st, c_by, c_bz of `actuation::segment_loads`; zero where none act).
fn joint_part(first: bool, incompressible: bool) -> [Tape; 2] {
    let mut cas = Cas::new();
    let cas = &mut cas;
    let zero = cas.zero();
    let (coords, before) = if first {
        (element_coordinates(cas, ""), 0)
    } else {
        let mut names: Vec<String> = ["ux", "uy", "uz", "rx", "ry", "rz"]
            .map(|c| format!("{c}_a"))
            .to_vec();
        names.extend(["ux", "uy", "uz", "rx", "ry", "rz"].map(|c| format!("{c}_b")));
        (Coordinates::new(cas, names), 1)
    };
    let p = part_params(cas, before + 8 + 9 + 3);
    let jp = JointParams::from(std::array::from_fn(|i| p[before + i]));
    let r0 = rows(&p[before + 8..]);
    let base_axis = [r0[0][0], r0[1][0], r0[2][0]];
    let half_b = cas.scaled(0.5, jp.l);
    let (prev, b) = if first {
        let prev = Slab {
            r: r0,
            centre: [zero; 3],
            half: zero,
        };
        (prev, 0)
    } else {
        let psi: V3 = std::array::from_fn(|i| coords.q[3 + i]);
        let psi_d: V3 = std::array::from_fn(|i| coords.qd[3 + i]);
        let (r, _, _) = element_frame(cas, &r0, &[zero; 3], &psi, &psi_d);
        let centre = bind3(cas, std::array::from_fn(|i| coords.q[i]));
        let half = cas.scaled(0.5, p[0]);
        (Slab { r, centre, half }, 6)
    };
    // Centres relative to the straight arm's centre of the previous
    // element (or the clamp): the next one is a half of each element along
    // the base axis on, plus its displacement.
    let gap = cas.add(prev.half, half_b);
    let u: V3 = std::array::from_fn(|i| coords.q[b + i]);
    let psi: V3 = std::array::from_fn(|i| coords.q[b + 3 + i]);
    let psi_d: V3 = std::array::from_fn(|i| coords.qd[b + 3 + i]);
    let (r, _, _) = element_frame(cas, &r0, &[zero; 3], &psi, &psi_d);
    let centre: V3 = std::array::from_fn(|i| {
        let straight = cas.mul(gap, base_axis[i]);
        cas.add(straight, u[i])
    });
    let slab = Slab {
        r,
        centre: bind3(cas, centre),
        half: half_b,
    };
    let pairs = coords.rate_pairs();
    let joint = beam_springs(cas, &jp, first, (&prev, &slab), None, incompressible, &pairs);
    let mut sys = empty_system(cas, coords, [zero; 3]);
    sys.elastic = cas.add_all(&joint.elastic);
    sys.rayleigh = cas.add_all(&joint.rayleigh);
    let loads = std::array::from_fn(|i| p[before + 8 + 9 + i]);
    let strain = &joint.strain;
    let work = strain_work(cas, loads, strain.stretch, strain.rho, strain.offset_scale);
    sys.actuation = cas.neg(work);
    part_tapes(cas, &sys)
}

/// The tip's loads and body on the last element, and the parameters it
/// reads (the world's, the base's, the tip's and the last element's
/// length: the same tapes at any element count); None without any.
fn tip_part(st: &Structure, layout: &ParamLayout) -> Option<([Tape; 2], Vec<Param>)> {
    if !(st.tip_mass || st.tip_force || st.tip_moment) {
        return None;
    }
    let last = Param::Element(st.elements() - 1, ElementParam::Length);
    let reads: Vec<Param> = (layout.params().iter().copied())
        .filter(|&p| {
            p == last
                || matches!(
                    p,
                    Param::Gravity(_)
                        | Param::BasePosition(_)
                        | Param::BaseRotation(..)
                        | Param::BaseQuaternion(_)
                        | Param::TipMass
                        | Param::TipForce(_)
                        | Param::TipMoment(_)
                        | Param::TipLength
                        | Param::TipInertia
                        | Param::TipAxialInertia
                )
        })
        .collect();
    let mut cas = Cas::new();
    let sys = tip_system(&mut cas, st, &ParamLayout::local(&reads));
    Some((part_tapes(&mut cas, &sys), reads))
}

/// The tip point relative to the last element's straight-arm centre and
/// the tip orientation, of the last element's coordinates: the `pose`
/// kernel of `runtime::parts::outputs`.
fn pose_tape(st: &Structure, layout: &ParamLayout) -> Tape {
    let mut cas = Cas::new();
    let sys = tip_system(&mut cas, st, layout);
    let eq = assemble(&mut cas, &sys);
    let out: Vec<ExprId> = [0, 1, 2, 5, 6, 7, 8].map(|i| eq.outputs[i]).to_vec();
    cas.to_tape(&out)
}

/// The parameters-only offsets of the outputs (`runtime::parts::outputs`):
/// the potential energy the parts leave out (every body's and the tip's
/// weight, and world-frame forces at the tip and along the arm, at the
/// straight-arm centres they are relative to), then the last element's
/// straight-arm centre.
fn offsets_tape(st: &Structure, layout: &ParamLayout) -> Tape {
    let mut cas = Cas::new();
    let cas = &mut cas;
    let symbols = ParamSymbols::new(cas, layout);
    let g = symbols.gravity();
    let p0 = symbols.xyz(Param::BasePosition);
    let axis = [0, 1, 2].map(|i| symbols.get(Param::BaseRotation(i, 0)));
    let mut along = cas.zero();
    let mut terms = Vec::new();
    let mut centre = p0;
    let loads = along_loads(cas, st, &symbols);
    for k in 0..st.elements() {
        let l = symbols.element(k, ElementParam::Length);
        let half = cas.scaled(0.5, l);
        let s_mid = cas.add(along, half);
        along = cas.add(along, l);
        centre = std::array::from_fn(|i| {
            let straight = cas.mul(s_mid, axis[i]);
            cas.add(p0[i], straight)
        });
        let m = symbols.element(k, ElementParam::Mass);
        let gc = cas.dot(&g, &centre);
        let mgc = cas.mul(m, gc);
        terms.push(cas.neg(mgc));
        // A world-frame force along the arm: -F . p, its load part's p
        // relative to this centre; buoyancy's too.
        for l in loads.iter().filter(|l| l.element == k && !l.local) {
            if let Some(f) = l.force {
                let fc = cas.dot(&f, &centre);
                terms.push(cas.neg(fc));
            }
        }
        if st.fluid.is_some() {
            let rho = symbols.get(Param::Fluid(FluidParam::Density));
            let displaced = cas.mul(rho, symbols.element(k, ElementParam::Volume));
            let gc = cas.dot(&g, &centre);
            terms.push(cas.mul(displaced, gc));
        }
    }
    if st.tip_mass {
        let gc = cas.dot(&g, &centre);
        let mgc = cas.mul(symbols.get(Param::TipMass), gc);
        terms.push(cas.neg(mgc));
    }
    if st.tip_force && !st.tip_frame_wrench {
        let f = symbols.xyz(Param::TipForce);
        let fc = cas.dot(&f, &centre);
        terms.push(cas.neg(fc));
    }
    let mut out = vec![cas.add_all(&terms)];
    out.extend(centre);
    cas.to_tape(&out)
}

/// The last element with the tip's loads and body, its centre at its
/// straight-arm centre's origin, orientation composed with the base's.
fn tip_system(cas: &mut Cas, st: &Structure, layout: &ParamLayout) -> System {
    let symbols = ParamSymbols::new(cas, layout);
    let coords = element_coordinates(cas, "");
    let zero = cas.zero();
    let r0: M3 = symbols.base_rotation();
    let psi: V3 = std::array::from_fn(|i| coords.q[3 + i]);
    let psi_d: V3 = std::array::from_fn(|i| coords.qd[3 + i]);
    let (r, omega, q_rel) = element_frame(cas, &r0, &[zero; 3], &psi, &psi_d);
    let last = st.elements() - 1;
    let half = cas.scaled(0.5, symbols.element(last, ElementParam::Length));
    let slab = Slab {
        r,
        centre: bind3(cas, std::array::from_fn(|i| coords.q[i])),
        half,
    };
    let tip = slab.end(cas, 1.0);
    let mount = TipMount {
        point: bind3(cas, tip),
        axis: [r[0][0], r[1][0], r[2][0]],
        omega,
        rotation: r,
    };
    let loads = tip_loads(cas, &symbols, st, &mount);
    let mut sys = empty_system(cas, coords, symbols.gravity());
    sys.attach_tip(loads, 0);
    let q0 = std::array::from_fn(|c| symbols.get(Param::BaseQuaternion(c as u8)));
    sys.tip_orientation = quat_mul(cas, &q0, &q_rel);
    sys
}

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

use super::{ModellingMethod, needs_bending_stiffness};
use crate::cas::{Cas, ExprId};
use crate::model::{Check, ElementParam, Method, ModelError, Segment, SegmentShape, Structure};
use crate::tmt::actuation::{Strain, actuation, thinning};
use crate::tmt::spatial::{
    M3, V3, add3, base_frame, bind3, coefficients, half_k_sq, left_jacobian, quat_mul, rotation,
    rotation_quat,
};
use crate::tmt::system::{Body, Coordinates, Inertia, ParamSymbols, System, TipMount, tip_loads};

pub(super) struct Eba;

impl ModellingMethod for Eba {
    fn spatial_only(&self) -> bool {
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
        if s.rest_curvature != 0.0 {
            return ck.err(
                p("rest_curvature"),
                "eba elements are straight at rest: remove the key or use pcc, ebr or rom".into(),
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

fn absolute_system(cas: &mut Cas, structure: &Structure, symbols: &ParamSymbols) -> System {
    let coords = Coordinates::new(cas, super::coordinate_names(structure));
    let zero = cas.zero();
    // The base frame, moving when prescribed: the absolute states are then
    // measured from the moving base's straight arm.
    let base = symbols.base_motion(cas);
    let frame = base_frame(cas, symbols, base.position, &base.turns);
    let (r0, p0, w0) = (frame.r, frame.p, frame.w);
    let base_axis = [r0[0][0], r0[1][0], r0[2][0]];
    // Rates (of the damping) relative to a moving base, too.
    let mut pairs = coords.rate_pairs();
    pairs.extend(&base.seeds);

    let mut bodies = Vec::new();
    let mut elastic = Vec::new();
    let mut rayleigh = Vec::new();
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
    let mut strains = Vec::new();
    for (k, &segment) in segment_of.iter().enumerate() {
        let c = 6 * k;
        let u: V3 = std::array::from_fn(|i| coords.q[c + i]);
        let psi: V3 = std::array::from_fn(|i| coords.q[c + 3 + i]);
        let psi_d: V3 = std::array::from_fn(|i| coords.qd[c + 3 + i]);
        let l = symbols.element(k, ElementParam::Length);
        let half = cas.scaled(0.5, l);
        // Centre of the straight arm plus the displacement.
        let s_mid = cas.add(along, half);
        let centre: V3 = std::array::from_fn(|i| {
            let straight = cas.mul(s_mid, base_axis[i]);
            cas.add_all(&[p0[i], straight, u[i]])
        });
        let centre = bind3(cas, centre);
        along = cas.add(along, l);
        let w = cas.dot(&psi, &psi);
        let w = cas.bind(w);
        let [c0, c1, c2, c3] = coefficients(cas, w, [0, 1, 2, 3]);
        let rel = rotation(cas, &psi, [c0, c1, c2]);
        let r: M3 = std::array::from_fn(|i| {
            std::array::from_fn(|j| {
                let col = [rel[0][j], rel[1][j], rel[2][j]];
                let e = cas.dot(&r0[i], &col);
                cas.bind(e)
            })
        });
        let w_local = left_jacobian(cas, &psi, &psi_d, [c1, c2, c3]);
        let q_rel = rotation_quat(cas, &psi, w);
        quat = quat_mul(cas, &q0, &q_rel);
        let turned = cas.turn(&r0, &w0, &w_local);
        omega = add3(cas, &w0, &turned);
        omega = bind3(cas, omega);
        let axis = [r[0][0], r[1][0], r[2][0]];
        bodies.push(Body {
            mass: symbols.element(k, ElementParam::Mass),
            inertia: Inertia::Axisymmetric {
                axis,
                axial: symbols.element(k, ElementParam::AxialInertia),
                lateral: symbols.element(k, ElementParam::Inertia),
            },
            position: centre,
            omega,
        });
        let slab = Slab { r, centre, half };

        // Beam springs to the previous element (or the clamp).
        let incompressible = structure.segments[segment].incompressible;
        let joint = beam_springs(cas, symbols, k, &prev, &slab, incompressible, &pairs);
        strains.push(Strain {
            segment,
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
    };
    let mount = TipMount {
        point: tip,
        axis: [prev.r[0][0], prev.r[1][0], prev.r[2][0]],
        omega,
        rotation: prev.r,
    };
    let loads = tip_loads(cas, symbols, structure, &mount);
    sys.attach_tip(loads, 0);
    sys
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

fn beam_springs(
    cas: &mut Cas,
    symbols: &ParamSymbols,
    k: usize,
    prev: &Slab,
    slab: &Slab,
    incompressible: bool,
    pairs: &[(ExprId, ExprId)],
) -> BeamJoint {
    let l = symbols.element(k, ElementParam::Length);
    let first = k == 0;
    let span = if first { 2.0 } else { 1.0 }; // stiffness factor l_e / span
    let kb = symbols.element(k, ElementParam::BendStiffness);
    let kt = symbols.element(k, ElementParam::TwistStiffness);
    let db = symbols.element(k, ElementParam::BendDamping);
    let dt = symbols.element(k, ElementParam::TwistDamping);
    let ka = symbols.element(k, ElementParam::StretchStiffness);
    let da = symbols.element(k, ElementParam::StretchDamping);
    let ks = symbols.element(k, ElementParam::ShearStiffness);
    let r_rel = transpose_mul(cas, &prev.r, &slab.r);
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
    let local: V3 = std::array::from_fn(|i| {
        let col = [prev.r[0][i], prev.r[1][i], prev.r[2][i]];
        let e = cas.dot(&col, &gap);
        cas.bind(e)
    });
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
        stretch: local[0],
        rho: v,
        offset_scale: thin.map(|t| t.1),
    };
    let (mut elastic, mut rayleigh) = (Vec::new(), Vec::new());
    let v_d = cas.time_derivatives(&v, pairs);
    for (i, (&x, &xd)) in v.iter().zip(&v_d).enumerate() {
        let (kk, dd) = if i == 0 { (kt, dt) } else { (kb, db) };
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
    for &x in &local[1..] {
        elastic.push(half_k_sq(cas, ks, x));
    }
    BeamJoint {
        strain,
        elastic,
        rayleigh,
    }
}

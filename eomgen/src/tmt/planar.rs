//! Planar kinematics: chains in the x-y plane, rotations about z.
//!
//! A frame is an origin (x, y) and an absolute angle phi from +x; each
//! element maps its base frame to its end frame and adds its lumped bodies:
//!
//! * rigid, joints at the base: joint angle q, then a uniform link; one body.
//! * rigid, joints at the midpoint (Hencky's model of a rod): half a link,
//!   the joint, half a link; two bodies.
//! * pcc: an arc of length l bent by theta = q (the chapter's chord
//!   construction, written with sinc and cosc so theta = 0 is regular); one
//!   body at the arc's exact centroid, oriented along the chord, with the
//!   bent arc's rotational inertia about it.
//!
//! Absolute angles keep the velocity map cheap: d(cos phi)/dt = -sin(phi) w,
//! whose partial derivative in any qd_i is one shared node.

use crate::cas::{Cas, ExprId, Func};
use crate::model::{ElementParam, Joints, Method, Param, Structure};

use super::actuation::{Strain, actuation};
use super::system::{
    Body, Chain, Coordinates, Inertia, Link, ParamSymbols, System, TipMount, tip_loads,
};

/// A planar frame: origin, absolute angle and its rate.
#[derive(Clone, Copy)]
struct Frame {
    x: ExprId,
    y: ExprId,
    phi: ExprId,
    w: ExprId,
}

/// Build the planar system of a model. Only the structure and the
/// parameter layout are read from `model`; values stay symbols.
pub fn planar_system(cas: &mut Cas, structure: &Structure, symbols: &ParamSymbols) -> System {
    let coords = Coordinates::new(cas, structure.coordinate_names());
    let zero = cas.zero();

    let base = symbols.base_motion(cas);
    let (phi, w) = match base.turns.first().copied() {
        Some((angle, rate)) => (cas.add(symbols.get(Param::BaseAngle), angle), rate),
        None => (symbols.get(Param::BaseAngle), zero),
    };
    let mut f = Frame {
        x: base.position[0],
        y: base.position[1],
        phi,
        w,
    };
    let z = base.position[2];
    let mut bodies = Vec::new();
    let mut elastic = Vec::new();
    let mut rayleigh = Vec::new();
    let mut links = Vec::new();
    let mut body_link = Vec::new();
    let mut strains = Vec::new();
    let mut k = 0;
    for (s, g) in structure.segments.iter().enumerate() {
        for _ in 0..g.elements {
            let (q, qd) = (coords.q[k], coords.qd[k]);
            // In the plane every element bends about z.
            strains.push(Strain {
                segment: s,
                stretch: zero,
                rho: [zero, zero, q],
                offset_scale: None,
            });
            let l = symbols.element(k, ElementParam::Length);
            let m = symbols.element(k, ElementParam::Mass);
            let inertia = symbols.element(k, ElementParam::Inertia);
            let stiff = symbols.element(k, ElementParam::BendStiffness);
            let damp = symbols.element(k, ElementParam::BendDamping);
            let rest = symbols.element(k, ElementParam::Rest);
            let body =
                |cas: &mut Cas, pos: [ExprId; 2], w: ExprId, mass: ExprId, inertia: ExprId| Body {
                    mass,
                    inertia: Inertia::Isotropic(inertia),
                    position: [cas.bind(pos[0]), cas.bind(pos[1]), z],
                    omega: [zero, zero, w],
                };
            match (g.method, g.joints) {
                (Method::Rigid, Joints::Base) => {
                    f = rotate(cas, f, q, qd);
                    let half = cas.scaled(0.5, l);
                    let c = along(cas, &f, half);
                    bodies.push(body(cas, c, f.w, m, inertia));
                    f = advance(cas, f, l);
                }
                (Method::Rigid, Joints::Midpoint) => {
                    let (quarter, half) = (cas.scaled(0.25, l), cas.scaled(0.5, l));
                    let half_m = cas.scaled(0.5, m);
                    let c = along(cas, &f, quarter);
                    bodies.push(body(cas, c, f.w, half_m, inertia));
                    f = advance(cas, f, half);
                    f = rotate(cas, f, q, qd);
                    let c = along(cas, &f, quarter);
                    bodies.push(body(cas, c, f.w, half_m, inertia));
                    f = advance(cas, f, half);
                }
                (Method::Pcc | Method::Vc, _) => {
                    let (c, chord_rate, arc_inertia, end) = pcc_element(cas, f, l, m, q, qd);
                    let total = cas.add(arc_inertia, inertia);
                    bodies.push(body(cas, c, chord_rate, m, total));
                    f = end;
                }
                (Method::Ebr | Method::Eba | Method::Rom | Method::Cosserat, _) => {
                    unreachable!("validated: ebr, eba and rom are 3D, cosserat statics only")
                }
            }
            body_link.resize(bodies.len(), links.len());
            links.push(Link {
                coords: vec![k],
                end: [f.x, f.y, z],
                end_omega: [zero, zero, f.w],
            });
            let dq = cas.sub(q, rest);
            elastic.push(half_k_sq(cas, stiff, dq));
            rayleigh.push(half_k_sq(cas, damp, qd));
            k += 1;
        }
    }

    let half_phi = cas.scaled(0.5, f.phi);
    let last_link = links.len().saturating_sub(1);
    let elastic = cas.add_all(&elastic);
    let rayleigh = cas.add_all(&rayleigh);
    let actuation = actuation(cas, symbols, structure, &strains);
    let tip_orientation = [cas.cos(half_phi), zero, zero, cas.sin(half_phi)];
    let mut sys = System {
        coords,
        bodies,
        gravity: symbols.gravity(),
        elastic,
        rayleigh,
        actuation,
        point_forces: Vec::new(),
        moments: Vec::new(),
        tip: [f.x, f.y, z],
        tip_orientation,
        chain: (!links.is_empty()).then_some(Chain {
            links,
            body_link,
            point_force_link: Vec::new(),
            moment_link: Vec::new(),
        }),
        seeds: base.seeds,
    };
    // The end frame's axis and rotation only when the tip needs them (a
    // tip body with length, a wrench in the tip frame).
    let (axis, rotation) = if structure.tip_length || structure.tip_frame_wrench {
        let (c, s) = (cas.cos(f.phi), cas.sin(f.phi));
        let (zero, one, ns) = (cas.zero(), cas.one(), cas.neg(s));
        (
            [c, s, zero],
            [[c, ns, zero], [s, c, zero], [zero, zero, one]],
        )
    } else {
        ([zero; 3], [[zero; 3]; 3])
    };
    let mount = TipMount {
        point: [f.x, f.y, z],
        axis,
        omega: [zero, zero, f.w],
        rotation,
    };
    let tip = tip_loads(cas, symbols, structure, &mount);
    sys.attach_tip(tip, last_link);
    sys
}

/// The frame turned by the joint angle q (rate qd).
fn rotate(cas: &mut Cas, f: Frame, q: ExprId, qd: ExprId) -> Frame {
    let phi = cas.add(f.phi, q);
    let w = cas.add(f.w, qd);
    Frame {
        phi: cas.bind(phi),
        w: cas.bind(w),
        ..f
    }
}

/// The point at distance d along the frame's axis.
fn along(cas: &mut Cas, f: &Frame, d: ExprId) -> [ExprId; 2] {
    let (c, s) = (cas.cos(f.phi), cas.sin(f.phi));
    [offset(cas, f.x, d, c), offset(cas, f.y, d, s)]
}

/// The frame moved by d along its axis.
fn advance(cas: &mut Cas, f: Frame, d: ExprId) -> Frame {
    let [x, y] = along(cas, &f, d);
    Frame {
        x: cas.bind(x),
        y: cas.bind(y),
        ..f
    }
}

/// A point at (a, b) in the frame's (axis, normal) coordinates.
fn local(cas: &mut Cas, f: &Frame, a: ExprId, b: ExprId) -> [ExprId; 2] {
    let (c, s) = (cas.cos(f.phi), cas.sin(f.phi));
    // x + a c - b s, y + a s + b c
    let (ac, bs) = (cas.mul(a, c), cas.mul(b, s));
    let (as_, bc) = (cas.mul(a, s), cas.mul(b, c));
    let x = cas.add_all(&[f.x, ac]);
    let x = cas.sub(x, bs);
    let y = cas.add_all(&[f.y, as_, bc]);
    [x, y]
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
    let c = local(cas, &f, a, b);
    // Inertia of the arc about its centroid.
    let two_r = cas.scaled(2.0, r);
    let (a2, b2) = (cas.powi(axis, 2), cas.powi(normal, 2));
    let shape = cas.sub(two_r, a2);
    let shape = cas.sub(shape, b2);
    let l2 = cas.powi(l, 2);
    let arc = cas.mul_all(&[m, l2, shape]);
    // Chord and end frame.
    let chord = rotate(cas, f, half_theta, half_rate);
    let len = cas.mul(l, s);
    let moved = advance(cas, chord, len);
    let end = rotate(cas, moved, half_theta, half_rate);
    (c, chord.w, cas.bind(arc), end)
}

/// x + d * dir
fn offset(cas: &mut Cas, x: ExprId, d: ExprId, dir: ExprId) -> ExprId {
    let t = cas.mul(d, dir);
    cas.add(x, t)
}

/// k x^2 / 2
fn half_k_sq(cas: &mut Cas, k: ExprId, x: ExprId) -> ExprId {
    let x2 = cas.powi(x, 2);
    let e = cas.mul(k, x2);
    cas.scaled(0.5, e)
}

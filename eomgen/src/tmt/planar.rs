//! Planar kinematics: chains in the x-y plane, rotations about z.
//!
//! A frame is an origin (x, y) and an absolute angle phi from +x; each
//! element maps its base frame to its end frame and adds its lumped bodies
//! (how, is its method's: `method/rigid.rs`, `method/pcc.rs`). Here: the
//! arm every method builds on ([`PlanarArm`]) and the frame helpers.
//!
//! Absolute angles keep the velocity map cheap: d(cos phi)/dt = -sin(phi) w,
//! whose partial derivative in any qd_i is one shared node.

use crate::cas::{Cas, ExprId};
use crate::model::{ElementParam, Param, Structure};

use super::actuation::{Strain, actuation};
use super::along::{AlongLoad, Applied, Drag, Placed};
use super::system::{
    Body, Chain, Coordinates, Inertia, Link, ParamSymbols, PlanarFrames, PlanarPose, Sample,
    System, TipMount, tip_loads,
};

/// A planar frame: origin, absolute angle and its rate.
#[derive(Clone, Copy)]
pub(crate) struct Frame {
    pub x: ExprId,
    pub y: ExprId,
    pub phi: ExprId,
    pub w: ExprId,
}

impl Frame {
    /// Moved by `offset` (x, y in itself), then turned by `turn`, its rate
    /// kept: a kink, or an arm's base on another frame.
    fn moved(self, cas: &mut Cas, offset: [ExprId; 2], turn: ExprId) -> Frame {
        let (c, s) = (cas.cos(self.phi), cas.sin(self.phi));
        let dx = [cas.mul(c, offset[0]), cas.mul(s, offset[1])];
        let dy = [cas.mul(s, offset[0]), cas.mul(c, offset[1])];
        let dx = cas.sub(dx[0], dx[1]);
        let dy = cas.add(dy[0], dy[1]);
        Frame {
            x: cas.add(self.x, dx),
            y: cas.add(self.y, dy),
            phi: cas.add(self.phi, turn),
            w: self.w,
        }
    }
}

/// A planar arm under construction: the chain's state every method's
/// elements extend, and what is common to every method (the base, one
/// angle an element, its spring and damper, gravity, actuation, the tip
/// loads). An element is `begin_element`, the method's placement
/// (a method's `place_planar`, in `method/`), `end_element`.
pub(crate) struct PlanarArm<'a> {
    symbols: &'a ParamSymbols,
    coords: Coordinates,
    zero: ExprId,
    /// The end frame of the chain so far.
    pub f: Frame,
    /// The plane's height (the base's z).
    z: ExprId,
    bodies: Vec<Body>,
    elastic: Vec<ExprId>,
    rayleigh: Vec<ExprId>,
    links: Vec<Link>,
    body_link: Vec<usize>,
    strains: Vec<Strain>,
    seeds: Vec<(ExprId, ExprId)>,
    /// What else moves its points: a compliant base's coordinates.
    moved_by: Vec<(ExprId, ExprId)>,
    /// The next element.
    k: usize,
    /// The segment of the element being placed, and each segment's end.
    segment: usize,
    ends: Vec<PlanarPose>,
    /// Contact points per element, and the points sampled so far.
    pub points: usize,
    samples: Vec<Sample>,
    /// The loads along the arm, and what they apply so far.
    pub loads: Vec<AlongLoad>,
    applied: Applied,
}

/// One planar element: its angle, rate and parameters.
pub(crate) struct Element2 {
    pub q: ExprId,
    pub qd: ExprId,
    pub l: ExprId,
    pub m: ExprId,
    pub inertia: ExprId,
    pub stiff: ExprId,
    pub damp: ExprId,
    pub rest: ExprId,
}

impl<'a> PlanarArm<'a> {
    /// An arm of coordinates `names` (one angle an element) at the base.
    pub fn new(cas: &mut Cas, names: Vec<String>, symbols: &'a ParamSymbols) -> Self {
        let coords = Coordinates::new(cas, names);
        let zero = cas.zero();
        let base = symbols.base_motion(cas);
        let (mut phi, mut w) = match base.turns.first().copied() {
            Some((angle, rate)) => (cas.add(symbols.get(Param::BaseAngle), angle), rate),
            None => (symbols.get(Param::BaseAngle), zero),
        };
        if let Some((rho, rate)) = base.twist {
            phi = cas.add(phi, rho[2]);
            w = cas.add(w, rate[2]);
        }
        let mut f = Frame {
            x: base.position[0],
            y: base.position[1],
            phi,
            w,
        };
        if let Some(super::system::MountFrame::Planar { p, angle, w: rate }) = symbols.mount() {
            // On another planar frame (an arm's end, a body): the position
            // and the angle in it (validation leaves such a base no motion
            // of its own).
            let on = Frame {
                x: p[0],
                y: p[1],
                phi: angle,
                w: cas.add(rate, w),
            };
            f = on.moved(cas, [base.position[0], base.position[1]], phi);
        }
        Self {
            symbols,
            coords,
            zero,
            f,
            z: base.position[2],
            bodies: Vec::new(),
            elastic: Vec::new(),
            rayleigh: Vec::new(),
            links: Vec::new(),
            body_link: Vec::new(),
            strains: Vec::new(),
            seeds: base.seeds,
            moved_by: base.moved_by,
            k: 0,
            segment: 0,
            ends: Vec::new(),
            points: 0,
            samples: Vec::new(),
            loads: Vec::new(),
            applied: Applied::default(),
        }
    }

    /// An arm at rest at the origin (angle 0, height 0) for one element
    /// derived on its own: a planar link cell (`build::planar_cell`).
    pub fn at_origin(cas: &mut Cas, coords: Coordinates, symbols: &'a ParamSymbols) -> Self {
        let zero = cas.zero();
        Self {
            symbols,
            coords,
            zero,
            f: Frame {
                x: zero,
                y: zero,
                phi: zero,
                w: zero,
            },
            z: zero,
            bodies: Vec::new(),
            elastic: Vec::new(),
            rayleigh: Vec::new(),
            links: Vec::new(),
            body_link: Vec::new(),
            strains: Vec::new(),
            seeds: Vec::new(),
            moved_by: Vec::new(),
            k: 0,
            segment: 0,
            ends: Vec::new(),
            points: 0,
            samples: Vec::new(),
            loads: Vec::new(),
            applied: Applied::default(),
        }
    }

    /// The bodies placed so far.
    pub fn bodies(&self) -> &[Body] {
        &self.bodies
    }

    /// The next element, of segment s: in the plane every element bends
    /// about z by its one angle.
    pub fn begin_element(&mut self, s: usize) -> Element2 {
        let k = self.k;
        self.segment = s;
        let (q, qd) = (self.coords.q[k], self.coords.qd[k]);
        let zero = self.zero;
        self.strains.push(Strain {
            segment: s,
            element: k,
            stretch: zero,
            rho: [zero, zero, q],
            offset_scale: None,
        });
        let e = |p| self.symbols.element(k, p);
        Element2 {
            q,
            qd,
            l: e(ElementParam::Length),
            m: e(ElementParam::Mass),
            inertia: e(ElementParam::Inertia),
            stiff: e(ElementParam::BendStiffness),
            damp: e(ElementParam::BendDamping),
            rest: e(ElementParam::Rest),
        }
    }

    /// A body at `pos` in the plane, turning at rate `w`.
    pub fn body(
        &mut self,
        cas: &mut Cas,
        pos: [ExprId; 2],
        w: ExprId,
        mass: ExprId,
        inertia: ExprId,
    ) {
        let position = [cas.bind(pos[0]), cas.bind(pos[1]), self.z];
        self.bodies.push(Body {
            mass,
            inertia: Inertia::Isotropic(inertia),
            position,
            omega: [self.zero, self.zero, w],
        });
    }

    /// Points along the element: `at(s)` is the centreline's frame at the
    /// fraction s of the element, for s = 1/P, 2/P, ..., 1; `length` the
    /// centreline's, where the method knows it.
    pub fn sample(
        &mut self,
        cas: &mut Cas,
        length: Option<ExprId>,
        at: impl Fn(&mut Cas, f64) -> Frame,
    ) {
        let points: Vec<_> = (1..=self.points)
            .map(|j| {
                let f = at(cas, j as f64 / self.points as f64);
                ([f.x, f.y], f.phi)
            })
            .collect();
        self.sample_all(cas, length, points);
        self.apply_loads(cas, &at);
    }

    /// The fluid the arm moves in: its drag, and its density for the
    /// buoyancy.
    pub fn set_fluid(&mut self, drag: Option<Drag>, buoyancy: Option<ExprId>) {
        self.applied.drag = drag;
        self.applied.buoyancy = buoyancy;
    }

    /// The loads on the element being placed, at the frames `at` gives
    /// along it (a method that samples by `sample_all` calls this too).
    pub fn apply_loads(&mut self, cas: &mut Cas, at: &impl Fn(&mut Cas, f64) -> Frame) {
        let (k, link, z, zero) = (self.k, self.links.len(), self.z, self.zero);
        let mut pairs = self.coords.rate_pairs();
        pairs.extend(&self.seeds);
        pairs.extend(&self.moved_by);
        self.applied.element(
            cas,
            &self.loads,
            (k, link),
            &mut |cas, s| {
                let f = at(cas, s);
                let (c, sn) = (cas.cos(f.phi), cas.sin(f.phi));
                let (c, sn) = (cas.bind(c), cas.bind(sn));
                let ns = cas.neg(sn);
                let one = cas.one();
                Placed {
                    point: [f.x, f.y, z],
                    rotation: [[c, ns, zero], [sn, c, zero], [zero, zero, one]],
                    omega: [zero, zero, f.w],
                }
            },
            &pairs,
            self.symbols,
        );
    }

    /// Points along the element given all at once (P of them, at s = 1/P,
    /// ..., 1, with the section's angle at each), by a method that shares
    /// work between them; `length` as for `sample`.
    pub fn sample_all(
        &mut self,
        cas: &mut Cas,
        length: Option<ExprId>,
        points: Vec<([ExprId; 2], ExprId)>,
    ) {
        debug_assert_eq!(points.len(), self.points);
        let count = points.len() as f64;
        for (j, ([x, y], angle)) in points.into_iter().enumerate() {
            let point = [cas.bind(x), cas.bind(y), self.z];
            let arc = length.map(|l| cas.scaled((j + 1) as f64 / count, l));
            let sample = Sample::planar(cas, point, angle).at_arc(arc);
            self.samples.push(sample);
        }
    }

    /// The end frame as another arm sits on it.
    pub fn mount_frame(&self) -> super::system::MountFrame {
        super::system::MountFrame::Planar {
            p: [self.f.x, self.f.y, self.z],
            angle: self.f.phi,
            w: self.f.w,
        }
    }

    /// The shape's first point: the frame the arm starts from.
    pub fn base_pose(&self, cas: &mut Cas) -> Sample {
        Sample::planar(cas, [self.f.x, self.f.y, self.z], self.f.phi)
    }

    /// A kink: the end frame moved by `offset` (x, y in itself) and turned
    /// by `turn`, both constant.
    pub fn kink(&mut self, cas: &mut Cas, turn: ExprId, offset: &[ExprId; 3]) {
        self.f = self.f.moved(cas, [offset[0], offset[1]], turn);
    }

    /// The element ends at the end frame: its link, spring and damper.
    pub fn end_element(&mut self, cas: &mut Cas, el: &Element2) {
        let (zero, f) = (self.zero, self.f);
        self.body_link.resize(self.bodies.len(), self.links.len());
        self.links.push(Link {
            coords: vec![self.k],
            end: [f.x, f.y, self.z],
            end_omega: [zero, zero, f.w],
        });
        let dq = cas.sub(el.q, el.rest);
        self.elastic.push(half_k_sq(cas, el.stiff, dq));
        self.rayleigh.push(half_k_sq(cas, el.damp, el.qd));
        self.k += 1;
        let end = PlanarPose {
            point: [f.x, f.y, self.z],
            angle: f.phi,
        };
        self.ends.resize(self.segment + 1, end);
        self.ends[self.segment] = end;
    }

    /// The system: what the elements built, plus gravity, actuation and the
    /// tip loads, written once for every method.
    pub fn finish(self, cas: &mut Cas, structure: &Structure) -> System {
        let Self {
            symbols,
            coords,
            zero,
            f,
            z,
            bodies,
            elastic,
            rayleigh,
            links,
            body_link,
            strains,
            seeds,
            ends,
            samples,
            applied,
            ..
        } = self;
        let half_phi = cas.scaled(0.5, f.phi);
        let last_link = links.len().saturating_sub(1);
        let elastic = cas.add_all(&elastic);
        let rayleigh = cas.add_all(&rayleigh);
        let actuation = actuation(cas, symbols, structure, &strains);
        let tip_orientation = [cas.cos(half_phi), zero, zero, cas.sin(half_phi)];
        let element_of_body = body_link.clone();
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
            seeds,
            segment_ends: Vec::new(),
            end_frames: Vec::new(),
            samples,
            bases: Vec::new(),
            planar: Some(PlanarFrames {
                segment_ends: ends,
                tip: PlanarPose {
                    point: [f.x, f.y, z],
                    angle: f.phi,
                },
            }),
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
        applied.attach(cas, &mut sys, symbols, &element_of_body);
        let tip = tip_loads(cas, symbols, structure, &mount);
        sys.attach_tip(tip, last_link);
        sys
    }
}

/// The frame turned by the joint angle q (rate qd).
pub(crate) fn rotate(cas: &mut Cas, f: Frame, q: ExprId, qd: ExprId) -> Frame {
    let phi = cas.add(f.phi, q);
    let w = cas.add(f.w, qd);
    Frame {
        phi: cas.bind(phi),
        w: cas.bind(w),
        ..f
    }
}

/// The point at distance d along the frame's axis.
pub(crate) fn along(cas: &mut Cas, f: &Frame, d: ExprId) -> [ExprId; 2] {
    let (c, s) = (cas.cos(f.phi), cas.sin(f.phi));
    [offset(cas, f.x, d, c), offset(cas, f.y, d, s)]
}

/// The frame moved by d along its axis.
pub(crate) fn advance(cas: &mut Cas, f: Frame, d: ExprId) -> Frame {
    let [x, y] = along(cas, &f, d);
    Frame {
        x: cas.bind(x),
        y: cas.bind(y),
        ..f
    }
}

/// A point at (a, b) in the frame's (axis, normal) coordinates.
pub(crate) fn local(cas: &mut Cas, f: &Frame, a: ExprId, b: ExprId) -> [ExprId; 2] {
    let (c, s) = (cas.cos(f.phi), cas.sin(f.phi));
    // x + a c - b s, y + a s + b c
    let (ac, bs) = (cas.mul(a, c), cas.mul(b, s));
    let (as_, bc) = (cas.mul(a, s), cas.mul(b, c));
    let x = cas.add_all(&[f.x, ac]);
    let x = cas.sub(x, bs);
    let y = cas.add_all(&[f.y, as_, bc]);
    [x, y]
}

/// x + d * dir
pub(crate) fn offset(cas: &mut Cas, x: ExprId, d: ExprId, dir: ExprId) -> ExprId {
    let t = cas.mul(d, dir);
    cas.add(x, t)
}

/// k x^2 / 2
pub(crate) fn half_k_sq(cas: &mut Cas, k: ExprId, x: ExprId) -> ExprId {
    let x2 = cas.powi(x, 2);
    let e = cas.mul(k, x2);
    cas.scaled(0.5, e)
}

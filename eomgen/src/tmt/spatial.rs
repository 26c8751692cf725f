//! 3D kinematics: serial chains of frames (rotation R, origin p, world
//! angular velocity w) that each element maps from its base to its end.
//! Here: the arm every method builds on ([`SpatialArm`]) and the frame
//! algebra; each method's placement is in its file under `method/`, in
//! short:
//!
//! Rotations are built from rotation vectors rho (components along the
//! frame's x, y, z: twist, bend about y, bend about z) with the Rodrigues
//! coefficients c_j(|rho|^2) (`runtime::rodrigues`), entire functions of
//! the squared angle, so the straight configuration is an ordinary point
//! with full rank:
//!
//! * `pcc`, `vc`: an arc of constant strain rho (bending pair, optional
//!   twist) and optional stretch d: R = exp([rho]x), end at
//!   (l + d) (I + c2 K + c3 K^2) e_x, one body at the arc's exact centroid
//!   (l + d) (I/2 + c3 K + c4 K^2) e_x, turning with the mid-arc frame
//!   exp([rho/2]x), with the inertia of a straight slice.
//! * `ebr`: half a rigid element, a joint rotating by exp([rho]x) and
//!   stretching by d, the other half: two bodies per element.
//! * `rigid`: revolute joints about the element frame's axes in sequence
//!   (a universal or spherical joint), at the base or midpoint of each link.
//!
//! Angular velocities come from the left Jacobian of exp:
//! w = c1 rho' + c2 rho x rho' + c3 (rho . rho') rho in the base frame.
//! Every vector a frame turns into the world goes through `Cas::turn`, so
//! velocities and accelerations follow by w x u (`cas/turning.rs`) rather
//! than by differentiating the chain of rotation matrices.

use crate::cas::{Cas, ExprId, Func};
use crate::model::{ElementParam, Param, SegmentShape, Structure};

use super::actuation::{Strain, actuation, thinning};
use super::along::{AlongLoad, Applied, Drag, Placed};
use super::system::{
    Body, Chain, Coordinates, Inertia, Link, ParamSymbols, Sample, System, TipMount, tip_loads,
};

pub type V3 = [ExprId; 3];
/// Rows of a rotation matrix.
pub type M3 = [[ExprId; 3]; 3];
/// A quaternion (w, x, y, z).
pub type Quat = [ExprId; 4];

/// The Hamilton product a b, bound.
pub(crate) fn quat_mul(cas: &mut Cas, a: &Quat, b: &Quat) -> Quat {
    let t = |cas: &mut Cas, terms: [(f64, usize, usize); 4]| {
        let parts: Vec<ExprId> = terms
            .iter()
            .map(|&(s, i, j)| {
                let m = cas.mul(a[i], b[j]);
                cas.scaled(s, m)
            })
            .collect();
        let e = cas.add_all(&parts);
        cas.bind(e)
    };
    [
        t(cas, [(1.0, 0, 0), (-1.0, 1, 1), (-1.0, 2, 2), (-1.0, 3, 3)]),
        t(cas, [(1.0, 0, 1), (1.0, 1, 0), (1.0, 2, 3), (-1.0, 3, 2)]),
        t(cas, [(1.0, 0, 2), (-1.0, 1, 3), (1.0, 2, 0), (1.0, 3, 1)]),
        t(cas, [(1.0, 0, 3), (1.0, 1, 2), (-1.0, 2, 1), (1.0, 3, 0)]),
    ]
}

/// The quaternion of exp([rho]x): (c0(w/4), c1(w/4) rho / 2), w = |rho|^2.
pub(crate) fn rotation_quat(cas: &mut Cas, rho: &V3, w: ExprId) -> Quat {
    let w4 = cas.scaled(0.25, w);
    let [h0, h1] = coefficients(cas, w4, [0, 1]);
    let s = cas.scaled(0.5, h1);
    [
        h0,
        cas.mul(s, rho[0]),
        cas.mul(s, rho[1]),
        cas.mul(s, rho[2]),
    ]
}

/// A frame: R (world from frame), origin and world angular velocity.
#[derive(Clone, Copy)]
pub(crate) struct Frame {
    pub r: M3,
    pub p: V3,
    pub w: V3,
    /// The orientation as a unit quaternion (w, x, y, z), composed alongside
    /// R (an output only: exact products, no square roots).
    pub quat: Quat,
}

impl Frame {
    /// The world frame at rest at `p`.
    pub fn at_rest(cas: &mut Cas, p: V3) -> Self {
        let (zero, one) = (cas.zero(), cas.one());
        Frame {
            r: std::array::from_fn(|i| std::array::from_fn(|j| if i == j { one } else { zero })),
            p,
            w: [zero; 3],
            quat: [one, zero, zero, zero],
        }
    }

    /// The frame's x axis in the world.
    pub fn axis(&self) -> V3 {
        [self.r[0][0], self.r[1][0], self.r[2][0]]
    }

    /// A body turned as this frame: its axis and its rotation
    /// (`Element3::body`).
    pub fn orientation(&self) -> (V3, impl FnOnce(&mut Cas) -> M3 + use<>) {
        let r = self.r;
        (self.axis(), move |_: &mut Cas| r)
    }
}

pub(crate) fn add3(cas: &mut Cas, a: &V3, b: &V3) -> V3 {
    std::array::from_fn(|k| cas.add(a[k], b[k]))
}

pub(crate) fn bind3(cas: &mut Cas, v: V3) -> V3 {
    v.map(|e| cas.bind(e))
}

/// The frame moved by a relative rotation `r_rel`, offset `p_rel` and
/// relative angular velocity `w_rel`, all in the frame's own coordinates.
pub(crate) fn compose(
    cas: &mut Cas,
    f: &Frame,
    r_rel: Option<(&M3, &Quat)>,
    p_rel: Option<&V3>,
    w_rel: Option<&V3>,
) -> Frame {
    let quat = match r_rel {
        Some((_, q)) => quat_mul(cas, &f.quat, q),
        None => f.quat,
    };
    let r_rel = r_rel.map(|(r, _)| r);
    let p = match p_rel {
        Some(d) => {
            let wd = cas.turn(&f.r, &f.w, d);
            let s = add3(cas, &f.p, &wd);
            bind3(cas, s)
        }
        None => f.p,
    };
    let w = match w_rel {
        Some(w) => {
            let ww = cas.turn(&f.r, &f.w, w);
            let s = add3(cas, &f.w, &ww);
            bind3(cas, s)
        }
        None => f.w,
    };
    let r = match r_rel {
        Some(s) => std::array::from_fn(|i| {
            std::array::from_fn(|j| {
                let col = [s[0][j], s[1][j], s[2][j]];
                let e = cas.dot(&f.r[i], &col);
                cas.bind(e)
            })
        }),
        None => f.r,
    };
    Frame { r, p, w, quat }
}

/// The Rodrigues coefficients c_j(w) for j in `js`, bound.
pub(crate) fn coefficients<const N: usize>(cas: &mut Cas, w: ExprId, js: [u8; N]) -> [ExprId; N] {
    js.map(|j| {
        let c = cas.func(Func::Rodrigues(j, 0), w);
        cas.bind(c)
    })
}

/// exp([rho]x) = c0 I + c1 [rho]x + c2 rho rho^T.
pub(crate) fn rotation(cas: &mut Cas, rho: &V3, c: [ExprId; 3]) -> M3 {
    let [c0, c1, c2] = c;
    std::array::from_fn(|i| {
        std::array::from_fn(|j| {
            let outer = cas.mul_all(&[c2, rho[i], rho[j]]);
            let mut terms = vec![outer];
            if i == j {
                terms.push(c0);
            } else {
                // [rho]x_ij = -eps_ijk rho_k
                let k = 3 - i - j;
                let sign = if (i + 1) % 3 == j { -1.0 } else { 1.0 };
                let t = cas.mul(c1, rho[k]);
                terms.push(cas.scaled(sign, t));
            }
            let e = cas.add_all(&terms);
            cas.bind(e)
        })
    })
}

/// The left Jacobian of exp applied to a rate: a c1 rho' + c2 rho x rho'
/// + c3 (rho . rho') rho, the angular velocity of exp([rho]x) in the base.
pub(crate) fn left_jacobian(cas: &mut Cas, rho: &V3, rate: &V3, c: [ExprId; 3]) -> V3 {
    let [c1, c2, c3] = c;
    let cr = cas.cross(rho, rate);
    let rr = cas.dot(rho, rate);
    let s = cas.mul(c3, rr);
    std::array::from_fn(|k| {
        let a = cas.mul(c1, rate[k]);
        let b = cas.mul(c2, cr[k]);
        let d = cas.mul(s, rho[k]);
        let e = cas.add_all(&[a, b, d]);
        cas.bind(e)
    })
}

/// (a I + b [rho]x + c [rho]x^2) e_x, with [rho]x e_x = (0, rho_z, -rho_y)
/// and [rho]x^2 e_x = rho rho_x - w e_x.
fn series_on_x(cas: &mut Cas, rho: &V3, w: ExprId, a: ExprId, b: ExprId, c: ExprId) -> V3 {
    let cx = cas.mul(c, rho[0]);
    let cw = cas.mul(c, w);
    let x0 = cas.sub(a, cw);
    let x0t = cas.mul(cx, rho[0]);
    let x = cas.add(x0, x0t);
    let by = cas.mul(b, rho[2]);
    let cy = cas.mul(cx, rho[1]);
    let y = cas.add(by, cy);
    let bz = cas.mul(b, rho[1]);
    let cz = cas.mul(cx, rho[2]);
    let z = cas.sub(cz, bz);
    [x, y, z]
}

/// The series (a I + b K + c K^2) t for K = [rho]x, w = |rho|^2:
/// a t + b rho x t + c (rho (rho . t) - w t).
fn series_on(cas: &mut Cas, rho: &V3, w: ExprId, [a, b, c]: [ExprId; 3], t: &V3) -> V3 {
    let cross = cross3(cas, rho, t);
    let dot = cas.dot(rho, t);
    std::array::from_fn(|i| {
        let at = cas.mul(a, t[i]);
        let bx = cas.mul(b, cross[i]);
        let wt = cas.mul(w, t[i]);
        let rd = cas.mul(rho[i], dot);
        let k2 = cas.sub(rd, wt);
        let ck2 = cas.mul(c, k2);
        cas.add_all(&[at, bx, ck2])
    })
}

fn cross3(cas: &mut Cas, a: &V3, b: &V3) -> V3 {
    std::array::from_fn(|i| {
        let (j, k) = ((i + 1) % 3, (i + 2) % 3);
        let p = cas.mul(a[j], b[k]);
        let q = cas.mul(a[k], b[j]);
        cas.sub(p, q)
    })
}

/// What a constant-strain arc is made of: its rotation vector rho (twist,
/// bend y, bend z) and rate, and its translation strain integrated over
/// the element: the length `len` along the section's normal (rest length
/// plus stretch) and, when it shears, the shear displacements along y and
/// z (`shear`).
#[derive(Clone, Copy)]
pub(crate) struct ArcStrain {
    pub rho: V3,
    pub rate: V3,
    pub len: ExprId,
    pub shear: Option<[ExprId; 2]>,
}

impl ArcStrain {
    /// The translation of the arc's series: (len, shear y, shear z).
    fn translation(&self) -> Option<V3> {
        self.shear.map(|[y, z]| [self.len, y, z])
    }

    /// The arc's first fraction s: every strain integral times s.
    pub fn part(&self, cas: &mut Cas, s: f64) -> ArcStrain {
        ArcStrain {
            rho: self.rho.map(|e| cas.scaled(s, e)),
            rate: self.rate.map(|e| cas.scaled(s, e)),
            len: cas.scaled(s, self.len),
            shear: self.shear.map(|d| d.map(|e| cas.scaled(s, e))),
        }
    }
}

/// Whether an element's mass goes as two half-arcs rather than one body:
/// when it stretches or shears. One body at the centroid leaves the stretch
/// and shear rates without inertia of their own (neighbours' centroids can
/// stay put while the strains swing), which puts spurious modes of tens of
/// kilohertz into a rod of ten elements; two halves give those rates most
/// of the slice's inertia (1/16 of m |t'|^2 against the exact 1/12) and
/// bring the highest mode down to the rod's own axial and shear waves.
pub(crate) fn in_halves(g: &SegmentShape) -> bool {
    g.extension || g.shear
}

/// A constant-strain arc from frame `f`: its centroid, its body's axis
/// and angular velocity (the mid-arc frame), and the end frame. The end
/// is at (I + c2 K + c3 K^2) t and the centroid at (I/2 + c3 K + c4 K^2) t
/// for the translation t (len e_x without shear: the same series on the
/// axis alone, which keeps the expressions of unsheared arcs as they were).
pub(crate) fn arc(cas: &mut Cas, f: &Frame, a: &ArcStrain) -> (V3, V3, V3, Frame) {
    let (rho, rate, len) = (&a.rho, &a.rate, a.len);
    let t = a.translation();
    let w = cas.dot(rho, rho);
    let w = cas.bind(w);
    let [c0, c1, c2, c3, c4] = coefficients(cas, w, [0, 1, 2, 3, 4]);
    let one = cas.one();
    let half = cas.constant(0.5);
    // End frame.
    let chord = match &t {
        Some(t) => series_on(cas, rho, w, [one, c2, c3], t),
        None => {
            let chord = series_on_x(cas, rho, w, one, c2, c3);
            chord.map(|e| cas.mul(len, e))
        }
    };
    let r_rel = rotation(cas, rho, [c0, c1, c2]);
    let w_rel = left_jacobian(cas, rho, rate, [c1, c2, c3]);
    let q_rel = rotation_quat(cas, rho, w);
    let end = compose(cas, f, Some((&r_rel, &q_rel)), Some(&chord), Some(&w_rel));
    // Centroid.
    let c = match &t {
        Some(t) => series_on(cas, rho, w, [half, c3, c4], t),
        None => {
            let c = series_on_x(cas, rho, w, half, c3, c4);
            c.map(|e| cas.mul(len, e))
        }
    };
    let c = c.map(|e| cas.bind(e));
    let wc = cas.turn(&f.r, &f.w, &c);
    let centroid = add3(cas, &f.p, &wc);
    // Mid-arc frame: exp([rho/2]x).
    let rho_h = rho.map(|e| cas.scaled(0.5, e));
    let rate_h = rate.map(|e| cas.scaled(0.5, e));
    let w_h = cas.scaled(0.25, w);
    let w_h = cas.bind(w_h);
    let [h1, h2, h3] = coefficients(cas, w_h, [1, 2, 3]);
    let axis_rel = series_on_x(cas, &rho_h, w_h, one, h1, h2);
    let axis = cas.turn(&f.r, &f.w, &axis_rel);
    let axis = bind3(cas, axis);
    let wm_rel = left_jacobian(cas, &rho_h, &rate_h, [h1, h2, h3]);
    let wm = cas.turn(&f.r, &f.w, &wm_rel);
    let omega = add3(cas, &f.w, &wm);
    let omega = bind3(cas, omega);
    (centroid, axis, omega, end)
}

/// The rotation of an arc's body, its frame midway along (exp([rho/2]x)
/// after `f`): asked for by anisotropic sections only (`Element3::body`).
pub(crate) fn mid_arc_rotation(f: &Frame, a: &ArcStrain) -> impl FnOnce(&mut Cas) -> M3 + use<> {
    let (r, rho) = (f.r, a.rho);
    move |cas: &mut Cas| {
        let rho_h = rho.map(|e| cas.scaled(0.5, e));
        let w = cas.dot(&rho_h, &rho_h);
        let w = cas.bind(w);
        let c = coefficients(cas, w, [0, 1, 2]);
        let turn = rotation(cas, &rho_h, c);
        std::array::from_fn(|i| {
            std::array::from_fn(|j| {
                let col = [turn[0][j], turn[1][j], turn[2][j]];
                let e = cas.dot(&r[i], &col);
                cas.bind(e)
            })
        })
    }
}

/// The turn exp([rho]x): its rotation, quaternion and angular velocity
/// (the left Jacobian applied to the rate) in the frame it turns from.
#[doc(hidden)] // white-box tests (tests/suite)
pub fn exp_turn(cas: &mut Cas, rho: &V3, rate: &V3) -> (M3, Quat, V3) {
    let wsq = cas.dot(rho, rho);
    let wsq = cas.bind(wsq);
    let [c0, c1, c2, c3] = coefficients(cas, wsq, [0, 1, 2, 3]);
    let r = rotation(cas, rho, [c0, c1, c2]);
    let w = left_jacobian(cas, rho, rate, [c1, c2, c3]);
    let q = rotation_quat(cas, rho, wsq);
    (r, q, w)
}

/// The frame turned by `q` about its own axis `k`.
pub(crate) fn revolute(cas: &mut Cas, f: &Frame, k: usize, q: ExprId, qd: ExprId) -> Frame {
    let (c, s) = (cas.cos(q), cas.sin(q));
    let (zero, one) = (cas.zero(), cas.one());
    let ns = cas.neg(s);
    let mut r = [[zero; 3]; 3];
    let (a, b) = ((k + 1) % 3, (k + 2) % 3);
    r[k][k] = one;
    r[a][a] = c;
    r[b][b] = c;
    r[a][b] = ns;
    r[b][a] = s;
    let mut w = [zero; 3];
    w[k] = qd;
    let half = cas.scaled(0.5, q);
    let mut quat = [zero; 4];
    quat[0] = cas.cos(half);
    quat[k + 1] = cas.sin(half);
    compose(cas, f, Some((&r, &quat)), None, Some(&w))
}

/// The frame moved by `d` along its axis.
pub(crate) fn advance(cas: &mut Cas, f: &Frame, d: ExprId) -> Frame {
    let zero = cas.zero();
    compose(cas, f, None, Some(&[d, zero, zero]), None)
}

/// A 3D arm under construction: the chain's state that every method's
/// elements extend (the current end frame, bodies, energies, links, lumped
/// strains, the next coordinate and element), and what is common to every
/// method: the base frame, gravity, actuation and the tip loads
/// ([`SpatialArm::finish`]). A method's file places its segments
/// (a method's `build_spatial`, in `method/`).
pub(crate) struct SpatialArm<'a> {
    pub symbols: &'a ParamSymbols,
    pub coords: Coordinates,
    pub zero: ExprId,
    /// The end frame of the chain so far.
    pub f: Frame,
    pub bodies: Vec<Body>,
    pub elastic: Vec<ExprId>,
    pub rayleigh: Vec<ExprId>,
    pub strains: Vec<Strain>,
    links: Vec<Link>,
    body_link: Vec<usize>,
    seeds: Vec<(ExprId, ExprId)>,
    /// What else moves its points: a compliant base's coordinates.
    moved_by: Vec<(ExprId, ExprId)>,
    /// The next coordinate.
    pub c: usize,
    /// The next element (slice, link).
    pub k: usize,
    /// Some links' coordinates are shared (rom slices): not a chain of
    /// links that own theirs, so M and h by the general sums.
    pub shared_coordinates: bool,
    /// Contact points per element, and the points sampled so far.
    pub points: usize,
    samples: Vec<Sample>,
    /// The loads along the arm, and what they apply so far.
    pub loads: Vec<AlongLoad>,
    applied: Applied,
}

/// An element's lumped quantities (parameters).
#[derive(Clone, Copy)]
pub(crate) struct Element3 {
    pub l: ExprId,
    pub m: ExprId,
    /// Each body's rotary inertia about its z axis, about its y axis (the
    /// same expression unless the section is anisotropic) and about its
    /// own axis.
    pub lateral: ExprId,
    pub lateral_y: ExprId,
    pub axial: ExprId,
}

impl Element3 {
    /// An element whose section bends alike about y and z.
    pub fn axisymmetric(l: ExprId, m: ExprId, lateral: ExprId, axial: ExprId) -> Self {
        Self {
            l,
            m,
            lateral,
            lateral_y: lateral,
            axial,
        }
    }

    fn anisotropic(&self) -> bool {
        self.lateral_y != self.lateral
    }

    /// Half of this element (a half-arc, `in_halves`): half the mass and
    /// axial inertia; laterally the element's lateral inertia is its
    /// section's rotary inertia (rho I l; axial / 2 when J = 2 I) and its
    /// slice's m l^2 / 12, of which a half of half the length carries half
    /// and an eighth: the section's half and m l^2 / 96.
    pub fn half(&self, cas: &mut Cas) -> Element3 {
        let axial = cas.scaled(0.5, self.axial);
        if self.anisotropic() {
            // The slice's part from the two laterals and the polar sum:
            // (lateral + lateral_y - axial) / 2.
            let both = cas.add(self.lateral, self.lateral_y);
            let both = cas.sub(both, self.axial);
            let slice = cas.scaled(0.5, both);
            let half = |cas: &mut Cas, lateral: ExprId| {
                let section = cas.sub(lateral, slice);
                let section = cas.scaled(0.5, section);
                let part = cas.scaled(0.125, slice);
                cas.add(section, part)
            };
            return Element3 {
                l: cas.scaled(0.5, self.l),
                m: cas.scaled(0.5, self.m),
                lateral: half(cas, self.lateral),
                lateral_y: half(cas, self.lateral_y),
                axial,
            };
        }
        let whole_section = cas.scaled(0.5, self.axial);
        let section = cas.scaled(0.25, self.axial);
        let slice = cas.sub(self.lateral, whole_section);
        let slice = cas.scaled(0.125, slice);
        let lateral = cas.add(section, slice);
        Element3::axisymmetric(
            cas.scaled(0.5, self.l),
            cas.scaled(0.5, self.m),
            lateral,
            axial,
        )
    }

    /// A body of this element's section, its own axis `axis`; an
    /// anisotropic section's principal axes are the columns of the body's
    /// rotation, `turn`, asked for only then.
    pub fn body(
        &self,
        cas: &mut Cas,
        (axis, turn): (V3, impl FnOnce(&mut Cas) -> M3),
        position: V3,
        omega: V3,
        mass: ExprId,
    ) -> Body {
        let inertia = match self.anisotropic() {
            false => Inertia::Axisymmetric {
                axis,
                axial: self.axial,
                lateral: self.lateral,
            },
            true => {
                let r = turn(cas);
                Inertia::Principal {
                    axes: std::array::from_fn(|k| [r[0][k], r[1][k], r[2][k]]),
                    moments: [self.axial, self.lateral_y, self.lateral],
                }
            }
        };
        Body {
            mass,
            inertia,
            position,
            omega,
        }
    }
}

/// A soft element's strain coordinates (bend y, bend z, twist, stretch)
/// with its springs, dampers and lumped strain recorded.
pub(crate) struct StrainElement {
    /// Rotation vector (twist, bend y, bend z) and its rate.
    pub rho: V3,
    pub rate: V3,
    /// The stretch and the stretched length l + stretch.
    pub stretch: ExprId,
    pub len: ExprId,
    /// The shear displacements along y and z, when the element shears.
    pub shear: Option<[ExprId; 2]>,
}

impl StrainElement {
    /// The arc of this strain.
    pub fn arc(&self) -> ArcStrain {
        ArcStrain {
            rho: self.rho,
            rate: self.rate,
            len: self.len,
            shear: self.shear,
        }
    }
}

impl<'a> SpatialArm<'a> {
    /// An arm of coordinates `names` (the methods' names) at the base.
    pub fn new(cas: &mut Cas, names: Vec<String>, symbols: &'a ParamSymbols) -> Self {
        let coords = Coordinates::new(cas, names);
        let zero = cas.zero();
        let base = symbols.base_motion(cas);
        let f = base_frame(cas, symbols, &base);
        Self {
            symbols,
            coords,
            zero,
            f,
            bodies: Vec::new(),
            elastic: Vec::new(),
            rayleigh: Vec::new(),
            strains: Vec::new(),
            links: Vec::new(),
            body_link: Vec::new(),
            seeds: base.seeds,
            moved_by: base.moved_by,
            c: 0,
            k: 0,
            shared_coordinates: false,
            points: 0,
            samples: Vec::new(),
            loads: Vec::new(),
            applied: Applied::default(),
        }
    }

    /// The current element's parameters.
    pub fn element(&self) -> Element3 {
        let e = |p| self.symbols.element(self.k, p);
        let lateral = e(ElementParam::Inertia);
        Element3 {
            l: e(ElementParam::Length),
            m: e(ElementParam::Mass),
            lateral,
            lateral_y: (self.symbols).element_or(self.k, ElementParam::InertiaY, lateral),
            axial: e(ElementParam::AxialInertia),
        }
    }

    /// The next coordinate and its rate.
    pub fn take(&mut self) -> (ExprId, ExprId) {
        let i = self.c;
        self.c += 1;
        (self.coords.q[i], self.coords.qd[i])
    }

    /// Points along the element: `at(s)` is the centreline's frame at the
    /// fraction s of the element, for s = 1/P, 2/P, ..., 1; `length` the
    /// centreline's, where the method knows it (a constant strain's).
    pub fn sample(
        &mut self,
        cas: &mut Cas,
        length: Option<ExprId>,
        at: impl Fn(&mut Cas, f64) -> Frame,
    ) {
        for j in 1..=self.points {
            let s = j as f64 / self.points as f64;
            let f = at(cas, s);
            let point = bind3(cas, f.p);
            let arc = length.map(|l| cas.scaled(s, l));
            self.samples
                .push(Sample::spatial(point, f.quat).at_arc(arc));
        }
        // The loads on this element, at the frames it places.
        let (k, link) = (self.k, self.links.len());
        let mut pairs = self.coords.rate_pairs();
        pairs.extend(&self.seeds);
        pairs.extend(&self.moved_by);
        self.applied.element(
            cas,
            &self.loads,
            (k, link),
            &mut |cas, s| {
                let f = at(cas, s);
                Placed {
                    point: f.p,
                    rotation: f.r,
                    omega: f.w,
                }
            },
            &pairs,
            self.symbols,
        );
    }

    /// The fluid the arm moves in: its drag, and its density for the
    /// buoyancy.
    pub fn set_fluid(&mut self, drag: Option<Drag>, buoyancy: Option<ExprId>) {
        self.applied.drag = drag;
        self.applied.buoyancy = buoyancy;
    }

    /// The shape's first point: the frame the arm starts from.
    pub fn base_pose(&self) -> Sample {
        Sample::spatial(self.f.p, self.f.quat)
    }

    /// A kink: the end frame moved by `offset` (in itself) and turned by
    /// the rotation vector `turn`, both constant.
    pub fn kink(&mut self, cas: &mut Cas, turn: &V3, offset: &V3) {
        let zero = cas.zero();
        let (r, q, _) = exp_turn(cas, turn, &[zero; 3]);
        self.f = compose(cas, &self.f, Some((&r, &q)), Some(offset), None);
    }

    /// Move the end frame by `d` along its axis.
    pub fn advance(&mut self, cas: &mut Cas, d: ExprId) {
        self.f = advance(cas, &self.f, d);
    }

    /// The element ends here: its bodies so far belong to a link that owns
    /// coordinates `first..` (none past them) and ends at the end frame.
    pub fn close_link(&mut self, first: usize) {
        self.body_link.resize(self.bodies.len(), self.links.len());
        self.links.push(Link {
            coords: (first..self.c).collect(),
            end: self.f.p,
            end_omega: self.f.w,
        });
        self.k += 1;
    }

    /// Take a soft element's strain coordinates (bend y, bend z, then twist
    /// and stretch as `g` has them), record its lumped strain, and add its
    /// springs and dampers (thinned with the stretch if incompressible).
    pub fn strain_element(
        &mut self,
        cas: &mut Cas,
        g: &SegmentShape,
        s: usize,
        el: &Element3,
    ) -> StrainElement {
        let zero = self.zero;
        let (by, by_d) = self.take();
        let (bz, bz_d) = self.take();
        let (tw, tw_d) = if g.twist { self.take() } else { (zero, zero) };
        let (st, st_d) = if g.extension {
            self.take()
        } else {
            (zero, zero)
        };
        let shear = g.shear.then(|| [self.take(), self.take()]);
        let rho = [tw, by, bz];
        let rate = [tw_d, by_d, bz_d];
        let len = cas.add(el.l, st);
        // Incompressible: the stretch thins the section.
        let thin = g.incompressible.then(|| thinning(cas, el.l, len));
        self.strains.push(Strain {
            segment: s,
            element: self.k,
            stretch: st,
            rho,
            offset_scale: thin.map(|t| t.1),
        });
        let e = |p| self.symbols.element(self.k, p);
        let rest = |p| self.symbols.element_or(self.k, p, zero);
        let bend = e(ElementParam::BendStiffness);
        let springs = Springs {
            bend,
            bend_y: self
                .symbols
                .element_or(self.k, ElementParam::BendStiffnessY, bend),
            bend_damping: e(ElementParam::BendDamping),
            rest: [rest(ElementParam::RestY), e(ElementParam::Rest)],
            twist: e(ElementParam::TwistStiffness),
            twist_damping: e(ElementParam::TwistDamping),
            rest_twist: rest(ElementParam::RestTwist),
            stretch: e(ElementParam::StretchStiffness),
            stretch_damping: e(ElementParam::StretchDamping),
            rest_stretch: rest(ElementParam::RestStretch),
        };
        let (mut e, mut d) = springs.energies(
            cas,
            [by, bz, tw, st],
            [by_d, bz_d, tw_d, st_d],
            thin.map(|t| t.0),
        );
        if let Some(pairs) = shear {
            let k = self.symbols.element(self.k, ElementParam::ShearStiffness);
            // Along z an anisotropic section's own.
            let k_z = (self.symbols).element_or(self.k, ElementParam::ShearStiffnessZ, k);
            // Shear rates damped as the stretch's (`axial_damping`).
            let c = self.symbols.element(self.k, ElementParam::StretchDamping);
            let terms: Vec<ExprId> = (pairs.iter().zip([k, k_z]))
                .map(|(&(x, _), k)| half_k_sq(cas, k, x))
                .collect();
            let damped: Vec<ExprId> = pairs.iter().map(|&(_, xd)| half_k_sq(cas, c, xd)).collect();
            e = cas.add_all(&[&[e][..], &terms].concat());
            d = cas.add_all(&[&[d][..], &damped].concat());
        }
        self.elastic.push(e);
        self.rayleigh.push(d);
        StrainElement {
            rho,
            rate,
            stretch: st,
            len,
            shear: shear.map(|[(y, _), (z, _)]| [y, z]),
        }
    }

    /// The system: what the elements built, plus gravity, actuation and the
    /// tip loads, written once for every method.
    pub fn finish(self, cas: &mut Cas, structure: &Structure) -> System {
        let Self {
            symbols,
            coords,
            f,
            bodies,
            elastic,
            rayleigh,
            strains,
            links,
            body_link,
            seeds,
            shared_coordinates,
            samples,
            applied,
            ..
        } = self;
        let last_link = links.len().saturating_sub(1);
        let elastic = cas.add_all(&elastic);
        let rayleigh = cas.add_all(&rayleigh);
        let actuation = actuation(cas, symbols, structure, &strains);
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
            tip: f.p,
            tip_orientation: f.quat,
            chain: (!links.is_empty() && !shared_coordinates).then_some(Chain {
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
            planar: None,
        };
        let mount = TipMount {
            point: f.p,
            axis: f.axis(),
            omega: f.w,
            rotation: f.r,
        };
        applied.attach(cas, &mut sys, symbols, &element_of_body);
        let tip = tip_loads(cas, symbols, structure, &mount);
        sys.attach_tip(tip, last_link);
        sys
    }
}

/// The base frame at its position: the prescribed turns in sequence, each
/// about its axis `base.axis[i]` in the frame the turns before it left, a
/// compliant base's turn exp([rho]x), then the declared direction
/// (rotation and quaternion parameters).
pub(crate) fn base_frame(
    cas: &mut Cas,
    symbols: &super::system::ParamSymbols,
    base: &super::system::BaseMotion,
) -> Frame {
    let (position, turns) = (base.position, &base.turns);
    let r: M3 = symbols.base_rotation();
    let q = std::array::from_fn(|c| symbols.get(Param::BaseQuaternion(c as u8)));
    if let Some(super::system::MountFrame::Spatial { r: mr, p, w, quat }) = symbols.mount() {
        // On another arm's frame: the position, then the direction, in it.
        let f = Frame { r: mr, p, w, quat };
        let f = compose(cas, &f, None, Some(&position), None);
        return compose(cas, &f, Some((&r, &q)), None, None);
    }
    let one = cas.one();
    let mut f = Frame::at_rest(cas, position);
    for (i, &(angle, rate)) in turns.iter().enumerate() {
        let n = symbols.xyz(|c| Param::BaseTurnAxis(i, c));
        // exp(angle [n]x) = cos I + sin [n]x + (1 - cos) n n^T, n a unit vector.
        let (c, s) = (cas.cos(angle), cas.sin(angle));
        let versine = cas.sub(one, c);
        let r = rotation(cas, &n, [c, s, versine]);
        let half = cas.scaled(0.5, angle);
        let (ch, sh) = (cas.cos(half), cas.sin(half));
        let q = [ch, cas.mul(sh, n[0]), cas.mul(sh, n[1]), cas.mul(sh, n[2])];
        let w = n.map(|k| cas.mul(k, rate));
        f = compose(cas, &f, Some((&r, &q)), None, Some(&w));
    }
    let still = turns.is_empty() && base.twist.is_none();
    if let Some((rho, rate)) = &base.twist {
        let (r, q, w) = exp_turn(cas, rho, rate);
        f = compose(cas, &f, Some((&r, &q)), None, Some(&w));
    }
    if still {
        // The identity folds away, but say so: a still base is its parameters.
        return Frame { r, quat: q, ..f };
    }
    compose(cas, &f, Some((&r, &q)), None, None)
}

/// An element's springs and dampers (pcc, vc, ebr; a link cell's too).
pub(crate) struct Springs {
    /// E I / l about z, and about y (the same but for anisotropic
    /// sections).
    pub bend: ExprId,
    pub bend_y: ExprId,
    pub bend_damping: ExprId,
    /// Rest bend about y and about z.
    pub rest: [ExprId; 2],
    pub twist: ExprId,
    pub twist_damping: ExprId,
    pub rest_twist: ExprId,
    pub stretch: ExprId,
    pub stretch_damping: ExprId,
    pub rest_stretch: ExprId,
}

impl Springs {
    /// Strain energy and Rayleigh function of the strain coordinates (bend
    /// about y, about z, twist, stretch; a zero where the element has
    /// none, whose terms then fold away), bending and twist stiffness
    /// scaled by `soft` when stretching thins the section.
    pub(crate) fn energies(
        &self,
        cas: &mut Cas,
        [by, bz, tw, st]: [ExprId; 4],
        [by_d, bz_d, tw_d, st_d]: [ExprId; 4],
        soft: Option<ExprId>,
    ) -> (ExprId, ExprId) {
        let soften = |cas: &mut Cas, k: ExprId| soft.map_or(k, |s| cas.mul(k, s));
        let kb = soften(cas, self.bend);
        let kb_y = soften(cas, self.bend_y);
        let kt = soften(cas, self.twist);
        let by_rel = cas.sub(by, self.rest[0]);
        let bz_rel = cas.sub(bz, self.rest[1]);
        let tw_rel = cas.sub(tw, self.rest_twist);
        let st_rel = cas.sub(st, self.rest_stretch);
        let elastic = [
            half_k_sq(cas, kb_y, by_rel),
            half_k_sq(cas, kb, bz_rel),
            half_k_sq(cas, kt, tw_rel),
            half_k_sq(cas, self.stretch, st_rel),
        ];
        let rayleigh = [
            half_k_sq(cas, self.bend_damping, by_d),
            half_k_sq(cas, self.bend_damping, bz_d),
            half_k_sq(cas, self.twist_damping, tw_d),
            half_k_sq(cas, self.stretch_damping, st_d),
        ];
        (cas.add_all(&elastic), cas.add_all(&rayleigh))
    }
}

/// k x^2 / 2
pub(crate) fn half_k_sq(cas: &mut Cas, k: ExprId, x: ExprId) -> ExprId {
    let x2 = cas.powi(x, 2);
    let e = cas.mul(k, x2);
    cas.scaled(0.5, e)
}

//! 3D kinematics: serial chains of frames (rotation R, origin p, world
//! angular velocity w) that each element maps from its base to its end.
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
use crate::model::{ElementParam, Joints, Method, Param, Structure};

use super::actuation::{Strain, actuation, thinning};
use super::system::{
    Body, Chain, Coordinates, Inertia, Link, ParamSymbols, System, TipMount, tip_loads,
};

pub(super) type V3 = [ExprId; 3];
/// Rows of a rotation matrix.
pub(super) type M3 = [[ExprId; 3]; 3];
/// A quaternion (w, x, y, z).
pub(super) type Quat = [ExprId; 4];

/// The Hamilton product a b, bound.
pub(super) fn quat_mul(cas: &mut Cas, a: &Quat, b: &Quat) -> Quat {
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
pub(super) fn rotation_quat(cas: &mut Cas, rho: &V3, w: ExprId) -> Quat {
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
pub(super) struct Frame {
    pub r: M3,
    pub p: V3,
    pub w: V3,
    /// The orientation as a unit quaternion (w, x, y, z), composed alongside
    /// R (an output only: exact products, no square roots).
    pub quat: Quat,
}

impl Frame {
    /// The frame's x axis in the world.
    fn axis(&self) -> V3 {
        [self.r[0][0], self.r[1][0], self.r[2][0]]
    }
}

pub(super) fn add3(cas: &mut Cas, a: &V3, b: &V3) -> V3 {
    std::array::from_fn(|k| cas.add(a[k], b[k]))
}

pub(super) fn bind3(cas: &mut Cas, v: V3) -> V3 {
    v.map(|e| cas.bind(e))
}

/// The frame moved by a relative rotation `r_rel`, offset `p_rel` and
/// relative angular velocity `w_rel`, all in the frame's own coordinates.
fn compose(
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
pub(super) fn coefficients<const N: usize>(cas: &mut Cas, w: ExprId, js: [u8; N]) -> [ExprId; N] {
    js.map(|j| {
        let c = cas.func(Func::Rodrigues(j, 0), w);
        cas.bind(c)
    })
}

/// exp([rho]x) = c0 I + c1 [rho]x + c2 rho rho^T.
pub(super) fn rotation(cas: &mut Cas, rho: &V3, c: [ExprId; 3]) -> M3 {
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
pub(super) fn left_jacobian(cas: &mut Cas, rho: &V3, rate: &V3, c: [ExprId; 3]) -> V3 {
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

/// A constant-strain arc of length `len` (rest length plus stretch) and
/// strain `rho` from frame `f`: its centroid, its body's axis and angular
/// velocity (the mid-arc frame), and the end frame.
pub(super) fn arc(
    cas: &mut Cas,
    f: &Frame,
    rho: &V3,
    rate: &V3,
    len: ExprId,
) -> (V3, V3, V3, Frame) {
    let w = cas.dot(rho, rho);
    let w = cas.bind(w);
    let [c0, c1, c2, c3, c4] = coefficients(cas, w, [0, 1, 2, 3, 4]);
    let one = cas.one();
    let half = cas.constant(0.5);
    // End frame.
    let chord = series_on_x(cas, rho, w, one, c2, c3);
    let chord = chord.map(|e| cas.mul(len, e));
    let r_rel = rotation(cas, rho, [c0, c1, c2]);
    let w_rel = left_jacobian(cas, rho, rate, [c1, c2, c3]);
    let q_rel = rotation_quat(cas, rho, w);
    let end = compose(cas, f, Some((&r_rel, &q_rel)), Some(&chord), Some(&w_rel));
    // Centroid.
    let c = series_on_x(cas, rho, w, half, c3, c4);
    let c = c.map(|e| {
        let e = cas.mul(len, e);
        cas.bind(e)
    });
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

/// The frame turned by `q` about its own axis `k`.
fn revolute(cas: &mut Cas, f: &Frame, k: usize, q: ExprId, qd: ExprId) -> Frame {
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
fn advance(cas: &mut Cas, f: &Frame, d: ExprId) -> Frame {
    let zero = cas.zero();
    compose(cas, f, None, Some(&[d, zero, zero]), None)
}

/// Build the 3D system of a model. Only the structure and the parameter
/// layout are read from `model`; values stay symbols.
pub fn spatial_system(cas: &mut Cas, structure: &Structure, symbols: &ParamSymbols) -> System {
    let coords = Coordinates::new(cas, structure.coordinate_names());
    let zero = cas.zero();

    let base = symbols.base_motion(cas);
    let mut f = base_frame(cas, symbols, base.position, &base.turns);
    let mut bodies = Vec::new();
    let mut elastic = Vec::new();
    let mut rayleigh = Vec::new();
    let mut links = Vec::new();
    let mut body_link = Vec::new();
    let mut strains = Vec::new();
    let mut c = 0; // next coordinate
    let mut k = 0; // element
    for (s, g) in structure.segments.iter().enumerate() {
        // rom: the segment's coefficients, shared by its slices, and its
        // strain energy integrated exactly.
        let rom = (g.method == Method::Rom).then(|| {
            let r = Rom::of(g, c);
            c += r.coordinates();
            let [e, d] = r.energies(cas, &coords, symbols, k);
            elastic.push(e);
            rayleigh.push(d);
            r
        });
        for e in 0..g.elements {
            let l = symbols.element(k, ElementParam::Length);
            let m = symbols.element(k, ElementParam::Mass);
            let lateral = symbols.element(k, ElementParam::Inertia);
            let axial = symbols.element(k, ElementParam::AxialInertia);
            let first = c;
            let body = |axis: V3, position: V3, omega: V3, mass: ExprId| Body {
                mass,
                inertia: Inertia::Axisymmetric {
                    axis,
                    axial,
                    lateral,
                },
                position,
                omega,
            };
            if g.method == Method::Rigid {
                let stiff = symbols.element(k, ElementParam::BendStiffness);
                let twist = symbols.element(k, ElementParam::TwistStiffness);
                let damp = symbols.element(k, ElementParam::BendDamping);
                let rest = symbols.element(k, ElementParam::Rest);
                let mut turn = |cas: &mut Cas, f: &Frame| {
                    let mut f = *f;
                    // The joint's lumped strain: its angles about their
                    // axes (exact for one axis, first order for several).
                    let mut rho = [zero; 3];
                    for &a in &g.axes {
                        let (q, qd) = (coords.q[c], coords.qd[c]);
                        rho[a.index()] = cas.add(rho[a.index()], q);
                        f = revolute(cas, &f, a.index(), q, qd);
                        let (kq, q_rest) = if a.index() == 0 {
                            (twist, zero)
                        } else {
                            (stiff, if a.index() == 2 { rest } else { zero })
                        };
                        let dq = cas.sub(q, q_rest);
                        elastic.push(half_k_sq(cas, kq, dq));
                        rayleigh.push(half_k_sq(cas, damp, qd));
                        c += 1;
                    }
                    strains.push(Strain {
                        segment: s,
                        stretch: zero,
                        rho,
                        offset_scale: None,
                    });
                    f
                };
                match g.joints {
                    Joints::Base => {
                        f = turn(cas, &f);
                        let half = cas.scaled(0.5, l);
                        let mid = advance(cas, &f, half);
                        bodies.push(body(f.axis(), mid.p, f.w, m));
                        f = advance(cas, &f, l);
                    }
                    Joints::Midpoint => {
                        let (quarter, half) = (cas.scaled(0.25, l), cas.scaled(0.5, l));
                        let half_m = cas.scaled(0.5, m);
                        let b = advance(cas, &f, quarter);
                        bodies.push(body(f.axis(), b.p, f.w, half_m));
                        f = advance(cas, &f, half);
                        f = turn(cas, &f);
                        let b = advance(cas, &f, quarter);
                        bodies.push(body(f.axis(), b.p, f.w, half_m));
                        f = advance(cas, &f, half);
                    }
                }
            } else if let Some(rom) = &rom {
                let (rho, rate, st) = rom.slice(cas, &coords, e, l);
                let len = cas.add(l, st);
                // Incompressible: bending and twist energy slice by slice
                // with the slice's thinning (Rom::energies leaves them out).
                let thin = rom.incompressible.then(|| {
                    let (soft, off) = thinning(cas, l, len);
                    let kb = symbols.element(k, ElementParam::BendStiffness);
                    let kt = symbols.element(k, ElementParam::TwistStiffness);
                    let rest = symbols.element(k, ElementParam::Rest);
                    let bz = cas.sub(rho[2], rest);
                    for (kk, x) in [(kb, rho[1]), (kb, bz), (kt, rho[0])] {
                        let kk = cas.mul(kk, soft);
                        elastic.push(half_k_sq(cas, kk, x));
                    }
                    off
                });
                strains.push(Strain {
                    segment: s,
                    stretch: st,
                    rho,
                    offset_scale: thin,
                });
                let (centroid, axis, omega, end) = arc(cas, &f, &rho, &rate, len);
                let centroid = bind3(cas, centroid);
                bodies.push(body(axis, centroid, omega, m));
                f = end;
            } else {
                // Strain coordinates: bend about y, about z, twist, stretch.
                let take = |c: &mut usize| {
                    let i = *c;
                    *c += 1;
                    (coords.q[i], coords.qd[i])
                };
                let (by, by_d) = take(&mut c);
                let (bz, bz_d) = take(&mut c);
                let (tw, tw_d) = if g.twist { take(&mut c) } else { (zero, zero) };
                let (st, st_d) = if g.extension {
                    take(&mut c)
                } else {
                    (zero, zero)
                };
                let rho = [tw, by, bz];
                let rate = [tw_d, by_d, bz_d];
                let len = cas.add(l, st);
                // Incompressible: the stretch thins the section.
                let thin = g.incompressible.then(|| thinning(cas, l, len));
                strains.push(Strain {
                    segment: s,
                    stretch: st,
                    rho,
                    offset_scale: thin.map(|t| t.1),
                });
                let springs = Springs {
                    bend: symbols.element(k, ElementParam::BendStiffness),
                    bend_damping: symbols.element(k, ElementParam::BendDamping),
                    rest: symbols.element(k, ElementParam::Rest),
                    twist: symbols.element(k, ElementParam::TwistStiffness),
                    twist_damping: symbols.element(k, ElementParam::TwistDamping),
                    stretch: symbols.element(k, ElementParam::StretchStiffness),
                    stretch_damping: symbols.element(k, ElementParam::StretchDamping),
                };
                let (e, d) = springs.energies(
                    cas,
                    [by, bz, tw, st],
                    [by_d, bz_d, tw_d, st_d],
                    thin.map(|t| t.0),
                );
                elastic.push(e);
                rayleigh.push(d);
                match g.method {
                    Method::Ebr => {
                        let (quarter, half) = (cas.scaled(0.25, l), cas.scaled(0.5, l));
                        let half_m = cas.scaled(0.5, m);
                        let b = advance(cas, &f, quarter);
                        bodies.push(body(f.axis(), b.p, f.w, half_m));
                        f = advance(cas, &f, half);
                        let wsq = cas.dot(&rho, &rho);
                        let wsq = cas.bind(wsq);
                        let [c0, c1, c2, c3] = coefficients(cas, wsq, [0, 1, 2, 3]);
                        let r_rel = rotation(cas, &rho, [c0, c1, c2]);
                        let w_rel = left_jacobian(cas, &rho, &rate, [c1, c2, c3]);
                        let q_rel = rotation_quat(cas, &rho, wsq);
                        f = compose(cas, &f, Some((&r_rel, &q_rel)), None, Some(&w_rel));
                        let b_len = cas.add(half, st);
                        let half_b = cas.scaled(0.5, b_len);
                        let b = advance(cas, &f, half_b);
                        bodies.push(body(f.axis(), b.p, f.w, half_m));
                        f = advance(cas, &f, b_len);
                    }
                    _ => {
                        let (centroid, axis, omega, end) = arc(cas, &f, &rho, &rate, len);
                        let centroid = bind3(cas, centroid);
                        bodies.push(body(axis, centroid, omega, m));
                        f = end;
                    }
                }
            }
            body_link.resize(bodies.len(), links.len());
            links.push(Link {
                coords: (first..c).collect(),
                end: f.p,
                end_omega: f.w,
            });
            k += 1;
        }
    }

    let has_rom = structure.segments.iter().any(|g| g.method == Method::Rom);
    let last_link = links.len().saturating_sub(1);
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
        tip: f.p,
        tip_orientation: f.quat,
        // rom slices share their segment's coordinates: not a chain of
        // links that own theirs, so M and h by the general sums.
        chain: (!links.is_empty() && !has_rom).then_some(Chain {
            links,
            body_link,
            point_force_link: Vec::new(),
            moment_link: Vec::new(),
        }),
        seeds: base.seeds,
    };
    let mount = TipMount {
        point: f.p,
        axis: f.axis(),
        omega: f.w,
        rotation: f.r,
    };
    let tip = tip_loads(cas, symbols, structure, &mount);
    sys.attach_tip(tip, last_link);
    sys
}

/// The base frame at `position`: the prescribed turns in sequence, each
/// about its axis `base.axis[i]` in the frame the turns before it left,
/// then the declared direction (rotation and quaternion parameters).
pub(super) fn base_frame(
    cas: &mut Cas,
    symbols: &super::system::ParamSymbols,
    position: V3,
    turns: &[(ExprId, ExprId)],
) -> Frame {
    let (zero, one) = (cas.zero(), cas.one());
    let mut f = Frame {
        r: std::array::from_fn(|i| std::array::from_fn(|j| if i == j { one } else { zero })),
        p: position,
        w: [zero; 3],
        quat: [one, zero, zero, zero],
    };
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
    let r: M3 = std::array::from_fn(|i| {
        std::array::from_fn(|j| symbols.get(Param::BaseRotation(i as u8, j as u8)))
    });
    let q = std::array::from_fn(|c| symbols.get(Param::BaseQuaternion(c as u8)));
    if turns.is_empty() {
        // The identity folds away, but say so: a still base is its parameters.
        return Frame { r, quat: q, ..f };
    }
    compose(cas, &f, Some((&r, &q)), None, None)
}

/// A rom segment: strain fields sum_i c_i sigma^i over sigma = s / L in
/// [0, 1], the coefficients c (angles: curvature times L; the stretch
/// field is dimensionless) its coordinates, field by field.
pub(super) struct Rom {
    pub first: usize,
    pub order: usize,
    pub slices: usize,
    pub twist: bool,
    pub extension: bool,
    /// Bending and twist energy by slices (see `spatial_system`), not here.
    pub incompressible: bool,
}

impl Rom {
    /// The rom of segment shape `g` whose coefficients start at `first`.
    pub(super) fn of(g: &crate::model::SegmentShape, first: usize) -> Self {
        Rom {
            first,
            order: g.order,
            slices: g.elements,
            twist: g.twist,
            extension: g.extension,
            incompressible: g.incompressible,
        }
    }

    pub(super) fn coordinates(&self) -> usize {
        (2 + usize::from(self.twist) + usize::from(self.extension)) * (self.order + 1)
    }

    /// Coordinate index of coefficient i of field f.
    pub(super) fn index(&self, f: usize, i: usize) -> usize {
        self.first + f * (self.order + 1) + i
    }

    /// int over slice e of sigma^i d sigma, for each i.
    pub(super) fn weights(&self, e: usize) -> Vec<f64> {
        let n = self.slices as f64;
        let (a, b) = (e as f64 / n, (e + 1) as f64 / n);
        (0..=self.order)
            .map(|i| {
                let p = (i + 1) as i32;
                (b.powi(p) - a.powi(p)) / p as f64
            })
            .collect()
    }

    /// One field integrated over slice e, of q (or, with `rates`, of qd).
    fn field(
        &self,
        cas: &mut Cas,
        coords: &Coordinates,
        f: usize,
        e: usize,
        rates: bool,
    ) -> ExprId {
        let terms: Vec<ExprId> = self
            .weights(e)
            .into_iter()
            .enumerate()
            .map(|(i, w)| {
                let j = self.index(f, i);
                let x = if rates { coords.qd[j] } else { coords.q[j] };
                cas.scaled(w, x)
            })
            .collect();
        cas.add_all(&terms)
    }

    /// The rotation vector of slice e (twist, bend y, bend z), its rate,
    /// and the slice's stretch, given the slice length l.
    fn slice(&self, cas: &mut Cas, coords: &Coordinates, e: usize, l: ExprId) -> (V3, V3, ExprId) {
        let zero = cas.zero();
        let mut rho = [zero; 3];
        let mut rate = [zero; 3];
        // Fields 0, 1 bend about y, z; then twist (about x); then stretch.
        for (f, axis) in [(0, 1), (1, 2)] {
            rho[axis] = self.field(cas, coords, f, e, false);
            rate[axis] = self.field(cas, coords, f, e, true);
        }
        if self.twist {
            rho[0] = self.field(cas, coords, 2, e, false);
            rate[0] = self.field(cas, coords, 2, e, true);
        }
        let stretch = if self.extension {
            // The strain integrated over the slice, times L = slices * l.
            let f = 2 + usize::from(self.twist);
            let s = self.field(cas, coords, f, e, false);
            let ls = cas.mul(l, s);
            cas.scaled(self.slices as f64, ls)
        } else {
            zero
        };
        (rho.map(|x| cas.bind(x)), rate.map(|x| cas.bind(x)), stretch)
    }

    /// Strain energy and Rayleigh function, integrated exactly:
    /// (k / 2) int_0^1 (field - rest)^2 d sigma with int sigma^(i+j) = 1 /
    /// (i + j + 1). Per-slice parameters of slice k: E I / l = slices E I / L.
    pub(super) fn energies(
        &self,
        cas: &mut Cas,
        coords: &Coordinates,
        symbols: &ParamSymbols,
        k: usize,
    ) -> [ExprId; 2] {
        let n = self.slices as f64;
        let quad = |cas: &mut Cas, x: &[ExprId]| {
            let mut terms = Vec::new();
            for (i, &a) in x.iter().enumerate() {
                for (j, &b) in x.iter().enumerate() {
                    let ab = cas.mul(a, b);
                    terms.push(cas.scaled(1.0 / (i + j + 1) as f64, ab));
                }
            }
            cas.add_all(&terms)
        };
        let fields = 2 + usize::from(self.twist) + usize::from(self.extension);
        let (mut elastic, mut rayleigh) = (Vec::new(), Vec::new());
        for f in 0..fields {
            let stretch = self.extension && f == fields - 1;
            if self.incompressible && !stretch {
                // Only the elastic part moves to the slices; damping stays.
                let ds = symbols.element(
                    k,
                    match f {
                        0 | 1 => ElementParam::BendDamping,
                        _ => ElementParam::TwistDamping,
                    },
                );
                let xd: Vec<ExprId> = (0..=self.order)
                    .map(|i| coords.qd[self.index(f, i)])
                    .collect();
                let d = quad(cas, &xd);
                let scale = cas.constant(1.0 / n);
                rayleigh.push(cas.mul_all(&[ds, scale, d]));
                continue;
            }
            let (stiff, damp) = match f {
                _ if stretch => (ElementParam::StretchStiffness, ElementParam::StretchDamping),
                0 | 1 => (ElementParam::BendStiffness, ElementParam::BendDamping),
                _ => (ElementParam::TwistStiffness, ElementParam::TwistDamping),
            };
            let ks = symbols.element(k, stiff);
            let ds = symbols.element(k, damp);
            // Bending, twist: (E I / L) c^T G c = (k_slice / n) ...; stretch:
            // E A L e^T G e = k_slice n l^2 ....
            let scale = if stretch {
                let l = symbols.element(k, ElementParam::Length);
                let l2 = cas.powi(l, 2);
                cas.scaled(n, l2)
            } else {
                cas.constant(1.0 / n)
            };
            let mut x: Vec<ExprId> = (0..=self.order)
                .map(|i| coords.q[self.index(f, i)])
                .collect();
            if f == 1 {
                // Rest curvature about z, constant along s: kappa0 L = n rest.
                let rest = symbols.element(k, ElementParam::Rest);
                let r = cas.scaled(n, rest);
                x[0] = cas.sub(x[0], r);
            }
            let xd: Vec<ExprId> = (0..=self.order)
                .map(|i| coords.qd[self.index(f, i)])
                .collect();
            let e = quad(cas, &x);
            let d = quad(cas, &xd);
            elastic.push(cas.mul_all(&[ks, scale, e]));
            rayleigh.push(cas.mul_all(&[ds, scale, d]));
        }
        let e = cas.add_all(&elastic);
        let d = cas.add_all(&rayleigh);
        [cas.scaled(0.5, e), cas.scaled(0.5, d)]
    }
}

/// An element's springs and dampers (pcc, vc, ebr; a link cell's too).
pub(super) struct Springs {
    pub bend: ExprId,
    pub bend_damping: ExprId,
    /// Rest bend about z.
    pub rest: ExprId,
    pub twist: ExprId,
    pub twist_damping: ExprId,
    pub stretch: ExprId,
    pub stretch_damping: ExprId,
}

impl Springs {
    /// Strain energy and Rayleigh function of the strain coordinates (bend
    /// about y, about z, twist, stretch; a zero where the element has
    /// none, whose terms then fold away), bending and twist stiffness
    /// scaled by `soft` when stretching thins the section.
    pub(super) fn energies(
        &self,
        cas: &mut Cas,
        [by, bz, tw, st]: [ExprId; 4],
        [by_d, bz_d, tw_d, st_d]: [ExprId; 4],
        soft: Option<ExprId>,
    ) -> (ExprId, ExprId) {
        let soften = |cas: &mut Cas, k: ExprId| soft.map_or(k, |s| cas.mul(k, s));
        let kb = soften(cas, self.bend);
        let kt = soften(cas, self.twist);
        let bz_rel = cas.sub(bz, self.rest);
        let elastic = [
            half_k_sq(cas, kb, by),
            half_k_sq(cas, kb, bz_rel),
            half_k_sq(cas, kt, tw),
            half_k_sq(cas, self.stretch, st),
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
pub(super) fn half_k_sq(cas: &mut Cas, k: ExprId, x: ExprId) -> ExprId {
    let x2 = cas.powi(x, 2);
    let e = cas.mul(k, x2);
    cas.scaled(0.5, e)
}

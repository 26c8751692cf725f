//! The mass matrix of a serial chain by composite bodies.
//!
//! M = sum_b T_b^T Mbar_b T_b is the same matrix whatever the order of the
//! sum. Summed per body it costs O(n) per entry (the lever arm of every
//! downstream body is a sum over the links between), O(n^3) in all. In a
//! chain, a coordinate j moves everything past its link rigidly, by one
//! twist S_j; the downstream bodies then enter only through their summed
//! spatial inertia about the world origin (m, h = sum m r, J = sum I + m
//! ([r]x^T [r]x)), which is a suffix sum over links. So, for coordinates
//! i <= j in links L(i) <= L(j):
//!
//! * L(i) < L(j): M_ij = S_i . Phi_j, with Phi_j the spatial momentum of
//!   unit qd_j: the composite past L(j) moving with S_j plus the bodies of
//!   L(j) moving with their own columns of T;
//! * L(i) = L(j): M_ij = S_i . C_{>L} S_j + sum over the bodies of L of
//!   their own T columns, T_bi^T Mbar_b T_bj.
//!
//! Five operations an entry plus O(n) set-up: Featherstone's composite
//! rigid body algorithm, written as CAS expressions so that everything
//! downstream (the symbolic L D L^T solve, hoisting, CSE) treats it like any
//! other expression.

use crate::cas::{Cas, ExprId};

use super::system::{Chain, Inertia, System};

/// A spatial inertia about the world origin: mass, first moment m r and
/// rotational inertia J, symmetric, stored xx, yy, zz, xy, xz, yz.
#[derive(Clone, Copy)]
struct SpatialInertia {
    m: ExprId,
    h: [ExprId; 3],
    j: [ExprId; 6],
}

/// A twist (angular velocity, velocity of the point at the world origin)
/// or a spatial momentum (angular momentum about the origin, linear
/// momentum): the pairing of one with the other is the power.
type Spatial = ([ExprId; 3], [ExprId; 3]);

fn sym_mul(cas: &mut Cas, j: &[ExprId; 6], w: &[ExprId; 3]) -> [ExprId; 3] {
    // Row k of the symmetric matrix, by index into the packed storage.
    const ROWS: [[usize; 3]; 3] = [[0, 3, 4], [3, 1, 5], [4, 5, 2]];
    ROWS.map(|row| {
        let terms: Vec<ExprId> = (0..3).map(|c| cas.mul(j[row[c]], w[c])).collect();
        cas.add_all(&terms)
    })
}

impl SpatialInertia {
    /// A body of mass m at r with rotational inertia `inertia` about its
    /// centre of mass.
    fn of_body(cas: &mut Cas, m: ExprId, r: &[ExprId; 3], inertia: &Inertia) -> Self {
        let h = r.map(|c| cas.mul(m, c));
        let r2 = cas.dot(r, r);
        let i = inertia.packed(cas);
        // J + m (|r|^2 1 - r r^T)
        let diag: [ExprId; 3] = std::array::from_fn(|k| {
            let rk2 = cas.powi(r[k], 2);
            let d = cas.sub(r2, rk2);
            let md = cas.mul(m, d);
            cas.add(i[k], md)
        });
        let off = [(0, 1, 3), (0, 2, 4), (1, 2, 5)].map(|(a, b, k)| {
            let p = cas.mul(h[a], r[b]);
            cas.sub(i[k], p)
        });
        Self {
            m,
            h,
            j: [diag[0], diag[1], diag[2], off[0], off[1], off[2]],
        }
    }

    fn sum(cas: &mut Cas, parts: &[Self]) -> Self {
        let m = cas.add_all(&parts.iter().map(|p| p.m).collect::<Vec<_>>());
        let h = std::array::from_fn(|k| {
            let terms: Vec<ExprId> = parts.iter().map(|p| p.h[k]).collect();
            cas.add_all(&terms)
        });
        let j = std::array::from_fn(|k| {
            let terms: Vec<ExprId> = parts.iter().map(|p| p.j[k]).collect();
            cas.add_all(&terms)
        });
        Self { m, h, j }.bound(cas)
    }

    /// Bound, so that the suffix sums nest instead of flattening into
    /// O(n^2) terms.
    fn bound(self, cas: &mut Cas) -> Self {
        Self {
            m: cas.bind(self.m),
            h: self.h.map(|e| cas.bind(e)),
            j: self.j.map(|e| cas.bind(e)),
        }
    }

    /// The momentum of the twist (w, v): (J w + h x v, m v + w x h).
    fn momentum(&self, cas: &mut Cas, twist: &Spatial) -> Spatial {
        let (w, v) = twist;
        let jw = sym_mul(cas, &self.j, w);
        let hv = cas.cross(&self.h, v);
        let wh = cas.cross(w, &self.h);
        let ang = std::array::from_fn(|k| cas.add(jw[k], hv[k]));
        let lin = std::array::from_fn(|k| {
            let mv = cas.mul(self.m, v[k]);
            cas.add(mv, wh[k])
        });
        (ang, lin)
    }
}

fn pair(cas: &mut Cas, a: &Spatial, b: &Spatial) -> ExprId {
    let x = cas.dot(&a.0, &b.0);
    let y = cas.dot(&a.1, &b.1);
    cas.add(x, y)
}

/// What the composite sums need of a chain: each coordinate's link and
/// twist, and the bodies of each link.
pub struct ChainKinematics<'a> {
    sys: &'a System,
    link_of: Vec<usize>,
    twists: Vec<Spatial>,
    bodies_of: Vec<Vec<usize>>,
    /// Velocities of the bodies' centres of mass, world frame.
    velocities: &'a [ExprId],
}

fn triple(v: &[ExprId], i: usize) -> [ExprId; 3] {
    [v[3 * i], v[3 * i + 1], v[3 * i + 2]]
}

impl<'a> ChainKinematics<'a> {
    /// `velocities` and `link_velocities` are the time derivatives of the
    /// body positions and of the link end points.
    pub fn new(
        cas: &mut Cas,
        sys: &'a System,
        chain: &Chain,
        velocities: &'a [ExprId],
        link_velocities: &[ExprId],
    ) -> Self {
        let n = sys.coords.len();
        let nl = chain.links.len();
        let mut link_of = vec![usize::MAX; n];
        for (l, link) in chain.links.iter().enumerate() {
            for &c in &link.coords {
                link_of[c] = l;
            }
        }
        assert!(
            link_of.windows(2).all(|w| w[0] <= w[1]) && link_of.iter().all(|&l| l < nl),
            "chain links must own the coordinates in order"
        );
        // Twists of the coordinates: the rigid motion past their link.
        let twists = (0..n)
            .map(|j| {
                let link = &chain.links[link_of[j]];
                let ve = triple(link_velocities, link_of[j]);
                let w = link.end_omega.map(|e| cas.diff(e, sys.coords.qd[j]));
                let v = ve.map(|e| cas.diff(e, sys.coords.qd[j]));
                let wr = cas.cross(&w, &link.end);
                let v0: [ExprId; 3] = std::array::from_fn(|k| cas.sub(v[k], wr[k]));
                (w.map(|e| cas.bind(e)), v0.map(|e| cas.bind(e)))
            })
            .collect();
        let bodies_of = (0..nl)
            .map(|l| {
                (0..sys.bodies.len())
                    .filter(|&b| chain.body_link[b] == l)
                    .collect()
            })
            .collect();
        Self {
            sys,
            link_of,
            twists,
            bodies_of,
            velocities,
        }
    }

    fn links(&self) -> usize {
        self.bodies_of.len()
    }

    /// Own column of T: body b under a coordinate of its own link.
    fn own_column(&self, cas: &mut Cas, b: usize, j: usize) -> Spatial {
        let qd = self.sys.coords.qd[j];
        let v = triple(self.velocities, b).map(|e| cas.diff(e, qd));
        let w = self.sys.bodies[b].omega.map(|e| cas.diff(e, qd));
        (w, v)
    }

    /// The upper triangle of M, row by row.
    pub fn mass(&self, cas: &mut Cas) -> Vec<ExprId> {
        let sys = self.sys;
        let n = sys.coords.len();
        let nl = self.links();
        // Suffix sums of spatial inertia: past[l] is everything beyond link l.
        let zero = cas.zero();
        let empty = SpatialInertia {
            m: zero,
            h: [zero; 3],
            j: [zero; 6],
        };
        let mut past = vec![empty; nl];
        for l in (0..nl.saturating_sub(1)).rev() {
            let mut parts = vec![past[l + 1]];
            for &b in &self.bodies_of[l + 1] {
                let body = &sys.bodies[b];
                parts.push(SpatialInertia::of_body(
                    cas,
                    body.mass,
                    &body.position,
                    &body.inertia,
                ));
            }
            past[l] = SpatialInertia::sum(cas, &parts);
        }

        // The momentum of unit qd_j: composite past its link plus its link's
        // own bodies.
        let momenta: Vec<Spatial> = (0..n)
            .map(|j| {
                let l = self.link_of[j];
                let (mut ang, mut lin) = past[l].momentum(cas, &self.twists[j]);
                for &b in &self.bodies_of[l] {
                    let body = &sys.bodies[b];
                    let (w, v) = self.own_column(cas, b, j);
                    let mv = v.map(|e| cas.mul(body.mass, e));
                    let rmv = cas.cross(&body.position, &mv);
                    let iw = body.inertia.apply(cas, &w);
                    for k in 0..3 {
                        ang[k] = cas.add_all(&[ang[k], iw[k], rmv[k]]);
                        lin[k] = cas.add(lin[k], mv[k]);
                    }
                }
                (ang.map(|e| cas.bind(e)), lin.map(|e| cas.bind(e)))
            })
            .collect();

        let mut mass = Vec::with_capacity(n * (n + 1) / 2);
        for i in 0..n {
            for (j, momentum) in momenta.iter().enumerate().skip(i) {
                let entry = if self.link_of[i] < self.link_of[j] {
                    pair(cas, &self.twists[i], momentum)
                } else {
                    let l = self.link_of[i];
                    let past_part = past[l].momentum(cas, &self.twists[j]);
                    let mut terms = vec![pair(cas, &self.twists[i], &past_part)];
                    for &b in &self.bodies_of[l] {
                        let body = &sys.bodies[b];
                        let (wi, vi) = self.own_column(cas, b, i);
                        let (wj, vj) = self.own_column(cas, b, j);
                        let vv = cas.dot(&vi, &vj);
                        terms.push(cas.mul(body.mass, vv));
                        terms.push(body.inertia.quadratic(cas, &wi, &wj));
                    }
                    cas.add_all(&terms)
                };
                mass.push(entry);
            }
        }
        mass
    }

    /// Generalised forces T^T f of wrenches on the bodies, and of forces at
    /// points: sum_b T_b^T (F_b, tau_b) + sum_p J_p^T F_p. A coordinate sees
    /// the summed wrench past its link through its twist, and the items of
    /// its own link through their own columns: O(n) for the chain.
    ///
    /// `body_forces[b]` is (F, tau) of body b (world frame); `points` are
    /// (link, position, velocity, force).
    pub fn generalized_forces(
        &self,
        cas: &mut Cas,
        body_forces: &[([ExprId; 3], [ExprId; 3])],
        points: &[PointItem],
        moments: &[MomentItem],
    ) -> Vec<ExprId> {
        let sys = self.sys;
        let n = sys.coords.len();
        let nl = self.links();
        // Wrenches about the origin per link: (tau + r x F, F).
        let mut link_wrench: Vec<Vec<Spatial>> = vec![Vec::new(); nl];
        for (l, bodies) in self.bodies_of.iter().enumerate() {
            for &b in bodies {
                let (f, tau) = body_forces[b];
                let rf = cas.cross(&sys.bodies[b].position, &f);
                let ang = std::array::from_fn(|k| cas.add(tau[k], rf[k]));
                link_wrench[l].push((ang, f));
            }
        }
        for p in points {
            let rf = cas.cross(&p.position, &p.force);
            link_wrench[p.link].push((rf, p.force));
        }
        let zero = cas.zero();
        for m in moments {
            link_wrench[m.link].push((m.moment, [zero; 3]));
        }
        let mut past: Vec<Spatial> = vec![([zero; 3], [zero; 3]); nl];
        for l in (0..nl.saturating_sub(1)).rev() {
            let mut parts = vec![past[l + 1]];
            parts.extend(link_wrench[l + 1].iter().copied());
            let sum = |cas: &mut Cas, pick: &dyn Fn(&Spatial) -> ExprId| {
                let terms: Vec<ExprId> = parts.iter().map(pick).collect();
                let s = cas.add_all(&terms);
                cas.bind(s)
            };
            let ang = [0, 1, 2].map(|k| sum(cas, &|w: &Spatial| w.0[k]));
            let lin = [0, 1, 2].map(|k| sum(cas, &|w: &Spatial| w.1[k]));
            past[l] = (ang, lin);
        }
        (0..n)
            .map(|j| {
                let l = self.link_of[j];
                let qd = sys.coords.qd[j];
                let mut terms = vec![pair(cas, &self.twists[j], &past[l])];
                for &b in &self.bodies_of[l] {
                    let (f, tau) = body_forces[b];
                    let (w, v) = self.own_column(cas, b, j);
                    terms.push(cas.dot(&v, &f));
                    terms.push(cas.dot(&w, &tau));
                }
                for p in points.iter().filter(|p| p.link == l) {
                    let v = p.velocity.map(|e| cas.diff(e, qd));
                    terms.push(cas.dot(&v, &p.force));
                }
                // A moment at the end of link l turns with the end frame,
                // whose angular velocity column is the twist's; one inside
                // it with its section, by that section's column.
                for m in moments.iter().filter(|m| m.link == l) {
                    let column = match m.omega {
                        Some(w) => w.map(|e| cas.diff(e, qd)),
                        None => self.twists[j].0,
                    };
                    terms.push(cas.dot(&column, &m.moment));
                }
                cas.add_all(&terms)
            })
            .collect()
    }
}

/// A moment on the end frame of a link.
pub struct MomentItem {
    pub link: usize,
    pub moment: [ExprId; 3],
    /// The angular velocity of the section it acts at, inside the link;
    /// None at the link's end frame.
    pub omega: Option<[ExprId; 3]>,
}

/// A force applied at a point of a chain.
pub struct PointItem {
    pub link: usize,
    pub position: [ExprId; 3],
    pub velocity: [ExprId; 3],
    pub force: [ExprId; 3],
}

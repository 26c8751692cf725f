//! Accelerations of a chain whose links own their coordinates by the
//! articulated-body recursion (Featherstone's ABA): qdd = -M^-1 h in
//! O(links), without forming M or factoring it.
//!
//! The composite sums ([`super::mass_bias_owned`]) build M in O(links^2)
//! and its L D L^T solve costs O(dof^3): at 20 links of three coordinates
//! the solve is two thirds of a right-hand side, and doubling the
//! elements triples the cost of a step. Here a sweep from the tip carries
//! the articulated inertia and bias wrench of everything past a link's end
//! frame, each link eliminates its own coordinates by a solve of their
//! count, and a sweep from the base gives the accelerations.
//!
//! Everything is in the world frame about its origin, as the forward
//! sweep ([`super::forward`]) leaves it: twists (w, v at the origin),
//! wrenches (moment about the origin, force), so a twist carried rigidly
//! is the same six numbers everywhere and pair(twist, wrench) is their dot
//! product. A link's body moves as V_b = V_0 + S_b xd and its end frame as
//! V_e = V_0 + S_e xd (V_0 its base frame's, S the spatial columns of its
//! coordinates); with accelerations split into the part at qdd = 0 (the
//! forward sweep's, whose wrenches `Link::force`, `torque` and the tip's
//! are) and the rest, a (the base frame's rest), the link's equations
//!
//!   S_b^T (I_b (a + S_b x) + F_b) + S_e^T (IA (a + S_e x) + pA) + Q = 0
//!
//! (IA, pA: the articulated inertia and bias wrench past the end frame,
//! Q the link's elastic and dissipative forces and the loads along the
//! arm's generalised forces on its coordinates) give x = -D^-1 (u + U^T
//! a) with D = S_b^T I_b S_b + S_e^T IA S_e, U = I_b S_b + IA S_e, u =
//! S_b^T F_b + S_e^T pA + Q, and the wrench the link passes to its base
//! frame, (I_b + IA - U D^-1 U^T) a + F_b + pA - U D^-1 u: the next IA
//! and pA. The base does not accelerate beyond its prescribed motion, so
//! a = 0 there.

// Small dense matrices (6 x 6, a link's coordinates): index loops read as
// the formulas.
#![allow(clippy::needless_range_loop)]

use super::{Cells, Inertia, LinkLayout, MAX_LINK_DOF, SCRATCH, Twist, add, cross, forward, sub};

type M6 = [[f64; 6]; 6];
type V6 = [f64; 6];

impl Inertia {
    /// The 6 x 6 matrix of [`Inertia::momentum`]: (J w + h x v, w x h + m v).
    #[inline(always)]
    fn matrix(&self) -> M6 {
        let j = &self.j;
        let h = self.h;
        let m = self.m;
        [
            [j[0], j[3], j[4], 0.0, -h[2], h[1]],
            [j[3], j[1], j[5], h[2], 0.0, -h[0]],
            [j[4], j[5], j[2], -h[1], h[0], 0.0],
            [0.0, h[2], -h[1], m, 0.0, 0.0],
            [-h[2], 0.0, h[0], 0.0, m, 0.0],
            [h[1], -h[0], 0.0, 0.0, 0.0, m],
        ]
    }
}

#[inline(always)]
fn six((w, v): Twist) -> V6 {
    [w[0], w[1], w[2], v[0], v[1], v[2]]
}

#[inline(always)]
fn dot6(a: &V6, b: &V6) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

#[inline(always)]
fn mul6(m: &M6, v: &V6) -> V6 {
    std::array::from_fn(|i| dot6(&m[i], v))
}

/// Factor the n x n symmetric positive definite `d` (n <= MAX_LINK_DOF,
/// its lower triangle) in place by L D L^T: `d` becomes its factors (L
/// below the diagonal, D on it); false unless positive definite.
#[inline(always)]
fn factor_small(d: &mut [[f64; MAX_LINK_DOF]; MAX_LINK_DOF], n: usize) -> bool {
    for j in 0..n {
        let mut p = d[j][j];
        for k in 0..j {
            p -= d[j][k] * d[j][k] * d[k][k];
        }
        if p.is_nan() || p <= 0.0 {
            return false;
        }
        d[j][j] = p;
        for i in j + 1..n {
            let mut s = d[i][j];
            for k in 0..j {
                s -= d[i][k] * d[j][k] * d[k][k];
            }
            d[i][j] = s / p;
        }
    }
    true
}

/// x = D^-1 b by the factors of [`factor_small`].
#[inline(always)]
fn solve_small(
    d: &[[f64; MAX_LINK_DOF]; MAX_LINK_DOF],
    n: usize,
    b: [f64; MAX_LINK_DOF],
) -> [f64; MAX_LINK_DOF] {
    let mut x = b;
    for i in 0..n {
        for k in 0..i {
            x[i] -= d[i][k] * x[k];
        }
    }
    for i in 0..n {
        x[i] /= d[i][i];
    }
    for i in (0..n).rev() {
        for k in i + 1..n {
            x[i] -= d[k][i] * x[k];
        }
    }
    x
}

/// What the sweep from the tip keeps of a link for the sweep from the
/// base: its end frame's columns, U, the factors of D and u.
#[derive(Clone, Copy, Default)]
pub(super) struct Eliminated {
    nc: usize,
    s_e: [V6; MAX_LINK_DOF],
    u_cols: [V6; MAX_LINK_DOF],
    d: [[f64; MAX_LINK_DOF]; MAX_LINK_DOF],
    u: [f64; MAX_LINK_DOF],
}

/// qdd = -M^-1 h of a chain whose links own their coordinates
/// ([`all_owned`]) into `qdd`, by the articulated-body recursion; false
/// unless every link's D is positive definite (M is then too).
/// `BODIES`: [`LinkLayout::general_bodies`]. Inlined into its caller,
/// which builds it for FMA.
#[inline(always)]
pub fn accelerations_owned<C: Cells, const BODIES: bool>(
    layout: &LinkLayout,
    cells: &mut C,
    q: &[f64],
    qd: &[f64],
    p: &[f64],
    qdd: &mut [f64],
) -> bool {
    debug_assert!(layout.direct_accelerations());
    let mut scratch = SCRATCH.take();
    let ok = {
        let s = &mut scratch;
        let nl = layout.links.len();
        s.x.resize(nl, [0.0; MAX_LINK_DOF]);
        s.xd.resize(nl, [0.0; MAX_LINK_DOF]);
        let mut at = 0;
        for (k, spec) in layout.links.iter().enumerate() {
            let nc = spec.map.len();
            s.x[k][..nc].copy_from_slice(&q[at..at + nc]);
            s.xd[k][..nc].copy_from_slice(&qd[at..at + nc]);
            at += nc;
        }
        let tip = forward::<C, BODIES>(layout, cells, p, s);
        // Loads along the arm and on its coordinates: generalised forces
        // added to h, each to its own coordinate's u (`s.forces` is free:
        // no rom forces here).
        let n = layout.dof;
        s.forces.clear();
        s.forces.resize(n, 0.0);
        if layout.loaded() {
            super::subtract_loads(layout, cells, (q, qd, p), &mut s.forces);
        }
        let mut ia = tip.past.matrix();
        let mut pa = six(tip.wrench);
        // Each link's elimination, kept for the sweep from the base.
        let mut kept = std::mem::take(&mut s.eliminated);
        kept.resize(nl, Eliminated::default());
        let mut ok = true;
        for k in (0..nl).rev() {
            let nc = layout.links[k].map.len();
            let l = &s.links[k];
            let at = s.start[k];
            let mut body = Inertia::default();
            body.add_body::<BODIES>(l.m, l.centroid, &l.rotary);
            let ib = body.matrix();
            let fb = six((add(l.torque, cross(l.centroid, l.force)), l.force));
            let e = &mut kept[k];
            e.nc = nc;
            let mut s_b = [[0.0; 6]; MAX_LINK_DOF];
            let mut ib_sb = [[0.0; 6]; MAX_LINK_DOF];
            let mut ia_se = [[0.0; 6]; MAX_LINK_DOF];
            for f in 0..nc {
                // The body's column as a twist about the origin.
                let (ow, ov) = s.own[at + f];
                let twist = (ow, sub(ov, cross(ow, l.centroid)));
                s_b[f] = six(twist);
                ib_sb[f] = six(body.momentum(twist));
                e.s_e[f] = six(s.twist[at + f]);
                ia_se[f] = mul6(&ia, &e.s_e[f]);
                e.u_cols[f] = std::array::from_fn(|i| ib_sb[f][i] + ia_se[f][i]);
                e.u[f] = dot6(&s_b[f], &fb)
                    + dot6(&e.s_e[f], &pa)
                    + s.local_force[at + f]
                    + s.forces[at + f];
            }
            for f in 0..nc {
                for f2 in 0..=f {
                    e.d[f][f2] = dot6(&s_b[f], &ib_sb[f2]) + dot6(&e.s_e[f], &ia_se[f2]);
                }
            }
            if !factor_small(&mut e.d, nc) {
                ok = false;
                break;
            }
            // IA <- I_b + IA - U D^-1 U^T, pA <- F_b + pA - U D^-1 u.
            let mut w = [[0.0; 6]; MAX_LINK_DOF];
            for i in 0..6 {
                let row = solve_small(&e.d, nc, std::array::from_fn(|f| e.u_cols[f][i]));
                for f in 0..nc {
                    w[f][i] = row[f];
                }
            }
            for i in 0..6 {
                // Symmetric: the upper half, mirrored.
                for j in i..6 {
                    let mut v = ib[i][j] + ia[i][j];
                    for f in 0..nc {
                        v -= e.u_cols[f][i] * w[f][j];
                    }
                    ia[i][j] = v;
                    ia[j][i] = v;
                }
                let mut v = fb[i] + pa[i];
                for f in 0..nc {
                    v -= w[f][i] * e.u[f];
                }
                pa[i] = v;
            }
        }
        if ok {
            // From the base: x = -D^-1 (u + U^T a), a += S_e x.
            let mut a: V6 = [0.0; 6];
            let mut at = 0;
            for e in &kept {
                let b: [f64; MAX_LINK_DOF] = std::array::from_fn(|f| {
                    if f < e.nc {
                        -(e.u[f] + dot6(&e.u_cols[f], &a))
                    } else {
                        0.0
                    }
                });
                let x = solve_small(&e.d, e.nc, b);
                for f in 0..e.nc {
                    qdd[at + f] = x[f];
                    for i in 0..6 {
                        a[i] += e.s_e[f][i] * x[f];
                    }
                }
                at += e.nc;
            }
        }
        s.eliminated = kept;
        ok
    };
    SCRATCH.set(scratch);
    ok
}

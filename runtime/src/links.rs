//! Mass + bias of a serial chain of constant-strain links (3D pcc and vc
//! arms) by a recursion over the links, each link's local kinematics from
//! one generated *cell*.
//!
//! A fully unrolled kernel of a 20-DOF 3D arm is over 100 KB of machine
//! code, past the processor's instruction caches: it runs at half the
//! instructions per nanosecond of a small one (BENCHMARKS.md, session 7).
//! Here the CAS derives one link on its own, in its base frame at rest (the
//! cell: relative rotation and end point, the body's centroid and axis,
//! their rates and convective accelerations, the columns of the link's
//! coordinates, the link's elastic and dissipative forces), identical links
//! share one cell, and this loop composes the world frame link by link and
//! sums M and h by composite bodies from the tip (Featherstone's CRBA and
//! RNEA, in the world frame as `eomgen/src/tmt/chain.rs` does symbolically).
//! The flat `MassBias` tape stays the interpreter's form: the two are
//! independent computations of the same M and h (tests/backends.rs).

use std::cell::RefCell;

use serde::{Deserialize, Serialize};

/// Parameters a cell reads, in this order, per link: element[k].length,
/// .mass, .inertia, .axial_inertia, joint[k].stiffness, .damping, .rest,
/// twist[k].stiffness, .damping, stretch[k].stiffness, .damping.
pub const CELL_PARAMS: usize = 11;

/// Where a cell's outputs sit, for a link of `n` coordinates.
pub mod cell {
    /// Relative rotation, rows.
    pub const ROTATION: usize = 0;
    /// End point in the base frame, its rate and convective acceleration.
    pub const END: usize = 9;
    pub const END_RATE: usize = 12;
    pub const END_ACCEL: usize = 15;
    /// Relative angular velocity of the end frame, its convective rate.
    pub const OMEGA: usize = 18;
    pub const OMEGA_RATE: usize = 21;
    /// The body: centroid, its rate and convective acceleration.
    pub const CENTROID: usize = 24;
    pub const CENTROID_RATE: usize = 27;
    pub const CENTROID_ACCEL: usize = 30;
    /// The body's angular velocity and its convective rate.
    pub const BODY_OMEGA: usize = 33;
    pub const BODY_OMEGA_RATE: usize = 36;
    /// The body's axis (its inertia is axisymmetric about it).
    pub const AXIS: usize = 39;
    pub const MASS: usize = 42;
    pub const LATERAL: usize = 43;
    pub const AXIAL: usize = 44;
    /// Then per coordinate c: the end frame's angular velocity column and
    /// end point velocity column (6), the body's angular and centroid
    /// velocity columns (6), and last the n generalised elastic and
    /// dissipative forces.
    pub const COLUMNS: usize = 45;

    pub fn len(n: usize) -> usize {
        COLUMNS + 13 * n
    }
}

/// A coordinate of a cell: a fixed linear combination of the arm's
/// coordinates, times a parameter where `scale` names one. A pcc link's
/// coordinates are the arm's own (one term, weight 1); a rom slice's strain
/// is its segment's coefficients integrated over the slice.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LocalCoordinate {
    /// (arm coordinate, weight)
    pub terms: Vec<(usize, f64)>,
    pub scale: Option<usize>,
}

/// One link: its cell, its coordinates and its parameters.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LinkSpec {
    pub cell: usize,
    /// The cell's coordinates, in its order.
    pub map: Vec<LocalCoordinate>,
    /// Indices into the parameter vector, [`CELL_PARAMS`] of them.
    pub params: Vec<usize>,
}

impl LinkSpec {
    /// The first of the arm's coordinates when the cell's coordinates are
    /// the arm's own, in order (pcc, vc), rather than shared combinations.
    pub fn owned(&self) -> Option<usize> {
        let first = self.map.first()?.terms.first()?.0;
        let own = self.map.iter().enumerate().all(|(f, c)| {
            c.scale.is_none() && c.terms.len() == 1 && c.terms[0] == (first + f, 1.0)
        });
        own.then_some(first)
    }
}

/// A chain of links and where its global parameters are.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LinkLayout {
    pub links: Vec<LinkSpec>,
    /// The arm's coordinates.
    pub dof: usize,
    /// Generalised forces not local to a link (a rom segment's strain
    /// energy and damping, integrated over the whole segment) come from a
    /// kernel of the arm's coordinates: `mass_bias`'s `forces`.
    pub forces: bool,
    pub gravity: [usize; 3],
    pub base_position: [usize; 3],
    /// Rows of the base rotation.
    pub base_rotation: [usize; 9],
    pub tip_force: Option<[usize; 3]>,
    pub tip_moment: Option<[usize; 3]>,
    /// The tip force and moment turn with the tip frame.
    pub tip_frame: bool,
    /// A tip body: its mass, and with a length (a cylinder along the tip
    /// axis, the tip point at its far end) its lateral and axial inertia.
    pub tip_mass: Option<usize>,
    pub tip_length: Option<usize>,
    pub tip_inertia: Option<[usize; 2]>,
}

/// The link recursion of a model: its layout, the cells, and the kernel of
/// the non-local forces when `layout.forces`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LinkKernels {
    pub layout: LinkLayout,
    pub cells: Vec<crate::Tape>,
    pub forces: Option<crate::Tape>,
}

type V3 = [f64; 3];
type M3 = [[f64; 3]; 3];

#[inline(always)]
fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
#[inline(always)]
fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
#[inline(always)]
fn scale(s: f64, a: V3) -> V3 {
    [s * a[0], s * a[1], s * a[2]]
}
#[inline(always)]
fn dot(a: V3, b: V3) -> f64 {
    a[0].mul_add(b[0], a[1].mul_add(b[1], a[2] * b[2]))
}
#[inline(always)]
fn cross(a: V3, b: V3) -> V3 {
    [
        a[1].mul_add(b[2], -(a[2] * b[1])),
        a[2].mul_add(b[0], -(a[0] * b[2])),
        a[0].mul_add(b[1], -(a[1] * b[0])),
    ]
}
#[inline(always)]
fn mat_vec(r: &M3, v: V3) -> V3 {
    [dot(r[0], v), dot(r[1], v), dot(r[2], v)]
}
#[inline(always)]
fn mat_mat(a: &M3, b: &M3) -> M3 {
    std::array::from_fn(|i| std::array::from_fn(|j| dot(a[i], [b[0][j], b[1][j], b[2][j]])))
}
#[inline(always)]
fn v3(x: &[f64], at: usize) -> V3 {
    [x[at], x[at + 1], x[at + 2]]
}
#[inline(always)]
fn pair(a: (V3, V3), b: (V3, V3)) -> f64 {
    dot(a.0, b.0) + dot(a.1, b.1)
}
/// Axisymmetric inertia applied to a vector.
#[inline(always)]
fn apply_body(lateral: f64, axial: f64, axis: V3, w: V3) -> V3 {
    add(
        scale(lateral, w),
        scale((axial - lateral) * dot(axis, w), axis),
    )
}

/// A spatial inertia about the world origin: mass, first moment m r and
/// rotational inertia J, symmetric, stored xx, yy, zz, xy, xz, yz.
#[derive(Clone, Copy, Default)]
struct Inertia {
    m: f64,
    h: V3,
    j: [f64; 6],
}

impl Inertia {
    /// Adds a body of mass m at r, axisymmetric about `axis`:
    /// J += lateral 1 + (axial - lateral) a a^T + m (|r|^2 1 - r r^T).
    #[inline(always)]
    fn add_body(&mut self, m: f64, r: V3, lateral: f64, axial: f64, axis: V3) {
        let r2 = dot(r, r);
        let d = axial - lateral;
        let diag = lateral + m * r2;
        self.m += m;
        self.h = add(self.h, scale(m, r));
        for (k, (a, b)) in [(0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)]
            .into_iter()
            .enumerate()
        {
            let base = if k < 3 { diag } else { 0.0 };
            self.j[k] += base + d * axis[a] * axis[b] - m * r[a] * r[b];
        }
    }

    /// The momentum of the twist (w, v): (J w + h x v, m v + w x h).
    #[inline(always)]
    fn momentum(&self, (w, v): (V3, V3)) -> (V3, V3) {
        let j = &self.j;
        let jw = [
            j[0] * w[0] + j[3] * w[1] + j[4] * w[2],
            j[3] * w[0] + j[1] * w[1] + j[5] * w[2],
            j[4] * w[0] + j[5] * w[1] + j[2] * w[2],
        ];
        (
            add(jw, cross(self.h, v)),
            add(scale(self.m, v), cross(w, self.h)),
        )
    }
}

/// What the sweep from the tip needs of a link, world frame.
#[derive(Clone, Copy, Default)]
struct Link {
    centroid: V3,
    axis: V3,
    m: f64,
    lateral: f64,
    axial: f64,
    force: V3,
    torque: V3,
}

/// Most coordinates a cell has (bend pair, twist, stretch).
const MAX_LINK_DOF: usize = 4;

type Twist = (V3, V3);

#[inline(always)]
fn flat((w, v): Twist) -> [f64; 6] {
    [w[0], w[1], w[2], v[0], v[1], v[2]]
}

/// Rows over the arm's coordinates, four to a chunk, zero padded:
/// fixed-width loops the compiler turns into vector instructions.
type Lanes = [f64; 4];
const LANES: usize = 4;

/// y += a x
#[inline(always)]
fn axpy(y: &mut [Lanes], a: f64, x: &[Lanes]) {
    for (y, x) in y.iter_mut().zip(x) {
        for l in 0..LANES {
            y[l] = a.mul_add(x[l], y[l]);
        }
    }
}

#[derive(Default)]
struct Scratch {
    links: Vec<Link>,
    /// Per cell coordinate of every link (link k's from `start[k]`): the
    /// twist its rate gives everything past the link (spatial, about the
    /// world origin), the velocity it gives the link's own body (angular,
    /// centroid), its elastic and dissipative force.
    start: Vec<usize>,
    owned: Vec<Option<usize>>,
    twist: Vec<Twist>,
    own: Vec<Twist>,
    local_force: Vec<f64>,
    /// Per arm coordinate b: the momentum its rate gives the links past
    /// the one the sweep from the tip is at (R_e below); after the sweep,
    /// the momentum it gives the whole arm.
    reach: Vec<Lanes>,
    /// The same after the sweep, by coordinate.
    momentum: Vec<Twist>,
    /// X below, `dof` by `dof`, row-major, for links of shared
    /// coordinates.
    cross: Vec<Lanes>,
    row: Vec<Lanes>,
    forces: Vec<f64>,
    cell_out: Vec<f64>,
    cell_params: Vec<f64>,
}

thread_local! {
    static SCRATCH: RefCell<Scratch> = RefCell::new(Scratch::default());
}

/// The value of cell coordinate `c`: its combination of `x` (coordinates
/// or rates).
#[inline(always)]
fn local(c: &LocalCoordinate, x: &[f64], p: &[f64]) -> f64 {
    let s = c.terms.iter().fold(0.0, |s, &(a, w)| w.mul_add(x[a], s));
    c.scale.map_or(s, |i| s * p[i])
}

/// The weight of a term of cell coordinate `c`.
#[inline(always)]
fn weight(c: &LocalCoordinate, w: f64, p: &[f64]) -> f64 {
    c.scale.map_or(w, |i| w * p[i])
}

type SharedArgs<'a> = (
    &'a LinkSpec,
    &'a [Twist],
    &'a [[f64; MAX_LINK_DOF]; MAX_LINK_DOF],
    &'a [f64; MAX_LINK_DOF],
    &'a [Twist; MAX_LINK_DOF],
    &'a [f64],
);

/// A link of shared coordinates onto the arm's: into X the coupling
/// S_f . R_e to the links past and half the own block (M = X + X^T), into
/// h its bias, into R its momenta. `W` chunks a row.
#[inline(always)]
fn shared_sums<const W: usize>(
    (spec, twists, block, g, momentum, p): SharedArgs,
    reach: &mut [Lanes],
    cross: &mut [Lanes],
    bias: &mut [f64],
) {
    for (f, cf) in spec.map.iter().enumerate() {
        let mut row = [[0.0; LANES]; W];
        for (k, &t) in flat(twists[f]).iter().enumerate() {
            let r: &[Lanes; W] = reach[k * W..(k + 1) * W].try_into().expect("W chunks");
            for i in 0..W {
                for l in 0..LANES {
                    row[i][l] = t.mul_add(r[i][l], row[i][l]);
                }
            }
        }
        for (f2, cf2) in spec.map.iter().enumerate() {
            let half = 0.5 * block[f][f2];
            for &(b, wb) in &cf2.terms {
                row[b / LANES][b % LANES] += half * weight(cf2, wb, p);
            }
        }
        for &(a, wa) in &cf.terms {
            let wa = weight(cf, wa, p);
            bias[a] = wa.mul_add(g[f], bias[a]);
            let x: &mut [Lanes; W] = (&mut cross[a * W..(a + 1) * W])
                .try_into()
                .expect("W chunks");
            for i in 0..W {
                for l in 0..LANES {
                    x[i][l] = wa.mul_add(row[i][l], x[i][l]);
                }
            }
        }
    }
    add_momenta(W, spec, momentum, p, reach);
}

/// `shared_sums` for rows of any length.
fn shared_sums_any(
    w: usize,
    (spec, twists, block, g, momentum, p): SharedArgs,
    reach: &mut [Lanes],
    cross: &mut [Lanes],
    bias: &mut [f64],
) {
    let mut row = vec![[0.0; LANES]; w];
    for (f, cf) in spec.map.iter().enumerate() {
        row.fill([0.0; LANES]);
        for (k, &t) in flat(twists[f]).iter().enumerate() {
            axpy(&mut row, t, &reach[k * w..(k + 1) * w]);
        }
        for (f2, cf2) in spec.map.iter().enumerate() {
            let half = 0.5 * block[f][f2];
            for &(b, wb) in &cf2.terms {
                row[b / LANES][b % LANES] += half * weight(cf2, wb, p);
            }
        }
        for &(a, wa) in &cf.terms {
            let wa = weight(cf, wa, p);
            bias[a] = wa.mul_add(g[f], bias[a]);
            axpy(&mut cross[a * w..(a + 1) * w], wa, &row);
        }
    }
    add_momenta(w, spec, momentum, p, reach);
}

/// R += the link's momenta through its weights.
#[inline(always)]
fn add_momenta(
    w: usize,
    spec: &LinkSpec,
    momentum: &[Twist; MAX_LINK_DOF],
    p: &[f64],
    reach: &mut [Lanes],
) {
    for (f, cf) in spec.map.iter().enumerate() {
        let m = flat(momentum[f]);
        for &(b, wb) in &cf.terms {
            let wb = weight(cf, wb, p);
            for (k, &mk) in m.iter().enumerate() {
                let r = &mut reach[k * w + b / LANES][b % LANES];
                *r = wb.mul_add(mk, *r);
            }
        }
    }
}

/// M (upper triangle, row by row) and h of the chain into `out` (the
/// `MassBias` layout). `cell(c, x, xd, p_k, out)` evaluates cell `c` at a
/// link's cell coordinates and rates and its parameters ([`CELL_PARAMS`]);
/// `forces(out)` writes the non-local generalised forces, added to h, when
/// `layout.forces`.
///
/// With J_e the map from the arm's rates to link e's cell rates (rows of
/// `LinkSpec::map`), S_e the twists of e's cell rates and F_e the momenta
/// they give the bodies from e on: M = X + X^T with X = sum_e J_e^T (S_e^T
/// R_e + D_e J_e / 2), D_e e's own block and R_e = sum_{e' > e} F_e' J_e'
/// the momenta the arm's rates give the links past e. For links that own
/// their coordinates (pcc) J_e selects them and this is the composite-body
/// algorithm; for rom slices, which share their segment's coordinates, the
/// same sums with the slice weights.
/// Inlined into its caller, which the generated code builds for FMA.
#[inline(always)]
pub fn mass_bias<F, G>(
    layout: &LinkLayout,
    mut cell: F,
    mut forces: G,
    q: &[f64],
    qd: &[f64],
    p: &[f64],
    out: &mut [f64],
) where
    F: FnMut(usize, &[f64], &[f64], &[f64], &mut [f64]),
    G: FnMut(&mut [f64]),
{
    let n = layout.dof;
    let nl = layout.links.len();
    assert!(layout.links.iter().all(|l| l.map.len() <= MAX_LINK_DOF));
    assert_eq!(out.len(), n * (n + 1) / 2 + n, "MassBias output length");
    // Out of the thread-local for the call: code inside `LocalKey::with`'s
    // closure is not inlined into the caller, which is built for FMA.
    let mut scratch = SCRATCH.take();
    {
        let s = &mut scratch;
        s.links.resize(nl, Link::default());
        s.start.clear();
        s.owned.resize(nl, None);
        let mut total = 0;
        for spec in &layout.links {
            s.start.push(total);
            total += spec.map.len();
        }
        for v in [&mut s.twist, &mut s.own] {
            v.resize(total, ([0.0; 3], [0.0; 3]));
        }
        s.local_force.resize(total, 0.0);
        // By component (angular x, y, z, linear x, y, z), `dof` each, in
        // chunks of four, so that loops over the arm's coordinates
        // vectorise whatever its size.
        let w = n.div_ceil(LANES);
        s.reach.clear();
        s.reach.resize(6 * w, [0.0; LANES]);
        s.row.resize(w, [0.0; LANES]);
        s.momentum.resize(n, ([0.0; 3], [0.0; 3]));
        s.cross.clear();
        s.cell_out.resize(cell::len(MAX_LINK_DOF), 0.0);
        s.cell_params.resize(CELL_PARAMS, 0.0);

        let gravity = layout.gravity.map(|i| p[i]);
        let mut r: M3 =
            std::array::from_fn(|i| std::array::from_fn(|j| p[layout.base_rotation[3 * i + j]]));
        let mut pos = layout.base_position.map(|i| p[i]);
        let (mut omega, mut alpha, mut acc) = ([0.0; 3], [0.0; 3], [0.0; 3]);
        let (mut x, mut xd) = ([0.0; MAX_LINK_DOF], [0.0; MAX_LINK_DOF]);
        for (k, spec) in layout.links.iter().enumerate() {
            let nc = spec.map.len();
            let owned = spec.owned();
            s.owned[k] = owned;
            match owned {
                Some(a) => {
                    x[..nc].copy_from_slice(&q[a..a + nc]);
                    xd[..nc].copy_from_slice(&qd[a..a + nc]);
                }
                None => {
                    for (f, c) in spec.map.iter().enumerate() {
                        x[f] = local(c, q, p);
                        xd[f] = local(c, qd, p);
                    }
                }
            }
            for (v, &i) in s.cell_params.iter_mut().zip(&spec.params) {
                *v = p[i];
            }
            let c = &mut s.cell_out[..cell::len(nc)];
            cell(spec.cell, &x[..nc], &xd[..nc], &s.cell_params, c);
            let c = &*c;
            let rel: M3 = std::array::from_fn(|i| v3(c, cell::ROTATION + 3 * i));
            let turn = |at: usize| mat_vec(&r, v3(c, at));
            let (d, dd, ddd) = (turn(cell::END), turn(cell::END_RATE), turn(cell::END_ACCEL));
            let (cen, cend, cendd) = (
                turn(cell::CENTROID),
                turn(cell::CENTROID_RATE),
                turn(cell::CENTROID_ACCEL),
            );
            let (w_rel, w_rel_d) = (turn(cell::OMEGA), turn(cell::OMEGA_RATE));
            let (w_b, w_b_d) = (turn(cell::BODY_OMEGA), turn(cell::BODY_OMEGA_RATE));
            let axis = turn(cell::AXIS);
            let (m, lateral, axial) = (c[cell::MASS], c[cell::LATERAL], c[cell::AXIAL]);

            // The body: centroid, convective accelerations, inertial and
            // gravity forces.
            let body_a = add(
                add(add(acc, cross(alpha, cen)), cross(omega, cross(omega, cen))),
                add(scale(2.0, cross(omega, cend)), cendd),
            );
            let body_w = add(omega, w_b);
            let body_alpha = add(add(alpha, cross(omega, w_b)), w_b_d);
            let iw = apply_body(lateral, axial, axis, body_w);
            let end = add(pos, d);
            s.links[k] = Link {
                centroid: add(pos, cen),
                axis,
                m,
                lateral,
                axial,
                force: scale(m, sub(body_a, gravity)),
                torque: add(
                    apply_body(lateral, axial, axis, body_alpha),
                    cross(body_w, iw),
                ),
            };
            let force_at = cell::COLUMNS + 12 * nc;
            for f in 0..nc {
                let j = s.start[k] + f;
                let col = cell::COLUMNS + 12 * f;
                let s_w = turn(col);
                let v_end = turn(col + 3);
                s.twist[j] = (s_w, sub(v_end, cross(s_w, end)));
                s.own[j] = (turn(col + 6), turn(col + 9));
                s.local_force[j] = c[force_at + f];
            }

            // The next frame.
            acc = add(
                add(add(acc, cross(alpha, d)), cross(omega, cross(omega, d))),
                add(scale(2.0, cross(omega, dd)), ddd),
            );
            alpha = add(add(alpha, cross(omega, w_rel)), w_rel_d);
            omega = add(omega, w_rel);
            pos = end;
            r = mat_mat(&r, &rel);
        }

        // What hangs on the end frame moves rigidly with it: the tip body
        // and the tip loads start the composite sums.
        let mut past = Inertia::default();
        let mut wrench: (V3, V3) = ([0.0; 3], [0.0; 3]);
        let axis = [r[0][0], r[1][0], r[2][0]];
        let length = layout.tip_length.map_or(0.0, |i| p[i]);
        let point = add(pos, scale(length, axis));
        if let Some(m) = layout.tip_mass.map(|i| p[i]) {
            let offset = scale(0.5 * length, axis);
            let centre = add(pos, offset);
            let (lateral, axial) = layout.tip_inertia.map_or((0.0, 0.0), |[l, a]| (p[l], p[a]));
            let a_c = add(
                add(acc, cross(alpha, offset)),
                cross(omega, cross(omega, offset)),
            );
            let force = scale(m, sub(a_c, gravity));
            let iw = apply_body(lateral, axial, axis, omega);
            let torque = add(apply_body(lateral, axial, axis, alpha), cross(omega, iw));
            past.add_body(m, centre, lateral, axial, axis);
            wrench = (add(torque, cross(centre, force)), force);
        }
        // Applied loads enter as forces of the opposite sign.
        let load = |idx: Option<[usize; 3]>| -> V3 {
            idx.map_or([0.0; 3], |i| {
                let v = i.map(|i| -p[i]);
                if layout.tip_frame { mat_vec(&r, v) } else { v }
            })
        };
        let (tip_f, tip_m) = (load(layout.tip_force), load(layout.tip_moment));
        wrench = (
            add(wrench.0, add(cross(point, tip_f), tip_m)),
            add(wrench.1, tip_f),
        );

        let (mass, bias) = out.split_at_mut(n * (n + 1) / 2);
        mass.fill(0.0);
        bias.fill(0.0);
        let index = |i: usize, j: usize| i * n - i * (i + 1) / 2 + j;
        for (k, spec) in layout.links.iter().enumerate().rev() {
            let l = s.links[k];
            let nc = spec.map.len();
            let at = s.start[k];
            // Per cell coordinate: the momentum its twist gives the links
            // past this one and this link's body, the link's own block of
            // M, and the generalised bias.
            let mut momentum = [([0.0; 3], [0.0; 3]); MAX_LINK_DOF];
            let mut block = [[0.0; MAX_LINK_DOF]; MAX_LINK_DOF];
            let mut g = [0.0; MAX_LINK_DOF];
            for f in 0..nc {
                let (ow, ov) = s.own[at + f];
                let mv = scale(l.m, ov);
                let composite = past.momentum(s.twist[at + f]);
                momentum[f] = (
                    add(
                        add(composite.0, apply_body(l.lateral, l.axial, l.axis, ow)),
                        cross(l.centroid, mv),
                    ),
                    add(composite.1, mv),
                );
                g[f] = pair(s.twist[at + f], wrench)
                    + dot(ov, l.force)
                    + dot(ow, l.torque)
                    + s.local_force[at + f];
                #[allow(clippy::needless_range_loop)] // fills both halves
                for f2 in f..nc {
                    let (wj, vj) = s.own[at + f2];
                    block[f][f2] = pair(s.twist[at + f2], composite)
                        + l.m * dot(ov, vj)
                        + dot(ow, apply_body(l.lateral, l.axial, l.axis, wj));
                    block[f2][f] = block[f][f2];
                }
            }
            match s.owned[k] {
                // The link owns coordinates a.. : its block of M and its h
                // directly; its rows past the block after the sweep.
                Some(a) => {
                    for f in 0..nc {
                        bias[a + f] = g[f];
                        for f2 in f..nc {
                            mass[index(a + f, a + f2)] = block[f][f2];
                        }
                        for (k, &m) in flat(momentum[f]).iter().enumerate() {
                            s.reach[k * w + (a + f) / LANES][(a + f) % LANES] = m;
                        }
                    }
                }
                // Shared coordinates: through the link's weights, into X
                // the coupling S_f . R_e to the links past and half the
                // own block (M = X + X^T), and into h.
                None => {
                    if s.cross.is_empty() {
                        s.cross.resize(n * w, [0.0; LANES]);
                    }
                    let twists = &s.twist[at..at + nc];
                    let (reach, cross) = (&mut s.reach[..], &mut s.cross[..]);
                    let args = (spec, twists, &block, &g, &momentum, p);
                    // Monomorphised by the row's chunk count, so that the
                    // loops over the arm's coordinates have fixed trip
                    // counts (runtime lengths left them mostly scalar).
                    match w {
                        1 => shared_sums::<1>(args, reach, cross, bias),
                        2 => shared_sums::<2>(args, reach, cross, bias),
                        3 => shared_sums::<3>(args, reach, cross, bias),
                        4 => shared_sums::<4>(args, reach, cross, bias),
                        5 => shared_sums::<5>(args, reach, cross, bias),
                        6 => shared_sums::<6>(args, reach, cross, bias),
                        7 => shared_sums::<7>(args, reach, cross, bias),
                        8 => shared_sums::<8>(args, reach, cross, bias),
                        _ => shared_sums_any(w, args, reach, cross, bias),
                    }
                }
            }
            past.add_body(l.m, l.centroid, l.lateral, l.axial, l.axis);
            let torque = add(l.torque, cross(l.centroid, l.force));
            wrench = (add(wrench.0, torque), add(wrench.1, l.force));
        }
        // Rows of owned coordinates past their link: twist . momentum.
        for (j, m) in s.momentum.iter_mut().enumerate() {
            let c = |k: usize| s.reach[k * w + j / LANES][j % LANES];
            *m = ([c(0), c(1), c(2)], [c(3), c(4), c(5)]);
        }
        for (k, spec) in layout.links.iter().enumerate() {
            if let Some(a) = s.owned[k] {
                let next = a + spec.map.len();
                for f in 0..spec.map.len() {
                    let twist = s.twist[s.start[k] + f];
                    let row = &mut mass[index(a + f, next)..index(a + f, n)];
                    for (m, &r) in row.iter_mut().zip(&s.momentum[next..]) {
                        *m = pair(twist, r);
                    }
                }
            }
        }
        if !s.cross.is_empty() {
            for i in 0..n {
                for j in i..n {
                    mass[index(i, j)] += s.cross[i * w + j / LANES][j % LANES]
                        + s.cross[j * w + i / LANES][i % LANES];
                }
            }
        }
        if layout.forces {
            s.forces.resize(n, 0.0);
            forces(&mut s.forces);
            for (h, f) in bias.iter_mut().zip(&s.forces) {
                *h += f;
            }
        }
    }
    SCRATCH.set(scratch);
}

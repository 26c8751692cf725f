//! Mass + bias of a planar chain by composite bodies in the plane: the
//! sums of [`super::mass_bias_owned`] with a turn about z for a rotation,
//! twists of three numbers (w, vx, vy) and inertias of four.
//!
//! A planar cell is written in the 3D layout (`eomgen`'s `planar_cell`: a
//! rotation about z, isotropic bodies, one coordinate), so the 3D
//! recursion runs it too, at about four times this one's work. Here each
//! link's cell is evaluated where the forward sweep reaches it (inlined
//! into the generated recursion, its outputs stay in registers), and a
//! link of one coordinate keeps one twist, one momentum and one row of M.
//! Planar arms no compiled-in model has run here on linked cells; compiled
//! in, short chains keep their flat kernels, which are quicker (eomgen's
//! `PLANAR_RECURSION_MIN_LINKS`). Tests: this against the 3D recursion on
//! the same cells and the closed form of a pendulum chain (unit), and
//! linked planar arms against the interpreter's flat tapes (backends).

use std::cell::RefCell;

use super::{CELL_PARAMS, Cells, LinkLayout, Loads, cell, link_params};

type P2 = [f64; 2];
/// A twist about the world origin, or a wrench: (w, vx, vy), (moment,
/// fx, fy).
type T3 = [f64; 3];

/// z x v.
#[inline(always)]
fn perp(v: P2) -> P2 {
    [-v[1], v[0]]
}
/// (a x b) . z.
#[inline(always)]
fn cross(a: P2, b: P2) -> f64 {
    a[0].mul_add(b[1], -(a[1] * b[0]))
}
#[inline(always)]
fn add(a: P2, b: P2) -> P2 {
    [a[0] + b[0], a[1] + b[1]]
}
#[inline(always)]
fn sub(a: P2, b: P2) -> P2 {
    [a[0] - b[0], a[1] - b[1]]
}
#[inline(always)]
fn scale(s: f64, a: P2) -> P2 {
    [s * a[0], s * a[1]]
}
#[inline(always)]
fn dot(a: P2, b: P2) -> f64 {
    a[0].mul_add(b[0], a[1] * b[1])
}
#[inline(always)]
fn pair(a: T3, b: T3) -> f64 {
    a[0].mul_add(b[0], a[1].mul_add(b[1], a[2] * b[2]))
}
/// The acceleration of the point r (from a frame's origin) that moves
/// rigidly with the frame: the origin's `acc`, alpha z x r, -omega^2 r.
#[inline(always)]
fn carried(acc: P2, alpha: f64, omega: f64, r: P2) -> P2 {
    add(add(acc, scale(alpha, perp(r))), scale(-omega * omega, r))
}

/// A planar inertia about the world origin: mass, first moment m r,
/// polar moment.
#[derive(Clone, Copy, Default)]
struct Inertia {
    m: f64,
    h: P2,
    j: f64,
}

impl Inertia {
    #[inline(always)]
    fn add_body(&mut self, m: f64, r: P2, inertia: f64) {
        self.m += m;
        self.h = add(self.h, scale(m, r));
        self.j += inertia + m * dot(r, r);
    }

    /// The momentum of the twist (w, v): (J w + h x v, m v + w x h).
    #[inline(always)]
    fn momentum(&self, t: T3) -> T3 {
        let v = [t[1], t[2]];
        let lin = add(scale(self.m, v), scale(t[0], perp(self.h)));
        [self.j.mul_add(t[0], cross(self.h, v)), lin[0], lin[1]]
    }
}

/// What the sums from the tip need of a link, world frame: its body, the
/// inertial and gravity forces on it, and (a link of one coordinate) the
/// twist its rate gives everything past the link, the velocity it gives
/// the link's own body (w, centroid), its elastic and dissipative force.
#[derive(Clone, Copy, Default)]
struct Link {
    centroid: P2,
    m: f64,
    inertia: f64,
    force: P2,
    torque: f64,
    twist: T3,
    own: T3,
    local_force: f64,
}

/// Per coordinate: its twist and the momentum its rate gives the links
/// from its own on.
type Column = (T3, T3);

/// Whether the sums in the plane cover a layout: a planar chain (a base
/// angle) of links of at most one coordinate each, on a base no input
/// turns (the spatial sums take the turning frame).
pub(super) fn covers(layout: &LinkLayout) -> bool {
    layout.base_angle.is_some()
        && layout.base_turns.is_empty()
        && layout.links.iter().all(|l| l.map.len() <= 1)
}

/// What hangs on the end frame: the composite inertia and wrench.
struct Tip {
    past: Inertia,
    wrench: T3,
}

/// The frame the forward sweep has reached: its turn (cos, sin), origin,
/// angular velocity and acceleration, and the origin's acceleration at
/// qdd = 0.
#[derive(Clone, Copy)]
struct Frame {
    turn: P2,
    pos: P2,
    omega: f64,
    alpha: f64,
    acc: P2,
}

/// One link's cell under `frame`: the link's sums entry, and the frame at
/// its end.
#[inline(always)]
fn place(
    c: &[f64; LEN],
    frame: &Frame,
    nc: usize,
    xd: f64,
    variable_inertia: bool,
    gravity: P2,
) -> (Link, Frame) {
    let Frame {
        turn: [cs, sn],
        pos,
        omega,
        alpha,
        acc,
    } = *frame;
    let turn = |i: usize| {
        let (x, y) = (c[i], c[i + 1]);
        [cs.mul_add(x, -(sn * y)), sn.mul_add(x, cs * y)]
    };
    let (d, dd, ddd) = (turn(cell::END), turn(cell::END_RATE), turn(cell::END_ACCEL));
    let (cen, cend, cendd) = (
        turn(cell::CENTROID),
        turn(cell::CENTROID_RATE),
        turn(cell::CENTROID_ACCEL),
    );
    let (m, inertia) = (c[cell::MASS], c[cell::LATERAL]);
    let body_a = add(
        carried(acc, alpha, omega, cen),
        add(scale(2.0 * omega, perp(cend)), cendd),
    );
    let body_w = omega + c[cell::BODY_OMEGA + 2];
    let end = add(pos, d);
    let mut link = Link {
        centroid: add(pos, cen),
        m,
        inertia,
        force: scale(m, sub(body_a, gravity)),
        torque: inertia * (alpha + c[cell::BODY_OMEGA_RATE + 2]),
        ..Link::default()
    };
    if nc == 1 {
        let col = cell::COLUMNS;
        let s_w = c[col + 2];
        let v = sub(turn(col + 3), scale(s_w, perp(end)));
        link.twist = [s_w, v[0], v[1]];
        let ov = turn(col + 9);
        link.own = [c[col + 8], ov[0], ov[1]];
        link.local_force = c[cell::forces(1)];
        if variable_inertia {
            // T = I(x) w^2 / 2: d(I w)/dt has I' w besides I alpha, and
            // dT/dx = w^2 dI/dx / 2.
            let rate = c[cell::inertia_rates(1)];
            link.torque += rate * xd * body_w;
            link.local_force -= 0.5 * body_w * body_w * rate;
        }
    }
    let (rc, rs) = (c[cell::ROTATION], c[cell::ROTATION + 3]);
    let next = Frame {
        turn: [cs.mul_add(rc, -(sn * rs)), sn.mul_add(rc, cs * rs)],
        pos: end,
        omega: omega + c[cell::OMEGA + 2],
        alpha: alpha + c[cell::OMEGA_RATE + 2],
        acc: add(
            carried(acc, alpha, omega, d),
            add(scale(2.0 * omega, perp(dd)), ddd),
        ),
    };
    (link, next)
}

/// Room for a planar cell's outputs.
const LEN: usize = cell::len(1);

/// The thread's buffers: per link its sums entry, per coordinate its
/// column.
#[derive(Default)]
struct Scratch {
    links: Vec<Link>,
    columns: Vec<Column>,
}

thread_local! {
    static SCRATCH: RefCell<Scratch> = RefCell::default();
}

/// The forward sweep: every link's cell where the sweep reaches it, into
/// a buffer of its own (the cell inlined, the buffer stays in registers),
/// under the frame composed so far; then the tip.
#[inline(always)]
fn forward<C: Cells>(
    layout: &LinkLayout,
    cells: &mut C,
    q: &[f64],
    qd: &[f64],
    p: &[f64],
    s: &mut Scratch,
) -> Tip {
    let loads = Loads::of(layout, cells);
    let loads = loads.values();
    let felt = super::felt_gravity(layout, p);
    let gravity = [felt[0], felt[1]];
    let (sn, cs) = layout.base_angle.map_or(0.0, |i| p[i]).sin_cos();
    let pos = super::base_motion(layout, p).0;
    let mut frame = Frame {
        turn: [cs, sn],
        pos: [pos[0], pos[1]],
        omega: 0.0,
        alpha: 0.0,
        acc: [0.0; 2],
    };
    s.links.clear();
    let mut at = 0;
    for spec in &layout.links {
        let mut cp = [0.0; CELL_PARAMS];
        link_params(&mut cp, spec, p, loads);
        let mut out = [0.0; LEN];
        let xd = match spec.map.len() {
            1 => {
                cells.one(spec.cell, &q[at..at + 1], &qd[at..at + 1], &cp, &mut out);
                at += 1;
                qd[at - 1]
            }
            _ => {
                cells.one(spec.cell, &[], &[], &cp, &mut out[..cell::len(0)]);
                0.0
            }
        };
        let nc = spec.map.len();
        let felt = super::link_gravity(layout, spec, p, [gravity[0], gravity[1], 0.0]);
        let (link, next) = place(
            &out,
            &frame,
            nc,
            xd,
            layout.variable_inertia,
            [felt[0], felt[1]],
        );
        s.links.push(link);
        frame = next;
    }
    let Frame {
        turn,
        pos,
        omega,
        alpha,
        acc,
    } = frame;
    tip(layout, p, (pos, turn), (omega, alpha, acc), gravity)
}

/// The tip body and loads on the end frame at `pos`, its axis `axis`,
/// moving by (omega, alpha, acc).
#[inline(always)]
fn tip(
    layout: &LinkLayout,
    p: &[f64],
    (pos, axis): (P2, P2),
    (omega, alpha, acc): (f64, f64, P2),
    gravity: P2,
) -> Tip {
    let mut past = Inertia::default();
    let mut wrench = [0.0; 3];
    let length = layout.tip_length.map_or(0.0, |i| p[i]);
    let point = add(pos, scale(length, axis));
    if let Some(m) = layout.tip_mass.map(|i| p[i]) {
        let offset = scale(0.5 * length, axis);
        let centre = add(pos, offset);
        // About z, across the tip's axis.
        let lateral = layout.tip_inertia.map_or(0.0, |[l, _]| p[l]);
        let force = scale(m, sub(carried(acc, alpha, omega, offset), gravity));
        past.add_body(m, centre, lateral);
        wrench = [lateral * alpha + cross(centre, force), force[0], force[1]];
    }
    // Applied loads enter as forces of the opposite sign.
    let tip_f = layout.tip_force.map_or([0.0; 2], |i| {
        let v = [-p[i[0]], -p[i[1]]];
        match layout.tip_frame {
            true => [
                axis[0].mul_add(v[0], -(axis[1] * v[1])),
                axis[1].mul_add(v[0], axis[0] * v[1]),
            ],
            false => v,
        }
    });
    let tip_m = layout.tip_moment.map_or(0.0, |i| -p[i[2]]);
    wrench[0] += cross(point, tip_f) + tip_m;
    wrench[1] += tip_f[0];
    wrench[2] += tip_f[1];
    Tip { past, wrench }
}

/// M (upper triangle, row by row) and h of a planar chain ([`covers`])
/// into `out` (the `MassBias` layout), by composite bodies from the tip:
/// a coordinate's row of M is its twist against the momenta of the
/// composite past it.
#[inline(always)]
pub(super) fn mass_bias<C: Cells>(
    layout: &LinkLayout,
    cells: &mut C,
    q: &[f64],
    qd: &[f64],
    p: &[f64],
    out: &mut [f64],
) {
    let n = layout.dof;
    assert_eq!(out.len(), n * (n + 1) / 2 + n, "MassBias output length");
    // Out of the thread-local for the call: a closure may stay out of
    // line, not built for FMA like the caller.
    let mut s = SCRATCH.take();
    let mut tip = forward(layout, cells, q, qd, p, &mut s);
    let (links, columns) = (&s.links, &mut s.columns);
    columns.resize(n, ([0.0; 3], [0.0; 3]));
    let (mass, bias) = out.split_at_mut(n * (n + 1) / 2);
    let mut i = n;
    for (l, spec) in links.iter().zip(&layout.links).rev() {
        if spec.map.len() == 1 {
            i -= 1;
            let (t, o) = (l.twist, l.own);
            let body = [l.inertia * o[0], l.m * o[1], l.m * o[2]];
            let composite = tip.past.momentum(t);
            let momentum = [
                composite[0] + body[0] + cross(l.centroid, [body[1], body[2]]),
                composite[1] + body[1],
                composite[2] + body[2],
            ];
            bias[i] =
                pair(t, tip.wrench) + dot([o[1], o[2]], l.force) + o[0] * l.torque + l.local_force;
            mass[i * n - i * (i + 1) / 2 + i] = pair(t, composite) + pair(o, body);
            columns[i] = (t, momentum);
        }
        tip.past.add_body(l.m, l.centroid, l.inertia);
        tip.wrench[0] += l.torque + cross(l.centroid, l.force);
        tip.wrench[1] += l.force[0];
        tip.wrench[2] += l.force[1];
    }
    // Coordinates i < j: twist_i . momentum_j.
    let mut at = 0;
    for i in 0..n {
        mass[at + 1..at + n - i]
            .iter_mut()
            .zip(&columns[i + 1..])
            .for_each(|(m, c)| *m = pair(columns[i].0, c.1));
        at += n - i;
    }
    SCRATCH.set(s);
}

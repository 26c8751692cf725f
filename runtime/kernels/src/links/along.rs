//! Loads along a chain (`[[load]]` at a point of an element, or per unit
//! length at every element's middle) by the sweep out to their points
//! (`points.rs`), so that an arm with loads runs on its link cells: each
//! load's generalised force Q_a = dp/dq_a . F + w_a . M (the point's
//! column and its section's angular column), taken from h; its directional
//! derivative from the Jvp; a constant world force's potential -F . p from
//! the outputs' potential energy, as the flat kernels do
//! (`eomgen/src/tmt/along.rs` places the same points). Driven forces on
//! the arm's coordinates (`[[torque]]`, `LinkLayout::torques`) are taken
//! from h here too; they have no potential, as in the flat kernels.

use serde::{Deserialize, Serialize};

use super::num::{Num, dot, mat_vec};
use super::points::{Asked, At, ContactPoint, PointMotion, sweep};
use super::{Cells, LinkLayout};
use crate::dual::Dual;

/// A load at a point of the chain, its components' parameter slots.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AlongLoad {
    /// Where it acts.
    pub at: ContactPoint,
    pub force: Option<[usize; 3]>,
    pub moment: Option<[usize; 3]>,
    /// Given in the section's frame, turning with it (a follower load).
    pub local: bool,
    /// A force per unit length: times this parameter (its element's
    /// length, the midpoint rule).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub per_length: Option<usize>,
}

/// An immersed arm's drag (`[fluid]` with drag coefficients): Morison's,
/// at each element's middle, of its velocity relative to the current, as
/// `eomgen/src/tmt/along.rs`'s dissipation gives it. Parameter slots.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Drag {
    pub density: usize,
    pub normal: usize,
    pub tangential: usize,
    pub current: [usize; 3],
    pub points: Vec<DragPoint>,
}

/// An element's middle and the slots of its width and length.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DragPoint {
    pub at: ContactPoint,
    pub width: usize,
    pub length: usize,
}

/// The drag force at a point moving at `v` (relative to the current
/// `current`) whose section's axis is `axis`: -dD/dv of the dissipation
/// D = (c_n |v_n|^3 + c_t |v_t|^3) / 6, c_n = rho C_n d l, c_t = pi rho C_t
/// d l, each magnitude sqrt(v^2 + eps^2) (eps 1 um/s) as the flat kernels
/// take it: -(c_n |v_n| v_n + c_t |v_t| v_t) / 2.
#[inline(always)]
fn drag_force<N: Num>(
    drag: &Drag,
    point: &DragPoint,
    p: &[f64],
    v: [N; 3],
    axis: [N; 3],
) -> [N; 3] {
    let rel: [N; 3] = std::array::from_fn(|c| v[c] - N::constant(p[drag.current[c]]));
    let along = dot(rel, axis);
    let across2 = dot(rel, rel) - along * along;
    let eps2 = N::constant(1e-12);
    let base = p[drag.density] * p[point.width] * p[point.length];
    let cn = N::constant(0.5 * p[drag.normal] * base) * (across2 + eps2).sqrt();
    let ct = N::constant(0.5 * std::f64::consts::PI * p[drag.tangential] * base)
        * (along * along + eps2).sqrt();
    std::array::from_fn(|c| N::ZERO - (cn * (rel[c] - along * axis[c]) + ct * along * axis[c]))
}

/// The drag's generalised forces, `add(a, Q_a)` per arm coordinate a; on
/// dual numbers along (dq, `dqd`).
fn drag_forces<N: Num>(
    layout: &LinkLayout,
    cells: &mut dyn Cells,
    (q, qd, dq, p): At,
    dqd: Option<&[f64]>,
    add_to: &mut impl FnMut(usize, N),
) {
    let Some(drag) = &layout.drag else {
        return;
    };
    let points: Vec<ContactPoint> = drag.points.iter().map(|d| d.at).collect();
    let asked = Asked {
        columns: true,
        spin: true,
    };
    sweep(
        layout,
        cells,
        (q, qd, dq, p),
        (&points, |_| true),
        (asked, None),
        |i, m: &PointMotion<N>| {
            // The velocity's derivative along dqd: the columns times it.
            let mut v = m.v;
            if let Some(dqd) = dqd {
                for (col, &r) in m.columns.iter().zip(dqd) {
                    for c in 0..3 {
                        v[c] = v[c] + col[c] * N::moving(0.0, r);
                    }
                }
            }
            let axis = [m.rotation[0][0], m.rotation[1][0], m.rotation[2][0]];
            let force = drag_force(drag, &drag.points[i], p, v, axis);
            for (a, col) in m.columns.iter().enumerate() {
                add_to(a, dot(*col, force));
            }
        },
    );
}

/// Load `i`'s force and moment in the world frame at its point.
#[inline(always)]
fn world<N: Num>(load: &AlongLoad, m: &PointMotion<N>, p: &[f64]) -> ([N; 3], [N; 3]) {
    let times = load.per_length.map_or(1.0, |i| p[i]);
    let vector = |slots: Option<[usize; 3]>, times: f64| -> [N; 3] {
        let v = slots.map_or([N::ZERO; 3], |s| s.map(|i| N::constant(times * p[i])));
        match load.local {
            true => mat_vec(&m.rotation, v),
            false => v,
        }
    };
    (vector(load.force, times), vector(load.moment, 1.0))
}

/// Each load's generalised forces, `add(a, Q_a)` per arm coordinate a,
/// on `N` (dual numbers: along `dq`).
fn generalised<N: Num>(
    layout: &LinkLayout,
    cells: &mut dyn Cells,
    (q, qd, dq, p): At,
    dqd: Option<&[f64]>,
    mut add_to: impl FnMut(usize, N),
) {
    for &[a, slot] in &layout.torques {
        add_to(a, N::constant(p[slot]));
    }
    drag_forces(layout, cells, (q, qd, dq, p), dqd, &mut add_to);
    let loads = &layout.along;
    if loads.is_empty() {
        return;
    }
    let points: Vec<ContactPoint> = loads.iter().map(|l| l.at).collect();
    let asked = Asked {
        columns: true,
        spin: loads.iter().any(|l| l.local || l.moment.is_some()),
    };
    sweep(
        layout,
        cells,
        (q, qd, dq, p),
        (&points, |_| true),
        (asked, None),
        |i, m: &PointMotion<N>| {
            let (force, moment) = world(&loads[i], m, p);
            for (a, col) in m.columns.iter().enumerate() {
                let mut qa = dot(*col, force);
                if loads[i].moment.is_some() {
                    qa = qa + dot(m.spin[a], moment);
                }
                add_to(a, qa);
            }
        },
    );
}

/// h minus the loads' generalised forces, the coordinates' driven ones
/// included.
pub fn subtract_loads(
    layout: &LinkLayout,
    cells: &mut dyn Cells,
    (q, qd, p): (&[f64], &[f64], &[f64]),
    h: &mut [f64],
) {
    generalised(layout, cells, (q, qd, None, p), None, |a, qa: f64| {
        h[a] -= qa
    });
}

/// tau and its tangent `dtau` minus the loads' generalised forces and
/// their derivative along (dq, dqd) (the loads depend on q and the
/// parameters, the coordinates' driven ones on the parameters, the drag
/// on q and qd too).
pub fn subtract_loads_tangent(
    layout: &LinkLayout,
    cells: &mut dyn Cells,
    (q, qd, p): (&[f64], &[f64], &[f64]),
    (dq, dqd): (&[f64], &[f64]),
    (tau, dtau): (&mut [f64], &mut [f64]),
) {
    generalised(
        layout,
        cells,
        (q, qd, Some(dq), p),
        Some(dqd),
        |a, qa: Dual| {
            tau[a] -= qa.v;
            dtau[a] -= qa.d;
        },
    );
}

/// The potential of the loads' constant world forces, -F . p each (a
/// follower force has none).
pub fn loads_potential(
    layout: &LinkLayout,
    cells: &mut dyn Cells,
    (q, qd, p): (&[f64], &[f64], &[f64]),
) -> f64 {
    let loads = &layout.along;
    let points: Vec<ContactPoint> = loads.iter().map(|l| l.at).collect();
    let world_force = |i: usize| !loads[i].local && loads[i].force.is_some();
    let asked = Asked {
        columns: false,
        spin: false,
    };
    let mut pe = 0.0;
    sweep(
        layout,
        cells,
        (q, qd, None, p),
        (&points, world_force),
        (asked, None),
        |i, m: &PointMotion<f64>| {
            let (force, _) = world(&loads[i], m, p);
            pe -= dot(force, m.p);
        },
    );
    pe
}

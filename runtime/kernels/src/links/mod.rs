//! Mass + bias of a serial chain of constant-strain links (3D pcc and vc
//! arms, rom slices) by a recursion over the links, each link's local
//! kinematics from one generated *cell*.
//!
//! A fully unrolled kernel of a 20-DOF 3D arm is over 100 KB of machine
//! code, past the processor's instruction caches: it runs at half the
//! instructions per nanosecond of a small one (measured by benches/interleaved.rs and callgrind).
//! Here the CAS derives one link on its own, in its base frame at rest (the
//! cell: relative rotation and end point, the body's centroid and axis,
//! their rates and convective accelerations, the columns of the link's
//! coordinates, the link's elastic and dissipative forces), identical links
//! share one cell, and this loop composes the world frame link by link and
//! sums M and h from the tip: by composite bodies (Featherstone's CRBA and
//! RNEA, in the world frame as `eomgen/src/tmt/chain.rs` does symbolically)
//! where links own their coordinates, over rows of the arm's coordinates
//! where they share them (rom).
//! The flat `MassBias` tape stays the interpreter's form: the two are
//! independent computations of the same M and h (tests/suite/backends.rs).

use std::cell::RefCell;

use serde::{Deserialize, Serialize};

mod along;
mod articulated;
mod base;
mod compiled;
mod contact;
mod frames;
mod num;
mod outputs;
mod planar;
mod points;
mod shared;
mod tangent;
pub use along::{
    AlongLoad, Drag, DragPoint, loads_potential, subtract_loads, subtract_loads_tangent,
};
pub use articulated::accelerations_owned;
pub use base::BaseTurn;
pub(crate) use base::{base_motion, base_orientation, base_rates, felt_gravity};
pub use compiled::{CellFn, CellLanesFn, CellTangentFn, CompiledCell};
pub use contact::{
    CONTACT_BOUND, ContactElement, contact_bounds, contact_jacobian, contact_jvp, contact_points,
    has_contact_bounds,
};
pub use frames::{ArmFrame, frame, frames};
pub use outputs::outputs;
pub(crate) use points::bits_equal;
pub use points::{ContactPoint, LinkOutputs};
pub use shared::{AT_ONCE, mass_bias_shared, mass_bias_shared_dyn, mass_bias_wide, padded};
pub use tangent::inverse_dynamics_tangent;

/// The element parameters a cell reads, in this order, per link:
/// element[k].length, .mass, .inertia, .axial_inertia, joint[k].stiffness,
/// .damping, .rest, twist[k].stiffness, .damping, stretch[k].stiffness,
/// .damping, shear[k].stiffness.
pub const ELEMENT_PARAMS: usize = 12;
/// Then the actuators' loads on the link's strain (c_st, c_by, c_bz: its
/// segment's, from the `loads` kernel; zero where no actuator acts).
pub const ACTUATION_LOADS: usize = 3;
/// Then the element's rest strains besides its bend about z (bend about y,
/// twist, stretch: `ElementParam::REST_3D`), which a cell of a 3D rest
/// shape reads; other cells' slots repeat the length's.
pub const REST_PARAMS: usize = 3;
/// Then, for a section that bends unequally about y and z
/// ([`LinkSpec::principal`]), its bend stiffness about y, its bodies'
/// rotary inertia about y and its shear stiffness along z
/// (`ElementParam::ANISOTROPIC`); zero for other links.
pub const PRINCIPAL_PARAMS: usize = 3;
/// Everything a cell reads besides its coordinates.
pub const CELL_PARAMS: usize = ELEMENT_PARAMS + ACTUATION_LOADS + REST_PARAMS + PRINCIPAL_PARAMS;

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
    /// velocity columns (6); then the n generalised elastic and
    /// dissipative forces; last the n derivatives of an isotropic body
    /// inertia in the coordinates (read when the layout has
    /// `variable_inertia`: a planar pcc arc's; zero otherwise).
    pub const COLUMNS: usize = 45;

    /// Where the generalised forces of a cell of `n` coordinates start.
    pub const fn forces(n: usize) -> usize {
        COLUMNS + 12 * n
    }

    /// Where the inertia derivatives start.
    pub const fn inertia_rates(n: usize) -> usize {
        COLUMNS + 13 * n
    }

    pub const fn len(n: usize) -> usize {
        COLUMNS + 14 * n
    }

    /// A cell whose body's inertia is not axisymmetric
    /// (`LinkSpec::principal`) reports after the rest its body's y axis
    /// (3) and its inertia about it (1): [`PRINCIPAL`] more values.
    pub const PRINCIPAL: usize = 4;

    /// The length of the outputs of a cell of `n` coordinates, with
    /// [`PRINCIPAL`] more where `principal`.
    pub const fn len_of(n: usize, principal: bool) -> usize {
        len(n) + if principal { PRINCIPAL } else { 0 }
    }
}

/// Where a *pose cell*'s outputs sit: what the `Outputs` kernel needs of a
/// link (no accelerations or columns; the link's quaternion and strain
/// energy besides), a kernel of its own so that `mass_bias`'s cells carry
/// nothing the hot path does not read.
pub mod pose {
    pub const ROTATION: usize = 0;
    pub const END: usize = 9;
    pub const END_RATE: usize = 12;
    pub const OMEGA: usize = 15;
    pub const CENTROID: usize = 18;
    pub const CENTROID_RATE: usize = 21;
    pub const BODY_OMEGA: usize = 24;
    pub const AXIS: usize = 27;
    pub const MASS: usize = 30;
    pub const LATERAL: usize = 31;
    pub const AXIAL: usize = 32;
    /// The relative rotation as a unit quaternion (w, x, y, z).
    pub const QUAT: usize = 33;
    /// The link's strain energy (springs; not the actuators' potential).
    pub const ENERGY: usize = 37;
    pub const LEN: usize = 38;
    /// A body whose inertia is not axisymmetric: its y axis and its
    /// inertia about it, after the rest.
    pub const Y_AXIS: usize = 38;
    pub const LATERAL_Y: usize = 41;
    pub const PRINCIPAL_LEN: usize = 42;
}

/// A coordinate of a cell: a fixed linear combination of the arm's
/// coordinates, times a parameter where `scale` names one. A pcc link's
/// coordinates are the arm's own (one term, weight 1); a rom slice's strain
/// is its segment's coefficients integrated over the slice.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LocalCoordinate {
    /// (arm coordinate, weight)
    pub terms: Vec<(usize, f64)>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scale: Option<usize>,
}

/// One link: its cell, its coordinates and its parameters.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct LinkSpec {
    pub cell: usize,
    /// The cell's coordinates, in its order.
    pub map: Vec<LocalCoordinate>,
    /// Indices into the parameter vector: [`ELEMENT_PARAMS`], then
    /// [`REST_PARAMS`].
    pub params: Vec<usize>,
    /// Which triple of the `loads` kernel's outputs the link's actuation
    /// loads are; None: none act on it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub load: Option<usize>,
    /// The slot of the volume its element displaces, where the arm is
    /// immersed (`LinkLayout::fluid_density`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub displaced: Option<usize>,
    /// A section that bends unequally about y and z: the slots of its
    /// [`PRINCIPAL_PARAMS`]. Its body's inertia then has a principal axis
    /// y of its own, which its cell reports ([`cell::len_of`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub principal: Option<[usize; PRINCIPAL_PARAMS]>,
}

impl LinkSpec {
    /// The length of this link's cell's outputs ([`cell::len_of`]).
    #[inline(always)]
    pub fn cell_len(&self) -> usize {
        cell::len_of(self.map.len(), self.principal.is_some())
    }
}

/// A chain of links and where its global parameters are.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct LinkLayout {
    pub links: Vec<LinkSpec>,
    /// The arm's coordinates.
    pub dof: usize,
    /// Generalised forces not local to a link (a rom segment's strain
    /// energy and damping, integrated over the whole segment) come from a
    /// kernel of the arm's coordinates: `mass_bias`'s `forces`.
    pub forces: bool,
    /// Triples of actuation loads the `loads` kernel (of the parameters
    /// alone, driven ones included) gives, one per actuated segment.
    #[serde(default)]
    pub loads: usize,
    pub gravity: [usize; 3],
    pub base_position: [usize; 3],
    /// A base moved along a driven path: its offset from `base_position`,
    /// the offset's rate and its acceleration (the slots of each's x, y,
    /// z), inputs the runtime writes at every evaluation.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub base_translation: Option<[[usize; 3]; 3]>,
    /// The base's turns by inputs, in sequence ([`BaseTurn`]), before the
    /// declared direction.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub base_turns: Vec<BaseTurn>,
    /// An immersed arm's fluid density: each link's body is buoyed by the
    /// weight of its share of its element's displaced fluid
    /// ([`link_gravity`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fluid_density: Option<usize>,
    /// Rows of the base rotation (3D chains).
    pub base_rotation: [usize; 9],
    /// A planar chain's base angle about z, which stands for the rotation
    /// and quaternion parameters.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub base_angle: Option<usize>,
    /// Bodies whose (isotropic) inertia changes with the cell coordinates
    /// (planar pcc arcs): the recursion adds the torque I' w and the forces
    /// -|w|^2 dI/dx / 2 of T = I(x) |w|^2 / 2 ([`cell::inertia_rates`]).
    #[serde(default)]
    pub variable_inertia: bool,
    /// The base orientation as a quaternion (w, x, y, z).
    #[serde(default)]
    pub base_quaternion: [usize; 4],
    pub tip_force: Option<[usize; 3]>,
    pub tip_moment: Option<[usize; 3]>,
    /// The tip force and moment turn with the tip frame.
    pub tip_frame: bool,
    /// A tip body: its mass, and with a length (a cylinder along the tip
    /// axis, the tip point at its far end) its lateral and axial inertia.
    pub tip_mass: Option<usize>,
    pub tip_length: Option<usize>,
    pub tip_inertia: Option<[usize; 2]>,
    /// The chain's contact points, in the order of the contact kernels,
    /// when the recursion gives them (`contact`); empty otherwise.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub contact: Vec<ContactPoint>,
    /// The elements those points are on, in order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub contact_elements: Vec<ContactElement>,
    /// The loads along the chain, in the links' order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub along: Vec<AlongLoad>,
    /// An immersed arm's drag at its elements' middles.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub drag: Option<Drag>,
    /// Driven generalised forces on the arm's coordinates (`[[torque]]`):
    /// each an arm coordinate and the slot of its value.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub torques: Vec<[usize; 2]>,
    /// Each segment's last link: where its end frame, which joints may
    /// hold, is.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub segment_ends: Vec<usize>,
    /// [`LinkLayout::weights`], computed on first use.
    #[serde(skip)]
    pub weights: std::sync::OnceLock<Vec<f64>>,
}

impl LinkLayout {
    /// Whether applied loads other than the tip's act: loads along the
    /// chain, a fluid's drag or forces on its coordinates
    /// ([`subtract_loads`]).
    pub fn loaded(&self) -> bool {
        !self.along.is_empty() || !self.torques.is_empty() || self.drag.is_some()
    }

    /// Whether some link's body needs more than an axisymmetric inertia
    /// in still air: a section that bends unequally
    /// ([`LinkSpec::principal`]) or an immersed arm's buoyancy. The
    /// recursion is built for each answer (its `BODIES` parameter), so
    /// that the common chain's sweep carries neither term.
    pub fn general_bodies(&self) -> bool {
        self.fluid_density.is_some() || self.links.iter().any(|l| l.principal.is_some())
    }

    /// Whether the articulated-body sweeps give the chain's accelerations
    /// ([`accelerations_owned`]): its links own their coordinates, no
    /// forces kernel adds to h and no link's inertia varies.
    pub fn direct_accelerations(&self) -> bool {
        all_owned(self) && !self.forces && !self.variable_inertia
    }

    /// The weights of every link's cell coordinates, dense: for link k
    /// and cell coordinate f < [`MAX_LINK_DOF`], a row of the arm's
    /// coordinates padded to [`padded`]`(dof)` (zeros for unused f), at
    /// `(k * MAX_LINK_DOF + f) * padded(dof)`; without `scale`.
    pub fn weights(&self) -> &[f64] {
        self.weights.get_or_init(|| {
            let n = padded(self.dof);
            let mut w = vec![0.0; self.links.len() * MAX_LINK_DOF * n];
            for (k, spec) in self.links.iter().enumerate() {
                for (f, c) in spec.map.iter().enumerate() {
                    for &(a, wa) in &c.terms {
                        w[(k * MAX_LINK_DOF + f) * n + a] += wa;
                    }
                }
            }
            w
        })
    }
}

/// The link recursion of a model: its layout, the cells, and the kernel of
/// the non-local forces when `layout.forces`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct LinkKernels {
    pub layout: LinkLayout,
    /// Whether compiled code takes `MassBias` from the recursion too (3D
    /// chains of four links or more, planar ones of 32 or more: eomgen's
    /// `link_chain`); shorter chains keep the flat kernel, quicker for
    /// their few coordinates, and take the Jvp and outputs from here.
    #[serde(default)]
    pub mass_bias: bool,
    pub cells: Vec<crate::Tape>,
    /// Each cell's pose cell ([`pose`]), for [`outputs`].
    #[serde(default)]
    pub poses: Vec<crate::Tape>,
    /// The strain energy of what the non-local forces come from (one
    /// value), for [`outputs`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub energy: Option<crate::Tape>,
    /// Each cell's outputs followed by their directional derivative along
    /// (dx, dxd) (the tape's `dir` input): [`inverse_dynamics_tangent`].
    pub tangents: Vec<crate::Tape>,
    pub forces: Option<crate::Tape>,
    /// The forces and their directional derivative along the arm's (dq,
    /// dqd).
    pub forces_tangent: Option<crate::Tape>,
    /// The actuation loads ([`LinkLayout::loads`] triples).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub loads: Option<crate::Tape>,
}

/// What the recursion evaluates: the cells and the non-local forces.
/// Generated code implements it over its compiled kernels (`four` in
/// vector lanes); tests over the tapes.
pub trait Cells {
    /// Cell `c` of one link at its cell coordinates `x`, rates `xd` and
    /// parameters `p` ([`CELL_PARAMS`]).
    fn one(&mut self, c: usize, x: &[f64], xd: &[f64], p: &[f64], out: &mut [f64]);

    /// Cell `c` of four links at once, lane l of every value link l's.
    fn four(
        &mut self,
        c: usize,
        x: &[[f64; 4]],
        xd: &[[f64; 4]],
        p: &[[f64; 4]],
        out: &mut [[f64; 4]],
    ) {
        by_lanes(|x, xd, p, o| self.one(c, x, xd, p, o), x, xd, p, out)
    }

    /// The generalised forces no link has (`LinkLayout::forces`), over
    /// the arm's coordinates.
    fn forces(&mut self, out: &mut [f64]);

    /// Cell `c` as [`Cells::one`] (the first [`cell::len`] values of
    /// `out`), then its outputs' directional derivatives along the cell
    /// coordinates' (dx, dxd) (as many again).
    #[allow(clippy::too_many_arguments)]
    fn tangent(
        &mut self,
        c: usize,
        x: &[f64],
        xd: &[f64],
        dx: &[f64],
        dxd: &[f64],
        p: &[f64],
        out: &mut [f64],
    );

    /// [`Cells::forces`] (the first `dof` values of `out`), then their
    /// directional derivative along the arm's (dq, dqd) = `dir`.
    fn forces_tangent(&mut self, dir: &[f64], out: &mut [f64]);

    /// The actuation loads, [`LinkLayout::loads`] triples.
    fn loads(&mut self, out: &mut [f64]);

    /// Cell `c`'s pose cell ([`pose`]) at cell coordinates `x`, rates `xd`
    /// and parameters `p`.
    fn pose(&mut self, c: usize, x: &[f64], xd: &[f64], p: &[f64], out: &mut [f64]);

    /// The strain energy the non-local forces derive from
    /// ([`LinkLayout::forces`]).
    fn energy(&mut self) -> f64;
}

/// Four links' cells one lane at a time by `one` (x, xd, p, out): where
/// no lane kernel is compiled.
pub(crate) fn by_lanes(
    mut one: impl FnMut(&[f64], &[f64], &[f64], &mut [f64]),
    x: &[[f64; 4]],
    xd: &[[f64; 4]],
    p: &[[f64; 4]],
    out: &mut [[f64; 4]],
) {
    let lane = |v: &[[f64; 4]], l: usize| -> Vec<f64> { v.iter().map(|v| v[l]).collect() };
    let mut o = vec![0.0; out.len()];
    for l in 0..4 {
        one(&lane(x, l), &lane(xd, l), &lane(p, l), &mut o);
        for (out, v) in out.iter_mut().zip(&o) {
            out[l] = *v;
        }
    }
}

/// The gravity link `spec`'s body feels, `felt` ([`felt_gravity`]) less
/// the buoyancy of an immersed arm: its element displaces rho V of fluid,
/// shared among its bodies as their mass m_b is among the element's m,
/// so that a body's buoyancy is m_b (rho V / m) g, opposite its weight.
#[inline(always)]
pub(crate) fn link_gravity(layout: &LinkLayout, spec: &LinkSpec, p: &[f64], felt: V3) -> V3 {
    match (layout.fluid_density, spec.displaced) {
        (Some(rho), Some(v)) => {
            let lift = p[rho] * p[v] / p[spec.params[1]];
            sub(felt, scale(lift, layout.gravity.map(|i| p[i])))
        }
        _ => felt,
    }
}

/// A link's cell coordinates (or their rates, accelerations, directions)
/// from the arm's `v`: each [`LocalCoordinate`]'s combination, scaled.
pub(crate) fn local(spec: &LinkSpec, p: &[f64], v: &[f64]) -> [f64; MAX_LINK_DOF] {
    let mut x = [0.0; MAX_LINK_DOF];
    for (x, c) in x.iter_mut().zip(&spec.map) {
        let sc = c.scale.map_or(1.0, |i| p[i]);
        *x = sc * c.terms.iter().map(|&(a, w)| w * v[a]).sum::<f64>();
    }
    x
}

/// The actuation loads ([`Cells::loads`]: [`LinkLayout::loads`]
/// triples), on the stack for up to eight actuated segments.
pub(crate) struct Loads {
    stack: [f64; 3 * 8],
    heap: Vec<f64>,
    len: usize,
}

impl Loads {
    #[inline(always)]
    pub(crate) fn of<C: Cells + ?Sized>(layout: &LinkLayout, cells: &mut C) -> Self {
        let len = 3 * layout.loads;
        let mut loads = Loads {
            stack: [0.0; 3 * 8],
            heap: Vec::new(),
            len,
        };
        if len > loads.stack.len() {
            loads.heap.resize(len, 0.0);
            cells.loads(&mut loads.heap);
        } else if len > 0 {
            cells.loads(&mut loads.stack[..len]);
        }
        loads
    }

    #[inline(always)]
    pub(crate) fn values(&self) -> &[f64] {
        match self.len > self.stack.len() {
            true => &self.heap,
            false => &self.stack[..self.len],
        }
    }
}

/// A link's cell parameters into `v`: its element parameters from `p`,
/// then its segment's actuation loads (`loads`: [`Loads::values`]; zero
/// where none act).
#[inline(always)]
pub(crate) fn link_params(v: &mut [f64; CELL_PARAMS], spec: &LinkSpec, p: &[f64], loads: &[f64]) {
    let (own, rest) = spec.params.split_at(ELEMENT_PARAMS);
    for (v, &i) in v.iter_mut().zip(own) {
        *v = p[i];
    }
    let at = spec.load.map(|l| 3 * l);
    let (actuation, rest_v) = v[ELEMENT_PARAMS..].split_at_mut(ACTUATION_LOADS);
    for (f, v) in actuation.iter_mut().enumerate() {
        *v = at.map_or(0.0, |at| loads[at + f]);
    }
    let (rest_v, principal) = rest_v.split_at_mut(REST_PARAMS);
    for (v, &i) in rest_v.iter_mut().zip(rest) {
        *v = p[i];
    }
    match spec.principal {
        Some(at) => {
            for (v, i) in principal.iter_mut().zip(at) {
                *v = p[i];
            }
        }
        None => principal.fill(0.0),
    }
}

/// Every link's cell parameters ([`link_params`]).
pub(crate) fn cell_params<C: Cells + ?Sized>(
    layout: &LinkLayout,
    cells: &mut C,
    p: &[f64],
    params: &mut Vec<[f64; CELL_PARAMS]>,
) {
    let loads = Loads::of(layout, cells);
    let loads = loads.values();
    params.resize(layout.links.len(), [0.0; CELL_PARAMS]);
    for (v, spec) in params.iter_mut().zip(&layout.links) {
        link_params(v, spec, p, loads);
    }
}

pub(super) type V3 = [f64; 3];
pub(super) type M3 = [[f64; 3]; 3];

#[inline(always)]
pub(super) fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
#[inline(always)]
pub(super) fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
#[inline(always)]
pub(super) fn scale(s: f64, a: V3) -> V3 {
    [s * a[0], s * a[1], s * a[2]]
}
#[inline(always)]
pub(super) fn dot(a: V3, b: V3) -> f64 {
    a[0].mul_add(b[0], a[1].mul_add(b[1], a[2] * b[2]))
}
#[inline(always)]
pub(super) fn cross(a: V3, b: V3) -> V3 {
    [
        a[1].mul_add(b[2], -(a[2] * b[1])),
        a[2].mul_add(b[0], -(a[0] * b[2])),
        a[0].mul_add(b[1], -(a[1] * b[0])),
    ]
}
#[inline(always)]
pub(super) fn mat_vec(r: &M3, v: V3) -> V3 {
    [dot(r[0], v), dot(r[1], v), dot(r[2], v)]
}
#[inline(always)]
pub(super) fn mat_mat(a: &M3, b: &M3) -> M3 {
    std::array::from_fn(|i| std::array::from_fn(|j| dot(a[i], [b[0][j], b[1][j], b[2][j]])))
}
#[inline(always)]
fn pair(a: (V3, V3), b: (V3, V3)) -> f64 {
    dot(a.0, b.0) + dot(a.1, b.1)
}
/// A body's rotary inertia about its centroid: `lateral` about every axis
/// normal to its `axis` and `axial` about it, and for a section that bends
/// unequally `extra` more about its y axis `y`:
/// J = lateral 1 + (axial - lateral) a a^T + extra y y^T.
#[derive(Clone, Copy, Default)]
struct Rotary {
    lateral: f64,
    axial: f64,
    axis: V3,
    y: V3,
    extra: f64,
}

impl Rotary {
    /// An axisymmetric body's.
    #[inline(always)]
    fn axisymmetric(lateral: f64, axial: f64, axis: V3) -> Self {
        Rotary {
            lateral,
            axial,
            axis,
            ..Default::default()
        }
    }

    /// J w; `BODIES` as [`LinkLayout::general_bodies`].
    #[inline(always)]
    fn apply<const BODIES: bool>(&self, w: V3) -> V3 {
        let j = add(
            scale(self.lateral, w),
            scale((self.axial - self.lateral) * dot(self.axis, w), self.axis),
        );
        match BODIES && self.extra != 0.0 {
            true => add(j, scale(self.extra * dot(self.y, w), self.y)),
            false => j,
        }
    }
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
    /// Adds a body of mass m at r of rotary inertia `j` ([`Rotary`]):
    /// J += j + m (|r|^2 1 - r r^T); `BODIES` as
    /// [`LinkLayout::general_bodies`].
    #[inline(always)]
    fn add_body<const BODIES: bool>(&mut self, m: f64, r: V3, j: &Rotary) {
        let r2 = dot(r, r);
        let d = j.axial - j.lateral;
        let diag = j.lateral + m * r2;
        self.m += m;
        self.h = add(self.h, scale(m, r));
        const PAIRS: [(usize, usize); 6] = [(0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)];
        for (k, (a, b)) in PAIRS.into_iter().enumerate() {
            let base = if k < 3 { diag } else { 0.0 };
            self.j[k] += base + d * j.axis[a] * j.axis[b] - m * r[a] * r[b];
        }
        if BODIES && j.extra != 0.0 {
            for (k, (a, b)) in PAIRS.into_iter().enumerate() {
                self.j[k] += j.extra * j.y[a] * j.y[b];
            }
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
    m: f64,
    rotary: Rotary,
    force: V3,
    torque: V3,
}

/// Most coordinates a cell has (bend pair, twist, stretch, shear pair).
pub const MAX_LINK_DOF: usize = 6;
/// Room for the outputs of any cell.
const CELL_STRIDE: usize = cell::len_of(MAX_LINK_DOF, true);

type Twist = (V3, V3);

#[inline(always)]
fn flat((w, v): Twist) -> [f64; 6] {
    [w[0], w[1], w[2], v[0], v[1], v[2]]
}

/// What the forward sweep leaves for the sums from the tip.
#[derive(Default)]
struct Scratch {
    links: Vec<Link>,
    /// Per cell coordinate of every link (link k's from `start[k]`): the
    /// twist its rate gives everything past the link (spatial, about the
    /// world origin), the velocity it gives the link's own body (angular,
    /// centroid), its elastic and dissipative force.
    start: Vec<usize>,
    twist: Vec<Twist>,
    own: Vec<Twist>,
    local_force: Vec<f64>,
    /// Per arm coordinate, composite sums: the momentum its rate gives
    /// the links past the one being summed.
    momentum: Vec<Twist>,
    forces: Vec<f64>,
    /// Per link: cell coordinates, rates and parameters.
    x: Vec<[f64; MAX_LINK_DOF]>,
    xd: Vec<[f64; MAX_LINK_DOF]>,
    params: Vec<[f64; CELL_PARAMS]>,
    /// The cells' outputs in lanes, [`CELL_STRIDE`] vectors a link or a
    /// group of four, and where link k's are (`slot[k]`: start, lane).
    cell_out: Vec<[f64; 4]>,
    slot: Vec<(usize, usize)>,
    one_out: Vec<f64>,
    /// Per link, the articulated-body sweep's elimination of its
    /// coordinates (`articulated`).
    eliminated: Vec<articulated::Eliminated>,
    /// A wide arm's rows of X, a block of columns at a time (`shared`).
    wide: Vec<[f64; shared::BLOCK]>,
}

thread_local! {
    static SCRATCH: RefCell<Scratch> = RefCell::new(Scratch::default());
}

/// Whether every link's cell coordinates are the arm's own, in order
/// (pcc, vc): then M and h come by composite bodies, [`mass_bias_owned`].
pub fn all_owned(layout: &LinkLayout) -> bool {
    let mut next = 0;
    layout.links.iter().all(|l| {
        let own =
            l.map.iter().enumerate().all(|(f, c)| {
                c.scale.is_none() && c.terms.len() == 1 && c.terms[0] == (next + f, 1.0)
            });
        next += l.map.len();
        own
    }) && next == layout.dof
}

/// The end frame of the chain after the forward sweep, and what hangs on
/// it: the composite inertia and wrench the sums from the tip start with.
#[derive(Clone, Copy)]
struct Tip {
    past: Inertia,
    wrench: Twist,
}

/// Every link's cell at its cell coordinates and rates (`s.x`, `s.xd`),
/// four links at once where four in a row share a cell (cell coordinates
/// depend on q, qd and p alone, so all are known before the sweep).
#[inline(always)]
fn evaluate_cells<C: Cells>(layout: &LinkLayout, cells: &mut C, p: &[f64], s: &mut Scratch) {
    let nl = layout.links.len();
    cell_params(layout, cells, p, &mut s.params);
    // Link k's outputs: lane `slot[k].1` of the CELL_STRIDE vectors from
    // `slot[k].0`, four links sharing them where evaluated together.
    s.slot.resize(nl, (0, 0));
    let mut used = 0;
    let mut k = 0;
    while k < nl {
        let (c, nc) = (layout.links[k].cell, layout.links[k].map.len());
        let len = layout.links[k].cell_len();
        if s.cell_out.len() < used + CELL_STRIDE {
            s.cell_out.resize(used + CELL_STRIDE, [0.0; 4]);
        }
        let out = &mut s.cell_out[used..used + len];
        // Links of one cell have one principal layout: the cell's.
        if k + 4 <= nl && layout.links[k..k + 4].iter().all(|l| l.cell == c) {
            let x: [[f64; 4]; MAX_LINK_DOF] =
                std::array::from_fn(|f| std::array::from_fn(|l| s.x[k + l][f]));
            let xd: [[f64; 4]; MAX_LINK_DOF] =
                std::array::from_fn(|f| std::array::from_fn(|l| s.xd[k + l][f]));
            let pl: [[f64; 4]; CELL_PARAMS] =
                std::array::from_fn(|i| std::array::from_fn(|l| s.params[k + l][i]));
            cells.four(c, &x[..nc], &xd[..nc], &pl, out);
            for l in 0..4 {
                s.slot[k + l] = (used, l);
            }
            k += 4;
        } else {
            s.one_out.resize(len, 0.0);
            cells.one(
                c,
                &s.x[k][..nc],
                &s.xd[k][..nc],
                &s.params[k],
                &mut s.one_out,
            );
            for (o, v) in out.iter_mut().zip(&s.one_out) {
                o[0] = *v;
            }
            s.slot[k] = (used, 0);
            k += 1;
        }
        used += CELL_STRIDE;
    }
}

/// The forward sweep: each link's cell under the world frame composed so
/// far, its body's inertial and gravity forces, the twists of its cell
/// coordinates; then the tip body and loads. The caller has put the cell
/// coordinates and rates in `s.x`, `s.xd` and the links' starts in
/// `s.start`. `BODIES`: [`LinkLayout::general_bodies`].
#[inline(always)]
fn forward<C: Cells, const BODIES: bool>(
    layout: &LinkLayout,
    cells: &mut C,
    p: &[f64],
    s: &mut Scratch,
) -> Tip {
    debug_assert!(BODIES || !layout.general_bodies());
    let nl = layout.links.len();
    s.links.resize(nl, Link::default());
    s.start.clear();
    let mut total = 0;
    for spec in &layout.links {
        s.start.push(total);
        total += spec.map.len();
    }
    for v in [&mut s.twist, &mut s.own] {
        v.resize(total, ([0.0; 3], [0.0; 3]));
    }
    s.local_force.resize(total, 0.0);
    evaluate_cells(layout, cells, p, s);

    let gravity = felt_gravity(layout, p);
    let mut r: M3 = base_orientation(layout, p).0;
    let mut pos = base_motion(layout, p).0;
    let (mut omega, mut alpha) = base_rates(layout, p);
    let mut acc = [0.0; 3];
    for (k, spec) in layout.links.iter().enumerate() {
        let nc = spec.map.len();
        let at = s.start[k];
        let (base, lane) = s.slot[k];
        let out: &[[f64; 4]; CELL_STRIDE] = s.cell_out[base..base + CELL_STRIDE]
            .try_into()
            .expect("a cell's outputs");
        let lane = lane & 3;
        let c = |i: usize| out[i][lane];
        let v3 = |i: usize| [c(i), c(i + 1), c(i + 2)];
        let rel: M3 = std::array::from_fn(|i| v3(cell::ROTATION + 3 * i));
        let turn = |at: usize| mat_vec(&r, v3(at));
        let (d, dd, ddd) = (turn(cell::END), turn(cell::END_RATE), turn(cell::END_ACCEL));
        let (cen, cend, cendd) = (
            turn(cell::CENTROID),
            turn(cell::CENTROID_RATE),
            turn(cell::CENTROID_ACCEL),
        );
        let (w_rel, w_rel_d) = (turn(cell::OMEGA), turn(cell::OMEGA_RATE));
        let (w_b, w_b_d) = (turn(cell::BODY_OMEGA), turn(cell::BODY_OMEGA_RATE));
        let m = c(cell::MASS);
        let mut rotary = Rotary::axisymmetric(c(cell::LATERAL), c(cell::AXIAL), turn(cell::AXIS));
        if BODIES && spec.principal.is_some() {
            let at = cell::len(nc);
            rotary.y = turn(at);
            rotary.extra = c(at + 3) - rotary.lateral;
        }

        // The body: centroid, convective accelerations, inertial and
        // gravity forces.
        let body_a = add(
            add(add(acc, cross(alpha, cen)), cross(omega, cross(omega, cen))),
            add(scale(2.0, cross(omega, cend)), cendd),
        );
        let body_w = add(omega, w_b);
        let body_alpha = add(add(alpha, cross(omega, w_b)), w_b_d);
        let iw = rotary.apply::<BODIES>(body_w);
        let end = add(pos, d);
        let g = match BODIES {
            true => link_gravity(layout, spec, p, gravity),
            false => gravity,
        };
        s.links[k] = Link {
            centroid: add(pos, cen),
            m,
            rotary,
            force: scale(m, sub(body_a, g)),
            torque: add(rotary.apply::<BODIES>(body_alpha), cross(body_w, iw)),
        };
        let force_at = cell::forces(nc);
        for f in 0..nc {
            let col = cell::COLUMNS + 12 * f;
            let s_w = turn(col);
            let v_end = turn(col + 3);
            s.twist[at + f] = (s_w, sub(v_end, cross(s_w, end)));
            s.own[at + f] = (turn(col + 6), turn(col + 9));
            s.local_force[at + f] = c(force_at + f);
        }
        if layout.variable_inertia {
            // T = I(x) |w|^2 / 2: d(I w)/dt has I' w besides I alpha, and
            // dT/dx = |w|^2 dI/dx / 2 (an isotropic body: no gyroscopic term).
            let rates = cell::inertia_rates(nc);
            let i_dot: f64 = (0..nc).map(|f| c(rates + f) * s.xd[k][f]).sum();
            let half_w2 = 0.5 * dot(body_w, body_w);
            s.links[k].torque = add(s.links[k].torque, scale(i_dot, body_w));
            for f in 0..nc {
                s.local_force[at + f] -= half_w2 * c(rates + f);
            }
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

    // What hangs on the end frame moves rigidly with it: the tip body and
    // the tip loads start the composite sums.
    let mut past = Inertia::default();
    let mut wrench: Twist = ([0.0; 3], [0.0; 3]);
    let axis = [r[0][0], r[1][0], r[2][0]];
    let length = layout.tip_length.map_or(0.0, |i| p[i]);
    let point = add(pos, scale(length, axis));
    if let Some(m) = layout.tip_mass.map(|i| p[i]) {
        let offset = scale(0.5 * length, axis);
        let centre = add(pos, offset);
        let (lateral, axial) = layout.tip_inertia.map_or((0.0, 0.0), |[l, a]| (p[l], p[a]));
        let rotary = Rotary::axisymmetric(lateral, axial, axis);
        let a_c = add(
            add(acc, cross(alpha, offset)),
            cross(omega, cross(omega, offset)),
        );
        let force = scale(m, sub(a_c, gravity));
        let iw = rotary.apply::<false>(omega);
        let torque = add(rotary.apply::<false>(alpha), cross(omega, iw));
        past.add_body::<false>(m, centre, &rotary);
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
    Tip { past, wrench }
}

/// A link's part of the sums from the tip, per cell coordinate f: the
/// momentum its twist gives this link's body and the links past it, the
/// link's own block of M, the generalised bias. Then the link joins the
/// composite.
#[inline(always)]
fn link_sums<const BODIES: bool>(
    s: &Scratch,
    k: usize,
    nc: usize,
    tip: &mut Tip,
) -> (
    [Twist; MAX_LINK_DOF],
    [[f64; MAX_LINK_DOF]; MAX_LINK_DOF],
    [f64; MAX_LINK_DOF],
) {
    // By reference: a copy of the link is a call to memcpy.
    let l = &s.links[k];
    let at = s.start[k];
    let mut momentum = [([0.0; 3], [0.0; 3]); MAX_LINK_DOF];
    let mut block = [[0.0; MAX_LINK_DOF]; MAX_LINK_DOF];
    let mut g = [0.0; MAX_LINK_DOF];
    // The momentum each coordinate's own velocity gives the body, about
    // its centroid: (I w, m v).
    let mut body = [([0.0; 3], [0.0; 3]); MAX_LINK_DOF];
    #[allow(clippy::needless_range_loop)] // own and body side by side
    for f in 0..nc {
        let (ow, ov) = s.own[at + f];
        body[f] = (l.rotary.apply::<BODIES>(ow), scale(l.m, ov));
    }
    for f in 0..nc {
        let (ow, ov) = s.own[at + f];
        let (iw, mv) = body[f];
        let composite = tip.past.momentum(s.twist[at + f]);
        momentum[f] = (
            add(add(composite.0, iw), cross(l.centroid, mv)),
            add(composite.1, mv),
        );
        g[f] = pair(s.twist[at + f], tip.wrench)
            + dot(ov, l.force)
            + dot(ow, l.torque)
            + s.local_force[at + f];
        #[allow(clippy::needless_range_loop)] // fills both halves
        for f2 in f..nc {
            block[f][f2] = pair(s.twist[at + f2], composite) + pair(s.own[at + f2], body[f]);
            block[f2][f] = block[f][f2];
        }
    }
    tip.past.add_body::<BODIES>(l.m, l.centroid, &l.rotary);
    let torque = add(l.torque, cross(l.centroid, l.force));
    tip.wrench = (add(tip.wrench.0, torque), add(tip.wrench.1, l.force));
    (momentum, block, g)
}

/// The thread's scratch, out of the thread-local for the call (code in
/// `LocalKey::with`'s closure, or in any closure, may stay out of line,
/// not built for FMA like the generated caller); after checking the
/// output length. Put back with `SCRATCH.set`.
#[inline(always)]
fn take_scratch(layout: &LinkLayout, out: &[f64]) -> Scratch {
    let n = layout.dof;
    assert!(layout.links.iter().all(|l| l.map.len() <= MAX_LINK_DOF));
    assert_eq!(out.len(), n * (n + 1) / 2 + n, "MassBias output length");
    SCRATCH.take()
}

/// M (upper triangle, row by row) and h of a chain whose links own their
/// coordinates ([`all_owned`]: pcc, vc) into `out` (the `MassBias`
/// layout), by composite bodies from the tip: a link's rows of M are its
/// coordinates' twists against the momenta of the composite past it.
/// `cells` evaluates the links' cells ([`Cells`]); `BODIES` is the
/// layout's [`LinkLayout::general_bodies`], known where the call is
/// emitted. Inlined into its caller, which the generated code builds for
/// FMA.
#[inline(always)]
pub fn mass_bias_owned<C: Cells, const BODIES: bool>(
    layout: &LinkLayout,
    cells: &mut C,
    q: &[f64],
    qd: &[f64],
    p: &[f64],
    out: &mut [f64],
) {
    debug_assert!(all_owned(layout));
    match planar::covers(layout) {
        true => planar::mass_bias(layout, cells, q, qd, p, out),
        false => mass_bias_spatial::<C, BODIES>(layout, cells, q, qd, p, out),
    }
    if layout.loaded() {
        let n = layout.dof;
        subtract_loads(layout, cells, (q, qd, p), &mut out[n * (n + 1) / 2..]);
    }
}

/// [`mass_bias_owned`] in 3D; a planar chain's cells run here too (a
/// rotation about z), which the tests compare with `planar`'s sums.
#[inline(always)]
#[doc(hidden)] // white-box tests (tests/suite)
pub fn mass_bias_spatial<C: Cells, const BODIES: bool>(
    layout: &LinkLayout,
    cells: &mut C,
    q: &[f64],
    qd: &[f64],
    p: &[f64],
    out: &mut [f64],
) {
    let n = layout.dof;
    let mut scratch = take_scratch(layout, out);
    {
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
        let mut tip = forward::<C, BODIES>(layout, cells, p, s);
        s.momentum.resize(n, ([0.0; 3], [0.0; 3]));
        let (mass, bias) = out.split_at_mut(n * (n + 1) / 2);
        let index = |i: usize, j: usize| i * n - i * (i + 1) / 2 + j;
        for (k, spec) in layout.links.iter().enumerate().rev() {
            let (a, nc) = (s.start[k], spec.map.len());
            let (momentum, block, g) = link_sums::<BODIES>(s, k, nc, &mut tip);
            for f in 0..nc {
                bias[a + f] = g[f];
                for f2 in f..nc {
                    mass[index(a + f, a + f2)] = block[f][f2];
                }
                s.momentum[a + f] = momentum[f];
            }
        }
        // Coordinates of different links: twist . momentum, a row at a
        // time from the link after i's.
        for (k, spec) in layout.links.iter().enumerate() {
            let next = s.start[k] + spec.map.len();
            for i in s.start[k]..next {
                let row = &mut mass[index(i, next)..index(i, n)];
                for (m, &phi) in row.iter_mut().zip(&s.momentum[next..]) {
                    *m = pair(s.twist[i], phi);
                }
            }
        }
    }
    SCRATCH.set(scratch);
}

/// The link recursion for any layout, choosing as the generated code does
/// ([`all_owned`], [`padded`]); for tests and tools, not built for FMA.
pub fn mass_bias<C: Cells>(
    layout: &LinkLayout,
    cells: &mut C,
    q: &[f64],
    qd: &[f64],
    p: &[f64],
    out: &mut [f64],
) {
    match (all_owned(layout), layout.general_bodies()) {
        (true, true) => mass_bias_owned::<C, true>(layout, cells, q, qd, p, out),
        (true, false) => mass_bias_owned::<C, false>(layout, cells, q, qd, p, out),
        (false, _) => mass_bias_shared_dyn(layout, cells, q, qd, p, out),
    }
}

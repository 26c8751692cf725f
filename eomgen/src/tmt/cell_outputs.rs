//! What a link cell and its pose cell report, written once for 3D links
//! (`cell.rs`) and planar ones (`planar_cell.rs`): the layouts of
//! `runtime::links::cell` and `runtime::links::pose` filled from a link's
//! motion, and a tape's tangent form (`with_tangent`), which the eba parts
//! use too.

use runtime::Tape;
use runtime::links::{cell, pose};

use crate::cas::{Cas, ExprId, SymKind};

use super::spatial::{Frame, V3};

/// The tape of `out` followed by its directional derivative along (dx,
/// dxd) of the coordinates `x` and rates `xd` (`SymKind::Dir` symbols:
/// dx first, then dxd): what `runtime::links::tangent` runs the recursion
/// on in dual numbers. One tape, so the values and their derivatives share
/// subexpressions.
pub(crate) fn with_tangent(cas: &mut Cas, out: &[ExprId], x: &[ExprId], xd: &[ExprId]) -> Tape {
    let n = x.len();
    let mut along = Vec::with_capacity(2 * n);
    for (i, &v) in x.iter().chain(xd).enumerate() {
        let dir = cas.symbol(&format!("dir{i}"), SymKind::Dir(i as u32));
        along.push((v, dir));
    }
    debug_assert_eq!(along.len(), 2 * n);
    let mut all = out.to_vec();
    all.extend(cas.time_derivatives(out, &along));
    cas.to_tape(&all)
}

/// How a cell's rates are taken: by the rate rule of turned vectors (3D
/// frames, `Cas::kinematic_rates`) or by plain time derivatives (planar).
#[derive(Clone, Copy)]
pub(crate) enum Rates {
    Turned,
    Plain,
}

/// Where a link's end frame and body are, in its base frame at rest.
pub(crate) struct Motion {
    /// Rows of the end frame's rotation.
    pub rotation: [V3; 3],
    pub end: V3,
    /// The end frame's angular velocity.
    pub omega: V3,
    pub quat: [ExprId; 4],
    pub centroid: V3,
    pub body_omega: V3,
    /// The body's axis (its inertia is axisymmetric about it).
    pub axis: V3,
}

impl Motion {
    /// A link ending on the frame `end`, its body's centroid, angular
    /// velocity and axis.
    pub fn ending(end: &Frame, centroid: V3, body_omega: V3, axis: V3) -> Self {
        Motion {
            rotation: end.r,
            end: end.p,
            omega: end.w,
            quat: end.quat,
            centroid,
            body_omega,
            axis,
        }
    }
}

/// A link's motion with the rates and convective accelerations a cell
/// reports, its body's mass and inertias and its springs' energy: what a
/// cell (`runtime::links::cell`) and a pose cell (`runtime::links::pose`)
/// are written from, for 3D and planar links alike.
pub(crate) struct LinkKinematics {
    m: Motion,
    end_rate: V3,
    end_accel: V3,
    omega_rate: V3,
    centroid_rate: V3,
    centroid_accel: V3,
    body_omega_rate: V3,
    /// Mass, lateral and axial inertia, the springs' energy.
    body: [ExprId; 4],
    /// A body whose inertia is not axisymmetric: its y axis and its
    /// inertia about it (`runtime::links::cell::PRINCIPAL`).
    principal: Option<(V3, ExprId)>,
}

impl LinkKinematics {
    pub fn new(
        cas: &mut Cas,
        m: Motion,
        body: [ExprId; 4],
        q: &[ExprId],
        qd: &[ExprId],
        how: Rates,
    ) -> Self {
        let pairs: Vec<(ExprId, ExprId)> = q.iter().copied().zip(qd.iter().copied()).collect();
        let rates = |cas: &mut Cas, v: &V3| -> V3 {
            let r = match how {
                Rates::Turned => cas.kinematic_rates(v, &pairs),
                Rates::Plain => cas.time_derivatives(v, &pairs),
            };
            [r[0], r[1], r[2]]
        };
        let end_rate = rates(cas, &m.end);
        let end_accel = rates(cas, &end_rate);
        let omega_rate = rates(cas, &m.omega);
        let centroid_rate = rates(cas, &m.centroid);
        let centroid_accel = rates(cas, &centroid_rate);
        let body_omega_rate = rates(cas, &m.body_omega);
        Self {
            m,
            end_rate,
            end_accel,
            omega_rate,
            centroid_rate,
            centroid_accel,
            body_omega_rate,
            body,
            principal: None,
        }
    }

    /// The body's y axis and its inertia about it, reported after the
    /// rest where given.
    pub fn with_principal(self, principal: Option<(V3, ExprId)>) -> Self {
        Self { principal, ..self }
    }

    /// Appends the body's y axis and its inertia about it, where given.
    fn principal_into(&self, out: &mut Vec<ExprId>) {
        if let Some((y, lateral_y)) = self.principal {
            out.extend_from_slice(&y);
            out.push(lateral_y);
        }
    }

    /// The cell's outputs for coordinates `q` (rates `qd`): the columns,
    /// the generalised forces of the potential `elastic` (springs and
    /// actuators) and the Rayleigh function, and the inertia's derivatives
    /// in q (zero unless it changes with them: a planar arc's).
    pub fn cell(
        &self,
        cas: &mut Cas,
        q: &[ExprId],
        qd: &[ExprId],
        elastic: ExprId,
        rayleigh: ExprId,
    ) -> Vec<ExprId> {
        let m = &self.m;
        let zero = cas.zero();
        let n = q.len();
        let mut out = vec![zero; cell::len(n)];
        for i in 0..3 {
            out[cell::ROTATION + 3 * i..][..3].copy_from_slice(&m.rotation[i]);
        }
        for (at, v) in [
            (cell::END, m.end),
            (cell::END_RATE, self.end_rate),
            (cell::END_ACCEL, self.end_accel),
            (cell::OMEGA, m.omega),
            (cell::OMEGA_RATE, self.omega_rate),
            (cell::CENTROID, m.centroid),
            (cell::CENTROID_RATE, self.centroid_rate),
            (cell::CENTROID_ACCEL, self.centroid_accel),
            (cell::BODY_OMEGA, m.body_omega),
            (cell::BODY_OMEGA_RATE, self.body_omega_rate),
            (cell::AXIS, m.axis),
        ] {
            out[at..at + 3].copy_from_slice(&v);
        }
        let [mass, lateral, axial, _] = self.body;
        out[cell::MASS] = mass;
        out[cell::LATERAL] = lateral;
        out[cell::AXIAL] = axial;
        for c in 0..n {
            let col = cell::COLUMNS + 12 * c;
            let columns = [&m.omega, &self.end_rate, &m.body_omega, &self.centroid_rate];
            for (s, v) in columns.into_iter().enumerate() {
                for k in 0..3 {
                    out[col + 3 * s + k] = cas.diff(v[k], qd[c]);
                }
            }
            let de = cas.diff(elastic, q[c]);
            let dr = cas.diff(rayleigh, qd[c]);
            out[cell::forces(n) + c] = cas.add(de, dr);
            out[cell::inertia_rates(n) + c] = cas.diff(lateral, q[c]);
        }
        self.principal_into(&mut out);
        debug_assert_eq!(out.len(), cell::len_of(n, self.principal.is_some()));
        out
    }

    /// The pose cell's outputs.
    pub fn pose(&self, cas: &mut Cas) -> Vec<ExprId> {
        let m = &self.m;
        let zero = cas.zero();
        let mut out = vec![zero; pose::LEN];
        for i in 0..3 {
            out[pose::ROTATION + 3 * i..][..3].copy_from_slice(&m.rotation[i]);
        }
        for (at, v) in [
            (pose::END, m.end),
            (pose::END_RATE, self.end_rate),
            (pose::OMEGA, m.omega),
            (pose::CENTROID, m.centroid),
            (pose::CENTROID_RATE, self.centroid_rate),
            (pose::BODY_OMEGA, m.body_omega),
            (pose::AXIS, m.axis),
        ] {
            out[at..at + 3].copy_from_slice(&v);
        }
        let [mass, lateral, axial, stored] = self.body;
        out[pose::MASS] = mass;
        out[pose::LATERAL] = lateral;
        out[pose::AXIAL] = axial;
        out[pose::QUAT..pose::QUAT + 4].copy_from_slice(&m.quat);
        out[pose::ENERGY] = stored;
        self.principal_into(&mut out);
        debug_assert!(self.principal.is_none() || out.len() == pose::PRINCIPAL_LEN);
        out
    }
}

/// The cell, its tangent and its pose cell of a link of no coordinates and
/// no body (a kink) whose end frame moves as `motion`.
pub(crate) fn bodiless_cells(cas: &mut Cas, motion: Motion, rates: Rates) -> [Tape; 3] {
    let zero = cas.zero();
    let kin = LinkKinematics::new(cas, motion, [zero; 4], &[], &[], rates);
    let out = kin.cell(cas, &[], &[], zero, zero);
    let pose_out = kin.pose(cas);
    [
        cas.to_tape(&out),
        with_tangent(cas, &out, &[], &[]),
        cas.to_tape(&pose_out),
    ]
}

/// A cell's parameters as symbols p0, p1, ... (`runtime::links::CELL_PARAMS`
/// of them: its element's, its actuation loads, its rest strains).
pub(crate) fn cell_param_symbols(cas: &mut Cas) -> Vec<ExprId> {
    (0..runtime::links::CELL_PARAMS)
        .map(|i| cas.symbol(&format!("p{i}"), SymKind::Param(i as u32)))
        .collect()
}

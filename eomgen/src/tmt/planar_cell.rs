//! Link cells of planar chains: one element of a planar arm, placed by its
//! method (`place_planar`) on an arm at rest at the origin, written in the
//! 3D cell layout of `runtime::links` (a rotation about z), so that the
//! link recursion runs planar and spatial chains alike.
//!
//! A planar element's body may change its inertia with the bend (a pcc
//! arc's spread): the cell gives dI/dtheta and the layout says
//! `variable_inertia`. Elements of more than one body (rigid links with
//! midpoint joints) are not covered: their chains keep the flat kernels.

use runtime::Tape;
use runtime::links::{ACTUATION_LOADS, CELL_PARAMS, ELEMENT_PARAMS, cell, pose};

use crate::cas::{Cas, ExprId, SymKind};
use crate::model::SegmentShape;

use super::actuation::strain_work;
use super::inertia::Inertia;
use super::planar::{Element2, PlanarArm, half_k_sq};
use super::system::{Coordinates, ParamSymbols};

/// The cell, its tangent and its pose cell of one element of segment
/// shape `g` (with its segment's actuation loads when `actuated`), or None
/// when the element is not one body.
pub(super) fn derive_planar_cell(g: &SegmentShape, actuated: bool) -> Option<[Tape; 3]> {
    let mut cas = Cas::new();
    let cas = &mut cas;
    let coords = Coordinates::new(cas, vec!["theta".into()]);
    let (q, qd) = (coords.q[0], coords.qd[0]);
    let p: Vec<ExprId> = (0..CELL_PARAMS)
        .map(|i| cas.symbol(&format!("p{i}"), SymKind::Param(i as u32)))
        .collect();
    // In the order of `ElementParam::CELL`: a planar element reads the
    // first three and the bend spring; then the actuation loads.
    let el = Element2 {
        q,
        qd,
        l: p[0],
        m: p[1],
        inertia: p[2],
        stiff: p[4],
        damp: p[5],
        rest: p[6],
    };
    let loads: [ExprId; ACTUATION_LOADS] = std::array::from_fn(|i| p[ELEMENT_PARAMS + i]);
    // The element reads its own parameters only: an empty layout.
    let symbols = ParamSymbols::new(cas, &Default::default());
    let mut arm = PlanarArm::at_origin(cas, coords, &symbols);
    crate::method::of(g.method).place_planar(cas, &mut arm, g, &el);
    let [body] = arm.bodies() else {
        return None;
    };
    let Inertia::Isotropic(inertia) = body.inertia else {
        return None;
    };
    let (mass, centroid, body_w) = (body.mass, body.position, body.omega[2]);
    let f = arm.f;
    let zero = cas.zero();
    let one = cas.one();

    // The element's spring and damper (as `PlanarArm::end_element`) and the
    // actuators' work on its bend.
    let bend = cas.sub(q, el.rest);
    let stored = half_k_sq(cas, el.stiff, bend);
    let rayleigh = half_k_sq(cas, el.damp, qd);
    let elastic = if actuated {
        let work = strain_work(cas, loads, zero, [zero, zero, q], None);
        cas.sub(stored, work)
    } else {
        stored
    };

    let pairs = [(q, qd)];
    let rate = |cas: &mut Cas, v: &[ExprId; 3]| -> [ExprId; 3] {
        let r = cas.time_derivatives(v, &pairs);
        [r[0], r[1], r[2]]
    };
    let end = [f.x, f.y, zero];
    let end_rate = rate(cas, &end);
    let end_accel = rate(cas, &end_rate);
    let omega = [zero, zero, f.w];
    let omega_rate = rate(cas, &omega);
    let centroid = [centroid[0], centroid[1], zero];
    let centroid_rate = rate(cas, &centroid);
    let centroid_accel = rate(cas, &centroid_rate);
    let body_omega = [zero, zero, body_w];
    let body_omega_rate = rate(cas, &body_omega);
    let (c, s) = (cas.cos(f.phi), cas.sin(f.phi));
    let ns = cas.neg(s);
    let rotation = [[c, ns, zero], [s, c, zero], [zero, zero, one]];
    let axis = [one, zero, zero];

    let mut out = vec![zero; cell::len(1)];
    for i in 0..3 {
        for j in 0..3 {
            out[cell::ROTATION + 3 * i + j] = rotation[i][j];
        }
    }
    for (at, v) in [
        (cell::END, end),
        (cell::END_RATE, end_rate),
        (cell::END_ACCEL, end_accel),
        (cell::OMEGA, omega),
        (cell::OMEGA_RATE, omega_rate),
        (cell::CENTROID, centroid),
        (cell::CENTROID_RATE, centroid_rate),
        (cell::CENTROID_ACCEL, centroid_accel),
        (cell::BODY_OMEGA, body_omega),
        (cell::BODY_OMEGA_RATE, body_omega_rate),
        (cell::AXIS, axis),
    ] {
        out[at..at + 3].copy_from_slice(&v);
    }
    out[cell::MASS] = mass;
    out[cell::LATERAL] = inertia;
    out[cell::AXIAL] = inertia;
    let columns = [&omega, &end_rate, &body_omega, &centroid_rate];
    for (s, v) in columns.into_iter().enumerate() {
        for k in 0..3 {
            out[cell::COLUMNS + 3 * s + k] = cas.diff(v[k], qd);
        }
    }
    let de = cas.diff(elastic, q);
    let dr = cas.diff(rayleigh, qd);
    out[cell::forces(1)] = cas.add(de, dr);
    out[cell::inertia_rates(1)] = cas.diff(inertia, q);

    let mut pose_out = vec![zero; pose::LEN];
    for i in 0..3 {
        for j in 0..3 {
            pose_out[pose::ROTATION + 3 * i + j] = rotation[i][j];
        }
    }
    for (at, v) in [
        (pose::END, end),
        (pose::END_RATE, end_rate),
        (pose::OMEGA, omega),
        (pose::CENTROID, centroid),
        (pose::CENTROID_RATE, centroid_rate),
        (pose::BODY_OMEGA, body_omega),
        (pose::AXIS, axis),
    ] {
        pose_out[at..at + 3].copy_from_slice(&v);
    }
    pose_out[pose::MASS] = mass;
    pose_out[pose::LATERAL] = inertia;
    pose_out[pose::AXIAL] = inertia;
    let half = cas.scaled(0.5, f.phi);
    pose_out[pose::QUAT] = cas.cos(half);
    pose_out[pose::QUAT + 3] = cas.sin(half);
    pose_out[pose::ENERGY] = stored;
    Some([
        cas.to_tape(&out),
        super::cell::with_tangent(cas, &out, &[q], &[qd]),
        cas.to_tape(&pose_out),
    ])
}

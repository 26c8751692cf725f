//! Link cells of planar chains: one element of a planar arm, placed by its
//! method (`place_planar`) on an arm at rest at the origin, written in the
//! 3D cell layout of `runtime::links` (a rotation about z), so that the
//! link recursion runs planar and spatial chains alike.
//!
//! A planar element's body may change its inertia with the bend (a pcc
//! arc's spread): the cell gives dI/dtheta and the layout says
//! `variable_inertia`. A rigid element of a midpoint joint is two links,
//! each one body: its half before the joint (no coordinate) and the joint
//! with the half past it (`rigid::planar_half`). A kink is a link of no
//! coordinates and no body.

use runtime::Tape;
use runtime::links::{ACTUATION_LOADS, ELEMENT_PARAMS};

use crate::cas::{Cas, ExprId};
use crate::model::SegmentShape;

use crate::method::rigid::planar_half;
use crate::tmt::actuation::strain_work;
use crate::tmt::cell_outputs::{
    LinkKinematics, Motion, Rates, bodiless_cells, cell_param_symbols, with_tangent,
};
use crate::tmt::inertia::Inertia;
use crate::tmt::planar::{Element2, PlanarArm, half_k_sq};
use crate::tmt::system::{Coordinates, ParamSymbols};

/// What of a planar element a link is.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum PlanarPart {
    /// The element, placed by its method.
    Whole,
    /// A rigid element's half before its midpoint joint.
    BeforeJoint,
    /// That element's joint and the half past it.
    PastJoint,
}

/// The cell, its tangent and its pose cell of `part` of one element of
/// segment shape `g` (with its segment's actuation loads, zero where no
/// actuator acts), or None when it is not one body.
pub(super) fn derive_planar_cell(g: &SegmentShape, part: PlanarPart) -> Option<[Tape; 3]> {
    let mut cas = Cas::new();
    let cas = &mut cas;
    let names = match part {
        PlanarPart::BeforeJoint => Vec::new(),
        _ => vec!["theta".into()],
    };
    let coords = Coordinates::new(cas, names);
    let zero = cas.zero();
    let (q, qd) = (coords.q.first(), coords.qd.first());
    let (q, qd) = (q.copied().unwrap_or(zero), qd.copied().unwrap_or(zero));
    let (qs, qds) = (coords.q.clone(), coords.qd.clone());
    let p = cell_param_symbols(cas);
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
    match part {
        PlanarPart::Whole => crate::method::of(g.method).place_planar(cas, &mut arm, g, &el),
        _ => planar_half(cas, &mut arm, &el, part == PlanarPart::PastJoint),
    }
    let [body] = arm.bodies() else {
        return None;
    };
    let Inertia::Isotropic(inertia) = body.inertia else {
        return None;
    };
    let (mass, centroid, body_w) = (body.mass, body.position, body.omega[2]);
    let f = arm.f;
    let one = cas.one();

    // The element's spring and damper (as `PlanarArm::end_element`) and the
    // actuators' work on its bend; none on a half before a joint.
    let (stored, rayleigh, elastic) = match part {
        PlanarPart::BeforeJoint => (zero, zero, zero),
        _ => {
            let bend = cas.sub(q, el.rest);
            let stored = half_k_sq(cas, el.stiff, bend);
            let rayleigh = half_k_sq(cas, el.damp, qd);
            let work = strain_work(cas, loads, zero, [zero, zero, q], None);
            (stored, rayleigh, cas.sub(stored, work))
        }
    };

    let (c, s) = (cas.cos(f.phi), cas.sin(f.phi));
    let ns = cas.neg(s);
    let half = cas.scaled(0.5, f.phi);
    let quat = [cas.cos(half), zero, zero, cas.sin(half)];
    let kin = LinkKinematics::new(
        cas,
        Motion {
            rotation: [[c, ns, zero], [s, c, zero], [zero, zero, one]],
            end: [f.x, f.y, zero],
            omega: [zero, zero, f.w],
            quat,
            centroid: [centroid[0], centroid[1], zero],
            body_omega: [zero, zero, body_w],
            // Isotropic: any axis.
            axis: [one, zero, zero],
        },
        [mass, inertia, inertia, stored],
        &qs,
        &qds,
        Rates::Plain,
    );
    let out = kin.cell(cas, &qs, &qds, elastic, rayleigh);
    let pose_out = kin.pose(cas);
    Some([
        cas.to_tape(&out),
        with_tangent(cas, &out, &qs, &qds),
        cas.to_tape(&pose_out),
    ])
}

/// The cell of a planar kink: a link of no coordinates and no body whose
/// end frame is the kink's constant offset (x, y in the frame before it)
/// turned by its angle, as `PlanarArm::kink` moves the arm's frame; the
/// turn in the first parameter slot, the offset in the next two
/// (`build::cell`'s `kink_link`).
pub(super) fn derive_planar_kink_cell() -> [Tape; 3] {
    let mut cas = Cas::new();
    let cas = &mut cas;
    let p = cell_param_symbols(cas);
    let (zero, one) = (cas.zero(), cas.one());
    let turn = p[0];
    let (c, s) = (cas.cos(turn), cas.sin(turn));
    let ns = cas.neg(s);
    let half = cas.scaled(0.5, turn);
    let quat = [cas.cos(half), zero, zero, cas.sin(half)];
    let motion = Motion {
        rotation: [[c, ns, zero], [s, c, zero], [zero, zero, one]],
        end: [p[1], p[2], zero],
        omega: [zero; 3],
        quat,
        centroid: [zero; 3],
        body_omega: [zero; 3],
        axis: [one, zero, zero],
    };
    bodiless_cells(cas, motion, Rates::Plain)
}

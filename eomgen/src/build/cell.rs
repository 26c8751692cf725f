//! Link cells: one constant-strain link of a 3D chain derived on its own,
//! in its base frame at rest, for `runtime::links` to run in a loop.
//!
//! The cell is the arm's own arc (`spatial::arc`) under the identity frame:
//! its relative rotation and end point, the body's centroid, axis and
//! angular velocity, their rates and convective accelerations (qdd = 0),
//! the columns of the link's coordinates, and the link's elastic and
//! dissipative generalised forces, as one tape of the link's coordinates
//! and [`CELL_PARAMS`] parameters. Links of the same shape share a cell.
//!
//! Chains this covers: every segment of a method with link cells
//! (the method's `link_cells`), the base still or moved along a driven path
//! (not turned). Chambers and tendons load each element's strain by their
//! segment's loads (`actuation::segment_loads`: linear in the strain; an
//! element's own where its chamber levers vary along the segment), which
//! a small kernel of the parameters gives and the cells read as
//! parameters: every cell reads them, zero where no actuator acts, so
//! that an arm with chambers runs on a bare arm's cells. A rom segment's
//! slices are links whose cell coordinates are fixed combinations of the
//! segment's coefficients (`LocalCoordinate`); its strain energy,
//! integrated exactly over the segment, is one more small kernel
//! (`derive_forces`). Loads along the arm act at points on the links'
//! arcs (`runtime::links::AlongLoad`), where contact points are sampled;
//! driven forces on named coordinates (`[[torque]]`) go straight into h.
//! Other models keep the flat `MassBias` kernel.

use runtime::Tape;
use runtime::links::{
    ACTUATION_LOADS, AlongLoad, CELL_PARAMS, ContactElement, ContactPoint, Drag, DragPoint,
    ELEMENT_PARAMS, LinkKernels, LinkLayout, LinkSpec, LocalCoordinate, PRINCIPAL_PARAMS,
    REST_PARAMS,
};

use crate::cas::{Cas, ExprId, SymKind};
use crate::model::{
    Axis, ElementParam, FluidParam, Joints, KinkParam, LoadParam, Method, Param, ParamLayout, Rate,
    SegmentShape, Structure, Xyz,
};

use super::planar_cell::{PlanarPart, derive_planar_cell, derive_planar_kink_cell};
use crate::method::ebr::{before_joint, past_joint};
use crate::method::rigid::{JointSprings, RestTurn, joint_turn};
use crate::method::rom::RomFields;
use crate::tmt::actuation::{ActuationLoads, strain_work, thinning};
use crate::tmt::cell_kind::{CellKind, PointsOn};
use crate::tmt::cell_outputs::{
    LinkKinematics, Motion, Rates, bodiless_cells, cell_param_symbols, with_tangent,
};
use crate::tmt::spatial::{
    ArcStrain, Element3, Frame, M3, Springs, V3, advance, arc, compose, exp_turn, half_k_sq,
    mid_arc_rotation,
};
use crate::tmt::system::{Coordinates, ParamSymbols};

/// Chains of fewer links keep the flat `MassBias` and its symbolic solve:
/// the recursion's overhead is not paid back below four links (the lanes
/// take four at once). Measured on stiff_flop (two links, 8 DOF): right-hand
/// side 757 ns flat against 1039 ns by the recursion (BENCHMARKS.md).
const RECURSION_MIN_LINKS: usize = 4;

/// A planar chain's flat `MassBias` and symbolic solve are quicker than
/// its recursion (`runtime::links::planar`) below about thirty links: the
/// mass and bias of 8 rigid links take 175 against 367 ns, of 10 pcc
/// elements 457 against 757 ns, of 32 rigid links 1435 against 1444 ns
/// (BENCHMARKS.md), while the flat code grows with the square of the
/// links (chain32's: 125 kB). Compiled in, shorter planar chains keep it;
/// any planar chain not compiled in runs on the recursion over compiled
/// cells.
const PLANAR_RECURSION_MIN_LINKS: usize = 32;

impl Shape {
    /// No strain beyond bending, no rest shape: a kink's (whose cell reads
    /// none of it).
    fn bare() -> Self {
        Shape {
            rest_3d: false,
            principal: false,
            twist: false,
            extension: false,
            shear: false,
            incompressible: false,
            rom: false,
            planar: None,
            kind: CellKind::Arc,
        }
    }
}

/// The layout and kernels of a chain the link recursion covers, or `None`
/// when its structure is outside it. Compiled chains take every kernel
/// from it but, when shorter than [`RECURSION_MIN_LINKS`] (3D) or
/// [`PLANAR_RECURSION_MIN_LINKS`] (planar), `MassBias` (and the symbolic
/// solve on it), whose flat form is the quicker for their few links;
/// chains not compiled in take every kernel from it (linked cells).
pub fn link_chain(st: &Structure, params: &ParamLayout) -> Option<LinkKernels> {
    let spatial = st.dimensions == 3;
    if !covered(st) {
        return None;
    }
    let actuated = ActuationLoads::of(params, st);
    let mut cells: Vec<(Shape, [Tape; 3])> = Vec::new();
    let mut links = Vec::new();
    let mut roms = Vec::new();
    // Each element's links, where its points lie on their arcs.
    let mut element_links = Vec::new();
    let mut segment_ends = Vec::new();
    let (mut first, mut k) = (0, 0);
    for (s, g) in st.segments.iter().enumerate() {
        let method = crate::method::of(g.method);
        let rom = method.polynomial_fields().then(|| RomFields::of(g, first));
        let shape = Shape {
            rest_3d: g.rest_3d,
            principal: g.anisotropic,
            twist: g.twist,
            extension: g.extension,
            shear: g.shear,
            incompressible: g.incompressible,
            rom: rom.is_some(),
            planar: (!spatial).then_some((g.method, g.joints)),
            kind: method.cell_kind(g, spatial),
        };
        let mut cell_of = |shape: Shape| -> Option<usize> {
            if let Some(c) = cells.iter().position(|(s, _)| *s == shape) {
                return Some(c);
            }
            cells.push((shape, shape_cell(shape, g, spatial)?));
            Some(cells.len() - 1)
        };
        if g.kink {
            let kink = cell_of(Shape {
                kind: CellKind::Kink,
                ..Shape::bare()
            })?;
            links.push(kink_link(params, s, kink, spatial));
        }
        let c = cell_of(shape)?;
        // An ebr element's first half is a link of its own, before the
        // joint's.
        let before = (shape.kind.after_half())
            .then(|| {
                cell_of(Shape {
                    kind: CellKind::BeforeJoint,
                    ..shape
                })
            })
            .flatten();
        let count = if spatial { g.coordinates_3d() } else { 1 };
        for e in 0..g.elements {
            // The loads of its segment, or of the element itself.
            let load = actuated.find(s, k);
            let displaced = displaced_volume(st, params, k);
            let principal = g.anisotropic.then(|| principal_params(params, k));
            let params = cell_slots(params, k);
            let maps = coordinate_maps(rom.as_ref(), e, count, first, params[0], shape.kind);
            // The element's links, its half before a joint included.
            let own = links.len()..links.len() + usize::from(before.is_some()) + maps.len();
            if let Some(b) = before {
                links.push(LinkSpec {
                    cell: b,
                    map: Vec::new(),
                    params: params.clone(),
                    load: None,
                    displaced,
                    principal,
                });
            }
            for map in maps {
                links.push(LinkSpec {
                    cell: c,
                    map,
                    params: params.clone(),
                    load,
                    displaced,
                    principal,
                });
            }
            // An inextensible, unshearable centreline is its element's
            // length long: the broad phase's bound.
            let length = (!g.extension && !g.shear).then_some(params[0]);
            let on = method.points_on_links(g, spatial);
            element_links.push(on.map(|on| ElementLinks {
                links: own,
                on,
                length,
            }));
            if rom.is_none() {
                first += count;
            }
            k += 1;
        }
        if let Some(r) = rom {
            first += r.coordinates();
            roms.push((r, k - g.elements));
        }
        segment_ends.push(links.len() - 1);
    }
    let contact = contact_points(&element_links, st.contact_points);
    let contact_elements = contact_elements(&element_links, &contact);
    let along = along_loads(st, params, &element_links)?;
    let drag = fluid_drag(st, params, &element_links)?;
    let layout = LinkLayout {
        drag,
        links,
        contact,
        contact_elements,
        along,
        segment_ends,
        dof: first,
        forces: !roms.is_empty(),
        loads: actuated.owners.len(),
        ..globals(st, params)
    };
    let forces = (!roms.is_empty()).then(|| derive_forces(params, first, &roms));
    let [forces, forces_tangent, energy] = match forces {
        Some(kernels) => kernels.map(Some),
        None => [None, None, None],
    };
    let min_links = match spatial {
        true => RECURSION_MIN_LINKS,
        false => PLANAR_RECURSION_MIN_LINKS,
    };
    let mass_bias = layout.links.len() >= min_links;
    let mut kernels = LinkKernels {
        layout,
        mass_bias,
        forces,
        forces_tangent,
        energy,
        loads: actuated.tape,
        ..Default::default()
    };
    for (_, [cell, tangent, pose]) in cells {
        kernels.cells.push(cell);
        kernels.tangents.push(tangent);
        kernels.poses.push(pose);
    }
    Some(kernels)
}

/// The cell of a link of `shape` in segment `g` (its three tapes), None
/// where no cell expresses it.
fn shape_cell(shape: Shape, g: &SegmentShape, spatial: bool) -> Option<[Tape; 3]> {
    Some(match (spatial, shape.kind) {
        (true, _) => derive_cell(shape),
        (false, CellKind::Kink) => derive_planar_kink_cell(),
        (false, CellKind::BeforeJoint) => derive_planar_cell(g, PlanarPart::BeforeJoint)?,
        (false, kind) if kind.after_half() => derive_planar_cell(g, PlanarPart::PastJoint)?,
        (false, _) => derive_planar_cell(g, PlanarPart::Whole)?,
    })
}

/// The slot of the volume element k displaces, where the arm is immersed:
/// its bodies' buoyancy (`runtime::links::link_gravity`).
fn displaced_volume(st: &Structure, params: &ParamLayout, k: usize) -> Option<usize> {
    (st.fluid.is_some()).then(|| params.index(Param::Element(k, ElementParam::Volume)))
}

/// The slots of element k's cell parameters (`ElementParam::CELL`, then
/// `REST_3D`); a planar cell reads no spatial parameter, and a cell
/// without a rest shape none of its: their slots repeat the length's.
fn cell_slots(params: &ParamLayout, k: usize) -> Vec<usize> {
    let length = params.index(Param::Element(k, ElementParam::Length));
    (ElementParam::CELL.iter())
        .chain(&ElementParam::REST_3D)
        .map(|&e| params.get(Param::Element(k, e)).unwrap_or(length))
        .collect()
}

/// The slots of element k's `ElementParam::ANISOTROPIC` parameters, each
/// its axisymmetric counterpart's where the element has none (as
/// `SpatialArm::element` and `strain_element` read them); a shear
/// stiffness the element lacks, its length's (a cell without shear reads
/// none).
fn principal_params(params: &ParamLayout, k: usize) -> [usize; PRINCIPAL_PARAMS] {
    let slot = |e: ElementParam| params.get(Param::Element(k, e));
    let length = params.index(Param::Element(k, ElementParam::Length));
    let fallback = [
        ElementParam::BendStiffness,
        ElementParam::Inertia,
        ElementParam::ShearStiffness,
    ];
    std::array::from_fn(|i| {
        (slot(ElementParam::ANISOTROPIC[i]))
            .or_else(|| slot(fallback[i]))
            .unwrap_or(length)
    })
}

/// Whether the recursion may cover the structure, its elements' cells
/// permitting (a planar element is covered when it is one body:
/// `planar_cell`).
fn covered(st: &Structure) -> bool {
    let spatial = st.dimensions == 3;
    !spatial || (st.segments.iter()).all(|g| crate::method::of(g.method).link_cells())
}

/// The chain's contact points (`points` an element, at s = 1/points, ...,
/// 1 along it) on the links of each element: an element of one link at
/// s along it, one of two halves (a half-arc pcc element, a rom slice) on
/// the first at 2 s up to its middle, else on the second at 2 s - 1, as the
/// methods sample them, in the links' order. Empty without contact or
/// where an element's points are not on its links' arcs: its contact
/// kernels are then its tapes'.
fn contact_points(elements: &[Option<ElementLinks>], points: usize) -> Vec<ContactPoint> {
    let mut out = Vec::with_capacity(elements.len() * points);
    for element in elements {
        let Some(links) = element else {
            return Vec::new();
        };
        for j in 1..=points {
            match on_links(links, j as f64 / points as f64) {
                Some(point) => out.push(point),
                None => return Vec::new(),
            }
        }
    }
    out
}

/// An element's links, where its points lie on them: how they lie, and
/// the parameter of its centreline's length where that is fixed.
struct ElementLinks {
    links: std::ops::Range<usize>,
    on: PointsOn,
    length: Option<usize>,
}

/// The point at the fraction `s` of an element on its links, as the
/// methods sample it: an element of one link at s along it, one of two
/// halves (a half-arc pcc element, a rom slice, a rigid element's halves
/// about a midpoint joint) on the first at 2 s up to its middle, else on
/// the second at 2 s - 1.
fn on_links(element: &ElementLinks, s: f64) -> Option<ContactPoint> {
    let links = &element.links;
    let straight = element.on == PointsOn::Straight;
    let on = |link: usize, at: f64| ContactPoint { link, at, straight };
    match links.len() {
        1 => Some(on(links.start, s)),
        2 if s <= 0.5 => Some(on(links.start, 2.0 * s)),
        2 => Some(on(links.start + 1, 2.0 * s - 1.0)),
        _ => None,
    }
}

/// The structure's loads along the arm at their points on the links, in
/// the links' order, as `tmt::along` places them (a force per unit length
/// at every element's middle, times its length); None where an element a
/// load acts on has no points on its links' arcs.
fn along_loads(
    st: &Structure,
    params: &ParamLayout,
    elements: &[Option<ElementLinks>],
) -> Option<Vec<AlongLoad>> {
    let mut out = Vec::new();
    for (i, l) in st.loads.iter().enumerate() {
        let slots = |given: bool, what: fn(Xyz) -> LoadParam| {
            given.then(|| Xyz::ALL.map(|c| params.index(Param::Load(i, what(c)))))
        };
        let (force, moment) = (
            slots(l.force, LoadParam::Force),
            slots(l.moment, LoadParam::Moment),
        );
        let place = |k: usize, s: f64| on_links(elements.get(k)?.as_ref()?, s);
        match l.at {
            Some((k, bits)) => out.push(AlongLoad {
                at: place(k, f64::from_bits(bits))?,
                force,
                moment,
                local: l.local,
                per_length: None,
            }),
            None => {
                let first: usize = st.segments[..l.segment].iter().map(|g| g.elements).sum();
                for k in first..first + st.segments[l.segment].elements {
                    out.push(AlongLoad {
                        at: place(k, 0.5)?,
                        force,
                        moment: None,
                        local: l.local,
                        per_length: Some(params.index(Param::Element(k, ElementParam::Length))),
                    });
                }
            }
        }
    }
    out.sort_by_key(|l| l.at.link);
    Some(out)
}

/// An immersed arm's drag at its elements' middles, as `tmt::along`
/// places it; `Some(None)` where it does not drag, None where a middle is
/// not on its links' arcs.
fn fluid_drag(
    st: &Structure,
    params: &ParamLayout,
    elements: &[Option<ElementLinks>],
) -> Option<Option<Drag>> {
    if st.fluid != Some(true) {
        return Some(None);
    }
    let fluid = |f| params.index(Param::Fluid(f));
    let element = |k, e| params.index(Param::Element(k, e));
    let points = (elements.iter().enumerate())
        .map(|(k, links)| {
            Some(DragPoint {
                at: on_links(links.as_ref()?, 0.5)?,
                width: element(k, ElementParam::Width),
                length: element(k, ElementParam::Length),
            })
        })
        .collect::<Option<Vec<_>>>()?;
    Some(Some(Drag {
        density: fluid(FluidParam::Density),
        normal: fluid(FluidParam::DragNormal),
        tangential: fluid(FluidParam::DragTangential),
        current: Xyz::ALL.map(|c| fluid(FluidParam::Current(c))),
        points,
    }))
}

/// The elements the contact points are on (none without them): their
/// first and last links and their centreline's length where it is fixed.
fn contact_elements(
    elements: &[Option<ElementLinks>],
    points: &[ContactPoint],
) -> Vec<ContactElement> {
    if points.is_empty() {
        return Vec::new();
    }
    (elements.iter().flatten())
        .map(|e| ContactElement {
            first: e.links.start,
            last: e.links.end - 1,
            length: e.length,
        })
        .collect()
}

/// Segment s's kink as a link of no coordinates before it, of cell
/// `cell`: the kink's constant turn (about y, z; in the plane its angle)
/// and offset in the cell's first parameter slots.
fn kink_link(params: &ParamLayout, s: usize, cell: usize, spatial: bool) -> LinkSpec {
    let index = |p: Param| params.index(p);
    let turns = if spatial { 2 } else { 1 };
    let turn: Vec<usize> = (0..turns)
        .map(|i| index(Param::Kink(s, KinkParam::Turn(i))))
        .collect();
    let offset = Xyz::ALL.map(|c| index(Param::Kink(s, KinkParam::Offset(c))));
    let slots = ElementParam::CELL.len() + ElementParam::REST_3D.len();
    let mut params: Vec<usize> = turn.iter().copied().chain(offset).collect();
    params.resize(slots, turn[0]);
    LinkSpec {
        cell,
        map: Vec::new(),
        params,
        load: None,
        displaced: None,
        principal: None,
    }
}

/// The arm's coordinates each link of element `e` reads, as its cell's
/// coordinates: a half-arc of a rom slice reads field f by the half's
/// weights (stretch and shear, strains, times the segment's length in slot
/// `length`); another element its own `count` coordinates from `first`, on
/// both links of a half-arc element.
fn coordinate_maps(
    rom: Option<&RomFields>,
    e: usize,
    count: usize,
    first: usize,
    length: usize,
    kind: CellKind,
) -> Vec<Vec<LocalCoordinate>> {
    match rom {
        Some(r) => r
            .halves(e)
            .iter()
            .map(|w| {
                (0..count)
                    .map(|f| {
                        let stretch = r.is_translation(f);
                        let n = if stretch { r.slices as f64 } else { 1.0 };
                        LocalCoordinate {
                            terms: w
                                .iter()
                                .enumerate()
                                .map(|(i, w)| (r.index(f, i), n * w))
                                .collect(),
                            scale: stretch.then_some(length),
                        }
                    })
                    .collect()
            })
            .collect(),
        None => {
            let map: Vec<LocalCoordinate> = (0..count)
                .map(|f| LocalCoordinate {
                    terms: vec![(first + f, 1.0)],
                    scale: None,
                })
                .collect();
            // A half-arc element is two links on the same
            // coordinates.
            match kind {
                CellKind::HalfArc => vec![map.clone(), map],
                _ => vec![map],
            }
        }
    }
}

/// Where a chain's gravity, base, tip body and tip loads are in the
/// parameter vector (its links, coordinates and kernels left empty).
fn globals(st: &Structure, params: &ParamLayout) -> LinkLayout {
    let spatial = st.dimensions == 3;
    let index = |p: Param| params.index(p);
    let triple = |p: fn(Xyz) -> Param| Xyz::ALL.map(|c| index(p(c)));
    LinkLayout {
        gravity: triple(Param::Gravity),
        base_position: triple(Param::BasePosition),
        fluid_density: st
            .fluid
            .is_some()
            .then(|| index(Param::Fluid(FluidParam::Density))),
        base_translation: st
            .base_translates
            .then(|| Rate::ALL.map(|r| Xyz::ALL.map(|c| index(Param::BaseTranslation(r, c))))),
        base_turns: (0..st.base_turns)
            .map(|i| runtime::links::BaseTurn {
                angle: Rate::ALL.map(|r| index(Param::BaseTurn(r, i))),
                axis: spatial.then(|| Xyz::ALL.map(|c| index(Param::BaseTurnAxis(i, c)))),
            })
            .collect(),
        base_rotation: match spatial {
            true => {
                std::array::from_fn(|i| index(Param::BaseRotation((i / 3) as u8, (i % 3) as u8)))
            }
            false => [0; 9],
        },
        base_quaternion: match spatial {
            true => std::array::from_fn(|i| index(Param::BaseQuaternion(i as u8))),
            false => [0; 4],
        },
        base_angle: (!spatial).then(|| index(Param::BaseAngle)),
        variable_inertia: !spatial,
        tip_force: st.tip_force.then(|| triple(Param::TipForce)),
        tip_moment: st.tip_moment.then(|| triple(Param::TipMoment)),
        tip_frame: st.tip_frame_wrench,
        tip_mass: st.tip_mass.then(|| index(Param::TipMass)),
        tip_length: st.tip_length.then(|| index(Param::TipLength)),
        tip_inertia: (st.tip_mass && st.tip_length)
            .then(|| [index(Param::TipInertia), index(Param::TipAxialInertia)]),
        torques: coordinate_torques(st, params),
        ..Default::default()
    }
}

/// The driven forces on named coordinates: each coordinate's index among
/// the arm's (the flat kernels' order) and its value's slot.
fn coordinate_torques(st: &Structure, params: &ParamLayout) -> Vec<[usize; 2]> {
    if st.torques.is_empty() {
        return Vec::new();
    }
    let names = crate::method::coordinate_names(st);
    (st.torques.iter().enumerate())
        .map(|(i, name)| {
            // Validation checked the name against the coordinates.
            let k = (names.iter().position(|n| n == name)).expect("validated coordinate name");
            [k, params.index(Param::Torque(i))]
        })
        .collect()
}

/// What a cell depends on besides its parameters' values.
#[derive(Clone, Copy, PartialEq, Eq)]
struct Shape {
    /// It reads a rest bend about y, twist and stretch.
    rest_3d: bool,
    /// Its section bends unequally about y and z: it reads
    /// `runtime::links::PRINCIPAL_PARAMS` and reports its body's y axis.
    principal: bool,
    twist: bool,
    extension: bool,
    shear: bool,
    incompressible: bool,
    /// A rom slice: the segment's stretch and damping are integrated over
    /// the whole segment (`derive_forces`), and its bending and twist too
    /// unless the section thins, when they go slice by slice as here.
    rom: bool,
    /// A planar element of this method and joint placement
    /// (`planar_cell`).
    planar: Option<(Method, Joints)>,
    /// What the link is of a 3D element.
    kind: CellKind,
}

/// The generalised forces of the rom segments' strain energy and Rayleigh
/// function (`RomFields::energies`, exact quadratics in the coefficients), as one
/// kernel of the arm's coordinates and parameters; that kernel's
/// [`with_tangent`]; and the strain energy (for the `Outputs`).
fn derive_forces(params: &ParamLayout, dof: usize, roms: &[(RomFields, usize)]) -> [Tape; 3] {
    let mut cas = Cas::new();
    let cas = &mut cas;
    let symbols = ParamSymbols::new(cas, params);
    let coords = Coordinates::new(cas, (0..dof).map(|i| format!("q{i}")).collect());
    let mut elastic = Vec::new();
    let mut rayleigh = Vec::new();
    for (r, k) in roms {
        let [e, d] = r.energies(cas, &coords, &symbols, *k);
        elastic.push(e);
        rayleigh.push(d);
    }
    let elastic = cas.add_all(&elastic);
    let rayleigh = cas.add_all(&rayleigh);
    let out: Vec<ExprId> = (0..dof)
        .map(|i| {
            let de = cas.diff(elastic, coords.q[i]);
            let dr = cas.diff(rayleigh, coords.qd[i]);
            cas.add(de, dr)
        })
        .collect();
    [
        cas.to_tape(&out),
        with_tangent(cas, &out, &coords.q, &coords.qd),
        cas.to_tape(&[elastic]),
    ]
}

/// A cell's coordinates: the bend pair, then twist, stretch and the shear
/// pair where present; none for an ebr element's half before its joint.
fn cell_coordinates(
    twist: bool,
    extension: bool,
    shear: bool,
    kind: CellKind,
) -> Vec<&'static str> {
    match kind {
        CellKind::BeforeJoint => return Vec::new(),
        CellKind::Revolute { axes, .. } => {
            let turns = ["turn_0", "turn_1", "turn_2"];
            return turns
                .into_iter()
                .zip(axes.iter().flatten())
                .map(|(n, _)| n)
                .collect();
        }
        _ => {}
    }
    let mut names = vec!["bend_y", "bend_z"];
    if twist {
        names.push("twist");
    }
    if extension {
        names.push("stretch");
    }
    if shear {
        names.extend(["shear_y", "shear_z"]);
    }
    names
}

/// A cell's springs and dampers from its parameters (bend, its damping,
/// rest curvature, twist, its damping, stretch, its damping): a rom slice
/// keeps only what thinning makes local, the rest is its segment's
/// (`derive_forces`).
fn cell_springs(
    rom: bool,
    incompressible: bool,
    zero: ExprId,
    k: [ExprId; 8],
    [rest_y, rest_twist, rest_stretch]: [ExprId; REST_PARAMS],
) -> Springs {
    let [kb, kb_y, db, rest, kt, dt, ks, ds] = k;
    if rom {
        let local = |k: ExprId| if incompressible { k } else { zero };
        Springs {
            bend: local(kb),
            bend_y: local(kb_y),
            bend_damping: zero,
            rest: [local(rest_y), local(rest)],
            twist: local(kt),
            twist_damping: zero,
            rest_twist: local(rest_twist),
            stretch: zero,
            stretch_damping: zero,
            rest_stretch: zero,
        }
    } else {
        Springs {
            bend: kb,
            bend_y: kb_y,
            bend_damping: db,
            rest: [rest_y, rest],
            twist: kt,
            twist_damping: dt,
            rest_twist,
            stretch: ks,
            stretch_damping: ds,
            rest_stretch,
        }
    }
}

/// A link's strain as its cell reads it: the rotation vector and its
/// rate, the centreline's length, the shear pair, the stretch.
struct LinkStrain {
    rho: V3,
    rate: V3,
    len: ExprId,
    shear: Option<[ExprId; 2]>,
    st: ExprId,
}

/// A link's motion from the identity frame by its kind: its body's
/// centroid, axis and angular velocity, its end frame and its body (an arc,
/// half an arc, or an ebr element's half before or past its joint), and
/// where `principal` its body's y axis (a principal axis of an anisotropic
/// section's inertia: `Element3::body`).
fn link_motion(
    cas: &mut Cas,
    (kind, principal): (CellKind, bool),
    identity: &Frame,
    element: Element3,
    half_m: ExprId,
    s: LinkStrain,
) -> (V3, V3, V3, Frame, Element3, Option<V3>) {
    let y_of = |r: M3| principal.then(|| [r[0][1], r[1][1], r[2][1]]);
    match kind {
        CellKind::Arc | CellKind::HalfArc => {
            let strain = ArcStrain {
                rho: s.rho,
                rate: s.rate,
                len: s.len,
                shear: s.shear,
            };
            let (strain, body) = match kind {
                CellKind::HalfArc => (strain.part(cas, 0.5), element.half(cas)),
                _ => (strain, element),
            };
            let (c, a, w, end) = arc(cas, identity, &strain);
            let y = principal.then(|| mid_arc_rotation(identity, &strain)(cas));
            (c, a, w, end, body, y.and_then(y_of))
        }
        CellKind::BeforeJoint => {
            let (quarter, half) = (cas.scaled(0.25, element.l), cas.scaled(0.5, element.l));
            let (c, end) = before_joint(cas, identity, quarter, half);
            let body = Element3 {
                m: half_m,
                ..element
            };
            (c, identity.axis(), identity.w, end, body, y_of(identity.r))
        }
        CellKind::PastJoint => {
            let half = cas.scaled(0.5, element.l);
            let (c, joint, end) = past_joint(cas, identity, &s.rho, &s.rate, half, s.st);
            let (a, w) = (joint.axis(), joint.w);
            let body = Element3 {
                m: half_m,
                ..element
            };
            (c, a, w, end, body, y_of(joint.r))
        }
        CellKind::Kink => unreachable!("a kink's cell is `derive_kink_cell`"),
        CellKind::Revolute { .. } => unreachable!("a joint's cell is `derive_revolute_cell`"),
    }
}

/// The cell of a link with the bend pair, and twist, stretch and the shear
/// pair when asked;
/// the cell [`with_tangent`]; and its pose cell (`runtime::links::pose`:
/// what the `Outputs` need of the link).
fn derive_cell(shape: Shape) -> [Tape; 3] {
    match shape.kind {
        CellKind::Kink => return derive_kink_cell(),
        CellKind::Revolute { axes, whole } => return derive_revolute_cell(shape, axes, whole),
        _ => {}
    }
    let Shape {
        twist,
        extension,
        shear,
        incompressible,
        rom,
        kind,
        rest_3d,
        ..
    } = shape;
    let mut cas = Cas::new();
    let cas = &mut cas;
    let names = cell_coordinates(twist, extension, shear, kind);
    let q: Vec<ExprId> = (0..names.len())
        .map(|i| cas.symbol(names[i], SymKind::Q(i as u32)))
        .collect();
    let qd: Vec<ExprId> = (0..names.len())
        .map(|i| cas.symbol(&format!("{}_dot", names[i]), SymKind::Qd(i as u32)))
        .collect();
    let p = cell_param_symbols(cas);
    // In the order of `ElementParam::CELL`, then the actuation loads.
    let [l, m, lateral, axial, kb, db, rest, kt, dt, ks, ds, kg] = std::array::from_fn(|i| p[i]);
    // A section that bends unequally: its bend stiffness about y, inertia
    // about y and shear stiffness along z, last.
    let [kb_y, lateral_y, kg_z] = match shape.principal {
        true => std::array::from_fn(|i| p[CELL_PARAMS - PRINCIPAL_PARAMS + i]),
        false => [kb, lateral, kg],
    };
    let loads: [ExprId; ACTUATION_LOADS] = std::array::from_fn(|i| p[ELEMENT_PARAMS + i]);
    let zero = cas.zero();
    let rests: [ExprId; REST_PARAMS] = match rest_3d {
        true => std::array::from_fn(|i| p[ELEMENT_PARAMS + ACTUATION_LOADS + i]),
        false => [zero; REST_PARAMS],
    };
    // Coordinates bend y, bend z, then twist and stretch where present.
    let mut strain = [zero; 4];
    let mut rates = [zero; 4];
    let slots = [Some(0), Some(1), twist.then_some(2), extension.then_some(3)];
    for (i, k) in slots.into_iter().flatten().take(q.len()).enumerate() {
        strain[k] = q[i];
        rates[k] = qd[i];
    }
    let [by, bz, tw, st] = strain;
    let [by_d, bz_d, tw_d, _] = rates;
    // Then the shear pair, last.
    let first_shear = 2 + usize::from(twist) + usize::from(extension);
    let shear_at = (shear && kind != CellKind::BeforeJoint).then_some(first_shear);
    // A rom slice's shear energy is its segment's (`derive_forces`).
    let shear_springs = shear_at.filter(|_| !rom);

    // The link's potential and Rayleigh function, as the whole arm has them.
    let len = cas.add(l, st);
    let thin = incompressible.then(|| thinning(cas, l, len));
    let soft = thin.map(|t| t.0);
    let springs = cell_springs(
        rom,
        incompressible,
        zero,
        [kb, kb_y, db, rest, kt, dt, ks, ds],
        rests,
    );
    let (mut elastic, mut rayleigh) = match kind {
        CellKind::BeforeJoint => (zero, zero),
        _ => springs.energies(cas, strain, rates, soft),
    };
    if let Some(i) = shear_springs {
        // As `SpatialArm::strain_element` has them: k G A / l springs, the
        // rates damped as the stretch's.
        let (y, z) = ((q[i], qd[i]), (q[i + 1], qd[i + 1]));
        let terms = [elastic, half_k_sq(cas, kg, y.0), half_k_sq(cas, kg_z, z.0)];
        elastic = cas.add_all(&terms);
        let terms = [rayleigh, half_k_sq(cas, ds, y.1), half_k_sq(cas, ds, z.1)];
        rayleigh = cas.add_all(&terms);
    }
    // The actuators' potential on the link's strain, as the whole arm has
    // it (the outputs' potential energy is the strain energy alone).
    let stored = elastic;
    // Every cell reads its segment's loads (zero where no actuator acts),
    // so that an actuated arm and a bare one share their cells.
    let work = strain_work(cas, loads, st, [tw, by, bz], thin.map(|t| t.1));
    let elastic = cas.sub(elastic, work);
    // Each half of a half-arc element carries half its energies.
    let share = |cas: &mut Cas, e: ExprId| match kind {
        CellKind::HalfArc => cas.scaled(0.5, e),
        _ => e,
    };
    let (stored, elastic, rayleigh) = (
        share(cas, stored),
        share(cas, elastic),
        share(cas, rayleigh),
    );

    let identity = Frame::at_rest(cas, [zero; 3]);
    let rho = [tw, by, bz];
    let rate = [tw_d, by_d, bz_d];
    let half_m = cas.scaled(0.5, m);
    let element = Element3 {
        lateral_y,
        ..Element3::axisymmetric(l, m, lateral, axial)
    };
    let shear = shear_at.map(|i| [q[i], q[i + 1]]);
    let (centroid, axis, omega, end, body, y_axis) = link_motion(
        cas,
        (kind, shape.principal),
        &identity,
        element,
        half_m,
        LinkStrain {
            rho,
            rate,
            len,
            shear,
            st,
        },
    );
    let kin = LinkKinematics::new(
        cas,
        Motion::ending(&end, centroid, omega, axis),
        [body.m, body.lateral, body.axial, stored],
        &q,
        &qd,
        Rates::Turned,
    )
    .with_principal(y_axis.map(|y| (y, body.lateral_y)));
    let out = kin.cell(cas, &q, &qd, elastic, rayleigh);
    let pose_out = kin.pose(cas);
    [
        cas.to_tape(&out),
        with_tangent(cas, &out, &q, &qd),
        cas.to_tape(&pose_out),
    ]
}

/// A rigid element's joint cell ([`CellKind::Revolute`]): the joint's turn
/// from the identity frame (`rigid::joint_turn`, its springs and dampers),
/// then the straight link of the whole element (`whole`) or of its half
/// past the joint, its body at its middle, as `method::rigid` builds the
/// arm's.
fn derive_revolute_cell(shape: Shape, axes: [Option<Axis>; 3], whole: bool) -> [Tape; 3] {
    let mut cas = Cas::new();
    let cas = &mut cas;
    let axes: Vec<Axis> = axes.into_iter().flatten().collect();
    let names = cell_coordinates(false, false, false, shape.kind);
    let q: Vec<ExprId> = (0..names.len())
        .map(|i| cas.symbol(names[i], SymKind::Q(i as u32)))
        .collect();
    let qd: Vec<ExprId> = (0..names.len())
        .map(|i| cas.symbol(&format!("{}_dot", names[i]), SymKind::Qd(i as u32)))
        .collect();
    let p = cell_param_symbols(cas);
    // In the order of `ElementParam::CELL`, then the actuation loads.
    let [l, m, lateral, axial, kb, db, rest, kt] = std::array::from_fn(|i| p[i]);
    let [kb_y, lateral_y] = match shape.principal {
        true => std::array::from_fn(|i| p[CELL_PARAMS - PRINCIPAL_PARAMS + i]),
        false => [kb, lateral],
    };
    let loads: [ExprId; ACTUATION_LOADS] = std::array::from_fn(|i| p[ELEMENT_PARAMS + i]);
    let [rest_y, rest_twist, _]: [ExprId; REST_PARAMS] =
        std::array::from_fn(|i| p[ELEMENT_PARAMS + ACTUATION_LOADS + i]);
    let rest = match shape.rest_3d {
        true => RestTurn::Vector([rest_twist, rest_y, rest]),
        false => RestTurn::AboutZ(rest),
    };
    let springs = JointSprings {
        twist: kt,
        bend_y: kb_y,
        bend: kb,
        damping: db,
    };
    let zero = cas.zero();
    let identity = Frame::at_rest(cas, [zero; 3]);
    let angles: Vec<(ExprId, ExprId)> = q.iter().copied().zip(qd.iter().copied()).collect();
    let turn = joint_turn(cas, &identity, (&axes, &angles), rest, springs);
    let stored = cas.add_all(&turn.elastic);
    let rayleigh = cas.add_all(&turn.rayleigh);
    let work = strain_work(cas, loads, zero, turn.rho, None);
    let elastic = cas.sub(stored, work);
    let (length, mass) = match whole {
        true => (l, m),
        false => (cas.scaled(0.5, l), cas.scaled(0.5, m)),
    };
    let joint = turn.frame;
    let middle = cas.scaled(0.5, length);
    let centroid = advance(cas, &joint, middle).p;
    let end = advance(cas, &joint, length);
    let y = [joint.r[0][1], joint.r[1][1], joint.r[2][1]];
    let kin = LinkKinematics::new(
        cas,
        Motion::ending(&end, centroid, joint.w, joint.axis()),
        [mass, lateral, axial, stored],
        &q,
        &qd,
        Rates::Turned,
    )
    .with_principal(shape.principal.then_some((y, lateral_y)));
    let out = kin.cell(cas, &q, &qd, elastic, rayleigh);
    let pose_out = kin.pose(cas);
    [
        cas.to_tape(&out),
        with_tangent(cas, &out, &q, &qd),
        cas.to_tape(&pose_out),
    ]
}

/// A kink's cell: no coordinates, no body, the frame moved by its offset
/// (parameter slots 2 to 4, in the frame) and turned by the rotation
/// vector (0, slot 0, slot 1), as `SpatialArm::kink` moves the arm's.
fn derive_kink_cell() -> [Tape; 3] {
    let mut cas = Cas::new();
    let cas = &mut cas;
    let p = cell_param_symbols(cas);
    let (zero, one) = (cas.zero(), cas.one());
    let identity = Frame::at_rest(cas, [zero; 3]);
    let turn = [zero, p[0], p[1]];
    let offset = [p[2], p[3], p[4]];
    let (r, quat, _) = exp_turn(cas, &turn, &[zero; 3]);
    let end = compose(cas, &identity, Some((&r, &quat)), Some(&offset), None);
    let motion = Motion::ending(&end, [zero; 3], [zero; 3], [one, zero, zero]);
    bodiless_cells(cas, motion, Rates::Turned)
}

//! A structure's [`System`] and its link cells, built by asking each
//! segment's method to place its elements on the TMT building blocks
//! (`tmt`); several arms, bodies and joints in `assembly`.

mod assembly;
mod cell;
mod kernel_key;
mod planar_cell;

use crate::cas::Cas;
use crate::cas::ExprId;
use crate::method;
use crate::model::{FluidParam, KinkParam, Param, ParamLayout, Structure};
use crate::tmt::along::{Drag, along_loads};
use crate::tmt::planar::PlanarArm;
use crate::tmt::spatial::SpatialArm;
use crate::tmt::system::MountFrame;
use crate::tmt::{ParamSymbols, System};

pub use assembly::{ArmBlock, Assembled, FrameRows, assembly_system};
pub use cell::link_chain;
pub use kernel_key::kernel_key;

/// The system of a structure: planar or spatial kinematics by
/// `dimensions`, absolute coordinates for eba; its parameters are the
/// symbols of `layout` (values never reach the derivation).
pub fn system(cas: &mut Cas, structure: &Structure, layout: &ParamLayout) -> System {
    let symbols = ParamSymbols::new(cas, layout);
    arm_system(cas, structure, &symbols)
}

/// One arm's system on the given parameter symbols (an assembly's arm
/// passes scoped ones).
pub(crate) fn arm_system(cas: &mut Cas, structure: &Structure, symbols: &ParamSymbols) -> System {
    let mut sys = kinematics(cas, structure, symbols);
    apply_torques(cas, structure, symbols, &mut sys);
    sys
}

/// The kinematics: a method that builds the whole arm (absolute
/// coordinates) does; otherwise every segment's method places its elements
/// on one chain, planar or spatial by `dimensions`.
fn kinematics(cas: &mut Cas, structure: &Structure, symbols: &ParamSymbols) -> System {
    let methods: Vec<_> = structure
        .segments
        .iter()
        .map(|g| method::of(g.method))
        .collect();
    if let Some(sys) = methods
        .first()
        .and_then(|m| m.whole_arm(cas, structure, symbols))
    {
        return sys;
    }
    if structure.dimensions == 3 {
        let names = method::coordinate_names(structure);
        let mut arm = SpatialArm::new(cas, names, symbols);
        arm.points = structure.contact_points;
        arm.loads = along_loads(cas, structure, symbols);
        arm.set_fluid(Drag::of(structure, symbols), buoyancy(structure, symbols));
        let base = (arm.points > 0).then(|| arm.base_pose());
        let (mut ends, mut frames) = (Vec::new(), Vec::new());
        for (s, (g, m)) in structure.segments.iter().zip(&methods).enumerate() {
            if g.kink {
                let [turn, offset] = kink(symbols, s, true);
                arm.kink(cas, &turn, &offset);
            }
            m.build_spatial(cas, &mut arm, g, s);
            ends.push((arm.f.p, arm.f.quat));
            let f = arm.f;
            frames.push(MountFrame::Spatial {
                r: f.r,
                p: f.p,
                w: f.w,
                quat: f.quat,
            });
        }
        let mut sys = arm.finish(cas, structure);
        sys.segment_ends = ends;
        sys.end_frames = frames;
        sys.bases = base.into_iter().collect();
        sys
    } else {
        let names = method::coordinate_names(structure);
        let mut arm = PlanarArm::new(cas, names, symbols);
        arm.points = structure.contact_points;
        arm.loads = along_loads(cas, structure, symbols);
        arm.set_fluid(Drag::of(structure, symbols), buoyancy(structure, symbols));
        let base = (arm.points > 0).then(|| arm.base_pose(cas));
        let mut frames = Vec::new();
        for (s, (g, m)) in structure.segments.iter().zip(&methods).enumerate() {
            if g.kink {
                let [turn, offset] = kink(symbols, s, false);
                arm.kink(cas, turn[2], &offset);
            }
            for _ in 0..g.elements {
                let el = arm.begin_element(s);
                m.place_planar(cas, &mut arm, g, &el);
                arm.end_element(cas, &el);
            }
            frames.push(arm.mount_frame());
        }
        let mut sys = arm.finish(cas, structure);
        sys.end_frames = frames;
        sys.bases = base.into_iter().collect();
        sys
    }
}

/// The fluid's density, where the arm is immersed.
fn buoyancy(structure: &Structure, symbols: &ParamSymbols) -> Option<ExprId> {
    (structure.fluid.is_some()).then(|| symbols.get(Param::Fluid(FluidParam::Density)))
}

/// Segment s's kink: its turn as a rotation vector (0, y, z), about z
/// alone in the plane, and its offset.
fn kink(symbols: &ParamSymbols, s: usize, spatial: bool) -> [[ExprId; 3]; 2] {
    let turn = |i| symbols.get(Param::Kink(s, KinkParam::Turn(i)));
    let zero = symbols.zero();
    let turn = match spatial {
        true => [zero, turn(0), turn(1)],
        false => [zero, zero, turn(0)],
    };
    [turn, symbols.xyz(|c| Param::Kink(s, KinkParam::Offset(c)))]
}

/// Driven generalised forces Q_k on named coordinates as the potential
/// -sum Q_k q_k added to the actuators' (the same path as chambers and
/// tendons: h and the static forces get -Q_k, the stiffness nothing).
fn apply_torques(cas: &mut Cas, structure: &Structure, symbols: &ParamSymbols, sys: &mut System) {
    if structure.torques.is_empty() {
        return;
    }
    let mut terms = vec![sys.actuation];
    for (i, name) in structure.torques.iter().enumerate() {
        // Validation checked the name against the coordinates.
        let k = sys
            .coords
            .names
            .iter()
            .position(|n| n == name)
            .expect("validated coordinate name");
        let work = cas.mul(symbols.get(Param::Torque(i)), sys.coords.q[k]);
        terms.push(cas.neg(work));
    }
    sys.actuation = cas.add_all(&terms);
}

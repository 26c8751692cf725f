//! The TMT method: kinematics modules describe a [`System`]; [`assemble`]
//! derives M, h and the outputs from it.

mod absolute;
mod actuation;
mod assemble;
mod cell;
mod chain;
mod inertia;
mod planar;
mod solve;
mod spatial;
mod system;

use crate::cas::Cas;
use crate::model::{Method, Param, ParamLayout, Structure};

pub use assemble::{Equations, assemble};
pub use cell::link_chain;
pub use planar::planar_system;
pub use solve::{SYMBOLIC_SOLVE_MAX_DOF, solve_accelerations};
pub use spatial::spatial_system;
pub use system::ParamSymbols;

/// The system of a structure: planar or spatial kinematics by
/// `dimensions`, absolute coordinates for eba; its parameters are the
/// symbols of `layout` (values never reach the derivation).
pub fn system(cas: &mut Cas, structure: &Structure, layout: &ParamLayout) -> System {
    let symbols = ParamSymbols::new(cas, layout);
    let mut sys = kinematics(cas, structure, &symbols);
    apply_torques(cas, structure, &symbols, &mut sys);
    sys
}

fn kinematics(cas: &mut Cas, structure: &Structure, symbols: &ParamSymbols) -> System {
    if structure.segments.iter().any(|s| s.method == Method::Eba) {
        absolute::absolute_system(cas, structure, symbols)
    } else if structure.dimensions == 3 {
        spatial_system(cas, structure, symbols)
    } else {
        planar_system(cas, structure, symbols)
    }
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
pub use system::{AppliedMoment, Body, Chain, Coordinates, Inertia, Link, PointForce, System};

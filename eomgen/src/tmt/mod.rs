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

pub use assemble::{Equations, assemble};
pub use cell::link_chain;
pub use planar::planar_system;
pub use solve::{SYMBOLIC_SOLVE_MAX_DOF, solve_accelerations};
pub use spatial::spatial_system;

/// The system of a model: planar or spatial kinematics by `dimensions`,
/// absolute coordinates for eba.
pub fn system(cas: &mut crate::cas::Cas, model: &crate::model::Model) -> System {
    let mut sys = kinematics(cas, model);
    apply_torques(cas, model, &mut sys);
    sys
}

/// The coordinate names of a model's system (what `[[torque]]` may name).
pub fn coordinate_names(model: &crate::model::Model) -> Vec<String> {
    kinematics(&mut crate::cas::Cas::new(), model).coords.names
}

fn kinematics(cas: &mut crate::cas::Cas, model: &crate::model::Model) -> System {
    if model
        .segments
        .iter()
        .any(|s| s.method == crate::model::Method::Eba)
    {
        absolute::absolute_system(cas, model)
    } else if model.dimensions == 3 {
        spatial_system(cas, model)
    } else {
        planar_system(cas, model)
    }
}
/// Driven generalised forces Q_k on named coordinates as the potential
/// -sum Q_k q_k added to the actuators' (the same path as chambers and
/// tendons: h and the static forces get -Q_k, the stiffness nothing).
fn apply_torques(cas: &mut crate::cas::Cas, model: &crate::model::Model, sys: &mut System) {
    if model.torques.is_empty() {
        return;
    }
    let symbols = system::ParamSymbols::new(cas, model);
    let mut terms = vec![sys.actuation];
    for (i, t) in model.torques.iter().enumerate() {
        // Validation checked the name against `coordinate_names`.
        let k = sys
            .coords
            .names
            .iter()
            .position(|n| *n == t.coordinate)
            .expect("validated coordinate name");
        let work = cas.mul(symbols.get(&format!("torque[{i}]")), sys.coords.q[k]);
        terms.push(cas.neg(work));
    }
    sys.actuation = cas.add_all(&terms);
}
pub use system::{AppliedMoment, Body, Chain, Coordinates, Inertia, Link, PointForce, System};

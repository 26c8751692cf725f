//! The TMT method: kinematics modules describe a [`System`]; [`assemble`]
//! derives M, h and the outputs from it.

mod absolute;
mod actuation;
mod assemble;
mod chain;
mod inertia;
mod planar;
mod solve;
mod spatial;
mod system;

pub use assemble::{Equations, assemble};
pub use planar::planar_system;
pub use solve::{SYMBOLIC_SOLVE_MAX_DOF, solve_accelerations};
pub use spatial::spatial_system;

/// The system of a model: planar or spatial kinematics by `dimensions`,
/// absolute coordinates for eba.
pub fn system(cas: &mut crate::cas::Cas, model: &crate::model::Model) -> System {
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
pub use system::{AppliedMoment, Body, Chain, Coordinates, Inertia, Link, PointForce, System};

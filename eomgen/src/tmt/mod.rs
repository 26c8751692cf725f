//! The TMT method: kinematics modules describe a [`System`]; [`assemble`]
//! derives M, h and the outputs from it.

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
pub use system::{AppliedMoment, Body, Chain, Coordinates, Inertia, Link, PointForce, System};

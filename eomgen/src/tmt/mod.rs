//! The TMT method's building blocks: kinematics (planar and spatial arms,
//! frames, strains, actuation) describe a [`System`]; [`assemble`] derives
//! M, h and the outputs from it. Below `method` in the layer order: each
//! method places its elements with these; `build` asks the methods.

pub(crate) mod actuation;
pub(crate) mod along;
pub(crate) mod cell_kind;
pub(crate) mod cell_outputs;
mod chain;
pub(crate) mod contact_frames;
mod equations;
pub(crate) mod inertia;
pub(crate) mod planar;
mod solve;
pub mod spatial;
pub(crate) mod system;

pub(crate) use cell_outputs::with_tangent;
pub use equations::{Equations, assemble};
pub use solve::{SYMBOLIC_SOLVE_MAX_DOF, solve_accelerations};
pub use system::ParamSymbols;
pub use system::{
    AppliedMoment, Body, Chain, Coordinates, Inertia, Link, PointForce, System, TipMount, tip_loads,
};

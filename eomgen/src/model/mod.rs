//! Model files: schema, loading with overrides, validation, structure.

pub mod assembly;
mod assembly_check;
mod assembly_params;
mod check;
pub mod contact;
mod contact_check;
mod error;
mod load;
mod params;
mod schema;
pub mod sensor;
mod signals;
mod structure;
mod validate;

pub(crate) use check::Check;
pub use error::ModelError;
pub use load::{Override, load_model, parse_model};
pub use params::{
    BodyParam, ChamberParam, Driven, ElementParam, ElementProps, JointParam, Param, ParamLayout,
    Rate, SpringParam, Xyz, base_rotation, base_turn_axis, channel, element_props, parameters,
};
pub use schema::{
    Axis, Base, Chambers, Joints, Method, Model, OneOrMany, Segment, SimulateDefaults, Start,
    Tendon, Tip, Torque, WrenchFrame,
};
pub use signals::{Compare, Input, Offset};
pub use structure::{AssemblyShape, GENERATOR_VERSION, JointShape, SegmentShape, Structure};
pub use validate::MAX_ELEMENTS;

//! Model files: schema, loading with overrides, validation, structure.

mod error;
mod load;
mod schema;
mod signals;
mod structure;
mod validate;

pub use error::ModelError;
pub use load::{Override, load_model, parse_model};
pub use schema::{
    Axis, Base, Chambers, Joints, Method, Model, OneOrMany, Segment, Start, Tendon, Tip, Torque,
    WrenchFrame,
};
pub use signals::{Compare, Input, Offset};
pub use structure::{
    BASE_TRANSLATION, BASE_TURN, Driven, ElementProps, GENERATOR_VERSION, SegmentShape, Structure,
    base_rotation, base_turn_axis, drives, element_props, parameters,
};
pub use validate::MAX_ELEMENTS;

//! Model files: schema, loading with overrides, validation, structure.

mod error;
mod load;
mod schema;
mod structure;
mod validate;

pub use error::ModelError;
pub use load::{Override, load_model, parse_model};
pub use schema::{Axis, Base, Chambers, Joints, Method, Model, Segment, Tip};
pub use structure::{
    ElementProps, GENERATOR_VERSION, SegmentShape, Structure, base_rotation, element_props,
    parameters,
};
pub use validate::MAX_ELEMENTS;

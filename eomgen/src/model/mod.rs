//! A model file's data: its schema, the methods by name, overrides of its
//! keys, its structure and parameter layout. Below `method` in the layer
//! order: what needs a method's answers (validation, a structure from a
//! model, parameter values) is in `load`.

pub mod assembly;
mod assembly_params;
mod check;
pub mod contact;
mod error;
mod fluid;
mod load;
mod methods;
mod overrides;
mod params;
mod profile;
mod relaxation;
mod rest;
mod schema;
mod section;
pub mod sensor;
mod signals;
mod structure;
mod suggest;

pub(crate) use check::Check;
pub use error::ModelError;
pub use fluid::Fluid;
pub use load::{Load, LoadFrame, LoadShape};
pub(crate) use methods::methods;
pub use overrides::Override;
pub use params::{
    BodyParam, ChamberParam, Driven, ElementParam, FluidParam, JointParam, KinkParam, LoadParam,
    Param, ParamLayout, Rate, SpringParam, Xyz, base_rotation, base_turn_axis, channel,
};
pub(crate) use params::{base_quaternion, chamber_value, chamber_value_of};
pub use profile::Profile;
pub use relaxation::Relaxation;
pub use rest::RestCurvature;
pub use schema::{
    Axis, Base, Chambers, Hole, Joints, Method, Model, OneOrMany, Segment, SimulateDefaults, Start,
    Tendon, Tip, Torque, WrenchFrame,
};
pub use section::SectionShape;
pub use signals::{Compare, Input, Offset};
pub(crate) use signals::{check_compare, check_input};
pub use structure::{AssemblyShape, GENERATOR_VERSION, JointShape, SegmentShape, Structure};
#[doc(hidden)]
pub use suggest::distance;
pub use suggest::with_suggestion;

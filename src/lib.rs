//! softarm: declared soft robot arms to fast, specialised equations of motion.
//!
//! This crate is the CLI's library: the compiled-in models (`generated`),
//! choosing a backend for a model ([`backend`]) and the on-disk tape cache
//! ([`cache`]). The generator is `eomgen`; the numerics are in `runtime`.

pub use softarm_models as generated;

pub mod backend;
pub mod cache;
pub mod cli;
pub mod compare;
pub mod contact;
pub mod continuum;
pub mod data;
pub mod export;
pub mod fit;
pub mod fixed_step;
pub mod grid;
pub mod inputs;
pub mod interrupt;
pub mod joints;
pub mod linearize;
pub mod output_dir;
pub mod progress;
pub mod run;
pub mod run_output;
pub mod scale;
pub mod scene;
pub mod shape;
pub mod viewer;

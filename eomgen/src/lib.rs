//! eomgen: softarm's generator.
//!
//! A model file is parsed and validated (`model`), its structure is derived
//! into expressions by the TMT method (`tmt`) in our CAS (`cas`), lowered to
//! tapes (`derive`), and emitted as Rust (`emit`). `generate` keeps a
//! `generated/` folder in step with `models/` for build.rs and the CLI.

pub mod atomic_write;
pub mod build;
pub mod cas;
pub mod derive;
pub mod emit;
pub mod generate;
pub mod load;
pub mod method;
pub mod model;
pub mod shape;
pub mod tmt;

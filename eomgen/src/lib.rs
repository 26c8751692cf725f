//! eomgen: softarm's generator.
//!
//! A model file is parsed and validated (`model`), its structure is derived
//! into expressions by the TMT method (`tmt`) in our CAS (`cas`), lowered to
//! tapes, and emitted as Rust (`emit`). `generate` ties these together for
//! build.rs and the CLI.

pub mod cas;
pub mod derive;
pub mod emit;
pub mod generate;
pub mod model;
pub mod tmt;

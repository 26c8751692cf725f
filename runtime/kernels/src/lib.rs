//! The kernel layer of softarm's runtime: tapes and their interpreter, the
//! [`Kernels`] trait both backends implement, special functions, the
//! Rodrigues family, the link recursion, the packed L D L^T solve, the
//! obstacles' shapes. Generated code and the generator use only this; the
//! `runtime` crate re-exports it whole and adds the simulation layer.
//!
//! A crate of its own so that the generated models compile as soon as it
//! is built, beside the simulation layer instead of after it, and so that
//! build.rs's generator and the models share one compilation of it. It
//! knows nothing of the CAS.

pub mod assembled;
pub mod cpu;
pub mod dual;
pub mod joints;
pub mod kernels;
pub mod lanes;
pub mod linalg;
pub mod linked;
pub mod linked_parts;
pub mod links;
pub mod obstacle;
pub mod output;
pub mod parts;
pub mod rodrigues;
pub mod rotation;
pub mod rows;
pub mod scalar;
pub mod solver;
pub mod special;
pub mod tape;
pub mod tape_text;
pub mod x4;

pub use kernels::{
    CompiledModel, Interpreted, KernelKind, Kernels, ModelInfo, N_OUTPUTS, OUTPUT_NAMES, TapeSet,
};
pub use linalg::Ldlt;
pub use solver::Solver;
pub use tape::{Inputs, Op, Slot, Tape};

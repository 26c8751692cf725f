//! The runtime of softarm: what generated code and the CLI run on, in two
//! layers.
//!
//! * The **kernel layer** (the modules at this level): tapes and their
//!   interpreter, the [`Kernels`] trait both backends implement, special
//!   functions, the Rodrigues family, the link recursion, the packed
//!   L D L^T solve. Generated code and the generator use only this.
//! * The **simulation layer** (`sim`, re-exported here, behind the default
//!   feature `simulate`): [`Arm`] binds parameter values and provides
//!   [`Dynamics`]; [`integrate`] simulates, [`statics`] finds equilibria,
//!   [`modes`](mod@modes) linearises about them.
//!
//! The generator turns `simulate` off, so build.rs's copy of it compiles
//! without nalgebra and the ODE crate. It knows nothing of the CAS.

pub mod cpu;
pub mod kernels;
pub mod lanes;
pub mod linalg;
pub mod linked;
pub mod links;
pub mod obstacle;
pub mod output;
pub mod parts;
pub mod rodrigues;
pub mod rotation;
pub mod rows;
pub mod solver;
pub mod special;
pub mod tape;

// The one place the simulation layer is gated.
#[cfg(feature = "simulate")]
mod sim;
#[cfg(feature = "simulate")]
pub use sim::*;

pub use kernels::{
    CompiledModel, Interpreted, KernelKind, Kernels, ModelInfo, N_OUTPUTS, OUTPUT_NAMES, TapeSet,
};
pub use linalg::Ldlt;
pub use solver::Solver;
pub use tape::{Inputs, Op, Slot, Tape};

//! The runtime of softarm: what generated code and the CLI run on, in two
//! layers.
//!
//! * The **kernel layer** (crate `runtime-kernels` in `kernels/`,
//!   re-exported here module by module): tapes and their interpreter, the
//!   [`Kernels`] trait both backends implement, special functions, the
//!   Rodrigues family, the link recursion, the packed L D L^T solve.
//!   Generated code and the generator use only this.
//! * The **simulation layer** (`sim`, re-exported here): [`Arm`] binds
//!   parameter values and provides [`Dynamics`]; [`integrate`] simulates,
//!   [`statics`] finds equilibria, [`modes`](mod@modes) linearises about
//!   them.

pub use runtime_kernels::{
    assembled, cpu, kernels, lanes, linalg, linked, linked_parts, links, obstacle, output, parts,
    rodrigues, rotation, rows, solver, special, tape,
};

mod sim;
pub use sim::*;

pub use runtime_kernels::{
    CompiledModel, Inputs, Interpreted, KernelKind, Kernels, Ldlt, ModelInfo, N_OUTPUTS,
    OUTPUT_NAMES, Op, Slot, Solver, Tape, TapeSet,
};

//! The runtime of softarm: what generated code and the CLI run on.
//!
//! It knows nothing of the CAS. Generated models implement [`Kernels`];
//! the tape interpreter ([`Interpreted`]) implements it too. [`Arm`] binds
//! parameter values and provides [`Dynamics`]; [`integrate`] simulates,
//! [`statics`] finds equilibria, [`modes`](mod@modes) linearises about them.

// The kernel side (tapes, special functions, the `Kernels` trait) is all
// the generator needs; everything that simulates sits behind the default
// feature `simulate`, so that build.rs's copy of the generator compiles
// without nalgebra and the ODE crate.
pub mod cpu;
pub mod kernels;
pub mod lanes;
pub mod linalg;
pub mod links;
pub mod rodrigues;
pub mod rows;
pub mod special;
pub mod tape;

#[cfg(feature = "simulate")]
pub mod arm;
#[cfg(feature = "simulate")]
pub mod bs23;
#[cfg(feature = "simulate")]
pub mod cosserat;
#[cfg(feature = "simulate")]
pub mod events;
#[cfg(feature = "simulate")]
pub mod integrate;
#[cfg(feature = "simulate")]
pub mod jacobian;
#[cfg(feature = "simulate")]
pub mod modes;
#[cfg(feature = "simulate")]
pub mod radau5;
#[cfg(feature = "simulate")]
pub mod signal;
#[cfg(feature = "simulate")]
pub mod statics;
#[cfg(feature = "simulate")]
pub mod stepper;
#[cfg(feature = "simulate")]
pub mod stiffness;
#[cfg(feature = "simulate")]
pub mod trbdf2;

/// The integrators by name, as `--solver` and `[simulate] solver` take them.
pub const SOLVER_NAMES: [&str; 10] = [
    "dopri5", "bs23", "dop853", "rk4", "euler", "radau5", "bdf", "trbdf2", "esdirk", "auto",
];

pub use kernels::{
    CompiledModel, Interpreted, KernelKind, Kernels, ModelInfo, N_OUTPUTS, OUTPUT_NAMES, TapeSet,
};
pub use linalg::Ldlt;
pub use tape::{Inputs, Op, Slot, Tape};

#[cfg(feature = "simulate")]
pub use arm::{AccelError, Arm, Dynamics, Workspace, accelerations};
#[cfg(feature = "simulate")]
pub use events::{Crossing, Event, EventHit};
#[cfg(feature = "simulate")]
pub use integrate::{SimFailure, SimOptions, SimStats, Solver, Trajectory, simulate};
#[cfg(feature = "simulate")]
pub use jacobian::rhs_jacobian;
#[cfg(feature = "simulate")]
pub use modes::{Modes, ModesError, modes};
#[cfg(feature = "simulate")]
pub use signal::{Drive, Signal, Table};
#[cfg(feature = "simulate")]
pub use statics::{StaticError, StaticOptions, StaticSolution, solve_static};
#[cfg(feature = "simulate")]
pub use stiffness::{StiffnessReport, analyse as analyse_stiffness};

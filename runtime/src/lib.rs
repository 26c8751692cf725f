//! The runtime of softarm: what generated code and the CLI run on.
//!
//! It knows nothing of the CAS. Generated models implement [`Kernels`];
//! the tape interpreter ([`Interpreted`]) implements it too. [`Arm`] binds
//! parameter values and provides [`Dynamics`]; [`integrate`] simulates,
//! [`statics`] finds equilibria, [`modes`](mod@modes) linearises about them.

pub mod arm;
pub mod bs23;
pub mod cosserat;
pub mod events;
pub mod integrate;
pub mod jacobian;
pub mod kernels;
pub mod linalg;
pub mod modes;
pub mod radau5;
pub mod rodrigues;
pub mod signal;
pub mod special;
pub mod statics;
pub mod stepper;
pub mod stiffness;
pub mod tape;
pub mod trbdf2;

pub use arm::{AccelError, Arm, Dynamics, Workspace, accelerations};
pub use events::{Crossing, Event, EventHit};
pub use integrate::{SimFailure, SimOptions, SimStats, Solver, Trajectory, simulate};
pub use jacobian::rhs_jacobian;
pub use kernels::{
    CompiledModel, Interpreted, KernelKind, Kernels, ModelInfo, N_OUTPUTS, OUTPUT_NAMES, TapeSet,
};
pub use linalg::Ldlt;
pub use modes::{Modes, ModesError, modes};
pub use signal::{Drive, Signal, Table};
pub use statics::{StaticError, StaticOptions, StaticSolution, solve_static};
pub use stiffness::{StiffnessReport, analyse as analyse_stiffness};
pub use tape::{Inputs, Op, Slot, Tape};

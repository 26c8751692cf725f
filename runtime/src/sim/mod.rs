//! The simulation layer: an arm's kernels with parameter values bound
//! ([`arm::Arm`], the [`arm::Dynamics`] trait), and what runs on it:
//! integrators, statics, modes, stiffness analysis, input signals, and the
//! Cosserat rod. Built only with the `simulate` feature (the generator
//! needs the kernel layer alone).

pub mod arm;
pub mod constraints;
pub mod contact;
pub mod cosserat;
pub mod integrate;
pub mod jacobian;
pub mod modes;
pub mod relaxation;
pub mod relaxed_forces;
pub mod signal;
pub mod statics;
pub mod stiffness;

pub use arm::{AccelError, Arm, Dynamics, Workspace, accelerations};
pub use integrate::events::{CONTACT_EVENT, Crossing, Event, EventHit};
pub use integrate::{
    ContactMeter, DEFAULT_SAMPLES, DEFAULT_T_END, INTERRUPTED, Interrupt, MeterSample, Row,
    RowSink, SimFailure, SimOptions, SimStats, SwitchRecord, Trajectory, simulate,
};
pub use jacobian::{rhs_jacobian, state_jacobian};
pub use modes::{Modes, ModesError, modes};
pub use signal::{Drive, Signal, Table};
pub use statics::{StaticError, StaticOptions, StaticSolution, solve_static};
pub use stiffness::{StiffnessReport, analyse as analyse_stiffness};

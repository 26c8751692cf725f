//! What a simulation is asked to do. The defaults here are the CLI's
//! defaults too (`softarm simulate` falls back on them), so the two cannot
//! disagree.

use super::events::Event;
use crate::solver::Solver;

/// The simulated time when neither the command line nor the model says.
pub const DEFAULT_T_END: f64 = 5.0;
/// Samples of the written trajectory when no spacing is given: t_end / this.
pub const DEFAULT_SAMPLES: f64 = 500.0;

#[derive(Clone, Debug)]
pub struct SimOptions {
    /// The run integrates from t0 (the time x0 is at) to t_end.
    pub t0: f64,
    pub t_end: f64,
    pub solver: Solver,
    pub rtol: f64,
    pub atol: f64,
    /// Step of fixed-step solvers (s).
    pub dt: f64,
    /// Spacing of the written trajectory (s).
    pub output_dt: f64,
    /// Sample at these times instead (ascending; from the methods' dense
    /// output, so they cost no extra steps).
    pub output_times: Option<Vec<f64>>,
    /// Zero crossings to locate (and to stop at, if terminal).
    pub events: Vec<Event>,
    /// Give up after this many steps.
    pub max_steps: usize,
    /// Where the run reports its progress: every accepted step stores the
    /// time it reached (`f64::to_bits`), for a progress display that
    /// polls it from another thread.
    pub progress: Option<std::sync::Arc<std::sync::atomic::AtomicU64>>,
    /// Asked every few accepted steps whether to stop (Ctrl-C in a host
    /// language): true ends the run as a failure whose reason is
    /// `INTERRUPTED`, with the trajectory so far.
    pub interrupt: Option<Interrupt>,
    /// Stream the samples: each is handed to this as soon as it is final
    /// (`integrate::rows`), and the trajectory the run returns holds only
    /// its last sample (with every event and contact switch).
    pub rows: Option<super::rows::RowSink>,
    /// The run goes on from where the last run on this arm ended (a
    /// control loop's steps): its contacts keep the records of how they
    /// began. Otherwise they begin afresh (`ContactSet::clear_records`).
    pub continues: bool,
    /// generalized-alpha's spectral radius at infinity, in [0, 1]: how much
    /// of a mode far above the step's resolution survives a step (1: all,
    /// no numerical damping; 0: none).
    pub rho_inf: f64,
}

/// The default spectral radius at infinity: modes the step does not resolve
/// lose a fifth of their amplitude a step, those it resolves next to none.
pub const DEFAULT_RHO_INF: f64 = 0.8;

/// The reason of a run stopped by its `SimOptions::interrupt`.
pub const INTERRUPTED: &str = "interrupted";

/// Whether to stop a run now.
#[derive(Clone)]
pub struct Interrupt(pub std::sync::Arc<dyn Fn() -> bool + Send + Sync>);

impl std::fmt::Debug for Interrupt {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Interrupt")
    }
}

impl Default for SimOptions {
    fn default() -> Self {
        Self {
            t0: 0.0,
            t_end: DEFAULT_T_END,
            solver: Solver::Auto,
            rtol: 1e-6,
            atol: 1e-9,
            dt: 1e-3,
            output_dt: DEFAULT_T_END / DEFAULT_SAMPLES,
            output_times: None,
            events: Vec::new(),
            max_steps: 10_000_000,
            progress: None,
            interrupt: None,
            rows: None,
            continues: false,
            rho_inf: DEFAULT_RHO_INF,
        }
    }
}

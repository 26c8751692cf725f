//! Ctrl-C (SIGINT) and a scheduler's SIGTERM as a request to stop: a run
//! stops at its next check, keeps what it computed and says so, instead
//! of dying with nothing written. A second Ctrl-C ends the process at once.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, OnceLock};
use std::time::Instant;

use signal_hook::consts::{SIGINT, SIGTERM};

/// Which signal asked the run to stop.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stop {
    /// SIGINT, Ctrl-C.
    Interrupt,
    /// SIGTERM, a scheduler's time limit.
    Terminate,
}

impl Stop {
    /// The shell's code for a process ended by the signal: 128 + its number.
    pub fn exit_code(self) -> u8 {
        match self {
            Stop::Interrupt => 130,
            Stop::Terminate => 143,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Stop::Interrupt => "SIGINT",
            Stop::Terminate => "SIGTERM",
        }
    }
}

struct Flags {
    interrupt: Arc<AtomicBool>,
    terminate: Arc<AtomicBool>,
}

static FLAGS: OnceLock<Flags> = OnceLock::new();

/// Catch SIGINT and SIGTERM from now on (once per process; later calls do
/// nothing). Where a handler cannot be installed, the signal keeps its
/// default action.
pub fn catch() {
    FLAGS.get_or_init(|| {
        let flags = Flags {
            interrupt: Arc::new(AtomicBool::new(false)),
            terminate: Arc::new(AtomicBool::new(false)),
        };
        for (signal, flag, code) in [
            (SIGINT, &flags.interrupt, Stop::Interrupt.exit_code()),
            (SIGTERM, &flags.terminate, Stop::Terminate.exit_code()),
        ] {
            // The second signal of a kind ends the process at once: the
            // first one set the flag the conditional exit reads.
            let _ =
                signal_hook::flag::register_conditional_shutdown(signal, code as i32, flag.clone());
            let _ = signal_hook::flag::register(signal, flag.clone());
        }
        flags
    });
}

/// The signal that asked to stop, if one did.
pub fn requested() -> Option<Stop> {
    let flags = FLAGS.get()?;
    if flags.terminate.load(Ordering::Relaxed) {
        Some(Stop::Terminate)
    } else if flags.interrupt.load(Ordering::Relaxed) {
        Some(Stop::Interrupt)
    } else {
        None
    }
}

/// A run's check for a stop request (`SimOptions::interrupt`), with the
/// signals caught: a signal, or the wall clock past `deadline`.
pub fn for_run(deadline: Option<Instant>) -> runtime::Interrupt {
    catch();
    runtime::Interrupt(Arc::new(move || {
        requested().is_some() || deadline.is_some_and(|d| Instant::now() >= d)
    }))
}

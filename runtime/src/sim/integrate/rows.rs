//! A run's samples streamed as they become final (`SimOptions::rows`), so
//! that a run of any length holds a bounded number of them in memory and a
//! writer can put each on disk the moment it is computed.
//!
//! A sample is final where no later work can change or drop it: at once
//! for a run by one method (the recorder hands it over), when its leg is
//! accepted for a run with joints (a leg over its drift budget is run
//! again). Legs and solver switches meet at a sample both sides hold; the
//! sink keeps the first (times strictly increase), as the kept trajectory
//! does. A sample's contact columns are computed when it is handed over,
//! while the contact records are still those it ran with.

use std::sync::{Arc, Mutex};

use super::outcome::Trajectory;
use crate::arm::Dynamics;

/// One final sample: the time, the state x = [q, qd], and with contact,
/// every channel's normal and friction force (`contact::channel_columns`).
pub struct Row<'a> {
    pub t: f64,
    pub x: &'a [f64],
    pub contact: &'a [f64],
}

/// What receives a run's rows, in time order, each once. The arm is the
/// run's, handed with each row (for its outputs).
pub type RowFn = dyn FnMut(&dyn Dynamics, &Row<'_>) + Send;

/// Where a run streams its samples; clones share the receiver and its
/// record of the last time handed over.
#[derive(Clone)]
pub struct RowSink(Arc<Mutex<Receiver>>);

struct Receiver {
    f: Box<RowFn>,
    last_t: Option<f64>,
    rows: usize,
}

impl RowSink {
    pub fn new(f: impl FnMut(&dyn Dynamics, &Row<'_>) + Send + 'static) -> Self {
        Self(Arc::new(Mutex::new(Receiver {
            f: Box::new(f),
            last_t: None,
            rows: 0,
        })))
    }

    /// Hand over the sample (t, x) unless one at t or later was.
    pub(crate) fn push(&self, arm: &dyn Dynamics, t: f64, x: &[f64]) {
        let mut r = self.0.lock().unwrap_or_else(|e| e.into_inner());
        if r.last_t.is_some_and(|last| t <= last) {
            return;
        }
        let n = arm.dof();
        let contact = match arm.contact() {
            Some(set) => crate::contact::channel_columns(arm, set, t, &x[..n], &x[n..2 * n]),
            None => Vec::new(),
        };
        let row = Row {
            t,
            x: &x[..2 * n + arm.internal_len()],
            contact: &contact,
        };
        (r.f)(arm, &row);
        r.last_t = Some(t);
        r.rows += 1;
    }

    /// Rows handed over so far.
    pub fn rows(&self) -> usize {
        self.0.lock().unwrap_or_else(|e| e.into_inner()).rows
    }
}

impl std::fmt::Debug for RowSink {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "RowSink({} rows)", self.rows())
    }
}

/// A streamed run's trajectory keeps its last sample only (where a later
/// leg starts), with its events and contact switches.
pub(super) fn keep_last(traj: &mut Trajectory) {
    let len = traj.t.len();
    if len > 1 {
        traj.t.drain(..len - 1);
        traj.x.drain(..len - 1);
    }
    let len = traj.contact.len();
    if len > 1 {
        traj.contact.drain(..len - 1);
    }
}

//! What a run gives back besides its failure: the sampled trajectory, the
//! contact switches' records, and what the run counted and metered.

use serde::Serialize;

use super::events::EventHit;
use crate::solver::Solver;

/// A change of solver made by `auto`.
#[derive(Clone, Debug, Serialize)]
pub struct SolverSwitch {
    pub at_s: f64,
    pub to: Solver,
    pub reason: String,
}

/// Sampled states x = [q, qd] at times t.
#[derive(Clone, Debug, Default)]
pub struct Trajectory {
    pub t: Vec<f64>,
    pub x: Vec<Vec<f64>>,
    /// The located events, in time order.
    pub events: Vec<EventHit>,
    /// A system with contacts: at each sample, every contact channel's
    /// total normal and friction force (`contact::channel_columns`),
    /// recorded while the run's contact state (impact speeds, held
    /// contacts) was the sample's. Empty otherwise.
    pub contact: Vec<Vec<f64>>,
    /// The contact switches' records, in time order.
    pub switches: Vec<SwitchRecord>,
}

/// At a contact switch (`integrate::touch`): the normal impulse the
/// contact forces had transmitted by then (`ContactMeter`), and the
/// pairs whose impulse law made the velocities jump there, with the
/// normal impulse of each (N s).
#[derive(Clone, Debug, Default)]
pub struct SwitchRecord {
    pub t: f64,
    pub metered_impulse_ns: f64,
    pub jumps: Vec<(usize, f64)>,
}

#[derive(Clone, Debug, Serialize)]
pub struct SimStats {
    pub solver: Solver,
    pub steps: usize,
    /// None where a failed method's count was lost with its error (the
    /// ODE crate's methods, but for a spent budget).
    pub rejected_steps: Option<usize>,
    pub rhs_evaluations: usize,
    pub jacobian_evaluations: usize,
    pub wall_s: f64,
    /// Set when `auto` switched solvers.
    pub switched: Option<SolverSwitch>,
    /// A system with joints: how far integration drifted off them.
    pub constraints: Option<ConstraintStats>,
    /// A system with contacts: what they did over the run.
    pub contact: Option<ContactMeter>,
}

impl SimStats {
    /// A run of `solver` that has done nothing yet.
    pub fn none(solver: Solver) -> Self {
        Self {
            solver,
            steps: 0,
            rejected_steps: Some(0),
            rhs_evaluations: 0,
            jacobian_evaluations: 0,
            wall_s: 0.0,
            switched: None,
            constraints: None,
            contact: None,
        }
    }

    /// Add a later run's counts, wall time, first switch and contact meter
    /// (the constraints' figures are their runner's to merge).
    pub fn absorb(&mut self, more: &SimStats) {
        self.steps += more.steps;
        self.rejected_steps = self
            .rejected_steps
            .zip(more.rejected_steps)
            .map(|(a, b)| a + b);
        self.rhs_evaluations += more.rhs_evaluations;
        self.jacobian_evaluations += more.jacobian_evaluations;
        self.wall_s += more.wall_s;
        if self.switched.is_none() {
            self.switched.clone_from(&more.switched);
        }
        self.contact = ContactMeter::then(self.contact, more.contact);
    }
}

/// What contacts did over a run, metered on every accepted step: the
/// energy they dissipated and the normal impulse their forces transmitted
/// (3-point Gauss-Legendre on the step's dense output, so as accurate as
/// the integration), and the deepest penetration seen at those points.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct ContactMeter {
    pub dissipated_j: f64,
    pub max_penetration_m: f64,
    /// The integral of every pair's normal force over time (N s); an
    /// impulse law's jumps are not forces and are not in it.
    pub normal_impulse_ns: f64,
}

/// What `ContactMeter` integrates, at one time: the power the contacts
/// dissipate, the deepest penetration and the sum of the normal forces.
#[derive(Clone, Copy, Debug, Default)]
pub struct MeterSample {
    pub power_w: f64,
    pub depth_m: f64,
    pub normal_n: f64,
}

impl ContactMeter {
    /// Two runs' meters, one after the other.
    pub fn then(a: Option<Self>, b: Option<Self>) -> Option<Self> {
        match (a, b) {
            (Some(a), Some(b)) => Some(Self {
                dissipated_j: a.dissipated_j + b.dissipated_j,
                max_penetration_m: a.max_penetration_m.max(b.max_penetration_m),
                normal_impulse_ns: a.normal_impulse_ns + b.normal_impulse_ns,
            }),
            (a, b) => a.or(b),
        }
    }

    /// Meter the step [t0, t1] by `at(t)`.
    pub(super) fn step(
        &mut self,
        t0: f64,
        t1: f64,
        mut at: impl FnMut(f64) -> Option<MeterSample>,
    ) {
        // The first call of a run sees no step yet.
        if t1 <= t0 {
            return;
        }
        let (mid, half) = (0.5 * (t0 + t1), 0.5 * (t1 - t0));
        let r = (0.6_f64).sqrt();
        for (x, w) in [(-r, 5.0 / 9.0), (0.0, 8.0 / 9.0), (r, 5.0 / 9.0)] {
            if let Some(s) = at(mid + half * x) {
                self.dissipated_j += half * w * s.power_w;
                self.normal_impulse_ns += half * w * s.normal_n;
                self.max_penetration_m = self.max_penetration_m.max(s.depth_m);
            }
        }
    }
}

/// How far integration drifted off the joints, and how often it was put
/// back.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct ConstraintStats {
    /// Largest point gap at a sample before projection (m).
    pub drift_max_m: f64,
    /// Largest angle gap (rad).
    pub drift_max_rad: f64,
    /// Largest |J qd| (m/s or rad/s).
    pub velocity_drift_max: f64,
    pub projections: usize,
}

impl ConstraintStats {
    /// The largest drifts of both, and their projections summed.
    pub fn merge(&mut self, more: &ConstraintStats) {
        self.drift_max_m = self.drift_max_m.max(more.drift_max_m);
        self.drift_max_rad = self.drift_max_rad.max(more.drift_max_rad);
        self.velocity_drift_max = self.velocity_drift_max.max(more.velocity_drift_max);
        self.projections += more.projections;
    }
}

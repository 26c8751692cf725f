//! Recording a run: the samples (evenly spaced or at given times), the
//! located events, the last accepted step, and a stop on a non-finite
//! state; what the run counted.

use std::cell::{Cell, RefCell};

use differential_equations::prelude::*;
use differential_equations::solout::EvenSolout;
use serde::Serialize;

use super::events::{EventHit, EventWatch};
use super::ode::ArmOde;
use super::options::SimOptions;
use super::state::StateVec;
use crate::solver::Solver;

/// How often `auto` re-checks stiffness (accepted explicit steps): the
/// recorder calls its watch this often.
pub const AUTO_CHECK_STEPS: usize = 200;

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
    pub rejected_steps: usize,
    pub rhs_evaluations: usize,
    pub jacobian_evaluations: usize,
    pub wall_s: f64,
    /// Set when `auto` switched solvers.
    pub switched: Option<SolverSwitch>,
    /// A system with joints: how far integration drifted off them.
    pub constraints: Option<super::projected::ConstraintStats>,
    /// A system with contacts: what they did over the run.
    pub contact: Option<ContactMeter>,
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
    fn step(&mut self, t0: f64, t1: f64, mut at: impl FnMut(f64) -> Option<MeterSample>) {
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

/// Samples evenly and stops on a non-finite accepted state. A fixed-step
/// method has no error estimate to reject a step whose right-hand side
/// failed, so for those a failure anywhere in the step stops it too (its
/// dense output would be NaN); adaptive methods reject such steps.
pub(super) struct Recorder<'a> {
    sampler: Sampler,
    /// The run's end: a fixed-step method's last step lands on it only up
    /// to the rounding of its summed steps, and its sample is still due.
    t_end: f64,
    /// The samples so far, unpadded, kept outside the crate's solution so
    /// that a run that fails still returns them.
    kept: &'a RefCell<Trajectory>,
    m: usize,
    /// The last accepted step, for failure reports.
    last_step: &'a Cell<Option<f64>>,
    events: &'a RefCell<EventWatch>,
    blown_up: &'a Cell<Option<f64>>,
    failed_in_step: &'a Cell<bool>,
    fixed_step: bool,
    /// `auto`: called every AUTO_CHECK_STEPS accepted steps with the state
    /// and the last step; Some(reason) stops the run for a switch.
    watch: Option<&'a Watch<'a>>,
    switch: &'a RefCell<Option<(f64, Vec<f64>, String)>>,
    accepted: usize,
    /// The contact switch (`integrate::touch`), when the arm has one.
    contact: Option<Box<super::events::SwitchFn<'a>>>,
    /// The contact meter's (power, depth) at (t, x), and its running sum.
    meter: Option<Box<super::ode::MeterFn<'a>>>,
    metered: &'a Cell<Option<ContactMeter>>,
    /// `SimOptions::progress`.
    progress: Option<std::sync::Arc<std::sync::atomic::AtomicU64>>,
    /// `SimOptions::interrupt`, and when it stopped the run.
    interrupt: Option<super::options::Interrupt>,
    interrupted: &'a Cell<Option<f64>>,
}

pub(super) type Watch<'a> = dyn Fn(&[f64], f64) -> Option<String> + 'a;

impl Recorder<'_> {
    fn keep<Y: StateVec>(&self, solution: &Solution<f64, Y>) {
        let mut kept = self.kept.borrow_mut();
        for k in kept.t.len()..solution.t.len() {
            kept.t.push(solution.t[k]);
            kept.x.push(solution.y[k].as_ref()[..self.m].to_vec());
        }
    }
}

impl<Y: StateVec> Solout<f64, Y> for Recorder<'_> {
    fn solout<I>(
        &mut self,
        t_curr: f64,
        t_prev: f64,
        y_curr: &Y,
        y_prev: &Y,
        interpolator: &mut I,
        solution: &mut Solution<f64, Y>,
    ) -> ControlFlag<f64, Y>
    where
        I: Interpolation<f64, Y> + ?Sized,
    {
        if t_curr > t_prev {
            self.last_step.set(Some(t_curr - t_prev));
        }
        let rhs_failed = self.failed_in_step.replace(false) && self.fixed_step;
        if rhs_failed || y_curr.as_ref().iter().any(|v| !v.is_finite()) {
            self.blown_up.set(Some(t_prev));
            return ControlFlag::Terminate;
        }
        if let Some(p) = &self.progress {
            p.store(t_curr.to_bits(), std::sync::atomic::Ordering::Relaxed);
        }
        // Asked every 64 accepted steps: a check costs a host call.
        if let Some(stop) = &self.interrupt
            && self.accepted.is_multiple_of(64)
            && (stop.0)()
        {
            self.interrupted.set(Some(t_curr));
            return ControlFlag::Terminate;
        }
        if let Some(meter) = &self.meter {
            let mut m = self.metered.get().unwrap_or_default();
            m.step(t_prev, t_curr, |t| {
                let y = interpolator.interpolate(t).ok()?;
                Some(meter(t, y.as_ref()))
            });
            self.metered.set(Some(m));
        }
        let hit = self.events.borrow_mut().check(
            t_prev,
            t_curr,
            y_prev,
            y_curr,
            interpolator,
            self.contact.as_deref(),
        );
        if let Some((t_event, y_event)) = hit {
            self.sampler
                .sample(t_event, t_prev, &y_event, y_prev, interpolator, solution);
            if solution.t.last() != Some(&t_event) {
                solution.push(t_event, y_event);
            }
            self.keep(solution);
            return ControlFlag::Terminate;
        }
        let flag = self
            .sampler
            .sample(t_curr, t_prev, y_curr, y_prev, interpolator, solution);
        self.sampler.at_end(t_curr, y_curr, self.t_end, solution);
        self.keep(solution);
        self.accepted += 1;
        if let Some(watch) = self.watch
            && self.accepted.is_multiple_of(AUTO_CHECK_STEPS)
            && let Some(reason) = watch(y_curr.as_ref(), t_curr - t_prev)
        {
            *self.switch.borrow_mut() = Some((t_curr, y_curr.as_ref().to_vec(), reason));
            return ControlFlag::Terminate;
        }
        flag
    }
}

/// Where the trajectory is sampled.
pub(super) enum Sampler {
    Even(EvenSolout<f64>),
    /// Ascending times, and the index of the next one due.
    At(Vec<f64>, usize),
}

impl Sampler {
    fn new(opts: &SimOptions) -> Self {
        match &opts.output_times {
            Some(times) => {
                // In time order, whatever order they were given in.
                let mut times = times.clone();
                times.sort_by(f64::total_cmp);
                Self::At(times, 0)
            }
            None => Self::Even(EvenSolout::new(opts.output_dt, 0.0, opts.t_end)),
        }
    }

    fn sample<Y: StateVec, I: Interpolation<f64, Y> + ?Sized>(
        &mut self,
        t_curr: f64,
        t_prev: f64,
        y_curr: &Y,
        y_prev: &Y,
        interpolator: &mut I,
        solution: &mut Solution<f64, Y>,
    ) -> ControlFlag<f64, Y> {
        match self {
            Self::Even(even) => even.solout(t_curr, t_prev, y_curr, y_prev, interpolator, solution),
            Self::At(times, next) => {
                while let Some(&t) = times.get(*next) {
                    if t > t_curr {
                        break;
                    }
                    *next += 1;
                    if t < t_prev {
                        continue;
                    }
                    let y = if t == t_curr {
                        y_curr.clone()
                    } else if t == t_prev {
                        y_prev.clone()
                    } else {
                        match interpolator.interpolate(t) {
                            Ok(y) => y,
                            Err(_) => continue,
                        }
                    };
                    solution.push(t, y);
                }
                ControlFlag::Continue
            }
        }
    }
}

impl Sampler {
    /// A step that ends within rounding of t_end (1e-9 relative: a fixed
    /// step's t0 + N h) ends the run there: its state is t_end's sample,
    /// if that is due and was not taken.
    fn at_end<Y: StateVec>(
        &mut self,
        t_curr: f64,
        y_curr: &Y,
        t_end: f64,
        solution: &mut Solution<f64, Y>,
    ) {
        let tol = 1e-9 * t_end.abs().max(f64::MIN_POSITIVE);
        if t_curr == t_end || (t_end - t_curr).abs() > tol || solution.t.last() == Some(&t_end) {
            return;
        }
        let due = match self {
            Self::Even(_) => true,
            Self::At(times, next) => match times.get(*next) {
                Some(&t) if (t - t_end).abs() <= tol => {
                    *next += 1;
                    true
                }
                _ => false,
            },
        };
        if due {
            // A sample the step took at its rounded end is this one.
            if solution.t.last().is_some_and(|&t| (t - t_end).abs() <= tol) {
                let _ = solution.pop();
            }
            solution.push(t_end, y_curr.clone());
        }
    }
}

/// What a run's recorder saw: the samples with the events, and the last
/// accepted step.
pub(super) struct Recorded {
    pub(super) kept: Trajectory,
    pub(super) last_step_s: Option<f64>,
    pub(super) contact: Option<ContactMeter>,
    /// `SimOptions::interrupt` stopped the run at this time.
    pub(super) interrupted: Option<f64>,
}

/// The shared state a run's `Recorder` writes to.
pub(super) struct RunLog {
    pub(super) blown_up: Cell<Option<f64>>,
    interrupted: Cell<Option<f64>>,
    events: RefCell<EventWatch>,
    kept: RefCell<Trajectory>,
    last_step: Cell<Option<f64>>,
    metered: Cell<Option<ContactMeter>>,
}

impl RunLog {
    pub(super) fn new(opts: &SimOptions, dof: usize) -> Self {
        Self {
            blown_up: Cell::new(None),
            interrupted: Cell::new(None),
            events: RefCell::new(EventWatch::new(&opts.events, 2 * dof)),
            kept: RefCell::new(Trajectory::default()),
            last_step: Cell::new(None),
            metered: Cell::new(None),
        }
    }

    pub(super) fn recorder<'a, D: crate::arm::Dynamics + ?Sized>(
        &'a self,
        opts: &SimOptions,
        ode: &'a ArmOde<'_, D>,
        fixed_step: bool,
        watch: Option<&'a Watch<'a>>,
        switch: &'a RefCell<Option<(f64, Vec<f64>, String)>>,
    ) -> Recorder<'a> {
        Recorder {
            sampler: Sampler::new(opts),
            t_end: opts.t_end,
            kept: &self.kept,
            m: 2 * ode.n,
            last_step: &self.last_step,
            events: &self.events,
            blown_up: &self.blown_up,
            failed_in_step: &ode.failed_in_step,
            fixed_step,
            watch,
            switch,
            accepted: 0,
            contact: ode.contact_switch(),
            meter: ode.contact_meter(),
            metered: &self.metered,
            progress: opts.progress.clone(),
            interrupt: opts.interrupt.clone(),
            interrupted: &self.interrupted,
        }
    }

    pub(super) fn finish(&self) -> Recorded {
        Recorded {
            kept: Trajectory {
                events: std::mem::take(&mut self.events.borrow_mut().hits),
                ..self.kept.take()
            },
            last_step_s: self.last_step.get(),
            contact: self.metered.get(),
            interrupted: self.interrupted.get(),
        }
    }
}

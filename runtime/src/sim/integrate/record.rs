//! Recording a run: the samples (evenly spaced or at given times), the
//! located events, the last accepted step, and a stop on a non-finite
//! state; what the run counted.

use std::cell::{Cell, RefCell};

use super::events::EventWatch;
use super::ode::ArmOde;
use super::options::SimOptions;
use super::outcome::{ContactMeter, Trajectory};
use super::state::StateVec;
use differential_equations::prelude::*;

/// How often `auto` re-checks stiffness (accepted explicit steps): the
/// recorder calls its watch this often.
pub const AUTO_CHECK_STEPS: usize = 200;

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
    /// The recorder's calls so far (the checks' cadence).
    calls: usize,
    /// Accepted steps so far (kept outside the crate's solution so that a
    /// failed run still reports them).
    accepted: &'a Cell<usize>,
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
    /// `SimOptions::rows`, with the run's arm: each sample is handed over
    /// as it is taken, and only the last is kept (with the crate's
    /// solution emptied), so memory stays bounded however long the run.
    rows: Option<(super::rows::RowSink, &'a dyn crate::arm::Dynamics)>,
}

pub(super) type Watch<'a> = dyn Fn(&[f64], f64) -> Option<String> + 'a;

/// Samples a streamed run hands over at once at most: a long step over
/// many output times (radau5 takes a second at a time on a damped arm)
/// does not gather them all first.
const STREAM_BATCH: usize = 256;

impl Recorder<'_> {
    fn keep<Y: StateVec>(&self, solution: &mut Solution<f64, Y>) {
        keep(self.kept, &self.rows, self.m, solution);
    }
}

/// The new samples of `solution` into `kept`, or handed over to the row
/// sink of a streamed run.
fn keep<Y: StateVec>(
    kept: &RefCell<Trajectory>,
    rows: &Option<(super::rows::RowSink, &dyn crate::arm::Dynamics)>,
    m: usize,
    solution: &mut Solution<f64, Y>,
) {
    {
        let mut kept = kept.borrow_mut();
        // Streamed: every sample but the last goes; the last stays in the
        // solution (the crate's even sampler replaces it when it lands
        // within rounding of the end) and in `kept`, to go at the run's end.
        if let Some((sink, arm)) = rows {
            let Some(last) = solution.t.len().checked_sub(1) else {
                return;
            };
            for (t, y) in solution.t.iter().zip(&solution.y).take(last) {
                sink.push(*arm, *t, &y.as_ref()[..m]);
            }
            solution.t.drain(..last);
            solution.y.drain(..last);
            kept.t = vec![solution.t[0]];
            kept.x = vec![solution.y[0].as_ref()[..m].to_vec()];
            return;
        }
        for k in kept.t.len()..solution.t.len() {
            kept.t.push(solution.t[k]);
            kept.x.push(solution.y[k].as_ref()[..m].to_vec());
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
            && self.calls.is_multiple_of(64)
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
        let (kept, rows, m) = (self.kept, &self.rows, self.m);
        let mut flush = |s: &mut Solution<f64, Y>| {
            if rows.is_some() && s.t.len() >= STREAM_BATCH {
                keep(kept, rows, m, s);
            }
        };
        if let Some((t_event, y_event)) = hit {
            self.sampler.sample(
                t_event,
                t_prev,
                &y_event,
                y_prev,
                interpolator,
                solution,
                &mut flush,
            );
            if solution.t.last() != Some(&t_event) {
                solution.push(t_event, y_event);
            }
            self.keep(&mut *solution);
            return ControlFlag::Terminate;
        }
        let flag = self.sampler.sample(
            t_curr,
            t_prev,
            y_curr,
            y_prev,
            interpolator,
            solution,
            &mut flush,
        );
        self.sampler.at_end(t_curr, y_curr, self.t_end, solution);
        self.keep(&mut *solution);
        self.calls += 1;
        // (A method's first call, at the start, is no step.)
        if t_curr > t_prev {
            self.accepted.set(self.accepted.get() + 1);
        }
        if let Some(watch) = self.watch
            && self.calls.is_multiple_of(AUTO_CHECK_STEPS)
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
    /// Every multiple k dt of the spacing from the run's start on, each
    /// computed as k times dt (a sum of steps drifts: ten thousand steps of
    /// 0.1 ms miss 1 s by 1e-13 s), then the end; a multiple within
    /// rounding of the end is the end. `next`: the k due, once known.
    Even {
        dt: f64,
        t_end: f64,
        next: Option<u64>,
    },
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
            None => Self::Even {
                dt: opts.output_dt,
                t_end: opts.t_end,
                next: None,
            },
        }
    }

    /// The samples in [t_prev, t_curr] not taken yet, into `solution`,
    /// `flush`ed after each (a streamed run hands them over in batches).
    #[allow(clippy::too_many_arguments)]
    fn sample<Y: StateVec, I: Interpolation<f64, Y> + ?Sized>(
        &mut self,
        t_curr: f64,
        t_prev: f64,
        y_curr: &Y,
        y_prev: &Y,
        interpolator: &mut I,
        solution: &mut Solution<f64, Y>,
        flush: &mut dyn FnMut(&mut Solution<f64, Y>),
    ) -> ControlFlag<f64, Y> {
        let mut at = |t: f64, solution: &mut Solution<f64, Y>| {
            let y = if t == t_curr {
                y_curr.clone()
            } else if t == t_prev {
                y_prev.clone()
            } else {
                match interpolator.interpolate(t) {
                    Ok(y) => y,
                    Err(_) => return,
                }
            };
            solution.push(t, y);
            flush(solution);
        };
        match self {
            Self::Even { dt, t_end, next } => {
                let (dt, t_end) = (*dt, *t_end);
                let end_tol = 1e-9 * dt;
                // The first multiple at or after the run's start.
                let k = next.get_or_insert_with(|| (t_prev / dt - 1e-9).ceil().max(0.0) as u64);
                loop {
                    let t = *k as f64 * dt;
                    if t > t_curr || t >= t_end - end_tol {
                        break;
                    }
                    if t >= t_prev {
                        at(t, solution);
                    }
                    *k += 1;
                }
                if t_curr == t_end && solution.t.last() != Some(&t_end) {
                    at(t_end, solution);
                }
            }
            Self::At(times, next) => {
                while let Some(&t) = times.get(*next) {
                    if t > t_curr {
                        break;
                    }
                    *next += 1;
                    if t < t_prev {
                        continue;
                    }
                    at(t, solution);
                }
            }
        }
        ControlFlag::Continue
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
            Self::Even { .. } => true,
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
    /// The accepted steps the recorder saw.
    pub(super) accepted: usize,
}

/// The shared state a run's `Recorder` writes to.
pub(super) struct RunLog {
    pub(super) blown_up: Cell<Option<f64>>,
    interrupted: Cell<Option<f64>>,
    events: RefCell<EventWatch>,
    kept: RefCell<Trajectory>,
    last_step: Cell<Option<f64>>,
    metered: Cell<Option<ContactMeter>>,
    accepted: Cell<usize>,
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
            accepted: Cell::new(0),
        }
    }

    pub(super) fn recorder<'a, D: crate::arm::Dynamics + ?Sized>(
        &'a self,
        opts: &SimOptions,
        ode: &'a ArmOde<'_, D>,
        arm: &'a dyn crate::arm::Dynamics,
        fixed_step: bool,
        watch: Option<&'a Watch<'a>>,
        switch: &'a RefCell<Option<(f64, Vec<f64>, String)>>,
    ) -> Recorder<'a> {
        Recorder {
            sampler: Sampler::new(opts),
            t_end: opts.t_end,
            kept: &self.kept,
            m: ode.len,
            last_step: &self.last_step,
            events: &self.events,
            blown_up: &self.blown_up,
            failed_in_step: &ode.failed_in_step,
            fixed_step,
            watch,
            switch,
            calls: 0,
            accepted: &self.accepted,
            contact: ode.contact_switch(),
            meter: ode.contact_meter(),
            metered: &self.metered,
            progress: opts.progress.clone(),
            interrupt: opts.interrupt.clone(),
            interrupted: &self.interrupted,
            rows: opts.rows.clone().map(|s| (s, arm)),
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
            accepted: self.accepted.get(),
        }
    }
}

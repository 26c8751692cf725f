//! A system with joints: integrated in legs of whole sample intervals, the
//! state projected back onto the joints (phi = 0, J qd = 0) at the end of
//! every leg.
//!
//! The accelerations hold J qdd + gamma = 0 exactly, so what drifts is
//! only the integration error of phi and J qd; no stabilising gain is
//! tuned. Each leg is an ordinary run of the chosen solver (any of them),
//! so projection needs no hook inside the steppers; a restart costs a
//! first step estimate (and a Jacobian for the implicit methods) per leg,
//! so legs double while the drift over a leg stays below a tenth of its
//! budget (`drift_budget`); a leg that exceeds it is run again in halves,
//! down to one sample interval, and that interval in up to `MAX_PIECES`
//! pieces, projected after each. The drift is measured at every sample and
//! piece end: the largest is what `ConstraintStats` reports (docs/design.md
//! section 7).

use super::failure::SimFailure;
use super::options::SimOptions;
use super::outcome::{ConstraintStats, SimStats, Trajectory};
use crate::arm::Dynamics;
use crate::constraints::{Drift, drift, project};

/// The drift a leg may leave before the next projection (m or rad): ten
/// times the absolute tolerance, so that the constraint error stays of the
/// order of the integration error asked for.
pub fn drift_budget(opts: &SimOptions) -> f64 {
    10.0 * opts.atol
}

/// The sample times after t0: `output_times`, or the even grid to t_end.
fn sample_times(opts: &SimOptions, t0: f64) -> Vec<f64> {
    let mut times: Vec<f64> = match &opts.output_times {
        Some(t) => t.clone(),
        None => {
            let steps = (opts.t_end / opts.output_dt - 1e-9).ceil().max(1.0) as usize;
            (1..=steps)
                .map(|k| (k as f64 * opts.output_dt).min(opts.t_end))
                .collect()
        }
    };
    times.retain(|&t| t > t0 && t <= opts.t_end);
    times.sort_by(f64::total_cmp);
    times.dedup();
    if times.last() != Some(&opts.t_end) {
        times.push(opts.t_end);
    }
    times
}

/// Most pieces one sample interval is cut into when a single interval
/// drifts past the budget.
const MAX_PIECES: usize = 64;

/// Most sample intervals a leg spans: a leg's samples are held until it is
/// accepted, so this bounds a streamed run's memory.
const MAX_LEG_SAMPLES: usize = 4096;

/// A leg's run: its samples (the last one projected), what it cost, and
/// the largest drift seen at them before projection.
struct Leg {
    traj: Trajectory,
    stats: SimStats,
    worst: Drift,
}

pub(super) fn run(
    arm: &dyn Dynamics,
    t0: f64,
    x0: Vec<f64>,
    opts: &SimOptions,
) -> Result<(Trajectory, SimStats), Box<SimFailure>> {
    let mut traj = Trajectory {
        t: vec![t0],
        x: vec![x0],
        ..Default::default()
    };
    let mut stats = SimStats {
        constraints: Some(ConstraintStats::default()),
        ..SimStats::none(opts.solver)
    };
    let times = sample_times(opts, t0);
    let budget = drift_budget(opts);
    // The legs keep their samples until accepted; this run streams them.
    let leg_opts = SimOptions {
        rows: None,
        ..opts.clone()
    };
    // Legs span `leg_len` sample intervals; a single interval that drifts
    // too far is cut into `pieces`, projected after each.
    let (mut next, mut leg_len, mut pieces) = (0, 1, 1);
    while next < times.len() {
        let t0 = *traj.t.last().expect("the start is a sample");
        let x = traj.x.last().expect("as many states as times").clone();
        let leg_times = &times[next..(next + leg_len).min(times.len())];
        let leg = match run_leg(arm, t0, x, leg_times, pieces, &leg_opts) {
            Ok(leg) => leg,
            Err(mut f) => {
                stats.absorb(&f.stats);
                let mut before = std::mem::take(&mut traj);
                let skip = f.trajectory.t.iter().take_while(|&&t| t <= t0).count();
                before.t.extend(f.trajectory.t.drain(..).skip(skip));
                before.x.extend(f.trajectory.x.drain(..).skip(skip));
                before.events.append(&mut f.trajectory.events);
                stream(arm, opts, &mut before);
                f.trajectory = before;
                f.stats = stats;
                return Err(f);
            }
        };
        stats.absorb(&leg.stats);
        let worst_gap = leg.worst.position_m.max(leg.worst.angle_rad);
        if worst_gap > budget && leg_len > 1 {
            // Over budget: this leg again, in halves.
            leg_len /= 2;
            continue;
        }
        if worst_gap > budget && pieces < MAX_PIECES {
            pieces *= 2;
            continue;
        }
        let cs = stats.constraints.as_mut().expect("set above");
        cs.drift_max_m = cs.drift_max_m.max(leg.worst.position_m);
        cs.drift_max_rad = cs.drift_max_rad.max(leg.worst.angle_rad);
        cs.velocity_drift_max = cs.velocity_drift_max.max(leg.worst.velocity);
        cs.projections += leg.stats.constraints.map_or(0, |c| c.projections);
        let t_end = leg.traj.t.last().copied();
        traj.events.extend(leg.traj.events);
        traj.t.extend(leg.traj.t);
        traj.x.extend(leg.traj.x);
        stream(arm, opts, &mut traj);
        // A terminal event ended the leg early: the run ends there.
        if t_end < leg_times.last().copied() {
            break;
        }
        next += leg_times.len();
        // Longer legs (or fewer pieces) while the drift stays well inside
        // its budget.
        if worst_gap < 0.1 * budget {
            if pieces > 1 {
                pieces /= 2;
            } else {
                leg_len = (2 * leg_len).min(MAX_LEG_SAMPLES);
            }
        }
    }
    stats.solver = opts.solver;
    Ok((traj, stats))
}

/// A streamed run hands over the samples of its accepted legs (the sink
/// skips those it has) and keeps the last.
fn stream(arm: &dyn Dynamics, opts: &SimOptions, traj: &mut Trajectory) {
    if let Some(sink) = &opts.rows {
        (traj.t.iter().zip(&traj.x)).for_each(|(t, x)| sink.push(arm, *t, x));
        super::rows::keep_last(traj);
    }
}

/// One leg from (t0, x) through `times`, in `pieces` runs when it is one
/// sample interval; the state projected at the end of every run, only the
/// samples kept.
fn run_leg(
    arm: &dyn Dynamics,
    t0: f64,
    x: Vec<f64>,
    times: &[f64],
    pieces: usize,
    opts: &SimOptions,
) -> Result<Leg, Box<SimFailure>> {
    let n = arm.dof();
    let t1 = *times.last().expect("a leg has a sample");
    let stops: Vec<f64> = if times.len() == 1 && pieces > 1 {
        (1..=pieces)
            .map(|k| {
                if k == pieces {
                    t1
                } else {
                    t0 + (t1 - t0) * k as f64 / pieces as f64
                }
            })
            .collect()
    } else {
        vec![t1]
    };
    let mut leg = Leg {
        traj: Trajectory::default(),
        stats: SimStats {
            constraints: Some(ConstraintStats::default()),
            ..SimStats::none(opts.solver)
        },
        worst: Drift::default(),
    };
    let (mut from, mut state) = (t0, x);
    for &stop in &stops {
        let sampled: Vec<f64> = times
            .iter()
            .copied()
            .filter(|&t| t > from && t <= stop)
            .collect();
        let run_opts = SimOptions {
            t_end: stop,
            output_times: Some(if sampled.is_empty() {
                vec![stop]
            } else {
                sampled
            }),
            ..opts.clone()
        };
        let (mut seg, more) = super::run_from(arm, from, state, &run_opts)?;
        leg.stats.absorb(&more);
        let skip = seg.t.iter().take_while(|&&t| t <= from).count();
        for (t, x) in seg.t.iter().zip(&seg.x).skip(skip) {
            let gap = drift(arm, *t, &x[..n], &x[n..]);
            leg.worst.position_m = leg.worst.position_m.max(gap.position_m);
            leg.worst.angle_rad = leg.worst.angle_rad.max(gap.angle_rad);
            leg.worst.velocity = leg.worst.velocity.max(gap.velocity);
        }
        let (Some(t_end), Some(mut end)) = (seg.t.pop(), seg.x.pop()) else {
            return Ok(leg);
        };
        let (q, qd) = end.split_at_mut(n);
        if let Err(e) = project(arm, t_end, q, qd, 1e-12) {
            return Err(Box::new(SimFailure {
                t_reached: t_end,
                last_step_s: None,
                reason: format!(
                    "the state could not be put back on the joints (row {} off by {:.3e} after {} iterations)",
                    e.row, e.residual, e.iterations
                ),
                suggestion: "tighten --rtol and --atol, or sample more often (--output-dt)".into(),
                state: end,
                trajectory: leg.traj,
                stats: leg.stats,
            }));
        }
        if let Some(c) = leg.stats.constraints.as_mut() {
            c.projections += 1;
        }
        leg.traj.events.extend(seg.events);
        for (t, x) in seg.t.into_iter().zip(seg.x).skip(skip) {
            if times.contains(&t) {
                leg.traj.t.push(t);
                leg.traj.x.push(x);
            }
        }
        // The end of a piece is kept only when it is a sample (or where a
        // terminal event stopped the run).
        let early = t_end < stop;
        if times.contains(&t_end) || early {
            leg.traj.t.push(t_end);
            leg.traj.x.push(end.clone());
        }
        if early {
            break;
        }
        (from, state) = (t_end, end);
    }
    Ok(leg)
}

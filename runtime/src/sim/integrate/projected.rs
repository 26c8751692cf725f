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
//! down to one sample interval. The drift is measured at every sample: the
//! largest is what `ConstraintStats` reports (docs/design.md section 7).

use serde::Serialize;

use super::failure::SimFailure;
use super::options::SimOptions;
use super::record::{SimStats, Trajectory};
use crate::arm::Dynamics;
use crate::constraints::{Drift, drift, project};

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

/// The drift a leg may leave before the next projection (m or rad): ten
/// times the absolute tolerance, so that the constraint error stays of the
/// order of the integration error asked for.
pub fn drift_budget(opts: &SimOptions) -> f64 {
    10.0 * opts.atol
}

/// The sample times after 0: `output_times`, or the even grid to t_end.
fn sample_times(opts: &SimOptions) -> Vec<f64> {
    let mut times: Vec<f64> = match &opts.output_times {
        Some(t) => t.clone(),
        None => {
            let steps = (opts.t_end / opts.output_dt - 1e-9).ceil().max(1.0) as usize;
            (1..=steps)
                .map(|k| (k as f64 * opts.output_dt).min(opts.t_end))
                .collect()
        }
    };
    times.retain(|&t| t > 0.0 && t <= opts.t_end);
    times.sort_by(f64::total_cmp);
    times.dedup();
    if times.last() != Some(&opts.t_end) {
        times.push(opts.t_end);
    }
    times
}

pub(super) fn run<D: Dynamics + ?Sized>(
    arm: &D,
    x0: Vec<f64>,
    opts: &SimOptions,
) -> Result<(Trajectory, SimStats), Box<SimFailure>> {
    let n = arm.dof();
    let mut traj = Trajectory {
        t: vec![0.0],
        x: vec![x0.clone()],
        events: Vec::new(),
    };
    let mut stats = SimStats {
        solver: opts.solver,
        steps: 0,
        rejected_steps: 0,
        rhs_evaluations: 0,
        jacobian_evaluations: 0,
        wall_s: 0.0,
        switched: None,
        constraints: Some(ConstraintStats::default()),
    };
    let add = |stats: &mut SimStats, more: &SimStats| {
        stats.steps += more.steps;
        stats.rejected_steps += more.rejected_steps;
        stats.rhs_evaluations += more.rhs_evaluations;
        stats.jacobian_evaluations += more.jacobian_evaluations;
        stats.wall_s += more.wall_s;
        if stats.switched.is_none() {
            stats.switched.clone_from(&more.switched);
        }
    };
    let (mut t0, mut x) = (0.0, x0);
    let times = sample_times(opts);
    let budget = drift_budget(opts);
    let (mut next, mut leg_len) = (0, 1);
    while next < times.len() {
        let leg_times = &times[next..(next + leg_len).min(times.len())];
        let t1 = *leg_times.last().expect("a leg has a sample");
        let leg = SimOptions {
            t_end: t1,
            output_times: Some(leg_times.to_vec()),
            ..opts.clone()
        };
        let (mut seg, more) = match super::run_from(arm, t0, x, &leg) {
            Ok(r) => r,
            Err(mut f) => {
                add(&mut stats, &f.stats);
                let mut before = std::mem::take(&mut traj);
                let skip = f.trajectory.t.iter().take_while(|&&t| t <= t0).count();
                before.t.extend(f.trajectory.t.drain(..).skip(skip));
                before.x.extend(f.trajectory.x.drain(..).skip(skip));
                before.events.append(&mut f.trajectory.events);
                f.trajectory = before;
                f.stats = stats;
                return Err(f);
            }
        };
        add(&mut stats, &more);
        let skip = seg.t.iter().take_while(|&&t| t <= t0).count();
        let mut worst = Drift::default();
        for (t, state) in seg.t.iter().zip(&seg.x).skip(skip) {
            let gap = drift(arm, *t, &state[..n], &state[n..]);
            worst.position_m = worst.position_m.max(gap.position_m);
            worst.angle_rad = worst.angle_rad.max(gap.angle_rad);
            worst.velocity = worst.velocity.max(gap.velocity);
        }
        let worst_gap = worst.position_m.max(worst.angle_rad);
        if worst_gap > budget && leg_len > 1 {
            // Over budget: this leg again, in halves.
            leg_len /= 2;
            x = traj.x.last().expect("the start is a sample").clone();
            continue;
        }
        let cs = stats.constraints.as_mut().expect("set above");
        cs.drift_max_m = cs.drift_max_m.max(worst.position_m);
        cs.drift_max_rad = cs.drift_max_rad.max(worst.angle_rad);
        cs.velocity_drift_max = cs.velocity_drift_max.max(worst.velocity);
        let Some(&t_end) = seg.t.last() else {
            break;
        };
        let mut state = seg.x.pop().expect("as many states as times");
        seg.t.pop();
        let (q, qd) = state.split_at_mut(n);
        if let Err(e) = project(arm, t_end, q, qd, 1e-12) {
            return Err(Box::new(SimFailure {
                t_reached: t_end,
                last_step_s: None,
                reason: format!(
                    "the state could not be put back on the joints (row {} off by {:.3e} after {} iterations)",
                    e.row, e.residual, e.iterations
                ),
                suggestion: "tighten --rtol and --atol, or sample more often (--output-dt)".into(),
                state,
                trajectory: traj,
                stats,
            }));
        }
        cs.projections += 1;
        traj.events.extend(seg.events);
        for (t, s) in seg.t.into_iter().zip(seg.x).skip(skip) {
            traj.t.push(t);
            traj.x.push(s);
        }
        traj.t.push(t_end);
        traj.x.push(state);
        // A terminal event ended the leg early: the run ends there.
        if t_end < t1 {
            break;
        }
        next += leg_times.len();
        // Longer legs while the drift stays well inside its budget.
        if worst_gap < 0.1 * budget {
            leg_len *= 2;
        }
        t0 = t1;
        x = traj.x.last().expect("just pushed").clone();
    }
    stats.solver = opts.solver;
    Ok((traj, stats))
}

//! Contacts whose force depends on how they began (Hunt-Crossley damping
//! from a coefficient of restitution reads the impact speed): the run goes
//! in legs between contact switches. Each leg is an ordinary run (with the
//! joints held, if any) that the contact switch stops where a pair begins
//! or ends to touch, located on the solver's dense output; between legs the
//! records are brought up to date (`ContactSet::update_records`), so
//! within a leg the right-hand side is a smooth function of the state.

use super::events::CONTACT_EVENT;
use super::failure::SimFailure;
use super::options::SimOptions;
use super::outcome::{SimStats, Trajectory};
use crate::arm::Dynamics;
use crate::contact::{impact, pair_forces};

/// Legs that end within this time of their start before the run gives up:
/// contacts that switch without the time moving (a chattering contact).
const MAX_STALLED_LEGS: usize = 50;

pub(super) fn run(
    arm: &dyn Dynamics,
    x0: Vec<f64>,
    opts: &SimOptions,
) -> Result<(Trajectory, SimStats), Box<SimFailure>> {
    let set = arm
        .contact()
        .expect("touch::run is for systems with contact");
    let n = arm.dof();
    let mut traj = Trajectory::default();
    let mut stats: Option<SimStats> = None;
    let (mut t0, mut x) = (opts.t0, x0);
    let mut stalled = 0;
    loop {
        let held = set.held_pairs();
        let held_forces: Vec<(usize, f64)> = if held.is_empty() {
            Vec::new()
        } else {
            let (_, f) = impact::held_accelerations(arm, set, t0, &x[..n], &x[n..], &held)
                .map_err(|e| fail_at(t0, &x, &traj, &stats, e.to_string()))?;
            held.into_iter().zip(f).collect()
        };
        let forces = pair_forces(arm, set, t0, &x[..n], &x[n..], true);
        let began = set.update_records(&forces, &held_forces);
        settle_records(arm, set, t0, &x, &forces, &began);
        let hits: Vec<usize> = began
            .into_iter()
            .filter(|&i| impact::restitution(set, i).is_some())
            .collect();
        let mut jumps = Vec::new();
        if !hits.is_empty() {
            let (q, qd) = x.split_at(n);
            let jump = impact::jump(arm, set, t0, q, qd, &hits)
                .map_err(|e| fail_at(t0, &x, &traj, &stats, e.to_string()))?;
            x[n..].copy_from_slice(&jump.qd);
            jumps = jump.impulses;
        }
        // Every leg but the first begins at a switch.
        if !traj.t.is_empty() || !jumps.is_empty() {
            let metered = stats.as_ref().and_then(|s| s.contact);
            traj.switches.push(crate::SwitchRecord {
                t: t0,
                metered_impulse_ns: metered.map_or(0.0, |m| m.normal_impulse_ns),
                jumps,
            });
        }
        let leg = super::run_leg(arm, t0, x.clone(), opts);
        let (mut seg, more) = match leg {
            Ok(r) => r,
            Err(mut f) => {
                extend(&mut traj, f.trajectory, t0);
                f.trajectory = traj;
                add(&mut stats, &f.stats);
                f.stats = stats.expect("set above");
                return Err(f);
            }
        };
        add(&mut stats, &more);
        let switched = seg
            .events
            .last()
            .is_some_and(|e| e.name == CONTACT_EVENT && Some(&e.t) == seg.t.last());
        let end = (seg.t.pop(), seg.x.pop());
        let (Some(t_end), Some(x_end)) = end else {
            break;
        };
        seg.t.push(t_end);
        seg.x.push(x_end.clone());
        let from = traj.t.len();
        extend(&mut traj, seg, t0);
        // While the records are still this leg's (a streamed run's rows
        // took theirs as they were handed over).
        match opts.rows {
            Some(_) => super::rows::keep_last(&mut traj),
            None => crate::contact::record_columns(arm, set, &mut traj, from),
        }
        if !switched || t_end >= opts.t_end {
            break;
        }
        stalled = if t_end - t0 <= 1e-12 * t_end.abs().max(1.0) {
            stalled + 1
        } else {
            0
        };
        if stalled > MAX_STALLED_LEGS {
            return Err(Box::new(SimFailure {
                t_reached: t_end,
                last_step_s: None,
                reason: format!(
                    "contacts switched {MAX_STALLED_LEGS} times at t = {t_end:.6} s without the time moving on (a contact chattering on its surface)"
                ),
                suggestion: "give the contact more damping (a lower restitution or `damping`), or use a law without restitution records (hertz, spring_dashpot)".into(),
                state: x_end,
                trajectory: traj,
                stats: stats.expect("set above"),
            }));
        }
        (t0, x) = (t_end, x_end);
    }
    let mut stats = stats.expect("at least one leg");
    stats.solver = opts.solver;
    Ok((traj, stats))
}

/// A Hunt-Crossley pair that began to touch slowly is damped at the scale
/// of its load (`contact::settle`), and one resting on its surface (gap 0,
/// not approaching: set down there at the start) while pressed in begins
/// to touch so, rather than creep in unrecorded.
fn settle_records(
    arm: &dyn Dynamics,
    set: &crate::contact::ContactSet,
    t: f64,
    x: &[f64],
    forces: &[crate::contact::PairForce<f64>],
    began: &[usize],
) {
    let (q, qd) = x.split_at(arm.dof());
    let touching = set.state().touching;
    for (i, f) in forces.iter().enumerate() {
        let resting = !touching[i] && f.gap == 0.0 && f.approach <= 0.0;
        if !(resting || began.contains(&i)) {
            continue;
        }
        if let Some(v) = crate::contact::settle::settling_speed(arm, set, t, q, qd, i) {
            set.touch_as_impact_at(i, v);
        }
    }
}

/// Append `seg`'s samples after `t0` (where the previous leg ended; all of
/// them for the first leg).
fn extend(traj: &mut Trajectory, seg: Trajectory, t0: f64) {
    let skip = if traj.t.is_empty() {
        0
    } else {
        seg.t.iter().take_while(|&&t| t <= t0).count()
    };
    traj.t.extend(seg.t.into_iter().skip(skip));
    traj.x.extend(seg.x.into_iter().skip(skip));
    traj.events.extend(seg.events);
    traj.switches.extend(seg.switches);
}

fn add(stats: &mut Option<SimStats>, more: &SimStats) {
    let Some(s) = stats else {
        *stats = Some(more.clone());
        return;
    };
    s.absorb(more);
    if let (Some(c), Some(m)) = (s.constraints.as_mut(), more.constraints.as_ref()) {
        c.merge(m);
    }
}

/// A failure between legs (an impact or a held contact that cannot be
/// solved), with what ran so far.
fn fail_at(
    t: f64,
    x: &[f64],
    traj: &Trajectory,
    stats: &Option<SimStats>,
    reason: String,
) -> Box<SimFailure> {
    Box::new(SimFailure {
        t_reached: t,
        last_step_s: None,
        reason: format!("at a contact switch: {reason}"),
        suggestion: "check that the impulse contacts and the joints do not hold one freedom twice"
            .into(),
        state: x.to_vec(),
        trajectory: traj.clone(),
        stats: stats
            .clone()
            .unwrap_or(SimStats::none(crate::solver::Solver::Auto)),
    })
}

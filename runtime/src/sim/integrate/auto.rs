//! `auto`: dopri5 while the arm is not stiff, radau5 once it is, judged
//! from the Jacobian's eigenvalues at the start and every
//! [`AUTO_CHECK_STEPS`](super::AUTO_CHECK_STEPS) accepted steps.

use std::cell::RefCell;

use nalgebra::DMatrix;

use super::dispatch::{run_explicit, simulate_implicit};
use super::failure::SimFailure;
use super::options::SimOptions;
use super::record::{SimStats, SolverSwitch, Trajectory};
use crate::arm::{Dynamics, Workspace};
use crate::jacobian::rhs_jacobian;
use crate::solver::Solver;

/// dopri5 while the arm is not stiff, radau5 once it is.
pub(super) fn run_auto<D: Dynamics + ?Sized>(
    arm: &D,
    t0: f64,
    x0: Vec<f64>,
    opts: &SimOptions,
) -> Result<(Trajectory, SimStats), Box<SimFailure>> {
    let n = arm.dof();
    let analyse_at = |t: f64, x: &[f64]| {
        let mut jac = DMatrix::zeros(2 * n, 2 * n);
        rhs_jacobian(arm, &mut Workspace::new(n), t, &x[..2 * n], &mut jac)
            .ok()
            .map(|_| crate::stiffness::analyse(&jac))
    };
    let implicit_opts = SimOptions {
        solver: Solver::Radau5,
        ..opts.clone()
    };
    let as_auto = |mut stats: SimStats, switch: SolverSwitch| {
        stats.solver = Solver::Auto;
        stats.switched = Some(switch);
        stats
    };
    if let Some(r) = analyse_at(t0, &x0)
        && r.stiffness_ratio > 1000.0
    {
        let (traj, stats) = simulate_implicit(arm, t0, x0, &implicit_opts)?;
        let reason = format!("stiff from the start: {}", r.reason);
        return Ok((
            traj,
            as_auto(
                stats,
                SolverSwitch {
                    at_s: t0,
                    to: Solver::Radau5,
                    reason,
                },
            ),
        ));
    }
    let watch = |x: &[f64], h: f64| -> Option<String> {
        let r = analyse_at(0.0, x)?;
        (r.stiffness_ratio > 1000.0 && h > 0.5 * r.stable_explicit_step_s).then(|| {
            format!(
                "dopri5 held at the stability limit ({h:.2e} s steps) of a stiff arm: {}",
                r.reason
            )
        })
    };
    let switch = RefCell::new(None);
    let explicit_opts = SimOptions {
        solver: Solver::Dopri5,
        ..opts.clone()
    };
    let (mut traj, mut stats) = run_explicit(arm, t0, x0, &explicit_opts, Some(&watch), &switch)?;
    stats.solver = Solver::Auto;
    let Some((t_switch, x_switch, reason)) = switch.take() else {
        return Ok((traj, stats));
    };
    let (rest, more) = simulate_implicit(arm, t_switch, x_switch, &implicit_opts)?;
    traj.events.extend(rest.events);
    for (t, x) in rest.t.into_iter().zip(rest.x) {
        if traj.t.last().is_none_or(|&last| t > last) {
            traj.t.push(t);
            traj.x.push(x);
        }
    }
    let merged = SimStats {
        solver: Solver::Auto,
        steps: stats.steps + more.steps,
        rejected_steps: stats.rejected_steps + more.rejected_steps,
        rhs_evaluations: stats.rhs_evaluations + more.rhs_evaluations,
        jacobian_evaluations: stats.jacobian_evaluations + more.jacobian_evaluations,
        wall_s: stats.wall_s + more.wall_s,
        switched: None,
        constraints: None,
        contact: super::record::ContactMeter::then(stats.contact, more.contact),
    };
    Ok((
        traj,
        as_auto(
            merged,
            SolverSwitch {
                at_s: t_switch,
                to: Solver::Radau5,
                reason,
            },
        ),
    ))
}

//! `auto`: dopri5 while the arm is not stiff; once it is, the implicit
//! method its stiffness report recommends (generalized-alpha for a
//! structure whose fast modes barely decay, radau5 otherwise), judged from
//! the Jacobian's eigenvalues at the start and every
//! [`AUTO_CHECK_STEPS`](super::super::AUTO_CHECK_STEPS) accepted steps.

use std::cell::RefCell;

use nalgebra::DMatrix;

use super::super::drivers::RunResult;
use super::super::options::SimOptions;
use super::super::outcome::{SimStats, SolverSwitch};
use super::{Integrator, dopri5, of};
use crate::arm::{Dynamics, Workspace};
use crate::jacobian::rhs_jacobian;
use crate::solver::Solver;

pub(super) struct Auto;

/// A stiffness ratio above this makes the arm stiff for `auto`.
const STIFF_RATIO: f64 = 1000.0;

/// The tightest relative tolerance at which `auto` takes generalized-alpha
/// for a lightly damped structure (undamped, the pcs right-angle frame at
/// the default 1e-6: genalpha 6218 steps, dopri5 2130, radau5 2904).
const GENALPHA_RTOL: f64 = 1e-4;

impl Integrator for Auto {
    fn run(&self, arm: &dyn Dynamics, t0: f64, x0: Vec<f64>, opts: &SimOptions) -> RunResult {
        let n = arm.dof();
        let analyse_at = |t: f64, x: &[f64]| {
            let mut jac = DMatrix::zeros(2 * n, 2 * n);
            rhs_jacobian(arm, &mut Workspace::new(n), t, &x[..2 * n], &mut jac)
                .ok()
                .and_then(|_| crate::stiffness::analyse(&jac))
        };
        // The implicit method a stiffness report recommends; generalized-
        // alpha, second order, only at an engineer's tolerance (rtol 1e-4
        // or looser): tighter, radau5's fifth order takes the larger steps.
        let second_order = arm.internal_len() == 0;
        let implicit = |r: &crate::stiffness::StiffnessReport| match r.recommended_solver {
            "genalpha" if opts.rtol >= GENALPHA_RTOL && second_order => Solver::GenAlpha,
            _ => Solver::Radau5,
        };
        // The report's reason, and why radau5 where it recommends
        // generalized-alpha.
        let why = |r: &crate::stiffness::StiffnessReport| match (r.recommended_solver, implicit(r))
        {
            ("genalpha", Solver::Radau5) if !second_order => format!(
                "{}; radau5 instead, for its first-order states (relaxed forces)",
                r.reason
            ),
            ("genalpha", Solver::Radau5) => format!(
                "{}; radau5 instead at rtol {:e}, tighter than {GENALPHA_RTOL:e}: its fifth order takes the larger steps",
                r.reason, opts.rtol
            ),
            _ => r.reason.clone(),
        };
        let as_auto = |mut stats: SimStats, at_s: f64, to: Solver, reason: String| {
            stats.solver = Solver::Auto;
            stats.switched = Some(SolverSwitch { at_s, to, reason });
            stats
        };
        if let Some(r) = analyse_at(t0, &x0)
            && r.stiffness_ratio > STIFF_RATIO
        {
            let reason = format!("stiff from the start: {}", why(&r));
            let to = implicit(&r);
            let opts = SimOptions {
                solver: to,
                ..opts.clone()
            };
            return match of(to).run(arm, t0, x0, &opts) {
                Ok((traj, stats)) => Ok((traj, as_auto(stats, t0, to, reason))),
                Err(mut f) => {
                    f.stats = as_auto(f.stats, t0, to, reason);
                    Err(f)
                }
            };
        }
        // The watch says why it stops dopri5; the method to go on with
        // rides beside it.
        let chosen = std::cell::Cell::new(Solver::Radau5);
        let watch = |x: &[f64], h: f64| -> Option<String> {
            let r = analyse_at(0.0, x)?;
            (r.stiffness_ratio > STIFF_RATIO && h > 0.5 * r.stable_explicit_step_s).then(|| {
                chosen.set(implicit(&r));
                format!(
                    "dopri5 held at the stability limit ({h:.2e} s steps) of a stiff arm: {}",
                    why(&r)
                )
            })
        };
        let switch = RefCell::new(None);
        let explicit_opts = SimOptions {
            solver: Solver::Dopri5,
            ..opts.clone()
        };
        let (mut traj, mut stats) =
            dopri5::watched(arm, t0, x0, &explicit_opts, Some(&watch), &switch)?;
        stats.solver = Solver::Auto;
        let Some((t_switch, x_switch, reason)) = switch.take() else {
            return Ok((traj, stats));
        };
        let to = chosen.get();
        let implicit_opts = SimOptions {
            solver: to,
            ..opts.clone()
        };
        let (rest, more, failed) = match of(to).run(arm, t_switch, x_switch, &implicit_opts) {
            Ok((rest, more)) => (rest, more, None),
            // The implicit leg failed: the failure reports both legs.
            Err(mut f) => (std::mem::take(&mut f.trajectory), f.stats.clone(), Some(f)),
        };
        traj.events.extend(rest.events);
        for (t, x) in rest.t.into_iter().zip(rest.x) {
            if traj.t.last().is_none_or(|&last| t > last) {
                traj.t.push(t);
                traj.x.push(x);
            }
        }
        stats.absorb(&more);
        stats.switched = None;
        stats.constraints = None;
        let stats = as_auto(stats, t_switch, to, reason);
        match failed {
            None => Ok((traj, stats)),
            Some(mut f) => {
                f.trajectory = traj;
                f.stats = stats;
                Err(f)
            }
        }
    }
}

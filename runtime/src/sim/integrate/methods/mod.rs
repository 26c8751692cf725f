//! The integration methods: one trait, one file per method, and the one
//! table ([`of`]) that maps each [`Solver`] to its method. A new method is
//! a file here, a variant with its name in `crate::solver`, and a line in
//! the table; `tests/suite/integrators.rs` runs every solver of that table
//! through the same conformance checks.

mod auto;
mod bdf;
pub mod bs23;
mod dop853;
mod dopri5;
mod esdirk;
mod euler;
pub mod gauss;
pub mod genalpha;
pub mod radau5;
mod radau5_fixed;
mod rk4;
pub mod trbdf2;

use super::drivers::{OwnIntegrator, RunResult, run_own};
use super::options::SimOptions;
use crate::arm::Dynamics;
use crate::solver::Solver;

/// A method that integrates an arm from (t0, x0) to `opts.t_end`,
/// sampling as `opts` asks and explaining a failure.
pub(super) trait Integrator: Sync {
    fn run(&self, arm: &dyn Dynamics, t0: f64, x0: Vec<f64>, opts: &SimOptions) -> RunResult;
}

/// A stepper written here (`bs23`, `radau5`, `trbdf2`, `genalpha`), run through the
/// recorder by `drivers::run_own`.
pub(super) struct Own(pub OwnIntegrator);

impl Integrator for Own {
    fn run(&self, arm: &dyn Dynamics, t0: f64, x0: Vec<f64>, opts: &SimOptions) -> RunResult {
        run_own(arm, t0, x0, opts, self.0)
    }
}

/// The method of each solver.
pub(super) fn of(solver: Solver) -> &'static dyn Integrator {
    match solver {
        Solver::Dopri5 => &dopri5::Dopri5,
        Solver::Dop853 => &dop853::Dop853,
        Solver::Bs23 => &Own(bs23::integrate),
        Solver::Rk4 => &rk4::Rk4,
        Solver::Euler => &euler::Euler,
        Solver::Radau5 => &Own(radau5::integrate),
        Solver::Radau5Fixed => &Own(radau5_fixed::integrate),
        Solver::Bdf => &bdf::Bdf,
        Solver::Trbdf2 => &Own(trbdf2::integrate),
        Solver::Esdirk => &esdirk::Esdirk,
        Solver::GenAlpha => &Own(genalpha::integrate),
        Solver::Gauss => &Own(gauss::integrate),
        Solver::Auto => &auto::Auto,
    }
}

/// x'' = -w^2 x as y = (x, v): the undamped oscillator the fixed-step
/// methods' own tests step through.
#[cfg(test)]
pub(super) struct Oscillator(pub f64);

#[cfg(test)]
impl super::stepper::OdeSystem for Oscillator {
    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) {
        dy[0] = y[1];
        dy[1] = -self.0 * self.0 * y[0];
    }
    fn jacobian(&mut self, _t: f64, _y: &[f64], j: &mut nalgebra::DMatrix<f64>) {
        j.fill(0.0);
        j[(0, 1)] = 1.0;
        j[(1, 0)] = -self.0 * self.0;
    }
}

/// `steps` steps of `method` at the fixed step h on [`Oscillator`]`(w)`
/// from x = 1, v = 0, the stages solved to `rtol`: the last state and
/// the counts.
#[cfg(test)]
pub(super) fn oscillate(
    method: OwnIntegrator,
    (w, h, steps): (f64, f64, usize),
    rtol: f64,
) -> (Vec<f64>, super::stepper::Counts) {
    let opts = super::stepper::Options {
        t_end: steps as f64 * h,
        rtol,
        atol: 1e-3 * rtol,
        max_steps: 100 * steps,
        rho_inf: 1.0,
        dt: h,
        positions: 1,
    };
    let mut last = vec![];
    let mut on_step =
        |_: f64,
         _: f64,
         _: &[f64],
         y: &[f64],
         _: &mut dyn differential_equations::interpolate::Interpolation<f64, Vec<f64>>| {
            last = y.to_vec();
            true
        };
    let mut counts = super::stepper::Counts::default();
    method(
        &mut Oscillator(w),
        0.0,
        vec![1.0, 0.0],
        &opts,
        &mut on_step,
        &mut counts,
    )
    .unwrap();
    (last, counts)
}

#[cfg(test)]
mod tests {
    use differential_equations::interpolate::Interpolation;
    use nalgebra::DMatrix;

    use super::super::stepper::{Counts, OdeSystem, Options};
    use super::OwnIntegrator;

    /// x'' = -w^2 x + F(t) / m at rest in equilibrium under F0 until a
    /// ramp takes F off over tau (a tip weight released).
    struct Released {
        w: f64,
        f0: f64,
        tau: f64,
    }

    impl Released {
        fn force(&self, t: f64) -> f64 {
            self.f0 * (1.0 - t / self.tau).clamp(0.0, 1.0)
        }
        /// The closed form after the ramp: the free swing from the state
        /// the ramp leaves, x(tau) = x0 sin(w tau) / (w tau), v(tau) =
        /// x0 (cos(w tau) - 1) / tau, x0 = F0 / w^2.
        fn exact(&self, t: f64) -> f64 {
            let (w, tau) = (self.w, self.tau);
            let x0 = self.f0 / (w * w);
            let a = x0 * (w * tau).sin() / (w * tau);
            let b = x0 * ((w * tau).cos() - 1.0) / tau;
            a * (w * (t - tau)).cos() + b / w * (w * (t - tau)).sin()
        }
    }

    impl OdeSystem for Released {
        fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) {
            dy[0] = y[1];
            dy[1] = -self.w * self.w * y[0] + self.force(t);
        }
        fn jacobian(&mut self, _t: f64, _y: &[f64], j: &mut DMatrix<f64>) {
            j.fill(0.0);
            j[(0, 1)] = 1.0;
            j[(1, 0)] = -self.w * self.w;
        }
    }

    /// Every adaptive method of ours started at rest in equilibrium (to a
    /// static solve's residual), the load released over 0.1 ms, 50
    /// periods: the first step must come from what the start's rate does
    /// next, not from the rate alone, which is nearly zero and made a
    /// step of the whole span. generalized-alpha at rho_inf = 0 then
    /// annihilated the swing within that one step and, its error measured
    /// from accelerations nearly zero at both ends, accepted it: the arm
    /// at rest, unloaded, after one step. Here it must swing: its largest
    /// excursion over the last period near the closed form's amplitude.
    #[test]
    fn a_start_at_rest_sees_a_quick_release() {
        let methods: [(&str, OwnIntegrator); 3] = [
            ("bs23", super::bs23::integrate),
            ("trbdf2", super::trbdf2::integrate),
            ("genalpha", super::genalpha::integrate),
        ];
        for (name, integrate) in methods {
            let mut sys = Released {
                w: 2.0 * std::f64::consts::PI,
                f0: 1.0,
                tau: 1e-4,
            };
            let x0 = sys.f0 / (sys.w * sys.w) * (1.0 + 1e-9);
            let t_end = 50.0;
            let opts = Options {
                t_end,
                rtol: 1e-3,
                atol: 1e-6,
                max_steps: 1_000_000,
                rho_inf: 0.0,
                dt: 0.0,
                positions: 1,
            };
            let mut swing = 0.0f64;
            let mut on_step =
                |_: f64, t: f64, _: &[f64], y: &[f64], _: &mut dyn Interpolation<f64, Vec<f64>>| {
                    if t >= t_end - 1.0 {
                        swing = swing.max(y[0].abs());
                    }
                    true
                };
            let mut counts = Counts::default();
            integrate(
                &mut sys,
                0.0,
                vec![x0, 0.0],
                &opts,
                &mut on_step,
                &mut counts,
            )
            .unwrap();
            // The amplitude from two samples a quarter period apart.
            let amplitude = (sys.exact(t_end).powi(2) + sys.exact(t_end + 0.25).powi(2)).sqrt();
            eprintln!(
                "{name}: {} steps, swing {swing:.4e} of {amplitude:.4e}",
                counts.accepted
            );
            assert!(
                swing > 0.5 * amplitude && counts.accepted > 100,
                "{name}: {} steps, the last period's largest |x| {swing:e} of {amplitude:e}",
                counts.accepted
            );
        }
    }
}

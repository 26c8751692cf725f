//! Forward sensitivities of a run to parameters, by the staggered direct
//! method (Caracotsios and Stewart; SUNDIALS' CVODES offers it too): the
//! state is integrated by radau5 as any run is, and after each accepted
//! step the sensitivities s_j = dx/dtheta_j, which obey the linear system
//!
//!   s_j' = J(t, x(t)) s_j + df/dtheta_j (t, x(t)),
//!
//! are carried over the same step by the two-stage Radau IIA collocation
//! (L-stable, so the arm's stiff modes decay in s as in x). J and
//! df/dtheta are evaluated once a step, at its end, and taken linear in
//! time within it (the step's start has them from the step before): the
//! scheme is then of order 2 in their variation, and costs one Jacobian
//! a step, where the Jacobians are nearly all of its cost. J is the exact Jacobian
//! of the right-hand side (`rhs_jacobian`, from the generated `Jvp`
//! kernel); df/dtheta_j is a centred difference quotient of the
//! accelerations of two arms whose parameters differ by +-delta_j along
//! theta_j (CVODES' default for the parameter part): a parameter reaches
//! the kernels through the parameter vector, inputs and derived values,
//! which the caller builds for each perturbed value. A viscoelastic arm's
//! relaxed forces are states like any other. A model with joints or
//! contact is not covered: its runs switch and project.

use differential_equations::error::Error;
use differential_equations::interpolate::Interpolation;
use nalgebra::{DMatrix, DVector};

use super::methods::radau5;
use super::ode::ArmOde;
use super::stepper::{Counts, Options};
use crate::arm::{AccelError, Dynamics, Workspace};
use crate::jacobian::state_jacobian;
use crate::relaxed_forces::state_rate;

/// A parameter's two perturbed arms: the same model at theta_j + delta
/// and theta_j - delta, every other value alike.
pub struct Perturbed<'a> {
    pub plus: &'a dyn Dynamics,
    pub minus: &'a dyn Dynamics,
    pub delta: f64,
}

/// The state and its sensitivities at the asked times.
#[derive(Clone, Debug, Default)]
pub struct Sensitivities {
    pub t: Vec<f64>,
    /// x = [q, qd] at each time.
    pub x: Vec<Vec<f64>>,
    /// s[i][j]: dx/dtheta_j at time i (2n values).
    pub s: Vec<Vec<Vec<f64>>>,
    pub steps: usize,
    pub rejected: usize,
}

/// Why a sensitivity run stopped before its end, with what it reached.
#[derive(Debug)]
pub struct SensitivityFailure {
    pub t: f64,
    pub reason: String,
    pub partial: Sensitivities,
}

impl std::fmt::Display for SensitivityFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "the run stopped at t = {} s: {}", self.t, self.reason)
    }
}

/// Two-stage Radau IIA: nodes and coefficients.
const C1: f64 = 1.0 / 3.0;
const A: [[f64; 2]; 2] = [[5.0 / 12.0, -1.0 / 12.0], [3.0 / 4.0, 1.0 / 4.0]];

/// What the step callback carries from step to step.
struct Carried<'a> {
    arm: &'a dyn Dynamics,
    params: &'a [Perturbed<'a>],
    ws: Workspace,
    /// dx/dtheta_j at the start of the step.
    s: Vec<DVector<f64>>,
    times: &'a [f64],
    next: usize,
    out: Sensitivities,
    error: Option<AccelError>,
    /// J and df/dtheta at the end of the last step.
    last: Option<Linearised>,
}

/// J and the parameter columns df/dtheta_j at a time.
struct Linearised {
    t: f64,
    j: DMatrix<f64>,
    b: Vec<DVector<f64>>,
}

impl Carried<'_> {
    /// J and the parameter columns df/dtheta_j at (t, x).
    fn linearised(&mut self, t: f64, x: &[f64]) -> Result<Linearised, AccelError> {
        let len = x.len();
        let mut j = DMatrix::zeros(len, len);
        state_jacobian(self.arm, &mut self.ws, t, x, &mut j)?;
        let (mut up, mut down) = (vec![0.0; len], vec![0.0; len]);
        let mut b = Vec::with_capacity(self.params.len());
        for p in self.params {
            state_rate(p.plus, &mut self.ws, t, x, &mut up)?;
            state_rate(p.minus, &mut self.ws, t, x, &mut down)?;
            b.push(DVector::from_iterator(
                len,
                (up.iter().zip(&down)).map(|(a, b)| (a - b) / (2.0 * p.delta)),
            ));
        }
        // The arm's own relaxed forces again (the perturbed arms' calls
        // set theirs).
        self.arm.set_internal(&x[2 * self.arm.dof()..]);
        Ok(Linearised { t, j, b })
    }

    /// Carry s over the step [t0, t1] and sample the asked times in it.
    fn step(
        &mut self,
        t0: f64,
        t1: f64,
        x1: &[f64],
        dense: &mut dyn Interpolation<f64, Vec<f64>>,
    ) -> Result<(), AccelError> {
        let h = t1 - t0;
        let start = match self.last.take() {
            Some(l) if l.t == t0 => l,
            _ => {
                let x0 = dense.interpolate(t0).unwrap_or_else(|_| x1.to_vec());
                self.linearised(t0, &x0)?
            }
        };
        let end = self.linearised(t1, x1)?;
        // At the first stage, C1 of the way along.
        let j1 = &start.j * (1.0 - C1) + &end.j * C1;
        let b1: Vec<DVector<f64>> = (start.b.iter().zip(&end.b))
            .map(|(a, b)| a * (1.0 - C1) + b * C1)
            .collect();
        let (j2, b2) = (&end.j, &end.b);
        let m = x1.len();
        // [I - h a11 J1, -h a12 J2; -h a21 J1, I - h a22 J2] [S1; S2] = rhs
        let mut k = DMatrix::identity(2 * m, 2 * m);
        for (bi, row) in A.iter().enumerate() {
            for (bj, (a, jm)) in row.iter().zip([&j1, j2]).enumerate() {
                let mut block = k.view_mut((bi * m, bj * m), (m, m));
                block -= jm * (h * a);
            }
        }
        let lu = k.lu();
        let mut stages = Vec::with_capacity(self.s.len());
        for (p, s0) in self.s.iter().enumerate() {
            let mut rhs = DVector::zeros(2 * m);
            for (bi, row) in A.iter().enumerate() {
                let v = s0 + (&b1[p] * row[0] + &b2[p] * row[1]) * h;
                rhs.rows_mut(bi * m, m).copy_from(&v);
            }
            let z = lu.solve(&rhs).ok_or(AccelError::NonFinite {
                t: t1,
                what: "sensitivities (their step's matrix is singular)",
            })?;
            stages.push((z.rows(0, m).into_owned(), z.rows(m, m).into_owned()));
        }
        // The asked times in (t0, t1]: x from the dense output, s from the
        // collocation polynomial through (t0, s0), (tc, S1), (t1, S2).
        while self.next < self.times.len() && self.times[self.next] <= t1 + 1e-12 * h.abs() {
            let t = self.times[self.next];
            let x = if t >= t1 {
                x1.to_vec()
            } else {
                dense.interpolate(t).unwrap_or_else(|_| x1.to_vec())
            };
            let tau = (t - t0) / h;
            // Lagrange weights on the nodes 0, C1, 1.
            let w0 = (tau - C1) * (tau - 1.0) / C1;
            let w1 = tau * (tau - 1.0) / (C1 * (C1 - 1.0));
            let w2 = tau * (tau - C1) / (1.0 - C1);
            let s = (self.s.iter().zip(&stages))
                .map(|(s0, (s1, s2))| (s0 * w0 + s1 * w1 + s2 * w2).as_slice().to_vec())
                .collect();
            self.record(t, x, s);
        }
        self.s = stages.into_iter().map(|(_, s2)| s2).collect();
        self.last = Some(end);
        Ok(())
    }

    fn record(&mut self, t: f64, x: Vec<f64>, s: Vec<Vec<f64>>) {
        self.out.t.push(t);
        self.out.x.push(x);
        self.out.s.push(s);
        self.next += 1;
    }
}

/// The run of `arm` from (t0, x0) to `opts.t_end` by radau5, with the
/// sensitivities to the parameters of `params` from `s0` (dx0/dtheta_j),
/// sampled at `times` (ascending, within [t0, t_end]).
pub fn forward_sensitivities(
    arm: &dyn Dynamics,
    params: &[Perturbed<'_>],
    t0: f64,
    x0: Vec<f64>,
    s0: Vec<Vec<f64>>,
    times: &[f64],
    opts: &Options,
) -> Result<Sensitivities, Box<SensitivityFailure>> {
    assert_eq!(s0.len(), params.len(), "one start sensitivity a parameter");
    let ode = ArmOde::new(arm);
    let mut carried = Carried {
        arm,
        params,
        ws: Workspace::new(arm.dof()),
        s: s0.iter().map(|s| DVector::from_column_slice(s)).collect(),
        times,
        next: 0,
        out: Sensitivities::default(),
        error: None,
        last: None,
    };
    while carried.next < times.len() && times[carried.next] <= t0 {
        carried.record(times[carried.next], x0.clone(), s0.clone());
    }
    let mut counts = Counts::default();
    let result = {
        let mut on_step = |t_prev: f64,
                           t: f64,
                           _y_prev: &[f64],
                           y: &[f64],
                           dense: &mut dyn Interpolation<f64, Vec<f64>>| {
            match carried.step(t_prev, t, y, dense) {
                Ok(()) => true,
                Err(e) => {
                    carried.error = Some(e);
                    false
                }
            }
        };
        radau5::integrate(&mut &ode, t0, x0, opts, &mut on_step, &mut counts)
    };
    carried.out.steps = counts.accepted;
    carried.out.rejected = counts.rejected;
    let reached = carried.out.t.last().copied().unwrap_or(t0);
    let failure =
        |t: f64, reason: String, partial| Box::new(SensitivityFailure { t, reason, partial });
    if let Some(e) = carried.error.take() {
        return Err(failure(reached, e.to_string(), carried.out));
    }
    match result {
        Err(e) => {
            let (t, why) = match e {
                Error::MaxSteps { t, .. } => (t, "the step budget is spent".to_string()),
                Error::StepSize { t, .. } => (t, "the step size fell below its floor".to_string()),
                other => (reached, format!("{other:?}")),
            };
            let why = match ode.first_error.borrow().as_ref() {
                Some(e) => format!("{why} ({e})"),
                None => why,
            };
            Err(failure(t, why, carried.out))
        }
        Ok(()) if carried.next < times.len() => Err(failure(
            reached,
            "the run ended before the last asked time".into(),
            carried.out,
        )),
        Ok(()) => Ok(carried.out),
    }
}

/// dx0/dtheta_j of a start in equilibrium at time t (h(q0, 0) = 0): the
/// tangent stiffness K = dh/dq gives dq0/dtheta_j = -K^-1 dh/dtheta_j,
/// the rates stay zero. An elastic arm's (a viscoelastic arm's start
/// moves its relaxed forces too: the caller differences its starts).
pub fn static_sensitivities(
    arm: &dyn Dynamics,
    params: &[Perturbed<'_>],
    t: f64,
    q: &[f64],
) -> Result<Vec<Vec<f64>>, AccelError> {
    let n = q.len();
    let zeros = vec![0.0; n];
    let mut k = vec![0.0; n * n];
    arm.stiffness(t, q, &mut k);
    let lu = DMatrix::from_row_slice(n, n, &k).lu();
    let (mut up, mut down) = (DVector::zeros(n), DVector::zeros(n));
    params
        .iter()
        .map(|p| {
            p.plus.bias(t, q, &zeros, &mut up);
            p.minus.bias(t, q, &zeros, &mut down);
            let dh = (&up - &down) / (2.0 * p.delta);
            let dq = lu.solve(&-dh).ok_or(AccelError::NonFinite {
                t,
                what: "start sensitivities (the stiffness is singular)",
            })?;
            Ok(dq.iter().copied().chain(zeros.iter().copied()).collect())
        })
        .collect()
}

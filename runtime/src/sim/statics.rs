//! Static equilibrium: h(q, 0) = 0 (gravity, elastic and applied forces
//! balance; with joints h + J^T lambda = 0 and phi = 0), by Newton's method on the generalised forces with the analytic
//! tangent stiffness K = dh/dq (`Dynamics::stiffness`), a backtracking line
//! search, and load continuation: the load parameters (gravity, applied
//! forces) are scaled from 0 to 1 in steps that grow on success and shrink on
//! failure, so that large deflections converge.

use nalgebra::{DMatrix, DVector};
use serde::Serialize;

use crate::arm::Dynamics;
use crate::constraints;
use crate::kernels::KernelKind;

#[derive(Clone, Debug)]
pub struct StaticOptions {
    /// Converged when the Newton step is below `step_tol * (1 + |q|)`.
    pub step_tol: f64,
    /// Newton iterations per load step.
    pub max_iterations: usize,
    /// Smallest load increment tried before giving up.
    pub min_load_step: f64,
}

impl Default for StaticOptions {
    fn default() -> Self {
        Self {
            step_tol: 1e-12,
            max_iterations: 40,
            min_load_step: 1e-4,
        }
    }
}

#[derive(Clone, Debug, Serialize)]
pub struct StaticSolution {
    pub q: Vec<f64>,
    /// max |h(q, 0) + J^T lambda| (and |phi|) at the solution.
    pub residual: f64,
    /// The joint forces (rows as `ModelInfo::constraints`; empty without
    /// joints).
    pub lambda: Vec<f64>,
    /// Newton iterations over all load steps.
    pub iterations: usize,
    /// Accepted load steps.
    pub load_steps: usize,
}

#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error(
    "the static solve did not converge: the last converged load fraction is {last_fraction:.4} \
     (0 = unloaded, 1 = the full load); {reason}. Try more elements, a smaller load, or a starting \
     configuration closer to the answer (--q0)"
)]
pub struct StaticError {
    pub last_fraction: f64,
    pub reason: String,
    /// The configuration at the last converged load fraction.
    pub q: Vec<f64>,
}

fn inf_norm(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m, x| m.max(x.abs()))
}

/// h(q, 0): the static generalised forces, from the `MassBias` kernel.
fn static_forces(d: &dyn Dynamics, q: &[f64], g: &mut [f64]) {
    let n = q.len();
    let mut packed = vec![0.0; n * (n + 1) / 2 + n];
    let zeros = vec![0.0; n];
    d.eval_kernel(KernelKind::MassBias, 0.0, q, &zeros, &mut packed);
    g.copy_from_slice(&packed[n * (n + 1) / 2..]);
    crate::contact::subtract_from_bias(d, 0.0, q, &zeros, g);
}

/// The static residual of z = [q, lambda]: h(q, 0) + J^T lambda and, with
/// joints, phi(q) (section 7 of docs/design.md).
fn residual(d: &dyn Dynamics, z: &[f64], r: &mut [f64]) {
    let n = d.dof();
    let (q, lambda) = z.split_at(n);
    static_forces(d, q, &mut r[..n]);
    if lambda.is_empty() {
        return;
    }
    let c = constraints::evaluate(d, 0.0, q, &vec![0.0; n]);
    let jt_l = c.jac.transpose() * DVector::from_column_slice(lambda);
    for i in 0..n {
        r[i] += jt_l[i];
    }
    r[n..].copy_from_slice(&c.phi);
}

/// The residual's Jacobian: K = dh/dq (analytic), and with joints
/// [K + d(J^T lambda)/dq, J^T; J, 0], the middle term by central
/// differences of the constraint kernel.
fn tangent(d: &dyn Dynamics, z: &[f64]) -> DMatrix<f64> {
    let n = d.dof();
    let (q, lambda) = z.split_at(n);
    let m = lambda.len();
    let mut kbuf = vec![0.0; n * n];
    d.stiffness(0.0, q, &mut kbuf);
    let mut k = DMatrix::zeros(n + m, n + m);
    k.view_mut((0, 0), (n, n))
        .copy_from(&DMatrix::from_row_slice(n, n, &kbuf));
    if m == 0 {
        return k;
    }
    let c = constraints::evaluate(d, 0.0, q, &vec![0.0; n]);
    k.view_mut((0, n), (n, m)).copy_from(&c.jac.transpose());
    k.view_mut((n, 0), (m, n)).copy_from(&c.jac);
    let g = constraints::geometric_stiffness(d, q, lambda);
    let mut top = k.view_mut((0, 0), (n, n));
    top += g;
    k
}

/// Newton from `z` = [q, lambda] at the current parameters. Ok:
/// (iterations, residual).
fn newton(d: &dyn Dynamics, z: &mut [f64], opts: &StaticOptions) -> Result<(usize, f64), String> {
    let len = z.len();
    let mut g = vec![0.0; len];
    let mut trial = vec![0.0; len];
    let mut g_trial = vec![0.0; len];
    residual(d, z, &mut g);
    let mut k = tangent(d, z);
    for it in 1..=opts.max_iterations {
        if g.iter().chain(k.iter()).any(|v| !v.is_finite()) {
            return Err("non-finite forces or stiffness".into());
        }
        let step = match k.clone().lu().solve(&DVector::from_column_slice(&g)) {
            Some(s) => s,
            None => {
                return Err(
                    "the tangent stiffness is singular (a buckling or snap-through point, or dependent joints?)"
                        .into(),
                );
            }
        };
        // Backtracking on the residual norm.
        let r0 = inf_norm(&g);
        let mut alpha = 1.0;
        loop {
            for i in 0..len {
                trial[i] = z[i] - alpha * step[i];
            }
            residual(d, &trial, &mut g_trial);
            let r = inf_norm(&g_trial);
            if r.is_finite() && (r < r0 || alpha < 1.0 / 64.0 || r0 == 0.0) {
                break;
            }
            alpha *= 0.5;
        }
        z.copy_from_slice(&trial);
        residual(d, z, &mut g);
        k = tangent(d, z);
        let dz = alpha * inf_norm(step.as_slice());
        if dz <= opts.step_tol * (1.0 + inf_norm(z)) {
            return Ok((it, inf_norm(&g)));
        }
    }
    Err(format!(
        "Newton did not converge in {} iterations",
        opts.max_iterations
    ))
}

/// Static equilibrium at the model's full load, from `q0` (a viscoelastic
/// arm's at its long-term moduli). The model's parameters are left as
/// they were.
pub fn solve_static(
    d: &mut dyn Dynamics,
    q0: &[f64],
    opts: &StaticOptions,
) -> Result<StaticSolution, StaticError> {
    let base = d.base_params().to_vec();
    // A viscoelastic arm held at rest has relaxed: its long-term moduli.
    let long_term = d
        .relaxation()
        .map_or_else(|| base.clone(), |r| r.long_term(&base));
    let loads = d.info().loads.clone();
    let scaled = |lambda: f64| {
        let mut p = long_term.clone();
        for &i in &loads {
            p[i] *= lambda;
        }
        p
    };
    let n = q0.len();
    // With joints the unknowns are [q, lambda].
    let mut q = q0.to_vec();
    q.resize(n + d.info().constraints.len(), 0.0);
    let mut iterations = 0;
    let mut load_steps = 0;
    let mut fraction = 0.0;
    // Equilibrium without loads first (elastic forces alone, rest shape).
    d.set_base_params(&scaled(0.0));
    let result = (|| {
        match newton(d, &mut q, opts) {
            Ok((it, _)) => iterations += it,
            Err(reason) => {
                return Err(StaticError {
                    last_fraction: 0.0,
                    reason,
                    q: q0.to_vec(),
                });
            }
        }
        let mut step: f64 = 1.0;
        let mut last_reason = String::new();
        while fraction < 1.0 {
            let target = (fraction + step).min(1.0);
            d.set_base_params(&scaled(target));
            let mut trial = q.clone();
            match newton(d, &mut trial, opts) {
                Ok((it, _)) => {
                    iterations += it;
                    load_steps += 1;
                    q = trial;
                    fraction = target;
                    step = (step * 2.0).min(1.0);
                }
                Err(reason) => {
                    last_reason = reason;
                    step *= 0.25;
                    if step < opts.min_load_step {
                        return Err(StaticError {
                            last_fraction: fraction,
                            reason: last_reason,
                            q: q[..n].to_vec(),
                        });
                    }
                }
            }
        }
        let _ = last_reason;
        Ok(())
    })();
    let mut g = vec![0.0; q.len()];
    if result.is_ok() {
        d.set_base_params(&long_term);
        residual(d, &q, &mut g);
    }
    d.set_base_params(&base);
    result?;
    let lambda = q.split_off(n);
    Ok(StaticSolution {
        residual: inf_norm(&g),
        q,
        lambda,
        iterations,
        load_steps,
    })
}

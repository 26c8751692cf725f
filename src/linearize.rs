//! The state-space model of an arm about an equilibrium, for controller
//! design: with x = (q, qd) (and a viscoelastic arm's relaxed forces,
//! relaxed at the equilibrium), u the held input channels and y the tip,
//!
//!   dx/dt = A dx + B du,   dy = C dx + D du.
//!
//! A is the right-hand side's analytic Jacobian (`runtime::state_jacobian`,
//! the generated `Jvp` kernel: what the implicit solvers use). B, C and D
//! are central differences: inputs enter through parameters, which the
//! kernels take no derivatives in, and the tip's derivative in q is three
//! rows; both are linear or smooth and cheap to difference.

use anyhow::{Result, anyhow, bail};
use nalgebra::DMatrix;
use runtime::{Dynamics, Workspace};

use crate::backend::Loaded;
use crate::inputs::Controls;

/// A linearisation and where it was taken.
#[derive(Clone, Debug)]
pub struct Linearization {
    pub a: DMatrix<f64>,
    pub b: DMatrix<f64>,
    pub c: DMatrix<f64>,
    pub d: DMatrix<f64>,
    /// The equilibrium's coordinates (the rates are zero) and inputs.
    pub q0: Vec<f64>,
    pub u0: Vec<f64>,
    /// Names of the states (coordinates, then their rates), the inputs
    /// and the outputs.
    pub states: Vec<String>,
    pub inputs: Vec<String>,
    pub outputs: Vec<String>,
}

/// The outputs y: the tip position.
pub const OUTPUTS: [&str; 3] = ["tip_x", "tip_y", "tip_z"];

/// Linearise `loaded` with the channels `inputs` held at `u0` (default
/// zero), about `q0` or else the static equilibrium under u0 found from
/// the model's start. The channels stay held at u0 afterwards.
pub fn linearize(
    loaded: &mut Loaded,
    inputs: &[String],
    u0: Option<&[f64]>,
    q0: Option<&[f64]>,
) -> Result<Linearization> {
    let controls = Controls::new(&loaded.model, &loaded.base_dir, inputs)
        .map_err(|e| anyhow!("{}: {e}", loaded.origin))?;
    let m = inputs.len();
    let u0 = match u0 {
        Some(u) if u.len() != m => bail!("u0 has {} values for {m} inputs", u.len()),
        Some(u) => u.to_vec(),
        None => vec![0.0; m],
    };
    if let Some(i) = u0.iter().position(|v| !v.is_finite()) {
        bail!("u0[{i}] is {}: must be finite", u0[i]);
    }
    controls.hold(&mut *loaded.arm, &u0);
    let q0 = match q0 {
        Some(q) => crate::run::start_coordinates(loaded, Some(q))?.0,
        None => {
            let (start, _) = crate::run::start_coordinates(loaded, None)?;
            runtime::solve_static(&mut *loaded.arm, &start, &Default::default())
                .map_err(|e| anyhow!("{}: no equilibrium under u0: {e}", loaded.origin))?
                .q
        }
    };
    let n = q0.len();
    let z0 = runtime::relaxed_forces::relaxed(&*loaded.arm, 0.0, &q0);
    let x0: Vec<f64> = (q0.iter().copied())
        .chain(std::iter::repeat_n(0.0, n))
        .chain(z0)
        .collect();
    let mut ws = Workspace::new(n);
    let mut a = DMatrix::zeros(x0.len(), x0.len());
    runtime::state_jacobian(&*loaded.arm, &mut ws, 0.0, &x0, &mut a)
        .map_err(|e| anyhow!("{}: {e}", loaded.origin))?;
    let (b, d) = input_columns(loaded, &controls, &u0, &x0, &mut ws)?;
    let c = tip_rows(&*loaded.arm, &x0);
    let states = crate::run::Table::names(&*loaded.arm, None)
        .into_iter()
        .skip(1)
        .take(2 * n)
        .chain(crate::run::relaxed_names(&*loaded.arm))
        .collect();
    Ok(Linearization {
        a,
        b,
        c,
        d,
        q0,
        u0,
        states,
        inputs: inputs.to_vec(),
        outputs: OUTPUTS.iter().map(|s| s.to_string()).collect(),
    })
}

/// Central-difference step for a value v.
fn step_for(v: f64) -> f64 {
    f64::EPSILON.cbrt() * v.abs().max(1.0)
}

/// B (states x m) and D (3 x m) by central differences in each input,
/// the others held at u0; the channels are left at u0. The relaxed
/// forces' rates do not depend on the inputs (they enter no stiffness).
fn input_columns(
    loaded: &mut Loaded,
    controls: &Controls,
    u0: &[f64],
    x0: &[f64],
    ws: &mut Workspace,
) -> Result<(DMatrix<f64>, DMatrix<f64>)> {
    let n = loaded.arm.dof();
    let m = u0.len();
    let (mut b, mut d) = (DMatrix::zeros(x0.len(), m), DMatrix::zeros(3, m));
    loaded.arm.set_internal(&x0[2 * n..]);
    let mut qdd = [vec![0.0; n], vec![0.0; n]];
    let mut tip = [[0.0; 3]; 2];
    for j in 0..m {
        let h = step_for(u0[j]);
        for (s, sign) in [1.0, -1.0].into_iter().enumerate() {
            let mut u = u0.to_vec();
            u[j] += sign * h;
            controls.hold(&mut *loaded.arm, &u);
            runtime::accelerations(&*loaded.arm, ws, 0.0, &x0[..n], &x0[n..2 * n], &mut qdd[s])
                .map_err(|e| anyhow!("{}: {e}", loaded.origin))?;
            let o = loaded.arm.outputs(0.0, &x0[..n], &x0[n..2 * n]);
            tip[s] = [o[0], o[1], o[2]];
        }
        for i in 0..n {
            b[(n + i, j)] = (qdd[0][i] - qdd[1][i]) / (2.0 * h);
        }
        for i in 0..3 {
            d[(i, j)] = (tip[0][i] - tip[1][i]) / (2.0 * h);
        }
    }
    controls.hold(&mut *loaded.arm, u0);
    Ok((b, d))
}

/// C (3 x states): the tip's derivative in q (central differences); the
/// tip does not depend on the rates or the relaxed forces.
fn tip_rows(arm: &dyn Dynamics, x0: &[f64]) -> DMatrix<f64> {
    let n = arm.dof();
    let mut c = DMatrix::zeros(3, x0.len());
    let mut q = x0[..n].to_vec();
    for j in 0..n {
        let h = step_for(q[j]);
        let q0 = q[j];
        q[j] = q0 + h;
        let plus = arm.outputs(0.0, &q, &x0[n..2 * n]);
        q[j] = q0 - h;
        let minus = arm.outputs(0.0, &q, &x0[n..2 * n]);
        q[j] = q0;
        for i in 0..3 {
            c[(i, j)] = (plus[i] - minus[i]) / (2.0 * h);
        }
    }
    c
}

//! Mass + bias and the Jvp of a system that is a sum of *parts*, each a
//! small kernel of a few of the arm's coordinates: an eba arm's elements
//! (a body of its own six coordinates) and the beam springs between
//! neighbours (twelve). M and h are the parts' blocks scattered and
//! summed; no frames are composed (that is the link recursion's case,
//! `crate::links`). Identical parts share one kernel, so generated code
//! grows with the kinds of parts, not with their number.

use serde::{Deserialize, Serialize};

/// One part: its kernel, the arm's coordinates it reads (its local
/// coordinate i is the arm's `coords[i]`) and its parameters (its local
/// parameter i is `p[params[i]]`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PartSpec {
    pub kernel: usize,
    pub coords: Vec<usize>,
    pub params: Vec<usize>,
}

/// The parts of a system.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PartLayout {
    pub dof: usize,
    pub parts: Vec<PartSpec>,
}

/// The part kernels of a model: kernel k maps a part's local coordinates,
/// rates and parameters to its block of M (upper triangle, row by row)
/// and of h; `tangents[k]` gives those and their directional derivatives
/// along the local (dx, dxd).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PartKernels {
    pub layout: PartLayout,
    pub kernels: Vec<crate::Tape>,
    pub tangents: Vec<crate::Tape>,
}

/// What the sums evaluate: generated code, or the tapes in tests.
pub trait Parts {
    /// Kernel `k` at local coordinates `x`, rates `xd`, parameters `p`.
    fn eval(&mut self, k: usize, x: &[f64], xd: &[f64], p: &[f64], out: &mut [f64]);
    /// Kernel `k` then its directional derivative along (dx, dxd).
    #[allow(clippy::too_many_arguments)]
    fn tangent(
        &mut self,
        k: usize,
        x: &[f64],
        xd: &[f64],
        dx: &[f64],
        dxd: &[f64],
        p: &[f64],
        out: &mut [f64],
    );
}

/// Entries of an m x m upper triangle.
fn tri(m: usize) -> usize {
    m * (m + 1) / 2
}

/// The part's local values of the arm's `v`, and its parameters.
fn gather(spec: &PartSpec, v: &[f64]) -> Vec<f64> {
    spec.coords.iter().map(|&i| v[i]).collect()
}

/// M (upper triangle, row by row) and h into `out` (the `MassBias`
/// layout): every part's block added where its coordinates are.
pub fn mass_bias<P: Parts>(
    layout: &PartLayout,
    parts: &mut P,
    q: &[f64],
    qd: &[f64],
    p: &[f64],
    out: &mut [f64],
) {
    let n = layout.dof;
    assert_eq!(out.len(), tri(n) + n, "MassBias output length");
    out.fill(0.0);
    let (mass, bias) = out.split_at_mut(tri(n));
    let index = |i: usize, j: usize| {
        let (i, j) = (i.min(j), i.max(j));
        i * n - i * (i + 1) / 2 + j
    };
    let mut local = Vec::new();
    for spec in &layout.parts {
        let m = spec.coords.len();
        local.resize(tri(m) + m, 0.0);
        let params: Vec<f64> = spec.params.iter().map(|&i| p[i]).collect();
        parts.eval(
            spec.kernel,
            &gather(spec, q),
            &gather(spec, qd),
            &params,
            &mut local,
        );
        let mut at = 0;
        for a in 0..m {
            for b in a..m {
                mass[index(spec.coords[a], spec.coords[b])] += local[at];
                at += 1;
            }
            bias[spec.coords[a]] += local[tri(m) + a];
        }
    }
}

/// tau = M qdd + h into `tau` and its directional derivative along `dir`
/// = (dq, dqd) into `dtau`, part by part (a part the direction does not
/// move adds its tau and nothing to dtau): the `Jvp` kernel of a system of
/// parts.
#[allow(clippy::too_many_arguments)]
pub fn inverse_dynamics_tangent<P: Parts>(
    layout: &PartLayout,
    parts: &mut P,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    dir: &[f64],
    p: &[f64],
    tau: &mut [f64],
    dtau: &mut [f64],
) {
    let n = layout.dof;
    assert!(dir.len() == 2 * n && tau.len() == n && dtau.len() == n);
    let (dq, dqd) = dir.split_at(n);
    tau.fill(0.0);
    dtau.fill(0.0);
    let mut out = Vec::new();
    for spec in &layout.parts {
        let m = spec.coords.len();
        let len = tri(m) + m;
        out.resize(2 * len, 0.0);
        let params: Vec<f64> = spec.params.iter().map(|&i| p[i]).collect();
        let (x, xd) = (gather(spec, q), gather(spec, qd));
        let (dx, dxd) = (gather(spec, dq), gather(spec, dqd));
        if dx.iter().chain(&dxd).all(|&v| v == 0.0) {
            parts.eval(spec.kernel, &x, &xd, &params, &mut out[..len]);
            out[len..].fill(0.0);
        } else {
            parts.tangent(spec.kernel, &x, &xd, &dx, &dxd, &params, &mut out);
        }
        let a_local = gather(spec, qdd);
        // Row a of the symmetric block times the local accelerations.
        let entry = |a: usize, b: usize| {
            let (a, b) = (a.min(b), a.max(b));
            a * m - a * (a + 1) / 2 + b
        };
        for a in 0..m {
            let (mut t, mut d) = (out[tri(m) + a], out[len + tri(m) + a]);
            for (b, &acc) in a_local.iter().enumerate() {
                t += out[entry(a, b)] * acc;
                d += out[len + entry(a, b)] * acc;
            }
            tau[spec.coords[a]] += t;
            dtau[spec.coords[a]] += d;
        }
    }
}

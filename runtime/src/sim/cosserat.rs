//! Static Cosserat rod by shooting: the continuum reference the lumped
//! methods converge to (the reference chapter, section 8.2.4.1).
//!
//! Along the arc length s, with the rod's frame R (third column the
//! tangent direction of the undeformed rod), strains v = R^T p' and
//! curvatures u (R' = R \[u\]x):
//!
//!   p' = R v,   v = v* + K_se^-1 R^T n     (K_se = diag(G A, G A, E A))
//!   R' = R \[u\]x, u = u* + K_bt^-1 R^T m    (K_bt = diag(E I1, E I2, G J))
//!   n' = -f,    m' = -p' x n - l
//!
//! with the base clamped (p, R given at s = 0) and the tip wrench given
//! (n, m at s = L). The unknown base wrench n(0), m(0) is found by Newton
//! on the tip residual, the rod integrated by RK4 on a fixed grid, and
//! large loads reached by continuation in the load factor. An inextensible
//! or unshearable rod is the limit of that stiffness to infinity: its
//! strain stays v* (`Rod::ea`, `Rod::ga` as `None`).

use std::sync::Arc;

use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};

/// A rod's section at one point: stiffnesses and mass per length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Section {
    /// Axial stiffness E A (N); `None`: inextensible.
    pub ea: Option<f64>,
    /// Shear stiffness k G A (N) along d1 and d2; `None`: unshearable.
    pub ga: Option<[f64; 2]>,
    /// Bending stiffness about the section's two axes and torsion G J (N m^2).
    pub ei: [f64; 2],
    pub gj: f64,
    /// Mass per length (kg/m), for gravity.
    pub rho_a: f64,
    /// The strains at rest: curvature u* about d1, d2 and twist about d3
    /// (1/m), and the stretch (v* = (0, 0, 1 + stretch)).
    pub rest_u: [f64; 3],
    pub rest_stretch: f64,
}

/// A rod whose section may vary along it (a taper).
#[derive(Clone)]
pub struct Rod {
    pub length: f64,
    /// The section at arc length s in [0, length].
    pub section: Arc<dyn Fn(f64) -> Section + Send + Sync>,
}

impl std::fmt::Debug for Rod {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Rod")
            .field("length", &self.length)
            .field("base", &(self.section)(0.0))
            .field("tip", &(self.section)(self.length))
            .finish()
    }
}

impl Rod {
    /// A uniform rod.
    pub fn uniform(length: f64, section: Section) -> Self {
        Self {
            length,
            section: Arc::new(move |_| section),
        }
    }
}

/// Loads on a rod (world frame).
#[derive(Clone, Debug, Default)]
pub struct RodLoads {
    pub gravity: [f64; 3],
    /// Force per length besides gravity (N/m).
    pub distributed_force: [f64; 3],
    pub tip_force: [f64; 3],
    pub tip_moment: [f64; 3],
}

#[derive(Clone, Debug)]
pub struct RodOptions {
    /// RK4 steps along the rod.
    pub steps: usize,
    /// Converged when the tip residual, scaled by the load, is below this.
    pub tol: f64,
    pub max_iterations: usize,
    /// Load factors tried at most (continuation from the unloaded rod).
    pub max_load_steps: usize,
}

impl Default for RodOptions {
    fn default() -> Self {
        Self {
            steps: 400,
            tol: 1e-10,
            max_iterations: 30,
            max_load_steps: 64,
        }
    }
}

#[derive(Clone, Debug)]
pub struct RodSolution {
    /// Positions at the grid points s_k = k L / steps.
    pub positions: Vec<[f64; 3]>,
    /// Frames (column-major 3x3) at the grid points.
    pub frames: Vec<Matrix3<f64>>,
    pub tip_position: [f64; 3],
    /// The base reaction: internal force and moment at s = 0.
    pub base_force: [f64; 3],
    pub base_moment: [f64; 3],
    /// What the shooting leaves of the tip boundary condition: the norm of
    /// (n(L) - F_tip) / force scale and (m(L) - M_tip) / moment scale.
    pub residual: f64,
    pub iterations: usize,
    pub load_steps: usize,
}

#[derive(Debug, thiserror::Error)]
pub enum RodError {
    #[error(
        "the Cosserat shooting did not converge (last converged load fraction {fraction:.3}); try more load steps or a smaller load"
    )]
    NoConvergence { fraction: f64 },
    #[error("invalid rod: {0}")]
    Invalid(String),
}

/// The distributed loads at one load factor: f(s) = gravity rho_a(s) +
/// distributed.
struct Loading {
    gravity: Vector3<f64>,
    distributed: Vector3<f64>,
}

impl Loading {
    fn scaled(&self, c: f64) -> Loading {
        Loading {
            gravity: self.gravity * c,
            distributed: self.distributed * c,
        }
    }
}

/// The integrated state along the rod.
#[derive(Clone, Copy)]
struct State {
    p: Vector3<f64>,
    r: Matrix3<f64>,
    n: Vector3<f64>,
    m: Vector3<f64>,
}

fn hat(u: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -u.z, u.y, u.z, 0.0, -u.x, -u.y, u.x, 0.0)
}

impl Rod {
    fn derivative(&self, x: &State, s: f64, loads: &Loading) -> State {
        let sec = (self.section)(s);
        let f = loads.gravity * sec.rho_a + loads.distributed;
        let e3 = Vector3::z();
        let rt = x.r.transpose();
        let v_rest = e3 * (1.0 + sec.rest_stretch);
        let v = if sec.ea.is_none() && sec.ga.is_none() {
            v_rest
        } else {
            let local = rt * x.n;
            let compliance = |k: Option<f64>| k.map_or(0.0, |k| 1.0 / k);
            let shear = [0, 1].map(|i| compliance(sec.ga.map(|g| g[i])));
            let axial = compliance(sec.ea);
            v_rest + Vector3::new(local.x * shear[0], local.y * shear[1], local.z * axial)
        };
        let lm = rt * x.m;
        let u = Vector3::from(sec.rest_u)
            + Vector3::new(lm.x / sec.ei[0], lm.y / sec.ei[1], lm.z / sec.gj);
        let dp = x.r * v;
        State {
            p: dp,
            r: x.r * hat(&u),
            n: -f,
            m: -dp.cross(&x.n),
        }
    }

    /// Integrate from the base with base wrench (n0, m0); the state at every
    /// grid point.
    fn shoot(
        &self,
        base: &(Vector3<f64>, Matrix3<f64>),
        f: &Loading,
        n0: Vector3<f64>,
        m0: Vector3<f64>,
        steps: usize,
    ) -> Vec<State> {
        let h = self.length / steps as f64;
        let mut x = State {
            p: base.0,
            r: base.1,
            n: n0,
            m: m0,
        };
        let axpy = |a: &State, k: &State, c: f64| State {
            p: a.p + k.p * c,
            r: a.r + k.r * c,
            n: a.n + k.n * c,
            m: a.m + k.m * c,
        };
        let mut out = Vec::with_capacity(steps + 1);
        out.push(x);
        for k in 0..steps {
            let s = k as f64 * h;
            let k1 = self.derivative(&x, s, f);
            let k2 = self.derivative(&axpy(&x, &k1, h / 2.0), s + h / 2.0, f);
            let k3 = self.derivative(&axpy(&x, &k2, h / 2.0), s + h / 2.0, f);
            let k4 = self.derivative(&axpy(&x, &k3, h), s + h, f);
            x = State {
                p: x.p + (k1.p + k2.p * 2.0 + k3.p * 2.0 + k4.p) * (h / 6.0),
                r: x.r + (k1.r + k2.r * 2.0 + k3.r * 2.0 + k4.r) * (h / 6.0),
                n: x.n + (k1.n + k2.n * 2.0 + k3.n * 2.0 + k4.n) * (h / 6.0),
                m: x.m + (k1.m + k2.m * 2.0 + k3.m * 2.0 + k4.m) * (h / 6.0),
            };
            // Back onto the rotations (the polar factor), against drift.
            let svd = x.r.svd(true, true);
            if let (Some(u), Some(vt)) = (svd.u, svd.v_t) {
                x.r = u * vt;
            }
            out.push(x);
        }
        out
    }
}

/// Solve the clamped rod: base at `position` with frame `frame` (its third
/// column the rod's initial tangent).
pub fn solve_rod(
    rod: &Rod,
    position: [f64; 3],
    frame: Matrix3<f64>,
    loads: &RodLoads,
    opts: &RodOptions,
) -> Result<RodSolution, RodError> {
    if opts.steps == 0 {
        return Err(RodError::Invalid("steps must be at least 1".into()));
    }
    // The section where the integration reads it: the grid and its
    // midpoints.
    let h = rod.length / opts.steps as f64;
    let sections: Vec<Section> = (0..=2 * opts.steps)
        .map(|k| (rod.section)(k as f64 * h / 2.0))
        .collect();
    let positive = |v: f64| v.is_finite() && v > 0.0;
    let stiff = positive(rod.length)
        && sections.iter().all(|sec| {
            sec.ei.iter().all(|&k| positive(k))
                && positive(sec.gj)
                && sec
                    .ea
                    .iter()
                    .chain(sec.ga.iter().flatten())
                    .all(|&k| positive(k))
        });
    if !stiff {
        return Err(RodError::Invalid(
            "length and stiffnesses must be finite and positive".into(),
        ));
    }
    let vectors_finite = [
        &position,
        &loads.gravity,
        &loads.distributed_force,
        &loads.tip_force,
        &loads.tip_moment,
    ]
    .iter()
    .all(|v| v.iter().all(|x| x.is_finite()));
    let valid = (sections.iter()).all(|sec| sec.rho_a.is_finite() && sec.rho_a >= 0.0)
        && vectors_finite
        && frame.iter().all(|x| x.is_finite());
    if !valid {
        return Err(RodError::Invalid(
            "mass per length must be zero or positive, positions, frames and loads finite".into(),
        ));
    }
    let base = (Vector3::from(position), frame);
    let v3 = Vector3::from;
    let full = Loading {
        gravity: v3(loads.gravity),
        distributed: v3(loads.distributed_force),
    };
    let (tip_f, tip_m) = (v3(loads.tip_force), v3(loads.tip_moment));
    // Scale of the residual: the largest force and moment the loads imply.
    let heaviest = sections.iter().map(|sec| sec.rho_a).fold(0.0, f64::max);
    let f_max = full.gravity * heaviest + full.distributed;
    let force_scale = (f_max.norm() * rod.length + tip_f.norm()).max(1e-12);
    let moment_scale = (tip_m.norm() + force_scale * rod.length).max(1e-12);
    let mut guess = Vector6::<f64>::zeros();
    let (mut fraction, mut step) = (0.0f64, 1.0f64);
    let mut iterations = 0;
    let mut load_steps = 0;
    while fraction < 1.0 {
        if load_steps >= opts.max_load_steps {
            return Err(RodError::NoConvergence { fraction });
        }
        let target = (fraction + step).min(1.0);
        let f = full.scaled(target);
        let (ft, mt) = (tip_f * target, tip_m * target);
        let residual = |w: &Vector6<f64>| -> Vector6<f64> {
            let xs = rod.shoot(
                &base,
                &f,
                w.fixed_rows::<3>(0).into(),
                w.fixed_rows::<3>(3).into(),
                opts.steps,
            );
            let end = xs[xs.len() - 1];
            let dn = (end.n - ft) / force_scale;
            let dm = (end.m - mt) / moment_scale;
            Vector6::new(dn.x, dn.y, dn.z, dm.x, dm.y, dm.z)
        };
        // Newton with a central-difference Jacobian of the shooting map.
        let mut w = guess;
        let mut converged = false;
        for _ in 0..opts.max_iterations {
            iterations += 1;
            let r = residual(&w);
            if !r.iter().all(|v| v.is_finite()) {
                break;
            }
            if r.norm() < opts.tol {
                converged = true;
                break;
            }
            let mut j = Matrix6::<f64>::zeros();
            for c in 0..6 {
                let scale = if c < 3 { force_scale } else { moment_scale };
                let d = 1e-6 * scale;
                let mut wp = w;
                let mut wm = w;
                wp[c] += d;
                wm[c] -= d;
                let col = (residual(&wp) - residual(&wm)) / (2.0 * d);
                j.set_column(c, &col);
            }
            let Some(dw) = j.lu().solve(&(-r)) else {
                break;
            };
            w += dw;
        }
        load_steps += 1;
        if converged {
            fraction = target;
            guess = w;
            step = (step * 2.0).min(1.0);
        } else {
            step *= 0.5;
            if step < 1e-4 {
                return Err(RodError::NoConvergence { fraction });
            }
        }
    }
    let xs = rod.shoot(
        &base,
        &full,
        guess.fixed_rows::<3>(0).into(),
        guess.fixed_rows::<3>(3).into(),
        opts.steps,
    );
    let end = xs[xs.len() - 1];
    let tip = end.p;
    let dn = (end.n - tip_f) / force_scale;
    let dm = (end.m - tip_m) / moment_scale;
    let residual = Vector6::new(dn.x, dn.y, dn.z, dm.x, dm.y, dm.z).norm();
    Ok(RodSolution {
        positions: xs.iter().map(|x| [x.p.x, x.p.y, x.p.z]).collect(),
        frames: xs.iter().map(|x| x.r).collect(),
        tip_position: [tip.x, tip.y, tip.z],
        base_force: [guess[0], guess[1], guess[2]],
        base_moment: [guess[3], guess[4], guess[5]],
        residual,
        iterations,
        load_steps,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bench rod of models/cantilever3d.toml: L 0.3 m, r 0.01 m, E 1 MPa, G = E/3.
    fn rod(inextensible: bool) -> Rod {
        Rod::uniform(0.3, section(inextensible))
    }

    fn section(inextensible: bool) -> Section {
        let soft = |k: f64| (!inextensible).then_some(k);
        let (e, r) = (1e6, 0.01);
        let area = std::f64::consts::PI * r * r;
        let i = std::f64::consts::PI * r.powi(4) / 4.0;
        Section {
            ea: soft(e * area),
            ga: soft(e / 3.0 * area).map(|g| [g; 2]),
            ei: [e * i, e * i],
            gj: e / 3.0 * 2.0 * i,
            rho_a: 1000.0 * area,
            rest_u: [0.0; 3],
            rest_stretch: 0.0,
        }
    }

    /// Base frame with the rod along +x: columns d1 = y, d2 = z, d3 = x.
    fn along_x() -> Matrix3<f64> {
        Matrix3::from_columns(&[Vector3::y(), Vector3::z(), Vector3::x()])
    }

    /// A unit lateral direction that is not along an axis.
    fn lateral() -> Vector3<f64> {
        Vector3::new(0.0, -0.6, 0.8)
    }

    #[test]
    fn small_lateral_tip_load_gives_the_beam_deflection() {
        let rod = rod(false);
        let l = rod.length;
        let f = 0.005 * 3.0 * section(false).ei[0] / l.powi(3) * l; // 0.5 % of L
        let load = lateral() * f;
        let sol = solve_rod(
            &rod,
            [0.0; 3],
            along_x(),
            &RodLoads {
                tip_force: load.into(),
                ..Default::default()
            },
            &RodOptions::default(),
        )
        .unwrap();
        let tip = Vector3::from(sol.tip_position);
        let beam = f * l.powi(3) / (3.0 * section(false).ei[0]);
        let along = tip.dot(&lateral());
        assert!((along - beam).abs() < 0.01 * beam, "{along} vs {beam}");
        // The base holds the load.
        let n0 = Vector3::from(sol.base_force);
        assert!((n0 - load).norm() < 1e-9 * f);
        // The reported residual is the converged tip condition's.
        assert!(sol.residual < RodOptions::default().tol, "{}", sol.residual);
    }

    #[test]
    fn invalid_rods_and_loads_are_errors_not_nans() {
        // Stiff at the base, not at the tip.
        let bad = Rod {
            section: Arc::new(|s| Section {
                ei: [1.0, if s > 0.2 { 0.0 } else { 1.0 }],
                ..section(false)
            }),
            ..rod(false)
        };
        let none = RodLoads::default();
        let opts = RodOptions::default();
        assert!(solve_rod(&bad, [0.0; 3], along_x(), &none, &opts).is_err());
        let nan = RodLoads {
            tip_force: [f64::NAN, 0.0, 0.0],
            ..Default::default()
        };
        assert!(solve_rod(&rod(false), [0.0; 3], along_x(), &nan, &opts).is_err());
    }

    #[test]
    fn large_tip_load_matches_the_published_elastica() {
        // Bisshopp and Drucker (1945): P L^2 / (E I) = 10 puts the tip of an
        // inextensible cantilever at 0.4450 L along and 0.8106 L across.
        let rod = rod(true);
        let l = rod.length;
        let p = 10.0 * section(false).ei[0] / (l * l);
        let sol = solve_rod(
            &rod,
            [0.0; 3],
            along_x(),
            &RodLoads {
                tip_force: (lateral() * p).into(),
                ..Default::default()
            },
            &RodOptions::default(),
        )
        .unwrap();
        let tip = Vector3::from(sol.tip_position);
        assert!((tip.x / l - 0.4450).abs() < 2e-4, "{tip:?}");
        assert!((tip.dot(&lateral()) / l - 0.8106).abs() < 2e-4, "{tip:?}");
    }

    #[test]
    fn self_weight_gives_the_distributed_load_deflection() {
        // w L^4 / (8 E I) for a light load: scale gravity to 1 % of L.
        let rod = rod(false);
        let l = rod.length;
        let g = 0.01 * l * 8.0 * section(false).ei[0] / (section(false).rho_a * l.powi(4));
        let sol = solve_rod(
            &rod,
            [0.0; 3],
            along_x(),
            &RodLoads {
                gravity: [0.0, -g, 0.0],
                ..Default::default()
            },
            &RodOptions::default(),
        )
        .unwrap();
        let beam = section(false).rho_a * g * l.powi(4) / (8.0 * section(false).ei[0]);
        let dy = -sol.tip_position[1];
        assert!((dy - beam).abs() < 0.01 * beam, "{dy} vs {beam}");
    }
}

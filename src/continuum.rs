//! `method = "cosserat"`: a model file as a Cosserat rod for
//! `runtime::cosserat`, the continuum reference of the lumped methods.
//!
//! One uniform segment. Inextensible and unshearable unless it says
//! otherwise: `extension = true` stretches it (E A), `shear = true` shears
//! it (k G A, k the `shear_factor`), as the lumped methods' keys do.

use anyhow::Result;
use eomgen::model::{Model, base_rotation};
use nalgebra::Matrix3;
use runtime::cosserat::{Rod, RodLoads, RodOptions, RodSolution, solve_rod};

/// True when the model asks for the Cosserat rod.
pub fn is_cosserat(model: &Model) -> bool {
    model.segments.iter().any(|s| s.method.statics_only())
}

/// Solve the static rod of a model whose segment is `cosserat`
/// (validation checked the model: one uniform segment, its stiffnesses).
pub fn solve(model: &Model, origin: &str) -> Result<RodSolution> {
    let s = &model.segments[0];
    let stiffness = |v: Option<f64>| v.expect("validated: the Cosserat rod's stiffness");
    let ea = s.stretches().then(|| stiffness(s.ea()));
    let ga = s.shears().then(|| stiffness(s.ga()));
    let (ei, gj) = (stiffness(s.ei()), stiffness(s.gj()));
    let mass = s.total_mass().unwrap_or(0.0);
    let rod = Rod {
        length: s.length,
        ea,
        ga,
        ei: [ei, ei],
        gj,
        rho_a: mass / s.length,
    };
    // The rod's frame has its tangent third: (y, z, x) of the base frame.
    let r0 = base_rotation(model.base.direction);
    let col = |j: usize| [r0[0][j], r0[1][j], r0[2][j]];
    let (e1, e2, e3) = (col(1), col(2), col(0));
    let frame = Matrix3::new(
        e1[0], e2[0], e3[0], //
        e1[1], e2[1], e3[1], //
        e1[2], e2[2], e3[2],
    );
    let loads = RodLoads {
        gravity: model.gravity,
        distributed_force: [0.0; 3],
        tip_force: model.tip.force.unwrap_or([0.0; 3]),
        tip_moment: model.tip.moment.unwrap_or([0.0; 3]),
    };
    solve_rod(
        &rod,
        model.base.position,
        frame,
        &loads,
        &RodOptions::default(),
    )
    .map_err(|e| anyhow::anyhow!("{origin}: {e}"))
}

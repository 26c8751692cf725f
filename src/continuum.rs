//! `method = "cosserat"`: a model file as a Cosserat rod for
//! `runtime::cosserat`, the continuum reference of the lumped methods.
//!
//! One uniform segment. Inextensible and unshearable like the lumped
//! methods, unless `extension = true`: then extensible (E A) and shearable
//! (G A, shear coefficient 1).

use anyhow::{Result, bail};
use eomgen::model::{Method, Model, base_rotation};
use nalgebra::Matrix3;
use runtime::cosserat::{Rod, RodLoads, RodOptions, RodSolution, solve_rod};

/// True when the model asks for the Cosserat rod.
pub fn is_cosserat(model: &Model) -> bool {
    model.segments.iter().any(|s| s.method == Method::Cosserat)
}

/// Solve the static rod of a model whose segment is `cosserat`.
pub fn solve(model: &Model, origin: &str) -> Result<RodSolution> {
    let [s] = model.segments.as_slice() else {
        bail!(
            "{origin}: segment: the Cosserat statics take one uniform [[segment]], got {}",
            model.segments.len()
        );
    };
    if s.rest_curvature != 0.0 {
        bail!(
            "{origin}: segment[0].rest_curvature: the Cosserat rod is straight at rest; remove the key"
        );
    }
    if model.tip.mass.is_some() {
        bail!(
            "{origin}: tip.mass: a tip mass is a load under gravity; give it as tip.force for the Cosserat statics"
        );
    }
    let need = |v: Option<f64>, key: &str| -> Result<f64> {
        v.ok_or_else(|| {
            anyhow::anyhow!("{origin}: segment[0].{key}: missing, the Cosserat rod needs it (or `youngs_modulus` with `outer_radius`)")
        })
    };
    let ei = need(s.ei(), "bending_stiffness")?;
    let gj = need(s.gj(), "torsional_stiffness")?;
    let extensible = s.stretches();
    let (ea, ga) = if extensible {
        let ea = need(s.ea(), "axial_stiffness")?;
        let g = s
            .shear_modulus
            .or(s.youngs_modulus.map(|e| e / 3.0))
            .unwrap_or(0.0);
        (ea, g * s.area().unwrap_or(0.0))
    } else {
        (0.0, 0.0)
    };
    let mass = match (s.mass, s.density) {
        (Some(m), _) => m,
        (None, Some(rho)) => rho * s.area().unwrap_or(0.0) * s.length,
        (None, None) => 0.0,
    };
    let rod = Rod {
        length: s.length,
        ea,
        ga,
        ei: [ei, ei],
        gj,
        rho_a: mass / s.length,
        inextensible: !extensible,
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

//! `method = "cosserat"`: a model file as a Cosserat rod for
//! `runtime::cosserat`, the continuum reference of the lumped methods.
//!
//! One segment, uniform or tapered. Inextensible and unshearable unless it says
//! otherwise: `extension = true` stretches it (E A), `shear = true` shears
//! it (k G A, k the `shear_factor`), as the lumped methods' keys do.

use anyhow::Result;
use std::sync::Arc;

use eomgen::model::{Model, Segment, base_rotation};
use nalgebra::Matrix3;
use runtime::cosserat::{Rod, RodLoads, RodOptions, RodSolution, Section, solve_rod};

/// True when the model asks for the Cosserat rod.
pub fn is_cosserat(model: &Model) -> bool {
    model.segments.iter().any(|s| s.method.statics_only())
}

/// The rod's section at the fraction `x` of the segment `s` (a
/// viscoelastic segment's at its long-term moduli).
fn section_at(s: &Segment, x: f64) -> Section {
    let here = s.at(x);
    let [rest_y, rest_z, rest_twist, rest_stretch] = s.rest_at(x, 3);
    // A viscoelastic rod in equilibrium has relaxed: its long-term moduli.
    let share = 1.0 - s.relaxation.iter().map(|r| r.ratio).sum::<f64>();
    let stiffness = |v: Option<f64>| share * v.expect("validated: the Cosserat rod's stiffness");
    Section {
        ea: s.stretches().then(|| stiffness(here.ea())),
        ga: s.shears().then(|| {
            let pair = here
                .ga_pair()
                .expect("validated: the Cosserat rod's shear stiffness");
            pair.map(|k| stiffness(Some(k)))
        }),
        ei: [stiffness(here.ei_y()), stiffness(here.ei())],
        gj: stiffness(here.gj()),
        rho_a: s.mass_per_length(x).unwrap_or(0.0),
        // The rod's frame is (y, z, x) of the section's.
        rest_u: [rest_y, rest_z, rest_twist],
        rest_stretch,
    }
}

/// The rod of segment `s`: uniform, or tapered with its sections taken
/// once at the points where the shooting reads them.
fn rod_of(s: &Segment, opts: &RodOptions) -> Rod {
    if !s.tapered() {
        return Rod::uniform(s.length, section_at(s, 0.5));
    }
    let half = 0.5 / opts.steps as f64;
    let table: Vec<Section> = (0..=2 * opts.steps)
        .map(|k| section_at(s, k as f64 * half))
        .collect();
    let (seg, length) = (s.clone(), s.length);
    Rod {
        length,
        section: Arc::new(move |at| {
            let x = at / length;
            let k = (x / half).round();
            match (k * half - x).abs() < 1e-9 {
                true => table[(k as usize).min(table.len() - 1)],
                false => section_at(&seg, x),
            }
        }),
    }
}

/// Solve the static rod of a model whose segment is `cosserat`
/// (validation checked the model: one segment, its stiffnesses).
pub fn solve(model: &Model, origin: &str) -> Result<RodSolution> {
    let s = &model.segments[0];
    let opts = RodOptions::default();
    let rod = rod_of(s, &opts);
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
        // Validated: constant world-frame forces per unit length.
        distributed_force: model.loads.iter().fold([0.0; 3], |acc, l| {
            let f = l.force.unwrap_or([0.0; 3]);
            [acc[0] + f[0], acc[1] + f[1], acc[2] + f[2]]
        }),
        tip_force: model.tip.force.unwrap_or([0.0; 3]),
        tip_moment: model.tip.moment.unwrap_or([0.0; 3]),
    };
    solve_rod(&rod, model.base.position, frame, &loads, &opts)
        .map_err(|e| anyhow::anyhow!("{origin}: {e}"))
}

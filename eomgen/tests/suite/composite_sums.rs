//! The composite-body sums of a chain against the same quantities summed
//! body by body: M = sum T^T Mbar T against the Jacobian of the generalised
//! momentum, and h = sum T^T f against one vector-Jacobian product. Two
//! evaluation orders that share no code past the kinematics. Planar and 3D
//! (axisymmetric world-frame inertias, tip moments), every 3D method.

use std::path::Path;

use eomgen::build::system;
use eomgen::cas::{Cas, SymKind};
use eomgen::load::load_model;
use eomgen::model::{Method, Model, Override, Param, ParamLayout, Structure};
use eomgen::tmt::assemble;

fn check(model: &Model, label: &str) {
    // Loads on, whatever the file says, so that every force path counts.
    let structure = Structure::of(model);
    let layout = ParamLayout::of(&structure);
    let values: Vec<f64> = layout
        .params()
        .iter()
        .zip(layout.values(model))
        .map(|(p, v)| match p {
            Param::Gravity(c) => [1.3, -9.81, 2.2][c.index()],
            Param::TipForce(c) => [0.7, -0.4, 0.3][c.index()],
            Param::TipMoment(c) => [0.05, -0.02, 0.04][c.index()],
            _ => v,
        })
        .collect();
    let mut cas = Cas::new();
    let mut sys = system(&mut cas, &structure, &layout);
    assert!(
        sys.chain.is_some(),
        "{}: the bundled arms are chains",
        label
    );
    let eq = assemble(&mut cas, &sys);
    let composite: Vec<_> = eq.mass_upper.iter().chain(&eq.bias).copied().collect();
    sys.chain = None;
    let eq = assemble(&mut cas, &sys);
    let body_by_body: Vec<_> = eq.mass_upper.iter().chain(&eq.bias).copied().collect();
    let n = sys.coords.len();
    for trial in 0..5 {
        // Deterministic states spanning bent and straight (theta = 0) ones.
        // Stretches (m) stay well below element lengths: an element
        // stretched to a negative length has no incompressible section.
        let q: Vec<f64> = (0..n)
            .map(|i| {
                let amplitude = if sys.coords.names[i].starts_with("stretch") {
                    1e-3
                } else {
                    1.3
                };
                match trial {
                    0 => 0.0,
                    _ => amplitude * ((i * 7 + trial * 3) as f64).sin(),
                }
            })
            .collect();
        let qd: Vec<f64> = (0..n)
            .map(|i| 2.1 * ((i * 5 + trial) as f64).cos())
            .collect();
        let value = |s| match cas.sym_kind(s) {
            SymKind::Q(i) => Some(q[i as usize]),
            SymKind::Qd(i) => Some(qd[i as usize]),
            SymKind::Param(i) => Some(values[i as usize]),
            _ => Some(0.0),
        };
        let a = cas.eval_many(&composite, &value).unwrap();
        let b = cas.eval_many(&body_by_body, &value).unwrap();
        let m = n * (n + 1) / 2;
        let scale = |r: std::ops::Range<usize>| b[r].iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let (scale_m, scale_h) = (scale(0..m), scale(m..b.len()));
        for (k, (x, y)) in a.iter().zip(&b).enumerate() {
            let s = if k < m { scale_m } else { scale_h };
            assert!(
                (x - y).abs() <= 1e-12 * s,
                "{}: entry {k} of M then h at trial {trial}: {x} vs {y}",
                label
            );
        }
    }
}

#[test]
fn composite_sums_equal_body_by_body_sums_on_every_bundled_model() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../models");
    let mut checked = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().and_then(|e| e.to_str()) != Some("toml") {
            continue;
        }
        let model = load_model(&path, &[]).unwrap();
        // rom shares its coordinates along a segment and eba has absolute
        // ones: no chain, no composite sums (tests/suite/backends.rs checks their
        // link recursion and flat tapes instead); an assembly is several
        // chains and bodies, summed body by body (tests/suite/joints.rs).
        let structure = Structure::of(&model);
        if structure.assembly.is_some()
            || structure
                .segments
                .iter()
                .any(|g| matches!(g.method, Method::Rom | Method::Eba))
        {
            continue;
        }
        check(&model, &path.display().to_string());
        checked += 1;
    }
    assert!(checked >= 5, "found only {checked} models");
}

#[test]
fn composite_sums_equal_body_by_body_sums_for_every_3d_method() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../models/cantilever3d.toml");
    for sets in [
        &["segment.0.method=ebr"][..],
        &["segment.0.method=rigid"],
        &[
            "segment.0.method=rigid",
            "segment.0.joints=base",
            "segment.0.joint_axes=[\"y\", \"x\", \"z\"]",
        ],
        &["segment.0.extension=true", "tip.mass=0.01"],
        &[
            "segment.0.method=ebr",
            "segment.0.extension=true",
            "segment.0.twist=false",
        ],
        &[
            "base.direction=[0.3, -0.5, 0.8]",
            "segment.0.rest_curvature=2.0",
        ],
    ] {
        let overrides: Vec<Override> = sets.iter().map(|s| Override::parse(s).unwrap()).collect();
        let model = load_model(&path, &overrides).unwrap();
        check(&model, &format!("cantilever3d {sets:?}"));
    }
}

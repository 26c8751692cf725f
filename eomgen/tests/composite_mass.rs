//! The composite-body mass matrix of a chain against the same M summed body
//! by body (the Jacobian of the generalised momentum): two evaluation orders
//! of M = sum T^T Mbar T that share no code past the kinematics.

use std::path::Path;

use eomgen::cas::{Cas, SymKind};
use eomgen::model::{load_model, parameters};
use eomgen::tmt::{assemble, planar_system};

#[test]
fn composite_mass_equals_body_by_body_mass_on_every_bundled_model() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../models");
    let mut checked = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().and_then(|e| e.to_str()) != Some("toml") {
            continue;
        }
        let model = load_model(&path, &[]).unwrap();
        let values: Vec<f64> = parameters(&model).into_iter().map(|(_, v)| v).collect();
        let mut cas = Cas::new();
        let mut sys = planar_system(&mut cas, &model);
        assert!(
            sys.chain.is_some(),
            "{}: planar arms are chains",
            path.display()
        );
        let composite = assemble(&mut cas, &sys).mass_upper;
        sys.chain = None;
        let body_by_body = assemble(&mut cas, &sys).mass_upper;
        let n = sys.coords.len();
        for trial in 0..5 {
            // Deterministic states spanning bent and straight (theta = 0) ones.
            let q: Vec<f64> = (0..n)
                .map(|i| match trial {
                    0 => 0.0,
                    _ => 1.3 * ((i * 7 + trial * 3) as f64).sin(),
                })
                .collect();
            let value = |s| match cas.sym_kind(s) {
                SymKind::Q(i) => Some(q[i as usize]),
                SymKind::Param(i) => Some(values[i as usize]),
                _ => Some(0.0),
            };
            let a = cas.eval_many(&composite, &value).unwrap();
            let b = cas.eval_many(&body_by_body, &value).unwrap();
            let scale = b.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            for (k, (x, y)) in a.iter().zip(&b).enumerate() {
                assert!(
                    (x - y).abs() <= 1e-12 * scale,
                    "{}: M entry {k} at trial {trial}: {x} vs {y}",
                    path.display()
                );
            }
        }
        checked += 1;
    }
    assert!(checked >= 5, "found only {checked} models");
}

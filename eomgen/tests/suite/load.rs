//! Each method's answers, reached as a user does: a model file loaded,
//! its structure, its coordinates.

use eomgen::load::*;
use eomgen::method::{ALL, coordinate_names};
use eomgen::model::{Model, ModelError, Structure};

/// A 3D model of one segment by `method`, with extra keys.
fn model(method: &str, extra: &str) -> Result<Model, ModelError> {
    let text = format!(
        r#"
name = "t"
dimensions = 3
gravity = [0.0, 0.0, -9.81]
[base]
direction = [1.0, 0.0, 0.0]
[[segment]]
method = "{method}"
length = 0.2
elements = 3
density = 1000.0
outer_radius = 0.01
youngs_modulus = 1e6
extension = true
{extra}
"#
    );
    parse_model(&text, "t.toml", false, &[])
}

/// Each method's coordinates, counted from its definition in the
/// chapter: per element 2 bends + twist + stretch (pcc, vc, ebr), all
/// six strains (pcs), 6 absolute states (eba), one per joint axis
/// (rigid); per strain field order + 1 coefficients (rom); none for a
/// method of statics alone. Every method of the registry has its count
/// here. Names are unique.
#[test]
fn coordinates_count_as_each_method_defines_them() {
    let defined = |method: &str| match method {
        "pcc" | "vc" | "ebr" => Some(("", 3 * 4)),
        "pcs" => Some(("", 3 * 6)),
        "eba" => Some(("", 3 * 6)),
        "rom" => Some(("order = 2", 4 * 3)),
        "rigid" => Some(("joint_axes = [\"z\", \"y\"]", 3 * 2)),
        "cosserat" => Some(("", 0)),
        _ => None,
    };
    for method in ALL.iter().map(|m| m.name()) {
        let (extra, want) =
            defined(method).unwrap_or_else(|| panic!("{method}: give its coordinate count"));
        let m = model(method, extra).unwrap_or_else(|e| panic!("{method}: {e}"));
        let names = coordinate_names(&Structure::of(&m));
        assert_eq!(names.len(), want, "{method}: {names:?}");
        let mut unique = names.clone();
        unique.sort();
        unique.dedup();
        assert_eq!(unique.len(), names.len(), "{method}: duplicate names");
    }
}

/// A key one method owns is rejected on every other, naming its owner.
#[test]
fn a_key_another_method_owns_is_rejected_with_its_owner() {
    for (method, key, owner) in [
        ("pcc", "order = 2", "rom"),
        ("ebr", "joint_damping = 0.1", "rigid"),
        ("rom", "joints = \"base\"", "rigid"),
        ("eba", "quadrature = 4", "rom"),
    ] {
        let e = model(method, key).unwrap_err().to_string();
        assert!(
            e.contains(&format!("not a key of {method} segments: only {owner}")),
            "{method} with {key}: {e}"
        );
    }
    // Its own keys are accepted.
    model("rom", "order = 2\nquadrature = 4").unwrap();
}

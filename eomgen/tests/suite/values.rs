//! A model's parameter values and their layout.

use eomgen::load::*;
use eomgen::model::channel;
use eomgen::model::{Param, ParamLayout, Structure};

/// Every parameter's name is unique and its index is its position: the
/// typed layout and the named one are one list.
#[test]
fn names_are_unique_and_indices_are_positions() {
    let text = r#"
name = "t"
dimensions = 3
gravity = [0.0, 0.0, -9.81]
[base]
direction = [1.0, 0.0, 0.0]
translation_inputs = ["a", "a", "a"]
rotation_inputs = ["a", "a"]
[[segment]]
method = "pcc"
length = 0.1
elements = 2
density = 1000.0
outer_radius = 0.01
youngs_modulus = 1e6
extension = true
[segment.chambers]
count = 3
radius = 0.002
distance = 0.005
inputs = ["a", "a", "a"]
[[tendon]]
input = "a"
distance = 0.006
[[torque]]
coordinate = "bend_y_0_0"
input = "a"
[tip]
mass = 0.01
length = 0.01
radius = 0.005
force_inputs = ["a", "a", "a"]
moment = [0.0, 0.0, 0.0]
[inputs.a]
kind = "constant"
value = 1.0
"#;
    let m = parse_model(text, "t.toml", false, &[]).unwrap();
    let layout = ParamLayout::of(&Structure::of(&m));
    let names = layout.names();
    let mut sorted = names.clone();
    sorted.sort();
    sorted.dedup();
    assert_eq!(sorted.len(), names.len(), "duplicate names: {names:?}");
    for (i, &p) in layout.params().iter().enumerate() {
        assert_eq!(layout.index(p), i);
    }
    for d in layout.driven() {
        assert_eq!(channel(&m, d.param), Some("a"), "{}", d.param.name());
    }
    // Driven: 9 base translation, 6 turn, 3 tip force, 3 pressures,
    // 1 tension, 1 torque; the tip moment is a constant.
    assert_eq!(layout.driven().len(), 9 + 6 + 3 + 3 + 1 + 1);
    assert!(
        layout
            .driven()
            .iter()
            .all(|d| !matches!(d.param, Param::TipMoment(_)))
    );
    assert_eq!(layout.values(&m).len(), layout.len());
}

//! Obstacle shapes made from their model-file keys (`obstacle`).

use runtime_kernels::obstacle::*;

fn keys(text: &str) -> ShapeKeys {
    serde_json::from_str(text).unwrap()
}

/// Each shape from its keys: normals and axes made unit, lengths
/// halved, a box's quaternion as its rotation (a quarter turn about z
/// takes x to y), the identity without one.
#[test]
fn each_shape_is_made_from_its_keys() {
    let made = |name: &str, text: &str| Shape::from_keys(name, &keys(text)).unwrap();
    assert_eq!(
        made("plane", r#"{"point": [0, 1, 0], "normal": [0, 0, 2]}"#),
        Shape::Plane {
            point: [0.0, 1.0, 0.0],
            normal: [0.0, 0.0, 1.0]
        }
    );
    assert_eq!(
        made("sphere", r#"{"center": [1, 2, 3], "radius": 0.5}"#),
        Shape::Sphere {
            center: [1.0, 2.0, 3.0],
            radius: 0.5
        }
    );
    assert_eq!(
        made(
            "cylinder",
            r#"{"center": [0, 0, 0], "axis": [3, 0, 4], "radius": 0.1, "length": 2}"#
        ),
        Shape::Cylinder {
            center: [0.0; 3],
            axis: [0.6, 0.0, 0.8],
            radius: 0.1,
            half_length: 1.0
        }
    );
    let h = 0.5f64.sqrt();
    let Shape::Box { rotation, half, .. } = made(
        "box",
        &format!(r#"{{"center": [0, 0, 0], "size": [1, 2, 3], "orientation": [{h}, 0, 0, {h}]}}"#),
    ) else {
        panic!("not a box")
    };
    assert_eq!(half, [0.5, 1.0, 1.5]);
    let quarter = [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
    for (row, want) in rotation.iter().zip(quarter) {
        for (a, b) in row.iter().zip(want) {
            assert!((a - b).abs() < 1e-15, "{rotation:?}");
        }
    }
    let Shape::Box { rotation, .. } = made("box", r#"{"center": [0, 0, 0], "size": [1, 1, 1]}"#)
    else {
        panic!("not a box")
    };
    assert_eq!(
        rotation,
        [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    );
    for name in Shape::NAMES {
        assert!(Shape::recipe(name).is_some(), "{name} has no recipe");
    }
}

/// Each key is read as the one it is named: given alone, it alone
/// is given.
#[test]
fn keys_are_named_in_their_order() {
    for key in ShapeKeys::KEYS {
        let value = match key {
            "radius" | "length" => "1",
            "orientation" => "[1, 0, 0, 0]",
            _ => "[1, 0, 0]",
        };
        let k = keys(&format!(r#"{{"{key}": {value}}}"#));
        let given: Vec<&str> = (Keys { keys: &k }.given().into_iter())
            .filter(|(_, present)| *present)
            .map(|(name, _)| name)
            .collect();
        assert_eq!(given, [key]);
    }
}

/// Exactly the shape's keys, each in range; an unknown shape names
/// them all.
#[test]
fn a_wrong_key_is_named_with_what_the_shape_takes() {
    let err = |name: &str, text: &str| Shape::from_keys(name, &keys(text)).unwrap_err();
    let e = err(
        "plane",
        r#"{"point": [0, 0, 0], "normal": [0, 1, 0], "radius": 1}"#,
    );
    assert_eq!(e.key, "radius");
    assert!(
        e.message.contains("a plane obstacle takes point, normal"),
        "{e:?}"
    );
    let e = err("sphere", r#"{"center": [0, 0, 0]}"#);
    assert_eq!(e.key, "radius");
    assert!(
        e.message
            .contains("missing: a sphere obstacle needs center, radius")
    );
    let e = err("cone", "{}");
    assert_eq!(e.key, "shape");
    assert!(e.message.contains("plane, sphere, cylinder, box"), "{e:?}");
    let e = err("plane", r#"{"point": [0, 0, 0], "normal": [0, 0, 0]}"#);
    assert_eq!(
        (e.key.as_str(), e.message.contains("zero vector")),
        ("normal", true)
    );
    let e = err("box", r#"{"center": [0, 0, 0], "size": [1, -1, 1]}"#);
    assert_eq!(e.key, "size[1]");
    let e = err(
        "box",
        r#"{"center": [0, 0, 0], "size": [1, 1, 1], "orientation": [0, 0, 0, 0]}"#,
    );
    assert_eq!(e.key, "orientation");
    let e = err("sphere", r#"{"center": [0, 0, 0], "radius": 0}"#);
    assert!(e.message.contains("must be positive"));
}

//! Obstacle shapes, defined once: the keys a model file gives each shape
//! and their checks ([`Shape::from_keys`], which the generator validates
//! with and the CLI builds with), the shape they make, and, with
//! `simulate`, the signed distance of a point from it and the broad phase.
//! Drawing a shape is the scene's (`src/scene.rs`, the viewer).

use serde::{Deserialize, Serialize};

/// An obstacle's shape keys as a model file gives them (`[[obstacle]]`);
/// which of them a shape takes, [`Shape::from_keys`] says.
#[derive(Clone, Debug, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ShapeKeys {
    /// A plane's point and outward normal.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub point: Option<[f64; 3]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub normal: Option<[f64; 3]>,
    /// A sphere's, cylinder's or box's centre.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub center: Option<[f64; 3]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius: Option<f64>,
    /// A cylinder's axis and its whole length.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axis: Option<[f64; 3]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub length: Option<f64>,
    /// A box's whole sizes along its axes and its orientation (a
    /// quaternion w, x, y, z; identity by default).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub size: Option<[f64; 3]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub orientation: Option<[f64; 4]>,
}

impl ShapeKeys {
    /// The keys, in the struct's order.
    pub const KEYS: [&'static str; 8] = [
        "point",
        "normal",
        "center",
        "radius",
        "axis",
        "length",
        "size",
        "orientation",
    ];
}

/// A shape key that is missing, not the shape's, or out of range: the key
/// (`radius`, `size[1]`; `shape` for an unknown shape) and what is wrong.
#[derive(Clone, Debug, PartialEq)]
pub struct KeyError {
    pub key: String,
    pub message: String,
}

/// The shape of an obstacle in its rest pose (world coordinates).
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// A half space: a point on its surface and the unit outward normal.
    Plane {
        point: [f64; 3],
        normal: [f64; 3],
    },
    Sphere {
        center: [f64; 3],
        radius: f64,
    },
    /// A finite, capped cylinder: unit axis, half length.
    Cylinder {
        center: [f64; 3],
        axis: [f64; 3],
        radius: f64,
        half_length: f64,
    },
    /// A box: its rotation R (columns: the box's axes in the world) and
    /// half sizes along them.
    Box {
        center: [f64; 3],
        rotation: [[f64; 3]; 3],
        half: [f64; 3],
    },
}

/// How a shape is made from its keys: the keys it needs, those it may
/// take, and the construction (the keys present and in range).
type Recipe = (
    &'static [&'static str],
    &'static [&'static str],
    fn(&Keys) -> Result<Shape, KeyError>,
);

impl Shape {
    /// The shapes' names in model files.
    pub const NAMES: [&'static str; 4] = ["plane", "sphere", "cylinder", "box"];

    /// Each shape's keys and construction, by name.
    #[doc(hidden)] // white-box tests (tests/suite)
    pub fn recipe(name: &str) -> Option<Recipe> {
        Some(match name {
            "plane" => (&["point", "normal"], &[], |k| {
                Ok(Shape::Plane {
                    point: k.vec("point")?,
                    normal: k.direction("normal")?,
                })
            }),
            "sphere" => (&["center", "radius"], &[], |k| {
                Ok(Shape::Sphere {
                    center: k.vec("center")?,
                    radius: k.positive("radius")?,
                })
            }),
            "cylinder" => (&["center", "axis", "radius", "length"], &[], |k| {
                Ok(Shape::Cylinder {
                    center: k.vec("center")?,
                    axis: k.direction("axis")?,
                    radius: k.positive("radius")?,
                    half_length: 0.5 * k.positive("length")?,
                })
            }),
            "box" => (&["center", "size"], &["orientation"], |k| {
                let size = k.keys.size.unwrap_or_default();
                for (i, v) in size.iter().enumerate() {
                    positive(&format!("size[{i}]"), *v)?;
                }
                Ok(Shape::Box {
                    center: k.vec("center")?,
                    rotation: k.rotation("orientation")?,
                    half: size.map(|s| 0.5 * s),
                })
            }),
            _ => return None,
        })
    }

    /// The shape `name` of the keys `keys`: exactly its keys, each in
    /// range, normals and axes made unit.
    pub fn from_keys(name: &str, keys: &ShapeKeys) -> Result<Shape, KeyError> {
        let Some((needs, may, make)) = Self::recipe(name) else {
            return Err(KeyError {
                key: "shape".into(),
                message: format!("unknown shape `{name}`: one of {}", Self::NAMES.join(", ")),
            });
        };
        let k = Keys { keys };
        for (key, present) in k.given() {
            let err = |message: String| {
                Err(KeyError {
                    key: key.into(),
                    message,
                })
            };
            if present && !needs.contains(&key) && !may.contains(&key) {
                return err(format!(
                    "a {name} obstacle takes {}; `{key}` is not one of them",
                    needs
                        .iter()
                        .chain(may)
                        .copied()
                        .collect::<Vec<_>>()
                        .join(", ")
                ));
            }
            if !present && needs.contains(&key) {
                return err(format!(
                    "missing: a {name} obstacle needs {}",
                    needs.join(", ")
                ));
            }
        }
        make(&k)
    }
}

/// The keys being read, each checked as it is.
#[doc(hidden)] // white-box tests (tests/suite)
pub struct Keys<'a> {
    pub keys: &'a ShapeKeys,
}

impl Keys<'_> {
    /// Each key of [`ShapeKeys::KEYS`], and whether it is given.
    pub fn given(&self) -> [(&'static str, bool); 8] {
        let k = self.keys;
        let present = [
            k.point.is_some(),
            k.normal.is_some(),
            k.center.is_some(),
            k.radius.is_some(),
            k.axis.is_some(),
            k.length.is_some(),
            k.size.is_some(),
            k.orientation.is_some(),
        ];
        std::array::from_fn(|i| (ShapeKeys::KEYS[i], present[i]))
    }

    fn vector(&self, key: &str) -> Option<[f64; 3]> {
        let k = self.keys;
        match key {
            "point" => k.point,
            "normal" => k.normal,
            "center" => k.center,
            "axis" => k.axis,
            _ => None,
        }
    }

    /// A finite point (a present key: `from_keys` checked).
    fn vec(&self, key: &str) -> Result<[f64; 3], KeyError> {
        let v = self.vector(key).unwrap_or_default();
        for (i, x) in v.iter().enumerate() {
            if !x.is_finite() {
                return Err(KeyError {
                    key: format!("{key}[{i}]"),
                    message: format!("must be a finite number, got {x}"),
                });
            }
        }
        Ok(v)
    }

    /// A direction, made unit.
    fn direction(&self, key: &str) -> Result<[f64; 3], KeyError> {
        let v = self.vec(key)?;
        let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        if len == 0.0 {
            return Err(KeyError {
                key: key.into(),
                message: "must not be the zero vector: it gives the shape's direction".into(),
            });
        }
        Ok(v.map(|c| c / len))
    }

    fn positive(&self, key: &str) -> Result<f64, KeyError> {
        let v = match key {
            "radius" => self.keys.radius,
            _ => self.keys.length,
        };
        positive(key, v.unwrap_or_default())
    }

    /// The rotation of a quaternion (w, x, y, z) of any non-zero length
    /// (identity when absent).
    fn rotation(&self, key: &str) -> Result<[[f64; 3]; 3], KeyError> {
        let q = self.keys.orientation.unwrap_or([1.0, 0.0, 0.0, 0.0]);
        let len = q.iter().map(|c| c * c).sum::<f64>().sqrt();
        if !(len.is_finite() && len > 0.0) {
            return Err(KeyError {
                key: key.into(),
                message: "a quaternion (w, x, y, z) of non-zero, finite length".into(),
            });
        }
        Ok(crate::rotation::from_unit_quaternion(q.map(|c| c / len)))
    }
}

fn positive(key: &str, v: f64) -> Result<f64, KeyError> {
    if v.is_finite() && v > 0.0 {
        return Ok(v);
    }
    Err(KeyError {
        key: key.into(),
        message: if v.is_finite() {
            format!("must be positive, got {v}")
        } else {
            format!("must be a finite number, got {v}")
        },
    })
}

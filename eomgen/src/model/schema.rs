//! The model file format: every key a user can write. `docs/model-format.md`
//! documents each one; keep the two in step.

use serde::{Deserialize, Serialize};

/// A declared arm (one `models/<arm>.toml`).
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Model {
    /// Display name.
    pub name: String,
    #[serde(default)]
    pub description: Option<String>,
    /// Gravitational acceleration in the world frame (m/s^2).
    pub gravity: [f64; 3],
    pub base: Base,
    #[serde(rename = "segment")]
    pub segments: Vec<Segment>,
    #[serde(default)]
    pub tip: Tip,
}

#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Base {
    /// Where the arm is clamped (m).
    #[serde(default)]
    pub position: [f64; 3],
    /// Direction of the undeformed arm (any length; normalised).
    pub direction: [f64; 3],
}

/// How a segment is modelled. Structural: changing it derives anew.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq, Hash)]
#[serde(rename_all = "lowercase")]
pub enum Method {
    /// A chain of `elements` rigid links joined by revolute joints.
    Rigid,
}

impl Method {
    pub fn name(self) -> &'static str {
        match self {
            Method::Rigid => "rigid",
        }
    }
}

#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Segment {
    pub method: Method,
    /// Length of the whole segment (m).
    pub length: f64,
    /// Number of elements (links): structural.
    #[serde(default = "one")]
    pub elements: usize,
    /// Mass of the whole segment (kg); or give `density` and `outer_radius`.
    #[serde(default)]
    pub mass: Option<f64>,
    /// Density (kg/m^3) of a circular section.
    #[serde(default)]
    pub density: Option<f64>,
    /// Outer radius of the section (m).
    #[serde(default)]
    pub outer_radius: Option<f64>,
    /// Inner radius of a hollow section (m).
    #[serde(default)]
    pub inner_radius: Option<f64>,
    /// Rotational stiffness of each joint (N m / rad).
    #[serde(default)]
    pub joint_stiffness: f64,
    /// Rotational damping of each joint (N m s / rad).
    #[serde(default)]
    pub joint_damping: f64,
}

fn one() -> usize {
    1
}

/// The tip payload. Which of its keys are present is structural: a model
/// without `mass` has no tip body and one without `force` no tip force, so
/// neither costs anything in the generated code.
#[derive(Clone, Debug, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Tip {
    /// Point mass at the tip (kg).
    #[serde(default)]
    pub mass: Option<f64>,
    /// Constant force at the tip, world frame (N).
    #[serde(default)]
    pub force: Option<[f64; 3]>,
}

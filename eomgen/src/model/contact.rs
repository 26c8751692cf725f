//! Contact: the obstacles a model's arms and bodies may touch
//! (`[[obstacle]]`), the force law between them (`[contact]`, overridden
//! per obstacle), and how the arm is sampled (docs/design.md section 8).
//!
//! Only the sampling is structural (`points_per_element`): the generator
//! emits the positions, velocities and Jacobians of the sampled points, and
//! the runtime computes gaps and forces from the numbers here, so an
//! obstacle or a law changes without a rebuild.

use runtime::obstacle::{KeyError, Shape, ShapeKeys};
use serde::{Deserialize, Serialize};

/// The force law of a contact.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq, Hash)]
#[serde(rename_all = "snake_case")]
pub enum ContactModel {
    /// F = k delta + c delta', never pulling.
    SpringDashpot,
    /// F = k delta^n.
    Hertz,
    /// F = k delta^n (1 + alpha delta'), alpha from the restitution and the
    /// impact velocity (or `damping` = k alpha given), never pulling.
    HuntCrossley,
    /// The chapter's impact stage: a velocity jump through the contact
    /// Jacobian with restitution e, then a unilateral constraint.
    Impulse,
}

impl ContactModel {
    pub const NAMES: [&'static str; 4] = ["spring_dashpot", "hertz", "hunt_crossley", "impulse"];
}

/// `[contact]` and an obstacle's `contact` table: every key optional, an
/// obstacle's keys over the model's over the defaults.
#[derive(Clone, Debug, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ContactLaw {
    #[serde(default)]
    pub model: Option<ContactModel>,
    /// k: N/m for spring_dashpot, N/m^n for hertz and hunt_crossley.
    #[serde(default)]
    pub stiffness: Option<f64>,
    /// n (hertz, hunt_crossley); default 1.5, the Hertz sphere's.
    #[serde(default)]
    pub exponent: Option<f64>,
    /// c (N s/m) for spring_dashpot; k alpha (N s/m^(n+1)) for
    /// hunt_crossley.
    #[serde(default)]
    pub damping: Option<f64>,
    /// e in [0, 1]: hunt_crossley's damping from it, impulse's rebound.
    #[serde(default)]
    pub restitution: Option<f64>,
    /// Coulomb coefficient mu.
    #[serde(default)]
    pub friction: Option<f64>,
    /// The slip speed (m/s) below which friction is regularised:
    /// F_t = -mu F_n v_t / sqrt(|v_t|^2 + v_s^2).
    #[serde(default)]
    pub slip_velocity: Option<f64>,
}

/// `[contact]`: the default law (the keys of [`ContactLaw`]), and how the
/// arms are sampled. (serde's `flatten` would not deny unknown keys.)
#[derive(Clone, Debug, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ContactDecl {
    #[serde(default)]
    pub model: Option<ContactModel>,
    #[serde(default)]
    pub stiffness: Option<f64>,
    #[serde(default)]
    pub exponent: Option<f64>,
    #[serde(default)]
    pub damping: Option<f64>,
    #[serde(default)]
    pub restitution: Option<f64>,
    #[serde(default)]
    pub friction: Option<f64>,
    #[serde(default)]
    pub slip_velocity: Option<f64>,
    /// Points checked along each element (structural), the last at the
    /// element's end; default 3.
    #[serde(default)]
    pub points_per_element: Option<usize>,
    /// Contact between non-neighbouring elements of the arms.
    #[serde(default)]
    pub self_contact: bool,
}

impl ContactDecl {
    /// The model-wide law.
    pub fn law(&self) -> ContactLaw {
        ContactLaw {
            model: self.model,
            stiffness: self.stiffness,
            exponent: self.exponent,
            damping: self.damping,
            restitution: self.restitution,
            friction: self.friction,
            slip_velocity: self.slip_velocity,
        }
    }
}

/// `[[obstacle]]`: a fixed shape, or one moved by input channels. The
/// shapes, their keys and their checks are runtime's
/// (`runtime::obstacle::Shape::from_keys`): one definition from the model
/// file to the contact forces.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
pub struct ObstacleDecl {
    pub name: String,
    /// One of `runtime::obstacle::Shape::NAMES`.
    pub shape: String,
    /// Input channels of the obstacle's displacement along x, y, z (m).
    #[serde(default)]
    pub translation_inputs: Option<Vec<String>>,
    /// This obstacle's law, over `[contact]`.
    #[serde(default)]
    pub contact: ContactLaw,
    /// The shape's keys, and any other: [`ObstacleDecl::geometry`] reads
    /// them (so that a wrong key is named with its path and what an
    /// obstacle takes).
    #[serde(flatten)]
    pub keys: toml::Table,
}

impl ObstacleDecl {
    /// The obstacle's shape from its keys, by runtime's recipe for it; an
    /// error names the key (relative to the obstacle) and what is wrong.
    pub fn geometry(&self) -> Result<Shape, KeyError> {
        if let Some(k) = (self.keys.keys()).find(|k| !ShapeKeys::KEYS.contains(&k.as_str())) {
            return Err(KeyError {
                key: k.clone(),
                message: format!(
                    "not a key of an obstacle: it takes name, shape, translation_inputs, contact and its shape's keys ({})",
                    ShapeKeys::KEYS.join(", ")
                ),
            });
        }
        let keys: ShapeKeys = serde_path_to_error::deserialize(toml::Value::Table(
            self.keys.clone(),
        ))
        .map_err(|e| KeyError {
            key: e.path().to_string(),
            message: e.into_inner().to_string(),
        })?;
        Shape::from_keys(&self.shape, &keys)
    }
}

impl ContactLaw {
    /// `self`'s keys where given, else `under`'s.
    pub fn over(&self, under: &ContactLaw) -> ContactLaw {
        ContactLaw {
            model: self.model.or(under.model),
            stiffness: self.stiffness.or(under.stiffness),
            exponent: self.exponent.or(under.exponent),
            damping: self.damping.or(under.damping),
            restitution: self.restitution.or(under.restitution),
            friction: self.friction.or(under.friction),
            slip_velocity: self.slip_velocity.or(under.slip_velocity),
        }
    }
}

/// Default points per element.
pub const POINTS_PER_ELEMENT: usize = 3;

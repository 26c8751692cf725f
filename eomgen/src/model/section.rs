//! A segment's section other than a circle (`[segment.section]`): a
//! rectangle or an ellipse of `height` along the section's y (in a planar
//! arm's plane, across the arm) and `width` along its z (out of the plane),
//! with its area, second moments about y and z and torsion constant; or a
//! section given by its properties (a beam's stiffnesses and inertias per
//! length, as tables of commercial profiles or a finite-element section
//! analysis give them).

use serde::{Deserialize, Serialize};

/// A value alike along both section axes, or one along each (y, z).
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq)]
#[serde(
    untagged,
    expecting = "`shear_stiffness`: a number, or two: [along y, along z] (N)"
)]
pub enum OneOrTwo {
    One(f64),
    Two([f64; 2]),
}

impl OneOrTwo {
    pub fn pair(self) -> [f64; 2] {
        match self {
            Self::One(v) => [v; 2],
            Self::Two(p) => p,
        }
    }
}

/// A rectangle or an ellipse (full axes, m).
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields, tag = "shape", rename_all = "lowercase")]
pub enum SectionShape {
    Rectangle {
        width: f64,
        height: f64,
    },
    Ellipse {
        width: f64,
        height: f64,
    },
    /// Given directly: E A (N), k G A (N: one value, or along y and
    /// along z), [E I_y,
    /// E I_z] and G J (N m^2), rho A (kg/m), [rho I_y, rho I_z] and rho J
    /// (kg m, J defaulting to I_y + I_z), and the radius that holds the
    /// section (m, for contact and drawing).
    Properties {
        axial_stiffness: f64,
        shear_stiffness: Option<OneOrTwo>,
        bending_stiffness: [f64; 2],
        torsional_stiffness: f64,
        mass_per_length: f64,
        rotary_inertia: [f64; 2],
        polar_inertia: Option<f64>,
        radius: Option<f64>,
    },
}

/// A section's values given directly (`SectionShape::Properties`), where a
/// segment's answers take them instead of the material's and the shape's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Given {
    pub ea: f64,
    /// k G A along y, along z.
    pub ga: Option<[f64; 2]>,
    /// About y, about z.
    pub ei: [f64; 2],
    pub gj: f64,
    pub rho_a: f64,
    /// rho I about y, about z, and rho J (kg m).
    pub rho_i: [f64; 2],
    pub rho_j: f64,
}

impl SectionShape {
    /// The values given directly, for a `properties` section.
    pub fn given(&self) -> Option<Given> {
        match *self {
            Self::Properties {
                axial_stiffness,
                shear_stiffness,
                bending_stiffness,
                torsional_stiffness,
                mass_per_length,
                rotary_inertia,
                polar_inertia,
                ..
            } => Some(Given {
                ea: axial_stiffness,
                ga: shear_stiffness.map(OneOrTwo::pair),
                ei: bending_stiffness,
                gj: torsional_stiffness,
                rho_a: mass_per_length,
                rho_i: rotary_inertia,
                rho_j: polar_inertia.unwrap_or(rotary_inertia[0] + rotary_inertia[1]),
            }),
            _ => None,
        }
    }

    /// (width along z, height along y) of a rectangle or an ellipse.
    pub fn sides(&self) -> Option<(f64, f64)> {
        match *self {
            Self::Rectangle { width, height } | Self::Ellipse { width, height } => {
                Some((width, height))
            }
            Self::Properties { .. } => None,
        }
    }

    /// The area (m^2); a section given by its properties has none (its
    /// mass and stiffnesses are given).
    pub fn area(&self) -> Option<f64> {
        let (w, h) = self.sides()?;
        Some(match self {
            Self::Ellipse { .. } => std::f64::consts::PI * w * h / 4.0,
            _ => w * h,
        })
    }

    /// Second moments (m^4) about the section's y (int z^2) and z
    /// (int y^2): the bends about y and about z.
    pub fn second_moments(&self) -> Option<[f64; 2]> {
        let (w, h) = self.sides()?;
        Some(match self {
            Self::Ellipse { .. } => {
                let (a, b) = (h / 2.0, w / 2.0);
                let pi = std::f64::consts::PI;
                [pi * a * b.powi(3) / 4.0, pi * b * a.powi(3) / 4.0]
            }
            _ => [h * w.powi(3) / 12.0, w * h.powi(3) / 12.0],
        })
    }

    /// St-Venant's torsion constant J (m^4): an ellipse's exact
    /// pi a^3 b^3 / (a^2 + b^2); a rectangle's by Roark's formula
    /// a b^3 (1/3 - 0.21 (b/a) (1 - b^4 / (12 a^4))), a >= b (within 0.2 %
    /// of the series solution: a square's 0.1408 a^4 against 0.1406 a^4).
    pub fn torsion(&self) -> Option<f64> {
        let (w, h) = self.sides()?;
        Some(match self {
            Self::Ellipse { .. } => {
                let (a, b) = (h / 2.0, w / 2.0);
                std::f64::consts::PI * a.powi(3) * b.powi(3) / (a * a + b * b)
            }
            _ => {
                let (a, b) = (w.max(h), w.min(h));
                let r = b / a;
                a * b.powi(3) * (1.0 / 3.0 - 0.21 * r * (1.0 - r.powi(4) / 12.0))
            }
        })
    }

    /// The radius of the circle that holds it, for contact and drawing (a
    /// `properties` section's `radius`, else none).
    pub fn bounding_radius(&self) -> f64 {
        match *self {
            Self::Rectangle { width, height } => 0.5 * width.hypot(height),
            Self::Ellipse { width, height } => 0.5 * width.max(height),
            Self::Properties { radius, .. } => radius.unwrap_or(0.0),
        }
    }
}

//! A segment's section other than a circle (`[segment.section]`): a
//! rectangle or an ellipse of `height` along the section's y (in a planar
//! arm's plane, across the arm) and `width` along its z (out of the plane).
//! Its area, second moments about y and z and torsion constant.

use serde::{Deserialize, Serialize};

/// A rectangle or an ellipse (full axes, m).
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields, tag = "shape", rename_all = "lowercase")]
pub enum SectionShape {
    Rectangle { width: f64, height: f64 },
    Ellipse { width: f64, height: f64 },
}

impl SectionShape {
    /// (width along z, height along y).
    pub fn sides(&self) -> (f64, f64) {
        match *self {
            Self::Rectangle { width, height } | Self::Ellipse { width, height } => (width, height),
        }
    }

    pub fn area(&self) -> f64 {
        let (w, h) = self.sides();
        match self {
            Self::Rectangle { .. } => w * h,
            Self::Ellipse { .. } => std::f64::consts::PI * w * h / 4.0,
        }
    }

    /// Second moments (m^4) about the section's y (int z^2) and z
    /// (int y^2): the bends about y and about z.
    pub fn second_moments(&self) -> [f64; 2] {
        let (w, h) = self.sides();
        match self {
            Self::Rectangle { .. } => [h * w.powi(3) / 12.0, w * h.powi(3) / 12.0],
            Self::Ellipse { .. } => {
                let (a, b) = (h / 2.0, w / 2.0);
                let pi = std::f64::consts::PI;
                [pi * a * b.powi(3) / 4.0, pi * b * a.powi(3) / 4.0]
            }
        }
    }

    /// St-Venant's torsion constant J (m^4): an ellipse's exact
    /// pi a^3 b^3 / (a^2 + b^2); a rectangle's by Roark's formula
    /// a b^3 (1/3 - 0.21 (b/a) (1 - b^4 / (12 a^4))), a >= b (within 0.2 %
    /// of the series solution: a square's 0.1408 a^4 against 0.1406 a^4).
    pub fn torsion(&self) -> f64 {
        let (w, h) = self.sides();
        match self {
            Self::Rectangle { .. } => {
                let (a, b) = (w.max(h), w.min(h));
                let r = b / a;
                a * b.powi(3) * (1.0 / 3.0 - 0.21 * r * (1.0 - r.powi(4) / 12.0))
            }
            Self::Ellipse { .. } => {
                let (a, b) = (h / 2.0, w / 2.0);
                std::f64::consts::PI * a.powi(3) * b.powi(3) / (a * a + b * b)
            }
        }
    }

    /// The radius of the circle that holds it, for contact and drawing.
    pub fn bounding_radius(&self) -> f64 {
        let (w, h) = self.sides();
        match self {
            Self::Rectangle { .. } => 0.5 * w.hypot(h),
            Self::Ellipse { .. } => 0.5 * w.max(h),
        }
    }
}

//! `[fluid]`: the arm is immersed. Each element displaces the fluid of
//! its outer section (buoyancy, at its middle) and is dragged by the
//! relative flow (Morison's quadratic drag, normal and tangential, at its
//! middle), a steady current optional.

use serde::{Deserialize, Serialize};

/// The fluid an arm moves in.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Fluid {
    /// Density (kg/m^3): water about 1000.
    pub density: f64,
    /// Drag coefficient across the arm (about 1.2 for a cylinder), on the
    /// projected area d l: F = 1/2 rho C_n d l |v_n| v_n. Default 0.
    #[serde(default)]
    pub drag_normal: f64,
    /// Skin-friction coefficient along the arm, on the wetted area pi d l.
    /// Default 0.
    #[serde(default)]
    pub drag_tangential: f64,
    /// The fluid's velocity, world frame (m/s).
    #[serde(default)]
    pub current: [f64; 3],
}

impl Fluid {
    /// Whether it drags (structural: the dissipation terms exist).
    pub fn drags(&self) -> bool {
        self.drag_normal != 0.0 || self.drag_tangential != 0.0
    }
}

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
    /// 2 (planar, in the x-y plane) or 3 (spatial). Structural.
    #[serde(default = "two")]
    pub dimensions: u8,
    /// Gravitational acceleration in the world frame (m/s^2).
    pub gravity: [f64; 3],
    pub base: Base,
    #[serde(rename = "segment")]
    pub segments: Vec<Segment>,
    #[serde(default)]
    pub tip: Tip,
    /// Defaults for `softarm simulate`; its options override them.
    #[serde(default)]
    pub simulate: SimulateDefaults,
}

/// `[simulate]`: how this arm is best simulated. Not structural.
#[derive(Clone, Debug, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SimulateDefaults {
    /// An integrator name, as `--solver` takes it.
    pub solver: Option<String>,
    pub t_end: Option<f64>,
    pub rtol: Option<f64>,
    pub atol: Option<f64>,
    /// Step of the fixed-step solvers (s).
    pub dt: Option<f64>,
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
    /// Piecewise constant curvature: `elements` arcs, one bending angle each
    /// (planar) or two bending angles, optional twist and stretch (3D).
    Pcc,
    /// Variable curvature: one constant-curvature arc per segment, each
    /// segment with its own length, section and material.
    Vc,
    /// Euler-Bernoulli elements with relative states: rigid elements joined
    /// at their midpoints by a rotation (two bending angles and a twist, as
    /// a rotation vector) and an optional stretch. 3D only.
    Ebr,
    /// Euler-Bernoulli elements with absolute states: each element's
    /// position and orientation in the world frame (6 coordinates), the
    /// elements coupled by beam springs (bending, twist, axial, shear).
    /// 3D only; twist and stretch are always present.
    Eba,
    /// Reduced-order model: curvature, twist and stretch as polynomials in
    /// s of degree `order`, the coefficients the coordinates; kinematics,
    /// mass and energies by `quadrature` slices along s. 3D only.
    Rom,
    /// The Cosserat rod, solved as a boundary value problem: statics only.
    Cosserat,
}

impl Method {
    pub fn name(self) -> &'static str {
        match self {
            Method::Rigid => "rigid",
            Method::Pcc => "pcc",
            Method::Vc => "vc",
            Method::Ebr => "ebr",
            Method::Eba => "eba",
            Method::Rom => "rom",
            Method::Cosserat => "cosserat",
        }
    }
}

/// Where the joints of a rigid segment sit. Structural.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq, Hash)]
#[serde(rename_all = "lowercase")]
pub enum Joints {
    /// At the base of each link (a pendulum chain).
    Base,
    /// At the middle of each element (Hencky's pseudo-rigid-body model of a
    /// continuous rod): half a link at the clamp and at the tip.
    Midpoint,
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
    /// Rotational stiffness of each joint (N m / rad); rigid segments.
    #[serde(default)]
    pub joint_stiffness: Option<f64>,
    /// Rotational damping of each joint (N m s / rad); rigid segments.
    #[serde(default)]
    pub joint_damping: Option<f64>,
    /// Young's modulus (Pa): bending stiffness E I from the section.
    #[serde(default)]
    pub youngs_modulus: Option<f64>,
    /// Bending stiffness E I (N m^2), instead of `youngs_modulus`.
    #[serde(default)]
    pub bending_stiffness: Option<f64>,
    /// Bending damping (N m^2 s): Rayleigh function eta kappa_dot^2 / 2 per
    /// unit length, i.e. (eta / l_e) theta_dot^2 / 2 per element.
    #[serde(default)]
    pub bending_damping: Option<f64>,
    /// Curvature at rest (1/m).
    #[serde(default)]
    pub rest_curvature: f64,
    /// Joint placement of a rigid segment (structural). Default: `midpoint`
    /// when the segment's stiffness comes from E I, else `base`.
    #[serde(default)]
    pub joints: Option<Joints>,
    /// 3D: the revolute axes of each joint of a rigid segment, in order, in
    /// the element frame (structural). Default `["z", "y"]`, plus `"x"` with
    /// twist: a universal or spherical joint.
    #[serde(default)]
    pub joint_axes: Option<Vec<Axis>>,
    /// 3D: whether elements twist about their axis (structural; default true).
    #[serde(default)]
    pub twist: Option<bool>,
    /// 3D: whether elements stretch (structural; default false).
    #[serde(default)]
    pub extension: Option<bool>,
    /// Shear modulus G (Pa) for the torsional stiffness G J; default E / 3
    /// (incompressible).
    #[serde(default)]
    pub shear_modulus: Option<f64>,
    /// Torsional stiffness G J (N m^2), instead of the shear modulus.
    #[serde(default)]
    pub torsional_stiffness: Option<f64>,
    /// Axial stiffness E A (N), instead of `youngs_modulus` times the area.
    #[serde(default)]
    pub axial_stiffness: Option<f64>,
    /// Axial damping (N s): Rayleigh function (c / l_e) stretch_dot^2 / 2
    /// per element.
    #[serde(default)]
    pub axial_damping: Option<f64>,
    /// Chamber holes along the segment (pneumatic actuators): they reduce
    /// the area, mass and second moments of the section.
    #[serde(default)]
    pub chambers: Option<Chambers>,
    /// rom: polynomial degree of the strain fields (structural; default 3).
    #[serde(default)]
    pub order: Option<usize>,
    /// rom: slices along s for kinematics, mass and energies (structural;
    /// default 4 (order + 1)).
    #[serde(default)]
    pub quadrature: Option<usize>,
}

impl Segment {
    /// Joint placement actually used (rigid segments).
    pub fn joint_placement(&self) -> Joints {
        self.joints.unwrap_or(
            if self.youngs_modulus.is_some() || self.bending_stiffness.is_some() {
                Joints::Midpoint
            } else {
                Joints::Base
            },
        )
    }

    /// Second moment of area of the section (m^4), if it has a radius.
    pub fn second_moment(&self) -> Option<f64> {
        let ro = self.outer_radius?;
        let ri = self.inner_radius.unwrap_or(0.0);
        let pi = std::f64::consts::PI;
        // n equally spaced holes at distance d: sum of d^2 sin^2 = n d^2 / 2
        // about any diameter (n >= 3), so the section stays isotropic.
        let holes = self.chambers.as_ref().map_or(0.0, |c| {
            let a = pi * c.radius * c.radius;
            c.count as f64 * (a * c.radius * c.radius / 4.0 + a * c.distance * c.distance / 2.0)
        });
        Some(pi / 4.0 * (ro.powi(4) - ri.powi(4)) - holes)
    }

    /// Bending stiffness E I (N m^2), if declared.
    pub fn ei(&self) -> Option<f64> {
        self.bending_stiffness
            .or_else(|| Some(self.youngs_modulus? * self.second_moment()?))
    }

    /// Area of the section (m^2), if it has a radius: the ring less the
    /// chamber holes.
    pub fn area(&self) -> Option<f64> {
        let ro = self.outer_radius?;
        let ri = self.inner_radius.unwrap_or(0.0);
        let holes = self
            .chambers
            .as_ref()
            .map_or(0.0, |c| c.count as f64 * c.radius * c.radius);
        Some(std::f64::consts::PI * (ro * ro - ri * ri - holes))
    }

    /// Torsional stiffness G J (N m^2): J = 2 I for circular sections, G
    /// defaulting to E / 3.
    pub fn gj(&self) -> Option<f64> {
        self.torsional_stiffness.or_else(|| {
            let g = self
                .shear_modulus
                .or_else(|| Some(self.youngs_modulus? / 3.0))?;
            Some(g * 2.0 * self.second_moment()?)
        })
    }

    /// Shear stiffness G A (N), shear coefficient 1.
    pub fn ga(&self) -> Option<f64> {
        let g = self
            .shear_modulus
            .or_else(|| Some(self.youngs_modulus? / 3.0))?;
        Some(g * self.area()?)
    }

    /// Axial stiffness E A (N).
    pub fn ea(&self) -> Option<f64> {
        self.axial_stiffness
            .or_else(|| Some(self.youngs_modulus? * self.area()?))
    }

    /// Lumped slices of the segment: `elements`, or `quadrature` for rom.
    pub fn slices(&self) -> usize {
        match self.method {
            Method::Rom => self.quadrature.unwrap_or(4 * (self.rom_order() + 1)),
            _ => self.elements,
        }
    }

    /// rom: the polynomial degree.
    pub fn rom_order(&self) -> usize {
        self.order.unwrap_or(3)
    }

    /// 3D: elements twist.
    pub fn twists(&self) -> bool {
        self.twist.unwrap_or(true)
    }

    /// 3D: elements stretch.
    pub fn stretches(&self) -> bool {
        self.extension.unwrap_or(false)
    }

    /// 3D: the revolute axes of each joint of a rigid segment.
    pub fn axes(&self) -> Vec<Axis> {
        self.joint_axes.clone().unwrap_or_else(|| {
            let mut a = vec![Axis::Z, Axis::Y];
            if self.twists() {
                a.push(Axis::X);
            }
            a
        })
    }
}

fn one() -> usize {
    1
}

fn two() -> u8 {
    2
}

/// Equally spaced circular chamber holes in a section.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Chambers {
    /// Number of holes (at least 3, equally spaced: the section stays
    /// isotropic in bending).
    pub count: usize,
    /// Hole radius (m).
    pub radius: f64,
    /// Distance of the hole centres from the axis (m).
    pub distance: f64,
}

/// An axis of an element's frame (x along the element).
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq, Hash)]
#[serde(rename_all = "lowercase")]
pub enum Axis {
    X,
    Y,
    Z,
}

impl Axis {
    pub fn index(self) -> usize {
        match self {
            Axis::X => 0,
            Axis::Y => 1,
            Axis::Z => 2,
        }
    }
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
    /// Constant moment on the tip, world frame (N m).
    #[serde(default)]
    pub moment: Option<[f64; 3]>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chamber_holes_reduce_area_and_second_moment_as_a_grid_integral_says() {
        let seg: Segment = toml::from_str(
            r#"
            method = "pcc"
            length = 0.1
            outer_radius = 0.0125
            inner_radius = 0.002
            chambers = { count = 6, radius = 0.0018, distance = 0.007 }
            "#,
        )
        .unwrap();
        let c = seg.chambers.clone().unwrap();
        // Midpoint rule on a fine grid over the square around the section.
        let (ro, ri) = (0.0125f64, 0.002f64);
        let n = 2000;
        let h = 2.0 * ro / n as f64;
        let (mut area, mut iy, mut iz) = (0.0, 0.0, 0.0);
        for a in 0..n {
            for b in 0..n {
                let (y, z) = (-ro + (a as f64 + 0.5) * h, -ro + (b as f64 + 0.5) * h);
                let r2 = y * y + z * z;
                if r2 > ro * ro || r2 < ri * ri {
                    continue;
                }
                let hole = (0..c.count).any(|k| {
                    let phi = 2.0 * std::f64::consts::PI * k as f64 / c.count as f64 + 0.3;
                    let (cy, cz) = (c.distance * phi.cos(), c.distance * phi.sin());
                    (y - cy).powi(2) + (z - cz).powi(2) < c.radius * c.radius
                });
                if !hole {
                    area += h * h;
                    iy += z * z * h * h;
                    iz += y * y * h * h;
                }
            }
        }
        let (a, i) = (seg.area().unwrap(), seg.second_moment().unwrap());
        assert!((a - area).abs() < 2e-3 * a, "area {a} vs grid {area}");
        for grid in [iy, iz] {
            assert!((i - grid).abs() < 2e-3 * i, "I {i} vs grid {grid}");
        }
    }
}

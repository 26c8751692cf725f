//! The model file format: every key a user can write. `docs/model-format.md`
//! documents each one; keep the two in step.

use serde::{Deserialize, Serialize};

use super::load::Load;
pub use super::methods::Method;
use super::profile::Profile;
use super::rest::RestCurvature;

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
    /// The arm of a single-arm file (absent when `[[arm]]`s declare them).
    #[serde(default)]
    pub base: Base,
    #[serde(default, rename = "segment")]
    pub segments: Vec<Segment>,
    #[serde(default)]
    pub tip: Tip,
    /// Tendons, each pulled by an input channel.
    #[serde(default, rename = "tendon")]
    pub tendons: Vec<Tendon>,
    /// Generalised forces on named coordinates (joint torques), each
    /// driven by an input channel.
    #[serde(default, rename = "torque")]
    pub torques: Vec<Torque>,
    /// Loads along the arm: at a point, or per unit length.
    #[serde(default, rename = "load")]
    pub loads: Vec<Load>,
    /// Input channels by name: time signals that drive pressures, tensions
    /// and tip loads at run time (not structural: swapping a data file or a
    /// signal needs no rebuild).
    #[serde(default)]
    pub inputs: std::collections::BTreeMap<String, super::signals::Input>,
    /// Measured tip motion to compare a simulation with.
    #[serde(default)]
    pub compare: Option<super::signals::Compare>,
    /// Defaults for `softarm simulate`; its options override them.
    #[serde(default)]
    pub simulate: SimulateDefaults,
    /// Several arms (`[[arm]]`), rigid bodies and joints: an assembly
    /// (`model::assembly`).
    #[serde(default, rename = "arm")]
    pub arms: Vec<ArmDecl>,
    #[serde(default, rename = "body")]
    pub bodies: Vec<BodyDecl>,
    #[serde(default, rename = "joint")]
    pub joints: Vec<JointDecl>,
    /// The default contact law and the arms' sampling.
    #[serde(default)]
    pub contact: Option<super::contact::ContactDecl>,
    #[serde(default, rename = "obstacle")]
    pub obstacles: Vec<super::contact::ObstacleDecl>,
    /// The fluid the arm is immersed in: buoyancy and drag.
    #[serde(default)]
    pub fluid: Option<super::fluid::Fluid>,
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
    /// generalized-alpha's spectral radius at infinity, in [0, 1].
    pub rho_inf: Option<f64>,
    /// Spacing of trajectory.csv's rows (s) [default: t_end / 500].
    pub output_dt: Option<f64>,
    /// Initial state: "rest" (default) or "static" (the equilibrium at t = 0).
    pub start: Option<Start>,
    /// Whether a viscoelastic arm starts relaxed at its start shape (it has
    /// rested there; default) or not (it was deformed just before t = 0).
    pub start_relaxed: Option<bool>,
    /// Initial coordinates by name (the rest 0, a free body's from its
    /// `position` and `angle`); `--q0` replaces them all.
    #[serde(default)]
    pub q0: std::collections::BTreeMap<String, f64>,
}

/// How a simulation starts.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum Start {
    /// At q0 (default straight), at rest.
    Rest,
    /// At rest in the static equilibrium at t = 0, found from q0.
    Static,
}

#[derive(Clone, Debug, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Base {
    /// Where the arm is clamped (m).
    #[serde(default)]
    pub position: [f64; 3],
    /// Direction of the undeformed arm (any length; normalised).
    pub direction: [f64; 3],
    /// A prescribed base motion: input channels of the displacement from
    /// `position` along x, y, z (m). Structural (the base's velocity and
    /// acceleration enter the equations).
    #[serde(default)]
    pub translation_inputs: Option<Vec<String>>,
    /// A prescribed base rotation: input channels of angles (rad) turned in
    /// sequence, each about its axis in the frame the turns before it left
    /// (intrinsic: z, y, x are yaw, pitch and roll), then `direction`. One
    /// turn, about z, in the plane. Structural.
    #[serde(default)]
    pub rotation_inputs: Option<Vec<String>>,
    /// The axis of each turn (3D, any length); default z, y, x in turn.
    #[serde(default)]
    pub rotation_axes: Option<Vec<[f64; 3]>>,
    /// A compliant base: the clamp is a mass on a spring and a damper to a
    /// driven point, `follow` (input channels of the point's displacement
    /// from `position` along x, y (, z); none: it stays put). Structural:
    /// present or not.
    #[serde(default)]
    pub mass: Option<f64>,
    /// N/m.
    #[serde(default)]
    pub stiffness: Option<f64>,
    /// N s/m.
    #[serde(default)]
    pub damping: Option<f64>,
    #[serde(default)]
    pub follow: Option<Vec<String>>,
    /// A compliant base that also turns: a rotational spring (N m/rad) and
    /// damper (N m s/rad) to the driven point's orientation, and the base's
    /// rotational inertia (kg m^2, default 0). Structural: present or not.
    #[serde(default)]
    pub rotational_stiffness: Option<f64>,
    #[serde(default)]
    pub rotational_damping: Option<f64>,
    #[serde(default)]
    pub inertia: Option<f64>,
    /// An assembly's arm based on another frame (`ARM.tip`,
    /// `ARM.segment.K.end` of an arm declared before it): carried by that
    /// arm's coordinates, its `position` and `direction` in that frame.
    /// Structural.
    #[serde(default)]
    pub on: Option<String>,
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
    /// Density (kg/m^3) of a circular section. This and the section and
    /// material values below are constant or vary along the segment
    /// (`Profile`).
    #[serde(default)]
    pub density: Option<Profile>,
    /// Outer radius of the section (m).
    #[serde(default)]
    pub outer_radius: Option<Profile>,
    /// Inner radius of a hollow section (m).
    #[serde(default)]
    pub inner_radius: Option<Profile>,
    /// A rectangular or elliptic section instead of a circle.
    #[serde(default)]
    pub section: Option<super::section::SectionShape>,
    /// Rotational stiffness of each joint (N m / rad); rigid segments.
    #[serde(default)]
    pub joint_stiffness: Option<f64>,
    /// Rotational damping of each joint (N m s / rad); rigid segments.
    #[serde(default)]
    pub joint_damping: Option<f64>,
    /// Young's modulus (Pa): bending stiffness E I from the section.
    #[serde(default)]
    pub youngs_modulus: Option<Profile>,
    /// Bending stiffness E I (N m^2), instead of `youngs_modulus`.
    #[serde(default)]
    pub bending_stiffness: Option<Profile>,
    /// Bending damping (N m^2 s): Rayleigh function eta kappa_dot^2 / 2 per
    /// unit length, i.e. (eta / l_e) theta_dot^2 / 2 per element.
    #[serde(default)]
    pub bending_damping: Option<f64>,
    /// Curvature at rest (1/m): one value (in 3D about z), or in 3D
    /// `[k_y, k_z]`; each constant or varying along the segment.
    #[serde(default)]
    pub rest_curvature: RestCurvature,
    /// 3D: twist at rest (rad/m) about the arm's axis: with a rest
    /// curvature, a helix.
    #[serde(default)]
    pub rest_twist: Option<Profile>,
    /// 3D, stretching elements: strain at rest (dimensionless), the
    /// elements' rest length (1 + strain) times their length.
    #[serde(default)]
    pub rest_stretch: Option<Profile>,
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
    /// 3D: whether elements shear, their centreline leaving the section's
    /// normal (structural; default false, true for pcs; eba always).
    #[serde(default)]
    pub shear: Option<bool>,
    /// Shear correction factor k of the shear stiffness k G A (default 1;
    /// Timoshenko's 0.9 or PyElastica's 27/28 for a solid circle).
    #[serde(default)]
    pub shear_factor: Option<f64>,
    /// A kink: the segment starts turned from the previous one's end (the
    /// base, for the first) by these angles (degrees): about z in the
    /// plane; in 3D about y and z, the rotation vector (0, y, z).
    #[serde(default)]
    pub turn: Option<Vec<f64>>,
    /// The segment starts this far (m) from the previous one's end, in that
    /// end's frame (before the turn).
    #[serde(default)]
    pub offset: Option<[f64; 3]>,
    /// 3D, stretching elements (`extension`; eba always): the material
    /// keeps its volume, so a stretch lambda thins the section (structural;
    /// default false; no effect on rigid links).
    #[serde(default)]
    pub incompressible: Option<bool>,
    /// Shear modulus G (Pa) for the torsional stiffness G J; default E / 3
    /// (incompressible).
    #[serde(default)]
    pub shear_modulus: Option<Profile>,
    /// Torsional stiffness G J (N m^2), instead of the shear modulus.
    #[serde(default)]
    pub torsional_stiffness: Option<Profile>,
    /// Axial stiffness E A (N), instead of `youngs_modulus` times the area.
    #[serde(default)]
    pub axial_stiffness: Option<Profile>,
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
    /// A viscoelastic material: its Prony series (`model::relaxation`);
    /// empty: elastic.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub relaxation: Vec<super::relaxation::Relaxation>,
}

/// A segment's answers from its keys alone; those its method decides
/// (`slices`, `stretches`, `shears`) are in `method/mod.rs`.
impl Segment {
    /// Joint placement actually used (rigid segments).
    pub fn joint_placement(&self) -> Joints {
        self.joints.unwrap_or(
            if self.youngs_modulus.is_some()
                || self.bending_stiffness.is_some()
                || self.given().is_some()
            {
                Joints::Midpoint
            } else {
                Joints::Base
            },
        )
    }

    /// This segment as a uniform one with the values it has at the
    /// fraction `x` of its length: what an element centred there reads.
    pub fn at(&self, x: f64) -> Segment {
        let here = |p: &Option<Profile>| p.as_ref().map(|p| Profile::Uniform(p.at(x)));
        Segment {
            density: here(&self.density),
            outer_radius: here(&self.outer_radius),
            inner_radius: here(&self.inner_radius),
            youngs_modulus: here(&self.youngs_modulus),
            bending_stiffness: here(&self.bending_stiffness),
            shear_modulus: here(&self.shear_modulus),
            torsional_stiffness: here(&self.torsional_stiffness),
            axial_stiffness: here(&self.axial_stiffness),
            rest_curvature: match &self.rest_curvature {
                RestCurvature::One(p) => RestCurvature::One(Profile::Uniform(p.at(x))),
                RestCurvature::Two(pair) => {
                    RestCurvature::Two(pair.clone().map(|p| Profile::Uniform(p.at(x))))
                }
            },
            rest_twist: here(&self.rest_twist),
            rest_stretch: here(&self.rest_stretch),
            chambers: self.chambers.as_ref().map(|c| Chambers {
                distance: Profile::Uniform(c.distance.at(x)),
                ..c.clone()
            }),
            ..self.clone()
        }
    }

    /// The rest strains at the fraction `x` along the segment, in
    /// `dimensions`: curvature about y and z (1/m), twist (rad/m), stretch.
    pub fn rest_at(&self, x: f64, dimensions: u8) -> [f64; 4] {
        let ([y, z], _) = self.rest_curvature.axes(dimensions == 3);
        let or_zero = |p: &Option<Profile>| p.as_ref().map_or(0.0, |p| p.at(x));
        [
            y.at(x),
            z.at(x),
            or_zero(&self.rest_twist),
            or_zero(&self.rest_stretch),
        ]
    }

    /// The first rest key that makes the segment other than straight at
    /// rest, if any.
    pub fn rest_key(&self) -> Option<&'static str> {
        let bent = |p: &Profile| p.knots().iter().any(|&v| v != 0.0);
        let curved = match &self.rest_curvature {
            RestCurvature::One(p) => bent(p),
            RestCurvature::Two(pair) => pair.iter().any(bent),
        };
        [
            ("rest_curvature", curved),
            ("rest_twist", self.rest_twist.is_some()),
            ("rest_stretch", self.rest_stretch.is_some()),
        ]
        .into_iter()
        .find_map(|(key, given)| given.then_some(key))
    }

    /// The segment starts turned or offset from the previous one's end.
    pub fn kinked(&self) -> bool {
        self.turn.is_some() || self.offset.is_some()
    }

    /// 3D: the rest shape needs more than a curvature about z (a curvature
    /// about y, a twist or a stretch is given): structural, so that the
    /// values may change without a rebuild.
    pub fn rest_3d(&self, dimensions: u8) -> bool {
        dimensions == 3
            && (self.rest_curvature.axes(true).1
                || self.rest_twist.is_some()
                || self.rest_stretch.is_some())
    }

    /// Whether any value varies along the segment (its section, material
    /// or rest shape).
    pub fn tapered(&self) -> bool {
        let rest: Vec<&Profile> = match &self.rest_curvature {
            RestCurvature::One(p) => vec![p],
            RestCurvature::Two(pair) => pair.iter().collect(),
        };
        (self.profiles().iter().filter_map(|(_, p)| *p))
            .chain(rest)
            .chain(self.rest_twist.as_ref())
            .chain(self.rest_stretch.as_ref())
            .any(|p| p.uniform().is_none())
    }

    /// The keys that may vary along the segment, with their profiles.
    pub fn profiles(&self) -> [(&'static str, Option<&Profile>); 9] {
        [
            ("density", self.density.as_ref()),
            ("outer_radius", self.outer_radius.as_ref()),
            ("inner_radius", self.inner_radius.as_ref()),
            ("youngs_modulus", self.youngs_modulus.as_ref()),
            ("bending_stiffness", self.bending_stiffness.as_ref()),
            ("shear_modulus", self.shear_modulus.as_ref()),
            ("torsional_stiffness", self.torsional_stiffness.as_ref()),
            ("axial_stiffness", self.axial_stiffness.as_ref()),
            (
                "chambers.distance",
                self.chambers.as_ref().map(|c| &c.distance),
            ),
        ]
    }

    /// The fractions where some value's profile bends (0, 1 and the
    /// tables' points), sorted: between two of them every value is linear.
    pub fn breaks(&self) -> Vec<f64> {
        let mut all: Vec<f64> = (self.profiles().iter())
            .flat_map(|(_, p)| p.map(Profile::breaks).unwrap_or_default())
            .chain([0.0, 1.0])
            .collect();
        all.sort_by(f64::total_cmp);
        all.dedup();
        all
    }

    /// A value of this section (a uniform segment's, or a tapered one's
    /// at its middle: elements read theirs through [`Segment::at`]).
    fn value(p: &Option<Profile>) -> Option<f64> {
        p.as_ref().map(|p| p.uniform().unwrap_or_else(|| p.at(0.5)))
    }

    pub fn outer(&self) -> Option<f64> {
        Self::value(&self.outer_radius)
    }

    pub fn inner(&self) -> Option<f64> {
        Self::value(&self.inner_radius)
    }

    pub fn modulus(&self) -> Option<f64> {
        Self::value(&self.youngs_modulus)
    }

    /// Second moment of area of the section (m^4) about its z axis, the
    /// axis a planar arm bends about, if it has a radius or a shape.
    pub fn second_moment(&self) -> Option<f64> {
        Some(self.second_moments()?[1])
    }

    /// Second moments of area (m^4) about the section's y and z axes
    /// through its centroid: the bends about y (int z^2) and about z (int
    /// y^2). A hole at angle a sits at (y, z) = d (cos a, sin a); isotropic
    /// patterns (sum cos 2a = sum sin 2a = 0) have n / 2 of cos^2 and of
    /// sin^2, the same about every diameter. Holes off the axis move the
    /// centroid (`centroid`), about which the arm bends: the parallel-axis
    /// term takes it there.
    pub fn second_moments(&self) -> Option<[f64; 2]> {
        if let Some(sec) = &self.section {
            return sec.second_moments();
        }
        let ro = self.outer()?;
        let ri = self.inner().unwrap_or(0.0);
        let pi = std::f64::consts::PI;
        let ring = pi / 4.0 * (ro.powi(4) - ri.powi(4));
        let Some(c) = &self.chambers else {
            return Some([ring, ring]);
        };
        let holes = c.hole_list();
        let d2 = c.offset() * c.offset();
        let about_axis = if c.equal_radii() {
            // One radius: n (a r^2 / 4 + a d^2 / 2) when isotropic.
            let r = holes.first().map_or(0.0, |h| h.radius);
            let (a, n, r2) = (pi * r * r, holes.len() as f64, r * r);
            if c.isotropic() {
                let i = ring - n * (a * r2 / 4.0 + a * d2 / 2.0);
                return Some([i, i]);
            }
            let sum =
                |f: fn(f64) -> f64| -> f64 { holes.iter().map(|h| f(h.angle.to_radians())).sum() };
            let (cos2, sin2) = (sum(|t| t.cos().powi(2)), sum(|t| t.sin().powi(2)));
            [
                ring - (n * a * r2 / 4.0 + a * d2 * sin2),
                ring - (n * a * r2 / 4.0 + a * d2 * cos2),
            ]
        } else {
            // Each hole's own moment (a r^2 / 4) and its parallel-axis term
            // about the circle's centre.
            let area_of = |h: &Hole| pi * h.radius * h.radius;
            let own: f64 = holes
                .iter()
                .map(|h| area_of(h) * h.radius * h.radius / 4.0)
                .sum();
            let sum = |f: fn(f64) -> f64| -> f64 {
                (holes.iter())
                    .map(|h| area_of(h) * f(h.angle.to_radians()))
                    .sum()
            };
            let (cos2, sin2) = (sum(|t| t.cos().powi(2)), sum(|t| t.sin().powi(2)));
            if c.isotropic() {
                let i = ring - (own + d2 * (cos2 + sin2) / 2.0);
                return Some([i, i]);
            }
            [ring - (own + d2 * sin2), ring - (own + d2 * cos2)]
        };
        if c.centred(false) {
            return Some(about_axis);
        }
        let [yc, zc] = self.centroid();
        let area = self.area()?;
        Some([
            about_axis[0] - area * zc * zc,
            about_axis[1] - area * yc * yc,
        ])
    }

    /// Where the section's centroid sits (y, z, m) from the centre of its
    /// outer circle: off it when chamber holes are not balanced about it.
    /// The arm's centreline runs through the centroid (its stiffness and
    /// the chambers' levers are taken about it).
    pub fn centroid(&self) -> [f64; 2] {
        let (Some(c), Some(area)) = (&self.chambers, self.area()) else {
            return [0.0, 0.0];
        };
        if c.centred(false) {
            return [0.0, 0.0];
        }
        let pi = std::f64::consts::PI;
        let first = |f: fn(f64) -> f64| -> f64 {
            (c.hole_list().iter())
                .map(|h| pi * h.radius * h.radius * c.offset() * f(h.angle.to_radians()))
                .sum()
        };
        // The holes' material is missing: the centroid moves away from them.
        [-first(f64::cos) / area, -first(f64::sin) / area]
    }

    /// The product of inertia I_yz (m^4) about the centroid: nonzero when
    /// the holes turn the section's principal axes away from y and z.
    pub fn product_moment(&self) -> f64 {
        let (Some(c), Some(area)) = (&self.chambers, self.area()) else {
            return 0.0;
        };
        let d2 = c.offset().powi(2);
        let about_axis: f64 = -(c.hole_list().iter())
            .map(|h| {
                let (t, a) = (
                    h.angle.to_radians(),
                    std::f64::consts::PI * h.radius * h.radius,
                );
                a * d2 * t.cos() * t.sin()
            })
            .sum::<f64>();
        let [yc, zc] = self.centroid();
        about_axis - area * yc * zc
    }

    /// Whether the section bends more stiffly about one of its axes than
    /// the other (3D: an anisotropic section's elements carry both).
    pub fn anisotropic(&self, dimensions: u8) -> bool {
        if dimensions != 3 || self.bending_stiffness.is_some() {
            return false;
        }
        let unequal = |[y, z]: [f64; 2]| (y - z).abs() > 1e-12 * y.abs().max(z.abs());
        let differ = |p: &Segment| {
            let given = p
                .given()
                .is_some_and(|g| unequal(g.ei) || unequal(g.rho_i) || g.ga.is_some_and(unequal));
            given || p.second_moments().is_some_and(unequal)
        };
        differ(self) || self.tapered() && self.breaks().iter().any(|&x| differ(&self.at(x)))
    }

    /// The section's values given directly (`shape = "properties"`).
    pub fn given(&self) -> Option<super::section::Given> {
        self.section.as_ref()?.given()
    }

    /// Bending stiffness E I (N m^2) about z, if declared.
    pub fn ei(&self) -> Option<f64> {
        Self::value(&self.bending_stiffness)
            .or_else(|| Some(self.given()?.ei[1]))
            .or_else(|| Some(self.modulus()? * self.second_moment()?))
    }

    /// Bending stiffness E I (N m^2) about y: E I about z where the section
    /// is isotropic or E I is given.
    pub fn ei_y(&self) -> Option<f64> {
        Self::value(&self.bending_stiffness)
            .or_else(|| Some(self.given()?.ei[0]))
            .or_else(|| Some(self.modulus()? * self.second_moments()?[0]))
    }

    /// Area of the section (m^2), if it has a radius: the ring less the
    /// chamber holes.
    pub fn area(&self) -> Option<f64> {
        if let Some(sec) = &self.section {
            return sec.area();
        }
        let ro = self.outer()?;
        let ri = self.inner().unwrap_or(0.0);
        let holes = self.chambers.as_ref().map_or(0.0, |c| {
            let holes = c.hole_list();
            match c.equal_radii() {
                true => holes
                    .first()
                    .map_or(0.0, |h| holes.len() as f64 * h.radius * h.radius),
                false => holes.iter().map(|h| h.radius * h.radius).sum(),
            }
        });
        Some(std::f64::consts::PI * (ro * ro - ri * ri - holes))
    }

    /// The shear modulus G, defaulting to E / 3 (incompressible).
    fn shear(&self) -> Option<f64> {
        Self::value(&self.shear_modulus).or_else(|| Some(self.modulus()? / 3.0))
    }

    /// Torsional stiffness G J (N m^2): J = 2 I for circular sections,
    /// St-Venant's for others, G defaulting to E / 3.
    pub fn gj(&self) -> Option<f64> {
        Self::value(&self.torsional_stiffness).or_else(|| {
            if let Some(g) = self.given() {
                return Some(g.gj);
            }
            let j = match &self.section {
                Some(sec) => sec.torsion()?,
                None => {
                    let [iy, iz] = self.second_moments()?;
                    iy + iz
                }
            };
            Some(self.shear()? * j)
        })
    }

    /// Whether the section's dimensions are given (a radius or a shape).
    pub fn has_section(&self) -> bool {
        self.outer_radius.is_some() || self.section.is_some()
    }

    /// Shear stiffness k G A (N) along the section's y, k the
    /// `shear_factor` (default 1).
    pub fn ga(&self) -> Option<f64> {
        Some(self.ga_pair()?[0])
    }

    /// Shear stiffness k G A (N) along y and along z: a `properties`
    /// section may give them apart; a shape's are alike.
    pub fn ga_pair(&self) -> Option<[f64; 2]> {
        if let Some(g) = self.given() {
            return g.ga;
        }
        Some([self.shear_factor.unwrap_or(1.0) * self.shear()? * self.area()?; 2])
    }

    /// Axial stiffness E A (N).
    pub fn ea(&self) -> Option<f64> {
        Self::value(&self.axial_stiffness)
            .or_else(|| Some(self.given()?.ea))
            .or_else(|| Some(self.modulus()? * self.area()?))
    }

    /// Mass per unit length (kg/m) at the fraction `x`: `density` times
    /// the section's area there, or a `mass` spread evenly.
    pub fn mass_per_length(&self, x: f64) -> Option<f64> {
        if let Some(g) = self.given() {
            return Some(g.rho_a);
        }
        match self.mass {
            Some(m) => Some(m / self.length),
            None => {
                let here = self.at(x);
                Some(here.density_value()? * here.area()?)
            }
        }
    }

    fn density_value(&self) -> Option<f64> {
        Self::value(&self.density)
    }

    /// rom: the polynomial degree.
    pub fn rom_order(&self) -> usize {
        self.order.unwrap_or(3)
    }

    /// 3D: elements twist.
    pub fn twists(&self) -> bool {
        self.twist.unwrap_or(true)
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

/// One chamber hole: its angle (degrees) and radius (m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hole {
    pub angle: f64,
    pub radius: f64,
}

/// Circular chamber holes along a segment, in the wall of its section:
/// pneumatic actuators when `inputs` drive them, passive holes otherwise.
///
/// Holes sit at `positions()` (degrees in the section, from the element
/// frame's y axis towards its z axis), each position a single hole or,
/// with `pair_spacing`, a pair at +- that angle (STIFF-FLOP's braided
/// pairs), of one radius or each position its own. In 3D the pattern must
/// keep the section's principal axes on y and z.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Chambers {
    /// Number of equally spaced positions, the first at angle 0.
    #[serde(default)]
    pub count: Option<usize>,
    /// Or the positions' angles (degrees) explicitly.
    #[serde(default)]
    pub angles: Option<Vec<f64>>,
    /// Each position a pair of holes at +- this angle (degrees).
    #[serde(default)]
    pub pair_spacing: Option<f64>,
    /// Hole radius (m): one for every position, or one per position.
    pub radius: OneOrMany,
    /// Distance of the hole centres from the axis (m): constant, or
    /// varying along the segment (`[base, tip]` or a table over s/L).
    pub distance: Profile,
    /// Area the pressure acts on, per hole (m^2; one, or one per
    /// position); default pi radius^2.
    #[serde(default)]
    pub area: Option<OneOrMany>,
    /// Input channel (pressure, Pa, gauge) of each position: structural.
    #[serde(default)]
    pub inputs: Option<Vec<String>>,
}

impl Chambers {
    /// Angles (degrees) of the positions.
    pub fn positions(&self) -> Vec<f64> {
        match (&self.angles, self.count) {
            (Some(a), _) => a.clone(),
            (None, Some(n)) => (0..n).map(|k| 360.0 * k as f64 / n as f64).collect(),
            (None, None) => Vec::new(),
        }
    }

    /// Angles (degrees) of every hole: positions, or pairs about them.
    pub fn holes(&self) -> Vec<f64> {
        let pos = self.positions();
        match self.pair_spacing {
            Some(h) => pos.iter().flat_map(|&a| [a - h, a + h]).collect(),
            None => pos,
        }
    }

    /// Every hole: its angle (degrees) and radius (m), its position's.
    pub fn hole_list(&self) -> Vec<Hole> {
        let radii = self.radius.values(self.positions().len());
        let pos = self.positions();
        pos.iter()
            .zip(radii)
            .flat_map(|(&a, radius)| match self.pair_spacing {
                Some(h) => vec![(a - h, radius), (a + h, radius)],
                None => vec![(a, radius)],
            })
            .map(|(angle, radius)| Hole { angle, radius })
            .collect()
    }

    /// The holes' distance from the axis: a uniform segment's (an
    /// element's segment, `Segment::at`), else at the segment's middle.
    pub fn offset(&self) -> f64 {
        self.distance.at(0.5)
    }

    /// The holes all of one radius.
    pub fn equal_radii(&self) -> bool {
        let r = self.radius.values(self.positions().len());
        r.windows(2).all(|w| w[0] == w[1])
    }

    /// Whether the holes bend alike about every diameter: sum a cos 2t =
    /// sum a sin 2t = 0 (a each hole's area) makes I_y = I_z and I_yz = 0
    /// (to round-off).
    pub fn isotropic(&self) -> bool {
        let holes = self.hole_list();
        let (cs, sn, total) = holes.iter().fold((0.0, 0.0, 0.0), |(x, y, s), h| {
            let (t, a) = (2.0 * h.angle.to_radians(), h.radius * h.radius);
            (x + a * t.cos(), y + a * t.sin(), s + a)
        });
        cs.hypot(sn) <= 1e-6 * total
    }

    /// Whether the holes leave the section's centroid on the arm's axis:
    /// sum cos a = 0 (the y offsets, all a planar arm bends by) and, in 3D,
    /// sum sin a = 0 too (to round-off).
    pub fn centred(&self, planar: bool) -> bool {
        let holes = self.hole_list();
        let (y, z, total) = holes.iter().fold((0.0, 0.0, 0.0), |(y, z, s), h| {
            let (t, a) = (h.angle.to_radians(), h.radius * h.radius);
            (y + a * t.cos(), z + a * t.sin(), s + a)
        });
        let off = if planar { y.abs() } else { y.hypot(z) };
        off <= 1e-6 * total
    }

    /// Holes per position.
    pub fn per_position(&self) -> usize {
        if self.pair_spacing.is_some() { 2 } else { 1 }
    }

    /// Pressure area of one hole at `position` (m^2).
    pub fn hole_area(&self, position: usize) -> f64 {
        let n = self.positions().len();
        match &self.area {
            Some(a) => a.values(n)[position],
            None => {
                let r = self.radius.values(n)[position];
                std::f64::consts::PI * r * r
            }
        }
    }
}

/// A tendon: a cable embedded at a fixed offset from the axis, pulled at the
/// base, terminated at the end of segment `end`. It does virtual work
/// -T dL on the fibre length L(q) it runs along, and only pulls.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Tendon {
    /// Input channel of its tension (N); a negative command is slack.
    pub input: String,
    /// Distance from the axis (m): one value, or one per segment it spans.
    pub distance: OneOrMany,
    /// Angle in the section (degrees, from the element frame's y axis
    /// towards z): one value, or one per segment it spans.
    #[serde(default)]
    pub angle: Option<OneOrMany>,
    /// Index of the segment at whose end it is terminated; default the last.
    #[serde(default)]
    pub end: Option<usize>,
}

/// A joint torque: a generalised force Q on one coordinate (N m on an angle,
/// N on a stretch), virtual work Q dq. The coordinate is named as
/// `softarm eom` lists them (`theta_0_3`, `bend_y_0_2`, `joint_z_1_0`, ...).
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Torque {
    pub coordinate: String,
    /// Input channel of its value.
    pub input: String,
}

/// A number, or one per item (a tendon's segments, a chamber's positions).
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(untagged, expecting = "a number, or a list of numbers (one per item)")]
pub enum OneOrMany {
    One(f64),
    Many(Vec<f64>),
}

impl OneOrMany {
    /// The value for item `s`.
    pub fn at(&self, s: usize) -> f64 {
        match self {
            OneOrMany::One(v) => *v,
            OneOrMany::Many(v) => v.get(s).copied().unwrap_or(f64::NAN),
        }
    }

    /// The values of `n` items.
    pub fn values(&self, n: usize) -> Vec<f64> {
        (0..n).map(|i| self.at(i)).collect()
    }

    /// Every value given.
    pub fn given(&self) -> Vec<f64> {
        match self {
            OneOrMany::One(v) => vec![*v],
            OneOrMany::Many(v) => v.clone(),
        }
    }
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
    /// Length of a rigid tip body (a cylinder along the tip axis, m): the
    /// tip point, where forces act and outputs are taken, is at its end.
    #[serde(default)]
    pub length: Option<f64>,
    /// Radius of that cylinder (m), for its rotational inertia.
    #[serde(default)]
    pub radius: Option<f64>,
    /// Input channels driving the three force components (structural).
    #[serde(default)]
    pub force_inputs: Option<[String; 3]>,
    /// Input channels driving the three moment components (structural).
    #[serde(default)]
    pub moment_inputs: Option<[String; 3]>,
    /// Frame of the tip force and moment: "world" (default) or "tip" (a
    /// load cell's frame, turning with the tip). Structural.
    #[serde(default)]
    pub wrench_frame: Option<WrenchFrame>,
    /// The wrench is a load cell's reading, in its frame: how its axes sit
    /// on the tip (`model::sensor`). Implies a wrench that turns with the
    /// tip.
    #[serde(default)]
    pub sensor_rotation: Option<SensorRotation>,
    /// Where the load cell's origin sits, in the tip frame (m): the force
    /// acts there. Structural (its moment about the tip point).
    #[serde(default)]
    pub sensor_offset: Option<[f64; 3]>,
}

/// The frame a tip wrench is given in.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq, Hash)]
#[serde(rename_all = "lowercase")]
pub enum WrenchFrame {
    World,
    Tip,
}

/// How the sensor's axes sit on the tip.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(untagged)]
pub enum SensorRotation {
    /// A rotation matrix R, v_tip = R v_sensor: its columns are the
    /// sensor's x, y, z axes in the tip frame.
    Matrix([[f64; 3]; 3]),
    /// A unit quaternion [w, x, y, z] turning the tip frame onto the
    /// sensor's.
    Quaternion([f64; 4]),
    /// The tip axis each sensor axis points along, e.g. `["z", "y", "-x"]`:
    /// the sensor's x is the tip's z, its y the tip's y, its z the tip's -x.
    Axes([String; 3]),
}

// The keys of an assembly: `[[arm]]`, `[[body]]`, `[[joint]]`
// (`model::assembly` gives them their meaning).
/// `[[arm]]`: one arm of several, keyed as a single-arm file keys its
/// top-level `[base]`, `[[segment]]` and `[tip]`.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ArmDecl {
    pub name: String,
    pub base: Base,
    #[serde(rename = "segment")]
    pub segments: Vec<Segment>,
    #[serde(default)]
    pub tip: Tip,
}

/// The shape of a rigid body, for its default inertia.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq, Hash)]
#[serde(rename_all = "lowercase")]
pub enum BodyShape {
    /// `radius`.
    Sphere,
    /// `radius` and `length`, its axis along the body's x.
    Cylinder,
    /// `size = [x, y, z]`.
    Box,
}

/// `[[body]]`: a rigid body, free (x, y and its angle in the plane) or
/// fixed where it is declared.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct BodyDecl {
    pub name: String,
    pub shape: BodyShape,
    #[serde(default)]
    pub radius: Option<f64>,
    #[serde(default)]
    pub length: Option<f64>,
    #[serde(default)]
    pub size: Option<[f64; 3]>,
    /// kg; or `density` (kg/m^3) times the shape's volume.
    #[serde(default)]
    pub mass: Option<f64>,
    #[serde(default)]
    pub density: Option<f64>,
    /// Planar: the moment of inertia about the body's centre, normal to
    /// the plane (kg m^2); default from the shape.
    #[serde(default)]
    pub inertia: Option<f64>,
    /// 3D: the principal moments about the body's x, y, z axes through its
    /// centre (kg m^2); default from the shape.
    #[serde(default)]
    pub principal_inertia: Option<[f64; 3]>,
    /// Initial position of the centre (m).
    #[serde(default)]
    pub position: [f64; 3],
    /// Initial angle of the body's frame from the world's (rad, planar).
    #[serde(default)]
    pub angle: f64,
    /// 3D: initial orientation of the body's frame, a quaternion (w, x, y,
    /// z; any non-zero length, normalised).
    #[serde(default)]
    pub orientation: Option<[f64; 4]>,
    /// Free (its own coordinates) or fixed where declared. Structural.
    #[serde(default = "yes")]
    pub free: bool,
}

fn yes() -> bool {
    true
}

/// What a joint holds.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq, Hash)]
#[serde(rename_all = "lowercase")]
pub enum JointKind {
    /// Position and orientation: the two frames move as one.
    Weld,
    /// Position only: a revolute joint in the plane, a ball-and-socket in
    /// 3D.
    Pin,
}

impl JointKind {
    pub fn name(self) -> &'static str {
        match self {
            Self::Weld => "weld",
            Self::Pin => "pin",
        }
    }
}

/// `[[joint]]`: frame `a`'s point at `offset_a` held to frame `b`'s at
/// `offset_b` (offsets in each frame's own axes); a weld also holds b's
/// angle at a's plus `angle`.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct JointDecl {
    pub name: String,
    pub kind: JointKind,
    pub a: String,
    pub b: String,
    #[serde(default)]
    pub offset_a: [f64; 3],
    #[serde(default)]
    pub offset_b: [f64; 3],
    #[serde(default)]
    pub angle: f64,
    /// 3D weld: b's frame is a's turned by this quaternion (w, x, y, z; any
    /// non-zero length, normalised); default none.
    #[serde(default)]
    pub orientation: Option<[f64; 4]>,
    /// An inactive joint is checked and then left out (structural): cut it
    /// with `--set joint.NAME.active=false`.
    #[serde(default = "active")]
    pub active: bool,
}

fn active() -> bool {
    true
}

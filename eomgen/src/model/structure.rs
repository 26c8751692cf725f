//! The structure of a model (what shapes the generated code) and its hash,
//! and the runtime parameter vector (what does not).
//!
//! Invariant: the parameter *layout* (names and order) is a function of the
//! structure alone, so one derivation serves every model with that
//! structure, and the parameter *values* are computed here at run time.

use sha2::{Digest, Sha256};

use super::assembly::{FrameRef, JointKind};
use super::schema::{Axis, Joints, Method, Model, WrenchFrame};

/// Bumped whenever derivation or emission changes what is generated, so
/// that cached tapes and generated files are re-derived.
pub const GENERATOR_VERSION: u32 = 74;

/// The structural part of one segment.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct SegmentShape {
    pub method: Method,
    pub elements: usize,
    /// Joint placement (rigid segments, and `Midpoint` for ebr; `Base` for
    /// others).
    pub joints: Joints,
    /// 3D: twist and stretch coordinates, and the joint axes of rigid
    /// segments (empty for other methods and in 2D).
    pub twist: bool,
    pub extension: bool,
    /// 3D: two shear coordinates an element (pcc, vc, pcs).
    pub shear: bool,
    /// Stretching thins the section at constant volume (pcc, vc, ebr with
    /// extension): bending and twist stiffness scale by lambda^-3, fibre
    /// offsets by lambda^-1/2.
    pub incompressible: bool,
    pub axes: Vec<Axis>,
    /// rom: the polynomial degree (0 otherwise).
    pub order: usize,
}

impl SegmentShape {
    /// Coordinates per element in 3D.
    pub fn coordinates_3d(&self) -> usize {
        crate::method::of(self.method).coordinates_per_element(self)
    }
}

/// Everything that shapes the equations; numbers are left out.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Structure {
    /// 2 or 3.
    pub dimensions: u8,
    pub segments: Vec<SegmentShape>,
    /// A tip body exists (`tip.mass` given).
    pub tip_mass: bool,
    /// A tip force exists (`tip.force` given).
    pub tip_force: bool,
    /// A tip moment exists (`tip.moment` given).
    pub tip_moment: bool,
    /// The tip body has a length (`tip.length` given): a cylinder whose end
    /// is the tip point.
    pub tip_length: bool,
    /// The tip force and moment turn with the tip (`wrench_frame = "tip"`).
    pub tip_frame_wrench: bool,
    /// Inputs drive the tip force, the tip moment: they are never folded
    /// into derived parameters.
    pub tip_force_driven: bool,
    pub tip_moment_driven: bool,
    /// Per segment: how many chamber positions inputs drive.
    pub chambers: Vec<usize>,
    /// Per tendon: the segment at whose end it is terminated.
    pub tendons: Vec<usize>,
    /// The coordinates that driven generalised forces act on.
    pub torques: Vec<String>,
    /// The base translates; how many prescribed turns it makes.
    pub base_translates: bool,
    pub base_turns: usize,
    /// The base is a mass on springs (coordinates of the assembly).
    pub base_compliant: bool,
    /// ... and follows a driven point (`base.follow`).
    pub base_follows: bool,
    /// ... and turns on a rotational spring (coordinates of the assembly).
    pub base_twists: bool,
    /// Contact points sampled along each element (0: no contact).
    pub contact_points: usize,
    /// Several arms, bodies and joints: the arms' own structures and what
    /// joins them (the fields above are then empty).
    pub assembly: Option<Box<AssemblyShape>>,
}

/// The structure of an assembly: its arms, which bodies are free, and
/// which frames each joint holds together, how.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct AssemblyShape {
    /// 2 or 3.
    pub dimensions: u8,
    pub arms: Vec<(String, Structure)>,
    /// Per body: its name (it names coordinates) and whether it is free
    /// (its own coordinates) or fixed.
    pub bodies: Vec<(String, bool)>,
    pub joints: Vec<JointShape>,
    /// Contact: every body's centre is a contact point, after the arms'.
    pub contact: bool,
}

#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct JointShape {
    pub name: String,
    pub kind: JointKind,
    pub a: FrameRef,
    pub b: FrameRef,
}

impl Structure {
    pub fn of(m: &Model) -> Self {
        if !m.is_assembly() {
            return Self::of_arm(m);
        }
        let frame = |t: &str| FrameRef::parse(t, m).unwrap_or(FrameRef::World);
        let assembly = AssemblyShape {
            dimensions: m.dimensions,
            arms: m
                .arm_models()
                .iter()
                .map(|(name, a)| (name.clone(), Self::of_arm(a)))
                .collect(),
            bodies: m.bodies.iter().map(|b| (b.name.clone(), b.free)).collect(),
            contact: m.has_contact(),
            joints: m
                .joints
                .iter()
                .map(|j| JointShape {
                    name: j.name.clone(),
                    kind: j.kind,
                    a: frame(&j.a),
                    b: frame(&j.b),
                })
                .collect(),
        };
        Self {
            dimensions: m.dimensions,
            segments: Vec::new(),
            tip_mass: false,
            tip_force: false,
            tip_moment: false,
            tip_length: false,
            tip_frame_wrench: false,
            tip_force_driven: false,
            tip_moment_driven: false,
            chambers: Vec::new(),
            tendons: Vec::new(),
            torques: Vec::new(),
            base_translates: false,
            base_turns: 0,
            base_compliant: false,
            base_follows: false,
            base_twists: false,
            contact_points: 0,
            assembly: Some(Box::new(assembly)),
        }
    }

    /// The structure of one arm (the model's own, or one of an assembly's).
    fn of_arm(m: &Model) -> Self {
        let spatial = m.dimensions == 3;
        Self {
            dimensions: m.dimensions,
            segments: m
                .segments
                .iter()
                .map(|s| {
                    let method = crate::method::of(s.method);
                    let (twist, extension, shear) = crate::method::strains(s);
                    SegmentShape {
                        // A method whose kinematics are another's (vc and pcs
                        // are pcc's arcs) is derived as that one: the same
                        // derivation (and compiled code) serves both.
                        method: method.derived_as().unwrap_or(s.method),
                        elements: s.slices(),
                        order: if method.polynomial_fields() {
                            s.rom_order()
                        } else {
                            0
                        },
                        joints: method.joints(s),
                        twist: spatial && twist,
                        extension: spatial && extension,
                        shear: spatial && shear,
                        incompressible: spatial && s.incompressible.unwrap_or(false),
                        axes: if spatial {
                            method.joint_axes(s)
                        } else {
                            Vec::new()
                        },
                    }
                })
                .collect(),
            tip_mass: m.tip.mass.is_some(),
            tip_force: m.tip.force.is_some() || m.tip.force_inputs.is_some(),
            // A sensor's force off the tip point has a moment about it.
            tip_moment: m.tip.moment.is_some()
                || m.tip.moment_inputs.is_some()
                || (m.tip.sensor_offset.is_some()
                    && (m.tip.force.is_some() || m.tip.force_inputs.is_some())),
            tip_length: m.tip.length.is_some(),
            tip_frame_wrench: m.tip.wrench_frame == Some(WrenchFrame::Tip) || m.tip.has_sensor(),
            tip_force_driven: m.tip.force_inputs.is_some(),
            tip_moment_driven: m.tip.moment_inputs.is_some()
                || (m.tip.sensor_offset.is_some() && m.tip.force_inputs.is_some()),
            chambers: m
                .segments
                .iter()
                .map(|s| {
                    s.chambers
                        .as_ref()
                        .and_then(|c| c.inputs.as_ref())
                        .map_or(0, Vec::len)
                })
                .collect(),
            tendons: m
                .tendons
                .iter()
                .map(|t| t.end.unwrap_or(m.segments.len() - 1))
                .collect(),
            torques: m.torques.iter().map(|t| t.coordinate.clone()).collect(),
            base_translates: m.base.translation_inputs.is_some(),
            base_turns: m.base.rotation_inputs.as_ref().map_or(0, Vec::len),
            base_compliant: m.base.is_compliant(),
            base_follows: m.base.is_compliant() && m.base.follow.is_some(),
            base_twists: m.base.turns_compliantly(),
            contact_points: m.contact_points(),
            assembly: None,
        }
    }

    /// Canonical text of the structure (what is hashed).
    pub fn canonical(&self) -> String {
        if let Some(a) = &self.assembly {
            let mut s = format!(
                "assembly of {} arms in {} dimensions\n",
                a.arms.len(),
                a.dimensions
            );
            for (name, arm) in &a.arms {
                s.push_str(&format!("arm {name:?}\n{}", arm.canonical()));
            }
            s.push_str(&format!("bodies {:?}\n", a.bodies));
            for j in &a.joints {
                s.push_str(&format!(
                    "joint {:?} {} {:?} {:?}\n",
                    j.name,
                    j.kind.name(),
                    j.a,
                    j.b
                ));
            }
            if a.contact {
                s.push_str("contact\n");
            }
            return s;
        }
        let space = if self.dimensions == 3 {
            "spatial"
        } else {
            "planar"
        };
        let mut s = format!("eomgen {GENERATOR_VERSION}\n{space}\n");
        for g in &self.segments {
            s.push_str(&format!(
                "segment {} {} {:?}",
                g.method.name(),
                g.elements,
                g.joints
            ));
            if self.dimensions == 3 {
                s.push_str(&format!(
                    " twist {} extension {} axes {:?}",
                    g.twist, g.extension, g.axes
                ));
                if g.incompressible {
                    s.push_str(" incompressible");
                }
                // Only when set: the hashes of models without shear stay.
                if g.shear {
                    s.push_str(" shear");
                }
            }
            if crate::method::of(g.method).polynomial_fields() {
                s.push_str(&format!(" order {}", g.order));
            }
            s.push('\n');
        }
        s.push_str(&format!(
            "tip mass {} force {}",
            self.tip_mass, self.tip_force
        ));
        if self.tip_moment {
            s.push_str(" moment true");
        }
        if self.tip_length {
            s.push_str(" length true");
        }
        if self.tip_frame_wrench {
            s.push_str(" frame tip");
        }
        if self.tip_force_driven || self.tip_moment_driven {
            s.push_str(&format!(
                " driven {} {}",
                self.tip_force_driven, self.tip_moment_driven
            ));
        }
        s.push('\n');
        // Actuators only when present: models without them keep their hash.
        if self.chambers.iter().any(|&n| n > 0) {
            s.push_str(&format!("chambers {:?}\n", self.chambers));
        }
        if !self.tendons.is_empty() {
            s.push_str(&format!("tendons {:?}\n", self.tendons));
        }
        if !self.torques.is_empty() {
            s.push_str(&format!("torques {:?}\n", self.torques));
        }
        if self.base_compliant {
            s.push_str(&format!("base compliant follows {}\n", self.base_follows));
            if self.base_twists {
                s.push_str("base compliant turns\n");
            }
        }
        if self.contact_points > 0 {
            s.push_str(&format!("contact points {}\n", self.contact_points));
        }
        if self.base_translates || self.base_turns > 0 {
            s.push_str(&format!(
                "base moves {} {}\n",
                self.base_translates, self.base_turns
            ));
        }
        s
    }

    /// The cache key: 16 hex digits of SHA-256 over the canonical text.
    pub fn hash(&self) -> String {
        let digest = Sha256::digest(self.canonical().as_bytes());
        digest.iter().take(8).map(|b| format!("{b:02x}")).collect()
    }

    pub fn elements(&self) -> usize {
        self.segments.iter().map(|s| s.elements).sum()
    }
}

impl SegmentShape {
    /// 3D: the strain fields of a soft element, in coordinate order: the
    /// bend pair, then twist and stretch where present.
    pub fn strain_fields(&self) -> Vec<&'static str> {
        let mut f = vec!["bend_y", "bend_z"];
        if self.twist {
            f.push("twist");
        }
        if self.extension {
            f.push("stretch");
        }
        if self.shear {
            f.extend(["shear_y", "shear_z"]);
        }
        f
    }
}

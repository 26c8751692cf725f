//! The structure of a model (what shapes the generated code) and its hash,
//! and the runtime parameter vector (what does not).
//!
//! Invariant: the parameter *layout* (names and order) is a function of the
//! structure alone, so one derivation serves every model with that
//! structure, and the parameter *values* are computed here at run time.

use sha2::{Digest, Sha256};

use super::assembly::{FrameRef, JointKind};
use super::schema::{Axis, Joints, Method};

/// Bumped whenever derivation or emission changes what is generated, so
/// that cached tapes and generated files are re-derived.
pub const GENERATOR_VERSION: u32 = 116;

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
    /// Its coordinates are polynomial strain fields' coefficients (rom),
    /// of degree `order` (0 otherwise).
    pub polynomial: bool,
    pub order: usize,
    /// The section varies along the segment where that shapes the
    /// equations (rom: its energies slice by slice); elsewhere each
    /// element's values are parameters, and this is false.
    pub varying: bool,
    /// 3D: its rest shape has a curvature about y, a twist or a stretch
    /// (their parameters exist), not only a curvature about z; for a
    /// method that places its rest shape (eba), any rest shape.
    pub rest_3d: bool,
    /// 3D: its section bends more stiffly about one axis than the other
    /// (its elements' `ElementParam::ANISOTROPIC` exist).
    pub anisotropic: bool,
    /// It starts turned or offset from the previous segment's end (its
    /// `KinkParam`s exist).
    pub kink: bool,
    /// Its driven chambers' levers vary along it (their distance from the
    /// axis does, or the section does under holes off its centre): each
    /// element reads its own (`Param::ChamberArm`).
    pub chambers_vary: bool,
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
    /// The `[[load]]`s along the arm.
    pub loads: Vec<super::load::LoadShape>,
    /// Immersed in a fluid (its parameters and the elements' displaced
    /// volumes and widths exist), and whether it drags.
    pub fluid: Option<bool>,
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
    /// Per arm: the frame its base sits on (an earlier arm's), if any.
    pub mounts: Vec<Option<FrameRef>>,
}

impl AssemblyShape {
    /// Some arm sits on another's frame: the arms' coordinates then move
    /// one another (one block of M, flat kernels).
    pub fn tree(&self) -> bool {
        self.mounts.iter().any(Option::is_some)
    }
}

#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct JointShape {
    pub name: String,
    pub kind: JointKind,
    pub a: FrameRef,
    pub b: FrameRef,
}

impl Structure {
    /// Canonical text of the structure (what is hashed).
    pub fn canonical(&self) -> String {
        if let Some(a) = &self.assembly {
            let mut s = format!(
                "assembly of {} arms in {} dimensions\n",
                a.arms.len(),
                a.dimensions
            );
            for (k, (name, arm)) in a.arms.iter().enumerate() {
                if let Some(Some(on)) = a.mounts.get(k) {
                    s.push_str(&format!("arm {name:?} on {on:?}\n"));
                }
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
            if g.polynomial {
                s.push_str(&format!(" order {}", g.order));
            }
            if g.varying {
                s.push_str(" varying");
            }
            if g.rest_3d {
                s.push_str(" rest3d");
            }
            if g.anisotropic {
                s.push_str(" anisotropic");
            }
            if g.kink {
                s.push_str(" kink");
            }
            if g.chambers_vary {
                s.push_str(" chambers_vary");
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
        if !self.loads.is_empty() {
            s.push_str(&format!("loads {:?}\n", self.loads));
        }
        if let Some(drags) = self.fluid {
            s.push_str(&format!("fluid drag {drags}\n"));
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

//! The structure of a model (what shapes the generated code) and its hash,
//! and the runtime parameter vector (what does not).
//!
//! Invariant: the parameter *layout* (names and order) is a function of the
//! structure alone, so one derivation serves every model with that
//! structure, and the parameter *values* are computed here at run time.

use sha2::{Digest, Sha256};

use super::schema::{Joints, Method, Model};

/// Bumped whenever derivation or emission changes what is generated, so
/// that cached tapes and generated files are re-derived.
pub const GENERATOR_VERSION: u32 = 21;

/// The structural part of one segment.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct SegmentShape {
    pub method: Method,
    pub elements: usize,
    /// Joint placement (rigid segments; `Base` for others).
    pub joints: Joints,
}

/// Everything that shapes the equations; numbers are left out.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Structure {
    pub segments: Vec<SegmentShape>,
    /// A tip body exists (`tip.mass` given).
    pub tip_mass: bool,
    /// A tip force exists (`tip.force` given).
    pub tip_force: bool,
}

impl Structure {
    pub fn of(m: &Model) -> Self {
        Self {
            segments: m
                .segments
                .iter()
                .map(|s| SegmentShape {
                    method: s.method,
                    elements: s.elements,
                    joints: match s.method {
                        Method::Rigid => s.joint_placement(),
                        Method::Pcc => Joints::Base,
                    },
                })
                .collect(),
            tip_mass: m.tip.mass.is_some(),
            tip_force: m.tip.force.is_some(),
        }
    }

    /// Canonical text of the structure (what is hashed).
    pub fn canonical(&self) -> String {
        let mut s = format!("eomgen {GENERATOR_VERSION}\nplanar\n");
        for g in &self.segments {
            s.push_str(&format!(
                "segment {} {} {:?}\n",
                g.method.name(),
                g.elements,
                g.joints
            ));
        }
        s.push_str(&format!(
            "tip mass {} force {}\n",
            self.tip_mass, self.tip_force
        ));
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

/// Per-element physical quantities, from the declared segment.
#[derive(Clone, Copy, Debug)]
pub struct ElementProps {
    pub length: f64,
    pub mass: f64,
    /// Rotational inertia (about the axis normal to the plane) of each rigid
    /// body of the element about its centre of mass: the whole link (rigid,
    /// base joints), each half link (rigid, midpoint joints), or the
    /// section's part m (r_o^2 + r_i^2) / 4 (pcc: the arc's part depends on
    /// the bend and is derived symbolically).
    pub inertia: f64,
    /// Joint or bending stiffness of the element (N m/rad): E I / l_e.
    pub stiffness: f64,
    /// Joint or bending damping (N m s/rad): eta / l_e.
    pub damping: f64,
    /// Angle at rest (rad): rest curvature times l_e.
    pub rest: f64,
}

pub fn element_props(m: &Model) -> Vec<ElementProps> {
    let mut out = Vec::new();
    for s in &m.segments {
        let n = s.elements as f64;
        let l = s.length / n;
        let ro = s.outer_radius.unwrap_or(0.0);
        let ri = s.inner_radius.unwrap_or(0.0);
        let mass = match (s.mass, s.density) {
            (Some(mass), _) => mass / n,
            (None, Some(rho)) => rho * std::f64::consts::PI * (ro * ro - ri * ri) * l,
            (None, None) => 0.0, // rejected by validation
        };
        // Uniform cylinders (hollow or solid) about a diameter through the
        // centre; slender rods when no radius is given.
        let section = mass * (ro * ro + ri * ri) / 4.0;
        let inertia = match (s.method, s.joint_placement()) {
            (Method::Rigid, Joints::Base) => mass * l * l / 12.0 + section,
            (Method::Rigid, Joints::Midpoint) => {
                (mass / 2.0) * (l / 2.0).powi(2) / 12.0 + section / 2.0
            }
            (Method::Pcc, _) => section,
        };
        let stiffness = match s.ei() {
            Some(ei) => ei / l,
            None => s.joint_stiffness.unwrap_or(0.0),
        };
        let damping = match s.bending_damping {
            Some(eta) => eta / l,
            None => s.joint_damping.unwrap_or(0.0),
        };
        for _ in 0..s.elements {
            out.push(ElementProps {
                length: l,
                mass,
                inertia,
                stiffness,
                damping,
                rest: s.rest_curvature * l,
            });
        }
    }
    out
}

/// Names and values of the runtime parameters, in layout order.
pub fn parameters(m: &Model) -> Vec<(String, f64)> {
    let d = m.base.direction;
    let mut p = vec![
        ("gravity.x".to_string(), m.gravity[0]),
        ("gravity.y".to_string(), m.gravity[1]),
        ("gravity.z".to_string(), m.gravity[2]),
        ("base.x".to_string(), m.base.position[0]),
        ("base.y".to_string(), m.base.position[1]),
        ("base.z".to_string(), m.base.position[2]),
        // Planar: the angle of the base direction from +x.
        ("base.angle".to_string(), d[1].atan2(d[0])),
    ];
    if let Some(mass) = m.tip.mass {
        p.push(("tip.mass".to_string(), mass));
    }
    if let Some(f) = m.tip.force {
        p.push(("tip.force.x".to_string(), f[0]));
        p.push(("tip.force.y".to_string(), f[1]));
        p.push(("tip.force.z".to_string(), f[2]));
    }
    for (k, e) in element_props(m).iter().enumerate() {
        p.push((format!("element[{k}].length"), e.length));
        p.push((format!("element[{k}].mass"), e.mass));
        p.push((format!("element[{k}].inertia"), e.inertia));
        p.push((format!("joint[{k}].stiffness"), e.stiffness));
        p.push((format!("joint[{k}].damping"), e.damping));
        p.push((format!("joint[{k}].rest"), e.rest));
    }
    p
}

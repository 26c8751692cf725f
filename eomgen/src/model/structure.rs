//! The structure of a model (what shapes the generated code) and its hash,
//! and the runtime parameter vector (what does not).
//!
//! Invariant: the parameter *layout* (names and order) is a function of the
//! structure alone, so one derivation serves every model with that
//! structure, and the parameter *values* are computed here at run time.

use sha2::{Digest, Sha256};

use super::schema::{Method, Model};

/// Bumped whenever derivation or emission changes what is generated, so
/// that cached tapes and generated files are re-derived.
pub const GENERATOR_VERSION: u32 = 8;

/// Everything that shapes the equations; numbers are left out.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Structure {
    pub segments: Vec<(Method, usize)>,
    /// A tip body exists (`tip.mass` given).
    pub tip_mass: bool,
    /// A tip force exists (`tip.force` given).
    pub tip_force: bool,
}

impl Structure {
    pub fn of(m: &Model) -> Self {
        Self {
            segments: m.segments.iter().map(|s| (s.method, s.elements)).collect(),
            tip_mass: m.tip.mass.is_some(),
            tip_force: m.tip.force.is_some(),
        }
    }

    /// Canonical text of the structure (what is hashed).
    pub fn canonical(&self) -> String {
        let mut s = format!("eomgen {GENERATOR_VERSION}\nplanar\n");
        for (m, n) in &self.segments {
            s.push_str(&format!("segment {} {}\n", m.name(), n));
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
        self.segments.iter().map(|s| s.1).sum()
    }
}

/// Per-element physical quantities, from the declared segment.
#[derive(Clone, Copy, Debug)]
pub struct ElementProps {
    pub length: f64,
    pub mass: f64,
    /// About the centre of mass, about the axis normal to the plane.
    pub inertia: f64,
    pub stiffness: f64,
    pub damping: f64,
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
        // A uniform cylinder (hollow or solid) about a diameter through its
        // centre; a slender rod when no radius is given.
        let inertia = mass * (l * l / 12.0 + (ro * ro + ri * ri) / 4.0);
        for _ in 0..s.elements {
            out.push(ElementProps {
                length: l,
                mass,
                inertia,
                stiffness: s.joint_stiffness,
                damping: s.joint_damping,
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
    }
    p
}

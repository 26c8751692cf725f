//! The structure of a model (what shapes the generated code) and its hash,
//! and the runtime parameter vector (what does not).
//!
//! Invariant: the parameter *layout* (names and order) is a function of the
//! structure alone, so one derivation serves every model with that
//! structure, and the parameter *values* are computed here at run time.

use sha2::{Digest, Sha256};

use super::schema::{Axis, Joints, Method, Model, WrenchFrame};

/// Bumped whenever derivation or emission changes what is generated, so
/// that cached tapes and generated files are re-derived.
pub const GENERATOR_VERSION: u32 = 44;

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
        match self.method {
            Method::Rigid => self.axes.len(),
            _ => 2 + usize::from(self.twist) + usize::from(self.extension),
        }
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
}

impl Structure {
    pub fn of(m: &Model) -> Self {
        let spatial = m.dimensions == 3;
        Self {
            dimensions: m.dimensions,
            segments: m
                .segments
                .iter()
                .map(|s| SegmentShape {
                    // vc is pcc one module per segment: the same kinematics,
                    // so the same derivation (and compiled code) serves both.
                    method: match s.method {
                        Method::Vc => Method::Pcc,
                        m => m,
                    },
                    elements: s.slices(),
                    order: if s.method == Method::Rom {
                        s.rom_order()
                    } else {
                        0
                    },
                    joints: match s.method {
                        Method::Rigid => s.joint_placement(),
                        Method::Ebr => Joints::Midpoint,
                        _ => Joints::Base,
                    },
                    twist: spatial
                        && (s.method == Method::Eba || (s.method != Method::Rigid && s.twists())),
                    extension: spatial
                        && (s.method == Method::Eba
                            || (s.method != Method::Rigid && s.stretches())),
                    incompressible: spatial && s.incompressible.unwrap_or(false),
                    axes: if spatial && s.method == Method::Rigid {
                        s.axes()
                    } else {
                        Vec::new()
                    },
                })
                .collect(),
            tip_mass: m.tip.mass.is_some(),
            tip_force: m.tip.force.is_some() || m.tip.force_inputs.is_some(),
            tip_moment: m.tip.moment.is_some() || m.tip.moment_inputs.is_some(),
            tip_length: m.tip.length.is_some(),
            tip_frame_wrench: m.tip.wrench_frame == Some(WrenchFrame::Tip),
            tip_force_driven: m.tip.force_inputs.is_some(),
            tip_moment_driven: m.tip.moment_inputs.is_some(),
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
        }
    }

    /// Canonical text of the structure (what is hashed).
    pub fn canonical(&self) -> String {
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
            }
            if g.method == Method::Rom {
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
    /// 3D: moment of inertia of each body about its own axis.
    pub axial_inertia: f64,
    /// 3D: G J / l_e (N m/rad) and its damping.
    pub twist_stiffness: f64,
    pub twist_damping: f64,
    /// 3D: E A / l_e (N/m) and c / l_e (N s/m).
    pub stretch_stiffness: f64,
    pub stretch_damping: f64,
    /// 3D, eba: G A / l_e (N/m).
    pub shear_stiffness: f64,
}

pub fn element_props(m: &Model) -> Vec<ElementProps> {
    let mut out = Vec::new();
    for s in &m.segments {
        let n = s.slices() as f64;
        let l = s.length / n;
        let ro = s.outer_radius.unwrap_or(0.0);
        let ri = s.inner_radius.unwrap_or(0.0);
        let mass = match (s.mass, s.density) {
            (Some(mass), _) => mass / n,
            (None, Some(rho)) => rho * s.area().unwrap_or(0.0) * l,
            (None, None) => 0.0, // rejected by validation
        };
        // Uniform cylinders (hollow, solid, with chamber holes) about a
        // diameter through the centre, m I / A ((r_o^2 + r_i^2) / 4 for a
        // ring); slender rods when no radius is given.
        let section = match (s.second_moment(), s.area()) {
            (Some(i), Some(a)) if a > 0.0 => mass * i / a,
            _ => mass * (ro * ro + ri * ri) / 4.0,
        };
        // Bodies: the whole link, or two half links (midpoint joints), or
        // the section's part of a pcc arc (in 2D the arc's part is derived
        // symbolically; in 3D the arc is lumped as a straight slice, below).
        let halves = matches!(
            (s.method, s.joint_placement()),
            (Method::Rigid, Joints::Midpoint) | (Method::Ebr, _)
        );
        let (inertia, axial_inertia) = match s.method {
            Method::Rigid if !halves => (mass * l * l / 12.0 + section, 2.0 * section),
            Method::Rigid | Method::Ebr => (
                (mass / 2.0) * (l / 2.0).powi(2) / 12.0 + section / 2.0,
                section,
            ),
            Method::Pcc | Method::Vc | Method::Rom | Method::Eba | Method::Cosserat => {
                let slice = if m.dimensions == 3 {
                    mass * l * l / 12.0
                } else {
                    0.0
                };
                (section + slice, 2.0 * section)
            }
        };
        let stiffness = match s.ei() {
            Some(ei) => ei / l,
            None => s.joint_stiffness.unwrap_or(0.0),
        };
        let damping = match s.bending_damping {
            Some(eta) => eta / l,
            None => s.joint_damping.unwrap_or(0.0),
        };
        let twist_stiffness = match s.gj() {
            Some(gj) => gj / l,
            None => s.joint_stiffness.unwrap_or(0.0),
        };
        let stretch_stiffness = s.ea().unwrap_or(0.0) / l;
        let stretch_damping = s.axial_damping.unwrap_or(0.0) / l;
        let shear_stiffness = s.ga().unwrap_or(0.0) / l;
        for _ in 0..s.slices() {
            out.push(ElementProps {
                length: l,
                mass,
                inertia,
                stiffness,
                damping,
                rest: s.rest_curvature * l,
                axial_inertia,
                twist_stiffness,
                twist_damping: damping,
                stretch_stiffness,
                stretch_damping,
                shear_stiffness,
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
    ];
    if m.dimensions == 3 {
        for (i, row) in base_rotation(d).iter().enumerate() {
            for (j, v) in row.iter().enumerate() {
                p.push((format!("base.R{i}{j}"), *v));
            }
        }
        for (c, v) in ["qw", "qx", "qy", "qz"].iter().zip(base_quaternion(d)) {
            p.push((format!("base.{c}"), v));
        }
    } else {
        // Planar: the angle of the base direction from +x.
        p.push(("base.angle".to_string(), d[1].atan2(d[0])));
    }
    // A moving base: the displacement and turn (inputs) with their first
    // and second time derivatives (inputs too, the signals' derivatives).
    if m.base.translation_inputs.is_some() {
        for (quantity, _) in BASE_TRANSLATION {
            for c in ["x", "y", "z"] {
                p.push((format!("base.{quantity}{c}"), 0.0));
            }
        }
    }
    for i in 0..m.base.rotation_inputs.as_ref().map_or(0, Vec::len) {
        for (quantity, _) in BASE_TURN {
            p.push((format!("base.{quantity}[{i}]"), 0.0));
        }
        if m.dimensions == 3 {
            let a = base_turn_axis(m, i);
            let n = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
            for (c, v) in ["x", "y", "z"].iter().zip(a) {
                p.push((format!("base.axis[{i}].{c}"), v / n));
            }
        }
    }
    if let Some(mass) = m.tip.mass {
        p.push(("tip.mass".to_string(), mass));
    }
    if let Some(f) = m.tip.force {
        p.push(("tip.force.x".to_string(), f[0]));
        p.push(("tip.force.y".to_string(), f[1]));
        p.push(("tip.force.z".to_string(), f[2]));
    }
    if m.tip.force.is_none() && m.tip.force_inputs.is_some() {
        for c in ["x", "y", "z"] {
            p.push((format!("tip.force.{c}"), 0.0));
        }
    }
    if m.tip.moment.is_some() || m.tip.moment_inputs.is_some() {
        let mo = m.tip.moment.unwrap_or_default();
        p.push(("tip.moment.x".to_string(), mo[0]));
        p.push(("tip.moment.y".to_string(), mo[1]));
        p.push(("tip.moment.z".to_string(), mo[2]));
    }
    if let Some(len) = m.tip.length {
        // A uniform cylinder along the tip axis, about its centre.
        let mass = m.tip.mass.unwrap_or(0.0);
        let r = m.tip.radius.unwrap_or(0.0);
        p.push(("tip.length".to_string(), len));
        p.push((
            "tip.inertia".to_string(),
            mass * (3.0 * r * r + len * len) / 12.0,
        ));
        p.push(("tip.axial_inertia".to_string(), mass * r * r / 2.0));
    }
    for (k, e) in element_props(m).iter().enumerate() {
        p.push((format!("element[{k}].length"), e.length));
        p.push((format!("element[{k}].mass"), e.mass));
        p.push((format!("element[{k}].inertia"), e.inertia));
        p.push((format!("joint[{k}].stiffness"), e.stiffness));
        p.push((format!("joint[{k}].damping"), e.damping));
        p.push((format!("joint[{k}].rest"), e.rest));
        if m.dimensions == 3 {
            p.push((format!("element[{k}].axial_inertia"), e.axial_inertia));
            p.push((format!("twist[{k}].stiffness"), e.twist_stiffness));
            p.push((format!("twist[{k}].damping"), e.twist_damping));
            p.push((format!("stretch[{k}].stiffness"), e.stretch_stiffness));
            p.push((format!("stretch[{k}].damping"), e.stretch_damping));
            p.push((format!("shear[{k}].stiffness"), e.shear_stiffness));
        }
    }
    // Actuators: per driven chamber position its pressure (an input) and
    // the pressure's lever: the holes' total area and first moments
    // a sum(z), a sum(y) in the section; per tendon its tension (an input)
    // and its offset in each segment it spans.
    for (s, seg) in m.segments.iter().enumerate() {
        let Some(c) = &seg.chambers else { continue };
        if c.inputs.is_none() {
            continue;
        }
        let a = c.hole_area();
        let spacing = c.pair_spacing.unwrap_or(0.0);
        for (j, angle) in c.positions().iter().enumerate() {
            let holes: Vec<f64> = if c.pair_spacing.is_some() {
                vec![angle - spacing, angle + spacing]
            } else {
                vec![*angle]
            };
            let (y, z) = holes.iter().fold((0.0, 0.0), |(y, z), h| {
                let h = h.to_radians();
                (y + c.distance * h.cos(), z + c.distance * h.sin())
            });
            p.push((format!("chamber[{s}][{j}].pressure"), 0.0));
            p.push((format!("chamber[{s}][{j}].area"), a * holes.len() as f64));
            p.push((format!("chamber[{s}][{j}].arm_y"), a * z));
            p.push((format!("chamber[{s}][{j}].arm_z"), a * y));
        }
    }
    for (i, t) in m.tendons.iter().enumerate() {
        p.push((format!("tendon[{i}].tension"), 0.0));
        let end = t.end.unwrap_or(m.segments.len() - 1);
        for s in 0..=end {
            let d = t.distance.at(s);
            let angle = t.angle.as_ref().map_or(0.0, |a| a.at(s)).to_radians();
            p.push((format!("tendon[{i}][{s}].y"), d * angle.cos()));
            p.push((format!("tendon[{i}][{s}].z"), d * angle.sin()));
        }
    }
    for i in 0..m.torques.len() {
        p.push((format!("torque[{i}]"), 0.0));
    }
    p
}

/// The base-motion parameters (name prefix) and the time derivative of
/// the input they take: displacement s, velocity v, acceleration a.
pub const BASE_TRANSLATION: [(&str, u8); 3] = [("s", 0), ("v", 1), ("a", 2)];
/// The axis of base turn i: as declared, else z, y, x in turn.
pub fn base_turn_axis(m: &Model, i: usize) -> [f64; 3] {
    const DEFAULT: [[f64; 3]; 3] = [[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]];
    m.base
        .rotation_axes
        .as_ref()
        .and_then(|a| a.get(i).copied())
        .unwrap_or(DEFAULT[i % 3])
}

/// A turn's angle, rate and acceleration (one set per turn, `[i]`).
pub const BASE_TURN: [(&str, u8); 3] = [("turn", 0), ("omega", 1), ("alpha", 2)];

/// A runtime parameter an input channel drives: the channel's value, or its
/// first or second time derivative (a moving base's velocity and
/// acceleration).
#[derive(Clone, Debug, PartialEq)]
pub struct Driven {
    pub param: String,
    pub channel: String,
    pub derivative: u8,
}

/// The runtime parameters that input channels drive. They change during a
/// run, so derivation never folds them into derived (precomputed)
/// parameters.
pub fn drives(m: &Model) -> Vec<Driven> {
    let value = |param: String, channel: &String| Driven {
        param,
        channel: channel.clone(),
        derivative: 0,
    };
    let mut d = Vec::new();
    if let Some(names) = &m.base.translation_inputs {
        for (quantity, derivative) in BASE_TRANSLATION {
            for (c, n) in ["x", "y", "z"].iter().zip(names) {
                d.push(Driven {
                    param: format!("base.{quantity}{c}"),
                    channel: n.clone(),
                    derivative,
                });
            }
        }
    }
    for (i, n) in m.base.rotation_inputs.iter().flatten().enumerate() {
        for (quantity, derivative) in BASE_TURN {
            d.push(Driven {
                param: format!("base.{quantity}[{i}]"),
                channel: n.clone(),
                derivative,
            });
        }
    }
    for (key, names) in [
        ("tip.force", &m.tip.force_inputs),
        ("tip.moment", &m.tip.moment_inputs),
    ] {
        if let Some(names) = names {
            for (c, n) in ["x", "y", "z"].iter().zip(names) {
                d.push(value(format!("{key}.{c}"), n));
            }
        }
    }
    for (s, seg) in m.segments.iter().enumerate() {
        if let Some(inputs) = seg.chambers.as_ref().and_then(|c| c.inputs.as_ref()) {
            for (j, n) in inputs.iter().enumerate() {
                d.push(value(format!("chamber[{s}][{j}].pressure"), n));
            }
        }
    }
    for (i, t) in m.tendons.iter().enumerate() {
        d.push(value(format!("tendon[{i}].tension"), &t.input));
    }
    for (i, t) in m.torques.iter().enumerate() {
        d.push(value(format!("torque[{i}]"), &t.input));
    }
    d
}

/// The quaternion (w, x, y, z) of [`base_rotation`]: (1 + c, x × u)
/// normalised, with c = x . u.
pub fn base_quaternion(d: [f64; 3]) -> [f64; 4] {
    let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    let u = [d[0] / n, d[1] / n, d[2] / n];
    let c = u[0];
    if c < -1.0 + 1e-12 {
        return [0.0, 0.0, 0.0, 1.0];
    }
    let s = (2.0 * (1.0 + c)).sqrt();
    [(1.0 + c) / s, 0.0, -u[2] / s, u[1] / s]
}

/// The rotation (rows) taking +x to the unit vector along `d` by the
/// shortest turn; a half turn about z when `d` points along -x.
pub fn base_rotation(d: [f64; 3]) -> [[f64; 3]; 3] {
    let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    let u = [d[0] / n, d[1] / n, d[2] / n];
    let c = u[0];
    if c < -1.0 + 1e-12 {
        return [[-1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0]];
    }
    // v = x × u = (0, -u_z, u_y); R = I + [v]x + [v]x^2 / (1 + c)
    let v = [0.0, -u[2], u[1]];
    let k = [[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]];
    let mut r = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            let k2: f64 = (0..3).map(|m| k[i][m] * k[m][j]).sum();
            r[i][j] = f64::from(u8::from(i == j)) + k[i][j] + k2 / (1.0 + c);
        }
    }
    r
}

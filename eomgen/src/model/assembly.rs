//! Several arms, rigid bodies and the joints between them: the keys of an
//! assembly (`[[arm]]`, `[[body]]`, `[[joint]]`), the frames a joint may
//! name, and each arm as the single-arm `Model` the rest of the generator
//! already knows (docs/design.md section 7).

pub use super::schema::{ArmDecl, BodyDecl, BodyShape, JointDecl, JointKind};
use super::schema::{Base, Model};

/// A frame a joint names. Arms and bodies by their index in the model.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FrameRef {
    World,
    Body(usize),
    /// The arm's tip point, its frame's x along the arm.
    Tip(usize),
    /// The end of segment `segment` of an arm.
    SegmentEnd {
        arm: usize,
        segment: usize,
    },
}

impl FrameRef {
    /// Read `world`, a body's name, `ARM.tip`, `ARM.segment.K.end` (an arm
    /// of a single-arm file is unnamed: `tip`, `segment.K.end`).
    pub fn parse(text: &str, m: &Model) -> Result<Self, String> {
        if text == "world" {
            return Ok(Self::World);
        }
        if let Some(b) = m.bodies.iter().position(|b| b.name == text) {
            return Ok(Self::Body(b));
        }
        let arms = arm_names(m);
        let (arm, rest) = match text.split_once('.') {
            _ if arms == [""] => (0, text),
            Some((name, rest)) => match arms.iter().position(|a| a == name) {
                Some(a) => (a, rest),
                None => return Err(unknown_frame(text, m)),
            },
            None => return Err(unknown_frame(text, m)),
        };
        if rest == "tip" {
            return Ok(Self::Tip(arm));
        }
        let segments = arm_segments(m, arm);
        let parts: Vec<&str> = rest.split('.').collect();
        if let ["segment", k, "end"] = parts[..] {
            return match k.parse::<usize>() {
                Ok(segment) if segment < segments => Ok(Self::SegmentEnd { arm, segment }),
                _ => Err(format!(
                    "\"{text}\": the arm has segments 0 to {}",
                    segments.saturating_sub(1)
                )),
            };
        }
        Err(unknown_frame(text, m))
    }
}

fn unknown_frame(text: &str, m: &Model) -> String {
    let mut known = vec!["world".to_string()];
    known.extend(m.bodies.iter().map(|b| b.name.clone()));
    for a in arm_names(m) {
        let dot = if a.is_empty() { "" } else { "." };
        known.push(format!("{a}{dot}tip"));
        known.push(format!("{a}{dot}segment.K.end"));
    }
    format!(
        "no frame \"{text}\"; a joint names one of: {}",
        known.join(", ")
    )
}

/// The arms' names: `[""]` for a single-arm file.
pub fn arm_names(m: &Model) -> Vec<String> {
    if m.arms.is_empty() && !m.segments.is_empty() {
        vec![String::new()]
    } else {
        m.arms.iter().map(|a| a.name.clone()).collect()
    }
}

fn arm_segments(m: &Model, arm: usize) -> usize {
    if m.arms.is_empty() {
        m.segments.len()
    } else {
        m.arms[arm].segments.len()
    }
}

impl Model {
    /// Whether this is more than one open chain from one base: several
    /// arms, bodies, joints or a compliant base.
    pub fn is_assembly(&self) -> bool {
        !self.arms.is_empty()
            || !self.bodies.is_empty()
            || !self.joints.is_empty()
            || self.base.is_compliant()
            || self.arms.iter().any(|a| a.base.is_compliant())
    }

    /// Each arm as a single-arm model (gravity, plane and inputs shared),
    /// with its name: the model itself, unnamed, for a single-arm file.
    pub fn arm_models(&self) -> Vec<(String, Model)> {
        if self.arms.is_empty() {
            if self.segments.is_empty() {
                return Vec::new();
            }
            let mut m = self.clone();
            m.bodies.clear();
            m.joints.clear();
            return vec![(String::new(), m)];
        }
        self.arms
            .iter()
            .map(|a| {
                let m = Model {
                    name: a.name.clone(),
                    base: a.base.clone(),
                    segments: a.segments.clone(),
                    tip: a.tip.clone(),
                    tendons: Vec::new(),
                    torques: Vec::new(),
                    compare: None,
                    arms: Vec::new(),
                    bodies: Vec::new(),
                    joints: Vec::new(),
                    ..self.clone()
                };
                (a.name.clone(), m)
            })
            .collect()
    }
}

impl BodyDecl {
    /// The shape's volume (m^3), if its dimensions are given.
    pub fn volume(&self) -> Option<f64> {
        let pi = std::f64::consts::PI;
        Some(match self.shape {
            BodyShape::Sphere => 4.0 / 3.0 * pi * self.radius?.powi(3),
            BodyShape::Cylinder => pi * self.radius?.powi(2) * self.length?,
            BodyShape::Box => self.size?.iter().product(),
        })
    }

    /// kg: `mass`, or `density` times the volume.
    pub fn total_mass(&self) -> Option<f64> {
        self.mass.or_else(|| Some(self.density? * self.volume()?))
    }

    /// The moment of inertia about the centre normal to the plane (z):
    /// `inertia`, or the shape's (a cylinder's axis along x).
    pub fn planar_inertia(&self) -> Option<f64> {
        if self.inertia.is_some() {
            return self.inertia;
        }
        Some(self.principal()?[2])
    }

    /// The principal moments about the body's x, y, z through its centre:
    /// `principal_inertia`, or the shape's (a cylinder's axis along x).
    pub fn principal(&self) -> Option<[f64; 3]> {
        if self.principal_inertia.is_some() {
            return self.principal_inertia;
        }
        let m = self.total_mass()?;
        Some(match self.shape {
            BodyShape::Sphere => [0.4 * m * self.radius?.powi(2); 3],
            BodyShape::Cylinder => {
                let r2 = self.radius?.powi(2);
                let lateral = m * (3.0 * r2 + self.length?.powi(2)) / 12.0;
                [0.5 * m * r2, lateral, lateral]
            }
            BodyShape::Box => {
                let s = self.size?.map(|v| v * v);
                [
                    m * (s[1] + s[2]) / 12.0,
                    m * (s[0] + s[2]) / 12.0,
                    m * (s[0] + s[1]) / 12.0,
                ]
            }
        })
    }

    /// The initial (or fixed) orientation, normalised; identity if absent.
    pub fn quaternion(&self) -> [f64; 4] {
        normalised(self.orientation)
    }
}

/// A quaternion normalised, identity when absent or zero.
pub fn normalised(q: Option<[f64; 4]>) -> [f64; 4] {
    let q = q.unwrap_or([1.0, 0.0, 0.0, 0.0]);
    let n = q.iter().map(|v| v * v).sum::<f64>().sqrt();
    if n > 0.0 && n.is_finite() {
        q.map(|v| v / n)
    } else {
        [1.0, 0.0, 0.0, 0.0]
    }
}

impl Base {
    /// The base rides on springs (`mass`, `stiffness`, `damping` given).
    pub fn is_compliant(&self) -> bool {
        self.mass.is_some()
            || self.stiffness.is_some()
            || self.damping.is_some()
            || self.turns_compliantly()
    }

    /// The compliant base turns on its rotational spring and damper.
    pub fn turns_compliantly(&self) -> bool {
        self.rotational_stiffness.is_some()
            || self.rotational_damping.is_some()
            || self.inertia.is_some()
    }
}

/// The initial coordinates of a model whose coordinates are `names`: a
/// free body's from its declared position and angle, `[simulate] q0` by
/// name, the rest 0.
pub fn initial_coordinates(
    m: &Model,
    names: &[String],
    file: &str,
) -> Result<Vec<f64>, super::ModelError> {
    let mut q = vec![0.0; names.len()];
    let mut set = |name: &str, v: f64| {
        if let Some(i) = names.iter().position(|n| n == name) {
            q[i] = v;
        }
    };
    for b in m.bodies.iter().filter(|b| b.free) {
        for (c, v) in ["x", "y", "z"].iter().zip(b.position) {
            set(&format!("{}.{c}", b.name), v);
        }
        set(&format!("{}.angle", b.name), b.angle);
        for (c, v) in ["qw", "qx", "qy", "qz"].iter().zip(b.quaternion()) {
            set(&format!("{}.{c}", b.name), v);
        }
    }
    for (name, &v) in &m.simulate.q0 {
        let key = format!("simulate.q0.{name}");
        if !v.is_finite() {
            return Err(super::ModelError::new(
                file,
                key,
                format!("must be a finite number, got {v}"),
            ));
        }
        if !names.contains(name) {
            return Err(super::ModelError::new(
                file,
                key,
                format!(
                    "no coordinate \"{name}\"; the coordinates are {}",
                    names.join(", ")
                ),
            ));
        }
        set(name, v);
    }
    Ok(q)
}

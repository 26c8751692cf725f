//! Checks of an assembly: every arm as a single-arm file is checked (its
//! errors under `arm.NAME.`), then names, bodies, joints and compliant
//! bases. What needs numbers (redundant joints, an assembly that cannot
//! close) is checked where the numbers are, before a run.

use std::collections::HashSet;

use super::assembly::{BodyDecl, BodyShape, FrameRef};
use super::check::Check;
use super::error::ModelError;
use super::schema::{Base, Model};

/// The assembly's own checks; `arm` checks one arm as a single-arm model.
pub(super) fn check_assembly(
    ck: &Check,
    arm: impl Fn(&Model) -> Result<(), ModelError>,
) -> Result<(), ModelError> {
    let m = ck.m;
    if m.dimensions != 2 {
        return ck.err(
            "dimensions".into(),
            "several arms, bodies, joints and compliant bases are planar so far: set dimensions = 2"
                .into(),
        );
    }
    if !m.arms.is_empty() && !m.segments.is_empty() {
        return ck.err(
            "segment".into(),
            "a model with [[arm]] declares every arm there: move the top-level [[segment]]s into an [[arm]]"
                .into(),
        );
    }
    if !m.arms.is_empty() && (!m.tendons.is_empty() || !m.torques.is_empty()) {
        return ck.err(
            if m.tendons.is_empty() {
                "torque"
            } else {
                "tendon"
            }
            .into(),
            "tendons and joint torques belong to a single-arm file so far".into(),
        );
    }
    if m.arms.is_empty() && m.segments.is_empty() && m.bodies.is_empty() {
        return ck.err(
            String::new(),
            "nothing to simulate: declare [[segment]]s, [[arm]]s or [[body]]s".into(),
        );
    }
    names(ck)?;
    for (name, am) in m.arm_models() {
        let key = |path: &str| {
            if name.is_empty() {
                path.to_string()
            } else if path.is_empty() {
                format!("arm.{name}")
            } else {
                format!("arm.{name}.{path}")
            }
        };
        arm(&am).map_err(|e| ModelError::new(ck.file, key(&e.path), e.message))?;
        compliant_base(ck, &am.base, &key("base"))?;
    }
    for b in &m.bodies {
        body(ck, b)?;
    }
    joints(ck)
}

/// Arms and bodies share one namespace (joints name them); joints have
/// their own; `world` is the ground.
fn names(ck: &Check) -> Result<(), ModelError> {
    let m = ck.m;
    let mut frames = HashSet::new();
    let named = m
        .arms
        .iter()
        .map(|a| ("arm", &a.name))
        .chain(m.bodies.iter().map(|b| ("body", &b.name)));
    for (kind, name) in named {
        let path = format!("{kind}.{name}.name");
        if name.trim().is_empty() || name.contains('.') || name == "world" {
            return ck.err(
                path,
                format!(
                    "\"{name}\" cannot name a {kind}: use a non-empty name without dots, not \"world\""
                ),
            );
        }
        if !frames.insert(name.as_str()) {
            return ck.err(
                path,
                format!("duplicate name \"{name}\": arms and bodies need names of their own"),
            );
        }
    }
    let mut joints = HashSet::new();
    for j in &m.joints {
        if !joints.insert(j.name.as_str()) {
            return ck.err(
                format!("joint.{}.name", j.name),
                format!("duplicate joint name \"{}\"", j.name),
            );
        }
    }
    Ok(())
}

fn body(ck: &Check, b: &BodyDecl) -> Result<(), ModelError> {
    let key = |k: &str| format!("body.{}.{k}", b.name);
    let needs: &[(&str, Option<f64>)] = match b.shape {
        BodyShape::Sphere => &[("radius", b.radius)],
        BodyShape::Cylinder => &[("radius", b.radius), ("length", b.length)],
        BodyShape::Box => &[],
    };
    for (k, v) in needs {
        match v {
            Some(v) => ck.positive(&key(k), *v)?,
            None => {
                return ck.err(key(k), format!("a {:?} body needs its {k} (m)", b.shape));
            }
        }
    }
    if b.shape == BodyShape::Box {
        match b.size {
            Some(s) => {
                for (i, v) in s.iter().enumerate() {
                    ck.positive(&format!("{}[{i}]", key("size")), *v)?;
                }
            }
            None => return ck.err(key("size"), "a box body needs size = [x, y, z] (m)".into()),
        }
    }
    match (b.mass, b.density) {
        (Some(m), _) => ck.positive(&key("mass"), m)?,
        (None, Some(rho)) => ck.positive(&key("density"), rho)?,
        (None, None) => {
            return ck.err(
                key("mass"),
                "give the body's mass (kg) or its density (kg/m^3)".into(),
            );
        }
    }
    if let Some(i) = b.inertia {
        ck.finite(&key("inertia"), i)?;
        if i <= 0.0 {
            return ck.err(
                key("inertia"),
                format!(
                    "the moment of inertia must be positive (a positive-definite inertia), got {i}"
                ),
            );
        }
    }
    ck.vec3(&key("position"), &b.position)?;
    ck.finite(&key("angle"), b.angle)
}

fn joints(ck: &Check) -> Result<(), ModelError> {
    let m = ck.m;
    for j in &m.joints {
        let key = |k: &str| format!("joint.{}.{k}", j.name);
        let a = FrameRef::parse(&j.a, m).map_err(|e| ModelError::new(ck.file, key("a"), e))?;
        let b = FrameRef::parse(&j.b, m).map_err(|e| ModelError::new(ck.file, key("b"), e))?;
        if a == b {
            return ck.err(
                key("b"),
                format!(
                    "the joint holds \"{}\" to itself: name two different frames",
                    j.b
                ),
            );
        }
        if a == FrameRef::World && b == FrameRef::World {
            return ck.err(
                key("b"),
                "a joint between the world and itself holds nothing".into(),
            );
        }
        ck.vec3(&key("offset_a"), &j.offset_a)?;
        ck.vec3(&key("offset_b"), &j.offset_b)?;
        ck.finite(&key("angle"), j.angle)?;
    }
    Ok(())
}

fn compliant_base(ck: &Check, base: &Base, key: &str) -> Result<(), ModelError> {
    if !base.is_compliant() {
        return Ok(());
    }
    let k = |s: &str| format!("{key}.{s}");
    let Some(mass) = base.mass else {
        return ck.err(
            k("mass"),
            "a compliant base needs its mass (kg) with its stiffness and damping".into(),
        );
    };
    ck.positive(&k("mass"), mass)?;
    for (name, v) in [("stiffness", base.stiffness), ("damping", base.damping)] {
        ck.non_negative(&k(name), v.unwrap_or(0.0))?;
    }
    if base.translation_inputs.is_some() || base.rotation_inputs.is_some() {
        return ck.err(
            k("follow"),
            "a compliant base follows its driven point through its spring: give `follow`, not translation_inputs or rotation_inputs".into(),
        );
    }
    if let Some(f) = &base.follow {
        if f.len() != 2 {
            return ck.err(
                k("follow"),
                format!("give two input channels (x, y), got {}", f.len()),
            );
        }
        for (i, c) in f.iter().enumerate() {
            ck.channel(&format!("{}[{i}]", k("follow")), c)?;
        }
    }
    Ok(())
}

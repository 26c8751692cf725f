//! Checks of an assembly: every arm as a single-arm file is checked (its
//! errors under `arm.NAME.`), then names, bodies, joints and compliant
//! bases. What needs numbers (redundant joints, an assembly that cannot
//! close) is checked where the numbers are, before a run.

use std::collections::HashSet;

use crate::model::assembly::{BodyDecl, BodyShape, FrameRef};
use crate::model::{Base, Model};
use crate::model::{Check, ModelError};

/// The assembly's own checks; `arm` checks one arm as a single-arm model.
pub(super) fn check_assembly(
    ck: &Check,
    arm: impl Fn(&Model) -> Result<(), ModelError>,
) -> Result<(), ModelError> {
    let m = ck.m;
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
        compliant_base(ck, &am.base, &key("base"), m.dimensions as usize)?;
    }
    for b in &m.bodies {
        body(ck, b)?;
    }
    joints(ck)
}

/// An arm based on another's frame: an earlier arm's tip or segment end
/// (its coordinates then carry this one), in 3D, the base itself held
/// still there (neither compliant nor driven).
pub(super) fn mounts(ck: &Check) -> Result<(), ModelError> {
    let m = ck.m;
    if m.arms.is_empty() {
        if m.base.on.is_some() {
            return ck.err(
                "base.on".into(),
                "a base on another frame is an [[arm]]'s in an assembly: declare the arms as [[arm]]s"
                    .into(),
            );
        }
        return Ok(());
    }
    let arms = m.arm_models();
    for (i, a) in m.arms.iter().enumerate() {
        let Some(on) = &a.base.on else { continue };
        let key = format!("arm.{}.base.on", a.name);
        let err = |msg: String| ck.err(key.clone(), msg);
        let parent = match FrameRef::parse(on, m) {
            Ok(FrameRef::Tip(j)) | Ok(FrameRef::SegmentEnd { arm: j, .. }) => j,
            Ok(FrameRef::Body(_)) => {
                held_base(ck, &key, &a.base)?;
                continue;
            }
            Ok(FrameRef::World) => {
                return err(format!(
                    "\"{on}\": an arm sits on a body or on another arm's `ARM.tip` or `ARM.segment.K.end` (on the world: the arm's own base)"
                ));
            }
            Err(e) => return err(e),
        };
        if parent >= i {
            return err(format!(
                "\"{on}\" is not an arm declared before this one: declare the arm it sits on first"
            ));
        }
        if let Some(s) = (arms[parent].1.segments.iter())
            .find(|s| !crate::method::of(s.method).segment_end_frames())
        {
            return err(format!(
                "an {} arm's frames do not carry other arms yet",
                s.method.name()
            ));
        }
        held_base(ck, &key, &a.base)?;
    }
    Ok(())
}

/// An arm on another frame is held there: its base moves with the frame
/// alone.
fn held_base(ck: &Check, key: &str, b: &crate::model::Base) -> Result<(), ModelError> {
    if b.is_compliant() || b.translation_inputs.is_some() || b.rotation_inputs.is_some() {
        return ck.err(
            key.to_string(),
            "an arm on another's frame is held there: no compliant base, translation_inputs or rotation_inputs".into(),
        );
    }
    Ok(())
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
        ck.file_name(&path, &format!("a {kind}"), name)?;
        if name == "world" {
            return ck.err(
                path,
                format!("\"world\" is the ground and cannot name a {kind}"),
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
    let spatial = ck.m.dimensions == 3;
    let wrong = match (
        spatial,
        b.inertia.is_some(),
        b.principal_inertia.is_some(),
        b.orientation.is_some(),
    ) {
        (true, true, _, _) => Some((
            "inertia",
            "a planar key: in 3D give principal_inertia = [Ixx, Iyy, Izz]",
        )),
        (false, _, true, _) => Some((
            "principal_inertia",
            "a 3D key: in the plane give inertia (about z)",
        )),
        (false, _, _, true) => Some(("orientation", "a 3D key: in the plane give angle")),
        _ => None,
    };
    if let Some((k, why)) = wrong {
        return ck.err(key(k), why.into());
    }
    if let Some(p) = b.principal_inertia {
        for (i, v) in p.iter().enumerate() {
            ck.finite(&format!("{}[{i}]", key("principal_inertia")), *v)?;
        }
        let ok = p.iter().all(|&v| v > 0.0)
            && p[0] <= p[1] + p[2]
            && p[1] <= p[0] + p[2]
            && p[2] <= p[0] + p[1];
        if !ok {
            return ck.err(
                key("principal_inertia"),
                format!(
                    "not the inertia of a body: the moments must be positive (a positive-definite inertia) and each at most the sum of the other two, got {p:?}"
                ),
            );
        }
    }
    if let Some(q) = b.orientation {
        for (i, v) in q.iter().enumerate() {
            ck.finite(&format!("{}[{i}]", key("orientation")), *v)?;
        }
        if q.iter().all(|&v| v == 0.0) {
            return ck.err(
                key("orientation"),
                "must be a non-zero quaternion (w, x, y, z)".into(),
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
        for (k, f) in [("a", a), ("b", b)] {
            if let FrameRef::SegmentEnd { arm, .. } = f
                && let Some(s) = (m.arm_models()[arm].1.segments.iter())
                    .find(|s| !crate::method::of(s.method).segment_end_frames())
            {
                return ck.err(
                    key(k),
                    format!(
                        "an {} arm's segment ends are not frames yet: hold its tip",
                        s.method.name()
                    ),
                );
            }
        }
        if let Some(q) = j.orientation {
            if m.dimensions != 3 || j.kind != crate::model::assembly::JointKind::Weld {
                return ck.err(
                    key("orientation"),
                    "a 3D weld's key (the plane's weld takes angle)".into(),
                );
            }
            if q.iter().any(|v| !v.is_finite()) || q.iter().all(|&v| v == 0.0) {
                return ck.err(
                    key("orientation"),
                    "must be a finite, non-zero quaternion (w, x, y, z)".into(),
                );
            }
        }
        ck.vec3(&key("offset_a"), &j.offset_a)?;
        ck.vec3(&key("offset_b"), &j.offset_b)?;
        ck.finite(&key("angle"), j.angle)?;
    }
    Ok(())
}

fn compliant_base(ck: &Check, base: &Base, key: &str, axes: usize) -> Result<(), ModelError> {
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
    for (name, v) in [
        ("stiffness", base.stiffness),
        ("damping", base.damping),
        ("rotational_stiffness", base.rotational_stiffness),
        ("rotational_damping", base.rotational_damping),
        ("inertia", base.inertia),
    ] {
        ck.non_negative(&k(name), v.unwrap_or(0.0))?;
    }
    // Its turn is a coordinate of its own: without rotary inertia the
    // mass matrix may be singular (an arm adds little about its own axis).
    if base.turns_compliantly() {
        match base.inertia {
            Some(i) if i > 0.0 => {}
            _ => {
                return ck.err(
                    k("inertia"),
                    format!(
                        "a base that turns on its rotational spring needs its rotary inertia (kg m^2, positive), got {}",
                        base.inertia.map_or("none".into(), |i| i.to_string())
                    ),
                );
            }
        }
    }
    if base.translation_inputs.is_some() || base.rotation_inputs.is_some() {
        return ck.err(
            k("follow"),
            "a compliant base follows its driven point through its spring: give `follow`, not translation_inputs or rotation_inputs".into(),
        );
    }
    if let Some(f) = &base.follow {
        if f.len() != axes {
            let which = if axes == 3 {
                "three (x, y, z)"
            } else {
                "two (x, y)"
            };
            return ck.err(
                k("follow"),
                format!("give {which} input channels, got {}", f.len()),
            );
        }
        for (i, c) in f.iter().enumerate() {
            ck.channel(&format!("{}[{i}]", k("follow")), c)?;
        }
    }
    Ok(())
}

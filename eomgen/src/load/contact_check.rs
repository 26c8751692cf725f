//! Checks of `[contact]` and `[[obstacle]]`: each law complete and in
//! range, each obstacle with exactly its shape's keys, names unique, and
//! every sampled segment of a method that can be sampled.

use crate::model::Model;
use crate::model::contact::{ContactLaw, ContactModel, ObstacleDecl};
use crate::model::{Check, ModelError};
use runtime::obstacle::Shape;

/// Largest `points_per_element`: past it contact costs more than the arm.
pub const MAX_POINTS_PER_ELEMENT: usize = 20;

pub(super) fn check_contact(ck: &Check) -> Result<(), ModelError> {
    let m = ck.m;
    if !m.has_contact() {
        return Ok(());
    }
    let decl = m.contact.clone().unwrap_or_default();
    if let Some(p) = decl.points_per_element
        && !(1..=MAX_POINTS_PER_ELEMENT).contains(&p)
    {
        return ck.err(
            "contact.points_per_element".into(),
            format!("must be 1 to {MAX_POINTS_PER_ELEMENT}, got {p}"),
        );
    }
    law_ranges(ck, "contact", &decl.law())?;
    sampled_methods(ck)?;
    let mut seen = std::collections::HashSet::new();
    for (i, o) in m.obstacles.iter().enumerate() {
        let key = format!("obstacle[{i}]");
        if o.name.is_empty() || !seen.insert(o.name.as_str()) {
            return ck.err(
                format!("{key}.name"),
                format!(
                    "obstacles need names of their own, got \"{}\" twice or empty",
                    o.name
                ),
            );
        }
        shape_keys(ck, &key, o)?;
        law_ranges(ck, &format!("{key}.contact"), &o.contact)?;
        law_complete(ck, &key, &o.contact, &decl.law())?;
        if let Some(channels) = &o.translation_inputs {
            let axes = m.dimensions as usize;
            if channels.len() != axes {
                return ck.err(
                    format!("{key}.translation_inputs"),
                    format!(
                        "give {axes} input channels (x, y{}), got {}",
                        if axes == 3 { ", z" } else { "" },
                        channels.len()
                    ),
                );
            }
            for (c, name) in channels.iter().enumerate() {
                ck.channel(&format!("{key}.translation_inputs[{c}]"), name)?;
            }
        }
    }
    Ok(())
}

/// Each given key in its range.
fn law_ranges(ck: &Check, key: &str, law: &ContactLaw) -> Result<(), ModelError> {
    let k = |s: &str| format!("{key}.{s}");
    if let Some(v) = law.stiffness {
        ck.positive(&k("stiffness"), v)?;
    }
    if let Some(v) = law.exponent {
        ck.positive(&k("exponent"), v)?;
    }
    for (name, v) in [("damping", law.damping), ("friction", law.friction)] {
        if let Some(v) = v {
            ck.non_negative(&k(name), v)?;
        }
    }
    if let Some(v) = law.slip_velocity {
        ck.positive(&k("slip_velocity"), v)?;
    }
    if let Some(e) = law.restitution
        && !(0.0..=1.0).contains(&e)
    {
        return ck.err(
            k("restitution"),
            format!("a coefficient of restitution is in [0, 1], got {e}"),
        );
    }
    Ok(())
}

/// The law an obstacle ends up with (its own keys over `[contact]`'s) has
/// what its model needs; an error names the key where the value came from.
fn law_complete(
    ck: &Check,
    key: &str,
    own: &ContactLaw,
    defaults: &ContactLaw,
) -> Result<(), ModelError> {
    let law = own.over(defaults);
    let model = law.model.unwrap_or(ContactModel::HuntCrossley);
    let at = |field: &str, mine: bool| {
        if mine {
            format!("{key}.contact.{field}")
        } else {
            format!("contact.{field}")
        }
    };
    if model != ContactModel::Impulse && law.stiffness.is_none() {
        return ck.err(
            format!("{key}.contact.stiffness"),
            "missing: a penalty contact law needs `stiffness` (in [contact] or the obstacle's own contact table)".into(),
        );
    }
    if model == ContactModel::HuntCrossley && law.restitution == Some(0.0) {
        return ck.err(
            at("restitution", own.restitution.is_some()),
            "hunt_crossley needs e > 0: no finite damping stops a penalty contact dead; for the chapter's no-rebound impact use model = \"impulse\"".into(),
        );
    }
    if model == ContactModel::HuntCrossley && law.damping.is_some() && law.restitution.is_some() {
        return ck.err(
            at("damping", own.damping.is_some()),
            "give hunt_crossley either `damping` or `restitution` (its damping then follows from e and the impact speed), not both".into(),
        );
    }
    if model == ContactModel::Hertz && law.damping.is_some() {
        return ck.err(
            at("damping", own.damping.is_some()),
            "hertz is undamped; use hunt_crossley for a damped Hertz contact".into(),
        );
    }
    Ok(())
}

/// Exactly the shape's keys, each in range (the shape's own checks), and
/// a planar model's plane upright.
fn shape_keys(ck: &Check, key: &str, o: &ObstacleDecl) -> Result<(), ModelError> {
    let k = |s: &str| format!("{key}.{s}");
    match o.geometry() {
        Err(e) => ck.err(k(&e.key), e.message),
        Ok(Shape::Plane { normal, .. }) if ck.m.dimensions == 2 && normal[2] != 0.0 => ck.err(
            k("normal"),
            "a planar model's plane has a normal in the x-y plane: the z component must be 0"
                .into(),
        ),
        Ok(_) => Ok(()),
    }
}

fn sampled_methods(ck: &Check) -> Result<(), ModelError> {
    for (prefix, arm) in ck.m.arm_models() {
        for (i, s) in arm.segments.iter().enumerate() {
            // The kinematics sample every method of the equations of
            // motion, none of statics alone.
            if s.method.statics_only() {
                let key = if prefix.is_empty() {
                    format!("segment[{i}].method")
                } else {
                    format!("arm.{prefix}.segment[{i}].method")
                };
                return ck.err(
                    key,
                    format!(
                        "contact samples {} segments; {} solves statics only",
                        crate::method::named(|m| !m.statics_only()),
                        s.method.name()
                    ),
                );
            }
        }
    }
    Ok(())
}

impl Model {
    /// The model has obstacles or self contact.
    pub fn has_contact(&self) -> bool {
        !self.obstacles.is_empty() || self.contact.as_ref().is_some_and(|c| c.self_contact)
    }

    /// Points sampled along each element (structural): 0 without contact.
    pub fn contact_points(&self) -> usize {
        if !self.has_contact() {
            return 0;
        }
        self.contact
            .as_ref()
            .and_then(|c| c.points_per_element)
            .unwrap_or(crate::model::contact::POINTS_PER_ELEMENT)
    }
}

//! `[[load]]`: on a segment that exists, a point on it, a force or a
//! moment (not both constant and driven), declared input channels, in the
//! plane only what stays in it; the Cosserat statics take a constant
//! distributed force alone.

use crate::model::{Check, Load, ModelError};

/// Every `[[load]]` of a single-arm model, and its `[fluid]`.
pub(crate) fn check_loads(ck: &Check) -> Result<(), ModelError> {
    let m = ck.m;
    check_fluid(ck)?;
    if m.is_assembly() && !m.loads.is_empty() {
        return ck.err(
            "load".into(),
            "loads on an assembly's arms are not supported yet: give them as tip loads or body loads".into(),
        );
    }
    for (i, l) in m.loads.iter().enumerate() {
        check_load(ck, i, l)?;
    }
    Ok(())
}

fn check_load(ck: &Check, i: usize, l: &Load) -> Result<(), ModelError> {
    let m = ck.m;
    let p = |k: &str| format!("load[{i}].{k}");
    let Some(seg) = m.segments.get(l.segment) else {
        return ck.err(
            p("segment"),
            format!(
                "no segment {}: the arm has {} (0 to {})",
                l.segment,
                m.segments.len(),
                m.segments.len().saturating_sub(1)
            ),
        );
    };
    if let Some(s) = l.s {
        ck.finite(&p("s"), s)?;
        if !(0.0..=seg.length).contains(&s) {
            return ck.err(
                p("s"),
                format!(
                    "must lie on segment {}: an arc length between 0 and its length {} m, got {s}",
                    l.segment, seg.length
                ),
            );
        }
    }
    for (key, value, inputs) in [
        ("force", &l.force, &l.force_inputs),
        ("moment", &l.moment, &l.moment_inputs),
    ] {
        if let Some(v) = value {
            ck.vec3(&p(key), v)?;
            if inputs.is_some() {
                return ck.err(
                    p(key),
                    format!("give either `{key}` or `{key}_inputs`, not both"),
                );
            }
        }
        for (k, name) in inputs.iter().flatten().enumerate() {
            ck.channel(&format!("{}[{k}]", p(&format!("{key}_inputs"))), name)?;
        }
    }
    if !l.has_force() && !l.has_moment() {
        return ck.err(
            p("force"),
            "missing: give a `force` or a `moment` (or their `_inputs`)".into(),
        );
    }
    if l.s.is_none() && l.has_moment() {
        return ck.err(
            p("moment"),
            "a distributed load (no `s`) is a force per unit length: give the moment at a point, with `s`".into(),
        );
    }
    if m.dimensions == 2 {
        let off_plane = l.force.is_some_and(|f| f[2] != 0.0)
            || l.moment.is_some_and(|v| v[0] != 0.0 || v[1] != 0.0);
        if off_plane {
            return ck.err(
                p(if l.force.is_some_and(|f| f[2] != 0.0) {
                    "force"
                } else {
                    "moment"
                }),
                "a planar arm stays in its plane: a force has no z, a moment only z".into(),
            );
        }
    }
    let method = crate::method::of(seg.method);
    let constant_world = l.s.is_none() && l.force_inputs.is_none() && !l.local();
    if method.statics_only() && !constant_world {
        return ck.err(
            p("s"),
            "the Cosserat statics take a constant distributed force in the world frame (no `s`, no inputs, no local frame)".into(),
        );
    }
    Ok(())
}

/// `[fluid]`: finite values, drag coefficients and density not negative;
/// every segment a chain method's with an outer radius (its displaced
/// volume and width); not on an assembly.
fn check_fluid(ck: &Check) -> Result<(), ModelError> {
    let m = ck.m;
    let Some(f) = &m.fluid else {
        return Ok(());
    };
    ck.non_negative("fluid.density", f.density)?;
    ck.non_negative("fluid.drag_normal", f.drag_normal)?;
    ck.non_negative("fluid.drag_tangential", f.drag_tangential)?;
    ck.vec3("fluid.current", &f.current)?;
    if m.is_assembly() && !m.arms.is_empty() {
        return ck.err(
            "fluid".into(),
            "an immersed assembly of several arms is not supported yet: immerse a single arm (on a compliant base or not)".into(),
        );
    }
    for (i, s) in m.segments.iter().enumerate() {
        let method = crate::method::of(s.method);
        if method.statics_only() {
            return ck.err(
                format!("segment[{i}].method"),
                format!(
                    "an immersed arm's segments are lumped (pcc, vc, pcs, ebr, eba, rom, rigid), got {}",
                    s.method.name()
                ),
            );
        }
        if s.outer_radius.is_none() {
            return ck.err(
                format!("segment[{i}].outer_radius"),
                "missing: an immersed segment displaces and meets the fluid by its `outer_radius` (m)".into(),
            );
        }
    }
    Ok(())
}

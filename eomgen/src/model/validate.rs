//! Checks that the types alone cannot express. Every message names the key
//! path and says what is allowed.

use super::error::ModelError;
use super::schema::{Method, Model};

/// Largest element count per segment: beyond it derivation and simulation
/// times are impractical for a planar chain.
pub const MAX_ELEMENTS: usize = 500;

pub fn validate(m: &Model, file: &str) -> Result<(), ModelError> {
    let err = |path: String, msg: String| Err(ModelError::new(file, path, msg));
    let finite = |path: &str, v: f64| -> Result<(), ModelError> {
        if v.is_finite() {
            Ok(())
        } else {
            Err(ModelError::new(
                file,
                path,
                format!("must be a finite number, got {v}"),
            ))
        }
    };
    let vec3 = |path: &str, v: &[f64; 3]| -> Result<(), ModelError> {
        for (i, x) in v.iter().enumerate() {
            finite(&format!("{path}[{i}]"), *x)?;
        }
        Ok(())
    };
    let positive = |path: &str, v: f64| -> Result<(), ModelError> {
        finite(path, v)?;
        if v > 0.0 {
            Ok(())
        } else {
            Err(ModelError::new(
                file,
                path,
                format!("must be positive, got {v}"),
            ))
        }
    };
    let non_negative = |path: &str, v: f64| -> Result<(), ModelError> {
        finite(path, v)?;
        if v >= 0.0 {
            Ok(())
        } else {
            Err(ModelError::new(
                file,
                path,
                format!("must be zero or positive, got {v}"),
            ))
        }
    };

    if m.name.trim().is_empty() {
        return err("name".into(), "must not be empty".into());
    }
    vec3("gravity", &m.gravity)?;
    vec3("base.position", &m.base.position)?;
    vec3("base.direction", &m.base.direction)?;
    let d = m.base.direction;
    let norm = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    if norm == 0.0 {
        return err(
            "base.direction".into(),
            "must be a non-zero vector (the undeformed arm axis)".into(),
        );
    }
    let planar = m.segments.iter().all(|s| matches!(s.method, Method::Rigid));
    if planar {
        if d[2].abs() > 1e-12 * norm {
            return err(
                "base.direction".into(),
                format!(
                    "planar arms move in the x-y plane: the z component must be 0, got {}",
                    d[2]
                ),
            );
        }
        if m.base.position[2] != 0.0 {
            return err(
                "base.position".into(),
                "planar arms move in the x-y plane: the z component must be 0".into(),
            );
        }
    }
    if m.segments.is_empty() {
        return err(
            "segment".into(),
            "at least one [[segment]] is needed".into(),
        );
    }
    for (i, s) in m.segments.iter().enumerate() {
        let p = |k: &str| format!("segment[{i}].{k}");
        positive(&p("length"), s.length)?;
        if s.elements == 0 || s.elements > MAX_ELEMENTS {
            return err(
                p("elements"),
                format!("must be between 1 and {MAX_ELEMENTS}, got {}", s.elements),
            );
        }
        match (s.mass, s.density) {
            (Some(_), Some(_)) => {
                return err(
                    p("mass"),
                    "give either `mass` or `density` (with `outer_radius`), not both".into(),
                );
            }
            (None, None) => {
                return err(
                    p("mass"),
                    "missing: give `mass` (kg) or `density` (kg/m^3) with `outer_radius` (m)"
                        .into(),
                );
            }
            (Some(mass), None) => positive(&p("mass"), mass)?,
            (None, Some(rho)) => {
                positive(&p("density"), rho)?;
                if s.outer_radius.is_none() {
                    return err(
                        p("outer_radius"),
                        "missing: `density` needs `outer_radius` (m)".into(),
                    );
                }
            }
        }
        if let Some(ro) = s.outer_radius {
            positive(&p("outer_radius"), ro)?;
            if let Some(ri) = s.inner_radius {
                non_negative(&p("inner_radius"), ri)?;
                if ri >= ro {
                    return err(
                        p("inner_radius"),
                        format!("must be smaller than outer_radius ({ro}), got {ri}"),
                    );
                }
            }
        } else if s.inner_radius.is_some() {
            return err(p("inner_radius"), "needs `outer_radius`".into());
        }
        non_negative(&p("joint_stiffness"), s.joint_stiffness)?;
        non_negative(&p("joint_damping"), s.joint_damping)?;
    }
    if let Some(mass) = m.tip.mass {
        non_negative("tip.mass", mass)?;
    }
    if let Some(force) = &m.tip.force {
        vec3("tip.force", force)?;
    }
    Ok(())
}

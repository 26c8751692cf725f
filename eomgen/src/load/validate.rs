//! Checks that the types alone cannot express. Every message names the key
//! path and says what is allowed.

use crate::method::Carried;
use crate::model::{Check, ModelError};
use crate::model::{Model, Segment};

/// Largest element count per segment: beyond it derivation and simulation
/// times are impractical for a planar chain.
pub const MAX_ELEMENTS: usize = 500;

/// Check what the types alone cannot express, concern by concern; the
/// first problem found is the error.
pub fn validate(m: &Model, file: &str) -> Result<(), ModelError> {
    let ck = Check { m, file };
    ck.file_name("name", "a model", &m.name)?;
    super::assembly_check::mounts(&ck)?;
    if m.is_assembly() {
        super::assembly_check::check_assembly(&ck, |arm| validate_arm(arm, file))?;
        relaxing_assembly(&ck)?;
        simulate_defaults(&ck)?;
        signals(&ck)?;
    } else {
        validate_arm(m, file)?;
    }
    super::load_check::check_loads(&ck)?;
    super::contact_check::check_contact(&ck)
}

/// A segment's relaxation: each ratio in (0, 1), their sum below 1 (a
/// positive long-term modulus), each time positive; no contact around
/// them yet (its runs switch, which carries the coordinates only).
fn relaxation(ck: &Check, i: usize, s: &Segment) -> Result<(), ModelError> {
    let p = |k: usize, key: &str| format!("segment[{i}].relaxation[{k}].{key}");
    for (k, r) in s.relaxation.iter().enumerate() {
        ck.finite(&p(k, "ratio"), r.ratio)?;
        if !(r.ratio > 0.0 && r.ratio < 1.0) {
            return ck.err(
                p(k, "ratio"),
                format!(
                    "the share of the modulus that relaxes lies between 0 and 1, got {}",
                    r.ratio
                ),
            );
        }
        ck.positive(&p(k, "time"), r.time)?;
    }
    let sum: f64 = s.relaxation.iter().map(|r| r.ratio).sum();
    if sum >= 1.0 {
        return ck.err(
            format!("segment[{i}].relaxation"),
            format!(
                "the ratios sum to {sum}: they must sum below 1, so that a long-term modulus remains"
            ),
        );
    }
    if !s.relaxation.is_empty() && ck.m.has_contact() {
        return ck.err(
            format!("segment[{i}].relaxation"),
            "a relaxing arm with contact is not supported yet: the contact's runs carry the \
             coordinates alone"
                .into(),
        );
    }
    Ok(())
}

/// An assembly's arms are elastic: its runs hold joints by projection,
/// which carries the coordinates alone.
fn relaxing_assembly(ck: &Check) -> Result<(), ModelError> {
    for (name, arm) in ck.m.arm_models() {
        if let Some(i) = arm.segments.iter().position(|s| !s.relaxation.is_empty()) {
            return ck.err(
                format!("arm.{name}.segment[{i}].relaxation"),
                "viscoelastic arms in an assembly are not supported yet: declare the arm alone"
                    .into(),
            );
        }
    }
    Ok(())
}

/// The checks of one arm (a single-arm file, or an assembly's arm).
fn validate_arm(m: &Model, file: &str) -> Result<(), ModelError> {
    let ck = Check { m, file };
    simulate_defaults(&ck)?;
    frame(&ck)?;
    for (i, s) in m.segments.iter().enumerate() {
        segment_section(&ck, i, s)?;
        segment_dimension_keys(&ck, i, s)?;
        crate::method::check_segment(&ck, i, s)?;
        relaxation(&ck, i, s)?;
    }
    tip(&ck)?;
    driven_loads_and_chambers(&ck)?;
    tendons(&ck)?;
    base_motion(&ck)?;
    torques(&ck)?;
    signals(&ck)
}

/// `[simulate]`: a known solver, positive times and tolerances.
fn simulate_defaults(ck: &Check) -> Result<(), ModelError> {
    let m = ck.m;
    let sim = &m.simulate;
    if let Some(solver) = &sim.solver
        && !runtime::Solver::NAMES.contains(&solver.as_str())
    {
        return ck.err(
            "simulate.solver".into(),
            format!(
                "unknown solver \"{solver}\"; allowed: {}",
                runtime::Solver::NAMES.join(", ")
            ),
        );
    }
    for (key, v) in [
        ("simulate.t_end", sim.t_end),
        ("simulate.rtol", sim.rtol),
        ("simulate.atol", sim.atol),
        ("simulate.dt", sim.dt),
        ("simulate.output_dt", sim.output_dt),
    ] {
        if let Some(v) = v {
            ck.positive(key, v)?;
        }
    }
    if let Some(rho) = sim.rho_inf
        && !(0.0..=1.0).contains(&rho)
    {
        return ck.err(
            "simulate.rho_inf".into(),
            format!("must lie in [0, 1] (1: no numerical damping), got {rho}"),
        );
    }
    Ok(())
}

/// Name, gravity, the base frame and the plane.
fn frame(ck: &Check) -> Result<(), ModelError> {
    let m = ck.m;
    ck.file_name("name", "a model", &m.name)?;
    ck.vec3("gravity", &m.gravity)?;
    ck.vec3("base.position", &m.base.position)?;
    ck.vec3("base.direction", &m.base.direction)?;
    let d = m.base.direction;
    let norm = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    if norm == 0.0 {
        return ck.err(
            "base.direction".into(),
            "must be a non-zero vector (the undeformed arm axis); give it in [base], \
             e.g. direction = [1.0, 0.0, 0.0] (a missing [base] leaves it zero)"
                .into(),
        );
    }
    if !matches!(m.dimensions, 2 | 3) {
        return ck.err(
            "dimensions".into(),
            format!("must be 2 (planar) or 3 (spatial), got {}", m.dimensions),
        );
    }
    let planar = m.dimensions == 2;
    if planar {
        if d[2].abs() > 1e-12 * norm {
            return ck.err(
                "base.direction".into(),
                format!(
                    "planar arms move in the x-y plane: the z component must be 0, got {}",
                    d[2]
                ),
            );
        }
        if m.base.position[2] != 0.0 {
            return ck.err(
                "base.position".into(),
                "planar arms move in the x-y plane: the z component must be 0".into(),
            );
        }
    }
    if m.segments.is_empty() {
        return ck.err(
            "segment".into(),
            "at least one [[segment]] is needed".into(),
        );
    }
    Ok(())
}

/// The tip body and its constant loads.
fn tip(ck: &Check) -> Result<(), ModelError> {
    let m = ck.m;
    crate::model::sensor::check(m, ck.file)?;
    if let Some(mass) = m.tip.mass {
        ck.non_negative("tip.mass", mass)?;
    }
    if let Some(force) = &m.tip.force {
        ck.vec3("tip.force", force)?;
    }
    if let Some(moment) = &m.tip.moment {
        ck.vec3("tip.moment", moment)?;
    }
    if let Some(l) = m.tip.length {
        ck.non_negative("tip.length", l)?;
        if m.tip.mass.is_none() {
            return ck.err(
                "tip.length".into(),
                "a tip body needs its `mass` (kg) too".into(),
            );
        }
    }
    if let Some(r) = m.tip.radius {
        ck.non_negative("tip.radius", r)?;
        if m.tip.length.is_none() {
            return ck.err(
                "tip.radius".into(),
                "needs `tip.length` (the tip body is a cylinder of that length)".into(),
            );
        }
    }
    Ok(())
}

/// Input channels of the tip loads and the chambers exist.
fn driven_loads_and_chambers(ck: &Check) -> Result<(), ModelError> {
    let m = ck.m;
    for (key, names) in [
        ("tip.force_inputs", &m.tip.force_inputs),
        ("tip.moment_inputs", &m.tip.moment_inputs),
    ] {
        if let Some(names) = names {
            for (i, n) in names.iter().enumerate() {
                ck.channel(&format!("{key}[{i}]"), n)?;
            }
        }
    }
    for (i, s) in m.segments.iter().enumerate() {
        if let Some(inputs) = s.chambers.as_ref().and_then(|c| c.inputs.as_ref()) {
            for (j, n) in inputs.iter().enumerate() {
                ck.channel(&format!("segment[{i}].chambers.inputs[{j}]"), n)?;
            }
        }
    }
    Ok(())
}

/// Tendons: a declared channel, the segments they span, inside the section.
fn tendons(ck: &Check) -> Result<(), ModelError> {
    let m = ck.m;
    for (i, t) in m.tendons.iter().enumerate() {
        let p = |k: &str| format!("tendon[{i}].{k}");
        ck.channel(&p("input"), &t.input)?;
        let end = t.end.unwrap_or(m.segments.len() - 1);
        if end >= m.segments.len() {
            return ck.err(
                p("end"),
                format!(
                    "must be a segment index, 0 to {}, got {end}",
                    m.segments.len() - 1
                ),
            );
        }
        for (key, v) in [("distance", Some(&t.distance)), ("angle", t.angle.as_ref())] {
            let Some(v) = v else { continue };
            if let crate::model::OneOrMany::Many(list) = v
                && list.len() != end + 1
            {
                return ck.err(
                    p(key),
                    format!(
                        "give one value, or one per segment the tendon spans ({}), got {}",
                        end + 1,
                        list.len()
                    ),
                );
            }
            for s in 0..=end {
                ck.finite(&p(key), v.at(s))?;
            }
        }
        for s in 0..=end {
            let d = t.distance.at(s);
            ck.non_negative(&p("distance"), d)?;
            let seg = &m.segments[s];
            if let Some(ro) = seg.outer_radius.as_ref().map(|r| r.min())
                && d > ro
            {
                let least = if seg.tapered() {
                    " at its thinnest"
                } else {
                    ""
                };
                return ck.err(
                    p("distance"),
                    format!(
                        "{d} m lies outside segment {s}'s section (outer radius {ro} m{least})"
                    ),
                );
            }
        }
    }
    Ok(())
}

/// A prescribed base motion: one channel per axis or turn, non-zero axes.
fn base_motion(ck: &Check) -> Result<(), ModelError> {
    let m = ck.m;
    if let Some(names) = &m.base.translation_inputs {
        let want = if m.dimensions == 3 { 3 } else { 2 };
        if names.len() != want {
            return ck.err(
                "base.translation_inputs".into(),
                format!(
                    "give one input channel per axis ({}), got {}",
                    if want == 3 {
                        "x, y, z"
                    } else {
                        "x, y: a planar base"
                    },
                    names.len()
                ),
            );
        }
        for (i, n) in names.iter().enumerate() {
            ck.channel(&format!("base.translation_inputs[{i}]"), n)?;
        }
    }
    let turns = m.base.rotation_inputs.as_deref().unwrap_or_default();
    if m.dimensions != 3 && turns.len() > 1 {
        return ck.err(
            "base.rotation_inputs".into(),
            format!(
                "a planar base turns about z only: give one input channel, got {}",
                turns.len()
            ),
        );
    }
    for (i, n) in turns.iter().enumerate() {
        ck.channel(&format!("base.rotation_inputs[{i}]"), n)?;
    }
    if let Some(axes) = &m.base.rotation_axes {
        if m.dimensions != 3 {
            return ck.err(
                "base.rotation_axes".into(),
                "a planar base turns about z: leave rotation_axes out".into(),
            );
        }
        if axes.len() != turns.len() {
            return ck.err(
                "base.rotation_axes".into(),
                format!(
                    "give one axis per rotation input ({}), got {}",
                    turns.len(),
                    axes.len()
                ),
            );
        }
        for (i, a) in axes.iter().enumerate() {
            let key = format!("base.rotation_axes[{i}]");
            ck.vec3(&key, a)?;
            if a.iter().all(|&c| c == 0.0) {
                return ck.err(key, "must be a non-zero vector".into());
            }
        }
    }
    Ok(())
}

/// Joint torques: a declared channel and a coordinate the structure has.
fn torques(ck: &Check) -> Result<(), ModelError> {
    let m = ck.m;
    if !m.torques.is_empty() {
        let names = crate::method::coordinate_names(&crate::model::Structure::of(m));
        for (i, t) in m.torques.iter().enumerate() {
            ck.channel(&format!("torque[{i}].input"), &t.input)?;
            if !names.contains(&t.coordinate) {
                return ck.err(
                    format!("torque[{i}].coordinate"),
                    format!(
                        "no coordinate \"{}\"; this model's are {}",
                        t.coordinate,
                        names.join(", ")
                    ),
                );
            }
        }
    }
    Ok(())
}

/// Input channels and `[compare]`, by `signals`.
fn signals(ck: &Check) -> Result<(), ModelError> {
    let m = ck.m;
    for (name, input) in &m.inputs {
        crate::model::check_input(name, input, ck.file)?;
    }
    if let Some(c) = &m.compare {
        crate::model::check_compare(c, ck.file)?;
    }
    Ok(())
}

/// A segment's size, mass, section and material values.
fn segment_section(ck: &Check, i: usize, s: &Segment) -> Result<(), ModelError> {
    let p = |k: &str| format!("segment[{i}].{k}");
    ck.positive(&p("length"), s.length)?;
    if s.elements == 0 || s.elements > MAX_ELEMENTS {
        return ck.err(
            p("elements"),
            format!("must be between 1 and {MAX_ELEMENTS}, got {}", s.elements),
        );
    }
    match (s.mass, &s.density) {
        // Its mass per length given.
        _ if s.given().is_some() => {}
        (Some(_), Some(_)) => {
            return ck.err(
                p("mass"),
                "give either `mass` or `density` (with `outer_radius`), not both".into(),
            );
        }
        (None, None) => {
            return ck.err(
                p("mass"),
                "missing: give `mass` (kg) or `density` (kg/m^3) with `outer_radius` (m)".into(),
            );
        }
        (Some(mass), None) => ck.positive(&p("mass"), mass)?,
        (None, Some(rho)) => {
            ck.positive_along(&p("density"), rho)?;
            if !s.has_section() {
                return ck.err(
                    p("outer_radius"),
                    "missing: `density` needs `outer_radius` (m) or a `section`".into(),
                );
            }
        }
    }
    section_shape(ck, i, s)?;
    // Every value positive, the inner radius only not negative (below).
    for (key, v) in s.profiles() {
        if let Some(v) = v.filter(|_| key != "inner_radius") {
            ck.positive_along(&p(key), v)?;
        }
    }
    if let Some(ri) = &s.inner_radius {
        ck.non_negative_along(&p("inner_radius"), ri)?;
        if s.outer_radius.is_none() {
            return ck.err(p("inner_radius"), "needs `outer_radius`".into());
        }
    }
    // Every value is linear between the profiles' points: the section is
    // checked where it is thinnest, at one of them.
    for x in s.breaks() {
        let here = s.at(x);
        let (ro, ri) = (here.outer(), here.inner());
        let at = match s.tapered() {
            true => format!(" at s/L = {x}"),
            false => String::new(),
        };
        if let (Some(ro), Some(ri)) = (ro, ri)
            && ri >= ro
        {
            return ck.err(
                p("inner_radius"),
                format!("must be smaller than outer_radius ({ro}), got {ri}{at}"),
            );
        }
        if let Some(c) = &here.chambers {
            let planar = ck.m.dimensions == 2;
            check_chambers(&here, c, &p("chambers"), planar, ck.file)
                .map_err(|e| e.with_suffix(&at))?;
        }
    }
    if let (Some(_), Some(_)) = (&s.youngs_modulus, &s.bending_stiffness) {
        return ck.err(
            p("bending_stiffness"),
            "give either `youngs_modulus` or `bending_stiffness`, not both".into(),
        );
    }
    if s.youngs_modulus.is_some() && !s.has_section() {
        return ck.err(
            p("outer_radius"),
            "missing: `youngs_modulus` needs the section's `outer_radius` (m) or a `section`"
                .into(),
        );
    }
    if let Some(c) = s.bending_damping {
        ck.non_negative(&p("bending_damping"), c)?;
    }
    rest_shape(ck, i, s)?;
    kink(ck, i, s)?;
    if let Some(c) = s.axial_damping {
        ck.non_negative(&p("axial_damping"), c)?;
    }
    Ok(())
}

/// `[segment.section]`: positive sides; instead of a radius, without
/// chamber holes. In 3D a section that bends more stiffly about one axis
/// carries both stiffnesses (`Segment::anisotropic`).
fn section_shape(ck: &Check, i: usize, s: &Segment) -> Result<(), ModelError> {
    let p = |k: &str| format!("segment[{i}].section.{k}");
    let Some(sec) = &s.section else {
        return Ok(());
    };
    let Some((w, h)) = sec.sides() else {
        return section_properties(ck, i, s);
    };
    ck.positive(&p("width"), w)?;
    ck.positive(&p("height"), h)?;
    for (key, given) in [
        ("outer_radius", s.outer_radius.is_some()),
        ("inner_radius", s.inner_radius.is_some()),
        ("chambers", s.chambers.is_some()),
    ] {
        if given {
            return ck.err(
                format!("segment[{i}].{key}"),
                format!(
                    "a segment with a `section` takes no `{key}` (holes and radii are a circle's)"
                ),
            );
        }
    }
    Ok(())
}

/// A section given by its properties: each value positive, and none of
/// what it replaces (the mass, the material, the shape's sizes) given too.
fn section_properties(ck: &Check, i: usize, s: &Segment) -> Result<(), ModelError> {
    let p = |k: &str| format!("segment[{i}].section.{k}");
    let g = s
        .given()
        .expect("a section without sides is given by its properties");
    for (key, v) in [
        ("axial_stiffness", g.ea),
        ("bending_stiffness[0]", g.ei[0]),
        ("bending_stiffness[1]", g.ei[1]),
        ("torsional_stiffness", g.gj),
        ("mass_per_length", g.rho_a),
        ("rotary_inertia[0]", g.rho_i[0]),
        ("rotary_inertia[1]", g.rho_i[1]),
        ("polar_inertia", g.rho_j),
    ] {
        ck.positive(&p(key), v)?;
    }
    for ga in g.ga.iter().flatten() {
        ck.positive(&p("shear_stiffness"), *ga)?;
    }
    let replaced = [
        ("mass", s.mass.is_some()),
        ("density", s.density.is_some()),
        ("outer_radius", s.outer_radius.is_some()),
        ("inner_radius", s.inner_radius.is_some()),
        ("chambers", s.chambers.is_some()),
        ("youngs_modulus", s.youngs_modulus.is_some()),
        ("bending_stiffness", s.bending_stiffness.is_some()),
        ("torsional_stiffness", s.torsional_stiffness.is_some()),
        ("axial_stiffness", s.axial_stiffness.is_some()),
        ("shear_modulus", s.shear_modulus.is_some()),
        ("shear_factor", s.shear_factor.is_some()),
    ];
    if let Some((key, _)) = replaced.iter().find(|(_, given)| *given) {
        return ck.err(
            format!("segment[{i}].{key}"),
            format!(
                "a segment whose section is given by its `properties` takes no `{key}`: the section's keys give its mass, stiffnesses and inertias"
            ),
        );
    }
    if s.shears() && g.ga.is_none() {
        return ck.err(
            p("shear_stiffness"),
            "missing: a shearing segment needs the section's `shear_stiffness` (k G A, N)".into(),
        );
    }
    Ok(())
}

/// A kink: one turn in the plane (about z), two in 3D (about y and z),
/// finite; an offset in the plane stays in it; no contact yet.
fn kink(ck: &Check, i: usize, s: &Segment) -> Result<(), ModelError> {
    let p = |k: &str| format!("segment[{i}].{k}");
    let planar = ck.m.dimensions == 2;
    if let Some(turn) = &s.turn {
        let want = if planar { 1 } else { 2 };
        if turn.len() != want {
            let form = if planar {
                "[angle about z] in the plane"
            } else {
                "[angle about y, angle about z] in 3D"
            };
            return ck.err(
                p("turn"),
                format!("give {form}, in degrees (got {} values)", turn.len()),
            );
        }
        for (k, &a) in turn.iter().enumerate() {
            ck.finite(&format!("{}[{k}]", p("turn")), a)?;
        }
    }
    if let Some(offset) = &s.offset {
        ck.vec3(&p("offset"), offset)?;
        if planar && offset[2] != 0.0 {
            return ck.err(
                p("offset"),
                "a planar arm stays in its plane: the offset's z must be 0".into(),
            );
        }
    }
    if s.kinked() && ck.m.has_contact() {
        return ck.err(
            p(if s.turn.is_some() { "turn" } else { "offset" }),
            "contact along an arm with kinks is not supported yet: use two arms joined by a weld"
                .into(),
        );
    }
    Ok(())
}

/// The rest curvature, twist and stretch: finite, in the plane one
/// curvature, a stretch only where the elements stretch.
fn rest_shape(ck: &Check, i: usize, s: &Segment) -> Result<(), ModelError> {
    let p = |k: &str| format!("segment[{i}].{k}");
    let planar = ck.m.dimensions == 2;
    if planar && let Some(e) = s.rest_curvature.planar_error() {
        return ck.err(p("rest_curvature"), e.into());
    }
    let ([y, z], _) = s.rest_curvature.axes(!planar);
    for (key, v) in [
        ("rest_curvature", Some(&y)),
        ("rest_curvature", Some(&z)),
        ("rest_twist", s.rest_twist.as_ref()),
        ("rest_stretch", s.rest_stretch.as_ref()),
    ] {
        for x in v.map(|v| v.knots()).unwrap_or_default() {
            ck.finite(&p(key), x)?;
        }
    }
    if let Some(e) = &s.rest_stretch
        && e.min() <= -1.0
    {
        return ck.err(
            p("rest_stretch"),
            format!(
                "a strain above -1 (a positive rest length), got {}",
                e.min()
            ),
        );
    }
    Ok(())
}

/// Keys of the other dimension: 3D keys in a planar arm, and in 3D what
/// twist and stretch need.
fn segment_dimension_keys(ck: &Check, i: usize, s: &Segment) -> Result<(), ModelError> {
    let p = |k: &str| format!("segment[{i}].{k}");
    let planar = ck.m.dimensions == 2;
    if planar {
        for (key, given) in [
            ("twist", s.twist.is_some()),
            ("extension", s.extension.is_some()),
            ("joint_axes", s.joint_axes.is_some()),
            ("shear_modulus", s.shear_modulus.is_some()),
            ("torsional_stiffness", s.torsional_stiffness.is_some()),
            ("axial_stiffness", s.axial_stiffness.is_some()),
            ("axial_damping", s.axial_damping.is_some()),
            ("incompressible", s.incompressible.is_some()),
            ("shear", s.shear.is_some()),
            ("shear_factor", s.shear_factor.is_some()),
            ("rest_twist", s.rest_twist.is_some()),
            ("rest_stretch", s.rest_stretch.is_some()),
        ] {
            if given {
                return ck.err(
                    p(key),
                    "a 3D key: set `dimensions = 3` at the top of the file to use it".into(),
                );
            }
        }
    } else {
        if let Some(axes) = &s.joint_axes
            && (axes.is_empty() || axes.len() > 3)
        {
            return ck.err(
                p("joint_axes"),
                format!("give 1 to 3 axes (\"x\", \"y\", \"z\"), got {}", axes.len()),
            );
        }
        // A second turn about an axis would name a second coordinate
        // alike and, about the same axis twice in a row, leave the mass
        // matrix singular.
        if let Some(axes) = &s.joint_axes
            && let Some(a) =
                (axes.iter().enumerate()).find_map(|(i, a)| axes[..i].contains(a).then_some(a))
        {
            return ck.err(
                p("joint_axes"),
                format!("give each axis once (\"x\", \"y\", \"z\"), got {a:?} twice")
                    .to_lowercase(),
            );
        }
        let method = crate::method::of(s.method);
        // Joints of the method's own with their stiffness hold the twist.
        let joints_hold =
            method.own_keys().contains(&"joint_stiffness") && s.joint_stiffness.is_some();
        if method.twisting(s) && !joints_hold && s.ei().is_some() && s.gj().is_none() {
            return ck.err(
                p("torsional_stiffness"),
                "missing: twisting elements need `torsional_stiffness` (G J), or `youngs_modulus` with the section (G = E/3 unless `shear_modulus` is given)".into(),
            );
        }
        // Where stretch is a choice and the section lumped, it needs the
        // stretch to act on.
        if s.incompressible == Some(true)
            && method.stretch() == Carried::Optional
            && method.lumps_section()
            && !s.stretches()
        {
            return ck.err(
                p("incompressible"),
                "acts on stretching elements: set `extension = true` too".into(),
            );
        }
        if method.stretch() != Carried::Never && s.stretches() && s.ea().is_none() {
            return ck.err(
                p("axial_stiffness"),
                "missing: `extension = true` needs `axial_stiffness` (E A), or `youngs_modulus` with the section".into(),
            );
        }
        let stretches = method.stretch() != Carried::Never && s.stretches();
        if s.rest_stretch.is_some() && !stretches {
            return ck.err(
                p("rest_stretch"),
                "acts on stretching elements: set `extension = true` too".into(),
            );
        }
        shear_keys(ck, i, s)?;
    }
    Ok(())
}

/// 3D: `shear` on a method that carries shear strains, with what its
/// stiffness k G A needs; `shear_factor` positive, on shearing elements.
fn shear_keys(ck: &Check, i: usize, s: &Segment) -> Result<(), ModelError> {
    let p = |k: &str| format!("segment[{i}].{k}");
    let shear = crate::method::of(s.method).shear();
    let carries = shear == Carried::Optional;
    let named = |c: Carried| crate::method::named(|m| m.shear() == c);
    match (s.shear, shear) {
        (Some(false), Carried::Always) => {
            return ck.err(
                p("shear"),
                format!(
                    "{} elements always shear (their absolute poses are held by shear springs): remove the key, or use {} to choose",
                    s.method.name(),
                    named(Carried::Optional)
                ),
            );
        }
        (Some(true), Carried::Never) => {
            return ck.err(
                p("shear"),
                format!(
                    "{} segments carry no shear strain: shear is for {} segments ({} always shears)",
                    s.method.name(),
                    named(Carried::Optional),
                    named(Carried::Always)
                ),
            );
        }
        _ => {}
    }
    let shears = match shear {
        Carried::Never => false,
        Carried::Optional => s.shears(),
        Carried::Always => true,
    };
    if let Some(k) = s.shear_factor {
        ck.positive(&p("shear_factor"), k)?;
        if !shears {
            return ck.err(
                p("shear_factor"),
                "acts on shearing elements: set `shear = true` too (or use pcs or eba)".into(),
            );
        }
    }
    if carries && s.shears() && s.ga().is_none() {
        return ck.err(
            p("shear_modulus"),
            "missing: shearing elements need `shear_modulus`, or `youngs_modulus` with the section (G = E/3)".into(),
        );
    }
    Ok(())
}

/// Chamber holes of segment `s` (its section where they are checked): one
/// way to place them, inside the wall, not overlapping, with declared
/// input channels; in 3D with the principal axes y and z.
fn check_chambers(
    s: &Segment,
    c: &crate::model::Chambers,
    path: &str,
    planar: bool,
    file: &str,
) -> Result<(), ModelError> {
    let err = |key: &str, msg: String| {
        let at = if key.is_empty() {
            path.to_string()
        } else {
            format!("{path}.{key}")
        };
        Err(ModelError::new(file, at, msg))
    };
    let (outer, inner) = (s.outer(), s.inner());
    let Some(ro) = outer else {
        return err("", "needs the section's `outer_radius`".into());
    };
    match (c.count, &c.angles) {
        (Some(_), Some(_)) => {
            return err(
                "angles",
                "give either `count` (equally spaced) or `angles`, not both".into(),
            );
        }
        (None, None) => {
            return err(
                "count",
                "missing: give `count` (equally spaced positions) or `angles` (degrees)".into(),
            );
        }
        (Some(0), None) => return err("count", "must be at least 1".into()),
        (None, Some(a)) => {
            if a.is_empty() {
                return err("angles", "give at least one angle (degrees)".into());
            }
            if let Some(v) = a.iter().find(|v| !v.is_finite()) {
                return err("angles", format!("must be finite numbers, got {v}"));
            }
        }
        _ => {}
    }
    if let Some(h) = c.pair_spacing
        && !(h.is_finite() && h > 0.0 && h < 90.0)
    {
        return err(
            "pair_spacing",
            format!("must be an angle between 0 and 90 degrees, got {h}"),
        );
    }
    let positions = c.positions().len();
    let per_position = [("radius", Some(&c.radius)), ("area", c.area.as_ref())];
    for (key, v) in per_position {
        let Some(v) = v else { continue };
        let given = v.given();
        if let crate::model::OneOrMany::Many(list) = v
            && list.len() != positions
        {
            return err(
                key,
                format!(
                    "give one value or one per position ({positions}), got {}",
                    list.len()
                ),
            );
        }
        if let Some(x) = given.iter().find(|x| !(x.is_finite() && **x > 0.0)) {
            return err(key, format!("must be positive, got {x}"));
        }
    }
    let d = c.offset();
    if !(d.is_finite() && d > 0.0) {
        return err("distance", format!("must be positive, got {d}"));
    }
    let ri = inner.unwrap_or(0.0);
    let holes = c.hole_list();
    if let Some(h) = holes
        .iter()
        .find(|h| d - h.radius < ri || d + h.radius > ro)
    {
        return err(
            "",
            format!(
                "holes of radius {} at distance {} must lie in the wall between inner radius {ri} and outer radius {ro}",
                h.radius, d
            ),
        );
    }
    let centre = |h: &crate::model::Hole| {
        let a = h.angle.to_radians();
        (d * a.cos(), d * a.sin())
    };
    for (i, a) in holes.iter().enumerate() {
        for b in &holes[i + 1..] {
            let ((ya, za), (yb, zb)) = (centre(a), centre(b));
            if (ya - yb).hypot(za - zb) <= a.radius + b.radius {
                return err(
                    "",
                    format!(
                        "holes of radius {} and {} at distance {} and angles {} and {} degrees overlap",
                        a.radius, b.radius, d, a.angle, b.angle
                    ),
                );
            }
        }
    }
    // The centroid may leave the axis (the levers and stiffness are taken
    // about it), but the principal axes must stay y and z: the elements
    // bend about those two.
    let [iy, iz] = s.second_moments().unwrap_or([1.0, 1.0]);
    if !planar && s.product_moment().abs() > 1e-9 * iy.max(iz) {
        return err(
            "",
            format!(
                "the holes at {holes:?} degrees turn the section's principal axes away from y and z (I_yz = {:.3e} m^4); place them symmetrically about the y or the z axis (for example 0 and 180, or 90 and 270, degrees)",
                s.product_moment()
            ),
        );
    }
    if let Some(inputs) = &c.inputs {
        let n = c.positions().len();
        if inputs.len() != n {
            return err(
                "inputs",
                format!(
                    "give one input channel per position ({n}{}), got {}",
                    if c.pair_spacing.is_some() {
                        ", a pair sharing one"
                    } else {
                        ""
                    },
                    inputs.len()
                ),
            );
        }
    }
    Ok(())
}

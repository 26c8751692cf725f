//! One home per modelling method.
//!
//! Each method is one file implementing [`ModellingMethod`]: its
//! coordinates and their names, the keys it owns and the checks of its
//! keys, and how its elements sit on the chain (their bodies, lumped
//! strains, springs and dampers). What every method shares is written
//! once elsewhere: the base and its motion, gravity, actuation, tip loads
//! and joint torques in the arm builders (`tmt::planar::PlanarArm`,
//! `tmt::spatial::SpatialArm`) and `tmt::system`; a segment's section and
//! material checks in `model::validate`.
//!
//! Adding a method: a file here implementing the trait, a variant of
//! `model::Method`, and its line in [`of`].

mod cosserat;
pub(crate) mod eba;
pub(crate) mod ebr;
mod pcc;
mod pcs;
mod rigid;
pub(crate) mod rom;
mod vc;

use crate::cas::Cas;
use crate::model::{Check, Method, ModelError, Segment, SegmentShape, Structure};
use crate::tmt::planar::{Element2, PlanarArm};
use crate::tmt::spatial::SpatialArm;
use crate::tmt::system::{ParamSymbols, System};

/// What a modelling method is, to the generator and to validation.
pub(crate) trait ModellingMethod: Sync {
    /// `[[segment]]` keys only this method takes (other methods reject
    /// them).
    fn own_keys(&self) -> &'static [&'static str] {
        &[]
    }

    /// A 3D method (rejected in a planar arm).
    fn spatial_only(&self) -> bool {
        false
    }

    /// The checks of this method's keys on segment `i` (after the section,
    /// material and dimension checks every segment has).
    fn check_keys(&self, ck: &Check, i: usize, s: &Segment) -> Result<(), ModelError>;

    /// 3D: the names of segment `s`'s coordinates.
    fn coordinate_names(&self, g: &SegmentShape, s: usize) -> Vec<String>;

    /// Planar: place one element (its bodies and end frame) on the arm.
    fn place_planar(
        &self,
        _cas: &mut Cas,
        _arm: &mut PlanarArm,
        _g: &SegmentShape,
        _el: &Element2,
    ) {
        unreachable!("validated: a 3D method, or statics only")
    }

    /// 3D: place segment `s`'s elements on the arm.
    fn build_spatial(&self, _cas: &mut Cas, _arm: &mut SpatialArm, _g: &SegmentShape, _s: usize) {
        unreachable!("validated: statics only, or a method that builds the whole arm")
    }

    /// A method whose coordinates are not a chain's (absolute states)
    /// builds the whole arm itself; chain methods return `None`.
    fn whole_arm(
        &self,
        _cas: &mut Cas,
        _st: &Structure,
        _symbols: &ParamSymbols,
    ) -> Option<System> {
        None
    }

    /// The link recursion (`runtime::links`) covers this method's links.
    fn link_cells(&self) -> bool {
        false
    }
}

/// The method of a segment.
pub(crate) fn of(method: Method) -> &'static dyn ModellingMethod {
    match method {
        Method::Rigid => &rigid::Rigid,
        Method::Pcc => &pcc::Pcc,
        Method::Pcs => &pcs::Pcs,
        Method::Vc => &vc::Vc,
        Method::Ebr => &ebr::Ebr,
        Method::Eba => &eba::Eba,
        Method::Rom => &rom::Rom,
        Method::Cosserat => &cosserat::Cosserat,
    }
}

/// Every method, for the keys they own.
const ALL: [Method; 8] = [
    Method::Rigid,
    Method::Pcc,
    Method::Pcs,
    Method::Vc,
    Method::Ebr,
    Method::Eba,
    Method::Rom,
    Method::Cosserat,
];

/// The generalised coordinates' names of a structure, in order: one angle
/// an element in the plane, else each segment's method's.
pub fn coordinate_names(st: &Structure) -> Vec<String> {
    let mut names = Vec::new();
    for (s, g) in st.segments.iter().enumerate() {
        if st.dimensions == 3 {
            names.extend(of(g.method).coordinate_names(g, s));
        } else {
            names.extend((0..g.elements).map(|e| format!("theta_{s}_{e}")));
        }
    }
    names
}

/// Segment `i`'s method-specific keys: none that another method owns, a
/// 3D method in 3D, then the method's own checks.
pub(crate) fn check_segment(ck: &Check, i: usize, s: &Segment) -> Result<(), ModelError> {
    let method = of(s.method);
    let given = serde_json::to_value(s).unwrap_or_default();
    for other in ALL {
        for &key in of(other).own_keys() {
            let present = given.get(key).is_some_and(|v| !v.is_null());
            if present && !method.own_keys().contains(&key) {
                let owners: Vec<&str> = ALL
                    .iter()
                    .filter(|m| of(**m).own_keys().contains(&key))
                    .map(|m| m.name())
                    .collect();
                return ck.err(
                    format!("segment[{i}].{key}"),
                    format!(
                        "not a key of {} segments: only {} segments take it",
                        s.method.name(),
                        owners.join(" and ")
                    ),
                );
            }
        }
    }
    if method.spatial_only() && ck.m.dimensions != 3 {
        return ck.err(
            format!("segment[{i}].method"),
            format!(
                "{} is a 3D method: set `dimensions = 3` at the top of the file",
                s.method.name()
            ),
        );
    }
    method.check_keys(ck, i, s)
}

/// What every soft method needs: a bending stiffness.
fn needs_bending_stiffness(ck: &Check, i: usize, s: &Segment) -> Result<(), ModelError> {
    if s.ei().is_some() {
        return Ok(());
    }
    ck.err(
        format!("segment[{i}].youngs_modulus"),
        format!(
            "missing: a {} segment needs `youngs_modulus` (with `outer_radius`) or `bending_stiffness`",
            s.method.name()
        ),
    )
}

/// 3D: a soft element's coordinates, per element: the strain fields.
fn strain_coordinate_names(g: &SegmentShape, s: usize) -> Vec<String> {
    let mut names = Vec::new();
    for e in 0..g.elements {
        for field in g.strain_fields() {
            names.push(format!("{field}_{s}_{e}"));
        }
    }
    names
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::parse_model;

    /// A 3D model of one segment by `method`, with extra keys.
    fn model(method: &str, extra: &str) -> Result<crate::model::Model, ModelError> {
        let text = format!(
            r#"
name = "t"
dimensions = 3
gravity = [0.0, 0.0, -9.81]
[base]
direction = [1.0, 0.0, 0.0]
[[segment]]
method = "{method}"
length = 0.2
elements = 3
density = 1000.0
outer_radius = 0.01
youngs_modulus = 1e6
extension = true
{extra}
"#
        );
        parse_model(&text, "t.toml", false, &[])
    }

    /// Each method's coordinates, counted from its definition in the
    /// chapter: per element 2 bends + twist + stretch (pcc, vc, ebr), 6
    /// absolute states (eba), one per joint axis (rigid); per strain field
    /// order + 1 coefficients (rom). Names are unique.
    #[test]
    fn coordinates_count_as_each_method_defines_them() {
        for (method, extra, want) in [
            ("pcc", "", 3 * 4),
            ("vc", "", 3 * 4),
            ("ebr", "", 3 * 4),
            ("eba", "", 3 * 6),
            ("rom", "order = 2", 4 * 3),
            ("rigid", "joint_axes = [\"z\", \"y\"]", 3 * 2),
        ] {
            let m = model(method, extra).unwrap_or_else(|e| panic!("{method}: {e}"));
            let names = coordinate_names(&Structure::of(&m));
            assert_eq!(names.len(), want, "{method}: {names:?}");
            let mut unique = names.clone();
            unique.sort();
            unique.dedup();
            assert_eq!(unique.len(), names.len(), "{method}: duplicate names");
        }
    }

    /// A key one method owns is rejected on every other, naming its owner.
    #[test]
    fn a_key_another_method_owns_is_rejected_with_its_owner() {
        for (method, key, owner) in [
            ("pcc", "order = 2", "rom"),
            ("ebr", "joint_damping = 0.1", "rigid"),
            ("rom", "joints = \"base\"", "rigid"),
            ("eba", "quadrature = 4", "rom"),
        ] {
            let e = model(method, key).unwrap_err().to_string();
            assert!(
                e.contains(&format!("not a key of {method} segments: only {owner}")),
                "{method} with {key}: {e}"
            );
        }
        // Its own keys are accepted.
        model("rom", "order = 2\nquadrature = 4").unwrap();
    }
}

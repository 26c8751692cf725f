//! One home per modelling method.
//!
//! Each method is one file implementing [`ModellingMethod`]: its
//! coordinates and their names, the keys it owns and the checks of its
//! keys, and how its elements sit on the chain (their bodies, lumped
//! strains, springs and dampers). What every method shares is written
//! once elsewhere: the base and its motion, gravity, actuation, tip loads
//! and joint torques in the arm builders (`tmt::planar::PlanarArm`,
//! `tmt::spatial::SpatialArm`) and `tmt::system`; a segment's section and
//! material checks in `load::validate`.
//!
//! Nothing outside this folder matches on `model::Method`: what the model
//! checks, the structure, the parameters, contact and the cells ask of a
//! method, they ask through [`of`] (`tests/suite/architecture.rs` holds it).
//!
//! Adding a method: a file here implementing the trait and its line in
//! the registry, `model/methods.rs` (its variant, its name in model files,
//! its file and type), which `dispatch!` below reads.

use crate::cas::Cas;

use crate::model::{Axis, Check, Joints, Method, ModelError, Segment, SegmentShape, Structure};
use crate::tmt::cell_kind::{CellKind, PointsOn};
use crate::tmt::planar::{Element2, PlanarArm};
use crate::tmt::spatial::SpatialArm;
use crate::tmt::system::{ParamSymbols, System};

/// Whether a method's elements carry a strain beyond bending (3D).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Carried {
    /// Never (a rigid link neither stretches nor shears).
    Never,
    /// As the segment's keys say (`extension`, `shear`).
    Optional,
    /// Always (eba's beam springs stretch and shear).
    Always,
}

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

    /// How its elements' sampled points lie on their links, where they
    /// do (`runtime::links`'s contact kernels and loads along the arm
    /// place them so); None: the flat kernels sample them.
    fn points_on_links(&self, _g: &SegmentShape, _spatial: bool) -> Option<PointsOn> {
        None
    }

    /// A method of statics alone (no equations of motion: nothing to
    /// derive, sample or simulate).
    fn statics_only(&self) -> bool {
        false
    }

    /// The method whose derivation serves this one's structure, when
    /// another's does (vc and pcs are pcc's arcs).
    fn derived_as(&self) -> Option<Method> {
        None
    }

    /// Lumped slices of a segment.
    fn slices(&self, s: &Segment) -> usize {
        s.elements
    }

    /// Its coordinates are the coefficients of polynomial strain fields
    /// of the segment's `order` (structural, and in the structure's
    /// canonical form).
    fn polynomial_fields(&self) -> bool {
        false
    }

    /// Where the joints of a segment's elements sit.
    fn joints(&self, _s: &Segment) -> Joints {
        Joints::Base
    }

    /// 3D: the revolute axes of each joint (a method of joints).
    fn joint_axes(&self, _s: &Segment) -> Vec<Axis> {
        Vec::new()
    }

    /// 3D: coordinates per element.
    fn coordinates_per_element(&self, g: &SegmentShape) -> usize {
        2 + usize::from(g.twist) + usize::from(g.extension) + 2 * usize::from(g.shear)
    }

    /// 3D: whether elements twist, stretch and shear (beyond the segment's
    /// keys, the method decides).
    fn twist(&self) -> Carried {
        Carried::Optional
    }
    fn stretch(&self) -> Carried {
        Carried::Optional
    }
    fn shear(&self) -> Carried {
        Carried::Optional
    }

    /// 3D: `extension` and `shear` are on unless the keys say otherwise.
    fn all_strains_by_default(&self) -> bool {
        false
    }

    /// 3D: a segment twists (a torsional stiffness is then needed).
    fn twisting(&self, s: &Segment) -> bool {
        s.twists()
    }

    /// The section is lumped, so `incompressible` can thin it as an
    /// element stretches (the Cosserat rod keeps its section).
    fn lumps_section(&self) -> bool {
        true
    }

    /// Where along element `e` (as a fraction of its length) its springs
    /// sit, which a varying section's stiffnesses are taken at: the
    /// element's middle, unless its springs join it to its neighbour.
    fn spring_at(&self, _e: usize) -> f64 {
        0.5
    }

    /// An element's rotational inertia about a diameter through its centre
    /// and about its axis, from its mass, length and the section's share
    /// (m I / A), in `dimensions`.
    fn element_inertia(
        &self,
        _s: &Segment,
        mass: f64,
        l: f64,
        section: f64,
        dimensions: u8,
    ) -> (f64, f64) {
        // The section's part of an arc; in 3D the arc is lumped as a
        // straight slice (in 2D its part is derived symbolically).
        let slice = if dimensions == 3 {
            mass * l * l / 12.0
        } else {
            0.0
        };
        (section + slice, 2.0 * section)
    }

    /// 3D: any rest shape, a curvature about z alone included, is
    /// structural (its elements read every rest parameter: an absolute
    /// method places its rest shape rather than measuring strains from it).
    fn rest_always_3d(&self) -> bool {
        false
    }

    /// A segment's end is a frame a joint may hold.
    fn segment_end_frames(&self) -> bool {
        true
    }

    /// The kind of link cell a segment's elements make (`build::cell`).
    fn cell_kind(&self, _g: &SegmentShape, _spatial: bool) -> CellKind {
        CellKind::Arc
    }
}

/// What a segment's method decides of it (the segment's other answers are
/// in `model::schema`, which knows methods only by name).
impl Segment {
    /// Lumped slices of the segment: `elements`, or `quadrature` for rom.
    pub fn slices(&self) -> usize {
        of(self.method).slices(self)
    }

    /// 3D: elements stretch.
    pub fn stretches(&self) -> bool {
        self.extension
            .unwrap_or(of(self.method).all_strains_by_default())
    }

    /// 3D: elements shear.
    pub fn shears(&self) -> bool {
        self.shear
            .unwrap_or(of(self.method).all_strains_by_default())
    }
}

impl SegmentShape {
    /// Coordinates per element in 3D.
    pub fn coordinates_3d(&self) -> usize {
        of(self.method).coordinates_per_element(self)
    }
}

/// Two half links, each half the element (midpoint joints).
fn half_links_inertia(mass: f64, l: f64, section: f64) -> (f64, f64) {
    (
        (mass / 2.0) * (l / 2.0).powi(2) / 12.0 + section / 2.0,
        section,
    )
}

/// The strains a segment's elements carry in 3D: twist, extension, shear.
pub(crate) fn strains(s: &Segment) -> (bool, bool, bool) {
    let m = of(s.method);
    let by = |c: Carried, key: bool| match c {
        Carried::Never => false,
        Carried::Optional => key,
        Carried::Always => true,
    };
    // Shear strain coordinates only where the keys choose them: a method
    // that always shears (eba) does so through its own coordinates' beam
    // springs.
    (
        by(m.twist(), s.twists()),
        by(m.stretch(), s.stretches()),
        m.shear() == Carried::Optional && s.shears(),
    )
}

/// The names of the methods `which` picks, as a list in prose ("a, b
/// and c"), for messages.
pub(crate) fn named(which: impl Fn(&dyn ModellingMethod) -> bool) -> String {
    let names: Vec<&str> = (ALL.iter())
        .filter(|m| which(of(**m)))
        .map(|m| m.name())
        .collect();
    match names.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!("{} and {last}", rest.join(", ")),
        _ => names.concat(),
    }
}

impl Method {
    /// A method of statics alone (the Cosserat rod).
    pub fn statics_only(self) -> bool {
        of(self).statics_only()
    }
}

/// Declares the method files and, from the registry's lines
/// (`model::methods`), [`ALL`] and [`of`].
macro_rules! dispatch {
    ($($(#[$doc:meta])* $variant:ident = $name:literal => $file:ident::$ty:ident,)*) => {
        $(pub(crate) mod $file;)*

        /// Every method, in the registry's order.
        pub const ALL: &[Method] = &[$(Method::$variant),*];

        /// The method of a segment.
        pub(crate) fn of(method: Method) -> &'static dyn ModellingMethod {
            match method {
                $(Method::$variant => &$file::$ty,)*
            }
        }
    };
}

crate::model::methods!(dispatch);

#[doc(hidden)]
pub use rom::{RomFields, legendre};

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
    for &other in ALL {
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

/// Why an arm with eba segments is no system of parts (eba's reason:
/// `eba::not_parts`); None for an arm without them, or one that is.
pub fn why_not_parts(st: &Structure) -> Option<&'static str> {
    let eba = st.segments.iter().any(|g| g.method == Method::Eba);
    eba.then(|| eba::not_parts(st)).flatten()
}

//! `vc`: variable curvature, one constant-curvature arc per segment, each
//! segment with its own length, section and material. Its kinematics are
//! pcc's (`model::Structure` derives a vc segment as a pcc one, so one
//! derivation and one compiled model serve both).

use super::{Method, ModellingMethod};
use super::pcc::Pcc;
use crate::cas::Cas;
use crate::model::{Check, ModelError, Segment, SegmentShape};
use crate::tmt::planar::{Element2, PlanarArm};
use crate::tmt::cell_kind::PointsOn;
use crate::tmt::spatial::SpatialArm;

pub(super) struct Vc;

impl ModellingMethod for Vc {
    fn derived_as(&self) -> Option<Method> {
        Some(Method::Pcc)
    }

    fn check_keys(&self, ck: &Check, i: usize, s: &Segment) -> Result<(), ModelError> {
        Pcc.check_keys(ck, i, s)
    }

    fn coordinate_names(&self, g: &SegmentShape, s: usize) -> Vec<String> {
        Pcc.coordinate_names(g, s)
    }

    fn place_planar(&self, cas: &mut Cas, arm: &mut PlanarArm, g: &SegmentShape, el: &Element2) {
        Pcc.place_planar(cas, arm, g, el)
    }

    fn build_spatial(&self, cas: &mut Cas, arm: &mut SpatialArm, g: &SegmentShape, s: usize) {
        Pcc.build_spatial(cas, arm, g, s)
    }

    fn link_cells(&self) -> bool {
        Pcc.link_cells()
    }

    fn points_on_links(&self, g: &SegmentShape, spatial: bool) -> Option<PointsOn> {
        Pcc.points_on_links(g, spatial)
    }
}

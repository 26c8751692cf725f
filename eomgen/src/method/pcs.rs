//! `pcs`: piecewise constant strain, the discrete Cosserat rod of Renda et
//! al. (2018): each element an arc of constant strain in all six of the
//! rod's strains, two bendings and twist (the rotation vector), extension
//! and two shears (the translation strain). It is pcc's arc with the
//! stretch and shear coordinates on (`model::Structure` derives a pcs
//! segment as a pcc one with `twist`, `extension` and `shear`, so one
//! derivation and one compiled model serve both); here only what differs:
//! 3D only, and its name in messages.

use super::{Method, ModellingMethod};
use super::pcc::Pcc;
use crate::cas::Cas;
use crate::model::{Check, ModelError, Segment, SegmentShape};
use crate::tmt::cell_kind::PointsOn;
use crate::tmt::spatial::SpatialArm;

pub(super) struct Pcs;

impl ModellingMethod for Pcs {
    fn derived_as(&self) -> Option<Method> {
        Some(Method::Pcc)
    }

    fn all_strains_by_default(&self) -> bool {
        true
    }

    fn spatial_only(&self) -> bool {
        true
    }

    fn check_keys(&self, ck: &Check, i: usize, s: &Segment) -> Result<(), ModelError> {
        Pcc.check_keys(ck, i, s)
    }

    fn coordinate_names(&self, g: &SegmentShape, s: usize) -> Vec<String> {
        Pcc.coordinate_names(g, s)
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

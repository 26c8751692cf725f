//! `cosserat`: the Cosserat rod, solved for statics by shooting
//! (`runtime::cosserat`, through `src/continuum.rs`): the continuum
//! reference the lumped methods are checked against. No generalised
//! coordinates and no dynamics; its checks say what the statics take.

use super::{ModellingMethod, needs_bending_stiffness};
use crate::model::{Check, ModelError, Segment, SegmentShape};

pub(super) struct Cosserat;

impl ModellingMethod for Cosserat {
    fn statics_only(&self) -> bool {
        true
    }

    fn lumps_section(&self) -> bool {
        false
    }

    fn check_keys(&self, ck: &Check, i: usize, s: &Segment) -> Result<(), ModelError> {
        if s.incompressible == Some(true) {
            return ck.err(
                format!("segment[{i}].incompressible"),
                "the Cosserat rod keeps its section as it stretches: remove the key, or use a lumped method (pcc, vc, ebr, eba, rom) to thin the section with the stretch".into(),
            );
        }
        needs_bending_stiffness(ck, i, s)?;
        one_uniform_rod(ck)?;
        constant_loads(ck)
    }

    fn coordinate_names(&self, _g: &SegmentShape, _s: usize) -> Vec<String> {
        Vec::new()
    }
}

/// The Cosserat statics take one uniform, straight segment with its
/// bending and twist stiffness, loaded by gravity and tip loads.
fn one_uniform_rod(ck: &Check) -> Result<(), ModelError> {
    let m = ck.m;
    let [s] = m.segments.as_slice() else {
        return ck.err(
            "segment".into(),
            format!(
                "the Cosserat statics take one [[segment]], got {}",
                m.segments.len()
            ),
        );
    };
    if s.kinked() {
        return ck.err(
            "segment[0].turn".into(),
            "the Cosserat rod starts at its base: set the base's direction instead of a kink".into(),
        );
    }
    if m.tip.mass.is_some() {
        return ck.err(
            "tip.mass".into(),
            "a tip mass is a load under gravity; give it as tip.force for the Cosserat statics"
                .into(),
        );
    }
    for (key, given) in [
        ("bending_stiffness", s.ei().is_some()),
        ("torsional_stiffness", s.gj().is_some()),
        ("axial_stiffness", !s.stretches() || s.ea().is_some()),
    ] {
        if !given {
            return ck.err(
                format!("segment[0].{key}"),
                "missing, the Cosserat rod needs it (or `youngs_modulus` with `outer_radius`)"
                    .into(),
            );
        }
    }
    Ok(())
}

/// The Cosserat statics solve a rod under constant loads: nothing that
/// inputs drive reaches it, so say so rather than ignore it.
fn constant_loads(ck: &Check) -> Result<(), ModelError> {
    let m = ck.m;
    // The Cosserat statics solve a rod under constant loads: nothing that
    // inputs drive reaches it, so say so rather than ignore it.
    let driven = [
        (
            "base.translation_inputs",
            m.base.translation_inputs.is_some(),
        ),
        ("base.rotation_inputs", m.base.rotation_inputs.is_some()),
        ("torque", !m.torques.is_empty()),
        ("tendon", !m.tendons.is_empty()),
        ("tip.force_inputs", m.tip.force_inputs.is_some()),
        ("tip.moment_inputs", m.tip.moment_inputs.is_some()),
        (
            "segment[0].chambers.inputs",
            m.segments
                .iter()
                .any(|s| s.chambers.as_ref().is_some_and(|c| c.inputs.is_some())),
        ),
    ];
    if let Some((key, _)) = driven.iter().find(|(_, given)| *given) {
        return ck.err(
            (*key).into(),
            "the Cosserat statics take constant tip loads and gravity only; actuators, joint torques, driven loads and a moving base need a lumped method (pcc, vc, ebr, eba, rom, rigid)".into(),
        );
    }
    Ok(())
}

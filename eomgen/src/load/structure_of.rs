//! A model's structure, from each segment's method: what the model file
//! says, as the derivation sees it (`model::Structure`).

use crate::model::assembly::FrameRef;
use crate::model::{
    AssemblyShape, JointShape, LoadShape, Model, SegmentShape, Structure, WrenchFrame,
};

impl Structure {
    pub fn of(m: &Model) -> Self {
        if !m.is_assembly() {
            return Self::of_arm(m);
        }
        let frame = |t: &str| FrameRef::parse(t, m).unwrap_or(FrameRef::World);
        let assembly = AssemblyShape {
            dimensions: m.dimensions,
            arms: m
                .arm_models()
                .iter()
                .map(|(name, a)| (name.clone(), Self::of_arm(a)))
                .collect(),
            bodies: m.bodies.iter().map(|b| (b.name.clone(), b.free)).collect(),
            contact: m.has_contact(),
            mounts: (m.arms.iter())
                .map(|a| a.base.on.as_deref().map(frame))
                .collect(),
            joints: m
                .joints
                .iter()
                .map(|j| JointShape {
                    name: j.name.clone(),
                    kind: j.kind,
                    a: frame(&j.a),
                    b: frame(&j.b),
                })
                .collect(),
        };
        Self {
            dimensions: m.dimensions,
            segments: Vec::new(),
            tip_mass: false,
            tip_force: false,
            tip_moment: false,
            tip_length: false,
            tip_frame_wrench: false,
            tip_force_driven: false,
            tip_moment_driven: false,
            chambers: Vec::new(),
            tendons: Vec::new(),
            torques: Vec::new(),
            base_translates: false,
            base_turns: 0,
            base_compliant: false,
            base_follows: false,
            base_twists: false,
            contact_points: 0,
            loads: Vec::new(),
            fluid: None,
            assembly: Some(Box::new(assembly)),
        }
    }

    /// The structure of one arm (the model's own, or one of an assembly's).
    fn of_arm(m: &Model) -> Self {
        let spatial = m.dimensions == 3;
        Self {
            dimensions: m.dimensions,
            segments: m
                .segments
                .iter()
                .map(|s| {
                    let method = crate::method::of(s.method);
                    let (twist, extension, shear) = crate::method::strains(s);
                    SegmentShape {
                        // A method whose kinematics are another's (vc and pcs
                        // are pcc's arcs) is derived as that one: the same
                        // derivation (and compiled code) serves both.
                        method: method.derived_as().unwrap_or(s.method),
                        elements: s.slices(),
                        polynomial: method.polynomial_fields(),
                        order: if method.polynomial_fields() {
                            s.rom_order()
                        } else {
                            0
                        },
                        joints: method.joints(s),
                        varying: method.polynomial_fields() && s.tapered(),
                        rest_3d: s.rest_3d(m.dimensions)
                            || (spatial && method.rest_always_3d() && s.rest_key().is_some()),
                        anisotropic: s.anisotropic(m.dimensions),
                        kink: s.kinked(),
                        chambers_vary: s.chambers.as_ref().is_some_and(|c| {
                            c.inputs.is_some()
                                && (c.distance.uniform().is_none()
                                    || s.tapered() && !c.centred(m.dimensions == 2))
                        }),
                        twist: spatial && twist,
                        extension: spatial && extension,
                        shear: spatial && shear,
                        incompressible: spatial && s.incompressible.unwrap_or(false),
                        axes: if spatial {
                            method.joint_axes(s)
                        } else {
                            Vec::new()
                        },
                    }
                })
                .collect(),
            tip_mass: m.tip.mass.is_some(),
            tip_force: m.tip.force.is_some() || m.tip.force_inputs.is_some(),
            // A sensor's force off the tip point has a moment about it.
            tip_moment: m.tip.moment.is_some()
                || m.tip.moment_inputs.is_some()
                || (m.tip.sensor_offset.is_some()
                    && (m.tip.force.is_some() || m.tip.force_inputs.is_some())),
            tip_length: m.tip.length.is_some(),
            tip_frame_wrench: m.tip.wrench_frame == Some(WrenchFrame::Tip) || m.tip.has_sensor(),
            tip_force_driven: m.tip.force_inputs.is_some(),
            tip_moment_driven: m.tip.moment_inputs.is_some()
                || (m.tip.sensor_offset.is_some() && m.tip.force_inputs.is_some()),
            chambers: m
                .segments
                .iter()
                .map(|s| {
                    s.chambers
                        .as_ref()
                        .and_then(|c| c.inputs.as_ref())
                        .map_or(0, Vec::len)
                })
                .collect(),
            tendons: m
                .tendons
                .iter()
                .map(|t| t.end.unwrap_or(m.segments.len() - 1))
                .collect(),
            torques: m.torques.iter().map(|t| t.coordinate.clone()).collect(),
            base_translates: m.base.translation_inputs.is_some(),
            base_turns: m.base.rotation_inputs.as_ref().map_or(0, Vec::len),
            base_compliant: m.base.is_compliant(),
            base_follows: m.base.is_compliant() && m.base.follow.is_some(),
            base_twists: m.base.turns_compliantly(),
            contact_points: m.contact_points(),
            loads: load_shapes(m),
            fluid: m.fluid.as_ref().map(|f| f.drags()),
            assembly: None,
        }
    }
}

/// Where each `[[load]]` acts (validated: its segment exists, its point
/// lies on it).
fn load_shapes(m: &Model) -> Vec<LoadShape> {
    m.loads
        .iter()
        .map(|l| {
            let first: usize = m.segments[..l.segment].iter().map(|s| s.slices()).sum();
            let g = &m.segments[l.segment];
            LoadShape {
                segment: l.segment,
                at: l.s.map(|s| {
                    let (e, f) = LoadShape::place(s, g.length, g.slices(), first);
                    (e, f.to_bits())
                }),
                local: l.local(),
                force: l.has_force(),
                moment: l.has_moment(),
                force_driven: l.force_inputs.is_some(),
                moment_driven: l.moment_inputs.is_some(),
            }
        })
        .collect()
}

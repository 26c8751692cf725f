//! The parameter layout of an assembly: gravity, every arm's own layout in
//! turn (its slots `Param::Scoped`), then the bodies, the joints and the
//! compliant bases. An arm's kernels read its slots at its offset, so one
//! arm's derivation is the single-arm one, scoped (`Cas::scoped`).

use std::collections::HashMap;

use super::params::{
    BodyParam, Driven, JointParam, Param, ParamLayout, Rate, SpringParam, Xyz, channel,
};
use super::schema::Model;
use super::structure::AssemblyShape;

impl ParamLayout {
    pub(super) fn of_assembly(a: &AssemblyShape) -> Self {
        let mut params: Vec<Param> = Xyz::ALL.map(Param::Gravity).to_vec();
        let mut driven = Vec::new();
        let mut arms = Vec::new();
        for (k, (name, st)) in a.arms.iter().enumerate() {
            let own = ParamLayout::of(st);
            let arm = k as u16;
            let scoped = |i: usize| Param::Scoped {
                arm,
                index: i as u32,
            };
            driven.extend(own.driven().iter().map(|d| Driven {
                param: scoped(own.index(d.param)),
                derivative: d.derivative,
            }));
            arms.push((name.clone(), params.len(), own.clone()));
            params.extend((0..own.len()).map(scoped));
        }
        let spatial = a.dimensions == 3;
        for (b, _) in a.bodies.iter().enumerate() {
            let b = b as u16;
            params.extend([BodyParam::Mass, BodyParam::Inertia].map(|w| Param::Body(b, w)));
            params.extend(Xyz::ALL.map(|c| Param::Body(b, BodyParam::Position(c))));
            params.push(Param::Body(b, BodyParam::Angle));
            if spatial {
                params.extend(Xyz::ALL.map(|c| Param::Body(b, BodyParam::Moment(c))));
                params.extend((0..4).map(|i| Param::Body(b, BodyParam::Quaternion(i))));
            }
        }
        for (j, _) in a.joints.iter().enumerate() {
            let j = j as u16;
            params.extend(Xyz::ALL.map(|c| Param::Joint(j, JointParam::OffsetA(c))));
            params.extend(Xyz::ALL.map(|c| Param::Joint(j, JointParam::OffsetB(c))));
            params.push(Param::Joint(j, JointParam::Angle));
            if spatial {
                params.extend((0..4).map(|i| Param::Joint(j, JointParam::Quaternion(i))));
            }
        }
        for (k, (_, st)) in a.arms.iter().enumerate() {
            if !st.base_compliant {
                continue;
            }
            let arm = k as u16;
            for w in [
                SpringParam::Mass,
                SpringParam::Stiffness,
                SpringParam::Damping,
            ] {
                params.push(Param::BaseSpring(arm, w));
            }
            if st.base_twists {
                for w in [
                    SpringParam::RotationalStiffness,
                    SpringParam::RotationalDamping,
                    SpringParam::Inertia,
                ] {
                    params.push(Param::BaseSpring(arm, w));
                }
            }
            // Without `follow` the point stays put: zeros, not inputs.
            let axes = if spatial {
                &Xyz::ALL[..]
            } else {
                &Xyz::ALL[..2]
            };
            for r in [Rate::Value, Rate::First] {
                for &c in axes {
                    let p = Param::BaseSpring(arm, SpringParam::Follow(r, c));
                    if st.base_follows {
                        driven.push(Driven {
                            param: p,
                            derivative: r.derivative(),
                        });
                    }
                    params.push(p);
                }
            }
        }
        let index: HashMap<Param, usize> =
            params.iter().enumerate().map(|(i, &p)| (p, i)).collect();
        Self {
            params,
            index,
            driven,
            arms,
            assembly: true,
        }
    }

    /// The input channel that drives `p` (an assembly's arm parameters by
    /// their arm's declaration).
    pub fn channel(&self, m: &Model, p: Param) -> Option<String> {
        match p {
            Param::Scoped { arm, index } => {
                let (_, _, layout) = &self.arms[arm as usize];
                let (_, am) = m.arm_models().into_iter().nth(arm as usize)?;
                channel(&am, layout.params()[index as usize]).map(str::to_string)
            }
            Param::BaseSpring(a, SpringParam::Follow(_, c)) => {
                let (_, am) = m.arm_models().into_iter().nth(a as usize)?;
                am.base.follow.as_ref()?.get(c.index()).cloned()
            }
            p => channel(m, p).map(str::to_string),
        }
    }
}

//! A checked model's parameter values, in its layout's order: the
//! elements' physical quantities (their inertia the method's), then each
//! parameter's number.

use crate::model::sensor::{Source, wrench_sources};
use crate::model::{
    BodyParam, ChamberParam, ElementParam, FluidParam, JointParam, KinkParam, LoadParam, Model,
    Param, ParamLayout, Segment, SpringParam, Structure, base_quaternion, base_rotation,
    base_turn_axis, chamber_value, chamber_value_of,
};

impl ParamLayout {
    /// The values of a model with this layout's structure, in layout order
    /// (driven parameters start at 0: their signals set them).
    pub fn values(&self, m: &Model) -> Vec<f64> {
        if self.is_assembly() {
            return self.assembly_values(m);
        }
        let elements = element_props(m);
        let d = m.base.direction;
        let rotation = base_rotation(d);
        let quaternion = base_quaternion(d);
        self.params()
            .iter()
            .map(|&p| match p {
                Param::Gravity(c) => m.gravity[c.index()],
                Param::BasePosition(c) => m.base.position[c.index()],
                Param::BaseRotation(i, j) => rotation[i as usize][j as usize],
                Param::BaseQuaternion(c) => quaternion[c as usize],
                Param::BaseAngle => d[1].atan2(d[0]),
                Param::BaseTranslation(..) | Param::BaseTurn(..) => 0.0,
                Param::BaseTurnAxis(i, c) => {
                    let a = base_turn_axis(m, i);
                    a[c.index()] / (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
                }
                Param::TipMass => m.tip.mass.unwrap_or(0.0),
                // In a sensor frame: the constant part of the map (a
                // driven component is overwritten by its drive).
                Param::TipForce(c) | Param::TipMoment(c) if m.tip.has_sensor() => {
                    let row = c.index()
                        + if matches!(p, Param::TipMoment(_)) {
                            3
                        } else {
                            0
                        };
                    wrench_sources(m, row)
                        .unwrap_or_default()
                        .iter()
                        .map(|(w, s)| match s {
                            Source::Constant(v) => w * v,
                            Source::Channel(_) => 0.0,
                        })
                        .sum()
                }
                Param::TipForce(c) => m.tip.force.map_or(0.0, |f| f[c.index()]),
                Param::TipMoment(c) => m.tip.moment.map_or(0.0, |f| f[c.index()]),
                Param::TipLength => m.tip.length.unwrap_or(0.0),
                // A uniform cylinder along the tip axis, about its centre.
                Param::TipInertia => {
                    let (mass, r) = (m.tip.mass.unwrap_or(0.0), m.tip.radius.unwrap_or(0.0));
                    let len = m.tip.length.unwrap_or(0.0);
                    mass * (3.0 * r * r + len * len) / 12.0
                }
                Param::TipAxialInertia => {
                    let (mass, r) = (m.tip.mass.unwrap_or(0.0), m.tip.radius.unwrap_or(0.0));
                    mass * r * r / 2.0
                }
                Param::Element(k, e) => elements[k].get(e),
                Param::Chamber {
                    segment,
                    position,
                    what,
                } => chamber_value(m, segment, position, what),
                Param::ChamberArm {
                    element,
                    position,
                    z,
                } => chamber_arm(m, element, position, z),
                Param::TendonTension(_) | Param::Torque(_) => 0.0,
                // A driven component starts at 0: its input sets it.
                Param::Load(i, LoadParam::Force(c)) => {
                    m.loads[i].force.map_or(0.0, |f| f[c.index()])
                }
                Param::Load(i, LoadParam::Moment(c)) => {
                    m.loads[i].moment.map_or(0.0, |f| f[c.index()])
                }
                Param::Fluid(what) => {
                    let f = m.fluid.as_ref().expect("the structure has the fluid");
                    match what {
                        FluidParam::Density => f.density,
                        FluidParam::DragNormal => f.drag_normal,
                        FluidParam::DragTangential => f.drag_tangential,
                        FluidParam::Current(c) => f.current[c.index()],
                    }
                }
                Param::Kink(s, KinkParam::Turn(i)) => {
                    let turn = m.segments[s].turn.as_deref().unwrap_or_default();
                    turn.get(i as usize).copied().unwrap_or(0.0).to_radians()
                }
                Param::Kink(s, KinkParam::Offset(c)) => {
                    m.segments[s].offset.map_or(0.0, |o| o[c.index()])
                }
                Param::TendonOffset { tendon, segment, z } => {
                    let t = &m.tendons[tendon];
                    let d = t.distance.at(segment);
                    let angle = t.angle.as_ref().map_or(0.0, |a| a.at(segment)).to_radians();
                    if z { d * angle.sin() } else { d * angle.cos() }
                }
                _ => unreachable!("assembly parameters have their own values"),
            })
            .collect()
    }

    /// The values of an assembly model, in layout order.
    pub(super) fn assembly_values(&self, m: &Model) -> Vec<f64> {
        let arm_models = m.arm_models();
        let arm_values: Vec<Vec<f64>> = self
            .arms()
            .iter()
            .zip(&arm_models)
            .map(|((_, _, layout), (_, am))| layout.values(am))
            .collect();
        self.params()
            .iter()
            .map(|&p| match p {
                Param::Gravity(c) => m.gravity[c.index()],
                Param::Scoped { arm, index } => arm_values[arm as usize][index as usize],
                Param::Body(b, what) => {
                    let body = &m.bodies[b as usize];
                    match what {
                        BodyParam::Mass => body.total_mass().unwrap_or(0.0),
                        BodyParam::Inertia => body.planar_inertia().unwrap_or(0.0),
                        BodyParam::Position(c) => body.position[c.index()],
                        BodyParam::Angle => body.angle,
                        BodyParam::Moment(c) => body.principal().map_or(0.0, |i| i[c.index()]),
                        BodyParam::Quaternion(i) => body.quaternion()[i as usize],
                    }
                }
                Param::Joint(j, what) => {
                    let joint = &m.joints[j as usize];
                    match what {
                        JointParam::OffsetA(c) => joint.offset_a[c.index()],
                        JointParam::OffsetB(c) => joint.offset_b[c.index()],
                        JointParam::Angle => joint.angle,
                        JointParam::Quaternion(i) => {
                            crate::model::assembly::normalised(joint.orientation)[i as usize]
                        }
                    }
                }
                Param::BaseSpring(a, what) => {
                    let base = &arm_models[a as usize].1.base;
                    match what {
                        SpringParam::Mass => base.mass.unwrap_or(0.0),
                        SpringParam::Stiffness => base.stiffness.unwrap_or(0.0),
                        SpringParam::Damping => base.damping.unwrap_or(0.0),
                        SpringParam::RotationalStiffness => {
                            base.rotational_stiffness.unwrap_or(0.0)
                        }
                        SpringParam::RotationalDamping => base.rotational_damping.unwrap_or(0.0),
                        SpringParam::Inertia => base.inertia.unwrap_or(0.0),
                        SpringParam::Follow(..) => 0.0,
                    }
                }
                _ => unreachable!("an assembly layout holds no unscoped arm parameter"),
            })
            .collect()
    }
}

/// Names and values of a model's runtime parameters, in layout order.
pub fn parameters(m: &Model) -> Vec<(String, f64)> {
    let layout = ParamLayout::of(&Structure::of(m));
    layout.names().into_iter().zip(layout.values(m)).collect()
}

/// The slots of segment `segment`'s stiffnesses (bending, twist,
/// stretch, shear): what a viscoelastic segment relaxes.
pub fn segment_stiffness(layout: &ParamLayout, m: &Model, segment: usize) -> Vec<usize> {
    let first: usize = m.segments[..segment].iter().map(|s| s.slices()).sum();
    let elements = first..first + m.segments[segment].slices();
    (layout.params().iter().enumerate())
        .filter(|(_, p)| match p {
            Param::Element(k, e) => {
                elements.contains(k)
                    && matches!(
                        e,
                        ElementParam::BendStiffness
                            | ElementParam::BendStiffnessY
                            | ElementParam::TwistStiffness
                            | ElementParam::StretchStiffness
                            | ElementParam::ShearStiffness
                    )
            }
            _ => false,
        })
        .map(|(i, _)| i)
        .collect()
}

/// Per-element physical quantities, from the declared segment.
#[derive(Clone, Copy, Debug)]
pub struct ElementProps {
    pub length: f64,
    pub mass: f64,
    /// Rotational inertia (about the axis normal to the plane) of each rigid
    /// body of the element about its centre of mass: the whole link (rigid,
    /// base joints), each half link (rigid, midpoint joints), or the
    /// section's part m (r_o^2 + r_i^2) / 4 (pcc: the arc's part depends on
    /// the bend and is derived symbolically).
    pub inertia: f64,
    /// Joint or bending stiffness of the element (N m/rad): E I / l_e.
    pub stiffness: f64,
    /// Joint or bending damping (N m s/rad): eta / l_e.
    pub damping: f64,
    /// Angle at rest (rad): rest curvature times l_e.
    pub rest: f64,
    /// 3D: moment of inertia of each body about its own axis.
    pub axial_inertia: f64,
    /// 3D: G J / l_e (N m/rad) and its damping.
    pub twist_stiffness: f64,
    pub twist_damping: f64,
    /// 3D: E A / l_e (N/m) and c / l_e (N s/m).
    pub stretch_stiffness: f64,
    pub stretch_damping: f64,
    /// 3D, shearing elements: k G A / l_e (N/m) along y, and along z.
    pub shear_stiffness: f64,
    pub shear_stiffness_z: f64,
    /// 3D rest shapes: bend about y and twist (rad), stretch (m), each the
    /// rest strain times l_e.
    pub rest_y: f64,
    pub rest_twist: f64,
    pub rest_stretch: f64,
    /// Immersed: the displaced volume (the outer section's) and the width
    /// across the flow (the outer diameter).
    pub volume: f64,
    pub width: f64,
    /// 3D anisotropic sections: E I_y / l_e and the bodies' rotary
    /// inertia about their y axis.
    pub stiffness_y: f64,
    pub inertia_y: f64,
}

impl ElementProps {
    pub fn get(&self, e: ElementParam) -> f64 {
        match e {
            ElementParam::Length => self.length,
            ElementParam::Mass => self.mass,
            ElementParam::Inertia => self.inertia,
            ElementParam::AxialInertia => self.axial_inertia,
            ElementParam::BendStiffness => self.stiffness,
            ElementParam::BendDamping => self.damping,
            ElementParam::Rest => self.rest,
            ElementParam::TwistStiffness => self.twist_stiffness,
            ElementParam::TwistDamping => self.twist_damping,
            ElementParam::StretchStiffness => self.stretch_stiffness,
            ElementParam::StretchDamping => self.stretch_damping,
            ElementParam::ShearStiffness => self.shear_stiffness,
            ElementParam::RestY => self.rest_y,
            ElementParam::RestTwist => self.rest_twist,
            ElementParam::RestStretch => self.rest_stretch,
            ElementParam::Volume => self.volume,
            ElementParam::Width => self.width,
            ElementParam::BendStiffnessY => self.stiffness_y,
            ElementParam::InertiaY => self.inertia_y,
            ElementParam::ShearStiffnessZ => self.shear_stiffness_z,
        }
    }
}

/// Element `element`'s lever of a chamber position (y's, or z's): its
/// segment's section and holes at the element's middle.
fn chamber_arm(m: &Model, element: usize, position: usize, z: bool) -> f64 {
    let mut k = element;
    for s in &m.segments {
        let n = s.slices();
        if k < n {
            let what = if z {
                ChamberParam::ArmZ
            } else {
                ChamberParam::ArmY
            };
            return chamber_value_of(&s.at((k as f64 + 0.5) / n as f64), position, what);
        }
        k -= n;
    }
    unreachable!("the layout's element {element} is one of the model's")
}

/// Each element's values (a rom segment's: each slice's): a tapered
/// segment's at the element's middle, so that its stiffness, mass and
/// inertia converge at second order in the element length.
pub fn element_props(m: &Model) -> Vec<ElementProps> {
    let mut out = Vec::new();
    for s in &m.segments {
        let n = s.slices();
        let method = crate::method::of(s.method);
        for e in 0..n {
            let at = |x: f64| s.at((e as f64 + x) / n as f64);
            let (body, springs) = (at(0.5), at(method.spring_at(e)));
            out.push(props_of(m, [&body, &springs], s.length / n as f64, n));
        }
    }
    out
}

/// The values of an element of length `l`, one of `n`: its body's from
/// the uniform segment `s`, its springs' from `springs` (the section where
/// they sit).
fn props_of(m: &Model, [s, springs]: [&Segment; 2], l: f64, n: usize) -> ElementProps {
    let ro = s.outer().unwrap_or(0.0);
    let ri = s.inner().unwrap_or(0.0);
    let given = s.given();
    let mass = match (s.mass, s.density.as_ref()) {
        _ if given.is_some() => s.mass_per_length(0.5).unwrap_or(0.0) * l,
        (Some(mass), _) => mass / n as f64,
        (None, Some(rho)) => rho.at(0.0) * s.area().unwrap_or(0.0) * l,
        (None, None) => 0.0, // rejected by validation
    };
    // Uniform cylinders (hollow, solid, with chamber holes) about a
    // diameter through the centre, m I / A ((r_o^2 + r_i^2) / 4 for a
    // ring); slender rods when no radius is given.
    // About z and about y.
    let [section, section_y] = match (s.second_moments(), s.area(), given) {
        (_, _, Some(g)) => [g.rho_i[1] * l, g.rho_i[0] * l],
        (Some([iy, iz]), Some(a), _) if a > 0.0 => [mass * iz / a, mass * iy / a],
        _ => [mass * (ro * ro + ri * ri) / 4.0; 2],
    };
    // Bodies: the whole link, or two half links (midpoint joints), or
    // the section's part of an arc: the method's.
    let method = crate::method::of(s.method);
    let (inertia, mut axial_inertia) = method.element_inertia(s, mass, l, section, m.dimensions);
    let inertia_y = match section_y == section {
        true => inertia,
        false => {
            let (lateral, axial_y) = method.element_inertia(s, mass, l, section_y, m.dimensions);
            // The polar moment is the sum of the two.
            axial_inertia = 0.5 * (axial_inertia + axial_y);
            lateral
        }
    };
    let joint = |e: Option<f64>| match e {
        Some(ei) => ei / l,
        None => s.joint_stiffness.unwrap_or(0.0),
    };
    let (stiffness, stiffness_y) = (joint(springs.ei()), joint(springs.ei_y()));
    // A polar moment given apart from I_y + I_z: the method's share of it.
    if let Some(g) = given {
        axial_inertia *= g.rho_j / (g.rho_i[0] + g.rho_i[1]);
    }
    let damping = match s.bending_damping {
        Some(eta) => eta / l,
        None => s.joint_damping.unwrap_or(0.0),
    };
    let twist_stiffness = match springs.gj() {
        Some(gj) => gj / l,
        None => s.joint_stiffness.unwrap_or(0.0),
    };
    let [rest_y, rest_z, rest_twist, rest_stretch] = s.rest_at(0.5, m.dimensions);
    ElementProps {
        length: l,
        mass,
        inertia,
        stiffness,
        damping,
        rest: rest_z * l,
        rest_y: rest_y * l,
        rest_twist: rest_twist * l,
        rest_stretch: rest_stretch * l,
        volume: std::f64::consts::PI * ro * ro * l,
        width: 2.0 * ro,
        axial_inertia,
        twist_stiffness,
        twist_damping: damping,
        stretch_stiffness: springs.ea().unwrap_or(0.0) / l,
        stretch_damping: s.axial_damping.unwrap_or(0.0) / l,
        shear_stiffness: springs.ga_pair().map_or(0.0, |g| g[0]) / l,
        shear_stiffness_z: springs.ga_pair().map_or(0.0, |g| g[1]) / l,
        stiffness_y,
        inertia_y,
    }
}

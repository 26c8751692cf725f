//! Typed runtime parameters and their layout.
//!
//! A [`Param`] says what a parameter is (the stiffness of element 3's bend,
//! the tension of tendon 0); a [`ParamLayout`] is the ordered list of the
//! parameters a structure has, computed once by [`ParamLayout::of`], with
//! an index per parameter. The generator, the link cells and the input
//! channels all find a parameter's slot through the layout, never by its
//! text name: names ([`Param::name`]) exist only for output, error
//! messages and the tape's metadata.
//!
//! Invariant: the layout is a function of the [`Structure`] alone, so one
//! derivation serves every model with that structure; the values come from
//! the model at run time ([`ParamLayout::values`]).

use std::collections::HashMap;

use super::schema::{Model, Segment};
use super::structure::Structure;

/// A component of a vector in the world frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Xyz {
    X,
    Y,
    Z,
}

impl Xyz {
    pub const ALL: [Xyz; 3] = [Xyz::X, Xyz::Y, Xyz::Z];

    pub fn index(self) -> usize {
        self as usize
    }

    fn name(self) -> &'static str {
        ["x", "y", "z"][self as usize]
    }
}

/// A prescribed base quantity and its time derivatives: the input channel
/// gives the value, its first and its second derivative.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Rate {
    Value,
    First,
    Second,
}

impl Rate {
    pub const ALL: [Rate; 3] = [Rate::Value, Rate::First, Rate::Second];

    /// How often the input channel is differentiated.
    pub fn derivative(self) -> u8 {
        self as u8
    }
}

/// One element's (link's, slice's) lumped quantities.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum ElementParam {
    /// Length at rest (m).
    Length,
    Mass,
    /// Rotational inertia of each body about a lateral axis (planar: about
    /// the plane's normal).
    Inertia,
    /// 3D: about the body's own axis.
    AxialInertia,
    /// Joint or bending stiffness E I / l_e (N m/rad) and its damping.
    BendStiffness,
    BendDamping,
    /// Angle at rest: rest curvature times l_e.
    Rest,
    /// 3D: G J / l_e and its damping.
    TwistStiffness,
    TwistDamping,
    /// 3D: E A / l_e and c / l_e.
    StretchStiffness,
    StretchDamping,
    /// 3D, shearing elements (pcs, eba): k G A / l_e.
    ShearStiffness,
    /// 3D rest shapes (`SegmentShape::rest_3d`): the bend about y, the
    /// twist (rest strain times l_e, rad) and the stretch (m) at rest.
    RestY,
    RestTwist,
    RestStretch,
    /// Immersed arms (`[fluid]`): the outer volume the element displaces
    /// (m^3) and its width across the flow (m).
    Volume,
    Width,
    /// 3D anisotropic sections (`SegmentShape::anisotropic`): E I_y / l_e,
    /// the bend about y (`BendStiffness` is then about z), and each body's
    /// rotary inertia about its y axis (`Inertia` about z).
    BendStiffnessY,
    InertiaY,
    /// 3D anisotropic sections: k G A_z / l_e, the shear along z
    /// (`ShearStiffness` is then along y).
    ShearStiffnessZ,
}

impl ElementParam {
    /// The parameters of every element, in layout order.
    pub const PLANAR: [ElementParam; 6] = [
        Self::Length,
        Self::Mass,
        Self::Inertia,
        Self::BendStiffness,
        Self::BendDamping,
        Self::Rest,
    ];
    /// The parameters 3D elements add, in layout order.
    pub const SPATIAL: [ElementParam; 6] = [
        Self::AxialInertia,
        Self::TwistStiffness,
        Self::TwistDamping,
        Self::StretchStiffness,
        Self::StretchDamping,
        Self::ShearStiffness,
    ];
    /// The parameters a 3D rest shape adds to its elements, in layout
    /// order; a link cell reads them after its actuation loads
    /// (`runtime::links::REST_PARAMS`).
    pub const REST_3D: [ElementParam; runtime::links::REST_PARAMS] =
        [Self::RestY, Self::RestTwist, Self::RestStretch];
    /// The parameters an anisotropic section adds, in layout order.
    pub const ANISOTROPIC: [ElementParam; 3] =
        [Self::BendStiffnessY, Self::InertiaY, Self::ShearStiffnessZ];
    /// A link cell's parameters, in the order the cell tape reads them
    /// (`runtime::links::ELEMENT_PARAMS` of them).
    pub const CELL: [ElementParam; runtime::links::ELEMENT_PARAMS] = [
        Self::Length,
        Self::Mass,
        Self::Inertia,
        Self::AxialInertia,
        Self::BendStiffness,
        Self::BendDamping,
        Self::Rest,
        Self::TwistStiffness,
        Self::TwistDamping,
        Self::StretchStiffness,
        Self::StretchDamping,
        Self::ShearStiffness,
    ];

    fn name(self, k: usize) -> String {
        let (group, what) = match self {
            Self::Length => ("element", "length"),
            Self::Mass => ("element", "mass"),
            Self::Inertia => ("element", "inertia"),
            Self::AxialInertia => ("element", "axial_inertia"),
            Self::BendStiffness => ("joint", "stiffness"),
            Self::BendDamping => ("joint", "damping"),
            Self::Rest => ("joint", "rest"),
            Self::TwistStiffness => ("twist", "stiffness"),
            Self::TwistDamping => ("twist", "damping"),
            Self::StretchStiffness => ("stretch", "stiffness"),
            Self::StretchDamping => ("stretch", "damping"),
            Self::ShearStiffness => ("shear", "stiffness"),
            Self::RestY => ("joint", "rest_y"),
            Self::RestTwist => ("twist", "rest"),
            Self::RestStretch => ("stretch", "rest"),
            Self::Volume => ("element", "volume"),
            Self::Width => ("element", "width"),
            Self::BendStiffnessY => ("joint", "stiffness_y"),
            Self::InertiaY => ("element", "inertia_y"),
            Self::ShearStiffnessZ => ("shear", "stiffness_z"),
        };
        format!("{group}[{k}].{what}")
    }
}

/// What a driven chamber position contributes: its pressure (an input) and
/// the lever of the pressure, the holes' total area and first moments.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum ChamberParam {
    Pressure,
    Area,
    /// a sum(z): the lever of a bend about y.
    ArmY,
    /// a sum(y): the lever of a bend about z.
    ArmZ,
}

impl ChamberParam {
    pub const ALL: [ChamberParam; 4] = [Self::Pressure, Self::Area, Self::ArmY, Self::ArmZ];
}

/// One runtime parameter, by what it is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Param {
    Gravity(Xyz),
    /// The declared clamp position.
    BasePosition(Xyz),
    /// 3D: the rotation taking +x to the base direction, row i, column j.
    BaseRotation(u8, u8),
    /// 3D: that rotation as a quaternion, w, x, y, z.
    BaseQuaternion(u8),
    /// Planar: the base direction's angle from +x.
    BaseAngle,
    /// A prescribed displacement of the base, its velocity and acceleration
    /// (inputs).
    BaseTranslation(Rate, Xyz),
    /// Prescribed turn i of the base, its rate and acceleration (inputs).
    BaseTurn(Rate, usize),
    /// 3D: the unit axis of turn i.
    BaseTurnAxis(usize, Xyz),
    TipMass,
    TipForce(Xyz),
    TipMoment(Xyz),
    /// A tip body's length, lateral and axial inertia (a cylinder).
    TipLength,
    TipInertia,
    TipAxialInertia,
    /// Element k's quantity.
    Element(usize, ElementParam),
    /// Driven chamber position `position` of segment `segment`.
    Chamber {
        segment: usize,
        position: usize,
        what: ChamberParam,
    },
    /// Element `element`'s lever of chamber position `position` (a sum of
    /// hole area times offset, y's then z's, as `ChamberParam::ArmY` and
    /// `ArmZ`), where the levers vary along the segment.
    ChamberArm {
        element: usize,
        position: usize,
        z: bool,
    },
    /// Tendon i's tension (an input).
    TendonTension(usize),
    /// Tendon i's offset in the section of a segment it spans: y, z.
    TendonOffset {
        tendon: usize,
        segment: usize,
        z: bool,
    },
    /// Joint torque i's generalised force (an input).
    Torque(usize),
    /// An assembly: parameter `index` of arm `arm`'s own layout.
    Scoped {
        arm: u16,
        index: u32,
    },
    /// An assembly's body `0`'s quantity.
    Body(u16, BodyParam),
    /// An assembly's joint `0`'s offsets and angle.
    Joint(u16, JointParam),
    /// Arm `0`'s compliant base.
    BaseSpring(u16, SpringParam),
    /// Segment `0`'s kink: where it starts from the previous one's end.
    Kink(usize, KinkParam),
    /// `[[load]]` `0`'s force and moment.
    Load(usize, LoadParam),
    /// The fluid's density, drag coefficients and current.
    Fluid(FluidParam),
}

/// The fluid's values (`[fluid]`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum FluidParam {
    Density,
    DragNormal,
    DragTangential,
    Current(Xyz),
}

/// A load's force (N, or N/m when distributed) and moment (N m).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum LoadParam {
    Force(Xyz),
    Moment(Xyz),
}

/// A kink's turn (radians; planar: 0 about z; 3D: 0 about y, 1 about z)
/// and its offset in the previous segment's end frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum KinkParam {
    Turn(u8),
    Offset(Xyz),
}

/// A rigid body's quantities: mass, planar inertia, and where a fixed body
/// sits.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum BodyParam {
    Mass,
    Inertia,
    Position(Xyz),
    Angle,
    /// 3D: the principal moment about the body's axis.
    Moment(Xyz),
    /// 3D: a fixed body's orientation, w, x, y, z.
    Quaternion(u8),
}

/// A joint's points in its two frames, and a weld's angle.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum JointParam {
    OffsetA(Xyz),
    OffsetB(Xyz),
    Angle,
    /// 3D weld: b's orientation in a's, w, x, y, z.
    Quaternion(u8),
}

/// A compliant base: its mass, spring and damper, and the driven point it
/// follows (displacement and velocity: inputs).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum SpringParam {
    Mass,
    Stiffness,
    Damping,
    /// The rotational spring and damper, and the base's rotational inertia.
    RotationalStiffness,
    RotationalDamping,
    Inertia,
    Follow(Rate, Xyz),
}

impl Param {
    /// The parameter's name, as outputs, errors and the tape's metadata
    /// show it.
    pub fn name(self) -> String {
        match self {
            Self::Gravity(c) => format!("gravity.{}", c.name()),
            Self::BasePosition(c) => format!("base.{}", c.name()),
            Self::BaseRotation(i, j) => format!("base.R{i}{j}"),
            Self::BaseQuaternion(c) => format!("base.{}", ["qw", "qx", "qy", "qz"][c as usize]),
            Self::BaseAngle => "base.angle".into(),
            Self::BaseTranslation(r, c) => {
                format!("base.{}{}", ["s", "v", "a"][r as usize], c.name())
            }
            Self::BaseTurn(r, i) => format!("base.{}[{i}]", ["turn", "omega", "alpha"][r as usize]),
            Self::BaseTurnAxis(i, c) => format!("base.axis[{i}].{}", c.name()),
            Self::TipMass => "tip.mass".into(),
            Self::TipForce(c) => format!("tip.force.{}", c.name()),
            Self::TipMoment(c) => format!("tip.moment.{}", c.name()),
            Self::TipLength => "tip.length".into(),
            Self::TipInertia => "tip.inertia".into(),
            Self::TipAxialInertia => "tip.axial_inertia".into(),
            Self::Element(k, e) => e.name(k),
            Self::Chamber {
                segment,
                position,
                what,
            } => {
                let w = ["pressure", "area", "arm_y", "arm_z"][what as usize];
                format!("chamber[{segment}][{position}].{w}")
            }
            Self::ChamberArm {
                element,
                position,
                z,
            } => format!(
                "element[{element}].chamber[{position}].{}",
                if z { "arm_z" } else { "arm_y" }
            ),
            Self::TendonTension(i) => format!("tendon[{i}].tension"),
            Self::TendonOffset { tendon, segment, z } => {
                format!("tendon[{tendon}][{segment}].{}", if z { "z" } else { "y" })
            }
            Self::Torque(i) => format!("torque[{i}]"),
            Self::Scoped { arm, index } => format!("arm[{arm}].p[{index}]"),
            Self::Body(b, what) => match what {
                BodyParam::Mass => format!("body[{b}].mass"),
                BodyParam::Inertia => format!("body[{b}].inertia"),
                BodyParam::Position(c) => format!("body[{b}].{}", c.name()),
                BodyParam::Angle => format!("body[{b}].angle"),
                BodyParam::Moment(c) => format!("body[{b}].moment.{}", c.name()),
                BodyParam::Quaternion(i) => {
                    format!("body[{b}].q{}", ["w", "x", "y", "z"][i as usize])
                }
            },
            Self::Joint(j, what) => match what {
                JointParam::OffsetA(c) => format!("joint[{j}].offset_a.{}", c.name()),
                JointParam::OffsetB(c) => format!("joint[{j}].offset_b.{}", c.name()),
                JointParam::Angle => format!("joint[{j}].angle"),
                JointParam::Quaternion(i) => {
                    format!("joint[{j}].q{}", ["w", "x", "y", "z"][i as usize])
                }
            },
            Self::Fluid(FluidParam::Density) => "fluid.density".into(),
            Self::Fluid(FluidParam::DragNormal) => "fluid.drag_normal".into(),
            Self::Fluid(FluidParam::DragTangential) => "fluid.drag_tangential".into(),
            Self::Fluid(FluidParam::Current(c)) => format!("fluid.current.{}", c.name()),
            Self::Load(i, LoadParam::Force(c)) => format!("load[{i}].force.{}", c.name()),
            Self::Load(i, LoadParam::Moment(c)) => format!("load[{i}].moment.{}", c.name()),
            Self::Kink(s, KinkParam::Turn(i)) => format!("segment[{s}].turn[{i}]"),
            Self::Kink(s, KinkParam::Offset(c)) => format!("segment[{s}].offset.{}", c.name()),
            Self::BaseSpring(a, what) => match what {
                SpringParam::Mass => format!("arm[{a}].base.mass"),
                SpringParam::Stiffness => format!("arm[{a}].base.stiffness"),
                SpringParam::Damping => format!("arm[{a}].base.damping"),
                SpringParam::RotationalStiffness => {
                    format!("arm[{a}].base.rotational_stiffness")
                }
                SpringParam::RotationalDamping => format!("arm[{a}].base.rotational_damping"),
                SpringParam::Inertia => format!("arm[{a}].base.inertia"),
                SpringParam::Follow(r, c) => {
                    format!(
                        "arm[{a}].base.follow_{}{}",
                        ["s", "v", "a"][r as usize],
                        c.name()
                    )
                }
            },
        }
    }

    /// A load that statics scales from 0 to 1 in its load continuation.
    pub fn is_load(self) -> bool {
        matches!(
            self,
            Self::Gravity(_) | Self::TipForce(_) | Self::TipMoment(_) | Self::Load(..)
        )
    }

    /// A parameter of a moving base: a variable of the kinematic time
    /// derivatives (its rate is the next derivative's parameter).
    pub fn moves_base(self) -> bool {
        matches!(self, Self::BaseTranslation(..) | Self::BaseTurn(..))
    }
}

/// A parameter an input channel drives, and how often the channel is
/// differentiated for it (a moving base's velocity and acceleration).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Driven {
    pub param: Param,
    pub derivative: u8,
}

/// The ordered parameters of one structure, with an index per parameter.
/// (The default is empty: what a link cell, whose parameters are its own,
/// may not read.)
#[derive(Clone, Debug, Default)]
pub struct ParamLayout {
    pub(super) params: Vec<Param>,
    pub(super) index: HashMap<Param, usize>,
    pub(super) driven: Vec<Driven>,
    /// An assembly's arms: name, first slot, own layout.
    pub(super) arms: Vec<(String, usize, ParamLayout)>,
    /// The layout of an assembly (`of_assembly`).
    pub(super) assembly: bool,
}

impl ParamLayout {
    /// The layout of `st`: gravity, base, base motion, tip, elements,
    /// actuators, torques.
    pub fn of(st: &Structure) -> Self {
        if let Some(a) = &st.assembly {
            return Self::of_assembly(a);
        }
        let spatial = st.dimensions == 3;
        let mut p = Vec::new();
        let mut driven = Vec::new();
        p.extend(Xyz::ALL.map(Param::Gravity));
        p.extend(Xyz::ALL.map(Param::BasePosition));
        if spatial {
            for i in 0..3 {
                p.extend((0..3).map(|j| Param::BaseRotation(i, j)));
            }
            p.extend((0..4).map(Param::BaseQuaternion));
        } else {
            p.push(Param::BaseAngle);
        }
        if st.base_translates {
            // In the plane the base moves in x and y; its z stays put.
            let moving = if spatial { 3 } else { 2 };
            for r in Rate::ALL {
                for c in Xyz::ALL {
                    let param = Param::BaseTranslation(r, c);
                    match c.index() < moving {
                        true => drive(&mut p, &mut driven, param, r.derivative()),
                        false => p.push(param),
                    }
                }
            }
        }
        for i in 0..st.base_turns {
            for r in Rate::ALL {
                drive(&mut p, &mut driven, Param::BaseTurn(r, i), r.derivative());
            }
            if spatial {
                p.extend(Xyz::ALL.map(|c| Param::BaseTurnAxis(i, c)));
            }
        }
        if st.tip_mass {
            p.push(Param::TipMass);
        }
        if st.tip_force {
            for c in Xyz::ALL {
                match st.tip_force_driven {
                    true => drive(&mut p, &mut driven, Param::TipForce(c), 0),
                    false => p.push(Param::TipForce(c)),
                }
            }
        }
        if st.tip_moment {
            for c in Xyz::ALL {
                match st.tip_moment_driven {
                    true => drive(&mut p, &mut driven, Param::TipMoment(c), 0),
                    false => p.push(Param::TipMoment(c)),
                }
            }
        }
        if st.tip_length {
            p.extend([Param::TipLength, Param::TipInertia, Param::TipAxialInertia]);
        }
        along_arm(st, &mut p, &mut driven);
        for (segment, &count) in st.chambers.iter().enumerate() {
            for position in 0..count {
                for what in ChamberParam::ALL {
                    let param = Param::Chamber {
                        segment,
                        position,
                        what,
                    };
                    match what {
                        ChamberParam::Pressure => drive(&mut p, &mut driven, param, 0),
                        _ => p.push(param),
                    }
                }
            }
        }
        let mut first = 0;
        for (g, &count) in st.segments.iter().zip(&st.chambers) {
            if g.chambers_vary {
                for element in first..first + g.elements {
                    for position in 0..count {
                        for z in [false, true] {
                            p.push(Param::ChamberArm {
                                element,
                                position,
                                z,
                            });
                        }
                    }
                }
            }
            first += g.elements;
        }
        for (tendon, &end) in st.tendons.iter().enumerate() {
            drive(&mut p, &mut driven, Param::TendonTension(tendon), 0);
            for segment in 0..=end {
                for z in [false, true] {
                    p.push(Param::TendonOffset { tendon, segment, z });
                }
            }
        }
        for i in 0..st.torques.len() {
            drive(&mut p, &mut driven, Param::Torque(i), 0);
        }
        // Drives in the order input channels are bound: base, tip, chambers,
        // tendons, torques (the layout's order).
        let index = p.iter().enumerate().map(|(i, &q)| (q, i)).collect();
        Self {
            params: p,
            index,
            driven,
            arms: Vec::new(),
            assembly: false,
        }
    }

    /// A kernel's own layout of just `keep`, in that order (a part's,
    /// which reads them as p0, p1, ... wherever the model keeps them), so
    /// that its tape does not change with the rest of the model.
    pub fn local(keep: &[Param]) -> Self {
        Self {
            params: keep.to_vec(),
            index: keep.iter().enumerate().map(|(i, &q)| (q, i)).collect(),
            ..Self::default()
        }
    }

    /// The slot of `p`. The generator asks only for parameters its
    /// structure has, so a miss is a generator bug.
    pub fn index(&self, p: Param) -> usize {
        match self.index.get(&p) {
            Some(&i) => i,
            None => panic!("parameter {} is not in the layout", p.name()),
        }
    }

    /// The slot of `p`, if the structure has it.
    pub fn get(&self, p: Param) -> Option<usize> {
        self.index.get(&p).copied()
    }

    pub fn len(&self) -> usize {
        self.params.len()
    }

    pub fn is_empty(&self) -> bool {
        self.params.is_empty()
    }

    /// The parameters in layout order.
    pub fn params(&self) -> &[Param] {
        &self.params
    }

    pub fn names(&self) -> Vec<String> {
        self.params.iter().map(|&p| self.name(p)).collect()
    }

    /// `p`'s name; an assembly arm's parameters by the arm's name.
    pub fn name(&self, p: Param) -> String {
        match p {
            Param::Scoped { arm, index } => {
                let (name, _, layout) = &self.arms[arm as usize];
                let inner = layout.params[index as usize].name();
                if name.is_empty() {
                    inner
                } else {
                    format!("{name}.{inner}")
                }
            }
            p => p.name(),
        }
    }

    /// An assembly's arms: name, first slot, own layout (empty otherwise).
    pub fn arms(&self) -> &[(String, usize, ParamLayout)] {
        &self.arms
    }

    /// An assembly's layout (its arms' parameters scoped).
    pub fn is_assembly(&self) -> bool {
        self.assembly
    }

    /// The parameters input channels drive (never folded into derived
    /// parameters: they change during a run).
    pub fn driven(&self) -> &[Driven] {
        &self.driven
    }

    /// The slots of the loads (statics scales them).
    pub fn loads(&self) -> Vec<usize> {
        (0..self.params.len())
            .filter(|&i| match self.params[i] {
                Param::Scoped { arm, index } => {
                    self.arms[arm as usize].2.params[index as usize].is_load()
                }
                p => p.is_load(),
            })
            .collect()
    }
}

/// The input channel that drives `p` in model `m` (`None` for a parameter
/// no channel drives).
pub fn channel(m: &Model, p: Param) -> Option<&str> {
    let name = match p {
        Param::BaseTranslation(_, c) => m.base.translation_inputs.as_ref()?.get(c.index()),
        Param::BaseTurn(_, i) => m.base.rotation_inputs.as_ref()?.get(i),
        Param::TipForce(c) => m.tip.force_inputs.as_ref()?.get(c.index()),
        Param::TipMoment(c) => m.tip.moment_inputs.as_ref()?.get(c.index()),
        Param::Chamber {
            segment,
            position,
            what: ChamberParam::Pressure,
        } => m.segments[segment]
            .chambers
            .as_ref()?
            .inputs
            .as_ref()?
            .get(position),
        Param::TendonTension(i) => Some(&m.tendons[i].input),
        Param::Load(i, LoadParam::Force(c)) => m.loads[i].force_inputs.as_ref()?.get(c.index()),
        Param::Load(i, LoadParam::Moment(c)) => m.loads[i].moment_inputs.as_ref()?.get(c.index()),
        Param::Torque(i) => Some(&m.torques[i].input),
        _ => None,
    };
    name.map(String::as_str)
}

/// A driven chamber position's pressure (0: its input sets it) and lever:
/// the holes' total area and first moments a sum(z), a sum(y) about the
/// section's centroid.
pub(crate) fn chamber_value(m: &Model, segment: usize, position: usize, what: ChamberParam) -> f64 {
    chamber_value_of(&m.segments[segment], position, what)
}

/// [`chamber_value`] of a segment (an element's: `Segment::at`).
pub(crate) fn chamber_value_of(seg: &Segment, position: usize, what: ChamberParam) -> f64 {
    let c = seg
        .chambers
        .as_ref()
        .expect("the structure has this segment's chambers");
    let a = c.hole_area(position);
    let angle = c.positions()[position];
    let holes: Vec<f64> = match c.pair_spacing {
        Some(spacing) => vec![angle - spacing, angle + spacing],
        None => vec![angle],
    };
    let (y, z) = holes.iter().fold((0.0, 0.0), |(y, z), h| {
        let h = h.to_radians();
        (y + c.offset() * h.cos(), z + c.offset() * h.sin())
    });
    // Levers about the centroid, through which the centreline runs.
    let n = holes.len() as f64;
    let [yc, zc] = seg.centroid();
    match what {
        ChamberParam::Pressure => 0.0,
        ChamberParam::Area => a * n,
        ChamberParam::ArmY => a * (z - n * zc),
        ChamberParam::ArmZ => a * (y - n * yc),
    }
}

/// The axis of base turn i: as declared, else z, y, x in turn.
pub fn base_turn_axis(m: &Model, i: usize) -> [f64; 3] {
    const DEFAULT: [[f64; 3]; 3] = [[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]];
    m.base
        .rotation_axes
        .as_ref()
        .and_then(|a| a.get(i).copied())
        .unwrap_or(DEFAULT[i % 3])
}

/// The quaternion (w, x, y, z) of [`base_rotation`]: (1 + c, x × u)
/// normalised, with c = x . u.
pub fn base_quaternion(d: [f64; 3]) -> [f64; 4] {
    let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    let u = [d[0] / n, d[1] / n, d[2] / n];
    let c = u[0];
    if c < -1.0 + 1e-12 {
        return [0.0, 0.0, 0.0, 1.0];
    }
    let s = (2.0 * (1.0 + c)).sqrt();
    [(1.0 + c) / s, 0.0, -u[2] / s, u[1] / s]
}

/// The rotation (rows) taking +x to the unit vector along `d` by the
/// shortest turn; a half turn about z when `d` points along -x.
pub fn base_rotation(d: [f64; 3]) -> [[f64; 3]; 3] {
    let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    let u = [d[0] / n, d[1] / n, d[2] / n];
    let c = u[0];
    if c < -1.0 + 1e-12 {
        return [[-1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0]];
    }
    // v = x × u = (0, -u_z, u_y); R = I + [v]x + [v]x^2 / (1 + c)
    let v = [0.0, -u[2], u[1]];
    let k = [[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]];
    let mut r = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            let k2: f64 = (0..3).map(|m| k[i][m] * k[m][j]).sum();
            r[i][j] = f64::from(u8::from(i == j)) + k[i][j] + k2 / (1.0 + c);
        }
    }
    r
}

/// A driven parameter: in the layout, and an input sets it.
fn drive(p: &mut Vec<Param>, driven: &mut Vec<Driven>, param: Param, derivative: u8) {
    driven.push(Driven { param, derivative });
    p.push(param);
}

/// What lies along a single arm: each element's parameters (a 3D rest
/// shape's and an immersed arm's too), the fluid's, the loads' and the
/// kinks'.
fn along_arm(st: &Structure, p: &mut Vec<Param>, driven: &mut Vec<Driven>) {
    let spatial = st.dimensions == 3;
    let mut k = 0;
    for g in &st.segments {
        for _ in 0..g.elements {
            p.extend(ElementParam::PLANAR.map(|e| Param::Element(k, e)));
            if spatial {
                p.extend(ElementParam::SPATIAL.map(|e| Param::Element(k, e)));
            }
            if g.rest_3d {
                p.extend(ElementParam::REST_3D.map(|e| Param::Element(k, e)));
            }
            if g.anisotropic {
                p.extend(ElementParam::ANISOTROPIC.map(|e| Param::Element(k, e)));
            }
            if st.fluid.is_some() {
                p.extend([ElementParam::Volume, ElementParam::Width].map(|e| Param::Element(k, e)));
            }
            k += 1;
        }
    }
    if st.fluid.is_some() {
        p.extend(
            [
                FluidParam::Density,
                FluidParam::DragNormal,
                FluidParam::DragTangential,
            ]
            .map(Param::Fluid),
        );
        p.extend(Xyz::ALL.map(|c| Param::Fluid(FluidParam::Current(c))));
    }
    for (i, l) in st.loads.iter().enumerate() {
        for (given, by_input, what) in [
            (
                l.force,
                l.force_driven,
                LoadParam::Force as fn(Xyz) -> LoadParam,
            ),
            (l.moment, l.moment_driven, LoadParam::Moment),
        ] {
            for c in Xyz::ALL.iter().filter(|_| given) {
                match by_input {
                    true => drive(p, driven, Param::Load(i, what(*c)), 0),
                    false => p.push(Param::Load(i, what(*c))),
                }
            }
        }
    }
    for (s, g) in st.segments.iter().enumerate() {
        if g.kink {
            let turns = if spatial { 2 } else { 1 };
            p.extend((0..turns).map(|i| Param::Kink(s, KinkParam::Turn(i))));
            p.extend(Xyz::ALL.map(|c| Param::Kink(s, KinkParam::Offset(c))));
        }
    }
}

//! An assembly as one TMT system: every arm's kinematics built as a single
//! arm's, in its own scope of coordinates and parameters (`Cas::scoped`),
//! the free bodies and compliant bases with coordinates of their own, and
//! the joints as constraint equations phi(q) = 0 on the frames they name
//! (docs/design.md section 7).
//!
//! Invariant: the coordinates are the arms' in declaration order (each
//! preceded by its compliant base's x, y (, z) and, when it turns, its
//! `base_angle` (plane) or rotation vector `base_rx, base_ry, base_rz`), then the free bodies' (x,
//! y and angle in the plane; x, y, z and a quaternion qw, qx, qy, qz in 3D);
//! every joint contributes its rows in declaration order, the point gap
//! (x, y (, z)), then a weld's angle gap (planar `angle`, 3D `rx, ry, rz`),
//! and last each free 3D body its quaternion's unit norm (`unit`).

use std::collections::HashMap;
use std::ops::Range;

use runtime::links::frame;

use crate::cas::{Cas, ExprId, Scope, SymKind};
use crate::model::assembly::{FrameRef, JointKind};
use crate::model::{
    AssemblyShape, BodyParam, JointParam, JointShape, Param, ParamLayout, Rate, SpringParam, Xyz,
};

use crate::tmt::system::{
    Body, Coordinates, Inertia, MountFrame, ParamSymbols, PointForce, Sample, System,
};

/// The assembled system and its constraint equations.
pub struct Assembled {
    pub sys: System,
    /// phi(q) = 0, rows as the module's invariant orders them.
    pub constraints: Vec<ExprId>,
    /// Their names: `JOINT.x`, `JOINT.angle`, `JOINT.rx`, `BODY.unit`, ...
    pub rows: Vec<String>,
    /// The same rows with the arms' frames they hold as variables.
    pub on_frames: FrameRows,
    /// Coordinates per independent subsystem (an arm with its compliant
    /// base, a free body), in order: M is block diagonal over them.
    pub blocks: Vec<usize>,
    /// Where each arm's own system sits in the assembly's.
    pub arms: Vec<ArmBlock>,
    /// The system without the arms' own terms (their links, springs,
    /// dampers, actuators, loads and contact points): the bodies, the
    /// compliant bases and whatever joins the arms. The assembly's M, h and their tangent are
    /// this system's plus each arm's, in its block.
    pub rest: System,
}

/// The joints' rows on the arms' frames they hold (an arm's tip or
/// segment end), each frame's variables (`runtime::links::frame`: origin,
/// planar angle, quaternion) symbols of the rows kernel's `aux`, with
/// their rates and their accelerations at qdd = 0 after them
/// (`runtime::joints`).
#[derive(Default)]
pub struct FrameRows {
    /// The held frames, in `aux` order.
    pub frames: Vec<FrameRef>,
    /// Each frame's variables.
    pub vars: Vec<[ExprId; frame::VARS]>,
    /// (x, x') and (x', x''): the time derivatives of the frame symbols.
    pub pairs: Vec<(ExprId, ExprId)>,
    pub rows: Vec<ExprId>,
}

impl FrameRows {
    /// Frame `f`'s pose of symbols, made on its first use.
    fn pose(&mut self, cas: &mut Cas, f: FrameRef) -> Pose {
        let k = match self.frames.iter().position(|&g| g == f) {
            Some(k) => k,
            None => {
                let k = self.frames.len();
                let sym = |cas: &mut Cas, i: usize| {
                    let at = k * frame::STATE + i;
                    cas.symbol(&format!("frame{k}.{i}"), SymKind::Aux(at as u32))
                };
                let x: [ExprId; frame::VARS] = std::array::from_fn(|i| sym(cas, i));
                let rate: [ExprId; frame::VARS] =
                    std::array::from_fn(|i| sym(cas, frame::RATE + i));
                let accel: [ExprId; frame::VARS] =
                    std::array::from_fn(|i| sym(cas, frame::ACCEL + i));
                for i in 0..frame::VARS {
                    self.pairs.push((x[i], rate[i]));
                    self.pairs.push((rate[i], accel[i]));
                }
                self.frames.push(f);
                self.vars.push(x);
                k
            }
        };
        let x = self.vars[k];
        Pose {
            point: [x[frame::POINT], x[frame::POINT + 1], x[frame::POINT + 2]],
            angle: x[frame::ANGLE],
            quat: std::array::from_fn(|i| x[frame::QUAT + i]),
        }
    }
}

/// An arm's place in the assembly: its coordinates `first..first + dof`
/// (after its compliant base's, if any) and its parameters from `params`
/// on, in its own layout's order.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ArmBlock {
    pub first: usize,
    pub dof: usize,
    pub params: usize,
}

/// The entries one arm's own system added to each of the builder's lists.
#[derive(Clone)]
struct ArmEntries {
    bodies: Range<usize>,
    elastic: Range<usize>,
    rayleigh: Range<usize>,
    actuation: Range<usize>,
    point_forces: Range<usize>,
    moments: Range<usize>,
    samples: Range<usize>,
}

/// `all` without the entries of every arm (`range` picks the list's).
fn without_arms<T: Clone>(
    all: &[T],
    arms: &[ArmEntries],
    range: impl Fn(&ArmEntries) -> &Range<usize>,
) -> Vec<T> {
    (all.iter().enumerate())
        .filter(|(i, _)| !arms.iter().any(|a| range(a).contains(i)))
        .map(|(_, x)| x.clone())
        .collect()
}

/// A compliant base's coordinates: its displacement, and its turn (a
/// rotation vector, with the base's inertia and angular velocity) when it
/// turns.
struct Sway {
    offset: [ExprId; 3],
    /// Its coordinates' (q, qd) pairs: what moves the arm's points besides
    /// the arm's own coordinates (drag sees them).
    seeds: Vec<(ExprId, ExprId)>,
    twist: Option<([ExprId; 3], [ExprId; 3])>,
    inertia: Option<ExprId>,
    omega: Option<[ExprId; 3]>,
}

/// A frame a joint may hold: its origin, and its orientation as a planar
/// angle (the plane) or a unit quaternion w, x, y, z (3D).
#[derive(Clone, Copy)]
struct Pose {
    point: [ExprId; 3],
    angle: ExprId,
    quat: [ExprId; 4],
}

/// An arm's frames for joints: its segment ends and its tip.
struct ArmFrames {
    segment_ends: Vec<Pose>,
    tip: Pose,
    /// Each segment end's whole frame (the last the tip's), for arms that
    /// sit on it.
    end_frames: Vec<MountFrame>,
}

impl ArmFrames {
    /// The frame `f` (this arm's tip or segment end) names.
    fn mount(&self, f: FrameRef) -> Option<MountFrame> {
        match f {
            FrameRef::Tip(_) => self.end_frames.last().copied(),
            FrameRef::SegmentEnd { segment, .. } => self.end_frames.get(segment).copied(),
            _ => None,
        }
    }
}

/// The system of an assembly structure.
pub fn assembly_system(cas: &mut Cas, a: &AssemblyShape, layout: &ParamLayout) -> Assembled {
    let mut b = Builder::new(cas, layout, a.dimensions == 3);
    let mut tips = Vec::new();
    let mut arm_frames = Vec::new();
    // Bodies that carry arms come first (their coordinates too), the rest
    // after the arms, as an assembly without carriers has always had them.
    let carries = |k: usize| a.mounts.contains(&Some(FrameRef::Body(k)));
    let mut body_frames: Vec<Option<(Pose, MountFrame)>> = vec![None; a.bodies.len()];
    for (k, (name, free)) in a.bodies.iter().enumerate() {
        if carries(k) {
            let (pose, omega) = b.body(cas, k, name, *free);
            body_frames[k] = Some((pose, b.carrier(cas, pose, omega)));
        }
    }
    for (k, ((name, st), (_, offset, arm_layout))) in a.arms.iter().zip(layout.arms()).enumerate() {
        // An arm on an earlier arm's frame (validated: a chain's) or on a
        // body.
        let mount = a.mounts.get(k).copied().flatten().and_then(|f| match f {
            FrameRef::Tip(j) | FrameRef::SegmentEnd { arm: j, .. } => {
                arm_frames.get(j).and_then(|p: &ArmFrames| p.mount(f))
            }
            FrameRef::Body(j) => body_frames[j].map(|(_, m)| m),
            FrameRef::World => None,
        });
        let frames = b.arm(cas, k, name, st, (*offset, arm_layout), mount);
        tips.push((frames.tip.point, frames.tip.quat));
        arm_frames.push(frames);
    }
    let body_frames: Vec<Pose> = (a.bodies.iter().enumerate())
        .map(|(k, (name, free))| match body_frames[k] {
            Some((pose, _)) => pose,
            None => b.body(cas, k, name, *free).0,
        })
        .collect();
    if a.contact {
        let spatial = b.spatial;
        for f in &body_frames {
            let sample = match spatial {
                true => Sample::spatial(f.point, f.quat),
                false => Sample::planar(cas, f.point, f.angle),
            };
            b.samples.push(sample);
        }
    }
    let frame = |f: FrameRef| match f {
        FrameRef::World => b.world,
        FrameRef::Body(k) => body_frames[k],
        FrameRef::Tip(arm) => arm_frames[arm].tip,
        FrameRef::SegmentEnd { arm, segment } => arm_frames[arm].segment_ends[segment],
    };
    let frames: Vec<(Pose, Pose)> = a.joints.iter().map(|j| (frame(j.a), frame(j.b))).collect();
    // The same rows on the arms' frames as variables of their own.
    let mut on_frames = FrameRows::default();
    let mut held = |cas: &mut Cas, f: FrameRef| match f {
        FrameRef::Tip(_) | FrameRef::SegmentEnd { .. } => on_frames.pose(cas, f),
        _ => frame(f),
    };
    let held: Vec<(Pose, Pose)> = (a.joints.iter())
        .map(|j| (held(cas, j.a), held(cas, j.b)))
        .collect();
    for (k, (joint, ((fa, fb), (ha, hb)))) in a
        .joints
        .iter()
        .zip(frames.into_iter().zip(held))
        .enumerate()
    {
        for (row, name) in b.joint(cas, k, joint, fa, fb) {
            b.constraints.push(row);
            b.rows.push(name);
        }
        on_frames
            .rows
            .extend(b.joint(cas, k, joint, ha, hb).into_iter().map(|r| r.0));
    }
    let units = std::mem::take(&mut b.units);
    for (name, q) in units {
        let sq: Vec<ExprId> = q.iter().map(|&c| cas.powi(c, 2)).collect();
        let norm = cas.add_all(&sq);
        let one = cas.one();
        let gap = cas.sub(norm, one);
        let row = cas.scaled(0.5, gap);
        b.constraints.push(row);
        on_frames.rows.push(row);
        b.rows.push(format!("{name}.unit"));
    }
    b.on_frames = on_frames;
    let zero = cas.zero();
    let (tip, tip_orientation) = tips
        .first()
        .copied()
        .unwrap_or(([zero; 3], [cas.one(), zero, zero, zero]));
    b.finish(cas, tip, tip_orientation)
}

/// What the assembly has gathered so far.
struct Builder {
    own: HashMap<Param, ExprId>,
    spatial: bool,
    zero: ExprId,
    world: Pose,
    names: Vec<String>,
    q: Vec<ExprId>,
    qd: Vec<ExprId>,
    qdd: Vec<ExprId>,
    bodies: Vec<Body>,
    elastic: Vec<ExprId>,
    rayleigh: Vec<ExprId>,
    actuation: Vec<ExprId>,
    point_forces: Vec<PointForce>,
    moments: Vec<crate::tmt::system::AppliedMoment>,
    seeds: Vec<(ExprId, ExprId)>,
    blocks: Vec<usize>,
    constraints: Vec<ExprId>,
    rows: Vec<String>,
    /// Free 3D bodies' quaternions, held to unit norm by the last rows.
    units: Vec<(String, [ExprId; 4])>,
    on_frames: FrameRows,
    /// Contact points: the arms' samples, then the bodies' centres.
    samples: Vec<Sample>,
    /// The arms' base frames.
    bases: Vec<Sample>,
    arm_blocks: Vec<ArmBlock>,
    arm_entries: Vec<ArmEntries>,
}

impl Builder {
    /// The assembly's own parameters (gravity, bodies, joints, bases) as
    /// symbols; the arms' come through their scoped `ParamSymbols`.
    fn new(cas: &mut Cas, layout: &ParamLayout, spatial: bool) -> Self {
        let mut own = HashMap::new();
        for (i, &p) in layout.params().iter().enumerate() {
            if !matches!(p, Param::Scoped { .. }) {
                own.insert(p, cas.symbol(&layout.name(p), SymKind::Param(i as u32)));
            }
        }
        let (zero, one) = (cas.zero(), cas.one());
        Self {
            own,
            spatial,
            zero,
            world: Pose {
                point: [zero; 3],
                angle: zero,
                quat: [one, zero, zero, zero],
            },
            names: Vec::new(),
            q: Vec::new(),
            qd: Vec::new(),
            qdd: Vec::new(),
            bodies: Vec::new(),
            elastic: Vec::new(),
            rayleigh: Vec::new(),
            actuation: Vec::new(),
            point_forces: Vec::new(),
            moments: Vec::new(),
            seeds: Vec::new(),
            blocks: Vec::new(),
            constraints: Vec::new(),
            rows: Vec::new(),
            units: Vec::new(),
            on_frames: FrameRows::default(),
            samples: Vec::new(),
            bases: Vec::new(),
            arm_blocks: Vec::new(),
            arm_entries: Vec::new(),
        }
    }

    fn get(&self, p: Param) -> ExprId {
        self.own[&p]
    }

    /// A coordinate at the next index: (q, qd).
    fn coordinate(&mut self, cas: &mut Cas, name: String) -> (ExprId, ExprId) {
        let i = self.names.len() as u32;
        let q = cas.symbol(&name, SymKind::Q(i));
        let qd = cas.symbol(&format!("{name}_dot"), SymKind::Qd(i));
        let qdd = cas.symbol(&format!("{name}_ddot"), SymKind::Qdd(i));
        self.names.push(name);
        self.q.push(q);
        self.qd.push(qd);
        self.qdd.push(qdd);
        (q, qd)
    }

    /// Arm k built in its scope, and its frames for joints.
    fn arm(
        &mut self,
        cas: &mut Cas,
        k: usize,
        name: &str,
        st: &crate::model::Structure,
        (offset, arm_layout): (usize, &ParamLayout),
        mount: Option<MountFrame>,
    ) -> ArmFrames {
        let prefix = if name.is_empty() {
            String::new()
        } else {
            format!("{name}.")
        };
        let first = self.names.len();
        let base = st
            .base_compliant
            .then(|| self.compliant_base(cas, k, &prefix, st.base_twists));
        let scope = Scope {
            prefix: prefix.clone(),
            coordinates: self.names.len() as u32,
            parameters: offset as u32,
        };
        let base_mass = self
            .own
            .get(&Param::BaseSpring(k as u16, SpringParam::Mass));
        let (zero, mut bodies) = (self.zero, Vec::new());
        let sys = cas.scoped(scope, |cas| {
            let mut symbols = ParamSymbols::new(cas, arm_layout);
            if let Some(m) = mount {
                symbols = symbols.with_mount(m);
            }
            if let (Some(base), Some(&mass)) = (&base, base_mass) {
                symbols = symbols.with_base_offset(base.offset, &base.seeds);
                if let Some((rho, rate)) = base.twist {
                    symbols = symbols.with_base_twist(rho, rate);
                }
                bodies.push(Body {
                    mass,
                    inertia: Inertia::Isotropic(base.inertia.unwrap_or(zero)),
                    position: symbols.base_motion(cas).position,
                    omega: base.omega.unwrap_or([zero; 3]),
                });
            }
            super::arm_system(cas, st, &symbols)
        });
        self.arm_blocks.push(ArmBlock {
            first: self.names.len(),
            dof: sys.coords.len(),
            params: offset,
        });
        self.names
            .extend(sys.coords.names.iter().map(|n| format!("{prefix}{n}")));
        self.q.extend(&sys.coords.q);
        self.qd.extend(&sys.coords.qd);
        self.qdd.extend(&sys.coords.qdd);
        self.blocks.push(self.names.len() - first);
        self.bodies.extend(bodies);
        let start = |v: usize| v..v;
        let mut own = ArmEntries {
            bodies: start(self.bodies.len()),
            elastic: start(self.elastic.len()),
            rayleigh: start(self.rayleigh.len()),
            actuation: start(self.actuation.len()),
            point_forces: start(self.point_forces.len()),
            moments: start(self.moments.len()),
            samples: start(self.samples.len()),
        };
        self.bodies.extend(sys.bodies);
        self.elastic.push(sys.elastic);
        self.rayleigh.push(sys.rayleigh);
        self.actuation.push(sys.actuation);
        self.point_forces.extend(sys.point_forces);
        own.bodies.end = self.bodies.len();
        own.elastic.end = self.elastic.len();
        own.rayleigh.end = self.rayleigh.len();
        own.actuation.end = self.actuation.len();
        own.point_forces.end = self.point_forces.len();
        self.samples.extend(sys.samples.iter().copied());
        own.samples.end = self.samples.len();
        self.bases.extend(sys.bases.iter().copied());
        self.moments.extend(sys.moments);
        own.moments.end = self.moments.len();
        self.arm_entries.push(own);
        self.seeds.extend(sys.seeds);
        match sys.planar {
            Some(planar) => {
                let pose = |p: crate::tmt::system::PlanarPose| Pose {
                    point: p.point,
                    angle: p.angle,
                    quat: [zero; 4],
                };
                ArmFrames {
                    end_frames: sys.end_frames,
                    segment_ends: planar.segment_ends.into_iter().map(pose).collect(),
                    tip: Pose {
                        point: sys.tip,
                        quat: sys.tip_orientation,
                        ..pose(planar.tip)
                    },
                }
            }
            None => {
                let pose = |(point, quat)| Pose {
                    point,
                    angle: zero,
                    quat,
                };
                ArmFrames {
                    segment_ends: sys.segment_ends.into_iter().map(pose).collect(),
                    tip: pose((sys.tip, sys.tip_orientation)),
                    end_frames: sys.end_frames,
                }
            }
        }
    }

    /// A compliant base's coordinates (its displacement, then its turn),
    /// with its springs and dampers to the driven point.
    fn compliant_base(&mut self, cas: &mut Cas, k: usize, prefix: &str, twists: bool) -> Sway {
        let spring = |w| Param::BaseSpring(k as u16, w);
        let axes = if self.spatial { 3 } else { 2 };
        let mut offset = [self.zero; 3];
        let mut seeds = Vec::new();
        for (c, axis) in Xyz::ALL.iter().take(axes).enumerate() {
            let (s, v) = self.coordinate(cas, format!("{prefix}base_{}", ["x", "y", "z"][c]));
            seeds.push((s, v));
            offset[c] = s;
            let gap = cas.sub(s, self.get(spring(SpringParam::Follow(Rate::Value, *axis))));
            let k_s = self.get(spring(SpringParam::Stiffness));
            self.elastic.push(half_k_sq(cas, k_s, gap));
            let slip = cas.sub(v, self.get(spring(SpringParam::Follow(Rate::First, *axis))));
            let c_s = self.get(spring(SpringParam::Damping));
            self.rayleigh.push(half_k_sq(cas, c_s, slip));
        }
        let mut sway = Sway {
            offset,
            seeds,
            twist: None,
            inertia: None,
            omega: None,
        };
        if twists {
            self.base_twist(cas, k, prefix, &mut sway);
        }
        sway
    }

    /// A compliant base's turn: a rotation vector from the driven
    /// orientation (about z alone in the plane) on a spring of energy
    /// k |rho|^2 / 2 (the geodesic angle's) and a damper on the angular
    /// velocity it makes, c |w|^2 / 2.
    fn base_twist(&mut self, cas: &mut Cas, k: usize, prefix: &str, sway: &mut Sway) {
        let spring = |w| self.get(Param::BaseSpring(k as u16, w));
        let (k_r, c_r) = (
            spring(SpringParam::RotationalStiffness),
            spring(SpringParam::RotationalDamping),
        );
        sway.inertia = Some(spring(SpringParam::Inertia));
        let zero = self.zero;
        let (mut rho, mut rate) = ([zero; 3], [zero; 3]);
        let axes: &[usize] = if self.spatial { &[0, 1, 2] } else { &[2] };
        for &c in axes {
            let name = if self.spatial {
                format!("{prefix}base_r{}", ["x", "y", "z"][c])
            } else {
                format!("{prefix}base_angle")
            };
            (rho[c], rate[c]) = self.coordinate(cas, name);
            sway.seeds.push((rho[c], rate[c]));
        }
        let omega = if self.spatial {
            crate::tmt::spatial::exp_turn(cas, &rho, &rate).2
        } else {
            rate
        };
        for c in 0..3 {
            let e = half_k_sq(cas, k_r, rho[c]);
            self.elastic.push(e);
            let r = half_k_sq(cas, c_r, omega[c]);
            self.rayleigh.push(r);
        }
        sway.twist = Some((rho, rate));
        sway.omega = Some(omega);
    }

    /// Body k: free (coordinates of its own) or fixed (parameters).
    /// Body k's frame for joints, and its angular velocity.
    fn body(&mut self, cas: &mut Cas, k: usize, name: &str, free: bool) -> (Pose, [ExprId; 3]) {
        let p = |w| Param::Body(k as u16, w);
        let zero = self.zero;
        if !free {
            let pose = Pose {
                point: Xyz::ALL.map(|c| self.get(p(BodyParam::Position(c)))),
                angle: self.get(p(BodyParam::Angle)),
                quat: if self.spatial {
                    [0, 1, 2, 3].map(|i| self.get(p(BodyParam::Quaternion(i))))
                } else {
                    [zero; 4]
                },
            };
            return (pose, [zero; 3]);
        }
        let first = self.names.len();
        let mass = self.get(p(BodyParam::Mass));
        let (pose, omega) = if self.spatial {
            let point = ["x", "y", "z"].map(|c| self.coordinate(cas, format!("{name}.{c}")).0);
            let both =
                ["qw", "qx", "qy", "qz"].map(|c| self.coordinate(cas, format!("{name}.{c}")));
            let (quat, rate) = (both.map(|b| b.0), both.map(|b| b.1));
            let moments = Xyz::ALL.map(|c| self.get(p(BodyParam::Moment(c))));
            let omega = self.spatial_body(cas, mass, point, quat, rate, moments);
            self.units.push((name.to_string(), quat));
            let pose = Pose {
                point,
                angle: zero,
                quat,
            };
            (pose, omega)
        } else {
            let (x, _) = self.coordinate(cas, format!("{name}.x"));
            let (y, _) = self.coordinate(cas, format!("{name}.y"));
            let (angle, rate) = self.coordinate(cas, format!("{name}.angle"));
            let point = [x, y, self.get(p(BodyParam::Position(Xyz::Z)))];
            let omega = [zero, zero, rate];
            self.bodies.push(Body {
                mass,
                inertia: Inertia::Isotropic(self.get(p(BodyParam::Inertia))),
                position: point,
                omega,
            });
            let pose = Pose {
                point,
                angle,
                quat: [zero; 4],
            };
            (pose, omega)
        };
        self.blocks.push(self.names.len() - first);
        (pose, omega)
    }

    /// A body's frame as an arm sits on it: its pose and angular velocity.
    fn carrier(&self, cas: &mut Cas, pose: Pose, omega: [ExprId; 3]) -> MountFrame {
        if !self.spatial {
            return MountFrame::Planar {
                p: pose.point,
                angle: pose.angle,
                w: omega[2],
            };
        }
        let zero = self.zero;
        let columns = [0, 1, 2].map(|k| {
            let mut e = [zero; 3];
            e[k] = cas.one();
            rotate(cas, pose.quat, e)
        });
        MountFrame::Spatial {
            r: std::array::from_fn(|i| std::array::from_fn(|j| columns[j][i])),
            p: pose.point,
            w: omega,
            quat: pose.quat,
        }
    }

    /// A free 3D body on quaternion coordinates: world angular velocity
    /// w = 2 (qw u' - qw' u + u x u') (u the vector part), its principal
    /// axes turned by the quaternion. Four coordinates for three freedoms
    /// leave M singular along q itself; a kinetic term c (q . q')^2 / 2,
    /// zero on the unit sphere the `unit` row holds q to, makes it
    /// positive definite without changing the motion.
    fn spatial_body(
        &mut self,
        cas: &mut Cas,
        mass: ExprId,
        point: [ExprId; 3],
        quat: [ExprId; 4],
        rate: [ExprId; 4],
        moments: [ExprId; 3],
    ) -> [ExprId; 3] {
        let zero = self.zero;
        let (u, du) = ([quat[1], quat[2], quat[3]], [rate[1], rate[2], rate[3]]);
        let cross = cas.cross(&u, &du);
        let omega: [ExprId; 3] = std::array::from_fn(|c| {
            let a = cas.mul(quat[0], du[c]);
            let b = cas.mul(rate[0], u[c]);
            let d = cas.sub(a, b);
            let s = cas.add(d, cross[c]);
            let s = cas.scaled(2.0, s);
            cas.bind(s)
        });
        let axes = [0, 1, 2].map(|k| {
            let mut e = [zero; 3];
            e[k] = cas.one();
            rotate(cas, quat, e).map(|c| cas.bind(c))
        });
        self.bodies.push(Body {
            mass,
            inertia: Inertia::Principal { axes, moments },
            position: point,
            omega,
        });
        let sum = cas.add_all(&moments);
        let c = cas.scaled(4.0 / 3.0, sum);
        let radial = cas.dot(&quat, &rate);
        self.bodies.push(Body {
            mass: zero,
            inertia: Inertia::Isotropic(c),
            position: [zero; 3],
            omega: [radial, zero, zero],
        });
        omega
    }

    /// Joint k's rows: the gap between its two points, then a weld's angle
    /// (planar) or rotation (3D, 2 vec(q_b conj(q_a q_offset)): the world
    /// rotation from a's turned frame to b's, to first order).
    fn joint(
        &self,
        cas: &mut Cas,
        k: usize,
        joint: &JointShape,
        fa: Pose,
        fb: Pose,
    ) -> Vec<(ExprId, String)> {
        let mut rows = Vec::new();
        let p = |w| Param::Joint(k as u16, w);
        let off_a = Xyz::ALL.map(|c| self.get(p(JointParam::OffsetA(c))));
        let off_b = Xyz::ALL.map(|c| self.get(p(JointParam::OffsetB(c))));
        let axes = if self.spatial { 3 } else { 2 };
        let (pa, pb) = if self.spatial {
            (point_at(cas, &fa, off_a), point_at(cas, &fb, off_b))
        } else {
            (planar_point(cas, &fa, off_a), planar_point(cas, &fb, off_b))
        };
        for c in 0..axes {
            let name = format!("{}.{}", joint.name, ["x", "y", "z"][c]);
            rows.push((cas.sub(pa[c], pb[c]), name));
        }
        if joint.kind != JointKind::Weld {
            return rows;
        }
        if !self.spatial {
            let turned = cas.add(fa.angle, self.get(p(JointParam::Angle)));
            rows.push((cas.sub(fb.angle, turned), format!("{}.angle", joint.name)));
            return rows;
        }
        let offset = [0, 1, 2, 3].map(|i| self.get(p(JointParam::Quaternion(i))));
        let target = quat_mul(cas, fa.quat, offset);
        let conj = [
            target[0],
            cas.neg(target[1]),
            cas.neg(target[2]),
            cas.neg(target[3]),
        ];
        let rel = quat_mul(cas, fb.quat, conj);
        for (c, name) in ["rx", "ry", "rz"].iter().enumerate() {
            rows.push((
                cas.scaled(2.0, rel[c + 1]),
                format!("{}.{name}", joint.name),
            ));
        }
        rows
    }

    fn finish(self, cas: &mut Cas, tip: [ExprId; 3], tip_orientation: [ExprId; 4]) -> Assembled {
        let gravity = Xyz::ALL.map(|c| self.get(Param::Gravity(c)));
        let rest = self.rest(cas, gravity);
        let sys = System {
            coords: Coordinates {
                names: self.names,
                q: self.q,
                qd: self.qd,
                qdd: self.qdd,
            },
            bodies: self.bodies,
            gravity,
            elastic: cas.add_all(&self.elastic),
            rayleigh: cas.add_all(&self.rayleigh),
            actuation: cas.add_all(&self.actuation),
            point_forces: self.point_forces,
            moments: self.moments,
            tip,
            tip_orientation,
            chain: None,
            seeds: self.seeds,
            planar: None,
            segment_ends: Vec::new(),
            end_frames: Vec::new(),
            samples: self.samples,
            bases: self.bases,
        };
        Assembled {
            sys,
            on_frames: self.on_frames,
            constraints: self.constraints,
            rows: self.rows,
            blocks: self.blocks,
            arms: self.arm_blocks,
            rest,
        }
    }

    /// The system without the arms' own entries (`Assembled::rest`).
    fn rest(&self, cas: &mut Cas, gravity: [ExprId; 3]) -> System {
        let arms = &self.arm_entries;
        let zero = self.zero;
        let sum = |cas: &mut Cas, all: &[ExprId], range: fn(&ArmEntries) -> &Range<usize>| {
            let kept = without_arms(all, arms, range);
            cas.add_all(&kept)
        };
        System {
            coords: Coordinates {
                names: self.names.clone(),
                q: self.q.clone(),
                qd: self.qd.clone(),
                qdd: self.qdd.clone(),
            },
            bodies: without_arms(&self.bodies, arms, |a| &a.bodies),
            gravity,
            elastic: sum(cas, &self.elastic, |a| &a.elastic),
            rayleigh: sum(cas, &self.rayleigh, |a| &a.rayleigh),
            actuation: sum(cas, &self.actuation, |a| &a.actuation),
            point_forces: without_arms(&self.point_forces, arms, |a| &a.point_forces),
            moments: without_arms(&self.moments, arms, |a| &a.moments),
            tip: [zero; 3],
            tip_orientation: [zero; 4],
            chain: None,
            seeds: self.seeds.clone(),
            planar: None,
            segment_ends: Vec::new(),
            end_frames: Vec::new(),
            // The points no arm has: the bodies' centres.
            samples: without_arms(&self.samples, arms, |a| &a.samples),
            bases: Vec::new(),
        }
    }
}

/// The point at `offset` (in the frame's own axes) of a planar frame.
fn planar_point(cas: &mut Cas, f: &Pose, offset: [ExprId; 3]) -> [ExprId; 3] {
    let (c, s) = (cas.cos(f.angle), cas.sin(f.angle));
    let x = {
        let a = cas.mul(c, offset[0]);
        let b = cas.mul(s, offset[1]);
        let d = cas.sub(a, b);
        cas.add(f.point[0], d)
    };
    let y = {
        let a = cas.mul(s, offset[0]);
        let b = cas.mul(c, offset[1]);
        let d = cas.add(a, b);
        cas.add(f.point[1], d)
    };
    [x, y, f.point[2]]
}

/// The point at `offset` (in the frame's own axes) of a 3D frame.
fn point_at(cas: &mut Cas, f: &Pose, offset: [ExprId; 3]) -> [ExprId; 3] {
    let turned = rotate(cas, f.quat, offset);
    std::array::from_fn(|c| cas.add(f.point[c], turned[c]))
}

/// v turned by the unit quaternion q: v + 2 w (u x v) + 2 u x (u x v).
fn rotate(cas: &mut Cas, q: [ExprId; 4], v: [ExprId; 3]) -> [ExprId; 3] {
    let u = [q[1], q[2], q[3]];
    let uv = cas.cross(&u, &v);
    let uuv = cas.cross(&u, &uv);
    std::array::from_fn(|c| {
        let a = cas.mul(q[0], uv[c]);
        let s = cas.add(a, uuv[c]);
        let s = cas.scaled(2.0, s);
        cas.add(v[c], s)
    })
}

/// The quaternion product a b (w, x, y, z).
fn quat_mul(cas: &mut Cas, a: [ExprId; 4], b: [ExprId; 4]) -> [ExprId; 4] {
    let (av, bv) = ([a[1], a[2], a[3]], [b[1], b[2], b[3]]);
    let dot = cas.dot(&av, &bv);
    let ww = cas.mul(a[0], b[0]);
    let w = cas.sub(ww, dot);
    let cross = cas.cross(&av, &bv);
    let v: [ExprId; 3] = std::array::from_fn(|c| {
        let x = cas.mul(a[0], bv[c]);
        let y = cas.mul(b[0], av[c]);
        cas.add_all(&[x, y, cross[c]])
    });
    [w, v[0], v[1], v[2]]
}

/// k x^2 / 2.
fn half_k_sq(cas: &mut Cas, k: ExprId, x: ExprId) -> ExprId {
    let sq = cas.mul(x, x);
    let e = cas.mul(k, sq);
    cas.scaled(0.5, e)
}

//! A mechanical system as the TMT method sees it: generalised coordinates,
//! lumped bodies, potentials, a Rayleigh function and applied forces, all as
//! CAS expressions. Kinematics modules build one; `assemble` derives the EOM.

use crate::cas::{Cas, ExprId, SymKind};
use crate::model::{ElementParam, Param, ParamLayout, Rate, Xyz};

pub use super::inertia::Inertia;

/// The parameter symbols of a structure, one per slot of its
/// [`ParamLayout`]: kinematics ask for a [`Param`], never a name.
pub struct ParamSymbols {
    layout: ParamLayout,
    ids: Vec<ExprId>,
    zero: ExprId,
    /// A compliant base's displacement: coordinates of the assembly.
    base_offset: Option<[ExprId; 3]>,
    base_seeds: Vec<(ExprId, ExprId)>,
    /// A compliant base's turn: a rotation vector and its rate.
    base_twist: Option<([ExprId; 3], [ExprId; 3])>,
    /// The frame the base sits on (another arm's), if any.
    mount: Option<MountFrame>,
}

impl ParamSymbols {
    pub fn new(cas: &mut Cas, layout: &ParamLayout) -> Self {
        let ids: Vec<ExprId> = layout
            .params()
            .iter()
            .enumerate()
            .map(|(i, p)| cas.symbol(&p.name(), SymKind::Param(i as u32)))
            .collect();
        for (p, &id) in layout.params().iter().zip(&ids) {
            if p.moves_base() {
                cas.set_moving(id);
            }
        }
        Self {
            layout: layout.clone(),
            ids,
            zero: cas.zero(),
            base_offset: None,
            base_seeds: Vec::new(),
            base_twist: None,
            mount: None,
        }
    }

    /// The base rides on coordinates (a compliant base of an assembly):
    /// its displacement from the declared position.
    /// A compliant base: its offset (coordinates) and the (coordinate,
    /// rate) pairs that move it, `seeds` of the base's motion.
    pub fn with_base_offset(mut self, offset: [ExprId; 3], seeds: &[(ExprId, ExprId)]) -> Self {
        self.base_offset = Some(offset);
        self.base_seeds = seeds.to_vec();
        self
    }

    /// The base turns on coordinates too: the rotation vector (about z
    /// alone in the plane) from the driven orientation, and its rate.
    pub fn with_base_twist(mut self, rho: [ExprId; 3], rate: [ExprId; 3]) -> Self {
        self.base_twist = Some((rho, rate));
        self
    }

    /// The base sits on `frame` (another arm's, in an assembly): its
    /// `position` and `direction` are in that frame.
    pub fn with_mount(mut self, frame: MountFrame) -> Self {
        self.mount = Some(frame);
        self
    }

    /// The frame the base sits on, if any.
    pub fn mount(&self) -> Option<MountFrame> {
        self.mount
    }

    /// The symbol of `p`; kinematics only ask for parameters their
    /// structure has, so a miss is a generator bug.
    pub fn get(&self, p: Param) -> ExprId {
        self.ids[self.layout.index(p)]
    }

    /// Element k's quantity `e`.
    pub fn element(&self, k: usize, e: ElementParam) -> ExprId {
        self.get(Param::Element(k, e))
    }

    /// The constant zero (what a parameter the structure lacks stands for).
    pub fn zero(&self) -> ExprId {
        self.zero
    }

    /// Element k's quantity `e` where its structure has it, else `or` (a
    /// 3D rest shape's strains: zero where the segment has none).
    pub fn element_or(&self, k: usize, e: ElementParam, or: ExprId) -> ExprId {
        (self.layout.get(Param::Element(k, e))).map_or(or, |i| self.ids[i])
    }

    /// A vector of three parameters.
    pub fn xyz(&self, p: impl Fn(Xyz) -> Param) -> [ExprId; 3] {
        Xyz::ALL.map(|c| self.get(p(c)))
    }

    /// The base's position and turn, moving when the model prescribes it.
    pub fn base_motion(&self, cas: &mut Cas) -> BaseMotion {
        let mut position = self.xyz(Param::BasePosition);
        let mut seeds = Vec::new();
        let chain = |seeds: &mut Vec<(ExprId, ExprId)>, [x, v, a]: [ExprId; 3]| {
            seeds.extend([(x, v), (v, a)]);
        };
        let translates = self
            .layout
            .get(Param::BaseTranslation(Rate::Value, Xyz::X))
            .is_some();
        if translates {
            for c in Xyz::ALL {
                let sva = Rate::ALL.map(|r| self.get(Param::BaseTranslation(r, c)));
                position[c.index()] = cas.add(position[c.index()], sva[0]);
                chain(&mut seeds, sva);
            }
        }
        if let Some(offset) = self.base_offset {
            for c in 0..3 {
                position[c] = cas.add(position[c], offset[c]);
            }
        }
        let mut turns = Vec::new();
        let turn = |i| Param::BaseTurn(Rate::Value, i);
        while self.layout.get(turn(turns.len())).is_some() {
            let i = turns.len();
            let t = Rate::ALL.map(|r| self.get(Param::BaseTurn(r, i)));
            chain(&mut seeds, t);
            turns.push((t[0], t[1]));
        }
        BaseMotion {
            position,
            turns,
            twist: self.base_twist,
            seeds,
            moved_by: self.base_seeds.clone(),
        }
    }

    /// The gravity vector.
    pub fn gravity(&self) -> [ExprId; 3] {
        self.xyz(Param::Gravity)
    }

    /// The base's declared rotation (rows: world from the base frame, the
    /// one that turns world +x onto `direction`).
    pub fn base_rotation(&self) -> [[ExprId; 3]; 3] {
        std::array::from_fn(|i| {
            std::array::from_fn(|j| self.get(Param::BaseRotation(i as u8, j as u8)))
        })
    }
}

/// Where the base is and how it moves: a prescribed displacement and turn
/// are parameters (inputs) whose rates are parameters too, so the time
/// derivatives of the kinematics see them through `seeds`.
pub struct BaseMotion {
    /// The declared position plus the displacement.
    pub position: [ExprId; 3],
    /// Turn angles and their rates, in sequence: about z (planar, one) or
    /// `base.axis[i]` (3D, each in the frame the turns before it left).
    pub turns: Vec<(ExprId, ExprId)>,
    /// A compliant base's rotation vector and its rate (coordinates), after
    /// the turns.
    pub twist: Option<([ExprId; 3], [ExprId; 3])>,
    /// (parameter, its rate) pairs for the kinematic time derivatives.
    pub seeds: Vec<(ExprId, ExprId)>,
    /// A compliant base's (coordinate, rate) pairs: an assembly's
    /// coordinates (its equations take their rates from its own list), which
    /// the arm's own velocities (drag) add to `seeds`.
    pub moved_by: Vec<(ExprId, ExprId)>,
}

/// q, qd symbols and their names.
#[derive(Clone)]
pub struct Coordinates {
    pub names: Vec<String>,
    pub q: Vec<ExprId>,
    pub qd: Vec<ExprId>,
    /// Accelerations (inputs of the `Jvp` kernel only).
    pub qdd: Vec<ExprId>,
}

impl Coordinates {
    pub fn new(cas: &mut Cas, names: Vec<String>) -> Self {
        let q = names
            .iter()
            .enumerate()
            .map(|(i, n)| cas.symbol(n, SymKind::Q(i as u32)))
            .collect();
        let qd = names
            .iter()
            .enumerate()
            .map(|(i, n)| cas.symbol(&format!("{n}_dot"), SymKind::Qd(i as u32)))
            .collect();
        let qdd = names
            .iter()
            .enumerate()
            .map(|(i, n)| cas.symbol(&format!("{n}_ddot"), SymKind::Qdd(i as u32)))
            .collect();
        Self { names, q, qd, qdd }
    }

    pub fn len(&self) -> usize {
        self.q.len()
    }

    pub fn is_empty(&self) -> bool {
        self.q.is_empty()
    }

    /// (q_i, qd_i) pairs: the time derivative with qdd = 0.
    pub fn rate_pairs(&self) -> Vec<(ExprId, ExprId)> {
        self.q
            .iter()
            .copied()
            .zip(self.qd.iter().copied())
            .collect()
    }
}

/// A lumped rigid body: Mbar = diag(m I3, J), all in the world frame.
#[derive(Clone)]
pub struct Body {
    pub mass: ExprId,
    /// Rotational inertia about the centre of mass.
    pub inertia: Inertia,
    /// Centre of mass in the world frame, a function of q.
    pub position: [ExprId; 3],
    /// Angular velocity in the world frame, linear in qd.
    pub omega: [ExprId; 3],
}

/// A world-frame force applied at a point (a function of q).
#[derive(Clone)]
pub struct PointForce {
    pub point: [ExprId; 3],
    pub force: [ExprId; 3],
}

/// A constant world-frame moment on a frame turning at `omega`.
#[derive(Clone)]
pub struct AppliedMoment {
    pub omega: [ExprId; 3],
    pub moment: [ExprId; 3],
}

/// A frame another arm may sit on. In 3D: rotation (rows), origin, world
/// angular velocity and orientation quaternion (w, x, y, z). In the plane:
/// origin, angle and its rate, as a planar arm's frames are.
#[derive(Clone, Copy, Debug)]
pub enum MountFrame {
    Spatial {
        r: [[ExprId; 3]; 3],
        p: [ExprId; 3],
        w: [ExprId; 3],
        quat: [ExprId; 4],
    },
    Planar {
        p: [ExprId; 3],
        angle: ExprId,
        w: ExprId,
    },
}

pub struct System {
    pub coords: Coordinates,
    pub bodies: Vec<Body>,
    pub gravity: [ExprId; 3],
    /// Elastic potential V_e(q).
    pub elastic: ExprId,
    /// Rayleigh dissipation function R(q, qd).
    pub rayleigh: ExprId,
    /// The actuators' potential V_a(q) = -(their virtual work's integral):
    /// generalised forces like V_e's, but not stored energy (not in the
    /// potential-energy output).
    pub actuation: ExprId,
    /// Constant (conservative) forces at points.
    pub point_forces: Vec<PointForce>,
    /// Constant moments on frames (no potential: not in the energy output).
    pub moments: Vec<AppliedMoment>,
    /// Tip position, an output.
    pub tip: [ExprId; 3],
    /// Tip frame's orientation (unit quaternion w, x, y, z), an output.
    pub tip_orientation: [ExprId; 4],
    /// Serial-chain structure, when the kinematics has it (M by composites).
    pub chain: Option<Chain>,
    /// Extra (parameter, rate) pairs of the kinematic time derivatives: a
    /// prescribed base motion.
    pub seeds: Vec<(ExprId, ExprId)>,
    /// Planar chains: the frames joints may hold (`None` in 3D).
    pub planar: Option<PlanarFrames>,
    /// 3D chains: each segment's end frame, origin and orientation (w, x,
    /// y, z), for joints (empty for a method that builds the whole arm).
    /// 3D chain arms: each segment end's whole frame (the last the tip's),
    /// which another arm may sit on.
    pub end_frames: Vec<MountFrame>,
    pub segment_ends: Vec<([ExprId; 3], [ExprId; 4])>,
    /// Points along the arm's centreline with their cross-section frames,
    /// element by element (`Structure::contact_points` each, the last at
    /// the element's end): contact reads the points, the shape both.
    pub samples: Vec<Sample>,
    /// The frame each arm's first element starts from (an arm's shape's
    /// first point), arm by arm.
    pub bases: Vec<Sample>,
}

/// A point of the centreline and the orientation of the cross section
/// there (unit quaternion w, x, y, z; its x axis along the arm).
#[derive(Clone, Copy, Debug)]
pub struct Sample {
    pub point: [ExprId; 3],
    pub frame: [ExprId; 4],
    /// A planar frame's angle about z (None in 3D).
    pub angle: Option<ExprId>,
    /// The centreline's length from its element's start to this point,
    /// where the method knows it (the contact frames' broad phase needs
    /// it; None: that arm's contact takes the points from the base).
    pub arc: Option<ExprId>,
}

impl Sample {
    /// A 3D frame: at `point`, turned by the unit quaternion `frame`.
    pub fn spatial(point: [ExprId; 3], frame: [ExprId; 4]) -> Self {
        Self {
            point,
            frame,
            angle: None,
            arc: None,
        }
    }

    /// A planar arm's frame: turned by `angle` about z.
    pub fn planar(cas: &mut Cas, point: [ExprId; 3], angle: ExprId) -> Self {
        let half = cas.scaled(0.5, angle);
        let zero = cas.zero();
        Self {
            point,
            frame: [cas.cos(half), zero, zero, cas.sin(half)],
            angle: Some(angle),
            arc: None,
        }
    }

    /// The same frame, `arc` along its element's centreline.
    pub fn at_arc(self, arc: Option<ExprId>) -> Self {
        Self { arc, ..self }
    }
}

/// A planar frame: origin and angle from the world's x axis.
#[derive(Clone, Copy, Debug)]
pub struct PlanarPose {
    pub point: [ExprId; 3],
    pub angle: ExprId,
}

/// The frames of a planar chain a joint may name.
#[derive(Clone, Debug)]
pub struct PlanarFrames {
    /// The end of each segment.
    pub segment_ends: Vec<PlanarPose>,
    /// The tip point, the end frame's angle.
    pub tip: PlanarPose,
}

impl System {
    /// Add the tip payload and loads, moving with `link` of the chain.
    pub fn attach_tip(&mut self, tip: TipLoads, link: usize) {
        self.tip = tip.point;
        if let Some(b) = tip.body {
            self.bodies.push(b);
            if let Some(c) = &mut self.chain {
                c.body_link.push(link);
            }
        }
        if let Some(f) = tip.force {
            self.point_forces.push(f);
            if let Some(c) = &mut self.chain {
                c.point_force_link.push(link);
            }
        }
        if let Some(m) = tip.moment {
            self.moments.push(m);
            if let Some(c) = &mut self.chain {
                c.moment_link.push((link, false));
            }
        }
    }
}

/// The arm's end frame, where the tip payload mounts.
pub struct TipMount {
    pub point: [ExprId; 3],
    /// The frame's x axis (along the arm) in the world.
    pub axis: [ExprId; 3],
    pub omega: [ExprId; 3],
    /// World from tip frame (rows), for wrenches given in the tip frame.
    pub rotation: [[ExprId; 3]; 3],
}

/// The tip payload as the TMT method sees it.
pub struct TipLoads {
    /// The tip point: the mount, or the end of the tip body.
    pub point: [ExprId; 3],
    pub body: Option<Body>,
    pub force: Option<PointForce>,
    pub moment: Option<AppliedMoment>,
}

/// The tip body (a point mass, or a cylinder along the tip axis), the tip
/// force at the tip point and the tip moment, as the structure declares
/// them; one definition for every kinematics.
pub fn tip_loads(
    cas: &mut Cas,
    symbols: &ParamSymbols,
    structure: &crate::model::Structure,
    mount: &TipMount,
) -> TipLoads {
    let zero = cas.zero();
    let param = |p: Param| symbols.get(p);
    let along = |cas: &mut Cas, d: ExprId| -> [ExprId; 3] {
        std::array::from_fn(|k| {
            let o = cas.mul(d, mount.axis[k]);
            let e = cas.add(mount.point[k], o);
            cas.bind(e)
        })
    };
    let (point, centre) = if structure.tip_length {
        let len = param(Param::TipLength);
        let half = cas.scaled(0.5, len);
        (along(cas, len), along(cas, half))
    } else {
        (mount.point, mount.point)
    };
    let body = structure.tip_mass.then(|| Body {
        mass: param(Param::TipMass),
        inertia: if structure.tip_length {
            Inertia::Axisymmetric {
                axis: mount.axis,
                axial: param(Param::TipAxialInertia),
                lateral: param(Param::TipInertia),
            }
        } else {
            Inertia::Isotropic(zero)
        },
        position: centre,
        omega: mount.omega,
    });
    // A wrench in the tip frame turns with it: world = R local.
    let oriented = |cas: &mut Cas, v: [ExprId; 3]| -> [ExprId; 3] {
        if structure.tip_frame_wrench {
            std::array::from_fn(|i| {
                let e = cas.dot(&mount.rotation[i], &v);
                cas.bind(e)
            })
        } else {
            v
        }
    };
    let force = structure.tip_force.then(|| {
        let f = symbols.xyz(Param::TipForce);
        PointForce {
            point,
            force: oriented(cas, f),
        }
    });
    let moment = structure.tip_moment.then(|| {
        let m = symbols.xyz(Param::TipMoment);
        AppliedMoment {
            omega: mount.omega,
            moment: oriented(cas, m),
        }
    });
    TipLoads {
        point,
        body,
        force,
        moment,
    }
}

/// A serial chain of links, each owning a run of coordinates.
///
/// Invariants: links own the coordinates in order; a body of link L depends
/// on no coordinate past L and moves rigidly with the end frame of link L - 1
/// under the coordinates before L.
pub struct Chain {
    pub links: Vec<Link>,
    /// The link of each body.
    pub body_link: Vec<usize>,
    /// The link of each point force (the link whose coordinates move the
    /// point non-rigidly).
    pub point_force_link: Vec<usize>,
    /// The link each moment acts on, and whether it acts at a section
    /// inside the link (a load along the arm, turning with its section's
    /// angular velocity) rather than at the link's end frame.
    pub moment_link: Vec<(usize, bool)>,
}

pub struct Link {
    /// Indices of the coordinates this link owns.
    pub coords: Vec<usize>,
    /// Origin of the link's end frame, world coordinates, a function of q.
    pub end: [ExprId; 3],
    /// Angular velocity of the end frame, world coordinates, linear in qd.
    pub end_omega: [ExprId; 3],
}

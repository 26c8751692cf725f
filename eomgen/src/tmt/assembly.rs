//! An assembly as one TMT system: every arm's kinematics built as a single
//! arm's, in its own scope of coordinates and parameters (`Cas::scoped`),
//! the free bodies and compliant bases with coordinates of their own, and
//! the joints as constraint equations phi(q) = 0 on the frames they name
//! (docs/design.md section 7).
//!
//! Invariant: the coordinates are the arms' in declaration order (each
//! preceded by its compliant base's x, y), then the free bodies' x, y and
//! angle; every joint contributes its rows in declaration order, x and y of
//! the point gap, then a weld's angle gap.

use std::collections::HashMap;

use crate::cas::{Cas, ExprId, Scope, SymKind};
use crate::model::assembly::{FrameRef, JointKind};
use crate::model::{
    AssemblyShape, BodyParam, JointParam, Param, ParamLayout, Rate, SpringParam, Xyz,
};

use super::system::{Body, Coordinates, Inertia, ParamSymbols, PlanarPose, System};

/// The assembled system and its constraint equations.
pub struct Assembled {
    pub sys: System,
    /// phi(q) = 0, rows as the module's invariant orders them.
    pub constraints: Vec<ExprId>,
    /// Their names: `JOINT.x`, `JOINT.y`, `JOINT.angle`.
    pub rows: Vec<String>,
    /// Coordinates per independent subsystem (an arm with its compliant
    /// base, a free body), in order: M is block diagonal over them.
    pub blocks: Vec<usize>,
}

/// The assembly's own parameters (gravity, bodies, joints, bases) by
/// `Param`; the arms' come through their scoped `ParamSymbols`.
struct OwnParams(HashMap<Param, ExprId>);

impl OwnParams {
    fn new(cas: &mut Cas, layout: &ParamLayout) -> Self {
        let mut ids = HashMap::new();
        for (i, &p) in layout.params().iter().enumerate() {
            if !matches!(p, Param::Scoped { .. }) {
                ids.insert(p, cas.symbol(&layout.name(p), SymKind::Param(i as u32)));
            }
        }
        Self(ids)
    }

    fn get(&self, p: Param) -> ExprId {
        self.0[&p]
    }
}

/// Coordinates of the assembly under construction: names, and their
/// symbols created at the next index.
struct Coords {
    names: Vec<String>,
    q: Vec<ExprId>,
    qd: Vec<ExprId>,
    qdd: Vec<ExprId>,
}

impl Coords {
    fn push(&mut self, cas: &mut Cas, name: String) -> (ExprId, ExprId) {
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

    /// The coordinates of a system built in a scope at this index.
    fn extend(&mut self, prefix: &str, c: &Coordinates) {
        self.names
            .extend(c.names.iter().map(|n| format!("{prefix}{n}")));
        self.q.extend(&c.q);
        self.qd.extend(&c.qd);
        self.qdd.extend(&c.qdd);
    }
}

/// The system of an assembly structure (planar).
pub fn assembly_system(cas: &mut Cas, a: &AssemblyShape, layout: &ParamLayout) -> Assembled {
    let own = OwnParams::new(cas, layout);
    let zero = cas.zero();
    let gravity = Xyz::ALL.map(|c| own.get(Param::Gravity(c)));
    let mut coords = Coords {
        names: Vec::new(),
        q: Vec::new(),
        qd: Vec::new(),
        qdd: Vec::new(),
    };
    let mut bodies = Vec::new();
    let (mut elastic, mut rayleigh, mut actuation) = (Vec::new(), Vec::new(), Vec::new());
    let (mut point_forces, mut moments, mut seeds) = (Vec::new(), Vec::new(), Vec::new());
    let mut tips = Vec::new();
    let mut arm_frames = Vec::new();
    let mut blocks = Vec::new();
    for (k, ((name, st), (_, offset, arm_layout))) in a.arms.iter().zip(layout.arms()).enumerate() {
        let prefix = if name.is_empty() {
            String::new()
        } else {
            format!("{name}.")
        };
        let spring = |w| own.get(Param::BaseSpring(k as u16, w));
        let first = coords.names.len();
        let base_offset = st.base_compliant.then(|| {
            let (x, xd) = coords.push(cas, format!("{prefix}base_x"));
            let (y, yd) = coords.push(cas, format!("{prefix}base_y"));
            let follow = |r, c| spring(SpringParam::Follow(r, c));
            for (s, v, c) in [(x, xd, Xyz::X), (y, yd, Xyz::Y)] {
                let gap = cas.sub(s, follow(Rate::Value, c));
                elastic.push(half_k_sq(cas, spring(SpringParam::Stiffness), gap));
                let slip = cas.sub(v, follow(Rate::First, c));
                rayleigh.push(half_k_sq(cas, spring(SpringParam::Damping), slip));
            }
            [x, y, zero]
        });
        let scope = Scope {
            prefix: prefix.clone(),
            coordinates: coords.names.len() as u32,
            parameters: *offset as u32,
        };
        let sys = cas.scoped(scope, |cas| {
            let mut symbols = ParamSymbols::new(cas, arm_layout);
            if let Some(o) = base_offset {
                symbols = symbols.with_base_offset(o);
                let position = symbols.base_motion(cas).position;
                bodies.push(Body {
                    mass: spring(SpringParam::Mass),
                    inertia: Inertia::Isotropic(zero),
                    position,
                    omega: [zero; 3],
                });
            }
            super::arm_system(cas, st, &symbols)
        });
        coords.extend(&prefix, &sys.coords);
        blocks.push(coords.names.len() - first);
        bodies.extend(sys.bodies);
        elastic.push(sys.elastic);
        rayleigh.push(sys.rayleigh);
        actuation.push(sys.actuation);
        point_forces.extend(sys.point_forces);
        moments.extend(sys.moments);
        seeds.extend(sys.seeds);
        tips.push((sys.tip, sys.tip_orientation));
        let planar = sys.planar.expect("assemblies are planar (validated)");
        arm_frames.push((
            planar.segment_ends,
            PlanarPose {
                point: sys.tip,
                angle: planar.tip.angle,
            },
        ));
    }
    let mut body_frames = Vec::new();
    for (b, (name, free)) in a.bodies.iter().enumerate() {
        let p = |w| own.get(Param::Body(b as u16, w));
        let pose = if *free {
            let (x, _) = coords.push(cas, format!("{name}.x"));
            let (y, _) = coords.push(cas, format!("{name}.y"));
            let (angle, rate) = coords.push(cas, format!("{name}.angle"));
            blocks.push(3);
            let point = [x, y, p(BodyParam::Position(Xyz::Z))];
            bodies.push(Body {
                mass: p(BodyParam::Mass),
                inertia: Inertia::Isotropic(p(BodyParam::Inertia)),
                position: point,
                omega: [zero, zero, rate],
            });
            PlanarPose { point, angle }
        } else {
            PlanarPose {
                point: Xyz::ALL.map(|c| p(BodyParam::Position(c))),
                angle: p(BodyParam::Angle),
            }
        };
        body_frames.push(pose);
    }
    let frame = |f: FrameRef| match f {
        FrameRef::World => PlanarPose {
            point: [zero; 3],
            angle: zero,
        },
        FrameRef::Body(b) => body_frames[b],
        FrameRef::Tip(arm) => arm_frames[arm].1,
        FrameRef::SegmentEnd { arm, segment } => arm_frames[arm].0[segment],
    };
    let (mut constraints, mut rows) = (Vec::new(), Vec::new());
    for (j, joint) in a.joints.iter().enumerate() {
        rows.extend(["x", "y"].map(|c| format!("{}.{c}", joint.name)));
        let p = |w| own.get(Param::Joint(j as u16, w));
        let (fa, fb) = (frame(joint.a), frame(joint.b));
        let pa = point_at(
            cas,
            fa,
            [JointParam::OffsetA(Xyz::X), JointParam::OffsetA(Xyz::Y)].map(p),
        );
        let pb = point_at(
            cas,
            fb,
            [JointParam::OffsetB(Xyz::X), JointParam::OffsetB(Xyz::Y)].map(p),
        );
        for c in 0..2 {
            constraints.push(cas.sub(pa[c], pb[c]));
        }
        if joint.kind == JointKind::Weld {
            let turned = cas.add(fa.angle, p(JointParam::Angle));
            constraints.push(cas.sub(fb.angle, turned));
            rows.push(format!("{}.angle", joint.name));
        }
    }
    let (tip, tip_orientation) = tips
        .first()
        .copied()
        .unwrap_or(([zero; 3], [cas.one(), zero, zero, zero]));
    let sys = System {
        coords: Coordinates {
            names: coords.names,
            q: coords.q,
            qd: coords.qd,
            qdd: coords.qdd,
        },
        bodies,
        gravity,
        elastic: cas.add_all(&elastic),
        rayleigh: cas.add_all(&rayleigh),
        actuation: cas.add_all(&actuation),
        point_forces,
        moments,
        tip,
        tip_orientation,
        chain: None,
        seeds,
        planar: None,
    };
    Assembled {
        sys,
        constraints,
        rows,
        blocks,
    }
}

/// The point at `offset` (in the frame's own axes) of a planar frame.
fn point_at(cas: &mut Cas, f: PlanarPose, offset: [ExprId; 2]) -> [ExprId; 2] {
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
    [x, y]
}

/// k x^2 / 2.
fn half_k_sq(cas: &mut Cas, k: ExprId, x: ExprId) -> ExprId {
    let sq = cas.mul(x, x);
    let e = cas.mul(k, sq);
    cas.scaled(0.5, e)
}

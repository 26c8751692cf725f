//! The kinds of link cell (`build::cell`); a method names its own.

use crate::model::Axis;

/// The kinematics of a 3D link.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(crate) enum CellKind {
    /// A constant-strain arc (pcc, vc, a rom slice).
    Arc,
    /// Half of a stretching or shearing arc (`tmt::spatial::in_halves`): half
    /// its strain, mass and energies; two links share the element's
    /// coordinates.
    HalfArc,
    /// An ebr element's half before its joint: no coordinates.
    BeforeJoint,
    /// An ebr element's joint and the half past it.
    PastJoint,
    /// A rigid element's joint (its axes in sequence, `method::rigid`'s
    /// `joint_turn`) and the link past it: the whole link where the joint
    /// is at its base, else the half past a midpoint joint (the half
    /// before it a [`CellKind::BeforeJoint`]).
    Revolute {
        axes: [Option<Axis>; 3],
        whole: bool,
    },
    /// A kink before a segment: its constant turn and offset, no
    /// coordinates, no body.
    Kink,
}

/// How an element's sampled points lie on its links.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(crate) enum PointsOn {
    /// Constant-strain arcs: the point at s is its link's arc cut at s.
    Arcs,
    /// Links that turn at their start and are straight past it (rigid
    /// links past their joints): the point at s is s times its link's end
    /// point, its section turned as the end.
    Straight,
}

impl CellKind {
    /// An element of this kind is a link of no coordinates (its half
    /// before a midpoint joint) and then one of this kind.
    pub(crate) fn after_half(self) -> bool {
        matches!(
            self,
            CellKind::PastJoint | CellKind::Revolute { whole: false, .. }
        )
    }
}

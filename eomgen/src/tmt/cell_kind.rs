//! The kinds of link cell (`build::cell`); a method names its own.

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
    /// A kink before a segment: its constant turn and offset, no
    /// coordinates, no body.
    Kink,
}

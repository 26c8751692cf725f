//! A mechanical system as the TMT method sees it: generalised coordinates,
//! lumped bodies, potentials, a Rayleigh function and applied forces, all as
//! CAS expressions. Kinematics modules build one; `assemble` derives the EOM.

use crate::cas::{Cas, ExprId, SymKind};

pub use super::inertia::Inertia;

/// The parameter symbols of a model, looked up by name (the layout of
/// `model::parameters`).
pub struct ParamSymbols {
    names: Vec<String>,
    ids: Vec<ExprId>,
}

impl ParamSymbols {
    pub fn new(cas: &mut Cas, model: &crate::model::Model) -> Self {
        let names: Vec<String> = crate::model::parameters(model)
            .into_iter()
            .map(|(n, _)| n)
            .collect();
        let ids = names
            .iter()
            .enumerate()
            .map(|(i, n)| cas.symbol(n, SymKind::Param(i as u32)))
            .collect();
        Self { names, ids }
    }

    /// The symbol of parameter `name`; kinematics only asks for names the
    /// layout has, so a miss is a generator bug.
    pub fn get(&self, name: &str) -> ExprId {
        let i = self
            .names
            .iter()
            .position(|n| n == name)
            .unwrap_or_else(|| panic!("no parameter {name}"));
        self.ids[i]
    }
}

/// q, qd symbols and their names.
pub struct Coordinates {
    pub names: Vec<String>,
    pub q: Vec<ExprId>,
    pub qd: Vec<ExprId>,
    /// Accelerations (inputs of the `Jacobian` kernel only).
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
pub struct PointForce {
    pub point: [ExprId; 3],
    pub force: [ExprId; 3],
}

/// A constant world-frame moment on a frame turning at `omega`.
pub struct AppliedMoment {
    pub omega: [ExprId; 3],
    pub moment: [ExprId; 3],
}

pub struct System {
    pub coords: Coordinates,
    pub bodies: Vec<Body>,
    pub gravity: [ExprId; 3],
    /// Elastic potential V_e(q).
    pub elastic: ExprId,
    /// Rayleigh dissipation function R(q, qd).
    pub rayleigh: ExprId,
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
    /// The link at whose end each moment acts.
    pub moment_link: Vec<usize>,
}

pub struct Link {
    /// Indices of the coordinates this link owns.
    pub coords: Vec<usize>,
    /// Origin of the link's end frame, world coordinates, a function of q.
    pub end: [ExprId; 3],
    /// Angular velocity of the end frame, world coordinates, linear in qd.
    pub end_omega: [ExprId; 3],
}

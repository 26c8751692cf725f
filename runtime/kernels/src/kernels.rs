//! Kernels: the numbered functions every model provides, and the trait that
//! both backends (generated Rust and the tape interpreter) implement.

use std::cell::RefCell;

use serde::{Deserialize, Serialize};

use crate::linalg::Ldlt;
use crate::links::ArmFrame;
pub use crate::output::{N_OUTPUTS, OUTPUT_NAMES};
use crate::tape::{Inputs, Tape};

/// The functions derived for every model. Output layouts are fixed here and
/// relied on by [`crate::Arm`]:
///
/// * `MassBias`: the upper triangle of M(q), row by row: (0,0), (0,1),
///   ..., (1,1), ..., then h(q, qd, t), n values (one pass, shared
///   subexpressions; M or h alone are read from it rather than generated
///   again, which kept a sixth of every model's generated code).
/// * `Outputs`: see [`OUTPUT_NAMES`].
/// * `Accel`: qdd = -M^-1 h (n values), the pivots D of M = L D L^T
///   (n values, all positive when M is positive definite), L below its
///   unit diagonal row by row (n (n - 1) / 2 values), then the contact
///   frames as `Contact` gives them (`ModelInfo::contact_frames`), or
///   where the chain has none the points' positions (3 per point): the
///   mass solve generated as straight-line code ([`TapeSet::accel`]), with what a contact force found
///   after it needs (the broad phase or the gaps, and L D L^T to solve
///   for it). Present only when `ModelInfo::accel` (small arms);
///   otherwise the runtime solves `MassBias` output.
/// * `Jvp`: the directional derivative of the inverse dynamics
///   tau(q, qd, qdd) = M qdd + h along the input direction (dq, dqd), at
///   the input `qdd` (n values). The runtime assembles the right-hand
///   side's Jacobian column by column from it (`Dynamics::jacobian_parts`)
///   and the tangent stiffness K = d h(q, 0) / dq as its columns at
///   qd = qdd = 0 (`Dynamics::stiffness`): one kernel the size of a few h
///   kernels instead of n^2 entries each.
/// * `Constraints`: the joints of an assembly as phi(q) = 0, m rows
///   (`ModelInfo::constraints`): phi (m values), its Jacobian J = d phi/dq
///   (m x n, row-major) and the velocity product gamma = (d/dt J) qd
///   (m values), so that J qdd + gamma = 0 holds the joints at the
///   acceleration level. Empty for a model without joints.
/// * `Contact`: the contact points along the arms (and the bodies'
///   centres), `ModelInfo::contact_points` of them, each as its position
///   p (3): the runtime finds the gaps; then the contact frames
///   (`ModelInfo::contact_frames` values, none for most structures).
///   Empty without contact.
/// * `ContactJacobian`: each point's position p (3), velocity v (3) and
///   dp/dq (3 x n, row-major), which the forces and their map J^T need.
///   Split into groups of points that depend on the same coordinates
///   (`ModelInfo::contact_groups`, an arm's element or a body): group g is
///   evaluated only when `dir[g]` is non-zero (an empty `dir`: every
///   group), so a right-hand side where the tip presses evaluates the
///   tip's group alone; the others' outputs are left as they were. With
///   contact frames, the groups read them as `aux` and start from their
///   element's base frame instead of from the arm's base.
/// * `ContactJvp`: the same points' dv and d(dp/dq) along the direction
///   dq (the first n of `dir`; 3 + 3 n values a point): the exact
///   Jacobian of the contact forces, column by column.
/// * `Derived`: the derived parameters (parameter-only subexpressions the
///   generator hoisted out of the other kernels), computed once per
///   parameter set; the other kernels read them after the base parameters.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum KernelKind {
    MassBias,
    Outputs,
    Accel,
    Jvp,
    Derived,
    Constraints,
    Contact,
    ContactJacobian,
    ContactJvp,
}

impl KernelKind {
    pub const ALL: [KernelKind; 9] = [
        Self::Jvp,
        Self::Accel,
        Self::MassBias,
        Self::Outputs,
        Self::Derived,
        Self::Constraints,
        Self::Contact,
        Self::ContactJacobian,
        Self::ContactJvp,
    ];

    pub fn output_len(self, info: &ModelInfo) -> usize {
        let dof = info.dof();
        let tri = dof * (dof + 1) / 2;
        match self {
            Self::MassBias => tri + dof,
            Self::Outputs => OUTPUT_NAMES.len(),
            Self::Derived => info.derived,
            Self::Jvp => dof,
            Self::Constraints => info.constraints.len() * (dof + 2),
            Self::Contact => info.contact_points * 3 + info.contact_frames,
            Self::ContactJacobian => info.contact_points * (6 + 3 * dof),
            Self::ContactJvp => info.contact_points * (3 + 3 * dof),
            Self::Accel => {
                if info.accel {
                    2 * dof + dof * dof.saturating_sub(1) / 2 + info.accel_contact_len()
                } else {
                    0
                }
            }
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Self::MassBias => "mass_bias",
            Self::Outputs => "outputs",
            Self::Derived => "derived",
            Self::Jvp => "jvp",
            Self::Accel => "accel",
            Self::Constraints => "constraints",
            Self::Contact => "contact",
            Self::ContactJacobian => "contact_jacobian",
            Self::ContactJvp => "contact_jvp",
        }
    }
}

/// What a derived model is: its coordinates and parameter layout.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModelInfo {
    /// Structural hash of the model (the cache key).
    pub hash: String,
    pub coordinates: Vec<String>,
    /// Names of the base parameters, in order.
    pub parameters: Vec<String>,
    /// Number of derived parameters, stored after the base ones.
    pub derived: usize,
    /// Whether the `Accel` kernel exists.
    pub accel: bool,
    /// Indices of the base parameters that are loads (gravity, applied
    /// forces): statics scales them for load continuation.
    pub loads: Vec<usize>,
    /// The rows of the `Constraints` kernel by name, `JOINT.x`, `JOINT.y`,
    /// `JOINT.angle` (none for a model without joints).
    #[serde(default)]
    pub constraints: Vec<String>,
    /// Sizes of the runs of coordinates whose bodies move independently
    /// (an assembly's arms and free bodies): M is block diagonal over them,
    /// which the constrained solve exploits. Empty: one block.
    #[serde(default)]
    pub blocks: Vec<usize>,
    /// Contact points (the `Contact` kernel's): each arm's, element by
    /// element, `points_per_element` each, then every body's centre.
    #[serde(default)]
    pub contact_points: usize,
    /// Points per `ContactJacobian` group, consecutive (their sum is
    /// `contact_points`; at most 2 n groups, so that `dir` can select them).
    #[serde(default)]
    pub contact_groups: Vec<usize>,
    /// Length of the contact frames (0: none), which a serial chain's
    /// contact kernels share (docs/design.md, "Contact along the arm"):
    /// for each group its base frame's origin A, its last point B and the
    /// centreline's length L between them (`CONTACT_BOUND` values a
    /// group: every point of the group lies in the ellipsoid of foci A and
    /// B and major axis L, the broad phase), then what the groups' kernels
    /// read as `aux` (the frames' orientations, the coordinates' twists).
    /// The `Accel` kernel gives them in place of the points.
    #[serde(default)]
    pub contact_frames: usize,
    /// (j, k): extended parameter k holds a copy of base parameter j (an
    /// assembly's arm reads its parameters as one slice: `ArmBlocks`), so
    /// that a driven j is written to k too each time it is.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub copies: Vec<(usize, usize)>,
}

pub use crate::links::CONTACT_BOUND;

impl ModelInfo {
    pub fn dof(&self) -> usize {
        self.coordinates.len()
    }

    /// Length of the parameter vector the kernels read: base + derived.
    pub fn extended_params(&self) -> usize {
        self.parameters.len() + self.derived
    }

    /// What the `Accel` kernel gives after the L D L^T factors: the
    /// contact frames where the chain has them, else every point.
    pub fn accel_contact_len(&self) -> usize {
        match self.contact_frames {
            0 => 3 * self.contact_points,
            n => n,
        }
    }

    /// The `ContactJacobian` groups as (first point, points).
    pub fn contact_group_ranges(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        self.contact_groups.iter().scan(0, |start, &len| {
            let first = *start;
            *start += len;
            Some((first, len))
        })
    }
}

/// A set of kernels for one model structure.
pub trait Kernels {
    fn info(&self) -> &ModelInfo;
    /// Evaluate `kind` into `out` (length `kind.output_len(info)`); `inp.p`
    /// is the extended parameter vector (base, then derived).
    fn eval(&self, kind: KernelKind, inp: &Inputs, out: &mut [f64]);
    /// Which backend this is, for reports.
    fn backend(&self) -> &'static str;
    /// Solve M x = b in place, M packed as `MassBias` lays it out (its first n(n+1)/2 values);
    /// false unless M is positive definite. Linked chains override it with
    /// the same solve built for FMA; small arms do not come here (their
    /// solve is the generated `Accel` kernel).
    fn solve_mass(&self, packed: &[f64], b: &mut [f64], ws: &mut Ldlt) -> bool {
        if !ws.factor(packed) {
            return false;
        }
        ws.solve(b);
        true
    }
    /// qdd = -M^-1 h into `qdd` by a recursion that forms no mass matrix
    /// (the articulated-body sweeps of a chain, O(links)), where the
    /// kernel set has one: None where it has not, Some(false) where M is
    /// not positive definite.
    fn accelerations(&self, _inp: &Inputs, _qdd: &mut [f64]) -> Option<bool> {
        None
    }

    /// The contact frames' bounds alone (`CONTACT_BOUND` values a group,
    /// the whole of `ModelInfo::contact_frames`), without the points, where
    /// the kernel set gives them so: the broad phase of a chain without
    /// an `Accel` kernel. False where it does not.
    fn contact_bounds(&self, _inp: &Inputs, _out: &mut [f64]) -> bool {
        false
    }

    /// The frames `which` of a chain that joints hold, as
    /// [`crate::links::frames`] gives them ([`crate::links::frame::len`]
    /// values each), where the kernel set runs on link cells. False where
    /// it does not: an assembly's joints then run on its flat tapes.
    fn frames(&self, _inp: &Inputs, _which: &[ArmFrame], _out: &mut [f64]) -> bool {
        false
    }
}

/// A boxed set of kernels is one: the backends are chosen at run time.
impl<K: Kernels + ?Sized> Kernels for Box<K> {
    fn info(&self) -> &ModelInfo {
        (**self).info()
    }
    fn eval(&self, kind: KernelKind, inp: &Inputs, out: &mut [f64]) {
        (**self).eval(kind, inp, out)
    }
    fn backend(&self) -> &'static str {
        (**self).backend()
    }
    fn solve_mass(&self, packed: &[f64], b: &mut [f64], ws: &mut Ldlt) -> bool {
        (**self).solve_mass(packed, b, ws)
    }
    fn accelerations(&self, inp: &Inputs, qdd: &mut [f64]) -> Option<bool> {
        (**self).accelerations(inp, qdd)
    }
    fn contact_bounds(&self, inp: &Inputs, out: &mut [f64]) -> bool {
        (**self).contact_bounds(inp, out)
    }
    fn frames(&self, inp: &Inputs, which: &[ArmFrame], out: &mut [f64]) -> bool {
        (**self).frames(inp, which, out)
    }
}

/// Derived tapes of one model: the interpreted backend, and what eomgen
/// emits as Rust for the compiled one.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TapeSet {
    pub info: ModelInfo,
    pub mass_bias: Tape,
    pub outputs: Tape,
    pub derived: Tape,
    /// The `Accel` kernel's values, then `MassBias`'s: one tape gives
    /// both (compiled, each kernel's function keeps its values and the
    /// compiler drops the code of the rest). Empty unless `info.accel`.
    pub accel: Tape,
    pub jvp: Tape,
    /// Empty unless `info.constraints > 0`.
    #[serde(default)]
    pub constraints: Tape,
    /// Empty unless `info.contact_points > 0`.
    #[serde(default)]
    pub contact: Tape,
    /// One tape per group of `info.contact_groups`.
    #[serde(default)]
    pub contact_jacobian: Vec<Tape>,
    #[serde(default)]
    pub contact_jvp: Tape,
    /// The layout and kernels of the link recursion (`crate::links`),
    /// which compiled models of the chains it covers use for `MassBias`;
    /// the interpreter keeps the flat tape.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub links: Option<crate::links::LinkKernels>,
    /// An assembly's arms' own kernels ([`ArmBlocks`]), which
    /// compiled models use for `MassBias`, `Jvp` and `Derived`; the
    /// interpreter keeps the flat tapes.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub arm_blocks: Option<ArmBlocks>,
    /// The parts of a system that is a sum of small kernels (eba), which
    /// compiled models use for `MassBias` and `Jvp`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub parts: Option<crate::parts::PartKernels>,
}

impl TapeSet {
    /// The tapes of `kind`: one, or for `ContactJacobian` one per group.
    pub fn tapes(&self, kind: KernelKind) -> &[Tape] {
        match kind {
            KernelKind::ContactJacobian => &self.contact_jacobian,
            _ => std::slice::from_ref(self.tape(kind)),
        }
    }

    /// The tape of a kernel that is one tape (not `ContactJacobian`).
    fn tape(&self, kind: KernelKind) -> &Tape {
        match kind {
            KernelKind::MassBias => &self.mass_bias,
            KernelKind::Outputs => &self.outputs,
            KernelKind::Derived => &self.derived,
            KernelKind::Accel => &self.accel,
            KernelKind::Jvp => &self.jvp,
            KernelKind::Constraints => &self.constraints,
            KernelKind::Contact => &self.contact,
            KernelKind::ContactJvp => &self.contact_jvp,
            KernelKind::ContactJacobian => unreachable!("ContactJacobian is grouped: `tapes`"),
        }
    }
}

/// An assembly's kernels through its arms' own (`TapeSet::arm_blocks`):
/// each distinct arm
/// structure is derived once as a single arm (its kernels, its link
/// recursion, its derived parameters), and the assembly's `MassBias` and
/// `Jvp` are the rest of the system's (bodies, compliant bases, what joins
/// the arms: a small flat tape) plus each arm's in its block of
/// coordinates. M is block diagonal over the arms and bodies, so nothing
/// else couples them there; joints and contact stay in their own kernels.
///
/// Each arm reads its parameters as one slice of the extended parameter
/// vector: the `Derived` kernel copies the arm's base parameters there and
/// computes the arm's derived ones after them, once per parameter set;
/// an input's value, which changes during a run, is written to its copy
/// too each time (`ModelInfo::copies`, [`ArmBlocks::copies`]). No derived
/// parameter reads an input.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ArmBlocks {
    /// `MassBias` of the system without the arms' own terms (the
    /// assembly's packed M and h).
    pub rest_mass_bias: Tape,
    /// `Jvp` of the same.
    pub rest_jvp: Tape,
    /// `Outputs` of the same (its energies; the tip is the first arm's).
    #[serde(default)]
    pub rest_outputs: Tape,
    /// The kernels of each distinct arm structure, as a single arm's.
    pub kinds: Vec<TapeSet>,
    pub arms: Vec<ArmInstance>,
    /// The contact points through the arms' own contact kernels (each
    /// arm's points, with its contact frames, from its kind's), and the
    /// points no arm has (the bodies' centres) from these; `None`: the
    /// assembly's flat contact kernels.
    #[serde(default)]
    pub rest_contact: Option<RestContact>,
    /// The joints on their arms' frames (`crate::joints`), where every
    /// arm a joint holds runs on link cells; `None`: the assembly's flat
    /// `Constraints` kernel.
    #[serde(default)]
    pub joints: Option<crate::joints::FrameJoints>,
}

/// The contact kernels of an assembly's points that are no arm's, which
/// follow the arms' points and groups.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RestContact {
    /// Their positions (3 each).
    pub contact: Tape,
    /// Their groups, as `TapeSet::contact_jacobian`'s.
    pub contact_jacobian: Vec<Tape>,
    pub contact_jvp: Tape,
    /// Points per group.
    pub groups: Vec<usize>,
}

/// One arm of the assembly.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ArmInstance {
    /// Its structure: an index into `ArmBlocks::kinds`.
    pub kind: usize,
    /// Its coordinates: `first..first + dof` of the assembly's.
    pub first: usize,
    pub dof: usize,
    /// Its base parameters: from `params` on, in its own layout's order.
    pub params: usize,
    /// Its driven base parameters (inputs), in its own layout.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub driven: Vec<usize>,
}

impl ArmBlocks {
    /// Where each arm's parameters (its base ones, then its derived ones)
    /// start among the assembly's derived parameters, after `own` of the
    /// assembly's own; and the total.
    pub fn derived_layout(&self, own: usize) -> (Vec<usize>, usize) {
        let mut at = own;
        let starts = self
            .arms
            .iter()
            .map(|a| {
                let start = at;
                at += self.kinds[a.kind].info.extended_params();
                start
            })
            .collect();
        (starts, at)
    }

    /// The copies of the arms' driven parameters in their slices
    /// (`ModelInfo::copies`), for `n_base` base parameters and `own` of
    /// the assembly's own derived ones.
    pub fn copies(&self, n_base: usize, own: usize) -> Vec<(usize, usize)> {
        let (starts, _) = self.derived_layout(own);
        (self.arms.iter().zip(starts))
            .flat_map(|(a, start)| {
                a.driven
                    .iter()
                    .map(move |&i| (a.params + i, n_base + start + i))
            })
            .collect()
    }
}

/// The interpreted backend.
pub struct Interpreted {
    tapes: TapeSet,
    scratch: RefCell<Vec<f64>>,
}

impl Interpreted {
    pub fn new(tapes: TapeSet) -> Self {
        Self {
            tapes,
            scratch: RefCell::new(Vec::new()),
        }
    }
    pub fn tapes(&self) -> &TapeSet {
        &self.tapes
    }
}

impl Kernels for Interpreted {
    fn info(&self) -> &ModelInfo {
        &self.tapes.info
    }
    fn eval(&self, kind: KernelKind, inp: &Inputs, out: &mut [f64]) {
        let mut slots = self.scratch.borrow_mut();
        if kind == KernelKind::ContactJacobian {
            let info = &self.tapes.info;
            // The contact frames: given, or from the `Contact` kernel.
            let mut own = Vec::new();
            let inp = match (info.contact_frames, inp.aux.is_empty()) {
                (0, _) | (_, false) => *inp,
                _ => {
                    own.resize(KernelKind::Contact.output_len(info), 0.0);
                    self.tapes.contact.eval(inp, &mut slots, &mut own);
                    Inputs {
                        aux: &own[3 * info.contact_points..],
                        ..*inp
                    }
                }
            };
            let width = out.len() / info.contact_points.max(1);
            let groups = info.contact_group_ranges();
            for (g, ((first, len), tape)) in groups.zip(&self.tapes.contact_jacobian).enumerate() {
                if inp.dir.is_empty() || inp.dir[g] != 0.0 {
                    tape.eval(
                        &inp,
                        &mut slots,
                        &mut out[first * width..(first + len) * width],
                    );
                }
            }
            return;
        }
        let tape = self.tapes.tape(kind);
        if kind == KernelKind::Jvp && (inp.qdd.is_empty() || inp.dir.is_empty()) {
            // As the compiled models do: absent accelerations and direction
            // read as zeros (only this kernel reads them).
            let zeros = vec![0.0; 2 * self.tapes.info.dof()];
            return self.jvp(&inp.zero_filled(&zeros), &mut slots, out);
        }
        if kind == KernelKind::Jvp {
            return self.jvp(inp, &mut slots, out);
        }
        if kind == KernelKind::Accel {
            let mut all = vec![0.0; tape.outputs.len()];
            tape.eval(inp, &mut slots, &mut all);
            return out.copy_from_slice(&all[..out.len()]);
        }
        tape.eval(inp, &mut slots, out);
    }
    fn backend(&self) -> &'static str {
        "interpreted"
    }
}

impl Interpreted {
    /// The Jvp: a system of parts by its part tapes (a column of the
    /// Jacobian touches a few parts, where the flat tape is the whole
    /// system), anything else by the flat tape.
    fn jvp(&self, inp: &Inputs, slots: &mut Vec<f64>, out: &mut [f64]) {
        match &self.tapes.parts {
            Some(parts) => {
                let mut tp = crate::parts::TapeParts {
                    kernels: parts,
                    slots: std::mem::take(slots),
                };
                crate::parts::jvp(
                    &parts.layout,
                    &mut tp,
                    inp.q,
                    inp.qd,
                    inp.qdd,
                    inp.dir,
                    inp.p,
                    out,
                );
                *slots = tp.slots;
            }
            None => self.tapes.jvp.eval(inp, slots, out),
        }
    }
}

/// A model compiled into the binary (an entry of `generated/mod.rs`).
pub struct CompiledModel {
    /// File stem of the model (`models/<name>.toml`).
    pub name: &'static str,
    pub hash: &'static str,
    pub dof: usize,
    /// The model file as it was when compiled in.
    pub source: &'static str,
    /// The data files it reads (paths as written in it, and their text),
    /// carried inside the binary: a copy of softarm runs its bundled
    /// models with no checkout beside it.
    pub files: &'static [(&'static str, &'static str)],
    pub kernels: fn() -> Box<dyn Kernels>,
    /// Its link cells, which chains of the same link shapes and other
    /// lengths link (`linked::LinkedKernels`).
    pub cells: &'static [crate::links::CompiledCell],
    /// Its part kernels, which systems of the same kinds of parts and
    /// other lengths link (`linked_parts::LinkedPartKernels`).
    pub parts: &'static [crate::parts::CompiledPart],
}

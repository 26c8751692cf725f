//! An assembly's joints through its arms' frames: the `Constraints` kernel
//! (phi, J = d phi/dq, gamma = (d/dt J) qd) from a small kernel of the
//! joints' rows on frame variables and each held frame's motion from its
//! arm's link cells (`links::frames`). The rows kernel is derived once per
//! joint, not per element: its size is the joints', and the arms' part of
//! J is the chain rule, (d phi/dx) (dx/dq), here.
//!
//! The rows kernel (`FrameJoints::rows`) reads, as `aux`, each held
//! frame's x, x' and x'' at qdd = 0 ([`frame::STATE`] values a frame, in
//! `FrameJoints::frames` order), and the bodies' coordinates as any kernel
//! does. It gives the `Constraints` kernel's layout with the arms' columns
//! of J left out (phi, d phi/dq of the coordinates it reads, gamma), then
//! G = d phi/dx: a row of [`frame::VARS`] values per frame for each
//! joint row.

use serde::{Deserialize, Serialize};

use crate::links::{ArmFrame, frame};
use crate::tape::Tape;

/// A frame a joint holds: arm `arm`'s (an index into the assembly's
/// arms) frame `at`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct JointFrame {
    pub arm: usize,
    pub at: ArmFrame,
}

/// An assembly's joints on frame variables.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FrameJoints {
    /// The arms' frames the rows read, in `aux` order.
    pub frames: Vec<JointFrame>,
    /// The rows kernel (module docs).
    pub rows: Tape,
}

/// The rows kernel's length for `m` rows, `n` coordinates and `frames`
/// held frames.
pub const fn rows_len(m: usize, n: usize, frames: usize) -> usize {
    m * (n + 2) + m * frame::VARS * frames
}

/// One held frame's motion (`links::frames`' values) on its arm, whose
/// coordinates are the assembly's `first..first + dof`.
#[derive(Clone, Copy)]
pub struct HeldFrame<'a> {
    pub first: usize,
    pub dof: usize,
    pub motion: &'a [f64],
}

/// The rows kernel's `aux`: each frame's x, x' and x''.
pub fn aux(frames: &[HeldFrame], out: &mut [f64]) {
    for (f, o) in frames.iter().zip(out.chunks_exact_mut(frame::STATE)) {
        o.copy_from_slice(&f.motion[..frame::STATE]);
    }
}

/// The `Constraints` kernel's outputs (`out`: m rows over `n`
/// coordinates) from the rows kernel's (`rows`) and the frames' columns:
/// J gains G_f (dx_f/dq) in each frame's arm's columns.
pub fn constraints(n: usize, frames: &[HeldFrame], rows: &[f64], out: &mut [f64]) {
    let m = out.len() / (n + 2);
    let nf = frames.len();
    debug_assert_eq!(rows.len(), rows_len(m, n, nf));
    let (own, g) = rows.split_at(m * (n + 2));
    out.copy_from_slice(own);
    for i in 0..m {
        let row = &mut out[m + i * n..m + (i + 1) * n];
        for (f, held) in frames.iter().enumerate() {
            let columns = &held.motion[frame::COLUMNS..];
            let arm = &mut row[held.first..held.first + held.dof];
            for v in 0..frame::VARS {
                let gv = g[(i * nf + f) * frame::VARS + v];
                if gv == 0.0 {
                    continue;
                }
                let column = &columns[v * held.dof..(v + 1) * held.dof];
                for (o, c) in arm.iter_mut().zip(column) {
                    *o += gv * c;
                }
            }
        }
    }
}

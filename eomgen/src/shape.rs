//! The arm's shape for outputs and animation: every arm's centreline at a
//! given number of points per element, each with its cross-section frame,
//! and every rigid body's pose, as one tape of (t, q, parameters).
//!
//! The points are the ones contact samples (`tmt::System::samples`), taken
//! from the same kinematics that M and h are derived from, so the drawn arm
//! is the simulated one, element by element and method by method: a pcc
//! element or a rom slice is drawn as its arc, an ebr element as its two
//! straight halves, an eba slab as the slab (gaps and all). The tape is
//! read at output times only: interpreted, never emitted.

use runtime::Tape;

use crate::build::{assembly_system, system};
use crate::cas::{Cas, ExprId};
use crate::model::{Param, ParamLayout, Structure};

/// Values a shape row holds: the point (x, y, z) and the section's
/// orientation as a unit quaternion (w, x, y, z), its x axis along the arm.
pub const ROW: usize = 7;

/// The shape's tape and what its rows are.
#[derive(Clone, Debug)]
pub struct ShapeTape {
    /// Rows of `ROW` values: each arm's base then its points, element by
    /// element, arm after arm; then every body's centre.
    pub tape: Tape,
    pub arms: Vec<ArmShape>,
    /// The bodies' names, in row order after the arms.
    pub bodies: Vec<String>,
}

/// One arm's rows.
#[derive(Clone, Debug)]
pub struct ArmShape {
    /// The arm's name (empty for a single-arm model).
    pub name: String,
    /// Points per element (the base adds one row).
    pub points: usize,
    /// Each element's length parameter (its index in the layout), for the
    /// material coordinate s of each row.
    pub lengths: Vec<usize>,
}

impl ShapeTape {
    /// Its rows at time t, coordinates q, parameters p (`ROW` values a
    /// row, in `arms` then `bodies` order).
    pub fn eval(&self, t: f64, q: &[f64], p: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; self.tape.outputs.len()];
        let inp = runtime::Inputs {
            t,
            q,
            qd: &[],
            qdd: &[],
            dir: &[],
            p,
            aux: &[],
        };
        self.tape.eval(&inp, &mut Vec::new(), &mut out);
        out
    }
}

impl ArmShape {
    pub fn rows(&self) -> usize {
        1 + self.points * self.lengths.len()
    }

    /// The material coordinate of each row (m from the base, unstretched)
    /// with the parameter values `p`.
    pub fn arc_lengths(&self, p: &[f64]) -> Vec<f64> {
        let mut s = vec![0.0];
        let mut start = 0.0;
        for &k in &self.lengths {
            let l = p[k];
            s.extend((1..=self.points).map(|j| start + l * j as f64 / self.points as f64));
            start += l;
        }
        s
    }
}

/// The shape of `structure` at `points` per element (at least 1).
pub fn shape_tape(structure: &Structure, points: usize) -> ShapeTape {
    let points = points.max(1);
    let layout = ParamLayout::of(structure);
    let mut cas = Cas::new();
    let (sys, arm_layouts) = match &structure.assembly {
        Some(a) => {
            let mut a = (**a).clone();
            for (_, st) in &mut a.arms {
                st.contact_points = points;
            }
            a.contact = true;
            let arms: Vec<_> = (a.arms.iter().zip(layout.arms()))
                .map(|((name, st), (_, first, own))| {
                    let lengths = element_lengths(st, own)
                        .into_iter()
                        .map(|i| first + i)
                        .collect();
                    (name.clone(), lengths)
                })
                .collect();
            (assembly_system(&mut cas, &a, &layout).sys, arms)
        }
        None => {
            let mut st = structure.clone();
            st.contact_points = points;
            let arms = vec![(String::new(), element_lengths(structure, &layout))];
            (system(&mut cas, &st, &layout), arms)
        }
    };
    let mut outs: Vec<ExprId> = Vec::new();
    let mut samples = sys.samples.iter();
    let mut arms = Vec::new();
    for ((name, lengths), base) in arm_layouts.into_iter().zip(&sys.bases) {
        let arm = ArmShape {
            name,
            points,
            lengths,
        };
        outs.extend(base.point.iter().chain(&base.frame));
        for s in samples.by_ref().take(arm.rows() - 1) {
            outs.extend(s.point.iter().chain(&s.frame));
        }
        arms.push(arm);
    }
    // What is left are the bodies' centres.
    for s in samples {
        outs.extend(s.point.iter().chain(&s.frame));
    }
    let bodies = structure
        .assembly
        .as_ref()
        .map(|a| a.bodies.iter().map(|(n, _)| n.clone()).collect())
        .unwrap_or_default();
    ShapeTape {
        tape: cas.to_tape(&outs),
        arms,
        bodies,
    }
}

/// Every element's length parameter, in element order.
fn element_lengths(st: &Structure, layout: &ParamLayout) -> Vec<usize> {
    (0..st.elements())
        .map(|k| {
            let p = Param::Element(k, crate::model::ElementParam::Length);
            layout.index(p)
        })
        .collect()
}

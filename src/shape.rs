//! The arm's shape in the outputs: `shape.csv`, every arm's centreline at
//! `--shape-points` per element with the cross-section frames, and every
//! body's pose, at each trajectory row (`eomgen::shape` derives the tape
//! from the model's structure; it is interpreted here, at output times
//! only).

use anyhow::{Result, bail};
use eomgen::model::{ParamLayout, Structure};
use eomgen::shape::{ROW, ShapeTape, shape_tape};
use runtime::Dynamics;
use runtime::contact::{self, Obstacle};

use crate::backend::Loaded;

/// Points per element when `--shape-points` is not given: a bent element
/// reads as a smooth tube.
pub const DEFAULT_POINTS: usize = 8;
/// More points per element than a screen can show, and shape.csv grows
/// with them.
pub const MAX_POINTS: usize = 64;

/// The shape of a loaded model.
pub struct Shape {
    tape: ShapeTape,
}

/// One row of `shape.csv` at one time (and of `static`'s `shape`).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct ShapeRow {
    /// The arm's name (`arm` for a model of one arm) or the body's.
    pub part: String,
    /// Index along the arm (0: the base), 0 for a body.
    pub point: usize,
    /// Material coordinate (m from the base, unstretched); 0 for a body.
    pub s: f64,
    /// Position (x, y, z), then the orientation (w, x, y, z).
    pub pose: [f64; ROW],
}

impl Shape {
    /// Derive the shape's tape; `points` per element (at least 1).
    pub fn new(loaded: &Loaded, points: usize) -> Result<Self> {
        if !(1..=MAX_POINTS).contains(&points) {
            bail!(
                "--shape-points {points}: must be 1 to {MAX_POINTS} points per element (0: no shape.csv)"
            );
        }
        let structure = Structure::of(&loaded.model);
        let names = ParamLayout::of(&structure).names();
        if names != loaded.arm.info().parameters {
            bail!(
                "{}: the model's parameters do not match its kernels' (a stale cache?)",
                loaded.origin
            );
        }
        Ok(Self {
            tape: shape_tape(&structure, points),
        })
    }

    /// The rows at time t, coordinates q.
    pub fn at(&self, arm: &dyn Dynamics, t: f64, q: &[f64]) -> Vec<ShapeRow> {
        let p = arm.params_at(t);
        let out = self.tape.eval(t, q, &p);
        let pose = |k: usize| -> [f64; ROW] { std::array::from_fn(|i| out[k * ROW + i]) };
        let mut rows = Vec::new();
        let mut k = 0;
        for a in &self.tape.arms {
            let part = if a.name.is_empty() { "arm" } else { &a.name };
            for (j, s) in a.arc_lengths(&p).into_iter().enumerate() {
                rows.push(ShapeRow {
                    part: part.to_string(),
                    point: j,
                    s,
                    pose: pose(k),
                });
                k += 1;
            }
        }
        for b in &self.tape.bodies {
            rows.push(ShapeRow {
                part: b.clone(),
                point: 0,
                s: 0.0,
                pose: pose(k),
            });
            k += 1;
        }
        if let Some(set) = arm.contact() {
            rows.extend(set.obstacles.iter().map(|o| ShapeRow {
                part: o.name.clone(),
                point: 0,
                s: 0.0,
                pose: obstacle_pose(o, t),
            }));
        }
        rows
    }

    /// `shape.csv` of a trajectory (times `t`, states `x`, q first),
    /// streamed to `w` (the text is many times the trajectory's size, a row
    /// per point: never held in memory).
    pub fn write_csv(
        &self,
        arm: &dyn Dynamics,
        t: &[f64],
        x: &[Vec<f64>],
        w: &mut impl std::io::Write,
    ) -> std::io::Result<()> {
        let n = arm.dof();
        Self::write_header(w)?;
        for (t, x) in t.iter().zip(x) {
            self.write_rows(arm, *t, &x[..n], w)?;
        }
        Ok(())
    }

    /// `shape.csv`'s header.
    pub fn write_header(w: &mut impl std::io::Write) -> std::io::Result<()> {
        writeln!(w, "t,part,point,s,x,y,z,qw,qx,qy,qz")
    }

    /// `shape.csv`'s rows at time t, coordinates q.
    pub fn write_rows(
        &self,
        arm: &dyn Dynamics,
        t: f64,
        q: &[f64],
        w: &mut impl std::io::Write,
    ) -> std::io::Result<()> {
        for r in self.at(arm, t, q) {
            write!(w, "{t:.9},{},{},{:.9}", r.part, r.point, r.s)?;
            for v in r.pose {
                write!(w, ",{v:.9e}")?;
            }
            writeln!(w)?;
        }
        Ok(())
    }
}

/// An obstacle's reference point (a plane's point, a centre) where its
/// motion has taken it at t, and the orientation of its shape: x along a
/// plane's normal or a cylinder's axis, a box's own axes.
pub fn obstacle_pose(o: &Obstacle, t: f64) -> [f64; ROW] {
    let d = o.motion.as_ref().map_or([0.0; 3], |m| m.at(t).0);
    let (at, r) = match &o.shape {
        contact::Shape::Plane { point, normal } => (*point, turn_x_onto(*normal)),
        contact::Shape::Sphere { center, .. } => (*center, IDENTITY),
        contact::Shape::Cylinder { center, axis, .. } => (*center, turn_x_onto(*axis)),
        contact::Shape::Box {
            center, rotation, ..
        } => (*center, *rotation),
    };
    let q = quaternion(&r);
    [
        at[0] + d[0],
        at[1] + d[1],
        at[2] + d[2],
        q[0],
        q[1],
        q[2],
        q[3],
    ]
}

const IDENTITY: [[f64; 3]; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// A rotation (rows) whose first column is the unit vector `a`.
fn turn_x_onto(a: [f64; 3]) -> [[f64; 3]; 3] {
    // The second axis: a unit vector across `a`, from the world axis least
    // along it.
    let k = (0..3)
        .min_by(|&i, &j| a[i].abs().total_cmp(&a[j].abs()))
        .unwrap_or(0);
    let mut e = [0.0; 3];
    e[k] = 1.0;
    let cross = |u: [f64; 3], v: [f64; 3]| {
        [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ]
    };
    let c = cross(a, e);
    let n = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
    let b = c.map(|x| x / n);
    let z = cross(a, b);
    std::array::from_fn(|i| [a[i], b[i], z[i]])
}

/// The unit quaternion (w, x, y, z) of a rotation matrix (rows), by the
/// largest of its four squared components (Shepperd).
pub fn quaternion(r: &[[f64; 3]; 3]) -> [f64; 4] {
    let tr = r[0][0] + r[1][1] + r[2][2];
    let cands = [tr, r[0][0], r[1][1], r[2][2]];
    let k = (0..4)
        .max_by(|&i, &j| cands[i].total_cmp(&cands[j]))
        .unwrap_or(0);
    let q = match k {
        0 => {
            let s = 2.0 * (1.0 + tr).sqrt();
            [
                0.25 * s,
                (r[2][1] - r[1][2]) / s,
                (r[0][2] - r[2][0]) / s,
                (r[1][0] - r[0][1]) / s,
            ]
        }
        1 => {
            let s = 2.0 * (1.0 + r[0][0] - r[1][1] - r[2][2]).sqrt();
            [
                (r[2][1] - r[1][2]) / s,
                0.25 * s,
                (r[0][1] + r[1][0]) / s,
                (r[0][2] + r[2][0]) / s,
            ]
        }
        2 => {
            let s = 2.0 * (1.0 - r[0][0] + r[1][1] - r[2][2]).sqrt();
            [
                (r[0][2] - r[2][0]) / s,
                (r[0][1] + r[1][0]) / s,
                0.25 * s,
                (r[1][2] + r[2][1]) / s,
            ]
        }
        _ => {
            let s = 2.0 * (1.0 - r[0][0] - r[1][1] + r[2][2]).sqrt();
            [
                (r[1][0] - r[0][1]) / s,
                (r[0][2] + r[2][0]) / s,
                (r[1][2] + r[2][1]) / s,
                0.25 * s,
            ]
        }
    };
    // w >= 0: one of the two quaternions of the rotation, always the same.
    if q[0] < 0.0 { q.map(|x| -x) } else { q }
}

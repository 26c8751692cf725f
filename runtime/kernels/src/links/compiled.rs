//! A link cell as compiled into a binary: its three kernels by function
//! pointer, found by key (`eomgen::build::cell_key`). The `linked` module runs
//! the recursion over such cells for chains no compiled-in model has.
//!
//! Invariant: a key names a cell's three tapes (cell, tangent, pose)
//! exactly, so a cell linked by key computes what the interpreter's tape of
//! that cell computes.

/// A cell kernel of one link: (x, xd, p, out).
pub type CellFn = fn(&[f64], &[f64], &[f64], &mut [f64]);
/// A cell kernel of four links in vector lanes: (x, xd, p, out).
pub type CellLanesFn = fn(&[[f64; 4]], &[[f64; 4]], &[[f64; 4]], &mut [[f64; 4]]);
/// A cell's tangent: (x, xd, dx, dxd, p, out).
pub type CellTangentFn = fn(&[f64], &[f64], &[f64], &[f64], &[f64], &mut [f64]);

/// One link cell as compiled into the binary, by its key: its three
/// kernels behind slices (a link's coordinates, rates, parameters).
#[derive(Clone, Copy)]
pub struct CompiledCell {
    pub key: &'static str,
    pub one: CellFn,
    /// Four links in vector lanes, where the model compiled them.
    pub four: Option<CellLanesFn>,
    pub tangent: CellTangentFn,
    pub pose: CellFn,
}

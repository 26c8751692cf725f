//! A link cell as compiled into a binary: its three kernels by function
//! pointer, found by key (`eomgen::build::kernel_key`). The `linked` module runs
//! the recursion over such cells for chains no compiled-in model has.
//!
//! Invariant: a key names a cell's three tapes (cell, tangent, pose)
//! exactly, so a cell linked by key computes what the interpreter's tape of
//! that cell computes.

/// A compiled kernel at local coordinates (a link cell's, a part's):
/// (x, xd, p, out).
pub type CellFn = fn(&[f64], &[f64], &[f64], &mut [f64]);
/// A cell kernel of four links in vector lanes: (x, xd, p, out).
pub type CellLanesFn = fn(&[[f64; 4]], &[[f64; 4]], &[[f64; 4]], &mut [[f64; 4]]);
/// Its tangent: (x, xd, dx, dxd, p, out).
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

/// A [`CompiledCell`] of a generated model's cell kernels (`name`,
/// `name_tangent`, `name_pose` over `n` coordinates), the slices of the
/// [`CellFn`] signatures turned into their arrays: the glue written once
/// here rather than in every generated file. `four`: the cell's lane
/// kernel behind a [`CellLanesFn`], or None.
#[macro_export]
macro_rules! compiled_cell {
    ($key:expr, $n:literal, $one:path, $tangent:path, $pose:path, $four:expr) => {
        $crate::links::CompiledCell {
            key: $key,
            one: |x, xd, p, out| {
                $one(
                    0.0,
                    x.try_into().expect("link coordinates"),
                    xd.try_into().expect("link rates"),
                    &[0.0; $n],
                    &[0.0; 2 * $n],
                    p.try_into().expect("cell parameters"),
                    out.try_into().expect("cell outputs"),
                )
            },
            four: $four,
            tangent: |x, xd, dx, dxd, p, out| {
                let mut dir = [0.0; 2 * $n];
                dir[..$n].copy_from_slice(dx);
                dir[$n..].copy_from_slice(dxd);
                $tangent(
                    0.0,
                    x.try_into().expect("link coordinates"),
                    xd.try_into().expect("link rates"),
                    &[0.0; $n],
                    &dir,
                    p.try_into().expect("cell parameters"),
                    out.try_into().expect("cell outputs and derivatives"),
                )
            },
            pose: |x, xd, p, out| {
                $pose(
                    0.0,
                    x.try_into().expect("link coordinates"),
                    xd.try_into().expect("link rates"),
                    &[0.0; $n],
                    &[0.0; 2 * $n],
                    p.try_into().expect("cell parameters"),
                    out.try_into().expect("pose outputs"),
                )
            },
        }
    };
}

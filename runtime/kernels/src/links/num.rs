//! The numbers the sweeps over cell outputs run on: `f64`, or `Dual`
//! where a sweep carries its derivative along a direction (the tangent,
//! the contact kernels' Jvp), and the 3-vector algebra written once over
//! both.

use std::ops::{Add, Mul, Sub};

use crate::dual::Dual;

pub(super) trait Num:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self>
{
    const ZERO: Self;
    /// A number that does not move along the direction.
    fn constant(v: f64) -> Self;
    /// Output `i` of a cell's outputs (`len` values, then, for a dual
    /// number, their derivatives).
    fn of_cell(out: &[f64], len: usize, i: usize) -> Self;
    /// A value `v` moving at `d` along the direction (an `f64` has none).
    fn moving(v: f64, d: f64) -> Self;
    fn sqrt(self) -> Self;
}

impl Num for f64 {
    const ZERO: f64 = 0.0;
    #[inline(always)]
    fn constant(v: f64) -> f64 {
        v
    }
    #[inline(always)]
    fn of_cell(out: &[f64], _len: usize, i: usize) -> f64 {
        out[i]
    }
    #[inline(always)]
    fn moving(v: f64, _d: f64) -> f64 {
        v
    }
    #[inline(always)]
    fn sqrt(self) -> f64 {
        f64::sqrt(self)
    }
}

impl Num for Dual {
    const ZERO: Dual = Dual::ZERO;
    #[inline(always)]
    fn constant(v: f64) -> Dual {
        Dual::constant(v)
    }
    #[inline(always)]
    fn of_cell(out: &[f64], len: usize, i: usize) -> Dual {
        Dual {
            v: out[i],
            d: out[len + i],
        }
    }
    #[inline(always)]
    fn moving(v: f64, d: f64) -> Dual {
        Dual { v, d }
    }
    #[inline(always)]
    fn sqrt(self) -> Dual {
        Dual::sqrt(self)
    }
}

#[inline(always)]
pub(super) fn add<N: Num>(a: [N; 3], b: [N; 3]) -> [N; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
#[inline(always)]
pub(super) fn sub<N: Num>(a: [N; 3], b: [N; 3]) -> [N; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
#[inline(always)]
pub(super) fn scale<N: Num>(s: N, a: [N; 3]) -> [N; 3] {
    [s * a[0], s * a[1], s * a[2]]
}
#[inline(always)]
pub(super) fn dot<N: Num>(a: [N; 3], b: [N; 3]) -> N {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
#[inline(always)]
pub(super) fn cross<N: Num>(a: [N; 3], b: [N; 3]) -> [N; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
#[inline(always)]
pub(super) fn mat_vec<N: Num>(r: &[[N; 3]; 3], v: [N; 3]) -> [N; 3] {
    [dot(r[0], v), dot(r[1], v), dot(r[2], v)]
}
#[inline(always)]
pub(super) fn mat_mat<N: Num>(a: &[[N; 3]; 3], b: &[[N; 3]; 3]) -> [[N; 3]; 3] {
    std::array::from_fn(|i| std::array::from_fn(|j| dot(a[i], [b[0][j], b[1][j], b[2][j]])))
}
/// Outputs `i..i + 3` of a cell's outputs as a vector.
#[inline(always)]
pub(super) fn cell_v3<N: Num>(out: &[f64], len: usize, i: usize) -> [N; 3] {
    [0, 1, 2].map(|k| N::of_cell(out, len, i + k))
}

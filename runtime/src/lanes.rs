//! Four values in the lanes of one vector: the type the generated lane
//! kernels (a link recursion's cells, four links at once) compute in.
//!
//! Every operation is the scalar one per lane (`mul_add` a fused
//! multiply-add, functions called lane by lane), so a lane kernel's
//! results have the bits of four calls of the scalar kernel; the arrays
//! of four let the compiler use 256-bit instructions.

use std::ops::{Add, Div, Mul, Neg, Sub};

#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(transparent)]
pub struct X4(pub [f64; 4]);

impl X4 {
    #[inline(always)]
    pub fn splat(x: f64) -> Self {
        X4([x; 4])
    }
    #[inline(always)]
    pub fn zip(self, b: Self, f: impl Fn(f64, f64) -> f64) -> Self {
        X4(std::array::from_fn(|l| f(self.0[l], b.0[l])))
    }
    #[inline(always)]
    pub fn map(self, f: impl Fn(f64) -> f64) -> Self {
        X4(self.0.map(f))
    }
    #[inline(always)]
    pub fn mul_add(self, b: Self, c: Self) -> Self {
        X4(std::array::from_fn(|l| self.0[l].mul_add(b.0[l], c.0[l])))
    }
    #[inline(always)]
    pub fn sqrt(self) -> Self {
        self.map(f64::sqrt)
    }
    #[inline(always)]
    pub fn abs(self) -> Self {
        self.map(f64::abs)
    }
    #[inline(always)]
    pub fn powi(self, n: i32) -> Self {
        self.map(|x| x.powi(n))
    }
    #[inline(always)]
    pub fn powf(self, b: Self) -> Self {
        self.zip(b, f64::powf)
    }
}

macro_rules! binary {
    ($($t:ident $f:ident $op:tt),*) => {$(
        impl $t for X4 {
            type Output = X4;
            #[inline(always)]
            fn $f(self, b: X4) -> X4 {
                X4(std::array::from_fn(|l| self.0[l] $op b.0[l]))
            }
        }
    )*};
}
binary!(Add add +, Sub sub -, Mul mul *, Div div /);

impl Neg for X4 {
    type Output = X4;
    #[inline(always)]
    fn neg(self) -> X4 {
        X4(self.0.map(|x| -x))
    }
}

/// A function of several orders (`special::sinc_orders`, ...) lane by lane.
#[inline(always)]
pub fn orders<const K: usize>(x: X4, f: impl Fn(f64) -> [f64; K]) -> [X4; K] {
    let v = x.0.map(f);
    std::array::from_fn(|k| X4(std::array::from_fn(|l| v[l][k])))
}

#[inline(always)]
pub fn sin_cos(x: X4) -> (X4, X4) {
    let v = x.0.map(crate::special::sin_cos);
    (X4(v.map(|p| p.0)), X4(v.map(|p| p.1)))
}

/// `rodrigues::family` lane by lane.
#[inline(always)]
pub fn family<const N: usize>(w: X4) -> [[X4; N]; crate::rodrigues::FAMILY_J] {
    let v = w.0.map(crate::rodrigues::family::<N>);
    std::array::from_fn(|j| std::array::from_fn(|n| X4(std::array::from_fn(|l| v[l][j][n]))))
}

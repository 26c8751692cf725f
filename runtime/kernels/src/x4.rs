//! `X4`: four values in the lanes of a 256-bit vector, as a [`Scalar`]:
//! the number type of a generic cell's lane instance (four links at once,
//! each with its own parameters, so its parameters are lanes too).
//!
//! Each operation is the one vector instruction that is, lane by lane, the
//! scalar operation (add, fused multiply-add, square root, ...), so the
//! lanes have the bits of four scalar calls; what has no instruction
//! (sines, the special functions) goes lane by lane through `lanes.rs`.
//! The methods are always inlined into the kernel, which is built for
//! `avx,fma` and run only after `cpu::require_fma`: an `X4` exists only
//! there, which is what makes the intrinsics below sound to call.
#![cfg(target_arch = "x86_64")]

use std::arch::x86_64::*;
use std::ops::{Add, Div, Mul, Neg, Sub};

use crate::lanes;
use crate::rodrigues::FAMILY_J;
use crate::scalar::Scalar;
use crate::special;

/// Four lanes.
#[derive(Clone, Copy, Debug)]
#[repr(transparent)]
pub struct X4(pub __m256d);

impl X4 {
    #[inline(always)]
    pub fn from_array(a: [f64; 4]) -> Self {
        X4(lanes::from_array(a))
    }

    /// Rows of lanes as vectors by a loop: `array::map`'s closure would
    /// stay out of line, not built for the kernel's target features.
    #[inline(always)]
    pub fn from_arrays<const N: usize>(a: &[[f64; 4]; N]) -> [Self; N] {
        let mut v = [<Self as Scalar>::c(0.0); N];
        for (v, a) in v.iter_mut().zip(a) {
            *v = X4::from_array(*a);
        }
        v
    }

    #[inline(always)]
    pub fn to_array(self) -> [f64; 4] {
        lanes::to_array(self.0)
    }

    #[inline(always)]
    fn map(self, f: impl Fn(f64) -> f64) -> Self {
        X4(lanes::map(self.0, f))
    }
}

/// One vector instruction on the lanes (SAFETY: module doc: an `X4` exists
/// only in code built for, and run on, a processor with AVX and FMA).
macro_rules! lanewise {
    ($($e:tt)*) => {
        X4(unsafe { $($e)* })
    };
}

macro_rules! binary {
    ($trait:ident, $f:ident, $intrinsic:ident) => {
        impl $trait for X4 {
            type Output = X4;
            #[inline(always)]
            fn $f(self, b: X4) -> X4 {
                lanewise!($intrinsic(self.0, b.0))
            }
        }
        impl $trait<f64> for X4 {
            type Output = X4;
            #[inline(always)]
            fn $f(self, b: f64) -> X4 {
                self.$f(X4::c(b))
            }
        }
    };
}

binary!(Add, add, _mm256_add_pd);
binary!(Sub, sub, _mm256_sub_pd);
binary!(Mul, mul, _mm256_mul_pd);
binary!(Div, div, _mm256_div_pd);

impl Neg for X4 {
    type Output = X4;
    #[inline(always)]
    fn neg(self) -> X4 {
        lanewise!(_mm256_xor_pd(self.0, _mm256_set1_pd(-0.0)))
    }
}

impl Scalar for X4 {
    type Param = X4;
    type Store = [f64; 4];
    #[inline(always)]
    fn store(self) -> [f64; 4] {
        self.to_array()
    }
    #[inline(always)]
    fn c(v: f64) -> Self {
        lanewise!(_mm256_set1_pd(v))
    }
    #[inline(always)]
    fn from_param(p: X4) -> Self {
        p
    }
    #[inline(always)]
    fn add_p(self, p: X4) -> Self {
        self + p
    }
    #[inline(always)]
    fn sub_p(self, p: X4) -> Self {
        self - p
    }
    #[inline(always)]
    fn rsub_p(self, p: X4) -> Self {
        p - self
    }
    #[inline(always)]
    fn mul_p(self, p: X4) -> Self {
        self * p
    }
    #[inline(always)]
    fn div_p(self, p: X4) -> Self {
        self / p
    }
    #[inline(always)]
    fn rdiv_p(self, p: X4) -> Self {
        p / self
    }
    #[inline(always)]
    fn sub_from(self, a: f64) -> Self {
        X4::c(a) - self
    }
    #[inline(always)]
    fn div_into(self, a: f64) -> Self {
        X4::c(a) / self
    }
    #[inline(always)]
    fn mul_add(self, b: Self, c: Self) -> Self {
        lanewise!(_mm256_fmadd_pd(self.0, b.0, c.0))
    }
    #[inline(always)]
    fn powi(self, n: i32) -> Self {
        self.map(|x| x.powi(n))
    }
    #[inline(always)]
    fn powf(self, b: Self) -> Self {
        let (a, b) = (self.to_array(), b.to_array());
        X4::from_array(std::array::from_fn(|l| a[l].powf(b[l])))
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        lanewise!(_mm256_sqrt_pd(self.0))
    }
    #[inline(always)]
    fn sin_cos(self) -> (Self, Self) {
        let (s, c) = special::sin_cos_x4(self.to_array());
        (X4::from_array(s), X4::from_array(c))
    }
    #[inline(always)]
    fn sin(self) -> Self {
        self.sin_cos().0
    }
    #[inline(always)]
    fn cos(self) -> Self {
        self.sin_cos().1
    }
    #[inline(always)]
    fn tan(self) -> Self {
        self.map(f64::tan)
    }
    #[inline(always)]
    fn exp(self) -> Self {
        self.map(f64::exp)
    }
    #[inline(always)]
    fn ln(self) -> Self {
        self.map(f64::ln)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        lanewise!(_mm256_andnot_pd(_mm256_set1_pd(-0.0), self.0))
    }
    #[inline(always)]
    fn sign(self) -> Self {
        self.map(special::sign)
    }
    #[inline(always)]
    fn sinc(self, k: u8) -> Self {
        self.map(|x| special::sinc(k, x))
    }
    #[inline(always)]
    fn cosc(self, k: u8) -> Self {
        self.map(|x| special::cosc(k, x))
    }
    #[inline(always)]
    fn sinc_rem(self, k: u8) -> Self {
        self.map(|x| special::sinc_rem(k, x))
    }
    #[inline(always)]
    fn rodrigues(self, j: u8, n: u8) -> Self {
        self.map(|x| crate::rodrigues::rodrigues(j, n, x))
    }
    #[inline(always)]
    fn sinc_orders<const K: usize>(self) -> [Self; K] {
        X4::from_arrays(&special::sinc_orders_x4::<K>(self.to_array()))
    }
    #[inline(always)]
    fn cosc_orders<const K: usize>(self) -> [Self; K] {
        X4::from_arrays(&special::cosc_orders_x4::<K>(self.to_array()))
    }
    #[inline(always)]
    fn sinc_rem_orders<const K: usize>(self) -> [Self; K] {
        X4::from_arrays(&special::sinc_rem_orders_x4::<K>(self.to_array()))
    }
    #[inline(always)]
    fn rodrigues_family<const N: usize>(self) -> [[Self; N]; FAMILY_J] {
        // SAFETY: as `lanewise!`.
        let v = unsafe { lanes::family::<N>(self.0) };
        // A loop, as `from_arrays`: the maps' closures stay out of line.
        let mut c = [[<Self as Scalar>::c(0.0); N]; FAMILY_J];
        for (c, v) in c.iter_mut().zip(&v) {
            for (c, v) in c.iter_mut().zip(v) {
                *c = X4(*v);
            }
        }
        c
    }
}

//! The numbers a generic kernel is written over: `f64` for its values,
//! [`Dual`] for its values and their derivatives along a direction, and
//! (lanes.rs) `X4` for four evaluations in the lanes of a vector.
//!
//! The generator emits a kernel whose tangent is needed (a link cell, an
//! eba part, the contact points) once, over `S: Scalar`, and instantiates
//! it twice: the `f64` instance is the very code a plain kernel would be
//! (each method below is the call the plain kernel makes), the `Dual`
//! instance its tangent. Parameters and constants stay `f64`: an operation
//! on them alone costs what it costs in the plain kernel, and one with a
//! moving operand uses the mixed operators.

use std::ops::{Add, Div, Mul, Neg, Sub};

use crate::dual::Dual;
use crate::rodrigues::{self, FAMILY_J};
use crate::special;

/// What the generated generic kernels call. `f64 op S` never appears: the
/// generator writes commutative operations with the moving operand first
/// and the others through [`Scalar::sub_from`] and [`Scalar::div_into`];
/// an operation of a moving value and a parameter through the `_p`
/// methods (for `f64` and `Dual`, whose parameters are `f64`, the mixed
/// operators; for lanes, the lanes' own).
pub trait Scalar:
    Copy
    + Add<Output = Self>
    + Add<f64, Output = Self>
    + Sub<Output = Self>
    + Sub<f64, Output = Self>
    + Mul<Output = Self>
    + Mul<f64, Output = Self>
    + Div<Output = Self>
    + Div<f64, Output = Self>
    + Neg<Output = Self>
{
    /// What the parameters are: `f64`, or for the lane kernels (four
    /// links at once, each with its own parameters) the lanes themselves.
    type Param: Scalar;
    /// How a lane kernel's outputs are stored: the value itself, or for
    /// lanes an array, so that the kernel writes its caller's rows in place.
    type Store: Copy;
    fn store(self) -> Self::Store;
    /// A constant.
    fn c(v: f64) -> Self;
    /// A constant as a parameter-typed value.
    #[inline(always)]
    fn pc(v: f64) -> Self::Param {
        <Self::Param as Scalar>::c(v)
    }
    fn from_param(p: Self::Param) -> Self;
    fn add_p(self, p: Self::Param) -> Self;
    fn sub_p(self, p: Self::Param) -> Self;
    /// p - self.
    fn rsub_p(self, p: Self::Param) -> Self;
    fn mul_p(self, p: Self::Param) -> Self;
    fn div_p(self, p: Self::Param) -> Self;
    /// p / self.
    fn rdiv_p(self, p: Self::Param) -> Self;
    /// a - self.
    fn sub_from(self, a: f64) -> Self;
    /// a / self.
    fn div_into(self, a: f64) -> Self;
    fn mul_add(self, b: Self, c: Self) -> Self;
    fn powi(self, n: i32) -> Self;
    fn powf(self, b: Self) -> Self;
    fn sqrt(self) -> Self;
    fn sin_cos(self) -> (Self, Self);
    fn sin(self) -> Self;
    fn cos(self) -> Self;
    fn tan(self) -> Self;
    fn exp(self) -> Self;
    fn ln(self) -> Self;
    fn abs(self) -> Self;
    fn sign(self) -> Self;
    fn sinc(self, k: u8) -> Self;
    fn cosc(self, k: u8) -> Self;
    fn sinc_rem(self, k: u8) -> Self;
    fn rodrigues(self, j: u8, n: u8) -> Self;
    fn sinc_orders<const K: usize>(self) -> [Self; K];
    fn cosc_orders<const K: usize>(self) -> [Self; K];
    fn sinc_rem_orders<const K: usize>(self) -> [Self; K];
    fn rodrigues_family<const N: usize>(self) -> [[Self; N]; FAMILY_J];
}

/// The parameter side of a `Scalar` whose parameters are `f64` (`f64`
/// and `Dual`): the mixed operators, and outputs stored as they are.
macro_rules! f64_parameters {
    ($store:ty) => {
        type Param = f64;
        type Store = $store;
        #[inline(always)]
        fn store(self) -> Self {
            self
        }
        #[inline(always)]
        fn from_param(p: f64) -> Self {
            Self::c(p)
        }
        #[inline(always)]
        fn add_p(self, p: f64) -> Self {
            self + p
        }
        #[inline(always)]
        fn sub_p(self, p: f64) -> Self {
            self - p
        }
        #[inline(always)]
        fn rsub_p(self, p: f64) -> Self {
            self.sub_from(p)
        }
        #[inline(always)]
        fn mul_p(self, p: f64) -> Self {
            self * p
        }
        #[inline(always)]
        fn div_p(self, p: f64) -> Self {
            self / p
        }
        #[inline(always)]
        fn rdiv_p(self, p: f64) -> Self {
            self.div_into(p)
        }
    };
}

impl Scalar for f64 {
    f64_parameters!(f64);
    #[inline(always)]
    fn c(v: f64) -> Self {
        v
    }
    #[inline(always)]
    fn sub_from(self, a: f64) -> Self {
        a - self
    }
    #[inline(always)]
    fn div_into(self, a: f64) -> Self {
        a / self
    }
    #[inline(always)]
    fn mul_add(self, b: Self, c: Self) -> Self {
        f64::mul_add(self, b, c)
    }
    #[inline(always)]
    fn powi(self, n: i32) -> Self {
        f64::powi(self, n)
    }
    #[inline(always)]
    fn powf(self, b: Self) -> Self {
        f64::powf(self, b)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    #[inline(always)]
    fn sin_cos(self) -> (Self, Self) {
        special::sin_cos(self)
    }
    #[inline(always)]
    fn sin(self) -> Self {
        special::sin(self)
    }
    #[inline(always)]
    fn cos(self) -> Self {
        special::cos(self)
    }
    #[inline(always)]
    fn tan(self) -> Self {
        f64::tan(self)
    }
    #[inline(always)]
    fn exp(self) -> Self {
        f64::exp(self)
    }
    #[inline(always)]
    fn ln(self) -> Self {
        f64::ln(self)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f64::abs(self)
    }
    #[inline(always)]
    fn sign(self) -> Self {
        special::sign(self)
    }
    #[inline(always)]
    fn sinc(self, k: u8) -> Self {
        special::sinc(k, self)
    }
    #[inline(always)]
    fn cosc(self, k: u8) -> Self {
        special::cosc(k, self)
    }
    #[inline(always)]
    fn sinc_rem(self, k: u8) -> Self {
        special::sinc_rem(k, self)
    }
    #[inline(always)]
    fn rodrigues(self, j: u8, n: u8) -> Self {
        rodrigues::rodrigues(j, n, self)
    }
    #[inline(always)]
    fn sinc_orders<const K: usize>(self) -> [Self; K] {
        special::sinc_orders::<K>(self)
    }
    #[inline(always)]
    fn cosc_orders<const K: usize>(self) -> [Self; K] {
        special::cosc_orders::<K>(self)
    }
    #[inline(always)]
    fn sinc_rem_orders<const K: usize>(self) -> [Self; K] {
        special::sinc_rem_orders::<K>(self)
    }
    #[inline(always)]
    fn rodrigues_family<const N: usize>(self) -> [[Self; N]; FAMILY_J] {
        rodrigues::family::<N>(self)
    }
}

impl Scalar for Dual {
    f64_parameters!(Dual);
    #[inline(always)]
    fn c(v: f64) -> Self {
        Dual::constant(v)
    }
    #[inline(always)]
    fn sub_from(self, a: f64) -> Self {
        Dual::constant(a) - self
    }
    #[inline(always)]
    fn div_into(self, a: f64) -> Self {
        Dual::constant(a) / self
    }
    #[inline(always)]
    fn mul_add(self, b: Self, c: Self) -> Self {
        Dual::mul_add(self, b, c)
    }
    #[inline(always)]
    fn powi(self, n: i32) -> Self {
        Dual::powi(self, n)
    }
    #[inline(always)]
    fn powf(self, b: Self) -> Self {
        Dual::powf(self, b)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        Dual::sqrt(self)
    }
    #[inline(always)]
    fn sin_cos(self) -> (Self, Self) {
        Dual::sin_cos(self)
    }
    #[inline(always)]
    fn sin(self) -> Self {
        Dual::sin_cos(self).0
    }
    #[inline(always)]
    fn cos(self) -> Self {
        Dual::sin_cos(self).1
    }
    #[inline(always)]
    fn tan(self) -> Self {
        Dual::tan(self)
    }
    #[inline(always)]
    fn exp(self) -> Self {
        Dual::exp(self)
    }
    #[inline(always)]
    fn ln(self) -> Self {
        Dual::ln(self)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        Dual::abs(self)
    }
    #[inline(always)]
    fn sign(self) -> Self {
        Dual::sign(self)
    }
    #[inline(always)]
    fn sinc(self, k: u8) -> Self {
        Dual::sinc(self, k)
    }
    #[inline(always)]
    fn cosc(self, k: u8) -> Self {
        Dual::cosc(self, k)
    }
    #[inline(always)]
    fn sinc_rem(self, k: u8) -> Self {
        Dual::sinc_rem(self, k)
    }
    #[inline(always)]
    fn rodrigues(self, j: u8, n: u8) -> Self {
        Dual::rodrigues(self, j, n)
    }
    #[inline(always)]
    fn sinc_orders<const K: usize>(self) -> [Self; K] {
        let next = special::sinc(K as u8, self.v);
        self.orders(special::sinc_orders::<K>(self.v), next)
    }
    #[inline(always)]
    fn cosc_orders<const K: usize>(self) -> [Self; K] {
        let next = special::cosc(K as u8, self.v);
        self.orders(special::cosc_orders::<K>(self.v), next)
    }
    #[inline(always)]
    fn sinc_rem_orders<const K: usize>(self) -> [Self; K] {
        let next = special::sinc_rem(K as u8, self.v);
        self.orders(special::sinc_rem_orders::<K>(self.v), next)
    }
    #[inline(always)]
    fn rodrigues_family<const N: usize>(self) -> [[Self; N]; FAMILY_J] {
        Dual::rodrigues_family::<N>(self)
    }
}

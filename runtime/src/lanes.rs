//! Four values in the lanes of one 256-bit vector: what the generated
//! lane kernels (a link recursion's cells, four links at once) compute in.
//!
//! The generated code calls the x86-64 intrinsics itself (each tape
//! operation is one: add, fused multiply-add, square root, ...), under
//! the kernel's `avx,fma` target features, so that every lane is exactly
//! the scalar operation and a lane kernel's results have the bits of four
//! calls of the scalar kernel. What has no vector instruction (sines, the
//! Rodrigues family, ...) goes lane by lane through these helpers.
#![cfg(target_arch = "x86_64")]

use std::arch::x86_64::__m256d;

/// The lanes as an array.
#[inline(always)]
pub fn to_array(v: __m256d) -> [f64; 4] {
    // SAFETY: both are 32 bytes of four f64s, every bit pattern valid.
    unsafe { std::mem::transmute::<__m256d, [f64; 4]>(v) }
}

/// An array into lanes.
#[inline(always)]
pub fn from_array(a: [f64; 4]) -> __m256d {
    // SAFETY: as `to_array`.
    unsafe { std::mem::transmute::<[f64; 4], __m256d>(a) }
}

/// `f` lane by lane.
#[inline(always)]
pub fn map(v: __m256d, f: impl Fn(f64) -> f64) -> __m256d {
    from_array(to_array(v).map(f))
}

/// A function of several orders (`special::sinc_orders`, ...) lane by lane.
#[inline(always)]
pub fn orders<const K: usize>(x: __m256d, f: impl Fn(f64) -> [f64; K]) -> [__m256d; K] {
    let v = to_array(x).map(f);
    std::array::from_fn(|k| from_array(std::array::from_fn(|l| v[l][k])))
}

/// `special::sin_cos` lane by lane.
#[inline(always)]
pub fn sin_cos(x: __m256d) -> (__m256d, __m256d) {
    let v = to_array(x).map(crate::special::sin_cos);
    (from_array(v.map(|p| p.0)), from_array(v.map(|p| p.1)))
}

/// `rodrigues::family` of the four lanes (`rodrigues::family_x4`).
///
/// # Safety
/// The processor must have AVX and FMA (code built with both calls it
/// without `unsafe`).
#[target_feature(enable = "avx,fma")]
#[inline]
pub fn family<const N: usize>(w: __m256d) -> [[__m256d; N]; crate::rodrigues::FAMILY_J] {
    crate::rodrigues::family_x4::<N>(w)
}

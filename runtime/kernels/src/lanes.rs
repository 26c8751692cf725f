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

use crate::rodrigues::{self, FAMILY_J, FAMILY_ORDERS, INV_FACTORIAL, SERIES_BELOW, TOPS};

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

// The helpers loop rather than call `array::map` or `from_fn`: those
// stay out of line in a kernel built for `avx,fma` (they are not), and
// cost a quarter of a planar arm's mass + bias.

/// `f` lane by lane.
#[inline(always)]
pub fn map(v: __m256d, f: impl Fn(f64) -> f64) -> __m256d {
    let mut a = to_array(v);
    for x in &mut a {
        *x = f(*x);
    }
    from_array(a)
}

/// `rodrigues::family` of the four lanes (`rodrigues::family_x4`).
///
/// # Safety
/// The processor must have AVX and FMA (code built with both calls it
/// without `unsafe`).
#[target_feature(enable = "avx,fma")]
#[inline]
pub fn family<const N: usize>(w: __m256d) -> [[__m256d; N]; FAMILY_J] {
    family_x4::<N>(w)
}

/// [`family`](crate::rodrigues::family) of four arguments in the lanes of a vector, with the bits
/// of four scalar calls: the same sums in the same order (the scalar code
/// does not fuse them either), lane by lane where the lanes would take
/// different branches.
///
/// # Safety
/// The processor must have AVX and FMA (code built with both calls it
/// without `unsafe`).
#[target_feature(enable = "avx,fma")]
#[inline]
pub fn family_x4<const N: usize>(
    w: std::arch::x86_64::__m256d,
) -> [[std::arch::x86_64::__m256d; N]; FAMILY_J] {
    use std::arch::x86_64::*;
    const { assert!(N <= FAMILY_ORDERS) };
    let lanes = to_array(w);
    let below = |limit: f64| lanes.iter().all(|x| x.abs() < limit);
    let tops: [[__m256d; N]; 2] = if below(1.0) {
        tops_x4::<N, 8>(w)
    } else if below(SERIES_BELOW) && lanes.iter().all(|x| x.abs() >= 1.0) {
        tops_x4::<N, 12>(w)
    } else {
        let v = lanes.map(rodrigues::family::<N>);
        return std::array::from_fn(|j| {
            std::array::from_fn(|n| from_array(std::array::from_fn(|l| v[l][j][n])))
        });
    };
    let mut c = [[_mm256_setzero_pd(); N]; FAMILY_J];
    c[FAMILY_J - 2] = tops[0];
    c[FAMILY_J - 1] = tops[1];
    for j in (0..FAMILY_J - 2).rev() {
        for n in 0..N {
            let wc = _mm256_mul_pd(w, c[j + 2][n]);
            c[j][n] = if n == 0 {
                _mm256_sub_pd(_mm256_set1_pd(INV_FACTORIAL[j]), wc)
            } else {
                let neg = _mm256_xor_pd(wc, _mm256_set1_pd(-0.0));
                _mm256_sub_pd(
                    neg,
                    _mm256_mul_pd(_mm256_set1_pd(n as f64), c[j + 2][n - 1]),
                )
            };
        }
    }
    c
}

#[target_feature(enable = "avx,fma")]
#[inline]
fn tops_x4<const N: usize, const T: usize>(
    w: std::arch::x86_64::__m256d,
) -> [[std::arch::x86_64::__m256d; N]; 2] {
    use std::arch::x86_64::*;
    let mut s = [[_mm256_setzero_pd(); N]; 2];
    for k in (0..T).rev() {
        for t in 0..2 {
            for n in 0..N {
                s[t][n] = _mm256_add_pd(_mm256_mul_pd(s[t][n], w), _mm256_set1_pd(TOPS[t][n][k]));
            }
        }
    }
    s
}

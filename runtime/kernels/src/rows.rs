//! Rows over an arm's coordinates, fixed length `N` (a multiple of four),
//! combined with 256-bit fused multiply-adds where the processor has them.
//!
//! The compiler's vectoriser leaves these loops scalar inside the link
//! recursion's large inlined body (measured: benches/interleaved.rs), so the
//! vector form is written out. In `add_combination` every lane is the
//! scalar `mul_add`, so both forms give the same bits; `dot2` adds its
//! four partial sums at the end, so its forms agree to round-off only.

/// Whether [`add_combination`] may use its vector form here.
pub fn simd_available() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx") && std::arch::is_x86_feature_detected!("fma")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// y += sum_k coef[k] rows[k]. `simd`: [`simd_available`].
#[inline(always)]
pub fn add_combination<const N: usize, const K: usize>(
    simd: bool,
    y: &mut [f64; N],
    coef: &[f64; K],
    rows: [&[f64; N]; K],
) {
    #[cfg(target_arch = "x86_64")]
    if simd {
        // SAFETY: the caller has checked that the processor has AVX and FMA.
        unsafe { add_combination_avx(y, coef, rows) };
        return;
    }
    let _ = simd;
    for (k, row) in rows.iter().enumerate() {
        for c in 0..N {
            y[c] = coef[k].mul_add(row[c], y[c]);
        }
    }
}

/// (w . a, w . b).
#[inline(always)]
pub fn dot2<const N: usize>(simd: bool, w: &[f64; N], a: &[f64; N], b: &[f64; N]) -> (f64, f64) {
    #[cfg(target_arch = "x86_64")]
    if simd {
        // SAFETY: the caller has checked that the processor has AVX and FMA.
        return unsafe { dot2_avx(w, a, b) };
    }
    let _ = simd;
    let (mut x, mut y) = (0.0, 0.0);
    for c in 0..N {
        x = w[c].mul_add(a[c], x);
        y = w[c].mul_add(b[c], y);
    }
    (x, y)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx,fma")]
#[inline]
unsafe fn dot2_avx<const N: usize>(w: &[f64; N], a: &[f64; N], b: &[f64; N]) -> (f64, f64) {
    use std::arch::x86_64::*;
    const { assert!(N.is_multiple_of(4), "rows are whole vectors") };
    let (mut x, mut y) = (_mm256_setzero_pd(), _mm256_setzero_pd());
    for at in (0..N).step_by(4) {
        // SAFETY: at + 4 <= N for every row.
        unsafe {
            let wv = _mm256_loadu_pd(w.as_ptr().add(at));
            x = _mm256_fmadd_pd(wv, _mm256_loadu_pd(a.as_ptr().add(at)), x);
            y = _mm256_fmadd_pd(wv, _mm256_loadu_pd(b.as_ptr().add(at)), y);
        }
    }
    let (x, y) = (crate::lanes::to_array(x), crate::lanes::to_array(y));
    ((x[0] + x[1]) + (x[2] + x[3]), (y[0] + y[1]) + (y[2] + y[3]))
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx,fma")]
#[inline]
unsafe fn add_combination_avx<const N: usize, const K: usize>(
    y: &mut [f64; N],
    coef: &[f64; K],
    rows: [&[f64; N]; K],
) {
    use std::arch::x86_64::*;
    const { assert!(N.is_multiple_of(4), "rows are whole vectors") };
    let c: [__m256d; K] = std::array::from_fn(|k| _mm256_set1_pd(coef[k]));
    for at in (0..N).step_by(4) {
        // SAFETY: at + 4 <= N for every row.
        unsafe {
            let mut acc = _mm256_loadu_pd(y.as_ptr().add(at));
            for k in 0..K {
                acc = _mm256_fmadd_pd(c[k], _mm256_loadu_pd(rows[k].as_ptr().add(at)), acc);
            }
            _mm256_storeu_pd(y.as_mut_ptr().add(at), acc);
        }
    }
}

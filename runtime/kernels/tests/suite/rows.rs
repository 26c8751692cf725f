//! Row combinations and dot products against exact sums (`rows`).

use runtime_kernels::rows::*;

/// Both forms of the dot products against a sum in exact rationals
/// (small integers over a power of two: every product and partial
/// sum is exact in f64, so any order gives the one true value).
#[test]
fn dot_products_match_an_exact_sum() {
    let w: [f64; 12] = std::array::from_fn(|c| (c as f64 - 5.0) / 8.0);
    let a: [f64; 12] = std::array::from_fn(|c| (3 * c % 7) as f64 / 4.0 - 1.0);
    let b: [f64; 12] = std::array::from_fn(|c| (c * c % 5) as f64 / 2.0);
    // By hand: sum over c of w_c a_c and w_c b_c in integers.
    let (mut ia, mut ib) = (0i64, 0i64);
    for c in 0..12i64 {
        ia += (c - 5) * (3 * c % 7 - 4);
        ib += (c - 5) * (c * c % 5);
    }
    let want = (ia as f64 / 32.0, ib as f64 / 16.0);
    assert_eq!(dot2(false, &w, &a, &b), want);
    assert_eq!(dot2(simd_available(), &w, &a, &b), want);
}

/// The vector form against the scalar one, bit for bit.
#[test]
fn vector_and_scalar_combinations_agree() {
    let rows: [[f64; 8]; 3] =
        std::array::from_fn(|k| std::array::from_fn(|c| (k * 8 + c) as f64 * 0.37 - 2.1));
    let coef = [1.5, -0.25, 3.125e-3];
    let start: [f64; 8] = std::array::from_fn(|c| c as f64 / 7.0);
    let (mut a, mut b) = (start, start);
    add_combination(false, &mut a, &coef, [&rows[0], &rows[1], &rows[2]]);
    add_combination(
        simd_available(),
        &mut b,
        &coef,
        [&rows[0], &rows[1], &rows[2]],
    );
    let mut want = start;
    for k in 0..3 {
        for c in 0..8 {
            want[c] = coef[k].mul_add(rows[k][c], want[c]);
        }
    }
    assert_eq!(a, want);
    assert_eq!(b, want);
}

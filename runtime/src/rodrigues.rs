//! The Rodrigues coefficient functions of a rotation vector, as functions
//! of its squared angle, and all their derivatives.
//!
//! For a rotation vector rho with w = |rho|^2 and K = [rho]x,
//!
//!   exp(K)             = I + c1(w) K + c2(w) K^2        (the rotation)
//!   int_0^1 exp(sK) ds = I + c2(w) K + c3(w) K^2        (an arc's chord)
//!   int_0^1 int_0^s    = I/2 + c3(w) K + c4(w) K^2      (an arc's centroid)
//!
//! with c_j(w) = sum_k (-w)^k / (2k + j)!: c0 = cos theta, c1 = sin theta /
//! theta, c2 = (1 - cos theta) / theta^2, c3 = (theta - sin theta) /
//! theta^3. As functions of w = theta^2 they are entire: the straight
//! configuration w = 0 is an ordinary point for every derivative, which is
//! what makes 3D pcc, ebr and rom kinematics singularity-free. (Written in
//! theta they would need sqrt(w), whose derivative is infinite at 0.)
//!
//! The series is summed for |w| below [`SERIES_BELOW`]; beyond it the closed
//! forms in theta and the recurrence 2 w c_j' = c_{j-1} - j c_j (from the
//! series term by term) give every order.

/// Below this |w| (|theta| < 3) the series is used: its largest term is at
/// most 1.5 times the value's scale there, so it loses under one digit.
pub const SERIES_BELOW: f64 = 9.0;

/// Largest `j` and derivative order the generator uses (bounds the tables).
pub const MAX_J: u8 = 6;

/// d^n/dw^n c_j(w).
#[inline]
pub fn rodrigues(j: u8, n: u8, w: f64) -> f64 {
    if w.abs() < SERIES_BELOW {
        if j <= TABLE_J && n <= TABLE_N {
            horner(&TABLE[j as usize][n as usize], terms_for(w), w)
        } else {
            series(j, n, w)
        }
    } else {
        closed(j, n, w)
    }
}

/// Orders and indices with precomputed series (what the kernels use).
const TABLE_J: u8 = 6;
const TABLE_N: u8 = 4;
const TABLE_TERMS: usize = 22;

/// TABLE[j][n][k]: (-1)^(k+n) (k+n)! / (k! (2k + 2n + j)!), the coefficient
/// of w^k in d^n/dw^n c_j.
static TABLE: [[[f64; TABLE_TERMS]; TABLE_N as usize + 1]; TABLE_J as usize + 1] = table();

const fn table() -> [[[f64; TABLE_TERMS]; TABLE_N as usize + 1]; TABLE_J as usize + 1] {
    let mut t = [[[0.0; TABLE_TERMS]; TABLE_N as usize + 1]; TABLE_J as usize + 1];
    let mut j = 0;
    while j <= TABLE_J as usize {
        let mut n = 0;
        while n <= TABLE_N as usize {
            let mut k = 0;
            while k < TABLE_TERMS {
                // (k+n)! / k! / (2k+2n+j)!, accumulated as a product.
                let mut c = 1.0;
                let mut i = k + 1;
                while i <= k + n {
                    c *= i as f64;
                    i += 1;
                }
                let mut i = 1;
                while i <= 2 * k + 2 * n + j {
                    c /= i as f64;
                    i += 1;
                }
                t[j][n][k] = if (k + n) % 2 == 0 { c } else { -c };
                k += 1;
            }
            n += 1;
        }
        j += 1;
    }
    t
}

/// Terms for round-off accuracy at |w| (the omitted tail is below 1e-17
/// of c_j(0) for every tabled order; checked against the long series in
/// the tests).
#[inline]
fn terms_for(w: f64) -> usize {
    let a = w.abs();
    if a < 0.25 {
        11
    } else if a < 1.0 {
        13
    } else if a < 4.0 {
        17
    } else {
        TABLE_TERMS
    }
}

#[inline]
fn horner(c: &[f64; TABLE_TERMS], terms: usize, w: f64) -> f64 {
    let mut s = 0.0;
    for &k in c[..terms].iter().rev() {
        s = s * w + k;
    }
    s
}

/// [`rodrigues`] of orders 0..N of one c_j at one argument, bit for bit.
#[inline]
pub fn rodrigues_orders<const N: usize>(j: u8, w: f64) -> [f64; N] {
    std::array::from_fn(|n| rodrigues(j, n as u8, w))
}

/// sum_k (-1)^(k+n) (k+n)! / (k! (2k + 2n + j)!) w^k, summed until the
/// terms no longer change the sum.
fn series(j: u8, n: u8, w: f64) -> f64 {
    let (j, n) = (j as u32, n as u32);
    // First coefficient (-1)^n n! / (2n + j)!.
    let mut term = if n % 2 == 0 { 1.0 } else { -1.0 };
    for i in 1..=n {
        term *= i as f64;
    }
    for i in 1..=(2 * n + j) {
        term /= i as f64;
    }
    let mut sum = term;
    let mut k = 0u32;
    loop {
        // ratio of coefficient k+1 to k
        let a = (2 * (k + n) + j) as f64;
        term *= -w * (k + n + 1) as f64 / ((k + 1) as f64 * (a + 1.0) * (a + 2.0));
        let next = sum + term;
        k += 1;
        if next == sum || k > 60 {
            return next;
        }
        sum = next;
    }
}

#[cold]
#[inline(never)]
fn closed(j: u8, n: u8, w: f64) -> f64 {
    let (j, n) = (j as usize, n as usize);
    let theta = w.abs().sqrt();
    let (c0, c1) = if w > 0.0 {
        (theta.cos(), theta.sin() / theta)
    } else {
        (theta.cosh(), theta.sinh() / theta)
    };
    // g[m][i]: order m of c_i, i = 0..=j.
    let mut g = vec![vec![0.0; j + 1]; n + 1];
    g[0][0] = c0;
    if j >= 1 {
        g[0][1] = c1;
    }
    for i in 2..=j {
        g[0][i] = (1.0 / factorial(i as u32 - 2) - g[0][i - 2]) / w;
    }
    for m in 0..n {
        g[m + 1][0] = if j >= 1 {
            -g[m][1] / 2.0
        } else {
            // c0' = -c1 / 2, computed directly.
            -rodrigues(1, m as u8, w) / 2.0
        };
        for i in 1..=j {
            g[m + 1][i] = (g[m][i - 1] - (i + 2 * m) as f64 * g[m][i]) / (2.0 * w);
        }
    }
    g[n][j]
}

fn factorial(n: u32) -> f64 {
    (1..=n).map(|i| i as f64).product()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The closed forms in theta, written out.
    fn c(j: u8, w: f64) -> f64 {
        let t = w.sqrt();
        match j {
            0 => t.cos(),
            1 => t.sin() / t,
            2 => (1.0 - t.cos()) / w,
            3 => (t - t.sin()) / (w * t),
            _ => unreachable!(),
        }
    }

    #[test]
    fn values_match_the_closed_forms_in_theta() {
        for &w in &[0.3f64, 1.0, 2.5, 8.9, 9.1, 20.0, 80.0] {
            for j in 0..=3 {
                let (a, b) = (rodrigues(j, 0, w), c(j, w));
                assert!(
                    (a - b).abs() <= 1e-14 * b.abs().max(0.1),
                    "c{j}({w}): {a} vs {b}"
                );
            }
        }
    }

    #[test]
    fn limits_at_zero_are_the_series_constants() {
        assert_eq!(rodrigues(0, 0, 0.0), 1.0);
        assert_eq!(rodrigues(1, 0, 0.0), 1.0);
        assert_eq!(rodrigues(2, 0, 0.0), 0.5);
        assert_eq!(rodrigues(3, 0, 0.0), 1.0 / 6.0);
        assert_eq!(rodrigues(4, 0, 0.0), 1.0 / 24.0);
        // c1' = -1/3! , c2' = -1/4!
        assert!((rodrigues(1, 1, 0.0) + 1.0 / 6.0).abs() < 1e-17);
        assert!((rodrigues(2, 1, 0.0) + 1.0 / 24.0).abs() < 1e-17);
        // c1'' = 2 * 1/5!
        assert!((rodrigues(1, 2, 0.0) - 2.0 / 120.0).abs() < 1e-17);
    }

    #[test]
    fn derivatives_match_central_differences_on_both_branches() {
        for &w in &[-3.0f64, -0.2, 0.0, 0.7, 4.0, 8.99, 9.01, 15.0, 40.0] {
            for j in 0..=4u8 {
                for n in 0..=3u8 {
                    let h = 1e-4 * w.abs().max(1.0);
                    let fd = (rodrigues(j, n, w + h) - rodrigues(j, n, w - h)) / (2.0 * h);
                    let d = rodrigues(j, n + 1, w);
                    let scale = d.abs().max(rodrigues(j, n, w).abs()).max(1e-6);
                    assert!(
                        (fd - d).abs() < 1e-6 * scale,
                        "c{j}^({}) at {w}: {d} vs fd {fd}",
                        n + 1
                    );
                }
            }
        }
    }

    #[test]
    fn branches_meet_at_the_switch() {
        for j in 0..=4u8 {
            for n in 0..=4u8 {
                let (s, c) = (series(j, n, SERIES_BELOW), closed(j, n, SERIES_BELOW));
                assert!(
                    (s - c).abs() < 1e-11 * s.abs().max(1e-6),
                    "c{j}^({n}): series {s} closed {c}"
                );
            }
        }
    }

    #[test]
    fn tabled_series_match_the_long_series() {
        for &w in &[
            0.0f64, 0.1, -0.2, 0.249, 0.3, 0.99, 1.5, 3.99, 4.5, 8.99, -8.0,
        ] {
            for j in 0..=TABLE_J {
                for n in 0..=TABLE_N {
                    let (a, b) = (rodrigues(j, n, w), series(j, n, w));
                    let scale = series(j, n, 0.0).abs();
                    assert!(
                        (a - b).abs() <= 2e-15 * scale.max(b.abs()),
                        "c{j}^({n})({w}): table {a:e} vs series {b:e}"
                    );
                }
            }
        }
    }

    #[test]
    fn recurrence_identity_holds() {
        // c_j = 1/j! - w c_{j+2}
        for &w in &[0.0f64, 0.4, 3.0, 12.0] {
            for j in 0..=3u8 {
                let lhs = rodrigues(j, 0, w);
                let rhs = 1.0 / factorial(j as u32) - w * rodrigues(j + 2, 0, w);
                assert!((lhs - rhs).abs() < 1e-13, "j {j} w {w}");
            }
        }
    }
}

//! The Rodrigues coefficient functions of a rotation vector, as functions
//! of its squared angle, and all their derivatives.
//!
//! For a rotation vector rho with w = |rho|^2 and K = \[rho\]x,
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
//! Kernels take every coefficient they need at one argument from one
//! [`family`] call. Below |w| = [`SERIES_BELOW`] it sums the series of the
//! top members only and recurs downward; beyond it the closed forms in
//! theta and the recurrence 2 w c_j' = c_{j-1} - j c_j (from the series
//! term by term) give every order.

/// Below this |w| (|theta| < 3) series are used: their largest term is at
/// most 1.5 times the value's scale there, so they lose under one digit.
pub const SERIES_BELOW: f64 = 9.0;

/// d^n/dw^n c_j(w): a member of [`family`] when it has one (bit for bit
/// the value a kernel's family call gives), else the long series or the
/// closed form.
#[inline]
pub fn rodrigues(j: u8, n: u8, w: f64) -> f64 {
    if usize::from(j) < FAMILY_J && usize::from(n) < FAMILY_ORDERS {
        family::<FAMILY_ORDERS>(w)[usize::from(j)][usize::from(n)]
    } else if w.abs() < SERIES_BELOW {
        series(j, n, w)
    } else {
        closed(j, n, w)
    }
}

/// The family covers c_0 ..= c_8 ...
pub const FAMILY_J: usize = 9;
/// ... and their derivatives of orders 0 ..= 4.
pub const FAMILY_ORDERS: usize = 5;

/// `family::<N>(w)[j][n]` = d^n/dw^n c_j(w) for j <= 8, n < N: every
/// coefficient a kernel needs at one argument from one call.
///
/// Below |w| = 9 only the two top members c_7, c_8 (and their
/// derivatives) are summed as series, which converge fast that high; the
/// rest follow downward from c_j = 1/j! - w c_{j+2} and its derivatives
/// d^n c_j = -w d^n c_{j+2} - n d^(n-1) c_{j+2}, which is stable there (the
/// error of a step is at most w / ((j + 1) (j + 2)) of the one before;
/// checked against the long series to 2e-15 in the tests). A pcc element's
/// 17 coefficients cost about a third of their separate series. Above
/// |w| = 9, where the downward recursion would amplify errors by w a step,
/// each member comes from the closed forms.
///
/// Order n depends only on orders below it, and the chains start from the
/// same tops whatever is asked for, so every member has the same bits for
/// every `N`: the interpreter's single values and a kernel's family agree.
#[inline]
pub fn family<const N: usize>(w: f64) -> [[f64; N]; FAMILY_J] {
    const { assert!(N <= FAMILY_ORDERS) };
    let a = w.abs();
    if a < 1.0 {
        downward(w, tops::<N, 8>(w))
    } else if a < SERIES_BELOW {
        downward(w, tops::<N, 12>(w))
    } else {
        closed_family(w)
    }
}

/// Series terms kept for the tops: 8 reach round-off below |w| = 1, 12
/// below 9, for every order up to 4 (first omitted term under 1e-17 of
/// the leading one).
const TOP_TERMS: usize = 12;

/// TOPS[t][n][k]: (-1)^(k+n) (k+n)! / (k! (2k + 2n + j)!) for j = 7 + t,
/// the coefficient of w^k in d^n/dw^n c_j.
pub(crate) static TOPS: [[[f64; TOP_TERMS]; FAMILY_ORDERS]; 2] = tops_table();

const fn tops_table() -> [[[f64; TOP_TERMS]; FAMILY_ORDERS]; 2] {
    let mut t = [[[0.0; TOP_TERMS]; FAMILY_ORDERS]; 2];
    let mut top = 0;
    while top < 2 {
        let j = FAMILY_J - 2 + top;
        let mut n = 0;
        while n < FAMILY_ORDERS {
            let mut k = 0;
            while k < TOP_TERMS {
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
                t[top][n][k] = if (k + n) % 2 == 0 { c } else { -c };
                k += 1;
            }
            n += 1;
        }
        top += 1;
    }
    t
}

/// 1/j! for the recursion's constant.
pub(crate) const INV_FACTORIAL: [f64; FAMILY_J] = {
    let mut f = [1.0; FAMILY_J];
    let mut j = 1;
    while j < FAMILY_J {
        f[j] = f[j - 1] / j as f64;
        j += 1;
    }
    f
};

/// Orders 0..N of c_7 and c_8 by T-term Horner sums.
#[inline(always)]
fn tops<const N: usize, const T: usize>(w: f64) -> [[f64; N]; 2] {
    let mut s = [[0.0; N]; 2];
    for k in (0..T).rev() {
        for t in 0..2 {
            for n in 0..N {
                s[t][n] = s[t][n] * w + TOPS[t][n][k];
            }
        }
    }
    s
}

#[inline(always)]
fn downward<const N: usize>(w: f64, tops: [[f64; N]; 2]) -> [[f64; N]; FAMILY_J] {
    let mut c = [[0.0; N]; FAMILY_J];
    c[FAMILY_J - 2] = tops[0];
    c[FAMILY_J - 1] = tops[1];
    for j in (0..FAMILY_J - 2).rev() {
        for n in 0..N {
            c[j][n] = if n == 0 {
                INV_FACTORIAL[j] - w * c[j + 2][0]
            } else {
                -(w * c[j + 2][n]) - n as f64 * c[j + 2][n - 1]
            };
        }
    }
    c
}

#[cold]
#[inline(never)]
fn closed_family<const N: usize>(w: f64) -> [[f64; N]; FAMILY_J] {
    std::array::from_fn(|j| std::array::from_fn(|n| closed(j as u8, n as u8, w)))
}

/// sum_k (-1)^(k+n) (k+n)! / (k! (2k + 2n + j)!) w^k, summed until the
/// terms no longer change the sum.
#[doc(hidden)] // white-box tests (tests/suite)
pub fn series(j: u8, n: u8, w: f64) -> f64 {
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
#[doc(hidden)] // white-box tests (tests/suite)
pub fn closed(j: u8, n: u8, w: f64) -> f64 {
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
            -closed(1, m as u8, w) / 2.0
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

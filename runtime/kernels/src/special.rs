//! Removable-singularity functions and all their derivatives.
//!
//! PCC kinematics is full of `sin(x)/x` and `(1 - cos x)/x`. The CAS keeps them
//! as first-class functions so that `x = 0` is an ordinary point: the closed
//! form is used away from zero and the Taylor series near it, for every
//! derivative order (the CAS differentiates `sinc(k, x)` into `sinc(k + 1, x)`).
//! The interpreter and the generated code call exactly these functions, which
//! is one reason the two backends agree to round-off.

/// Below this |x| the Taylor series is used. At |x| = 1 the closed form of the
/// third derivative loses about two digits to cancellation; the series needs
/// about a dozen terms there.
const SERIES_BELOW: f64 = 1.0;
/// Series terms kept in the tables. At |x| < 1 the first omitted term of
/// any derivative up to order 7 is below 2^-54 of the value after nine
/// terms; ten leave a margin.
const TERMS: u32 = 10;

/// Terms needed at |x|: the pcc kernels spend much of their time in these
/// series, and small angles need few terms (the bounds are checked against
/// the full series in the tests below).
#[inline(always)]
fn terms_for(x: f64) -> usize {
    let a = x.abs();
    if a < 0.25 {
        6
    } else if a < 0.5 {
        8
    } else {
        TERMS as usize
    }
}

/// d^k/dx^k [sin(x) / x]  (k = 0 is sinc itself, 1 at x = 0).
#[inline]
pub fn sinc(k: u8, x: f64) -> f64 {
    if x.abs() < SERIES_BELOW {
        SINC.eval(k, x)
    } else {
        sinc_closed(k, x)
    }
}

// The closed forms are kept out of line: inlined into every call site of a
// kernel they would triple its code and crowd the instruction cache, while
// the bent elements of a soft arm mostly take the series branch.
#[cold]
#[inline(never)]
fn sinc_closed(k: u8, x: f64) -> f64 {
    leibniz_over_xp(k, x, 1, sin_deriv)
}

/// [`sinc`] of orders 0..K at one argument, bit for bit: the kernels need
/// a pcc element's sinc with its first two derivatives together.
#[inline(always)]
pub fn sinc_orders<const K: usize>(x: f64) -> [f64; K] {
    if x.abs() < SERIES_BELOW {
        SINC.orders(x)
    } else {
        std::array::from_fn(|k| sinc_closed(k as u8, x))
    }
}

/// [`cosc`] of orders 0..K at one argument, bit for bit.
#[inline(always)]
pub fn cosc_orders<const K: usize>(x: f64) -> [f64; K] {
    if x.abs() < SERIES_BELOW {
        COSC.orders(x)
    } else {
        std::array::from_fn(|k| cosc_closed(k as u8, x))
    }
}

/// [`sinc_rem`] of orders 0..K at one argument, bit for bit.
#[inline(always)]
pub fn sinc_rem_orders<const K: usize>(x: f64) -> [f64; K] {
    if x.abs() < SERIES_BELOW {
        SINC_REM.orders(x)
    } else {
        std::array::from_fn(|k| sinc_rem_closed(k as u8, x))
    }
}

/// d^k/dx^k [(1 - cos(x)) / x]  (k = 0 is 0 at x = 0, slope 1/2).
#[inline]
pub fn cosc(k: u8, x: f64) -> f64 {
    if x.abs() < SERIES_BELOW {
        COSC.eval(k, x)
    } else {
        cosc_closed(k, x)
    }
}

#[cold]
#[inline(never)]
fn cosc_closed(k: u8, x: f64) -> f64 {
    {
        leibniz_over_xp(k, x, 1, |i, x| {
            if i == 0 {
                1.0 - x.cos()
            } else {
                -cos_deriv(i, x)
            }
        })
    }
}

/// d^k/dx^k [(x - sin x) / x^3]  (k = 0 is 1/6 at x = 0). With sinc and cosc
/// it gives the centroid and rotational inertia of a bent (PCC) element.
#[inline]
pub fn sinc_rem(k: u8, x: f64) -> f64 {
    if x.abs() < SERIES_BELOW {
        SINC_REM.eval(k, x)
    } else {
        sinc_rem_closed(k, x)
    }
}

#[cold]
#[inline(never)]
fn sinc_rem_closed(k: u8, x: f64) -> f64 {
    {
        leibniz_over_xp(k, x, 3, |i, x| match i {
            0 => x - x.sin(),
            1 => 1.0 - x.cos(),
            _ => -sin_deriv(i, x),
        })
    }
}

/// (sin x, cos x) in one call. On glibc this is `sincos`, which shares the
/// argument reduction; std's `f64::sin_cos` is two separate calls. Every
/// backend takes its sines and cosines from here, so they agree bit for bit.
///
/// Below pi/4 (half the bending angle of a pcc element, nearly always) the
/// Taylor polynomials are used instead, inlined: a libm call costs more
/// than the twenty flops, and the kernels make one per element.
#[inline]
pub fn sin_cos(x: f64) -> (f64, f64) {
    if x.abs() <= std::f64::consts::FRAC_PI_4 {
        small_sin_cos(x)
    } else {
        libm_sin_cos(x)
    }
}

/// Coefficients (-1)^j / (2j + 1)! and (-1)^j / (2j)!; at |x| = pi/4 the
/// first omitted terms are below 1e-19.
const SIN_TAYLOR: [f64; 9] = taylor(1);
const COS_TAYLOR: [f64; 10] = taylor(0);

const fn taylor<const N: usize>(first: u32) -> [f64; N] {
    let mut c = [0.0; N];
    let mut j = 0;
    while j < N {
        let sign = if j % 2 == 0 { 1.0 } else { -1.0 };
        c[j] = sign / factorial(first + 2 * j as u32);
        j += 1;
    }
    c
}

#[inline(always)]
fn small_sin_cos(x: f64) -> (f64, f64) {
    let x2 = x * x;
    (
        split_horner(&SIN_TAYLOR, x2) * x,
        split_horner(&COS_TAYLOR, x2),
    )
}

#[inline(never)]
fn libm_sin_cos(x: f64) -> (f64, f64) {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        unsafe extern "C" {
            fn sincos(x: f64, s: *mut f64, c: *mut f64);
        }
        let (mut s, mut c) = (0.0, 0.0);
        // SAFETY: sincos writes one f64 through each of two valid pointers.
        unsafe { sincos(x, &mut s, &mut c) };
        (s, c)
    }
    #[cfg(not(all(target_os = "linux", target_env = "gnu")))]
    {
        x.sin_cos()
    }
}

/// sin x, the same value [`sin_cos`] gives.
#[inline]
pub fn sin(x: f64) -> f64 {
    sin_cos(x).0
}

/// cos x, the same value [`sin_cos`] gives.
#[inline]
pub fn cos(x: f64) -> f64 {
    sin_cos(x).1
}

/// sign(x): -1, 0 or 1 (the derivative of |x|; 0 at 0 rather than NaN).
#[inline]
pub fn sign(x: f64) -> f64 {
    if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// Derivative orders with precomputed Taylor tables; higher orders (never
/// needed by the generator so far) are computed term by term.
const TABLE_ORDERS: usize = 8;

/// Taylor series of an even or odd removable function, with the Horner
/// coefficients of its first derivatives computed at compile time (the
/// series branch is the hot path of every pcc kernel).
struct Series {
    /// Lowest exponent with a non-zero coefficient (0 or 1).
    first: u32,
    /// coef(m) of x^m for m = first, first + 2, ...: `coef[j]` for m = first + 2 j.
    coef: [f64; TERMS as usize + TABLE_ORDERS],
    /// table[k][i]: the coefficient of x^(lowest(k) - k + 2 i) in the k-th derivative.
    table: [[f64; TERMS as usize]; TABLE_ORDERS],
}

impl Series {
    const fn new(first: u32, coef: [f64; TERMS as usize + TABLE_ORDERS]) -> Self {
        let mut table = [[0.0; TERMS as usize]; TABLE_ORDERS];
        let mut k = 0;
        while k < TABLE_ORDERS {
            // Index of the lowest exponent >= k with the right parity.
            let mut j0 = 0;
            while first + 2 * j0 < k as u32 {
                j0 += 1;
            }
            let mut i = 0;
            while i < TERMS as usize {
                let m = first + 2 * (j0 + i as u32);
                table[k][i] = coef[j0 as usize + i] * falling(m, k as u32);
                i += 1;
            }
            k += 1;
        }
        Self { first, coef, table }
    }

    #[inline]
    fn eval(&self, k: u8, x: f64) -> f64 {
        match terms_for(x) {
            6 => self.eval_n::<6>(k, x),
            8 => self.eval_n::<8>(k, x),
            _ => self.eval_n::<{ TERMS as usize }>(k, x),
        }
    }

    /// Orders 0..K at one argument: one branch and K independent Horner
    /// chains, each the same arithmetic as [`Series::eval`].
    #[inline(always)]
    fn orders<const K: usize>(&self, x: f64) -> [f64; K] {
        match terms_for(x) {
            6 => std::array::from_fn(|k| self.eval_n::<6>(k as u8, x)),
            8 => std::array::from_fn(|k| self.eval_n::<8>(k as u8, x)),
            _ => std::array::from_fn(|k| self.eval_n::<{ TERMS as usize }>(k as u8, x)),
        }
    }

    /// The k-th derivative with N series terms. Fixed trip counts, so the
    /// Horner loops unroll into straight code at constant-order call sites.
    #[inline(always)]
    fn eval_n<const N: usize>(&self, k: u8, x: f64) -> f64 {
        let k32 = u32::from(k);
        let mut m0 = self.first;
        while m0 < k32 {
            m0 += 2;
        }
        let x2 = x * x;
        let sum = if (k as usize) < TABLE_ORDERS {
            horner::<N>(&self.table[k as usize], x2)
        } else {
            self.high_order(k, x2)
        };
        if m0 > k32 { sum * x } else { sum }
    }

    /// The series of a derivative past the tables, term by term.
    #[cold]
    #[inline(never)]
    fn high_order(&self, k: u8, x2: f64) -> f64 {
        let k32 = u32::from(k);
        let mut m0 = self.first;
        while m0 < k32 {
            m0 += 2;
        }
        let j0 = ((m0 - self.first) / 2) as usize;
        let mut sum = 0.0;
        for i in (0..TERMS as usize).rev() {
            let c = self.coef.get(j0 + i).copied().unwrap_or(0.0);
            sum = sum * x2 + c * falling(m0 + 2 * i as u32, k32);
        }
        sum
    }
}

/// sum_i row[i] x2^i for i < N.
#[inline(always)]
fn horner<const N: usize>(row: &[f64; TERMS as usize], x2: f64) -> f64 {
    let head: &[f64; N] = row[..N].try_into().expect("N <= TERMS");
    split_horner(head, x2)
}

/// sum_i row[i] x2^i as two interleaved Horner chains in x2^2 (even and
/// odd i): half the dependency chain of plain Horner, for the kernels'
/// many short series.
#[inline(always)]
fn split_horner<const N: usize>(row: &[f64; N], x2: f64) -> f64 {
    let x4 = x2 * x2;
    let (mut even, mut odd) = (0.0, 0.0);
    let mut i = N;
    while i > 0 {
        i -= 1;
        if i.is_multiple_of(2) {
            even = even * x4 + row[i];
        } else {
            odd = odd * x4 + row[i];
        }
    }
    even + x2 * odd
}

/// Coefficients (-1)^j / (m + shift)! for m = first + 2 j.
const fn alternating(first: u32, shift: u32) -> [f64; TERMS as usize + TABLE_ORDERS] {
    let mut c = [0.0; TERMS as usize + TABLE_ORDERS];
    let mut j = 0;
    while j < c.len() {
        let m = first + 2 * j as u32;
        let sign = if (j as u32).is_multiple_of(2) {
            1.0
        } else {
            -1.0
        };
        c[j] = sign / factorial(m + shift);
        j += 1;
    }
    c
}

/// sin(x)/x = sum_j (-1)^j x^(2j) / (2j + 1)!
static SINC: Series = Series::new(0, alternating(0, 1));
/// (1 - cos x)/x = sum_j (-1)^j x^(2j+1) / (2j + 2)!
static COSC: Series = Series::new(1, alternating(1, 1));
/// (x - sin x)/x^3 = sum_j (-1)^j x^(2j) / (2j + 3)!
static SINC_REM: Series = Series::new(0, alternating(0, 3));

/// Four arguments (the lanes of a vector kernel, `x4`), with the bits of
/// four scalar calls: where every lane takes the series branch with the
/// same number of terms, the same arithmetic runs on arrays of four, which
/// a kernel built for AVX compiles to vector instructions; else lane by
/// lane. The pcc cells of a bent arm spend most of their time here.
pub type Lanes = [f64; 4];

/// [`sinc_orders`] of four arguments.
#[inline(always)]
pub fn sinc_orders_x4<const K: usize>(x: Lanes) -> [Lanes; K] {
    SINC.orders_x4(x, sinc_orders::<K>)
}

/// [`cosc_orders`] of four arguments.
#[inline(always)]
pub fn cosc_orders_x4<const K: usize>(x: Lanes) -> [Lanes; K] {
    COSC.orders_x4(x, cosc_orders::<K>)
}

/// [`sinc_rem_orders`] of four arguments.
#[inline(always)]
pub fn sinc_rem_orders_x4<const K: usize>(x: Lanes) -> [Lanes; K] {
    SINC_REM.orders_x4(x, sinc_rem_orders::<K>)
}

/// [`sin_cos`] of four arguments.
#[inline(always)]
pub fn sin_cos_x4(x: Lanes) -> (Lanes, Lanes) {
    let (mut s, mut c) = ([0.0; 4], [0.0; 4]);
    if x.iter().all(|x| x.abs() <= std::f64::consts::FRAC_PI_4) {
        let x2 = mul4(x, x);
        let sp = split_horner4(&SIN_TAYLOR, x2);
        return (mul4(sp, x), split_horner4(&COS_TAYLOR, x2));
    }
    for l in 0..4 {
        (s[l], c[l]) = sin_cos(x[l]);
    }
    (s, c)
}

#[inline(always)]
fn mul4(a: Lanes, b: Lanes) -> Lanes {
    let mut v = [0.0; 4];
    for l in 0..4 {
        v[l] = a[l] * b[l];
    }
    v
}

/// [`split_horner`] lane by lane, the same operations in the same order.
#[inline(always)]
fn split_horner4<const N: usize>(row: &[f64; N], x2: Lanes) -> Lanes {
    let x4 = mul4(x2, x2);
    let (mut even, mut odd) = ([0.0; 4], [0.0; 4]);
    let mut i = N;
    while i > 0 {
        i -= 1;
        let acc = if i.is_multiple_of(2) {
            &mut even
        } else {
            &mut odd
        };
        for l in 0..4 {
            acc[l] = acc[l] * x4[l] + row[i];
        }
    }
    let mut v = [0.0; 4];
    for l in 0..4 {
        v[l] = even[l] + x2[l] * odd[l];
    }
    v
}

impl Series {
    #[inline(always)]
    fn orders_x4<const K: usize>(&self, x: Lanes, scalar: fn(f64) -> [f64; K]) -> [Lanes; K] {
        let n = terms_for(x[0]);
        let shared = K <= TABLE_ORDERS
            && x.iter()
                .all(|v| v.abs() < SERIES_BELOW && terms_for(*v) == n);
        match (shared, n) {
            (true, 6) => self.orders_n4::<K, 6>(x),
            (true, 8) => self.orders_n4::<K, 8>(x),
            (true, _) => self.orders_n4::<K, { TERMS as usize }>(x),
            (false, _) => {
                let mut out = [[0.0; 4]; K];
                for l in 0..4 {
                    for (o, v) in out.iter_mut().zip(scalar(x[l])) {
                        o[l] = v;
                    }
                }
                out
            }
        }
    }

    /// [`Series::eval_n`] of orders 0..K, four lanes at once.
    #[inline(always)]
    fn orders_n4<const K: usize, const N: usize>(&self, x: Lanes) -> [Lanes; K] {
        let x2 = mul4(x, x);
        let mut out = [[0.0; 4]; K];
        for (k, o) in out.iter_mut().enumerate() {
            let k32 = k as u32;
            let mut m0 = self.first;
            while m0 < k32 {
                m0 += 2;
            }
            let head: &[f64; N] = self.table[k][..N].try_into().expect("N <= TERMS");
            let sum = split_horner4(head, x2);
            *o = if m0 > k32 { mul4(sum, x) } else { sum };
        }
        out
    }
}

/// d^k/dx^k [g(x) / x^p] by Leibniz:
/// sum_j C(k,j) g^(k-j)(x) (-1)^j (p + j - 1)! / (p - 1)! x^(-p-j).
#[inline]
fn leibniz_over_xp(k: u8, x: f64, p: u32, g: impl Fn(u32, f64) -> f64) -> f64 {
    let k = u32::from(k);
    let inv = 1.0 / x;
    let mut sum = 0.0;
    let mut xp = powi_u(inv, p); // x^(-p-j)
    for j in 0..=k {
        let sgn = if j % 2 == 0 { 1.0 } else { -1.0 };
        let rising = factorial(p + j - 1) / factorial(p - 1);
        sum += binomial(k, j) * g(k - j, x) * sgn * rising * xp;
        xp *= inv;
    }
    sum
}

#[inline]
fn sin_deriv(i: u32, x: f64) -> f64 {
    match i % 4 {
        0 => x.sin(),
        1 => x.cos(),
        2 => -x.sin(),
        _ => -x.cos(),
    }
}

#[inline]
fn cos_deriv(i: u32, x: f64) -> f64 {
    match i % 4 {
        0 => x.cos(),
        1 => -x.sin(),
        2 => -x.cos(),
        _ => x.sin(),
    }
}

#[inline]
const fn factorial(n: u32) -> f64 {
    let mut acc = 1.0;
    let mut i = 2;
    while i <= n {
        acc *= i as f64;
        i += 1;
    }
    acc
}

/// m (m-1) ... (m-k+1)
#[inline]
const fn falling(m: u32, k: u32) -> f64 {
    let mut acc = 1.0;
    let mut i = 0;
    while i < k {
        acc *= (m - i) as f64;
        i += 1;
    }
    acc
}

#[inline]
fn binomial(n: u32, k: u32) -> f64 {
    falling(n, k) / factorial(k)
}

#[inline]
fn powi_u(x: f64, n: u32) -> f64 {
    (0..n).fold(1.0, |acc, _| acc * x)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Four lanes give the bits of four scalar calls: lanes that share a
    /// series length, lanes that do not, and lanes past the series.
    #[test]
    fn lanes_have_the_bits_of_scalar_calls() {
        let groups = [
            [0.0, 1e-9, -0.2, 0.24],
            [0.3, -0.45, 0.26, 0.49],
            [0.6, -0.9, 0.75, 0.99],
            [0.1, 0.3, -0.7, 0.2],
            [0.5, 1.5, -3.0, 0.7],
        ];
        let same = |a: Lanes, b: [f64; 4], what: &str| {
            for l in 0..4 {
                assert_eq!(a[l].to_bits(), b[l].to_bits(), "{what} lane {l}");
            }
        };
        for x in groups {
            let (s, c) = sin_cos_x4(x);
            same(s, x.map(|x| sin_cos(x).0), "sin");
            same(c, x.map(|x| sin_cos(x).1), "cos");
            let lanes = [
                sinc_orders_x4::<3>(x),
                cosc_orders_x4(x),
                sinc_rem_orders_x4(x),
            ];
            let scalar: [fn(f64) -> [f64; 3]; 3] =
                [sinc_orders::<3>, cosc_orders::<3>, sinc_rem_orders::<3>];
            for (lane, f) in lanes.iter().zip(scalar) {
                for (k, order) in lane.iter().enumerate() {
                    same(*order, x.map(|x| f(x)[k]), &format!("order {k} at {x:?}"));
                }
            }
        }
    }

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol * (1.0 + a.abs().max(b.abs()))
    }

    #[test]
    fn values_match_closed_forms() {
        for &x in &[-2.5, -1.0, -0.999, -0.3, 1e-9, 0.3, 0.999, 1.0, 1.7, 3.0] {
            let f: f64 = x;
            assert!(close(sinc(0, x), f.sin() / f, 1e-14), "sinc {x}");
            assert!(close(cosc(0, x), (1.0 - f.cos()) / f, 1e-7), "cosc {x}");
            // d/dx sin(x)/x = (x cos x - sin x)/x^2
            let d1 = (f * f.cos() - f.sin()) / (f * f);
            if x.abs() > 1e-3 {
                assert!(close(sinc(1, x), d1, 1e-12), "sinc' {x}");
            }
        }
    }

    #[test]
    fn sinc_rem_matches_its_closed_form_and_limits() {
        for &x in &[-2.5f64, -1.0, -0.5, 0.3, 0.999, 1.001, 1.7, 3.0] {
            let closed = (x - x.sin()) / (x * x * x);
            assert!(close(sinc_rem(0, x), closed, 1e-9), "x={x}");
        }
        assert!(close(sinc_rem(0, 0.0), 1.0 / 6.0, 1e-15));
        assert_eq!(sinc_rem(1, 0.0), 0.0);
        assert!(close(sinc_rem(2, 0.0), -2.0 / 120.0, 1e-15));
    }

    /// The series as a long sum, smallest terms first: the reference for the
    /// truncation in `terms_for`.
    fn long_series(first: u32, shift: u32, k: u32, x: f64) -> f64 {
        let mut terms = Vec::new();
        for j in 0..30u32 {
            let m = first + 2 * j;
            if m < k {
                continue;
            }
            let sign = if j % 2 == 0 { 1.0 } else { -1.0 };
            terms.push(sign * falling(m, k) / factorial(m + shift) * x.powi((m - k) as i32));
        }
        terms.iter().rev().sum()
    }

    #[test]
    fn truncated_series_match_the_long_series_to_round_off() {
        type Removable = fn(u8, f64) -> f64;
        // (name, function, lowest exponent, factorial shift)
        let cases: [(&str, Removable, u32, u32); 3] = [
            ("sinc", sinc, 0, 1),
            ("cosc", cosc, 1, 1),
            ("sinc_rem", sinc_rem, 0, 3),
        ];
        for (name, f, first, shift) in cases {
            for k in 0..TABLE_ORDERS as u8 {
                for i in -200..200 {
                    let x = i as f64 / 200.0 * 0.9999;
                    let reference = long_series(first, shift, u32::from(k), x);
                    let got = f(k, x);
                    let scale = reference.abs().max(f64::MIN_POSITIVE);
                    assert!(
                        (got - reference).abs() <= 8.0 * f64::EPSILON * scale,
                        "{name}^({k})({x}) = {got}, long series {reference}"
                    );
                }
            }
        }
    }

    #[test]
    fn small_angle_sin_cos_matches_libm_to_two_ulp() {
        for i in -2000..=2000 {
            let x = i as f64 / 2000.0 * std::f64::consts::FRAC_PI_4;
            let (s, c) = sin_cos(x);
            assert!(
                (s - x.sin()).abs() <= 2.0 * f64::EPSILON * x.sin().abs(),
                "sin {x}"
            );
            assert!(
                (c - x.cos()).abs() <= 2.0 * f64::EPSILON * x.cos(),
                "cos {x}"
            );
        }
        // Past pi/4 the libm path; both sides of the switch agree.
        let (a, b) = (
            std::f64::consts::FRAC_PI_4,
            std::f64::consts::FRAC_PI_4.next_up(),
        );
        assert!((sin_cos(a).0 - sin_cos(b).0).abs() < 1e-15);
        assert!((sin_cos(a).1 - sin_cos(b).1).abs() < 1e-15);
    }

    #[test]
    fn orders_agree_bit_for_bit_with_single_orders() {
        for i in -300..300 {
            let x = i as f64 / 97.0;
            let s: [f64; 4] = sinc_orders(x);
            let c: [f64; 4] = cosc_orders(x);
            let r: [f64; 4] = sinc_rem_orders(x);
            for k in 0..4u8 {
                let j = k as usize;
                assert_eq!(s[j].to_bits(), sinc(k, x).to_bits(), "sinc {k} {x}");
                assert_eq!(c[j].to_bits(), cosc(k, x).to_bits(), "cosc {k} {x}");
                assert_eq!(r[j].to_bits(), sinc_rem(k, x).to_bits(), "rem {k} {x}");
            }
        }
    }

    #[test]
    fn limits_at_zero() {
        assert_eq!(sinc(0, 0.0), 1.0);
        assert_eq!(sinc(1, 0.0), 0.0);
        assert!(close(sinc(2, 0.0), -1.0 / 3.0, 1e-15));
        assert_eq!(cosc(0, 0.0), 0.0);
        assert!(close(cosc(1, 0.0), 0.5, 1e-15));
        assert_eq!(cosc(2, 0.0), 0.0);
        assert!(close(cosc(3, 0.0), -0.25, 1e-15)); // 3! * (-1/24)
    }

    #[test]
    fn branches_meet_continuously() {
        // Both sides of the switch agree for every order used in practice.
        for k in 0..6u8 {
            let below = 1.0 - 1e-12;
            let above = 1.0 + 1e-12;
            assert!(close(sinc(k, below), sinc(k, above), 1e-11), "sinc k={k}");
            assert!(close(cosc(k, below), cosc(k, above), 1e-11), "cosc k={k}");
            assert!(
                close(sinc_rem(k, below), sinc_rem(k, above), 1e-10),
                "sinc_rem k={k}"
            );
            assert!(close(sinc(k, -below), sinc(k, -above), 1e-11));
            assert!(close(cosc(k, -below), cosc(k, -above), 1e-11));
        }
    }

    #[test]
    fn derivatives_match_finite_differences() {
        for k in 0..5u8 {
            for &x in &[-2.0, -0.7, 0.0, 0.2, 0.95, 1.05, 2.4] {
                let h = 1e-5;
                let fd = (sinc(k, x + h) - sinc(k, x - h)) / (2.0 * h);
                assert!(close(sinc(k + 1, x), fd, 1e-7), "sinc k={k} x={x}");
                let fd = (cosc(k, x + h) - cosc(k, x - h)) / (2.0 * h);
                assert!(close(cosc(k + 1, x), fd, 1e-7), "cosc k={k} x={x}");
                let fd = (sinc_rem(k, x + h) - sinc_rem(k, x - h)) / (2.0 * h);
                assert!(close(sinc_rem(k + 1, x), fd, 1e-7), "sinc_rem k={k} x={x}");
            }
        }
    }
}

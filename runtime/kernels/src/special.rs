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
#[doc(hidden)] // white-box tests (tests/suite)
pub const TABLE_ORDERS: usize = 8;

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

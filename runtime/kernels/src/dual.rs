//! Dual numbers: a value and its derivative along one direction.
//!
//! The tangent of a kernel is the kernel itself run on dual numbers
//! (forward-mode differentiation): the generated kernels that need one are
//! written once over `Scalar` (scalar.rs) and instantiated for `f64`
//! and for [`Dual`], and the link recursion's tangent carries duals through
//! the cells (`links::tangent`). Every rule here is the CAS's own
//! (`cas::diff`): sinc of order k differentiates to order k + 1, |x| to
//! sign x, sign x to 0, so a dual tangent and a symbolic one agree to
//! round-off.

use std::ops::{Add, Div, Mul, Neg, Sub};

use crate::rodrigues::{self, FAMILY_J, FAMILY_ORDERS};
use crate::special;

/// A value `v` and its directional derivative `d`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Dual {
    pub v: f64,
    pub d: f64,
}

impl Dual {
    pub const ZERO: Dual = Dual { v: 0.0, d: 0.0 };

    #[inline(always)]
    pub fn new(v: f64, d: f64) -> Self {
        Dual { v, d }
    }

    /// A number that does not move along the direction.
    #[inline(always)]
    pub fn constant(v: f64) -> Self {
        Dual { v, d: 0.0 }
    }

    /// f(v) with f'(v) = `slope`: the chain rule.
    #[inline(always)]
    fn along(self, v: f64, slope: f64) -> Self {
        Dual {
            v,
            d: slope * self.d,
        }
    }

    #[inline(always)]
    pub fn mul_add(self, b: Dual, c: Dual) -> Dual {
        Dual {
            v: self.v.mul_add(b.v, c.v),
            d: self.d.mul_add(b.v, self.v.mul_add(b.d, c.d)),
        }
    }

    #[inline(always)]
    pub fn sqrt(self) -> Dual {
        let v = self.v.sqrt();
        Dual {
            v,
            d: self.d / (2.0 * v),
        }
    }

    #[inline(always)]
    pub fn powi(self, n: i32) -> Dual {
        match n {
            0 => Dual::constant(1.0),
            _ => self.along(self.v.powi(n), f64::from(n) * self.v.powi(n - 1)),
        }
    }

    /// b^x = exp(x ln b): d = b^x (dx ln b + x db / b), as `cas::diff`.
    #[inline(always)]
    pub fn powf(self, x: Dual) -> Dual {
        let v = self.v.powf(x.v);
        let d = match (self.d == 0.0, x.d == 0.0) {
            (_, true) => x.v * self.v.powf(x.v - 1.0) * self.d,
            _ => v * (x.d * self.v.ln() + x.v * self.d / self.v),
        };
        Dual { v, d }
    }

    #[inline(always)]
    pub fn sin_cos(self) -> (Dual, Dual) {
        let (s, c) = special::sin_cos(self.v);
        (self.along(s, c), self.along(c, -s))
    }

    #[inline(always)]
    pub fn tan(self) -> Dual {
        let t = self.v.tan();
        self.along(t, t.mul_add(t, 1.0))
    }

    #[inline(always)]
    pub fn exp(self) -> Dual {
        let e = self.v.exp();
        self.along(e, e)
    }

    #[inline(always)]
    pub fn ln(self) -> Dual {
        self.along(self.v.ln(), 1.0 / self.v)
    }

    #[inline(always)]
    pub fn abs(self) -> Dual {
        self.along(self.v.abs(), special::sign(self.v))
    }

    #[inline(always)]
    pub fn sign(self) -> Dual {
        Dual::constant(special::sign(self.v))
    }

    #[inline(always)]
    pub fn sinc(self, k: u8) -> Dual {
        self.along(special::sinc(k, self.v), special::sinc(k + 1, self.v))
    }

    #[inline(always)]
    pub fn cosc(self, k: u8) -> Dual {
        self.along(special::cosc(k, self.v), special::cosc(k + 1, self.v))
    }

    #[inline(always)]
    pub fn sinc_rem(self, k: u8) -> Dual {
        self.along(
            special::sinc_rem(k, self.v),
            special::sinc_rem(k + 1, self.v),
        )
    }

    #[inline(always)]
    pub fn rodrigues(self, j: u8, n: u8) -> Dual {
        self.along(
            rodrigues::rodrigues(j, n, self.v),
            rodrigues::rodrigues(j, n + 1, self.v),
        )
    }

    /// Orders 0..K of a removable function at one argument, each with its
    /// derivative, the next order (`orders` gives 0..K, `next` order K).
    #[inline(always)]
    pub fn orders<const K: usize>(self, orders: [f64; K], next: f64) -> [Dual; K] {
        std::array::from_fn(|k| {
            let slope = if k + 1 < K { orders[k + 1] } else { next };
            self.along(orders[k], slope)
        })
    }

    /// `rodrigues::family::<N>` with the derivatives: order n's is order
    /// n + 1, from the full family or, past it, the single coefficient.
    #[inline(always)]
    pub fn rodrigues_family<const N: usize>(self) -> [[Dual; N]; FAMILY_J] {
        let f = rodrigues::family::<FAMILY_ORDERS>(self.v);
        std::array::from_fn(|j| {
            std::array::from_fn(|n| {
                let slope = match n + 1 < FAMILY_ORDERS {
                    true => f[j][n + 1],
                    false => rodrigues::rodrigues(j as u8, (n + 1) as u8, self.v),
                };
                self.along(f[j][n], slope)
            })
        })
    }
}

/// The value parts of `x` to `out[..n]` and their derivatives to
/// `out[n..]`: the layout of a symbolic tangent kernel's outputs.
#[inline(always)]
pub fn split(x: &[Dual], out: &mut [f64]) {
    let (values, derivatives) = out.split_at_mut(x.len());
    for ((v, d), x) in values.iter_mut().zip(derivatives).zip(x) {
        *v = x.v;
        *d = x.d;
    }
}

/// The derivatives of each row of `x` (rows of `width`) past its first
/// three values, row after row into `out`: the `ContactJvp` kernel's dv
/// and d(dp/dq) from the `ContactJacobian` rows (p, v, dp/dq).
#[inline(always)]
pub fn row_tails(x: &[Dual], width: usize, out: &mut [f64]) {
    let tail = width - 3;
    for (row, out) in x.chunks_exact(width).zip(out.chunks_exact_mut(tail)) {
        for (o, x) in out.iter_mut().zip(&row[3..]) {
            *o = x.d;
        }
    }
}

/// Duals of `v` moving along `d`.
#[inline(always)]
pub fn seed<const N: usize>(v: &[f64; N], d: &[f64]) -> [Dual; N] {
    std::array::from_fn(|i| Dual::new(v[i], d[i]))
}

macro_rules! binary {
    ($trait:ident, $f:ident, |$a:ident, $b:ident| $v:expr, $d:expr) => {
        impl $trait for Dual {
            type Output = Dual;
            #[inline(always)]
            fn $f(self, $b: Dual) -> Dual {
                let $a = self;
                Dual { v: $v, d: $d }
            }
        }
        impl $trait<f64> for Dual {
            type Output = Dual;
            #[inline(always)]
            fn $f(self, b: f64) -> Dual {
                self.$f(Dual::constant(b))
            }
        }
    };
}

binary!(Add, add, |a, b| a.v + b.v, a.d + b.d);
binary!(Sub, sub, |a, b| a.v - b.v, a.d - b.d);
binary!(Mul, mul, |a, b| a.v * b.v, a.d.mul_add(b.v, a.v * b.d));
binary!(Div, div, |a, b| a.v / b.v, (a.d - a.v / b.v * b.d) / b.v);

impl Neg for Dual {
    type Output = Dual;
    #[inline(always)]
    fn neg(self) -> Dual {
        Dual {
            v: -self.v,
            d: -self.d,
        }
    }
}

//! Canonical constructors: the only way nodes are made.
//!
//! Rewrite rules applied on construction (each has a test in `tests.rs`):
//! * constants fold (when the result is finite); -0.0 becomes 0.0;
//! * sums flatten, collect like terms (`2x + 3x -> 5x`), drop zeros and sort;
//! * products flatten, multiply constants, merge powers of the same base
//!   (`x^a x^b -> x^(a+b)`), drop ones, and are zero if a factor is zero;
//! * `x^0 -> 1`, `x^1 -> x`, `(x^a)^n -> x^(a n)` and `(x y)^n -> x^n y^n`
//!   for integer n;
//! * odd and even functions pull out a negative coefficient
//!   (`sin(-x) -> -sin(x)`, `cos(-x) -> cos(x)`); `ln(exp x) -> x`,
//!   `exp(ln x) -> x`, `|(|x|)| -> |x|`;
//! * `Bind` of a constant, symbol or bind is that expression.
//!
//! Sums are not expanded and products are not distributed: expansion blows
//! kinematic expressions up combinatorially, and CSE works on the factored form.

use std::collections::BTreeMap;

use super::expr::{Cas, ExprId, Func, Node};

fn canon_bits(c: f64) -> u64 {
    debug_assert!(c.is_finite());
    if c == 0.0 {
        0.0f64.to_bits()
    } else {
        c.to_bits()
    }
}

fn is_integer(c: f64) -> bool {
    c.fract() == 0.0 && c.abs() < 1e15
}

impl Cas {
    pub fn constant(&mut self, c: f64) -> ExprId {
        assert!(c.is_finite(), "non-finite constant {c} in an expression");
        self.intern(Node::Const(canon_bits(c)))
    }

    pub fn zero(&mut self) -> ExprId {
        self.constant(0.0)
    }

    pub fn one(&mut self) -> ExprId {
        self.constant(1.0)
    }

    /// A free symbol (tests and scratch algebra).
    pub fn var(&mut self, name: &str) -> ExprId {
        self.symbol(name, super::SymKind::Free)
    }

    /// Split a term into (numeric coefficient, the rest).
    pub(crate) fn split_coeff(&mut self, t: ExprId) -> (f64, ExprId) {
        if let Node::Mul(fs) = self.node(t)
            && let Some(c) = self.as_const(fs[0])
        {
            let rest: Vec<ExprId> = fs[1..].to_vec();
            let rest = if rest.len() == 1 {
                rest[0]
            } else {
                self.intern(Node::Mul(rest.into()))
            };
            return (c, rest);
        }
        (1.0, t)
    }

    /// c * rest, where rest is not a constant and has no coefficient.
    fn scale(&mut self, c: f64, rest: ExprId) -> ExprId {
        if c == 1.0 {
            return rest;
        }
        let k = self.constant(c);
        let mut fs = vec![k];
        match self.node(rest) {
            Node::Mul(xs) => fs.extend(xs.iter().copied()),
            _ => fs.push(rest),
        }
        self.intern(Node::Mul(fs.into()))
    }

    pub fn add_all(&mut self, terms: &[ExprId]) -> ExprId {
        let mut constant = 0.0;
        let mut collected: BTreeMap<ExprId, f64> = BTreeMap::new();
        let mut stack: Vec<ExprId> = terms.iter().rev().copied().collect();
        while let Some(t) = stack.pop() {
            match self.node(t) {
                Node::Const(bits) => constant += f64::from_bits(*bits),
                Node::Add(xs) => stack.extend(xs.iter().rev().copied()),
                _ => {
                    let (c, rest) = self.split_coeff(t);
                    *collected.entry(rest).or_insert(0.0) += c;
                }
            }
        }
        let mut out = Vec::with_capacity(collected.len() + 1);
        if constant != 0.0 {
            out.push(self.constant(constant));
        }
        for (rest, c) in collected {
            if c != 0.0 {
                out.push(self.scale(c, rest));
            }
        }
        match out.len() {
            0 => self.zero(),
            1 => out[0],
            _ => self.intern(Node::Add(out.into())),
        }
    }

    pub fn mul_all(&mut self, factors: &[ExprId]) -> ExprId {
        let mut coeff = 1.0;
        let mut powers: BTreeMap<ExprId, Vec<ExprId>> = BTreeMap::new();
        let mut stack: Vec<ExprId> = factors.iter().rev().copied().collect();
        let one = self.one();
        while let Some(f) = stack.pop() {
            match self.node(f) {
                Node::Const(bits) => coeff *= f64::from_bits(*bits),
                Node::Mul(xs) => stack.extend(xs.iter().rev().copied()),
                Node::Pow(b, e) => powers.entry(*b).or_default().push(*e),
                _ => powers.entry(f).or_default().push(one),
            }
        }
        if coeff == 0.0 {
            return self.zero();
        }
        let mut rest = Vec::with_capacity(powers.len());
        for (base, exps) in powers {
            let e = self.add_all(&exps);
            let p = self.pow(base, e);
            match self.node(p) {
                Node::Const(bits) => coeff *= f64::from_bits(*bits),
                Node::Mul(xs) => {
                    let xs = xs.clone();
                    for x in xs.iter() {
                        match self.as_const(*x) {
                            Some(c) => coeff *= c,
                            None => rest.push(*x),
                        }
                    }
                }
                _ => rest.push(p),
            }
        }
        if coeff == 0.0 {
            return self.zero();
        }
        rest.sort();
        match (rest.len(), coeff == 1.0) {
            (0, _) => self.constant(coeff),
            (1, true) => rest[0],
            _ => {
                let mut fs = Vec::with_capacity(rest.len() + 1);
                if coeff != 1.0 {
                    fs.push(self.constant(coeff));
                }
                fs.extend(rest);
                if fs.len() == 1 {
                    return fs[0];
                }
                self.intern(Node::Mul(fs.into()))
            }
        }
    }

    pub fn add(&mut self, a: ExprId, b: ExprId) -> ExprId {
        self.add_all(&[a, b])
    }

    pub fn sub(&mut self, a: ExprId, b: ExprId) -> ExprId {
        let nb = self.neg(b);
        self.add_all(&[a, nb])
    }

    pub fn mul(&mut self, a: ExprId, b: ExprId) -> ExprId {
        self.mul_all(&[a, b])
    }

    pub fn neg(&mut self, a: ExprId) -> ExprId {
        let m1 = self.constant(-1.0);
        self.mul_all(&[m1, a])
    }

    pub fn div(&mut self, a: ExprId, b: ExprId) -> ExprId {
        let m1 = self.constant(-1.0);
        let inv = self.pow(b, m1);
        self.mul_all(&[a, inv])
    }

    pub fn scaled(&mut self, c: f64, a: ExprId) -> ExprId {
        let k = self.constant(c);
        self.mul_all(&[k, a])
    }

    pub fn powi(&mut self, b: ExprId, n: i32) -> ExprId {
        let e = self.constant(f64::from(n));
        self.pow(b, e)
    }

    pub fn sqrt(&mut self, a: ExprId) -> ExprId {
        let h = self.constant(0.5);
        self.pow(a, h)
    }

    pub fn pow(&mut self, b: ExprId, e: ExprId) -> ExprId {
        let ec = self.as_const(e);
        let bc = self.as_const(b);
        match ec {
            Some(0.0) => return self.one(),
            Some(1.0) => return b,
            _ => {}
        }
        if let (Some(x), Some(y)) = (bc, ec) {
            let v = x.powf(y);
            if v.is_finite() && (x >= 0.0 || is_integer(y)) {
                return self.constant(v);
            }
        }
        if bc == Some(1.0) {
            return self.one();
        }
        if let Some(n) = ec.filter(|&c| is_integer(c)) {
            match self.node(b).clone() {
                Node::Pow(x, a) => {
                    let ne = self.scaled(n, a);
                    return self.pow(x, ne);
                }
                Node::Mul(xs) => {
                    let ps: Vec<ExprId> = xs
                        .iter()
                        .map(|&x| {
                            let ne = self.constant(n);
                            self.pow(x, ne)
                        })
                        .collect();
                    return self.mul_all(&ps);
                }
                _ => {}
            }
        }
        self.intern(Node::Pow(b, e))
    }

    /// A negative-looking argument: (-1 * coefficient, the positive part).
    fn negative_part(&mut self, x: ExprId) -> Option<ExprId> {
        let (c, rest) = self.split_coeff(x);
        if c < 0.0 && self.as_const(x).is_none() {
            Some(self.scale(-c, rest))
        } else {
            None
        }
    }

    pub fn func(&mut self, f: Func, x: ExprId) -> ExprId {
        if let Some(c) = self.as_const(x) {
            let v = f.apply(c);
            if v.is_finite() {
                return self.constant(v);
            }
        }
        if let Some(parity) = f.parity()
            && let Some(pos) = self.negative_part(x)
        {
            let inner = self.func(f, pos);
            return self.scaled(parity, inner);
        }
        match (f, self.node(x).clone()) {
            (Func::Ln, Node::Func(Func::Exp, y)) => return y,
            (Func::Exp, Node::Func(Func::Ln, y)) => return y,
            (Func::Abs, Node::Func(Func::Abs | Func::Exp, _)) => return x,
            _ => {}
        }
        self.intern(Node::Func(f, x))
    }

    pub fn sin(&mut self, x: ExprId) -> ExprId {
        self.func(Func::Sin, x)
    }
    pub fn cos(&mut self, x: ExprId) -> ExprId {
        self.func(Func::Cos, x)
    }
    /// sin(x)/x, 1 at 0.
    pub fn sinc(&mut self, x: ExprId) -> ExprId {
        self.func(Func::Sinc(0), x)
    }
    /// (1 - cos x)/x, 0 at 0.
    pub fn cosc(&mut self, x: ExprId) -> ExprId {
        self.func(Func::Cosc(0), x)
    }

    pub fn bind(&mut self, x: ExprId) -> ExprId {
        match self.node(x) {
            Node::Const(_) | Node::Sym(_) | Node::Bind(_) => x,
            _ => self.intern(Node::Bind(x)),
        }
    }

    /// Sum of pairwise products, the workhorse of TMT assembly.
    pub fn dot(&mut self, a: &[ExprId], b: &[ExprId]) -> ExprId {
        let terms: Vec<ExprId> = a.iter().zip(b).map(|(&x, &y)| self.mul(x, y)).collect();
        self.add_all(&terms)
    }

    /// The cross product a x b of 3-vectors.
    pub fn cross(&mut self, a: &[ExprId; 3], b: &[ExprId; 3]) -> [ExprId; 3] {
        std::array::from_fn(|k| {
            let (i, j) = ((k + 1) % 3, (k + 2) % 3);
            let p = self.mul(a[i], b[j]);
            let m = self.mul(a[j], b[i]);
            self.sub(p, m)
        })
    }
}

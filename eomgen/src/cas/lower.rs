//! Linearisation of the DAG into a tape, with value numbering (CSE across
//! all outputs of a kernel).
//!
//! Sums become chains of `Add`/`Sub` (a term with a negative coefficient is
//! subtracted), products become `Mul` chains with negative powers moved into
//! one `Div`, and `x^2` becomes `x * x`. Identical instructions are emitted
//! once.

use std::collections::HashMap;

use runtime::tape::{Op, Slot, Tape};

use super::expr::{Cas, ExprId, Func, Node, SymKind};

/// Builds one tape from any number of output expressions.
pub struct Lowerer<'a> {
    cas: &'a Cas,
    ops: Vec<Op>,
    numbering: HashMap<(u8, u64, u64), Slot>,
    done: HashMap<ExprId, Slot>,
}

fn key(op: &Op) -> (u8, u64, u64) {
    let u = |s: Slot| u64::from(s);
    match *op {
        Op::Const(c) => (0, c.to_bits(), 0),
        Op::Q(i) => (1, u64::from(i), 0),
        Op::Qd(i) => (2, u64::from(i), 0),
        Op::Param(i) => (3, u64::from(i), 0),
        Op::Time => (4, 0, 0),
        Op::Add(a, b) => (5, u(a.min(b)), u(a.max(b))),
        Op::Sub(a, b) => (6, u(a), u(b)),
        Op::Mul(a, b) => (7, u(a.min(b)), u(a.max(b))),
        Op::Div(a, b) => (8, u(a), u(b)),
        Op::Neg(a) => (9, u(a), 0),
        Op::Powi(a, n) => (10, u(a), n as u32 as u64),
        Op::Powf(a, b) => (11, u(a), u(b)),
        Op::Sqrt(a) => (12, u(a), 0),
        Op::Sin(a) => (13, u(a), 0),
        Op::Cos(a) => (14, u(a), 0),
        Op::Tan(a) => (15, u(a), 0),
        Op::Exp(a) => (16, u(a), 0),
        Op::Ln(a) => (17, u(a), 0),
        Op::Abs(a) => (18, u(a), 0),
        Op::Sign(a) => (19, u(a), 0),
        Op::Sinc(k, a) => (20, u(a), u64::from(k)),
        Op::Cosc(k, a) => (21, u(a), u64::from(k)),
    }
}

impl<'a> Lowerer<'a> {
    pub fn new(cas: &'a Cas) -> Self {
        Self {
            cas,
            ops: Vec::new(),
            numbering: HashMap::new(),
            done: HashMap::new(),
        }
    }

    fn push(&mut self, op: Op) -> Slot {
        let k = key(&op);
        if let Some(&s) = self.numbering.get(&k) {
            return s;
        }
        let s = self.ops.len() as Slot;
        self.ops.push(op);
        self.numbering.insert(k, s);
        s
    }

    fn constant(&mut self, c: f64) -> Slot {
        self.push(Op::Const(c))
    }

    /// Lower `e`, returning the slot holding its value.
    pub fn lower(&mut self, e: ExprId) -> Slot {
        if let Some(&s) = self.done.get(&e) {
            return s;
        }
        let s = match self.cas.node(e).clone() {
            Node::Const(bits) => self.constant(f64::from_bits(bits)),
            Node::Sym(sym) => match self.cas.sym_kind(sym) {
                SymKind::Q(i) => self.push(Op::Q(i)),
                SymKind::Qd(i) => self.push(Op::Qd(i)),
                SymKind::Param(i) => self.push(Op::Param(i)),
                SymKind::Time => self.push(Op::Time),
                k @ (SymKind::Qdd(_) | SymKind::Free) => {
                    panic!(
                        "symbol {} ({k:?}) cannot be lowered",
                        self.cas.sym_name(sym)
                    )
                }
            },
            Node::Add(xs) => self.lower_sum(&xs),
            Node::Mul(xs) => {
                let (c, rest) = match self.cas.as_const(xs[0]) {
                    Some(c) => (c, &xs[1..]),
                    None => (1.0, &xs[..]),
                };
                self.lower_product(c, rest)
            }
            Node::Pow(b, x) => self.lower_pow(b, x),
            Node::Func(f, x) => {
                let a = self.lower(x);
                self.push(match f {
                    Func::Sin => Op::Sin(a),
                    Func::Cos => Op::Cos(a),
                    Func::Tan => Op::Tan(a),
                    Func::Exp => Op::Exp(a),
                    Func::Ln => Op::Ln(a),
                    Func::Abs => Op::Abs(a),
                    Func::Sign => Op::Sign(a),
                    Func::Sinc(k) => Op::Sinc(k, a),
                    Func::Cosc(k) => Op::Cosc(k, a),
                })
            }
            Node::Bind(x) => self.lower(x),
        };
        self.done.insert(e, s);
        s
    }

    fn lower_sum(&mut self, xs: &[ExprId]) -> Slot {
        // (negated?, slot of the magnitude)
        let mut parts: Vec<(bool, Slot)> = Vec::with_capacity(xs.len());
        for &t in xs {
            match self.cas.node(t) {
                Node::Mul(fs) if self.cas.as_const(fs[0]).is_some_and(|c| c < 0.0) => {
                    let c = -self.cas.as_const(fs[0]).unwrap_or(-1.0);
                    let fs = fs.clone();
                    let s = self.lower_product(c, &fs[1..]);
                    parts.push((true, s));
                }
                Node::Const(bits) if f64::from_bits(*bits) < 0.0 => {
                    let s = self.constant(-f64::from_bits(*bits));
                    parts.push((true, s));
                }
                _ => {
                    let s = self.lower(t);
                    parts.push((false, s));
                }
            }
        }
        // Start from a positive term when there is one.
        let start = parts.iter().position(|p| !p.0);
        match start {
            Some(i) => {
                let mut acc = parts[i].1;
                for (j, &(neg, s)) in parts.iter().enumerate() {
                    if j == i {
                        continue;
                    }
                    acc = self.push(if neg {
                        Op::Sub(acc, s)
                    } else {
                        Op::Add(acc, s)
                    });
                }
                acc
            }
            None => {
                let mut acc = parts[0].1;
                for &(_, s) in &parts[1..] {
                    acc = self.push(Op::Add(acc, s));
                }
                self.push(Op::Neg(acc))
            }
        }
    }

    /// c * prod(factors), with negative constant powers moved to a divisor.
    fn lower_product(&mut self, c: f64, factors: &[ExprId]) -> Slot {
        let mut num: Vec<Slot> = Vec::new();
        let mut den: Vec<Slot> = Vec::new();
        for &f in factors {
            if let Node::Pow(b, x) = self.cas.node(f)
                && let Some(e) = self.cas.as_const(*x)
                && e < 0.0
            {
                let b = *b;
                den.push(self.pow_const(b, -e));
                continue;
            }
            num.push(self.lower(f));
        }
        let mut acc: Option<Slot> = None;
        if c != 1.0 && c != -1.0 {
            acc = Some(self.constant(c));
        }
        for s in num {
            acc = Some(match acc {
                None => s,
                Some(a) => self.push(Op::Mul(a, s)),
            });
        }
        let mut acc = match acc {
            Some(a) => a,
            None => self.constant(1.0),
        };
        if !den.is_empty() {
            let mut d = den[0];
            for &s in &den[1..] {
                d = self.push(Op::Mul(d, s));
            }
            acc = self.push(Op::Div(acc, d));
        }
        if c == -1.0 {
            self.push(Op::Neg(acc))
        } else {
            acc
        }
    }

    fn lower_pow(&mut self, b: ExprId, x: ExprId) -> Slot {
        match self.cas.as_const(x) {
            Some(e) if e < 0.0 => {
                let d = self.pow_const(b, -e);
                let one = self.constant(1.0);
                self.push(Op::Div(one, d))
            }
            Some(e) => self.pow_const(b, e),
            None => {
                let a = self.lower(b);
                let y = self.lower(x);
                self.push(Op::Powf(a, y))
            }
        }
    }

    /// b^e for a constant e > 0.
    fn pow_const(&mut self, b: ExprId, e: f64) -> Slot {
        let a = self.lower(b);
        if e == 1.0 {
            a
        } else if e == 2.0 {
            self.push(Op::Mul(a, a))
        } else if e == 0.5 {
            self.push(Op::Sqrt(a))
        } else if e.fract() == 0.0 && e <= 64.0 {
            self.push(Op::Powi(a, e as i32))
        } else {
            let y = self.constant(e);
            self.push(Op::Powf(a, y))
        }
    }

    /// Lower all `outputs` and finish the tape.
    pub fn finish(mut self, outputs: &[ExprId]) -> Tape {
        let outs: Vec<Slot> = outputs.iter().map(|&e| self.lower(e)).collect();
        Tape {
            ops: self.ops,
            outputs: outs,
        }
    }
}

impl Cas {
    /// Linearise `outputs` into one tape.
    pub fn to_tape(&self, outputs: &[ExprId]) -> Tape {
        Lowerer::new(self).finish(outputs)
    }
}

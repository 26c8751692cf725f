//! Linearisation of the DAG into a tape, with value numbering (CSE across
//! all outputs of a kernel).
//!
//! Sums become chains of `Add`/`Sub` (a term with a negative coefficient is
//! subtracted), products become `Mul` chains with negative powers moved into
//! one `Div`, and `x^2` becomes `x * x`. Identical instructions are emitted
//! once.
//!
//! Sines and cosines of a bound angle plus an increment that several angles
//! share (a pcc element turns its frame by theta/2 twice) come from the
//! addition theorems: six flops instead of a `sin_cos` call each.
//!
//! With a [`Hoist`], every subexpression that depends on parameters alone
//! (and the parameter-only part of each sum and product) is not computed in
//! the kernel but read as a *derived parameter*: `Param(n_params + k)`. The
//! derived parameters are computed once per parameter set by their own tape
//! ([`Hoist::finish`]), not on every call.

use rustc_hash::{FxHashMap as HashMap, FxHashSet as HashSet};

use runtime::tape::{Op, Slot, Tape};

use super::expr::{Cas, ExprId, Func, Node, SymKind};

/// Parameter-only subexpressions hoisted out of kernels, shared by all
/// kernels of one model.
pub struct Hoist {
    n_params: u32,
    /// Parameters that change during a run (driven by inputs): never hoisted.
    inputs: HashSet<u32>,
    exprs: Vec<ExprId>,
    index: HashMap<ExprId, u32>,
    param_only: HashMap<ExprId, bool>,
}

impl Hoist {
    pub fn new(n_params: usize) -> Self {
        Self {
            n_params: n_params as u32,
            inputs: HashSet::default(),
            exprs: Vec::new(),
            index: HashMap::default(),
            param_only: HashMap::default(),
        }
    }

    /// Mark parameters as inputs: expressions of them stay in the kernels.
    pub fn with_inputs(mut self, inputs: impl IntoIterator<Item = usize>) -> Self {
        self.inputs = inputs.into_iter().map(|i| i as u32).collect();
        self
    }

    /// Parameter index of a hoisted expression.
    fn slot_param(&mut self, e: ExprId) -> u32 {
        let k = *self.index.entry(e).or_insert_with(|| {
            self.exprs.push(e);
            (self.exprs.len() - 1) as u32
        });
        self.n_params + k
    }

    /// Whether `e` depends on parameters (and constants) only, and on at
    /// least one parameter.
    fn is_param_only(&mut self, cas: &Cas, e: ExprId) -> bool {
        if let Some(&b) = self.param_only.get(&e) {
            return b;
        }
        let b = match cas.node(e) {
            Node::Const(_) => false,
            Node::Sym(s) => {
                matches!(cas.sym_kind(*s), SymKind::Param(i) if !self.inputs.contains(&i))
            }
            _ => {
                let kids = cas.children(e);
                let mut any_param = false;
                let mut ok = true;
                for k in kids {
                    if cas.as_const(k).is_some() {
                        continue;
                    }
                    if self.is_param_only(cas, k) {
                        any_param = true;
                    } else {
                        ok = false;
                        break;
                    }
                }
                ok && any_param
            }
        };
        self.param_only.insert(e, b);
        b
    }

    pub fn len(&self) -> usize {
        self.exprs.len()
    }

    pub fn is_empty(&self) -> bool {
        self.exprs.is_empty()
    }

    /// The tape computing the derived parameters from the base ones.
    pub fn finish(&self, cas: &mut Cas) -> Tape {
        Lowerer::new(cas).finish(&self.exprs.clone())
    }
}

/// Builds one tape from any number of output expressions.
pub struct Lowerer<'a> {
    cas: &'a mut Cas,
    hoist: Option<&'a mut Hoist>,
    ops: Vec<Op>,
    numbering: HashMap<(u8, u64, u64), Slot>,
    done: HashMap<ExprId, Slot>,
    /// Angle increments shared by two or more trigonometric arguments.
    shared_increments: HashSet<ExprId>,
}

fn key(op: &Op) -> (u8, u64, u64) {
    let u = |s: Slot| u64::from(s);
    match *op {
        Op::Const(c) => (0, c.to_bits(), 0),
        Op::Q(i) => (1, u64::from(i), 0),
        Op::Qd(i) => (2, u64::from(i), 0),
        Op::Qdd(i) => (23, u64::from(i), 0),
        Op::Dir(i) => (25, u64::from(i), 0),
        Op::Aux(i) => (26, u64::from(i), 0),
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
        Op::SincRem(k, a) => (22, u(a), u64::from(k)),
        Op::Rodrigues(j, n, a) => (24, u(a), (u64::from(j) << 8) | u64::from(n)),
        Op::MulAdd(..) | Op::MulSub(..) | Op::NegMulAdd(..) => {
            unreachable!("fused only after value numbering")
        }
    }
}

/// Sums longer than this are not factored (see `Lowerer::factor_sum`).
const MAX_FACTORED_TERMS: usize = 24;

impl<'a> Lowerer<'a> {
    pub fn new(cas: &'a mut Cas) -> Self {
        Self {
            cas,
            hoist: None,
            ops: Vec::new(),
            numbering: HashMap::default(),
            done: HashMap::default(),
            shared_increments: HashSet::default(),
        }
    }

    /// A lowerer that reads parameter-only subexpressions from `hoist`.
    pub fn hoisting(cas: &'a mut Cas, hoist: &'a mut Hoist) -> Self {
        Self {
            cas,
            hoist: Some(hoist),
            ops: Vec::new(),
            numbering: HashMap::default(),
            done: HashMap::default(),
            shared_increments: HashSet::default(),
        }
    }

    fn param_only(&mut self, e: ExprId) -> bool {
        match self.hoist.as_deref_mut() {
            Some(h) => h.is_param_only(self.cas, e),
            None => false,
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
        if !matches!(self.cas.node(e), Node::Sym(_)) && self.param_only(e) {
            let k = self
                .hoist
                .as_deref_mut()
                .expect("param_only implies hoisting")
                .slot_param(e);
            let s = self.push(Op::Param(k));
            self.done.insert(e, s);
            return s;
        }
        let s = match self.cas.node(e).clone() {
            Node::Const(bits) => self.constant(f64::from_bits(bits)),
            Node::Sym(sym) => match self.cas.sym_kind(sym) {
                SymKind::Q(i) => self.push(Op::Q(i)),
                SymKind::Qd(i) => self.push(Op::Qd(i)),
                SymKind::Param(i) => self.push(Op::Param(i)),
                SymKind::Time => self.push(Op::Time),
                SymKind::Qdd(i) => self.push(Op::Qdd(i)),
                SymKind::Dir(i) => self.push(Op::Dir(i)),
                SymKind::Aux(i) => self.push(Op::Aux(i)),
                k @ SymKind::Free => {
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
            Node::Func(f @ (Func::Sin | Func::Cos), x)
                if self
                    .split_angle(x)
                    .is_some_and(|(_, rest)| self.shared_increments.contains(&rest)) =>
            {
                let (base, rest) = self.split_angle(x).expect("checked above");
                self.lower_angle_sum(f == Func::Sin, base, rest)
            }
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
                    Func::SincRem(k) => Op::SincRem(k, a),
                    Func::Rodrigues(j, n) => Op::Rodrigues(j, n, a),
                })
            }
            Node::Bind(x) => self.lower(x),
        };
        self.done.insert(e, s);
        s
    }

    /// An angle `x = base + rest` with `base` a frame's angle: the split
    /// that the addition theorems use.
    fn split_angle(&mut self, x: ExprId) -> Option<(ExprId, ExprId)> {
        let sum = match self.cas.node(x) {
            Node::Bind(y) => *y,
            _ => x,
        };
        let Node::Add(terms) = self.cas.node(sum) else {
            return None;
        };
        let terms = terms.clone();
        // The frame's angle: a bound one, or at the base a parameter-only
        // one (whose sine and cosine are hoisted out of the kernel).
        let only = |ts: Vec<ExprId>| (ts.len() == 1).then(|| ts[0]);
        let binds: Vec<ExprId> = terms
            .iter()
            .copied()
            .filter(|&t| matches!(self.cas.node(t), Node::Bind(_)))
            .collect();
        let base = match binds.len() {
            0 => {
                let fixed: Vec<ExprId> = terms
                    .iter()
                    .copied()
                    .filter(|&t| self.param_only(t))
                    .collect();
                only(fixed)?
            }
            _ => only(binds)?,
        };
        let rest: Vec<ExprId> = terms.into_iter().filter(|&t| t != base).collect();
        Some((base, self.cas.add_all(&rest)))
    }

    /// sin or cos of base + rest by the addition theorems.
    fn lower_angle_sum(&mut self, sine: bool, base: ExprId, rest: ExprId) -> Slot {
        let (sb, cb) = (self.cas.sin(base), self.cas.cos(base));
        let (sr, cr) = (self.cas.sin(rest), self.cas.cos(rest));
        let [sb, cb, sr, cr] = [sb, cb, sr, cr].map(|e| self.lower(e));
        if sine {
            // sin b cos r + cos b sin r
            let a = self.push(Op::Mul(sb, cr));
            let b = self.push(Op::Mul(cb, sr));
            self.push(Op::Add(a, b))
        } else {
            // cos b cos r - sin b sin r
            let a = self.push(Op::Mul(cb, cr));
            let b = self.push(Op::Mul(sb, sr));
            self.push(Op::Sub(a, b))
        }
    }

    /// Find the increments that two or more trigonometric arguments share.
    fn find_shared_increments(&mut self, roots: &[ExprId]) {
        let mut seen = HashSet::default();
        let mut stack = roots.to_vec();
        let mut angles = HashSet::default();
        while let Some(e) = stack.pop() {
            if !seen.insert(e) {
                continue;
            }
            if let Node::Func(Func::Sin | Func::Cos, x) = self.cas.node(e) {
                angles.insert(*x);
            }
            stack.extend(self.cas.children(e));
        }
        let mut uses: HashMap<ExprId, usize> = HashMap::default();
        let mut angles: Vec<ExprId> = angles.into_iter().collect();
        angles.sort();
        for x in angles {
            if let Some((_, rest)) = self.split_angle(x) {
                *uses.entry(rest).or_default() += 1;
            }
        }
        self.shared_increments = uses
            .into_iter()
            .filter(|&(_, n)| n >= 2)
            .map(|(r, _)| r)
            .collect();
    }

    fn lower_sum(&mut self, xs: &[ExprId]) -> Slot {
        // (negated?, slot of the magnitude)
        let mut parts: Vec<(bool, Slot)> = Vec::with_capacity(xs.len());
        // The parameter-only terms are one hoisted sum.
        let (fixed, dynamic): (Vec<ExprId>, Vec<ExprId>) = xs
            .iter()
            .partition(|&&t| self.cas.as_const(t).is_some() || self.param_only(t));
        let xs: Vec<ExprId> = if fixed.len() >= 2 && fixed.iter().any(|&t| self.param_only(t)) {
            let f = self.cas.add_all(&fixed);
            std::iter::once(f).chain(dynamic).collect()
        } else {
            xs.to_vec()
        };
        if let Some(factored) = self.factor_sum(&xs) {
            return self.lower(factored);
        }
        for &t in &xs {
            let hoisted = self.param_only(t);
            match self.cas.node(t) {
                Node::Mul(fs) if self.cas.as_const(fs[0]).is_some_and(|c| c < 0.0) && !hoisted => {
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

    /// The factors of a term, without its numeric coefficient.
    fn factors(&self, t: ExprId) -> Vec<ExprId> {
        match self.cas.node(t) {
            Node::Mul(fs) => fs
                .iter()
                .copied()
                .filter(|&f| self.cas.as_const(f).is_none())
                .collect(),
            Node::Const(_) => Vec::new(),
            _ => vec![t],
        }
    }

    /// `f (sum of quotients) + rest` for the factor f that most terms share
    /// (greedy multivariate Horner): derivatives come out of the CAS as sums
    /// of products, and collecting, say, cos(phi) out of a dozen of them
    /// saves a multiplication for each. None when no factor is shared.
    fn factor_sum(&mut self, xs: &[ExprId]) -> Option<ExprId> {
        // Each step re-counts what is left: quadratic in the terms. Long
        // sums (Jacobian entries of long chains) are left as they are.
        if xs.len() > MAX_FACTORED_TERMS {
            return None;
        }
        let mut count: HashMap<ExprId, usize> = HashMap::default();
        for &t in xs {
            let mut fs = self.factors(t);
            fs.sort();
            fs.dedup();
            for f in fs {
                *count.entry(f).or_default() += 1;
            }
        }
        let (&f, &n) = count
            .iter()
            .max_by_key(|&(&f, &n)| (n, std::cmp::Reverse(f)))?;
        if n < 2 {
            return None;
        }
        let mut quotients = Vec::new();
        let mut rest = Vec::new();
        for &t in xs {
            if !self.factors(t).contains(&f) {
                rest.push(t);
                continue;
            }
            let q = match self.cas.node(t).clone() {
                Node::Mul(fs) => {
                    let i = fs.iter().position(|&x| x == f).expect("factor present");
                    let others: Vec<ExprId> = fs
                        .iter()
                        .enumerate()
                        .filter(|&(j, _)| j != i)
                        .map(|(_, &x)| x)
                        .collect();
                    self.cas.mul_all(&others)
                }
                _ => self.cas.one(),
            };
            quotients.push(q);
        }
        let inner = self.cas.add_all(&quotients);
        let product = self.cas.mul(f, inner);
        rest.push(product);
        Some(self.cas.add_all(&rest))
    }

    /// c * prod(factors), with negative constant powers moved to a divisor.
    fn lower_product(&mut self, c: f64, factors: &[ExprId]) -> Slot {
        // The coefficient and the parameter-only factors are one hoisted
        // product.
        let (fixed, dynamic): (Vec<ExprId>, Vec<ExprId>) =
            factors.iter().partition(|&&f| self.param_only(f));
        if !fixed.is_empty() && !dynamic.is_empty() && (fixed.len() >= 2 || (c != 1.0 && c != -1.0))
        {
            let k = self.cas.constant(c);
            let mut group = vec![k];
            group.extend(&fixed);
            let g = self.cas.mul_all(&group);
            let mut fs = vec![g];
            fs.extend(dynamic);
            return self.lower_product(1.0, &fs);
        }
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
        self.find_shared_increments(outputs);
        let outs: Vec<Slot> = outputs.iter().map(|&e| self.lower(e)).collect();
        super::fuse::fuse_multiply_adds(Tape {
            ops: self.ops,
            outputs: outs,
        })
    }
}

impl Cas {
    /// Linearise `outputs` into one tape.
    pub fn to_tape(&mut self, outputs: &[ExprId]) -> Tape {
        Lowerer::new(self).finish(outputs)
    }

    /// Linearise with parameter-only subexpressions read from `hoist`.
    pub fn to_tape_hoisted(&mut self, outputs: &[ExprId], hoist: &mut Hoist) -> Tape {
        Lowerer::hoisting(self, hoist).finish(outputs)
    }
}

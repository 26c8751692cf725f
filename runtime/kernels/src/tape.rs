//! The tape: a flat, SSA instruction list that evaluates one kernel.
//!
//! eomgen linearises the CSE'd expression DAG into a tape. The same tape is
//! either interpreted here (models not compiled in) or emitted as Rust by
//! eomgen (compiled-in models), so both backends run the same operations in
//! the same order.
//!
//! Invariant: an instruction only reads slots with smaller indices; slot `i`
//! holds the value of `ops[i]`.

use serde::{Deserialize, Serialize};

use crate::rodrigues;
use crate::special;

/// Every member of one argument's Rodrigues family.
type Family = [[f64; rodrigues::FAMILY_ORDERS]; rodrigues::FAMILY_J];

/// Slot index into the tape.
pub type Slot = u32;

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Op {
    Const(f64),
    /// Generalised coordinate `q[i]`.
    Q(u32),
    /// Generalised rate `qd[i]`.
    Qd(u32),
    /// Generalised acceleration `qdd[i]` (read by the `Jvp` kernel).
    Qdd(u32),
    /// Component i of the `Jvp` kernel's direction (dq, then dqd).
    Dir(u32),
    /// Runtime parameter `p[i]`.
    Param(u32),
    Time,
    /// Value i of the kernel's `aux` input: what another kernel computed
    /// for this one (the `Accel` kernel's contact frames, which the
    /// `ContactJacobian` groups start from).
    Aux(u32),
    Add(Slot, Slot),
    Sub(Slot, Slot),
    Mul(Slot, Slot),
    /// a * b + c with one rounding (`f64::mul_add`).
    MulAdd(Slot, Slot, Slot),
    /// a * b - c with one rounding.
    MulSub(Slot, Slot, Slot),
    /// c - a * b with one rounding.
    NegMulAdd(Slot, Slot, Slot),
    Div(Slot, Slot),
    Neg(Slot),
    Powi(Slot, i32),
    Powf(Slot, Slot),
    Sqrt(Slot),
    Sin(Slot),
    Cos(Slot),
    Tan(Slot),
    Exp(Slot),
    Ln(Slot),
    Abs(Slot),
    Sign(Slot),
    /// k-th derivative of sin(x)/x.
    Sinc(u8, Slot),
    /// k-th derivative of (1 - cos x)/x.
    Cosc(u8, Slot),
    /// k-th derivative of (x - sin x)/x^3.
    SincRem(u8, Slot),
    /// n-th derivative of the Rodrigues coefficient c_j(w) (`rodrigues`).
    Rodrigues(u8, u8, Slot),
}

/// The values a kernel reads.
#[derive(Clone, Copy, Debug)]
pub struct Inputs<'a> {
    pub t: f64,
    pub q: &'a [f64],
    pub qd: &'a [f64],
    /// Accelerations; only the `Jvp` kernel reads them (may be empty for
    /// the others).
    pub qdd: &'a [f64],
    /// The `Jvp` kernel's direction (dq, dqd), 2n values (may be empty for
    /// the others).
    pub dir: &'a [f64],
    pub p: &'a [f64],
    /// Values another kernel computed for this one: the contact frames
    /// (`ModelInfo::contact_frames`) the `ContactJacobian` groups read;
    /// empty for the others.
    pub aux: &'a [f64],
}

impl<'a> Inputs<'a> {
    /// These inputs with absent accelerations and direction read from
    /// `zeros` (2n zeros), as every backend's `Jvp` reads them.
    pub fn zero_filled(&self, zeros: &'a [f64]) -> Inputs<'a> {
        let n = zeros.len() / 2;
        Inputs {
            qdd: if self.qdd.is_empty() {
                &zeros[..n]
            } else {
                self.qdd
            },
            dir: if self.dir.is_empty() { zeros } else { self.dir },
            ..*self
        }
    }
}

impl Op {
    /// An input or a constant: read, not computed.
    pub fn is_leaf(&self) -> bool {
        matches!(
            self,
            Op::Const(_)
                | Op::Q(_)
                | Op::Qd(_)
                | Op::Qdd(_)
                | Op::Dir(_)
                | Op::Param(_)
                | Op::Time
                | Op::Aux(_)
        )
    }

    /// Operands, in order.
    pub fn operands(&self) -> impl Iterator<Item = Slot> {
        let (n, s) = match *self {
            Op::MulAdd(a, b, c) | Op::MulSub(a, b, c) | Op::NegMulAdd(a, b, c) => (3, [a, b, c]),
            Op::Add(a, b) | Op::Sub(a, b) | Op::Mul(a, b) | Op::Div(a, b) | Op::Powf(a, b) => {
                (2, [a, b, 0])
            }
            Op::Neg(a)
            | Op::Powi(a, _)
            | Op::Sqrt(a)
            | Op::Sin(a)
            | Op::Cos(a)
            | Op::Tan(a)
            | Op::Exp(a)
            | Op::Ln(a)
            | Op::Abs(a)
            | Op::Sign(a)
            | Op::Sinc(_, a)
            | Op::Cosc(_, a)
            | Op::SincRem(_, a)
            | Op::Rodrigues(_, _, a) => (1, [a, 0, 0]),
            Op::Const(_)
            | Op::Q(_)
            | Op::Qd(_)
            | Op::Qdd(_)
            | Op::Dir(_)
            | Op::Param(_)
            | Op::Time
            | Op::Aux(_) => (0, [0; 3]),
        };
        s.into_iter().take(n)
    }

    /// The same operation reading slot `f(a)` wherever it read slot `a`
    /// (for passes that renumber a tape).
    pub fn map_slots(&self, f: impl Fn(Slot) -> Slot) -> Op {
        match *self {
            Op::Add(a, b) => Op::Add(f(a), f(b)),
            Op::Sub(a, b) => Op::Sub(f(a), f(b)),
            Op::Mul(a, b) => Op::Mul(f(a), f(b)),
            Op::MulAdd(a, b, c) => Op::MulAdd(f(a), f(b), f(c)),
            Op::MulSub(a, b, c) => Op::MulSub(f(a), f(b), f(c)),
            Op::NegMulAdd(a, b, c) => Op::NegMulAdd(f(a), f(b), f(c)),
            Op::Div(a, b) => Op::Div(f(a), f(b)),
            Op::Powf(a, b) => Op::Powf(f(a), f(b)),
            Op::Neg(a) => Op::Neg(f(a)),
            Op::Powi(a, k) => Op::Powi(f(a), k),
            Op::Sqrt(a) => Op::Sqrt(f(a)),
            Op::Sin(a) => Op::Sin(f(a)),
            Op::Cos(a) => Op::Cos(f(a)),
            Op::Tan(a) => Op::Tan(f(a)),
            Op::Exp(a) => Op::Exp(f(a)),
            Op::Ln(a) => Op::Ln(f(a)),
            Op::Abs(a) => Op::Abs(f(a)),
            Op::Sign(a) => Op::Sign(f(a)),
            Op::Sinc(k, a) => Op::Sinc(k, f(a)),
            Op::Cosc(k, a) => Op::Cosc(k, f(a)),
            Op::SincRem(k, a) => Op::SincRem(k, f(a)),
            Op::Rodrigues(j, k, a) => Op::Rodrigues(j, k, f(a)),
            leaf @ (Op::Const(_)
            | Op::Q(_)
            | Op::Qd(_)
            | Op::Qdd(_)
            | Op::Dir(_)
            | Op::Param(_)
            | Op::Time
            | Op::Aux(_)) => leaf,
        }
    }
}

#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Tape {
    pub ops: Vec<Op>,
    /// Slot of each output, in output order.
    pub outputs: Vec<Slot>,
}

impl Tape {
    /// Evaluate into `out` (length `outputs.len()`), using `slots` as scratch.
    pub fn eval(&self, inp: &Inputs, slots: &mut Vec<f64>, out: &mut [f64]) {
        #[cfg(target_arch = "x86_64")]
        if crate::cpu::has_fma() {
            // SAFETY: the processor has FMA (checked just above).
            unsafe { self.eval_fma(inp, slots, out) };
            return;
        }
        self.eval_body(inp, slots, out);
    }

    /// [`Tape::eval`] with `mul_add` as one instruction instead of a libm
    /// call: the same bits, faster.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "fma")]
    fn eval_fma(&self, inp: &Inputs, slots: &mut Vec<f64>, out: &mut [f64]) {
        self.eval_body(inp, slots, out);
    }

    #[inline(always)]
    fn eval_body(&self, inp: &Inputs, slots: &mut Vec<f64>, out: &mut [f64]) {
        slots.resize(self.ops.len(), 0.0);
        // Rodrigues coefficients come in families (`rodrigues::family`):
        // each argument's is computed once and its members read from it.
        let mut families: Vec<(Slot, Family)> = Vec::new();
        for (i, op) in self.ops.iter().enumerate() {
            // Operands come from the slots before this one (the tape's
            // invariant, checked by the split's bounds).
            let (done, rest) = slots.split_at_mut(i);
            let s = |k: Slot| done[k as usize];
            let v = match *op {
                Op::Rodrigues(j, n, a)
                    if usize::from(j) < rodrigues::FAMILY_J
                        && usize::from(n) < rodrigues::FAMILY_ORDERS =>
                {
                    let c = match families.iter().find(|f| f.0 == a) {
                        Some(f) => &f.1,
                        None => {
                            families.push((a, rodrigues::family(s(a))));
                            &families[families.len() - 1].1
                        }
                    };
                    c[usize::from(j)][usize::from(n)]
                }
                Op::Const(c) => c,
                Op::Q(i) => inp.q[i as usize],
                Op::Qd(i) => inp.qd[i as usize],
                Op::Qdd(i) => inp.qdd[i as usize],
                Op::Dir(i) => inp.dir[i as usize],
                Op::Param(i) => inp.p[i as usize],
                Op::Time => inp.t,
                Op::Aux(i) => inp.aux[i as usize],
                Op::Add(a, b) => s(a) + s(b),
                Op::Sub(a, b) => s(a) - s(b),
                Op::Mul(a, b) => s(a) * s(b),
                Op::MulAdd(a, b, c) => s(a).mul_add(s(b), s(c)),
                Op::MulSub(a, b, c) => s(a).mul_add(s(b), -s(c)),
                Op::NegMulAdd(a, b, c) => (-s(a)).mul_add(s(b), s(c)),
                Op::Div(a, b) => s(a) / s(b),
                Op::Neg(a) => -s(a),
                Op::Powi(a, n) => s(a).powi(n),
                Op::Powf(a, b) => s(a).powf(s(b)),
                Op::Sqrt(a) => s(a).sqrt(),
                Op::Sin(a) => special::sin(s(a)),
                Op::Cos(a) => special::cos(s(a)),
                Op::Tan(a) => s(a).tan(),
                Op::Exp(a) => s(a).exp(),
                Op::Ln(a) => s(a).ln(),
                Op::Abs(a) => s(a).abs(),
                Op::Sign(a) => special::sign(s(a)),
                Op::Sinc(k, a) => special::sinc(k, s(a)),
                Op::Cosc(k, a) => special::cosc(k, s(a)),
                Op::SincRem(k, a) => special::sinc_rem(k, s(a)),
                Op::Rodrigues(j, n, a) => rodrigues::rodrigues(j, n, s(a)),
            };
            rest[0] = v;
        }
        for (o, &slot) in out.iter_mut().zip(&self.outputs) {
            *o = slots[slot as usize];
        }
    }

    /// The tape of the outputs `first..first + len` alone, without the
    /// operations only the others need.
    pub fn slice(&self, first: usize, len: usize) -> Tape {
        let outputs = &self.outputs[first..first + len];
        let mut needed = vec![false; self.ops.len()];
        for &s in outputs {
            needed[s as usize] = true;
        }
        for i in (0..self.ops.len()).rev() {
            if needed[i] {
                for a in self.ops[i].operands() {
                    needed[a as usize] = true;
                }
            }
        }
        let mut new_slot = vec![Slot::MAX; self.ops.len()];
        let mut ops = Vec::new();
        for (i, op) in self.ops.iter().enumerate() {
            if needed[i] {
                new_slot[i] = ops.len() as Slot;
                ops.push(op.map_slots(|a| new_slot[a as usize]));
            }
        }
        Tape {
            ops,
            outputs: outputs.iter().map(|&s| new_slot[s as usize]).collect(),
        }
    }

    /// Number of arithmetic operations (inputs and constants excluded; a
    /// fused multiply-add counts as the two it replaces).
    pub fn op_count(&self) -> usize {
        self.ops
            .iter()
            .map(|op| match op {
                _ if op.is_leaf() => 0,
                Op::MulAdd(..) | Op::MulSub(..) | Op::NegMulAdd(..) => 2,
                _ => 1,
            })
            .sum()
    }
}

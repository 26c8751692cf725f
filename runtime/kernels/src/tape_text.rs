//! A tape as compact text, exact to the bit: how generated code carries a
//! kernel it interprets rather than compiles (a kernel that runs once per
//! parameter set gains nothing from compiled code, which would cost build
//! time and source size).
//!
//! One token an instruction, separated by white space: an opcode letter,
//! then its operands joined by commas. A slot operand is written as how
//! far back it is (instruction `i` reading slot `s` writes `i - s`, small
//! numbers for the nearby values most instructions read); indices of
//! inputs and orders are written as they are, a constant in Rust's
//! shortest exponent form (`{:e}`, which parses back to the same bits).
//! After the instructions, `|` and the output slots, comma-separated.

use crate::tape::{Op, Slot, Tape};

impl Tape {
    /// The tape as text (`Tape::from_text` reads it back, equal).
    pub fn to_text(&self) -> String {
        let mut s = String::with_capacity(8 * self.ops.len());
        for (i, op) in self.ops.iter().enumerate() {
            if i > 0 {
                s.push(if i % 16 == 0 { '\n' } else { ' ' });
            }
            let back = |a: &Slot| (i as Slot - a).to_string();
            let (code, args): (char, Vec<String>) = match op {
                Op::Const(c) => ('k', vec![format!("{c:e}")]),
                Op::Q(j) => ('q', vec![j.to_string()]),
                Op::Qd(j) => ('v', vec![j.to_string()]),
                Op::Qdd(j) => ('a', vec![j.to_string()]),
                Op::Dir(j) => ('d', vec![j.to_string()]),
                Op::Param(j) => ('p', vec![j.to_string()]),
                Op::Time => ('t', vec![]),
                Op::Aux(j) => ('x', vec![j.to_string()]),
                Op::Add(a, b) => ('+', vec![back(a), back(b)]),
                Op::Sub(a, b) => ('-', vec![back(a), back(b)]),
                Op::Mul(a, b) => ('*', vec![back(a), back(b)]),
                Op::MulAdd(a, b, c) => ('f', vec![back(a), back(b), back(c)]),
                Op::MulSub(a, b, c) => ('g', vec![back(a), back(b), back(c)]),
                Op::NegMulAdd(a, b, c) => ('h', vec![back(a), back(b), back(c)]),
                Op::Div(a, b) => ('/', vec![back(a), back(b)]),
                Op::Neg(a) => ('n', vec![back(a)]),
                Op::Powi(a, k) => ('i', vec![back(a), k.to_string()]),
                Op::Powf(a, b) => ('w', vec![back(a), back(b)]),
                Op::Sqrt(a) => ('r', vec![back(a)]),
                Op::Sin(a) => ('s', vec![back(a)]),
                Op::Cos(a) => ('c', vec![back(a)]),
                Op::Tan(a) => ('T', vec![back(a)]),
                Op::Exp(a) => ('e', vec![back(a)]),
                Op::Ln(a) => ('l', vec![back(a)]),
                Op::Abs(a) => ('b', vec![back(a)]),
                Op::Sign(a) => ('z', vec![back(a)]),
                Op::Sinc(k, a) => ('S', vec![k.to_string(), back(a)]),
                Op::Cosc(k, a) => ('C', vec![k.to_string(), back(a)]),
                Op::SincRem(k, a) => ('R', vec![k.to_string(), back(a)]),
                Op::Rodrigues(n, j, a) => ('O', vec![n.to_string(), j.to_string(), back(a)]),
            };
            s.push(code);
            s.push_str(&args.join(","));
        }
        s.push_str("\n|");
        let outs: Vec<String> = self.outputs.iter().map(Slot::to_string).collect();
        s.push_str(&outs.join(","));
        s
    }

    /// Read [`Tape::to_text`]'s form; an error names the instruction.
    pub fn from_text(text: &str) -> Result<Tape, String> {
        let (body, outs) = text
            .rsplit_once('|')
            .ok_or("a tape's text ends with `|` and its outputs")?;
        let mut ops = Vec::new();
        for (i, token) in body.split_whitespace().enumerate() {
            let op = parse_op(i, token).ok_or_else(|| format!("instruction {i}: `{token}`"))?;
            ops.push(op);
        }
        let outputs = (outs.split(',').filter(|s| !s.trim().is_empty()))
            .map(|s| {
                s.trim()
                    .parse::<Slot>()
                    .ok()
                    .filter(|&o| (o as usize) < ops.len())
            })
            .collect::<Option<Vec<_>>>()
            .ok_or("an output that is no instruction's slot")?;
        Ok(Tape { ops, outputs })
    }
}

/// A generated kernel carried as tape text (`eomgen`'s `emit_interpreted`):
/// the text read once, at the first call, then interpreted on the inputs.
#[macro_export]
macro_rules! interpreted {
    ($text:literal, $t:expr, $q:expr, $qd:expr, $qdd:expr, $dir:expr, $p:expr, $out:expr) => {{
        static TAPE: std::sync::LazyLock<$crate::tape::Tape> = std::sync::LazyLock::new(|| {
            $crate::tape::Tape::from_text($text).expect("the generated tape reads")
        });
        let inp = $crate::tape::Inputs {
            t: $t,
            q: $q,
            qd: $qd,
            qdd: $qdd,
            dir: $dir,
            p: $p,
            aux: &[],
        };
        TAPE.eval(&inp, &mut Vec::new(), $out);
    }};
}

/// Instruction `i` from its token; None if malformed or reading ahead.
fn parse_op(i: usize, token: &str) -> Option<Op> {
    let mut chars = token.chars();
    let code = chars.next()?;
    let rest = chars.as_str();
    let args: Vec<&str> = if rest.is_empty() {
        Vec::new()
    } else {
        rest.split(',').collect()
    };
    let n = |k: usize| -> Option<u32> { args.get(k)?.parse().ok() };
    // A slot `back` instructions before this one, never this one or later.
    let s = |k: usize| -> Option<Slot> {
        let back: usize = args.get(k)?.parse().ok()?;
        (back >= 1 && back <= i).then(|| (i - back) as Slot)
    };
    let small = |k: usize| -> Option<u8> { args.get(k)?.parse().ok() };
    let op = match (code, args.len()) {
        ('k', 1) => Op::Const(args[0].parse().ok()?),
        ('q', 1) => Op::Q(n(0)?),
        ('v', 1) => Op::Qd(n(0)?),
        ('a', 1) => Op::Qdd(n(0)?),
        ('d', 1) => Op::Dir(n(0)?),
        ('p', 1) => Op::Param(n(0)?),
        ('t', 0) => Op::Time,
        ('x', 1) => Op::Aux(n(0)?),
        ('+', 2) => Op::Add(s(0)?, s(1)?),
        ('-', 2) => Op::Sub(s(0)?, s(1)?),
        ('*', 2) => Op::Mul(s(0)?, s(1)?),
        ('f', 3) => Op::MulAdd(s(0)?, s(1)?, s(2)?),
        ('g', 3) => Op::MulSub(s(0)?, s(1)?, s(2)?),
        ('h', 3) => Op::NegMulAdd(s(0)?, s(1)?, s(2)?),
        ('/', 2) => Op::Div(s(0)?, s(1)?),
        ('n', 1) => Op::Neg(s(0)?),
        ('i', 2) => Op::Powi(s(0)?, args[1].parse().ok()?),
        ('w', 2) => Op::Powf(s(0)?, s(1)?),
        ('r', 1) => Op::Sqrt(s(0)?),
        ('s', 1) => Op::Sin(s(0)?),
        ('c', 1) => Op::Cos(s(0)?),
        ('T', 1) => Op::Tan(s(0)?),
        ('e', 1) => Op::Exp(s(0)?),
        ('l', 1) => Op::Ln(s(0)?),
        ('b', 1) => Op::Abs(s(0)?),
        ('z', 1) => Op::Sign(s(0)?),
        ('S', 2) => Op::Sinc(small(0)?, s(1)?),
        ('C', 2) => Op::Cosc(small(0)?, s(1)?),
        ('R', 2) => Op::SincRem(small(0)?, s(1)?),
        ('O', 3) => Op::Rodrigues(small(0)?, small(1)?, s(2)?),
        _ => return None,
    };
    Some(op)
}

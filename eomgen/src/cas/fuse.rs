//! Fused multiply-adds: the last step of lowering.
//!
//! A sum or difference one of whose operands is a product used nowhere
//! else becomes one fused operation (`Op::MulAdd`, `MulSub`, `NegMulAdd`):
//! a single rounding instead of two and, on processors with FMA, one
//! instruction instead of two. Products read more than once stay, so no
//! multiplication is ever done twice.

use runtime::{Op, Slot, Tape};

/// `tape` with its single-use products fused into the sums that read
/// them, and the products that became dead removed.
pub fn fuse_multiply_adds(tape: Tape) -> Tape {
    let n = tape.ops.len();
    let mut uses = vec![0u32; n];
    for op in &tape.ops {
        for a in op.operands() {
            uses[a as usize] += 1;
        }
    }
    for &o in &tape.outputs {
        uses[o as usize] += 1;
    }
    let product = |s: Slot, uses: &[u32]| match tape.ops[s as usize] {
        Op::Mul(a, b) if uses[s as usize] == 1 => Some((a, b)),
        _ => None,
    };
    let mut ops = tape.ops.clone();
    let mut dead = vec![false; n];
    for (i, op) in tape.ops.iter().enumerate() {
        let fused = match *op {
            Op::Add(x, y) => match (product(x, &uses), product(y, &uses)) {
                (Some((a, b)), _) => Some((Op::MulAdd(a, b, y), x)),
                (None, Some((a, b))) => Some((Op::MulAdd(a, b, x), y)),
                _ => None,
            },
            Op::Sub(x, y) => match (product(x, &uses), product(y, &uses)) {
                (Some((a, b)), _) => Some((Op::MulSub(a, b, y), x)),
                (None, Some((a, b))) => Some((Op::NegMulAdd(a, b, x), y)),
                _ => None,
            },
            _ => None,
        };
        if let Some((f, gone)) = fused {
            ops[i] = f;
            dead[gone as usize] = true;
        }
    }
    // Compact: drop the dead products, renumber what remains.
    let mut new_slot = vec![Slot::MAX; n];
    let mut kept = Vec::with_capacity(n);
    for (i, op) in ops.iter().enumerate() {
        if !dead[i] {
            new_slot[i] = kept.len() as Slot;
            kept.push(op.map_slots(|a| {
                let s = new_slot[a as usize];
                debug_assert!(s != Slot::MAX, "an operand was fused away");
                s
            }));
        }
    }
    Tape {
        ops: kept,
        outputs: tape.outputs.iter().map(|&o| new_slot[o as usize]).collect(),
    }
}

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

#[cfg(test)]
mod tests {
    use super::*;
    use runtime::Inputs;

    fn eval(tape: &Tape, q: &[f64]) -> Vec<f64> {
        let inp = Inputs {
            t: 0.0,
            q,
            qd: &[],
            qdd: &[],
            dir: &[],
            p: &[],
            aux: &[],
        };
        let mut out = vec![0.0; tape.outputs.len()];
        tape.eval(&inp, &mut Vec::new(), &mut out);
        out
    }

    /// q0 q1 + q2, q2 - q0 q1 (the product read twice stays), q0 q2 - q1.
    fn sample() -> Tape {
        use Op::*;
        Tape {
            ops: vec![
                Q(0),
                Q(1),
                Q(2),
                Mul(0, 1), // 3: read twice
                Add(3, 2), // 4
                Sub(2, 3), // 5
                Mul(0, 2), // 6: read once
                Sub(6, 1), // 7
                Mul(1, 2), // 8: read once
                Sub(0, 8), // 9
                Add(4, 5), // 10: no product operand
            ],
            outputs: vec![4, 5, 7, 9, 10],
        }
    }

    #[test]
    fn single_use_products_fuse_and_shared_ones_stay() {
        let fused = fuse_multiply_adds(sample());
        let count = |f: fn(&Op) -> bool| fused.ops.iter().filter(|o| f(o)).count();
        assert_eq!(count(|o| matches!(o, Op::Mul(..))), 1, "{:?}", fused.ops);
        assert_eq!(count(|o| matches!(o, Op::MulSub(..))), 1);
        assert_eq!(count(|o| matches!(o, Op::NegMulAdd(..))), 1);
        // The flops are the same; two instructions are gone.
        assert_eq!(fused.op_count(), sample().op_count());
        assert_eq!(fused.ops.len(), sample().ops.len() - 2);
    }

    #[test]
    fn fused_tapes_compute_the_same_values_with_one_rounding() {
        let (a, b, c) = (0.1f64, 3.0f64, -0.7f64);
        let plain = eval(&sample(), &[a, b, c]);
        let fused = eval(&fuse_multiply_adds(sample()), &[a, b, c]);
        for (x, y) in plain.iter().zip(&fused) {
            assert!((x - y).abs() <= 4.0 * f64::EPSILON * x.abs().max(1.0));
        }
        // Bit for bit what one rounding gives.
        assert_eq!(fused[2].to_bits(), a.mul_add(c, -b).to_bits());
        assert_eq!(fused[3].to_bits(), (-b).mul_add(c, a).to_bits());
    }
}

//! Single-use products fused into the sums that read them
//! (`eomgen::cas::fuse_multiply_adds`): the same values, fewer operations.

use eomgen::cas::*;
use runtime::{Inputs, Op, Tape};

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

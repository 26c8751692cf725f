//! A tape written as text and read back (`tape_text`).

use runtime_kernels::tape::Inputs;
use runtime_kernels::{Op, Slot, Tape};

/// A tape with every instruction, constants of every kind included.
fn every_op() -> Tape {
    let mut ops = vec![
        Op::Q(0),
        Op::Qd(1),
        Op::Qdd(0),
        Op::Dir(1),
        Op::Param(2),
        Op::Time,
        Op::Aux(0),
        Op::Const(0.1),
        Op::Const(-1e-300),
        Op::Const(f64::MAX),
        Op::Const(5e-324),
        Op::Const(-0.0),
    ];
    let more = [
        Op::Add(0, 1),
        Op::Sub(2, 3),
        Op::Mul(4, 5),
        Op::MulAdd(6, 7, 0),
        Op::MulSub(1, 2, 3),
        Op::NegMulAdd(4, 5, 6),
        Op::Div(7, 4),
        Op::Neg(0),
        Op::Powi(1, -3),
        Op::Powf(4, 7),
        Op::Sqrt(4),
        Op::Sin(0),
        Op::Cos(1),
        Op::Tan(7),
        Op::Exp(7),
        Op::Ln(4),
        Op::Abs(3),
        Op::Sign(3),
        Op::Sinc(2, 0),
        Op::Cosc(1, 1),
        Op::SincRem(3, 0),
        Op::Rodrigues(1, 2, 0),
    ];
    ops.extend(more);
    let outputs = (0..ops.len() as Slot).rev().collect();
    Tape { ops, outputs }
}

#[test]
fn text_reads_back_to_the_same_tape_and_bits() {
    let tape = every_op();
    let text = tape.to_text();
    let back = Tape::from_text(&text).unwrap();
    assert_eq!(back.ops.len(), tape.ops.len());
    for (a, b) in back.ops.iter().zip(&tape.ops) {
        match (a, b) {
            (Op::Const(x), Op::Const(y)) => assert_eq!(x.to_bits(), y.to_bits()),
            _ => assert_eq!(a, b),
        }
    }
    assert_eq!(back.outputs, tape.outputs);
    let inp = Inputs {
        t: 0.7,
        q: &[0.3],
        qd: &[0.0, -0.4],
        qdd: &[1.1],
        dir: &[0.0, 0.25],
        p: &[0.0, 0.0, 2.5],
        aux: &[0.9],
    };
    let mut out = [vec![0.0; tape.outputs.len()], vec![0.0; tape.outputs.len()]];
    tape.eval(&inp, &mut Vec::new(), &mut out[0]);
    back.eval(&inp, &mut Vec::new(), &mut out[1]);
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&out[0]), bits(&out[1]));
}

#[test]
fn malformed_text_is_refused_by_instruction() {
    for (text, says) in [
        ("q0 +1,2\n|1", "instruction 1"),
        ("q0 q1 +1\n|1", "instruction 2"),
        ("q0 ?3\n|0", "instruction 1"),
        ("q0 n0\n|0", "instruction 1"),
        ("q0 n1", "ends with `|`"),
        ("q0 n1\n|2", "no instruction's slot"),
    ] {
        let err = Tape::from_text(text).unwrap_err();
        assert!(err.contains(says), "{text:?}: {err}");
    }
}

//! Tapes and their slices evaluated (`tape`).

use runtime_kernels::tape::*;

/// A slice computes its outputs as the whole tape does, without the
/// operations only the others need.
#[test]
fn a_slice_keeps_what_its_outputs_need() {
    // out = [q0 * q1, sin(q0) + p0, q1 + 2]
    let tape = Tape {
        ops: vec![
            Op::Q(0),
            Op::Q(1),
            Op::Mul(0, 1),
            Op::Sin(0),
            Op::Param(0),
            Op::Add(3, 4),
            Op::Const(2.0),
            Op::Add(1, 6),
        ],
        outputs: vec![2, 5, 7],
    };
    let inp = Inputs {
        t: 0.0,
        q: &[0.3, 1.7],
        qd: &[0.0, 0.0],
        qdd: &[],
        dir: &[],
        p: &[0.25],
        aux: &[],
    };
    let (mut slots, mut all) = (Vec::new(), [0.0; 3]);
    tape.eval(&inp, &mut slots, &mut all);
    let part = tape.slice(1, 2);
    assert_eq!(part.ops.len(), 7, "q0 * q1 is not needed");
    let mut out = [0.0; 2];
    part.eval(&inp, &mut slots, &mut out);
    assert_eq!(out, [all[1], all[2]]);
}

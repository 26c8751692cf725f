//! The spatial arm's turn: Rodrigues' formula, its quaternion and its rate.

use eomgen::cas::SymKind;
use eomgen::cas::{Cas, ExprId};
use eomgen::tmt::spatial::*;

/// exp([rho]x) by the closed form, cos t I + sin t / t [rho]x +
/// (1 - cos t) / t^2 rho rho^T with t = |rho|, in f64.
fn rodrigues(rho: [f64; 3]) -> [[f64; 3]; 3] {
    let t = (rho[0] * rho[0] + rho[1] * rho[1] + rho[2] * rho[2]).sqrt();
    if t == 0.0 {
        return std::array::from_fn(|i| std::array::from_fn(|j| f64::from(i == j)));
    }
    let (a, b) = (t.sin() / t, (1.0 - t.cos()) / (t * t));
    let k = [
        [0.0, -rho[2], rho[1]],
        [rho[2], 0.0, -rho[0]],
        [-rho[1], rho[0], 0.0],
    ];
    std::array::from_fn(|i| {
        std::array::from_fn(|j| t.cos() * f64::from(i == j) + a * k[i][j] + b * rho[i] * rho[j])
    })
}

/// The turn's rotation, quaternion and angular velocity at `rho`
/// moving at `rate`, evaluated.
fn turn_at(rho: [f64; 3], rate: [f64; 3]) -> ([[f64; 3]; 3], [f64; 4], [f64; 3]) {
    let mut cas = Cas::new();
    let r: V3 = std::array::from_fn(|i| cas.symbol(&format!("r{i}"), SymKind::Q(i as u32)));
    let v: V3 = std::array::from_fn(|i| cas.symbol(&format!("v{i}"), SymKind::Qd(i as u32)));
    let (m, q, w) = exp_turn(&mut cas, &r, &v);
    let mut roots: Vec<ExprId> = m.iter().flatten().copied().collect();
    roots.extend(q);
    roots.extend(w);
    let value = |s| match cas.sym_kind(s) {
        SymKind::Q(i) => Some(rho[i as usize]),
        SymKind::Qd(i) => Some(rate[i as usize]),
        _ => None,
    };
    let x = cas.eval_many(&roots, &value).unwrap();
    (
        std::array::from_fn(|i| std::array::from_fn(|j| x[3 * i + j])),
        std::array::from_fn(|i| x[9 + i]),
        std::array::from_fn(|i| x[13 + i]),
    )
}

/// exp([rho]x) is the Rodrigues rotation, its quaternion the same
/// rotation, and its angular velocity the one R' R^T gives (central
/// differences along the rate), through the straight state too.
#[test]
fn the_turn_is_rodrigues_its_quaternion_and_its_rate() {
    let rate = [0.3, -0.7, 0.2];
    for rho in [
        [0.0; 3],
        [1e-12, -2e-12, 0.5e-12],
        [0.2, -0.1, 0.4],
        [1.5, 2.0, -0.7],
    ] {
        let (m, q, w) = turn_at(rho, rate);
        let want = rodrigues(rho);
        for i in 0..3 {
            for j in 0..3 {
                assert!((m[i][j] - want[i][j]).abs() < 1e-14, "{rho:?} R[{i}][{j}]");
            }
        }
        let norm = q.iter().map(|c| c * c).sum::<f64>().sqrt();
        assert!((norm - 1.0).abs() < 1e-14, "{rho:?}: |q| = {norm}");
        // The quaternion by the model's own reading of one (a load
        // cell's `sensor_rotation`).
        let from_q = eomgen::model::sensor::SensorRotation::Quaternion(q)
            .matrix()
            .unwrap();
        for i in 0..3 {
            for j in 0..3 {
                assert!(
                    (from_q[i][j] - m[i][j]).abs() < 1e-14,
                    "{rho:?} q -> R[{i}][{j}]"
                );
            }
        }
        let h = 1e-6;
        let step = |s: f64| turn_at(std::array::from_fn(|i| rho[i] + s * rate[i]), rate).0;
        let (a, b) = (step(h), step(-h));
        // [w]x = R' R^T.
        let rd = |i: usize, j: usize| (a[i][j] - b[i][j]) / (2.0 * h);
        let omega = |i: usize, j: usize| (0..3).map(|k| rd(i, k) * m[j][k]).sum::<f64>();
        let fd = [omega(2, 1), omega(0, 2), omega(1, 0)];
        for i in 0..3 {
            assert!(
                (w[i] - fd[i]).abs() < 1e-8,
                "{rho:?}: w {w:?} against {fd:?}"
            );
        }
    }
}

//! The TMT derivation against the textbook double pendulum of uniform rods
//! (docs/design.md section 5), with joint springs and dampers, through the
//! library (both backends) and through `softarm eom`.

use crate::common::*;
use eomgen::load::load_model;
use nalgebra::{DMatrix, DVector};
use runtime::Dynamics;
use softarm::backend::{BackendChoice, load};

const L1: f64 = 0.3;
const L2: f64 = 0.2;
const M1: f64 = 0.5;
const M2: f64 = 0.3;
const K: f64 = 2.0;
const C: f64 = 0.1;
const G: f64 = 9.81;

/// Closed-form M(q) and h(q, qd): q1 from the downward vertical, q2
/// relative; slender uniform rods (I = m l^2 / 12 about the centre).
fn closed_form(q: &[f64], qd: &[f64]) -> ([[f64; 2]; 2], [f64; 2]) {
    let (i1, i2) = (M1 * L1 * L1 / 12.0, M2 * L2 * L2 / 12.0);
    let (c2, s2) = (q[1].cos(), q[1].sin());
    let m11 =
        i1 + M1 * (L1 / 2.0).powi(2) + i2 + M2 * (L1 * L1 + (L2 / 2.0).powi(2) + L1 * L2 * c2);
    let m12 = i2 + M2 * ((L2 / 2.0).powi(2) + L1 * (L2 / 2.0) * c2);
    let m22 = i2 + M2 * (L2 / 2.0).powi(2);
    let hc = M2 * L1 * (L2 / 2.0) * s2;
    let coriolis = [
        -hc * (2.0 * qd[0] * qd[1] + qd[1] * qd[1]),
        hc * qd[0] * qd[0],
    ];
    let s1 = q[0].sin();
    let s12 = (q[0] + q[1]).sin();
    let gravity = [
        M1 * G * (L1 / 2.0) * s1 + M2 * G * (L1 * s1 + (L2 / 2.0) * s12),
        M2 * G * (L2 / 2.0) * s12,
    ];
    let h = [
        coriolis[0] + gravity[0] + K * q[0] + C * qd[0],
        coriolis[1] + gravity[1] + K * q[1] + C * qd[1],
    ];
    ([[m11, m12], [m12, m22]], h)
}

fn random_states(n: usize) -> Vec<(Vec<f64>, Vec<f64>)> {
    let mut rng = Rng::new(20261121);
    (0..n)
        .map(|_| (rng.vec(2, -3.0, 3.0), rng.vec(2, -4.0, 4.0)))
        .collect()
}

fn check(arm: &dyn Dynamics, label: &str) {
    for (q, qd) in random_states(25) {
        let (m_ref, h_ref) = closed_form(&q, &qd);
        let mut m = DMatrix::zeros(2, 2);
        let mut h = DVector::zeros(2);
        arm.mass_bias(0.0, &q, &qd, &mut m, &mut h);
        for i in 0..2 {
            for j in 0..2 {
                assert_close(
                    m[(i, j)],
                    m_ref[i][j],
                    1e-12,
                    0.0,
                    format_args!("{label} M[{i}][{j}] at {q:?}"),
                );
            }
            // The floor covers terms that cancel to near zero in one form only.
            assert_close(
                h[i],
                h_ref[i],
                1e-12,
                1e-3,
                format_args!("{label} h[{i}] at {q:?} {qd:?}"),
            );
        }
    }
}

#[test]
fn compiled_matches_closed_form() {
    let l = load("double_pendulum", &[], BackendChoice::Compiled, None).unwrap();
    assert_eq!(l.arm.backend(), "compiled");
    check(&*l.arm, "compiled");
}

#[test]
fn interpreted_matches_closed_form() {
    let dir = tempfile::tempdir().unwrap();
    let l = load(
        "double_pendulum",
        &[],
        BackendChoice::Interpreted,
        Some(dir.path().to_path_buf()),
    )
    .unwrap();
    assert_eq!(l.arm.backend(), "interpreted");
    check(&*l.arm, "interpreted");
}

#[test]
fn model_file_holds_the_textbook_values() {
    // The constants above are the model's: a change to either shows here.
    let m = load_model(&model_path("double_pendulum"), &[]).unwrap();
    assert_eq!((m.segments[0].length, m.segments[0].mass), (L1, Some(M1)));
    assert_eq!((m.segments[1].length, m.segments[1].mass), (L2, Some(M2)));
    assert_eq!(m.segments[0].joint_stiffness, Some(K));
    assert_eq!(m.segments[1].joint_damping, Some(C));
    assert_eq!(m.gravity, [0.0, -G, 0.0]);
}

#[test]
fn cli_eom_matches_closed_form() {
    let dir = tempfile::tempdir().unwrap();
    for (q, qd) in random_states(20) {
        let qs = format!("{},{}", q[0], q[1]);
        let qds = format!("{},{}", qd[0], qd[1]);
        let out = softarm(
            &["eom", "double_pendulum", "--q", &qs, "--qd", &qds, "--json"],
            dir.path(),
        );
        assert!(out.status.success(), "{}", stderr(&out));
        let v: serde_json::Value = serde_json::from_str(&stdout(&out)).unwrap();
        let (m_ref, h_ref) = closed_form(&q, &qd);
        for i in 0..2 {
            for j in 0..2 {
                let m = v["mass"][i][j].as_f64().unwrap();
                assert_close(m, m_ref[i][j], 1e-12, 0.0, "cli M");
            }
            let h = v["bias"][i].as_f64().unwrap();
            assert_close(h, h_ref[i], 1e-12, 1e-3, "cli h");
        }
        // Tip: the end of rod 2.
        let tip = [
            L1 * q[0].sin() + L2 * (q[0] + q[1]).sin(),
            -L1 * q[0].cos() - L2 * (q[0] + q[1]).cos(),
        ];
        assert_close(
            v["tip_position"][0].as_f64().unwrap(),
            tip[0],
            1e-12,
            1e-3,
            "tip x",
        );
        assert_close(
            v["tip_position"][1].as_f64().unwrap(),
            tip[1],
            1e-12,
            1e-3,
            "tip y",
        );
    }
}

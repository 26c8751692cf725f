//! The Rodrigues family against its closed forms and long series (`rodrigues`).

use runtime_kernels::rodrigues::*;

/// The closed forms in theta, written out.
fn c(j: u8, w: f64) -> f64 {
    let t = w.sqrt();
    match j {
        0 => t.cos(),
        1 => t.sin() / t,
        2 => (1.0 - t.cos()) / w,
        3 => (t - t.sin()) / (w * t),
        _ => unreachable!(),
    }
}

#[test]
fn values_match_the_closed_forms_in_theta() {
    for &w in &[0.3f64, 1.0, 2.5, 8.9, 9.1, 20.0, 80.0] {
        for j in 0..=3 {
            let (a, b) = (rodrigues(j, 0, w), c(j, w));
            assert!(
                (a - b).abs() <= 1e-14 * b.abs().max(0.1),
                "c{j}({w}): {a} vs {b}"
            );
        }
    }
}

#[test]
fn limits_at_zero_are_the_series_constants() {
    assert_eq!(rodrigues(0, 0, 0.0), 1.0);
    assert_eq!(rodrigues(1, 0, 0.0), 1.0);
    assert_eq!(rodrigues(2, 0, 0.0), 0.5);
    assert_eq!(rodrigues(3, 0, 0.0), 1.0 / 6.0);
    assert_eq!(rodrigues(4, 0, 0.0), 1.0 / 24.0);
    // c1' = -1/3! , c2' = -1/4!
    assert!((rodrigues(1, 1, 0.0) + 1.0 / 6.0).abs() < 1e-17);
    assert!((rodrigues(2, 1, 0.0) + 1.0 / 24.0).abs() < 1e-17);
    // c1'' = 2 * 1/5!
    assert!((rodrigues(1, 2, 0.0) - 2.0 / 120.0).abs() < 1e-17);
}

#[test]
fn derivatives_match_central_differences_on_both_branches() {
    for &w in &[-3.0f64, -0.2, 0.0, 0.7, 4.0, 8.99, 9.01, 15.0, 40.0] {
        for j in 0..=4u8 {
            for n in 0..=3u8 {
                let h = 1e-4 * w.abs().max(1.0);
                let fd = (rodrigues(j, n, w + h) - rodrigues(j, n, w - h)) / (2.0 * h);
                let d = rodrigues(j, n + 1, w);
                let scale = d.abs().max(rodrigues(j, n, w).abs()).max(1e-6);
                assert!(
                    (fd - d).abs() < 1e-6 * scale,
                    "c{j}^({}) at {w}: {d} vs fd {fd}",
                    n + 1
                );
            }
        }
    }
}

#[test]
fn branches_meet_at_the_switch() {
    for j in 0..=4u8 {
        for n in 0..=4u8 {
            let (s, c) = (series(j, n, SERIES_BELOW), closed(j, n, SERIES_BELOW));
            assert!(
                (s - c).abs() < 1e-11 * s.abs().max(1e-6),
                "c{j}^({n}): series {s} closed {c}"
            );
        }
    }
}

#[test]
fn tabled_series_match_the_long_series() {
    for &w in &[
        0.0f64, 0.1, -0.2, 0.249, 0.3, 0.99, 1.5, 3.99, 4.5, 8.99, -8.0,
    ] {
        for j in 0..FAMILY_J as u8 {
            for n in 0..FAMILY_ORDERS as u8 {
                let (a, b) = (rodrigues(j, n, w), series(j, n, w));
                let scale = series(j, n, 0.0).abs();
                assert!(
                    (a - b).abs() <= 2e-15 * scale.max(b.abs()),
                    "c{j}^({n})({w}): family {a:e} vs series {b:e}"
                );
            }
        }
    }
}

#[test]
fn family_members_do_not_depend_on_how_many_orders_are_asked() {
    for &w in &[0.0f64, 1e-12, -0.3, 0.7, 2.0, 8.5, 9.5, 30.0] {
        let all = family::<FAMILY_ORDERS>(w);
        let two = family::<2>(w);
        let three = family::<3>(w);
        for j in 0..FAMILY_J {
            for n in 0..2 {
                assert_eq!(two[j][n].to_bits(), all[j][n].to_bits(), "c{j}^({n})({w})");
            }
            for n in 0..3 {
                assert_eq!(
                    three[j][n].to_bits(),
                    all[j][n].to_bits(),
                    "c{j}^({n})({w})"
                );
            }
        }
    }
}

#[test]
fn recurrence_identity_holds() {
    // c_j = 1/j! - w c_{j+2}
    for &w in &[0.0f64, 0.4, 3.0, 12.0] {
        for j in 0..=3u8 {
            let lhs = rodrigues(j, 0, w);
            let rhs = 1.0 / factorial(j as u32) - w * rodrigues(j + 2, 0, w);
            assert!((lhs - rhs).abs() < 1e-13, "j {j} w {w}");
        }
    }
}

/// n!, the references' own.
fn factorial(n: u32) -> f64 {
    (1..=n).map(f64::from).product()
}

//! The special functions against their long series (`special`).

use runtime_kernels::special::*;

/// Four lanes give the bits of four scalar calls: lanes that share a
/// series length, lanes that do not, and lanes past the series.
#[test]
fn lanes_have_the_bits_of_scalar_calls() {
    let groups = [
        [0.0, 1e-9, -0.2, 0.24],
        [0.3, -0.45, 0.26, 0.49],
        [0.6, -0.9, 0.75, 0.99],
        [0.1, 0.3, -0.7, 0.2],
        [0.5, 1.5, -3.0, 0.7],
    ];
    let same = |a: Lanes, b: [f64; 4], what: &str| {
        for l in 0..4 {
            assert_eq!(a[l].to_bits(), b[l].to_bits(), "{what} lane {l}");
        }
    };
    for x in groups {
        let (s, c) = sin_cos_x4(x);
        same(s, x.map(|x| sin_cos(x).0), "sin");
        same(c, x.map(|x| sin_cos(x).1), "cos");
        let lanes = [
            sinc_orders_x4::<3>(x),
            cosc_orders_x4(x),
            sinc_rem_orders_x4(x),
        ];
        let scalar: [fn(f64) -> [f64; 3]; 3] =
            [sinc_orders::<3>, cosc_orders::<3>, sinc_rem_orders::<3>];
        for (lane, f) in lanes.iter().zip(scalar) {
            for (k, order) in lane.iter().enumerate() {
                same(*order, x.map(|x| f(x)[k]), &format!("order {k} at {x:?}"));
            }
        }
    }
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + a.abs().max(b.abs()))
}

#[test]
fn values_match_closed_forms() {
    for &x in &[-2.5, -1.0, -0.999, -0.3, 1e-9, 0.3, 0.999, 1.0, 1.7, 3.0] {
        let f: f64 = x;
        assert!(close(sinc(0, x), f.sin() / f, 1e-14), "sinc {x}");
        assert!(close(cosc(0, x), (1.0 - f.cos()) / f, 1e-7), "cosc {x}");
        // d/dx sin(x)/x = (x cos x - sin x)/x^2
        let d1 = (f * f.cos() - f.sin()) / (f * f);
        if x.abs() > 1e-3 {
            assert!(close(sinc(1, x), d1, 1e-12), "sinc' {x}");
        }
    }
}

#[test]
fn sinc_rem_matches_its_closed_form_and_limits() {
    for &x in &[-2.5f64, -1.0, -0.5, 0.3, 0.999, 1.001, 1.7, 3.0] {
        let closed = (x - x.sin()) / (x * x * x);
        assert!(close(sinc_rem(0, x), closed, 1e-9), "x={x}");
    }
    assert!(close(sinc_rem(0, 0.0), 1.0 / 6.0, 1e-15));
    assert_eq!(sinc_rem(1, 0.0), 0.0);
    assert!(close(sinc_rem(2, 0.0), -2.0 / 120.0, 1e-15));
}

/// The series as a long sum, smallest terms first: the reference for the
/// truncation in `terms_for`.
fn long_series(first: u32, shift: u32, k: u32, x: f64) -> f64 {
    let mut terms = Vec::new();
    for j in 0..30u32 {
        let m = first + 2 * j;
        if m < k {
            continue;
        }
        let sign = if j % 2 == 0 { 1.0 } else { -1.0 };
        terms.push(sign * falling(m, k) / factorial(m + shift) * x.powi((m - k) as i32));
    }
    terms.iter().rev().sum()
}

#[test]
fn truncated_series_match_the_long_series_to_round_off() {
    type Removable = fn(u8, f64) -> f64;
    // (name, function, lowest exponent, factorial shift)
    let cases: [(&str, Removable, u32, u32); 3] = [
        ("sinc", sinc, 0, 1),
        ("cosc", cosc, 1, 1),
        ("sinc_rem", sinc_rem, 0, 3),
    ];
    for (name, f, first, shift) in cases {
        for k in 0..TABLE_ORDERS as u8 {
            for i in -200..200 {
                let x = i as f64 / 200.0 * 0.9999;
                let reference = long_series(first, shift, u32::from(k), x);
                let got = f(k, x);
                let scale = reference.abs().max(f64::MIN_POSITIVE);
                assert!(
                    (got - reference).abs() <= 8.0 * f64::EPSILON * scale,
                    "{name}^({k})({x}) = {got}, long series {reference}"
                );
            }
        }
    }
}

#[test]
fn small_angle_sin_cos_matches_libm_to_two_ulp() {
    for i in -2000..=2000 {
        let x = i as f64 / 2000.0 * std::f64::consts::FRAC_PI_4;
        let (s, c) = sin_cos(x);
        assert!(
            (s - x.sin()).abs() <= 2.0 * f64::EPSILON * x.sin().abs(),
            "sin {x}"
        );
        assert!(
            (c - x.cos()).abs() <= 2.0 * f64::EPSILON * x.cos(),
            "cos {x}"
        );
    }
    // Past pi/4 the libm path; both sides of the switch agree.
    let (a, b) = (
        std::f64::consts::FRAC_PI_4,
        std::f64::consts::FRAC_PI_4.next_up(),
    );
    assert!((sin_cos(a).0 - sin_cos(b).0).abs() < 1e-15);
    assert!((sin_cos(a).1 - sin_cos(b).1).abs() < 1e-15);
}

#[test]
fn orders_agree_bit_for_bit_with_single_orders() {
    for i in -300..300 {
        let x = i as f64 / 97.0;
        let s: [f64; 4] = sinc_orders(x);
        let c: [f64; 4] = cosc_orders(x);
        let r: [f64; 4] = sinc_rem_orders(x);
        for k in 0..4u8 {
            let j = k as usize;
            assert_eq!(s[j].to_bits(), sinc(k, x).to_bits(), "sinc {k} {x}");
            assert_eq!(c[j].to_bits(), cosc(k, x).to_bits(), "cosc {k} {x}");
            assert_eq!(r[j].to_bits(), sinc_rem(k, x).to_bits(), "rem {k} {x}");
        }
    }
}

#[test]
fn limits_at_zero() {
    assert_eq!(sinc(0, 0.0), 1.0);
    assert_eq!(sinc(1, 0.0), 0.0);
    assert!(close(sinc(2, 0.0), -1.0 / 3.0, 1e-15));
    assert_eq!(cosc(0, 0.0), 0.0);
    assert!(close(cosc(1, 0.0), 0.5, 1e-15));
    assert_eq!(cosc(2, 0.0), 0.0);
    assert!(close(cosc(3, 0.0), -0.25, 1e-15)); // 3! * (-1/24)
}

#[test]
fn branches_meet_continuously() {
    // Both sides of the switch agree for every order used in practice.
    for k in 0..6u8 {
        let below = 1.0 - 1e-12;
        let above = 1.0 + 1e-12;
        assert!(close(sinc(k, below), sinc(k, above), 1e-11), "sinc k={k}");
        assert!(close(cosc(k, below), cosc(k, above), 1e-11), "cosc k={k}");
        assert!(
            close(sinc_rem(k, below), sinc_rem(k, above), 1e-10),
            "sinc_rem k={k}"
        );
        assert!(close(sinc(k, -below), sinc(k, -above), 1e-11));
        assert!(close(cosc(k, -below), cosc(k, -above), 1e-11));
    }
}

#[test]
fn derivatives_match_finite_differences() {
    for k in 0..5u8 {
        for &x in &[-2.0, -0.7, 0.0, 0.2, 0.95, 1.05, 2.4] {
            let h = 1e-5;
            let fd = (sinc(k, x + h) - sinc(k, x - h)) / (2.0 * h);
            assert!(close(sinc(k + 1, x), fd, 1e-7), "sinc k={k} x={x}");
            let fd = (cosc(k, x + h) - cosc(k, x - h)) / (2.0 * h);
            assert!(close(cosc(k + 1, x), fd, 1e-7), "cosc k={k} x={x}");
            let fd = (sinc_rem(k, x + h) - sinc_rem(k, x - h)) / (2.0 * h);
            assert!(close(sinc_rem(k + 1, x), fd, 1e-7), "sinc_rem k={k} x={x}");
        }
    }
}

/// n!, the references' own.
fn factorial(n: u32) -> f64 {
    (1..=n).map(f64::from).product()
}

/// m (m - 1) ... (m - k + 1), the references' own.
fn falling(m: u32, k: u32) -> f64 {
    (0..k).map(|i| f64::from(m) - f64::from(i)).product()
}

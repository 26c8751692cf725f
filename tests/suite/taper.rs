//! Tapered segments (`outer_radius = [base, tip]`) against beam theory and
//! the Cosserat rod:
//!
//! * a small tip load bends a linearly tapered cantilever by
//!   int P (L - s)^2 / (E I(s)) ds (plus int P / (k G A(s)) ds where the
//!   method shears), the integral taken here by Simpson's rule: every
//!   method converges to it, the Cosserat rod to its step error;
//! * its own weight bends it by int M(s) (L - s) / (E I(s)) ds with
//!   M(s) = int_s^L rho g A(t) (t - s) dt: the mass is where the section is;
//! * far from straight, pcc and the Cosserat rod agree.

use std::f64::consts::PI;

use crate::common::*;

const L: f64 = 0.2;
const E: f64 = 1e6;
const RHO: f64 = 1000.0;
const R0: f64 = 0.012;
const R1: f64 = 0.006;

fn radius(s: f64) -> f64 {
    R0 + (R1 - R0) * s / L
}

fn ei(s: f64) -> f64 {
    E * PI * radius(s).powi(4) / 4.0
}

fn area(s: f64) -> f64 {
    PI * radius(s).powi(2)
}

/// int_a^b f by Simpson's rule on `n` (even) intervals.
fn simpson(a: f64, b: f64, n: usize, f: impl Fn(f64) -> f64) -> f64 {
    let h = (b - a) / n as f64;
    let inner: f64 = (1..n)
        .map(|k| f(a + k as f64 * h) * if k % 2 == 1 { 4.0 } else { 2.0 })
        .sum();
    (f(a) + f(b) + inner) * h / 3.0
}

fn model(tip_force: f64, gravity: f64) -> String {
    format!(
        r#"
name = "tapered"
dimensions = 3
gravity = [0.0, 0.0, {gravity}]
[base]
direction = [1.0, 0.0, 0.0]
[[segment]]
method = "pcc"
length = {L}
elements = 8
density = {RHO}
outer_radius = [{R0}, {R1}]
youngs_modulus = {E}
[tip]
force = [0.0, 0.0, {tip_force}]
"#
    )
}

/// Each method's sets at a coarse and a fine resolution, and whether it
/// shears (pcs, eba).
fn methods() -> Vec<(&'static str, [Vec<String>; 2], bool)> {
    let by_elements = |m| [method_sets(m, 8), method_sets(m, 16)];
    let mut rom = by_elements("rom");
    for r in &mut rom {
        r.push("segment.0.order=5".into());
    }
    vec![
        ("pcc", by_elements("pcc"), false),
        ("vc", by_elements("vc"), false),
        ("ebr", by_elements("ebr"), false),
        ("rigid", by_elements("rigid"), false),
        ("pcs", by_elements("pcs"), true),
        ("eba", by_elements("eba"), true),
        ("rom", rom, false),
    ]
}

#[test]
fn a_tapered_cantilever_bends_as_the_integral_of_m_over_ei() {
    let dir = tempfile::tempdir().unwrap();
    let p = 1e-4; // 0.02 % of L: beam theory's linear range
    let text = model(-p, 0.0);
    let bending = simpson(0.0, L, 20_000, |s| p * (L - s).powi(2) / ei(s));
    let shearing = simpson(0.0, L, 20_000, |s| p / (E / 3.0 * area(s)));
    // The bending deflection is 10^4 times its linearisation error.
    assert!(bending / L < 2e-4, "{bending}");
    for (method, [coarse, fine], shears) in methods() {
        let want = bending + if shears { shearing } else { 0.0 };
        let err = |sets: &[String]| (-static_tip(dir.path(), &text, sets)[2] - want) / want;
        let (e_coarse, e_fine) = (err(&coarse), err(&fine));
        // Each element at its middle section: second order (or better).
        assert!(
            e_fine.abs() < 2e-3 && e_fine.abs() * 3.5 < e_coarse.abs(),
            "{method}: relative error {e_coarse:.2e} at the coarse resolution, {e_fine:.2e} at the fine"
        );
    }
    let rod = static_tip(dir.path(), &text, &["segment.0.method=cosserat".into()]);
    assert_close(-rod[2], bending, 1e-6, 0.0, "the Cosserat rod");
}

#[test]
fn a_tapered_cantilever_sags_under_its_own_weight_as_beam_theory_says() {
    let dir = tempfile::tempdir().unwrap();
    let g = 9.81e-3; // a milli-g: the linear range
    let text = model(0.0, -g);
    let moment = |s: f64| simpson(s, L, 400, |t| RHO * g * area(t) * (t - s));
    let want = simpson(0.0, L, 400, |s| moment(s) * (L - s) / ei(s));
    assert!(want / L < 2e-4, "{want}");
    let pcc = |n: usize| {
        let sets = [format!("segment.0.elements={n}")];
        (-static_tip(dir.path(), &text, &sets)[2] - want) / want
    };
    // pcc lumps each element's weight: second order (on a uniform rod,
    // -1.3e-3 at 16 elements).
    let (coarse, fine) = (pcc(16), pcc(32));
    assert!(
        fine.abs() < 1e-3 && fine.abs() * 3.5 < coarse.abs(),
        "pcc: relative error {coarse:.2e} at 16 elements, {fine:.2e} at 32"
    );
    let rod = static_tip(dir.path(), &text, &["segment.0.method=cosserat".into()]);
    assert_close(-rod[2], want, 1e-5, 0.0, "the Cosserat rod");
}

#[test]
fn a_tapered_cantilever_bent_far_matches_the_cosserat_rod() {
    let dir = tempfile::tempdir().unwrap();
    // A tip load that bends the rod far from straight.
    let text = model(-0.4, 0.0);
    let rod = static_tip(dir.path(), &text, &["segment.0.method=cosserat".into()]);
    assert!(-rod[2] > 0.25 * L, "bent far: {rod:?}");
    let pcc = static_tip(dir.path(), &text, &["segment.0.elements=24".into()]);
    for c in 0..3 {
        assert_close(
            pcc[c],
            rod[c],
            1e-4,
            L,
            format_args!("pcc's tip, component {c}"),
        );
    }
}

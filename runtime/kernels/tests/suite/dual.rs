//! Dual numbers' rules against central differences (`dual`).

use runtime_kernels::dual::*;

/// Each rule against a central difference of its value.
#[test]
fn every_rule_matches_a_central_difference() {
    let h = 1e-6;
    type Rule = fn(Dual) -> Dual;
    let rules: Vec<(&str, f64, Rule)> = vec![
        ("mul", 0.7, |x| x * x * 3.0),
        ("div", 0.7, |x| (x + 2.0) / (x * x + 1.0)),
        ("sqrt", 0.7, |x| x.sqrt()),
        ("powi", 0.7, |x| x.powi(3)),
        ("powf", 0.7, |x| x.powf(x + 0.5)),
        ("powf const", 0.7, |x| x.powf(Dual::constant(2.5))),
        ("sin", 0.7, |x| x.sin_cos().0),
        ("cos", 1.3, |x| x.sin_cos().1),
        ("tan", 0.7, |x| x.tan()),
        ("exp", 0.7, |x| x.exp()),
        ("ln", 0.7, |x| x.ln()),
        ("abs", -0.7, |x| x.abs()),
        ("sinc", 0.7, |x| x.sinc(1)),
        ("cosc", 2.7, |x| x.cosc(2)),
        ("sinc_rem", 0.3, |x| x.sinc_rem(0)),
        ("rodrigues", 0.4, |x| x.rodrigues(3, 1)),
        ("rodrigues family", 0.4, |x| x.rodrigues_family::<5>()[2][4]),
        ("mul_add", 0.7, |x| x.mul_add(x, x * 2.0)),
    ];
    for (name, x, f) in rules {
        let exact = f(Dual::new(x, 1.0)).d;
        let fd = (f(Dual::constant(x + h)).v - f(Dual::constant(x - h)).v) / (2.0 * h);
        assert!(
            (exact - fd).abs() < 1e-7 * (1.0 + fd.abs()),
            "{name}: {exact} against {fd}"
        );
    }
}

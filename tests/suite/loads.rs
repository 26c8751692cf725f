//! Loads along the arm (`[[load]]`) against beam theory and against the
//! tip loads they generalise, on a cantilever (L = 0.2 m, r = 10 mm,
//! E = 1 MPa):
//!
//! * a force P at mid-span bends the tip by 5 P L^3 / (48 E I) (plus
//!   P a / (k G A) where the method shears), every method converging at
//!   second order, in 3D and in the plane;
//! * a moment M at a bends the tip by M a (2 L - a) / (2 E I), on an
//!   element boundary or inside an element;
//! * a force q per unit length bends it by q L^4 / (8 E I), also on the
//!   Cosserat rod;
//! * a point load at the tip in the section's frame is the tip force in
//!   the tip's frame, far from straight; an input drives a load as a
//!   constant does.

use std::f64::consts::PI;

use crate::common::*;

pub(crate) const L: f64 = 0.2;
pub(crate) const E: f64 = 1e6;
pub(crate) const R: f64 = 0.01;

pub(crate) fn ei() -> f64 {
    E * PI * R.powi(4) / 4.0
}

/// The loaded cantilever, eight pcc elements, with `extra` (its loads).
pub(crate) fn cantilever(dimensions: u8, extra: &str) -> String {
    format!(
        r#"
name = "loaded"
dimensions = {dimensions}
gravity = [0.0, 0.0, 0.0]
[base]
direction = [1.0, 0.0, 0.0]
[[segment]]
method = "pcc"
length = {L}
elements = 8
density = 1000.0
outer_radius = {R}
youngs_modulus = {E}
{extra}
"#
    )
}

/// Relative errors at two resolutions, the second twice the first.
fn converges(errors: (f64, f64), what: &str) {
    let (coarse, fine) = errors;
    assert!(
        fine.abs() < 3e-3 && (fine.abs() * 3.5 < coarse.abs() || fine.abs() < 1e-6),
        "{what}: relative error {coarse:.2e}, then {fine:.2e} at twice the elements"
    );
}

#[test]
fn a_force_at_mid_span_bends_the_tip_as_beam_theory_says() {
    let dir = tempfile::tempdir().unwrap();
    let p = 1e-3;
    let point = format!(
        "[[load]]\nsegment = 0\ns = {}\nforce = [0.0, {p}, 0.0]",
        L / 2.0
    );
    let want = 5.0 * p * L.powi(3) / (48.0 * ei());
    for dims in [3, 2] {
        let text = cantilever(dims, &point);
        let methods: &[&str] = if dims == 3 {
            &["pcc", "ebr", "rigid", "pcs", "rom"]
        } else {
            &["pcc", "rigid"]
        };
        for &method in methods {
            let shear = match method {
                "pcs" => p * L / 2.0 / (E / 3.0 * PI * R * R),
                _ => 0.0,
            };
            // 7 and 14 elements put the load inside an element, 8 and 16
            // on a boundary.
            let err = |n| {
                (static_tip(dir.path(), &text, &method_sets(method, n))[1] - want - shear) / want
            };
            converges((err(7), err(14)), &format!("{method} in {dims}D"));
            converges((err(8), err(16)), &format!("{method} in {dims}D"));
        }
    }
}

/// The same force on eba's absolute elements, which shear as pcs does;
/// its finite differences converge at second order from further, so at
/// twice the elements.
#[test]
fn a_force_at_mid_span_bends_an_eba_arm_as_beam_theory_says() {
    let dir = tempfile::tempdir().unwrap();
    let p = 1e-3;
    let point = format!(
        "[[load]]\nsegment = 0\ns = {}\nforce = [0.0, {p}, 0.0]",
        L / 2.0
    );
    let want = 5.0 * p * L.powi(3) / (48.0 * ei()) + p * L / 2.0 / (E / 3.0 * PI * R * R);
    let text = cantilever(3, &point);
    let err = |n| (static_tip(dir.path(), &text, &method_sets("eba", n))[1] - want) / want;
    converges((err(14), err(28)), "eba, the load inside an element");
    converges((err(16), err(32)), "eba, the load on a boundary");
}

#[test]
fn a_moment_and_a_distributed_force_bend_it_as_beam_theory_says() {
    let dir = tempfile::tempdir().unwrap();
    let (m, a) = (2e-5, 0.05);
    let moment = format!("[[load]]\nsegment = 0\ns = {a}\nmoment = [0.0, 0.0, {m}]");
    let want = m * a * (2.0 * L - a) / (2.0 * ei());
    for dims in [3, 2] {
        let text = cantilever(dims, &moment);
        let err = |n| (static_tip(dir.path(), &text, &method_sets("pcc", n))[1] - want) / want;
        converges((err(8), err(16)), &format!("a moment in {dims}D"));
        // Inside an element, at the fraction f of it, the moment does work
        // on the section's share f of the element's bend, which carries
        // the element's whole length at f M / E I: the tip falls short by
        // M l^2 f (1 - f) / (2 E I) of beam theory (7 elements: f = 3/4,
        // 14: f = 1/2), exactly the model's own.
        for (n, f) in [(7, 0.75), (14, 0.5)] {
            let l = L / n as f64;
            let short = m * l * l * f * (1.0 - f) / (2.0 * ei()) / want;
            let what = format!("a moment inside an element, {n} elements, in {dims}D");
            assert_close(err(n), -short, 1e-6, 0.0, &what);
        }
    }
    let q = 1e-2;
    let spread = format!("[[load]]\nsegment = 0\nforce = [0.0, 0.0, {q}]");
    let text = cantilever(3, &spread);
    let want = q * L.powi(4) / (8.0 * ei());
    let err = |n| (static_tip(dir.path(), &text, &method_sets("pcc", n))[2] - want) / want;
    converges((err(8), err(16)), "a force per unit length");
    let rod = static_tip(dir.path(), &text, &["segment.0.method=cosserat".into()]);
    assert_close(rod[2], want, 1e-3, 0.0, "the Cosserat rod under it");
}

#[test]
fn a_local_point_load_at_the_tip_is_the_tip_force_in_the_tips_frame() {
    let dir = tempfile::tempdir().unwrap();
    // Far from straight: a follower force across the arm.
    let force = "force = [0.0, 0.0, -0.5]";
    let point = format!("[[load]]\nsegment = 0\ns = {L}\nframe = \"local\"\n{force}");
    let tip = format!("[tip]\n{force}\nwrench_frame = \"tip\"");
    let a = static_tip(dir.path(), &cantilever(3, &point), &[]);
    let b = static_tip(dir.path(), &cantilever(3, &tip), &[]);
    assert!(a[2] < -0.2 * L, "bent far: {a:?}");
    for c in 0..3 {
        assert_close(a[c], b[c], 1e-9, L, format_args!("component {c}"));
    }
    // An input drives it as the constant does.
    let driven = point.replace(
        force,
        "force_inputs = [\"zero\", \"zero\", \"f\"]\n[inputs.f]\nkind = \"constant\"\nvalue = -0.5\n[inputs.zero]\nkind = \"constant\"\nvalue = 0.0",
    );
    let c = static_tip(dir.path(), &cantilever(3, &driven), &[]);
    for k in 0..3 {
        assert_close(c[k], a[k], 1e-12, L, format_args!("driven, component {k}"));
    }
}

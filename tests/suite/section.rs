//! Rectangular and elliptic sections (`[segment.section]`) against beam
//! theory: a planar arm bends by M / (E I_z) with I_z = w h^3 / 12 (a
//! rectangle) or pi w h^3 / 64 (an ellipse), h its side in the plane; it
//! sags under its own weight by q L^4 / (8 E I) with q = rho A g; a square
//! twists by M L / (G J), J St-Venant's 0.1406 a^4 (the series solution).

use std::f64::consts::PI;

use crate::common::*;

const L: f64 = 0.2;
const E: f64 = 1e6;
const RHO: f64 = 1000.0;

fn arm(dimensions: u8, section: &str, elements: usize, extra: &str) -> String {
    format!(
        r#"
name = "sectioned"
dimensions = {dimensions}
gravity = [0.0, 0.0, 0.0]
[base]
direction = [1.0, 0.0, 0.0]
[[segment]]
method = "pcc"
length = {L}
elements = {elements}
density = {RHO}
youngs_modulus = {E}
section = {section}
{extra}
"#
    )
}

#[test]
fn a_planar_arm_bends_by_its_sections_second_moment_in_the_plane() {
    let dir = tempfile::tempdir().unwrap();
    let (w, h): (f64, f64) = (0.02, 0.006);
    let m = 1e-4;
    let moment = format!("[tip]\nmoment = [0.0, 0.0, {m}]");
    for (shape, iz) in [
        ("rectangle", w * h.powi(3) / 12.0),
        ("ellipse", PI * w * h.powi(3) / 64.0),
    ] {
        let section = format!("{{ shape = \"{shape}\", width = {w}, height = {h} }}");
        let tip = static_tip(dir.path(), &arm(2, &section, 1, &moment), &[]);
        let theta = m * L / (E * iz);
        let want = [L * theta.sin() / theta, L * (1.0 - theta.cos()) / theta];
        for c in 0..2 {
            assert_close(tip[c], want[c], 1e-9, L, &format!("{shape}, component {c}"));
        }
    }
    // Its own weight, in the plane: q = rho w h g.
    let g = 9.81e-3;
    let section = format!("{{ shape = \"rectangle\", width = {w}, height = {h} }}");
    let want = RHO * w * h * g * L.powi(4) / (8.0 * E * w * h.powi(3) / 12.0);
    let err = |n| {
        let text = arm(2, &section, n, "").replace("[0.0, 0.0, 0.0]", &format!("[0.0, -{g}, 0.0]"));
        (-static_tip(dir.path(), &text, &[])[1] - want) / want
    };
    let (coarse, fine) = (err(8), err(16));
    assert!(
        fine.abs() < 3e-3 && fine.abs() * 3.5 < coarse.abs(),
        "its own weight: {coarse:.2e} at 8 elements, {fine:.2e} at 16"
    );
}

#[test]
fn a_square_twists_by_st_venants_torsion_constant() {
    let dir = tempfile::tempdir().unwrap();
    let a: f64 = 0.01;
    let m = 1e-4;
    let section = format!("{{ shape = \"rectangle\", width = {a}, height = {a} }}");
    let text = arm(3, &section, 4, &format!("[tip]\nmoment = [{m}, 0.0, 0.0]"));
    let mut l = load_text(dir.path(), &text, &[]);
    let n = l.arm.dof();
    let sol = runtime::solve_static(
        &mut *l.arm,
        &vec![0.0; n],
        &runtime::StaticOptions::default(),
    )
    .unwrap();
    let names = &l.arm.info().coordinates;
    let twist: f64 = (names.iter().zip(&sol.q))
        .filter(|(n, _)| n.starts_with("twist"))
        .map(|(_, q)| q)
        .sum();
    // J of a square by the series solution (Timoshenko and Goodier).
    let want = m * L / (E / 3.0 * 0.140577 * a.powi(4));
    assert_close(twist, want, 3e-3, 0.0, "the square's twist");
}

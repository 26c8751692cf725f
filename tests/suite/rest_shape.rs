//! 3D rest shapes (`rest_curvature = [k_y, k_z]`, `rest_twist`,
//! `rest_stretch`) against the closed form of a rod of constant strain and
//! against the Cosserat rod:
//!
//! * unloaded, a rod curved about both axes and twisted at rest is a helix
//!   whose tip is L (I + c2 K + c3 K^2) v, K = [L u]x, u = (twist, k_y,
//!   k_z), v = (1 + stretch) e_x: exact for the constant-strain methods
//!   (pcc, vc, pcs, rom) at any resolution, second order for ebr and the
//!   rigid (Hencky) chain, and the Cosserat rod to its step error;
//! * under a tip load, every method converges to the Cosserat rod;
//! * at rest it stays at rest.

use crate::common::*;
use runtime::{SimOptions, StaticOptions, simulate, solve_static};

const L: f64 = 0.2;
const KY: f64 = 4.0;
const KZ: f64 = -6.0;
const TWIST: f64 = 3.0;

fn model(tip_force: [f64; 3]) -> String {
    format!(
        r#"
name = "helix"
dimensions = 3
gravity = [0.0, 0.0, 0.0]
[base]
direction = [1.0, 0.0, 0.0]
[[segment]]
method = "pcc"
length = {L}
elements = 8
density = 1000.0
outer_radius = 0.01
youngs_modulus = 1e6
rest_curvature = [{KY}, {KZ}]
rest_twist = {TWIST}
[tip]
force = {tip_force:?}
"#
    )
}

/// The tip of a rod of constant strain: curvature and twist `u` (about x,
/// y, z of the section), translation strain `v`, length `len`, from the
/// origin along +x.
fn constant_strain_tip(u: [f64; 3], v: [f64; 3], len: f64) -> [f64; 3] {
    let rho = u.map(|c| c * len);
    let t = (rho[0] * rho[0] + rho[1] * rho[1] + rho[2] * rho[2]).sqrt();
    let (c2, c3) = ((1.0 - t.cos()) / (t * t), (t - t.sin()) / (t * t * t));
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let kv = cross(rho, v);
    let kkv = cross(rho, kv);
    std::array::from_fn(|i| len * (v[i] + c2 * kv[i] + c3 * kkv[i]))
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|i| (a[i] - b[i]).powi(2)).sum::<f64>().sqrt()
}

#[test]
fn an_unloaded_rod_curved_and_twisted_at_rest_is_its_helix() {
    let dir = tempfile::tempdir().unwrap();
    let text = model([0.0; 3]);
    let want = constant_strain_tip([TWIST, KY, KZ], [1.0, 0.0, 0.0], L);
    // Far from straight: the helix turns by 1.5 rad.
    assert!(distance(want, [L, 0.0, 0.0]) > 0.1 * L, "{want:?}");
    for method in ["pcc", "vc", "pcs", "rom"] {
        for n in [3, 8] {
            let tip = static_tip(dir.path(), &text, &method_sets(method, n));
            let err = distance(tip, want) / L;
            assert!(err < 1e-9, "{method} at {n}: {err:e} of L off the helix");
        }
    }
    for method in ["ebr", "rigid", "eba"] {
        let err = |n| distance(static_tip(dir.path(), &text, &method_sets(method, n)), want) / L;
        let (coarse, fine) = (err(8), err(16));
        assert!(
            fine < 2e-3 && fine * 3.5 < coarse,
            "{method}: {coarse:e} of L at 8 elements, {fine:e} at 16"
        );
    }
    let rod = static_tip(dir.path(), &text, &["segment.0.method=cosserat".into()]);
    assert!(
        distance(rod, want) / L < 1e-9,
        "Cosserat: {rod:?} vs {want:?}"
    );
}

#[test]
fn a_rest_stretch_lengthens_the_helix() {
    let dir = tempfile::tempdir().unwrap();
    let text = model([0.0; 3]);
    let want = constant_strain_tip([TWIST, KY, KZ], [1.05, 0.0, 0.0], L);
    for method in ["pcc", "pcs", "rom", "cosserat"] {
        let mut s = method_sets(method, 4);
        if method == "cosserat" {
            s.truncate(1);
        }
        s.extend([
            "segment.0.extension=true".into(),
            "segment.0.rest_stretch=0.05".into(),
        ]);
        let tip = static_tip(dir.path(), &text, &s);
        let err = distance(tip, want) / L;
        assert!(err < 1e-9, "{method}: {err:e} of L off the stretched helix");
    }
}

#[test]
fn a_loaded_helix_converges_to_the_cosserat_rod() {
    let dir = tempfile::tempdir().unwrap();
    // A load across the helix that moves the tip by about a fifth of L.
    let text = model([0.0, 0.1, -0.3]);
    let rod = static_tip(dir.path(), &text, &["segment.0.method=cosserat".into()]);
    let unloaded = constant_strain_tip([TWIST, KY, KZ], [1.0, 0.0, 0.0], L);
    assert!(distance(rod, unloaded) > 0.1 * L, "{rod:?}");
    let err = |sets: &[String]| distance(static_tip(dir.path(), &text, sets), rod) / L;
    for method in ["pcc", "ebr", "rigid"] {
        let (coarse, fine) = (err(&method_sets(method, 8)), err(&method_sets(method, 16)));
        assert!(
            fine < 2e-3 && fine * 3.0 < coarse,
            "{method}: {coarse:e} of L from the Cosserat rod at 8, {fine:e} at 16"
        );
    }
    // rom's error is its fields' degree's.
    let rom = |order: usize| {
        let mut s = method_sets("rom", 12);
        s.push(format!("segment.0.order={order}"));
        err(&s)
    };
    let (low, high) = (rom(2), rom(5));
    assert!(
        high < 1e-5 && high * 10.0 < low,
        "rom: {low:e} of L from the Cosserat rod at order 2, {high:e} at 5"
    );
}

/// eba's beam springs stretch and shear: it converges to the extensible,
/// shearable rod, which the load moves measurably from the other.
#[test]
fn a_loaded_eba_helix_converges_to_the_shearing_cosserat_rod() {
    let dir = tempfile::tempdir().unwrap();
    let text = model([0.0, 0.1, -0.3]);
    let cosserat = |more: &[&str]| {
        let mut sets = vec!["segment.0.method=cosserat".to_string()];
        sets.extend(more.iter().map(|s| s.to_string()));
        static_tip(dir.path(), &text, &sets)
    };
    let rod = cosserat(&[]);
    let shearing = cosserat(&["segment.0.extension=true", "segment.0.shear=true"]);
    assert!(
        distance(shearing, rod) > 1e-3 * L,
        "{shearing:?} vs {rod:?}"
    );
    let err = |n| {
        distance(
            static_tip(dir.path(), &text, &method_sets("eba", n)),
            shearing,
        ) / L
    };
    let (coarse, fine) = (err(6), err(12));
    assert!(
        fine < 3e-3 && fine * 3.0 < coarse,
        "eba: {coarse:e} of L from the shearing Cosserat rod at 6, {fine:e} at 12"
    );
}

#[test]
fn a_helix_at_rest_stays_at_rest() {
    let dir = tempfile::tempdir().unwrap();
    let text = model([0.0; 3]).replace("youngs_modulus", "bending_damping = 1e-3\nyoungs_modulus");
    assert!(text.contains("bending_damping"));
    for method in ["pcc", "eba"] {
        stays_at_rest(dir.path(), &text, &method_sets(method, 8));
    }
}

fn stays_at_rest(dir: &std::path::Path, text: &str, sets: &[String]) {
    let sets: Vec<&str> = sets.iter().map(String::as_str).collect();
    let mut l = load_text(dir, text, &sets);
    let n = l.arm.dof();
    let rest = solve_static(&mut *l.arm, &vec![0.0; n], &StaticOptions::default())
        .unwrap()
        .q;
    // Curved: its coordinates (pcc's strains) or its placement (eba's).
    let tip = l.arm.outputs(0.0, &rest, &vec![0.0; n]);
    assert!(
        distance([tip[0], tip[1], tip[2]], [L, 0.0, 0.0]) > 0.1 * L,
        "{tip:?}"
    );
    let opts = SimOptions {
        t_end: 0.2,
        ..Default::default()
    };
    let x0 = [rest.clone(), vec![0.0; n]].concat();
    let (traj, _) = simulate(&*l.arm, x0, &opts).unwrap();
    let moved = (traj.x.iter())
        .flat_map(|x| x[..n].iter().zip(&rest).map(|(q, r)| (q - r).abs()))
        .fold(0.0, f64::max);
    assert!(moved < 1e-12, "moved by {moved:e}");
}

/// Bathe and Bolourchi's 45-degree bend: radius 100, unit square section
/// (E = 1e7, G = E / 2; E I = G J = 1e7 / 12 as Simo and Vu-Quoc take
/// them), curved in its plane, loaded at the tip by 600 out of it. Simo
/// and Vu-Quoc (1986, "A three-dimensional finite-strain rod model. Part
/// II", CMAME 58, 8 elements) give the tip at (47.23, 15.79, 53.37); the
/// Cosserat rod (400 steps) lies within 0.11 of it, and the lumped
/// methods converge to the rod.
#[test]
fn the_45_degree_bend_matches_simo_and_vu_quoc_and_the_cosserat_rod() {
    let dir = tempfile::tempdir().unwrap();
    let radius = 100.0;
    let text = format!(
        r#"
name = "bend45"
dimensions = 3
gravity = [0.0, 0.0, 0.0]
[base]
direction = [1.0, 0.0, 0.0]
[[segment]]
method = "pcc"
length = {}
elements = 16
mass = 1.0
bending_stiffness = {ei}
torsional_stiffness = {ei}
rest_curvature = {}
[tip]
force = [0.0, 0.0, 600.0]
"#,
        radius * std::f64::consts::FRAC_PI_4,
        1.0 / radius,
        ei = 1e7 / 12.0
    );
    let published = [47.23, 15.79, 53.37];
    let rod = static_tip(dir.path(), &text, &["segment.0.method=cosserat".into()]);
    for c in 0..3 {
        assert!(
            (rod[c] - published[c]).abs() < 0.12,
            "{rod:?} vs {published:?}"
        );
    }
    for method in ["pcc", "ebr"] {
        let err =
            |n| distance(static_tip(dir.path(), &text, &method_sets(method, n)), rod) / radius;
        let (coarse, fine) = (err(16), err(32));
        assert!(
            fine < 3e-4 && fine * 3.5 < coarse,
            "{method}: {coarse:e} of the radius from the rod at 16 elements, {fine:e} at 32"
        );
    }
}

/// A rest shape that varies along the rod (bend about y ramping from 0 to
/// 8 1/m, twist from 0 to 5 rad/m, bend about z constant): unloaded, every
/// method places it. Reference: the rest shape's own equations, R' = R
/// [u(s)]x and r' = R e_x, integrated by RK4 on nalgebra's rotations. The
/// lumped methods take each element's strain at its middle and converge at
/// second order (pcc's arcs, ebr's and the rigid chain's joints, eba's
/// placed slabs and rom's quadrature slices alike); the Cosserat rod
/// integrates it along s.
#[test]
fn a_rest_shape_varying_along_the_rod_is_placed_by_every_method() {
    let dir = tempfile::tempdir().unwrap();
    let text = model([0.0; 3])
        .replace(
            &format!("rest_curvature = [{KY}, {KZ}]"),
            "rest_curvature = [[0.0, 8.0], -4.0]",
        )
        .replace(&format!("rest_twist = {TWIST}"), "rest_twist = [0.0, 5.0]");
    assert!(text.contains("[[0.0, 8.0], -4.0]") && text.contains("[0.0, 5.0]"));
    let strain = |s: f64| {
        let x = s / L;
        nalgebra::Vector3::new(5.0 * x, 8.0 * x, -4.0)
    };
    let steps = 4000;
    let h = L / steps as f64;
    let (mut r, mut p) = (nalgebra::Rotation3::identity(), nalgebra::Vector3::zeros());
    for i in 0..steps {
        // RK4 on (r, R): the rotation advanced by the averaged rate (exact
        // to fourth order for a rate linear in s), the position by Simpson.
        let s = i as f64 * h;
        let k = (strain(s) + 4.0 * strain(s + h / 2.0) + strain(s + h)) / 6.0;
        let mid =
            r * nalgebra::Rotation3::new(strain(s) * (h / 4.0) + strain(s + h / 2.0) * (h / 4.0));
        let end = r * nalgebra::Rotation3::new(k * h);
        let ex = nalgebra::Vector3::x();
        p += h / 6.0 * (r * ex + 4.0 * (mid * ex) + end * ex);
        r = end;
    }
    let want = [p.x, p.y, p.z];
    assert!(distance(want, [L, 0.0, 0.0]) > 0.1 * L, "{want:?}");
    for method in ["pcc", "ebr", "rigid", "eba"] {
        let err = |n| distance(static_tip(dir.path(), &text, &method_sets(method, n)), want) / L;
        let (coarse, fine) = (err(6), err(12));
        assert!(
            fine < 2e-3 && fine * 3.5 < coarse,
            "{method}: {coarse:e} of L off the rest shape at 6 elements, {fine:e} at 12"
        );
    }
    // rom's rest field is constant over each quadrature slice (as its
    // varying sections are): second order in its slices.
    let rom = |n| {
        let mut s = method_sets("rom", n);
        s.push("segment.0.order=2".into());
        distance(static_tip(dir.path(), &text, &s), want) / L
    };
    let (coarse, fine) = (rom(6), rom(12));
    assert!(
        fine < 2e-3 && fine * 3.5 < coarse,
        "rom: {coarse:e} of L off the rest shape at 6 slices, {fine:e} at 12"
    );
    let rod = static_tip(dir.path(), &text, &["segment.0.method=cosserat".into()]);
    let rod = distance(rod, want) / L;
    assert!(rod < 1e-8, "Cosserat: {rod:e} of L off");
}

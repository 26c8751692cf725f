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
    for method in ["ebr", "rigid"] {
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

#[test]
fn a_helix_at_rest_stays_at_rest() {
    let dir = tempfile::tempdir().unwrap();
    let text = model([0.0; 3]).replace("youngs_modulus", "bending_damping = 1e-3\nyoungs_modulus");
    assert!(text.contains("bending_damping"));
    let mut l = load_text(dir.path(), &text, &[]);
    let n = l.arm.dof();
    let rest = solve_static(&mut *l.arm, &vec![0.0; n], &StaticOptions::default())
        .unwrap()
        .q;
    assert!(rest.iter().any(|q| q.abs() > 0.1), "{rest:?}");
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

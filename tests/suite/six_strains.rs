//! The six strains of the rod (two bendings, twist, extension, two shears)
//! in pcs, piecewise constant strain (the discrete Cosserat rod), and in
//! rom with shear and extension (the variable-strain rod), in statics and
//! in motion, against closed forms and the Cosserat rod (`method =
//! "cosserat"`, a shooting solution of the continuum):
//!
//! * a helix of constant strain, held by the tip wrench that the Cosserat
//!   equilibrium n' + k x n = 0, m' + k x m + v x n = 0 gives for it: exact
//!   for pcs at any element count and rom at any order, and the Cosserat
//!   rod's solution too;
//! * Timoshenko's shear deflection F L / (k G A), the part of a small
//!   tip deflection the shear factor k sets;
//! * second-order convergence to the extensible, shearable rod under a
//!   large skew tip load;
//! * energy conserved by an undamped pcs arm swinging in all six strains.

use crate::common::*;
use eomgen::model::Override;
use nalgebra::{Rotation3, Vector3};
use runtime::{SimOptions, StaticOptions, simulate, solve_static};
use softarm::backend::{BackendChoice, Loaded, load};

const L: f64 = 0.3;
const E: f64 = 1e6;
const R: f64 = 0.01;

fn ei() -> f64 {
    E * std::f64::consts::PI * R.powi(4) / 4.0
}

fn area() -> f64 {
    std::f64::consts::PI * R * R
}

fn cantilever3d(sets: &[String]) -> Loaded {
    let overrides: Vec<Override> = sets.iter().map(|s| Override::parse(s).unwrap()).collect();
    let dir = std::env::temp_dir().join("softarm-test-cache");
    load("cantilever3d", &overrides, BackendChoice::Auto, Some(dir)).unwrap()
}

/// The static tip of cantilever3d under `sets`: by a lumped method (from
/// the straight state, loads by continuation), or by the Cosserat rod when
/// `sets` say `method=cosserat`.
fn static_tip(sets: &[String]) -> [f64; 3] {
    if sets.iter().any(|s| s == "segment.0.method=cosserat") {
        let overrides: Vec<Override> = sets.iter().map(|s| Override::parse(s).unwrap()).collect();
        let (model, origin) = softarm::backend::read_model("cantilever3d", &overrides).unwrap();
        return softarm::continuum::solve(&model, &origin)
            .unwrap()
            .tip_position;
    }
    let mut l = cantilever3d(sets);
    let n = l.arm.dof();
    let sol = solve_static(&mut *l.arm, &vec![0.0; n], &StaticOptions::default()).unwrap();
    let o = l.arm.outputs(0.0, &sol.q, &vec![0.0; n]);
    [o[0], o[1], o[2]]
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

fn sets(method: &str, more: &[String]) -> Vec<String> {
    let mut s = vec![format!("segment.0.method={method}")];
    if method == "cosserat" || method == "rom" {
        s.extend([
            "segment.0.extension=true".into(),
            "segment.0.shear=true".into(),
        ]);
    }
    s.extend_from_slice(more);
    s
}

/// A helix of constant strain: curvature k = (twist, bend y, 0) and
/// translation strain v = (1 + e, shear y, 0) in the section's frame (x
/// along the normal), with the force n = lambda k and moment
/// m = (G J k_x, E I k_y, 0) it carries. Constant n and m balance when
/// k x n = 0 (n along k) and k x m + v x n = 0, whose z component is
/// k_x (E I - G J) + lambda + lambda^2 k_x (1/EA - 1/kGA) = 0: the root
/// that vanishes with the twist. Returns the tip wrench (world frame) that
/// holds it and its tip, r(L) = int_0^L exp(s [k]x) v ds by Simpson's rule
/// on nalgebra's exponential map.
struct Helix {
    force: [f64; 3],
    moment: [f64; 3],
    tip: [f64; 3],
    strain: [f64; 2],
}

fn helix(kx: f64, ky: f64, gj: f64, ea: f64, kga: f64) -> Helix {
    let a = kx * (1.0 / ea - 1.0 / kga);
    let c = kx * (ei() - gj);
    // (-1 + sqrt(1 - 4 a c)) / (2 a), written to hold at a = 0.
    let lambda = -2.0 * c / (1.0 + (1.0 - 4.0 * a * c).sqrt());
    let n = Vector3::new(lambda * kx, lambda * ky, 0.0);
    let m = Vector3::new(gj * kx, ei() * ky, 0.0);
    let v = Vector3::new(1.0 + n.x / ea, n.y / kga, 0.0);
    let k = Vector3::new(kx, ky, 0.0);
    // The balance the root was chosen for.
    let residual = k.cross(&m) + v.cross(&n);
    assert!(residual.norm() < 1e-15, "helix residual {residual}");
    let steps = 4000;
    let mut sum = Vector3::zeros();
    for i in 0..=steps {
        let s = L * i as f64 / steps as f64;
        let w = match i {
            0 => 1.0,
            _ if i == steps => 1.0,
            _ if i % 2 == 1 => 4.0,
            _ => 2.0,
        };
        sum += w * (Rotation3::new(k * s) * v);
    }
    let tip = sum * (L / (3.0 * steps as f64));
    let end = Rotation3::new(k * L);
    let (f, mo) = (end * n, end * m);
    Helix {
        force: [f.x, f.y, f.z],
        moment: [mo.x, mo.y, mo.z],
        tip: [tip.x, tip.y, tip.z],
        strain: [v.x - 1.0, v.y],
    }
}

#[test]
fn a_constant_strain_helix_is_exact_for_pcs_and_rom_at_any_resolution_and_for_the_rod() {
    // A rod soft in stretch and shear (E A = 2 N, k G A = 1 N) bent by
    // 1.5 rad and twisted by 0.9 rad: strains of a few per cent.
    let (gj, ea, kga) = (ei() * 2.0 / 3.0, 2.0, 1.0);
    let h = helix(3.0, 5.0, gj, ea, kga);
    assert!(
        h.strain[0].abs() > 0.01 && h.strain[1].abs() > 0.03,
        "{:?}",
        h.strain
    );
    let keys = vec![
        format!("segment.0.torsional_stiffness={gj}"),
        format!("segment.0.axial_stiffness={ea}"),
        format!("segment.0.shear_modulus={}", kga / area()),
        format!("tip.force=[{}, {}, {}]", h.force[0], h.force[1], h.force[2]),
        format!(
            "tip.moment=[{}, {}, {}]",
            h.moment[0], h.moment[1], h.moment[2]
        ),
    ];
    // Far from the straight rod, and far from where an unsheared,
    // unstretched helix of the same curvature ends.
    let rigid = helix(3.0, 5.0, gj, 1e12, 1e12);
    assert!(dist(h.tip, rigid.tip) > 0.01 * L);
    for elements in [1, 3] {
        let mut s = sets("pcs", &keys);
        s.push(format!("segment.0.elements={elements}"));
        let tip = static_tip(&s);
        let err = dist(tip, h.tip);
        eprintln!("pcs, {elements} elements: {:.2e} of L", err / L);
        assert!(err < 1e-9 * L, "pcs, {elements} elements: {err:e} m");
    }
    for order in [0, 2] {
        let mut s = sets("rom", &keys);
        s.push(format!("segment.0.order={order}"));
        let tip = static_tip(&s);
        let err = dist(tip, h.tip);
        eprintln!("rom, order {order}: {:.2e} of L", err / L);
        assert!(err < 1e-9 * L, "rom, order {order}: {err:e} m");
    }
    let tip = static_tip(&sets("cosserat", &keys));
    let err = dist(tip, h.tip);
    eprintln!(
        "the Cosserat rod: {:.2e} of L; strains {:?}",
        err / L,
        h.strain
    );
    assert!(err < 1e-6 * L, "the Cosserat rod: {err:e} m");
}

#[test]
fn the_shear_factor_sets_timoshenkos_shear_deflection() {
    // A small lateral tip force: the tip moves F L^3 / (3 E I) by bending
    // (pcs's share of which depends on the element count) plus F L / (k G A)
    // by shear, exactly, at any element count. Two factors differ by the
    // shear part alone.
    let f = 1e-4;
    let tip_y = |k: f64| {
        let keys = vec![
            format!("tip.force=[0, {f}, 0]"),
            format!("segment.0.shear_factor={k}"),
            "segment.0.elements=4".into(),
        ];
        static_tip(&sets("pcs", &keys))[1]
    };
    let (k1, k2) = (1.0, 0.5);
    let ga = E / 3.0 * area();
    let want = f * L / ga * (1.0 / k2 - 1.0 / k1);
    let got = tip_y(k2) - tip_y(k1);
    eprintln!("shear deflection {got:e} m, Timoshenko {want:e} m");
    // What is left is the small load's nonlinearity: (F L^2 / E I)^2.
    assert_close(got, want, 1e-4, 0.0, "shear deflection");
}

#[test]
fn pcs_and_rom_converge_to_the_extensible_shearable_rod() {
    // P L^2 / E I = 10 along (0, -0.6, 0.8), as for the other methods
    // (tests/suite/spatial.rs); a soft stretch and shear (E A = 20 N, k G A = 10 N)
    // so that they move the tip by centimetres.
    let p = 10.0 * ei() / (L * L);
    let keys = vec![
        format!("tip.force=[0, {}, {}]", -0.6 * p, 0.8 * p),
        "segment.0.axial_stiffness=20".into(),
        format!("segment.0.shear_modulus={}", 10.0 / area()),
    ];
    let reference = static_tip(&sets("cosserat", &keys));
    let mut stiff = sets("cosserat", &keys[..1]);
    stiff.retain(|s| !s.contains("extension") && !s.contains("shear"));
    let unstretched = static_tip(&stiff);
    assert!(dist(reference, unstretched) > 0.05 * L);
    let err = |method: &str, size: &str| {
        let mut s = sets(method, &keys);
        s.push(size.to_string());
        dist(static_tip(&s), reference)
    };
    let (coarse, fine) = (
        err("pcs", "segment.0.elements=4"),
        err("pcs", "segment.0.elements=8"),
    );
    eprintln!(
        "pcs: {:.3} % of L at 4 elements, {:.4} % at 8; stretch and shear move the tip {:.1} % of L",
        100.0 * coarse / L,
        100.0 * fine / L,
        100.0 * dist(reference, unstretched) / L
    );
    assert!(
        fine < coarse / 3.5,
        "pcs: error {coarse:e} at 4 elements, {fine:e} at 8"
    );
    assert!(fine < 0.005 * L, "pcs: error {fine:e} at 8 elements");
    // rom: quadratic, then quartic fields (18 and 30 DOF).
    let (quadratic, quartic) = (
        err("rom", "segment.0.order=2"),
        err("rom", "segment.0.order=4"),
    );
    eprintln!(
        "rom: {:.3} % of L at order 2, {:.4} % at 4",
        100.0 * quadratic / L,
        100.0 * quartic / L
    );
    assert!(
        quartic < quadratic / 3.0,
        "rom: error {quadratic:e} at order 2, {quartic:e} at 4"
    );
    assert!(quartic < 0.005 * L, "rom: error {quartic:e} at order 4");
}

#[test]
fn an_undamped_pcs_arm_swinging_in_all_six_strains_conserves_energy() {
    let sets = vec![
        "segment.0.method=pcs".to_string(),
        "segment.0.elements=2".into(),
        "gravity=[0, -4, -9.81]".into(),
        // Soft in stretch and shear, so that they swing visibly.
        "segment.0.axial_stiffness=30".into(),
        format!("segment.0.shear_modulus={}", 20.0 / area()),
    ];
    let l = cantilever3d(&sets);
    let arm = &*l.arm;
    let n = arm.dof();
    assert_eq!(n, 12, "six strains an element");
    let names = arm.info().coordinates.clone();
    let mut rng = Rng::new(5);
    // Angles of tenths of a radian, displacements of millimetres.
    let length = |name: &str| name.starts_with("stretch") || name.starts_with("shear");
    let scale: Vec<f64> = names
        .iter()
        .map(|c| if length(c) { 0.01 } else { 1.0 })
        .collect();
    let mut x0: Vec<f64> = scale.iter().map(|s| s * rng.uniform(-0.4, 0.4)).collect();
    x0.extend(scale.iter().map(|s| s * rng.uniform(-2.0, 2.0)));
    let opts = SimOptions {
        t_end: 2.0,
        rtol: 1e-10,
        atol: 1e-13,
        output_dt: 0.01,
        ..Default::default()
    };
    let (traj, _) = simulate(arm, x0, &opts).unwrap();
    let drift = energy_drift(arm, &traj);
    eprintln!("relative energy drift {drift:.1e}");
    assert!(drift < 1e-7, "relative energy drift {drift:e}");
    // Every shear coordinate swings through zero.
    for (i, name) in names.iter().enumerate() {
        if name.starts_with("shear") {
            let crossings = traj
                .x
                .windows(2)
                .filter(|w| w[0][i].signum() != w[1][i].signum())
                .count();
            assert!(crossings >= 2, "{name} crossed zero {crossings} times");
        }
    }
}

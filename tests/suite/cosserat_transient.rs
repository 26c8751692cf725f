//! The cantilever3d rod released straight under gravity, against the
//! Cosserat rod's answer from PyElastica (scripts/pyelastica_reference.py:
//! 200 elements with the clamp half an element out, within about 0.03 %
//! of L of the converged rod by its second-order refinement), in three
//! forms committed under tests/data/:
//!
//! * `cantilever3d_cosserat_tip.csv`: the extensible, shearable rod of
//!   constant section, the rod softarm's methods discretise;
//! * `cantilever3d_cosserat_pyelastica_law_tip.csv`: PyElastica's own law,
//!   whose section thins as the rod stretches (0.62 % of L from the first
//!   over 2 s);
//! * `cantilever3d_inextensible_tip.csv`: stretch and shear stiffness
//!   times 1000, the inextensible rod.
//!
//! Each test holds a method's distance at its figure in
//! docs/validation.md, so that a change that worsens it fails; the
//! six-strain rom of rod_swing_rom (36 coordinates) holds softarm's 1 % of L
//! over 2 s, against both extensible references.

use eomgen::model::Override;
use runtime::{SimOptions, Solver};
use softarm::backend::{BackendChoice, load};

const L: f64 = 0.3;

/// The rod of constant section.
const ROD: &str = "cantilever3d_cosserat_tip.csv";
/// PyElastica's constitutive law.
const PYELASTICA_LAW: &str = "cantilever3d_cosserat_pyelastica_law_tip.csv";
/// The inextensible, unshearable rod.
const INEXTENSIBLE: &str = "cantilever3d_inextensible_tip.csv";

fn reference(file: &str) -> Vec<[f64; 4]> {
    let path = format!("{}/tests/data/{file}", env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(path)
        .expect("the committed reference")
        .lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.trim().parse().unwrap()).collect();
            [v[0], v[1], v[2], v[3]]
        })
        .collect()
}

/// The tip of `model` under gravity along -z by dopri5 at `rtol`, at the
/// references' times (every 10 ms) to `t_end` (at most their 2 s).
fn tips(model: &str, rtol: f64, t_end: f64) -> Vec<(f64, [f64; 3])> {
    let times: Vec<f64> = reference(ROD).iter().map(|r| r[0]).collect();
    assert_eq!(times.len(), 201, "2 s every 10 ms");
    let times: Vec<f64> = times.into_iter().filter(|&t| t <= t_end + 1e-9).collect();
    let gravity = Override::parse("gravity=[0,0,-9.81]").unwrap();
    let l = load(model, &[gravity], BackendChoice::Auto, None).unwrap();
    let n = l.arm.dof();
    let opts = SimOptions {
        t_end,
        solver: Solver::Dopri5,
        rtol,
        atol: rtol * 1e-3,
        output_times: Some(times),
        ..SimOptions::default()
    };
    let (traj, _) = runtime::simulate(&*l.arm, vec![0.0; 2 * n], &opts).unwrap();
    traj.t
        .iter()
        .zip(&traj.x)
        .map(|(t, x)| {
            let o = l.arm.outputs(*t, &x[..n], &x[n..]);
            (*t, [o[0], o[1], o[2]])
        })
        .collect()
}

/// The tips' largest distance from reference `file` over 0.5 s and over
/// their whole span (% of L).
fn distance(tips: &[(f64, [f64; 3])], file: &str) -> (f64, f64) {
    let reference = reference(file);
    assert!(tips.len() <= reference.len());
    let (mut half, mut whole) = (0.0f64, 0.0f64);
    for ((t, o), r) in tips.iter().zip(&reference) {
        assert!((t - r[0]).abs() < 1e-9);
        let d = ((o[0] - r[1]).powi(2) + (o[1] - r[2]).powi(2) + (o[2] - r[3]).powi(2)).sqrt();
        whole = whole.max(d);
        if *t <= 0.5 + 1e-9 {
            half = half.max(d);
        }
    }
    let (half, whole) = (100.0 * half / L, 100.0 * whole / L);
    let span = tips.last().map_or(0.0, |t| t.0);
    eprintln!("against {file}: {half:.3} % of L over 0.5 s, {whole:.3} % over {span} s");
    (half, whole)
}

#[test]
fn the_references_are_the_rod_they_say() {
    // The extensible references part where the rod stretches, the
    // inextensible one by the stretch's whole effect: several % of L.
    let rod = reference(ROD);
    let far = |file: &str| {
        let other = reference(file);
        rod.iter()
            .zip(&other)
            .map(|(a, b)| ((a[1] - b[1]).powi(2) + (a[3] - b[3]).powi(2)).sqrt())
            .fold(0.0, f64::max)
            / L
    };
    let law = far(PYELASTICA_LAW);
    let inextensible = far(INEXTENSIBLE);
    assert!(law > 0.002 && law < 0.02, "the laws part by {law} L");
    assert!(
        inextensible > 0.03,
        "stretch moves the tip by {inextensible} L"
    );
    // The rod starts at L along x and falls under gravity alone: z =
    // -g t^2 / 2 at first (the tip's first 10 ms, to the rod's bending).
    let first = rod[1];
    assert!((first[1] - L).abs() < 1e-6 && (first[3] + 9.81 * 0.01f64.powi(2) / 2.0).abs() < 2e-5);
}

#[test]
fn the_inextensible_pcc_rod_swings_within_its_recorded_distance() {
    // cantilever3d: 5 pcc elements, inextensible and unshearable
    // (docs/validation.md: 4.47 / 12.96 % of L from the inextensible rod,
    // 5.98 / 17.87 % from the rod), with a margin of 2 %.
    // The stretch it cannot follow is most of its distance from the rod.
    let tips = tips("cantilever3d", 1e-8, 2.0);
    let (half, whole) = distance(&tips, INEXTENSIBLE);
    assert!(half <= 4.56 && whole <= 13.22, "{half} / {whole} % of L");
    let (half, whole) = distance(&tips, ROD);
    assert!(half <= 6.10 && whole <= 18.23, "{half} / {whole} % of L");
}

// rod_swing, 10 pcs elements, 60 coordinates (docs/validation.md: 0.92
// / 3.29 % of L at rtol 1e-6), with a margin of 2 %: its stretch and shear
// take dopri5 about 60,000 steps a second, so the default run holds the
// first half second and the long checks the whole 2 s.
#[test]
fn the_pcs_rod_that_stretches_and_shears_swings_within_its_recorded_distance() {
    let (half, _) = distance(&tips("rod_swing", 1e-6, 0.5), ROD);
    assert!(half <= 0.94, "{half} % of L over 0.5 s");
}

#[test]
#[ignore = "long (2 s of a 60-coordinate rod, about 17 s): run by .ci/run's long checks"]
fn the_pcs_rod_that_stretches_and_shears_swings_within_its_recorded_distance_for_two_seconds() {
    let (half, whole) = distance(&tips("rod_swing", 1e-6, 2.0), ROD);
    assert!(half <= 0.94, "{half} % of L over 0.5 s");
    assert!(whole <= 3.36, "{whole} % of L over 2 s");
}

#[test]
fn the_six_strain_rom_follows_the_cosserat_rod_within_a_fifth_of_a_percent() {
    // rod_swing_rom: rom of order 5 with all six strains, 36 coordinates,
    // at its own rtol 1e-5 (docs/validation.md: 0.070 and 0.170 % of L
    // against the rod, 0.556 and 0.753 % against PyElastica's law). The
    // goal is 1 % over 2 s; the recorded figures, with a margin, hold it to
    // what it reaches.
    let tips = tips("rod_swing_rom", 1e-5, 2.0);
    let (half, whole) = distance(&tips, ROD);
    assert!(half <= 0.075, "{half} % of L over 0.5 s");
    assert!(whole <= 0.18, "{whole} % of L over 2 s");
    let (half, whole) = distance(&tips, PYELASTICA_LAW);
    assert!(half <= 0.57 && whole <= 0.77, "{half} / {whole} % of L");
}

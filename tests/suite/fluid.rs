//! An immersed arm (`[fluid]`) against closed forms and a conservation
//! law, on a cantilever (L = 0.2 m, r = 10 mm, E = 1 MPa, rho = 1000):
//!
//! * in a fluid of its own density it floats straight under gravity; in
//!   one of half its density it sags as beam theory says under half its
//!   weight, q L^4 / (8 E I) with q = (rho - rho_f) A g;
//! * a steady current U across it bends it as the distributed load
//!   rho_f C_n d U^2 / 2 does;
//! * moving, drag only dissipates: the energy of a released arm falls
//!   from one sample to the next, where without the fluid it is kept.

use std::f64::consts::PI;
use std::path::Path;

use crate::common::*;
use runtime::{SimOptions, StaticOptions, simulate, solve_static};

const L: f64 = 0.2;
const E: f64 = 1e6;
const R: f64 = 0.01;
const RHO: f64 = 1000.0;

fn ei() -> f64 {
    E * PI * R.powi(4) / 4.0
}

fn immersed(gravity: f64, fluid: &str, elements: usize) -> String {
    format!(
        r#"
name = "immersed"
dimensions = 3
gravity = [0.0, 0.0, {gravity}]
[base]
direction = [1.0, 0.0, 0.0]
[[segment]]
method = "pcc"
length = {L}
elements = {elements}
density = {RHO}
outer_radius = {R}
youngs_modulus = {E}
{fluid}
"#
    )
}

fn static_tip(dir: &Path, text: &str) -> [f64; 3] {
    let mut l = load_text(dir, text, &[]);
    let n = l.arm.dof();
    let sol = solve_static(&mut *l.arm, &vec![0.0; n], &StaticOptions::default()).unwrap();
    let o = l.arm.outputs(0.0, &sol.q, &vec![0.0; n]);
    [o[0], o[1], o[2]]
}

/// The sag of a distributed load q beyond Euler-Bernoulli's on a method
/// that shears (eba): q L^2 / (2 k G A), G = E / 3 by default.
fn shear_sag(method: &str, q: f64) -> f64 {
    match method {
        "eba" => q * L * L / (2.0 * E / 3.0 * PI * R * R),
        _ => 0.0,
    }
}

#[test]
fn buoyancy_floats_a_neutral_arm_and_halves_a_denser_ones_sag() {
    let dir = tempfile::tempdir().unwrap();
    let g = -9.81e-3;
    for method in ["pcc", "eba"] {
        let text = |fluid: &str, n| {
            immersed(g, fluid, n).replace("method = \"pcc\"", &format!("method = \"{method}\""))
        };
        let neutral = static_tip(dir.path(), &text(&format!("[fluid]\ndensity = {RHO}"), 8));
        assert!(
            (neutral[0] - L).abs() < 1e-12 && neutral[2].abs() < 1e-12,
            "{method}: {neutral:?}"
        );
        let q = (RHO - RHO / 2.0) * PI * R * R * g;
        let want = q * L.powi(4) / (8.0 * ei()) + shear_sag(method, q);
        let half = format!("[fluid]\ndensity = {}", RHO / 2.0);
        let err = |n| (static_tip(dir.path(), &text(&half, n))[2] - want) / want;
        // eba's finite differences converge at second order from further.
        let n = if method == "eba" { 16 } else { 8 };
        let (coarse, fine) = (err(n), err(2 * n));
        assert!(
            fine.abs() < 3e-3 && fine.abs() * 3.5 < coarse.abs(),
            "{method}: sag in a fluid of half its density: {coarse:.2e} at {n} elements, {fine:.2e} at twice"
        );
    }
}

#[test]
fn a_steady_current_bends_the_arm_by_its_drag() {
    let dir = tempfile::tempdir().unwrap();
    let (rho_f, cn, u) = (1000.0, 1.2, 0.03);
    let fluid =
        format!("[fluid]\ndensity = {rho_f}\ndrag_normal = {cn}\ncurrent = [0.0, 0.0, {u}]");
    let q = 0.5 * rho_f * cn * 2.0 * R * u * u;
    for method in ["pcc", "eba"] {
        let want = q * L.powi(4) / (8.0 * ei()) + shear_sag(method, q);
        assert!(want < 2e-3 * L, "the linear range: {want}");
        let text = |n| {
            immersed(0.0, &fluid, n).replace("method = \"pcc\"", &format!("method = \"{method}\""))
        };
        let err = |n| (static_tip(dir.path(), &text(n))[2] - want) / want;
        let n = if method == "eba" { 16 } else { 8 };
        let (coarse, fine) = (err(n), err(2 * n));
        assert!(
            fine.abs() < 3e-3 && fine.abs() * 3.0 < coarse.abs(),
            "{method}: bent by the current: {coarse:.2e} at {n} elements, {fine:.2e} at twice"
        );
    }
}

#[test]
fn drag_only_takes_energy_out() {
    let dir = tempfile::tempdir().unwrap();
    let energies = |fluid: &str| -> Vec<f64> {
        let l = load_text(dir.path(), &immersed(0.0, fluid, 4), &[]);
        let n = l.arm.dof();
        let mut x0 = vec![0.0; 2 * n];
        x0[1] = 0.3; // the first element bent about z
        let opts = SimOptions {
            t_end: 0.5,
            output_dt: 0.01,
            rtol: 1e-9,
            atol: 1e-12,
            ..Default::default()
        };
        let (traj, _) = simulate(&*l.arm, x0, &opts).unwrap();
        (traj.x.iter())
            .map(|x| {
                let o = l.arm.outputs(0.0, &x[..n], &x[n..]);
                let names = runtime::OUTPUT_NAMES;
                let at = |k: &str| o[names.iter().position(|n| *n == k).unwrap()];
                at("kinetic") + at("potential")
            })
            .collect()
    };
    let kept = energies("");
    let drift = kept.iter().map(|e| (e - kept[0]).abs()).fold(0.0, f64::max);
    assert!(
        drift < 1e-6 * kept[0],
        "undamped and dry, drift {drift:e} of {}",
        kept[0]
    );
    let dragged = energies("[fluid]\ndensity = 1000.0\ndrag_normal = 1.2");
    for w in dragged.windows(2) {
        assert!(
            w[1] <= w[0] + 1e-12 * dragged[0],
            "energy rose: {} to {}",
            w[0],
            w[1]
        );
    }
    let last = dragged[dragged.len() - 1];
    assert!(
        last < 0.9 * dragged[0],
        "dragged: {} of {}",
        last,
        dragged[0]
    );
}

/// A rod falling across itself in a fluid reaches the terminal speed at
/// which its drag carries its weight less its buoyancy: its base a free
/// point mass m_b (a compliant base on no spring, dry), the rod horizontal,
/// falling along -z, so (m_b + (rho - rho_f) A L) g = rho_f C_n d L v^2 / 2.
/// The light base barely bends the stiff rod, so every element's velocity
/// stays across it. (A soft rod, bent by the start, where the dry base
/// falls faster than the buoyed rod, glides sideways on its tilted
/// elements' drag instead; the skin friction here damps what sideways
/// drift the start leaves.) The drag must see the base's own velocity: an
/// arm's points move with its compliant base's coordinates too.
#[test]
fn a_rod_falling_in_a_fluid_reaches_its_terminal_speed() {
    let dir = tempfile::tempdir().unwrap();
    let (rho_f, cn, g, m_b) = (1000.0, 1.2, 9.81, 1e-3);
    let rho = 2.0 * RHO;
    let text = immersed(
        -g,
        &format!("[fluid]\ndensity = {rho_f}\ndrag_normal = {cn}\ndrag_tangential = 0.1"),
        4,
    )
    .replace(
        &format!("density = {RHO}\nouter"),
        &format!("density = {rho}\nouter"),
    )
    .replace("[base]\n", &format!("[base]\nmass = {m_b}\n"))
    .replace(&format!("youngs_modulus = {E}"), "youngs_modulus = 1e8");
    assert!(text.contains(&format!("density = {rho}")) && text.contains("mass = 0.001"));
    let area = PI * R * R;
    let weight = (m_b + (rho - rho_f) * area * L) * g;
    let want = (2.0 * weight / (rho_f * cn * 2.0 * R * L)).sqrt();
    let l = load_text(dir.path(), &text, &[]);
    let n = l.arm.dof();
    let opts = SimOptions {
        t_end: 2.0,
        output_dt: 0.1,
        rtol: 1e-8,
        atol: 1e-10,
        ..Default::default()
    };
    let (traj, _) = simulate(&*l.arm, vec![0.0; 2 * n], &opts).unwrap();
    let tip_z = |k: usize| {
        let x = &traj.x[k];
        l.arm.outputs(traj.t[k], &x[..n], &x[n..])[2]
    };
    let last = traj.t.len() - 1;
    let speed = -(tip_z(last) - tip_z(last - 1)) / (traj.t[last] - traj.t[last - 1]);
    // Half way there after about a tenth of a second: long settled at 2 s.
    assert!(-tip_z(last) > want, "fell {} m", -tip_z(last));
    assert_close(speed, want, 1e-7, 0.0, "terminal speed");
}

//! Viscoelastic segments (`relaxation = [{ ratio, time }, ...]`, a Prony
//! series of standard linear solids on every stiffness) against the
//! closed forms of linear viscoelasticity, on a light cantilever (L = 0.2
//! m, r = 10 mm, E_0 = 1 MPa, density 1 kg/m^3: its first mode near 440
//! rad/s, so that it follows a load quasi-statically on the relaxation's
//! time scale of a second):
//!
//! * creep under a tip load ramped on: every coordinate follows the
//!   elastic answer q_s times chi(t), where chi solves the material's own
//!   law c chi' + chi - sum_k ratio_k a_k = w(t), time_k a_k' = chi - a_k
//!   (w the load's history, c = eta / E I the bending damping's time),
//!   integrated here by RK4; every method;
//! * relaxation under a held deflection: the force that holds it falls as
//!   E(t) / E_0 = 1 - sum_k ratio_k (1 - exp(-t / time_k));
//! * the loss at a frequency: under a sinusoidal tip force the tip lags by
//!   the phase of the complex modulus E*(w) = E_0 (1 - sum ratio_k + sum
//!   ratio_k i w time_k / (1 + i w time_k)) + i w eta / I, and moves by
//!   E_0 / |E*| of the elastic amplitude;
//! * statics takes the long-term modulus E_0 (1 - sum ratio_k), and
//!   linearize's slow eigenvalues are the material law's retardation rate.

use std::f64::consts::PI;

use runtime::{SimOptions, Solver, simulate};

use crate::common::*;

const L: f64 = 0.2;
const R: f64 = 0.01;
const E: f64 = 1e6;
const P: f64 = 1e-4;

fn ei() -> f64 {
    E * PI * R.powi(4) / 4.0
}

/// The cantilever with a tip force along -y driven by input `f`; `tail`
/// adds the segment's relaxation and the input.
fn cantilever(
    method: &str,
    resolution: &str,
    damping: f64,
    relaxation: &str,
    tail: &str,
) -> String {
    format!(
        r#"
name = "viscoelastic"
dimensions = 3
gravity = [0.0, 0.0, 0.0]
[base]
direction = [1.0, 0.0, 0.0]
[[segment]]
method = "{method}"
{resolution}
length = {L}
density = 1.0
outer_radius = {R}
youngs_modulus = {E}
shear_modulus = {G}
bending_damping = {damping}
{relaxation}
[tip]
force_inputs = ["zero", "f", "zero"]
[inputs.zero]
kind = "constant"
value = 0.0
{tail}
"#,
        G = E / 3.0
    )
}

fn radau(t_end: f64, times: Vec<f64>) -> SimOptions {
    SimOptions {
        t_end,
        rtol: 1e-9,
        atol: 1e-13,
        solver: Solver::Radau5,
        output_times: Some(times),
        ..SimOptions::default()
    }
}

/// chi(t) of the material law c chi' + chi - sum g_k a_k = w(t),
/// tau_k a_k' = chi - a_k, from rest, by RK4 at step `h`, at `times`.
fn material_law(
    c: f64,
    branches: &[(f64, f64)],
    w: impl Fn(f64) -> f64,
    times: &[f64],
) -> Vec<f64> {
    let m = branches.len();
    let rate = |t: f64, y: &[f64]| -> Vec<f64> {
        let chi = y[0];
        let held: f64 = (0..m).map(|k| branches[k].0 * y[1 + k]).sum();
        let mut d = vec![(w(t) - chi + held) / c];
        d.extend((0..m).map(|k| (chi - y[1 + k]) / branches[k].1));
        d
    };
    let h: f64 = 1e-5;
    let (mut t, mut y) = (0.0, vec![0.0; 1 + m]);
    let mut out = Vec::new();
    for &target in times {
        while t < target - 1e-12 {
            let h = h.min(target - t);
            let k1 = rate(t, &y);
            let at = |k: &[f64], s: f64| -> Vec<f64> {
                y.iter().zip(k).map(|(a, b)| a + s * b).collect()
            };
            let k2 = rate(t + h / 2.0, &at(&k1, h / 2.0));
            let k3 = rate(t + h / 2.0, &at(&k2, h / 2.0));
            let k4 = rate(t + h, &at(&k3, h));
            for i in 0..y.len() {
                y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            }
            t += h;
        }
        out.push(y[0]);
    }
    out
}

#[test]
fn a_ramped_tip_load_creeps_as_the_material_law_says_for_every_method() {
    let dir = tempfile::tempdir().unwrap();
    // Bending damping at half the first mode's critical value: the
    // ramp's ringing dies within a few hundredths of a second.
    let eta = 1.8e-5;
    let branches = [(0.3, 0.4), (0.2, 1.5)];
    let relaxation = "relaxation = [{ ratio = 0.3, time = 0.4 }, { ratio = 0.2, time = 1.5 }]";
    let ramp = format!(
        "[inputs.f]\nkind = \"ramp\"\nfrom = 0.0\nto = {}\nstart = 0.0\nend = 0.2",
        -P
    );
    let w = |t: f64| (t / 0.2).min(1.0);
    let times = vec![0.3, 0.6, 1.0, 2.0, 4.0];
    let chi = material_law(eta / ei(), &branches, w, &times);
    for (method, resolution) in [
        ("pcc", "elements = 6"),
        ("vc", "elements = 4"),
        ("ebr", "elements = 6"),
        ("eba", "elements = 6"),
        ("pcs", "elements = 6"),
        ("rigid", "elements = 6"),
        ("rom", "order = 3"),
    ] {
        let text = cantilever(method, resolution, eta, relaxation, &ramp);
        let full = format!("[inputs.f]\nkind = \"constant\"\nvalue = {}", -P);
        let elastic = cantilever(method, resolution, eta, "", &full);
        // The elastic answer under the full load (instantaneous modulus).
        let mut el = load_text(dir.path(), &elastic, &[]);
        let n = el.arm.dof();
        let qs = runtime::solve_static(&mut *el.arm, &vec![0.0; n], &Default::default())
            .unwrap()
            .q;
        let l = load_text(dir.path(), &text, &[]);
        let scale = qs.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        // radau5 for every method; for pcc also gauss at a 1 ms step from
        // the rest shape at rest (its steps land on the ramp's end).
        let gauss = SimOptions {
            solver: Solver::Gauss,
            dt: 1e-3,
            ..radau(4.0, times.clone())
        };
        let runs = match method {
            "pcc" => vec![radau(4.0, times.clone()), gauss],
            _ => vec![radau(4.0, times.clone())],
        };
        for opts in runs {
            let (traj, _) = simulate(&*l.arm, vec![0.0; 2 * n], &opts).unwrap();
            let mut worst = 0.0f64;
            for (x, c) in traj.x.iter().zip(&chi) {
                for (q, s) in x[..n].iter().zip(&qs) {
                    worst = worst.max((q - c * s).abs() / (c * scale));
                }
            }
            let solver = opts.solver.name();
            eprintln!(
                "{method}, {solver}: creep, largest error {worst:.2e} of the coordinates' scale"
            );
            assert!(
                worst < 5e-5,
                "{method}, {solver}: the creep is {worst:.2e} off the material law"
            );
        }
        // It did creep: the load's last state is 1 / (1 - 0.5) = 2x the
        // elastic answer, and chi(4 s) is well on the way.
        assert!(chi[4] > 1.8 && chi[0] < 1.2, "chi = {chi:?}");
    }
}

#[test]
fn the_force_holding_a_deflection_relaxes_as_the_prony_series() {
    let dir = tempfile::tempdir().unwrap();
    let (g1, t1, g2, t2) = (0.3, 0.2, 0.25, 1.0);
    let relaxation =
        format!("relaxation = [{{ ratio = {g1}, time = {t1} }}, {{ ratio = {g2}, time = {t2} }}]");
    // So heavy that it barely moves in 2 s: the deflection is held.
    let heavy = |r: &str| {
        cantilever(
            "pcc",
            "elements = 5",
            0.0,
            r,
            "[inputs.f]\nkind = \"constant\"\nvalue = 0.0",
        )
        .replace("density = 1.0", "density = 1e17")
            + "[simulate]\nstart_relaxed = false\n"
    };
    let l = load_text(dir.path(), &heavy(&relaxation), &[]);
    let elastic = load_text(dir.path(), &heavy(""), &[]);
    let n = l.arm.dof();
    let q0: Vec<f64> = (0..n).map(|i| 0.01 * (1.0 + i as f64)).collect();
    // The elastic force at q0, K q0: what holds it at the first instant.
    let mut f0 = nalgebra::DVector::zeros(n);
    elastic.arm.bias(0.0, &q0, &vec![0.0; n], &mut f0);
    let mut x0: Vec<f64> = q0.iter().copied().chain(vec![0.0; n]).collect();
    x0.extend(vec![0.0; l.arm.internal_len()]);
    let times = vec![0.05, 0.2, 0.5, 1.0, 2.0];
    let (traj, _) = simulate(&*l.arm, x0, &radau(2.0, times.clone())).unwrap();
    for (t, x) in times.iter().zip(&traj.x) {
        let moved = (0..n).map(|i| (x[i] - q0[i]).abs()).fold(0.0, f64::max);
        assert!(
            moved < 1e-7,
            "the deflection moved by {moved:.2e} at t = {t}"
        );
        let share = 1.0 - g1 * (1.0 - (-t / t1).exp()) - g2 * (1.0 - (-t / t2).exp());
        for i in 0..n {
            // The holding force: K q0 less the branches' relaxed forces.
            let relaxed: f64 = (0..2).map(|k| x[2 * n + k * n + i]).sum();
            let held = f0[i] - relaxed;
            assert_close(
                held,
                share * f0[i],
                1e-7,
                1e-12,
                format_args!("holding force {i} at t = {t}"),
            );
        }
    }
}

#[test]
fn a_sinusoidal_tip_force_lags_by_the_complex_modulus() {
    let dir = tempfile::tempdir().unwrap();
    let (g, tau, eta) = (0.4, 0.25, 1.8e-5);
    let w = 4.0;
    let text = cantilever(
        "pcc",
        "elements = 6",
        eta,
        &format!("relaxation = [{{ ratio = {g}, time = {tau} }}]"),
        &format!(
            "[inputs.f]\nkind = \"sine\"\namplitude = {}\nfrequency = {}",
            -P,
            w / (2.0 * PI)
        ),
    );
    let l = load_text(dir.path(), &text, &[]);
    let n = l.arm.dof();
    // The elastic amplitude: the static tip under the force's amplitude.
    let elastic = cantilever(
        "pcc",
        "elements = 6",
        eta,
        "",
        "[inputs.f]\nkind = \"constant\"\nvalue = -1e-4",
    );
    let mut el = load_text(dir.path(), &elastic, &[]);
    let qs = runtime::solve_static(&mut *el.arm, &vec![0.0; n], &Default::default())
        .unwrap()
        .q;
    let static_tip = el.arm.outputs(0.0, &qs, &vec![0.0; n])[1];
    // Two periods after the creep transient has died (retardation time
    // tau / (1 - g) = 0.42 s): projected on sin and cos by the trapezoid.
    let (start, periods, samples) = (8.0, 2.0, 400);
    let span = periods * 2.0 * PI / w;
    let times: Vec<f64> = (0..=samples)
        .map(|k| start + span * k as f64 / samples as f64)
        .collect();
    let (traj, _) = simulate(
        &*l.arm,
        vec![0.0; 2 * n],
        &radau(start + span, times.clone()),
    )
    .unwrap();
    let (mut s, mut c) = (0.0, 0.0);
    for (k, (t, x)) in times.iter().zip(&traj.x).enumerate() {
        // Along the force (-y): in phase with it when elastic.
        let y = -l.arm.outputs(*t, &x[..n], &x[n..2 * n])[1];
        let weight = if k == 0 || k == samples { 0.5 } else { 1.0 };
        s += weight * y * (w * t).sin();
        c += weight * y * (w * t).cos();
    }
    let (s, c) = (2.0 * s / samples as f64, 2.0 * c / samples as f64);
    // y = A sin(w t - phi) = A cos(phi) sin(w t) - A sin(phi) cos(w t),
    // the force's amplitude P sin(w t).
    let (amplitude, phase) = ((s * s + c * c).sqrt(), (-c).atan2(s));
    let (re, im) = {
        let wt = w * tau;
        (
            1.0 - g + g * wt * wt / (1.0 + wt * wt),
            g * wt / (1.0 + wt * wt) + w * eta / ei(),
        )
    };
    let expected_phase = im.atan2(re);
    let expected_amplitude = static_tip.abs() / (re * re + im * im).sqrt();
    eprintln!(
        "loss: phase {phase:.6} rad (complex modulus: {expected_phase:.6}), amplitude {amplitude:.6e} m ({expected_amplitude:.6e})"
    );
    assert_close(
        phase,
        expected_phase,
        2e-3,
        0.0,
        "the tip's lag behind the force",
    );
    assert_close(
        amplitude,
        expected_amplitude,
        2e-3,
        0.0,
        "the tip's amplitude",
    );
}

#[test]
fn statics_takes_the_long_term_modulus_and_linearize_the_retardation_rate() {
    let dir = tempfile::tempdir().unwrap();
    let (g, tau, eta) = (0.4, 0.5, 1.8e-5);
    let tail = "[inputs.f]\nkind = \"constant\"\nvalue = -1e-4";
    let relaxing = cantilever(
        "pcc",
        "elements = 6",
        eta,
        &format!("relaxation = [{{ ratio = {g}, time = {tau} }}]"),
        tail,
    );
    let long_term = cantilever("pcc", "elements = 6", eta, "", tail)
        .replace(
            &format!("youngs_modulus = {E}"),
            &format!("youngs_modulus = {}", E * (1.0 - g)),
        )
        .replace(
            &format!("shear_modulus = {}", E / 3.0),
            &format!("shear_modulus = {}", E / 3.0 * (1.0 - g)),
        );
    let a = static_tip(dir.path(), &relaxing, &[]);
    let b = static_tip(dir.path(), &long_term, &[]);
    eprintln!(
        "static tip y: relaxing {:.9e}, long-term modulus {:.9e}",
        a[1], b[1]
    );
    assert_close(
        a[1],
        b[1],
        1e-9,
        0.0,
        "the static tip at the long-term modulus",
    );
    // The Cosserat rod too, under the same force held constant.
    let rod = vec!["segment.0.method=cosserat".to_string()];
    let constant = |text: &str| {
        let head = text.split("[inputs.zero]").next().unwrap();
        head.replace(
            "force_inputs = [\"zero\", \"f\", \"zero\"]",
            &format!("force = [0.0, {}, 0.0]", -P),
        )
    };
    let (a, b) = (
        static_tip(dir.path(), &constant(&relaxing), &rod),
        static_tip(dir.path(), &constant(&long_term), &rod),
    );
    eprintln!(
        "Cosserat rod: relaxing {:.9e}, long-term modulus {:.9e}",
        a[1], b[1]
    );
    assert_close(
        a[1],
        b[1],
        1e-9,
        0.0,
        "the Cosserat rod at the long-term modulus",
    );
    // The slow eigenvalues of A: each coordinate creeps at its material
    // law's slow rate, the smaller root of
    // (l + 1 / c)(l + 1 / tau) = g / (c tau), with c = eta / E I for the
    // bends and eta / G J for the twist (the twist's damping is eta too).
    let path = dir.path().join("relaxing.toml");
    std::fs::write(&path, &relaxing).unwrap();
    let mut loaded = softarm::backend::load(
        path.to_str().unwrap(),
        &[],
        softarm::backend::BackendChoice::Auto,
        Some(dir.path().join("cache")),
    )
    .unwrap();
    let lin = softarm::linearize::linearize(&mut loaded, &[], None, None).unwrap();
    let n = loaded.arm.dof();
    assert_eq!(
        lin.a.nrows(),
        3 * n,
        "states: q, qd and one branch's relaxed forces"
    );
    let slow = |c: f64| {
        let (sum, prod) = (1.0 / c + 1.0 / tau, (1.0 - g) / (c * tau));
        -(sum - (sum * sum - 4.0 * prod).sqrt()) / 2.0
    };
    let (bend, twist) = (
        slow(eta / ei()),
        slow(eta / (E / 3.0 * PI * R.powi(4) / 2.0)),
    );
    let mut eig: Vec<f64> = lin.a.complex_eigenvalues().iter().map(|e| e.re).collect();
    eig.sort_by(|x, y| y.partial_cmp(x).unwrap());
    eprintln!(
        "slowest eigenvalues {:?}; material law: bends {bend:.7}, twist {twist:.7}",
        &eig[..n]
    );
    let near = |e: f64, l: f64| (e - l).abs() < 5e-5 * l.abs();
    let bends = eig[..n].iter().filter(|&&e| near(e, bend)).count();
    let twists = eig[..n].iter().filter(|&&e| near(e, twist)).count();
    assert_eq!(
        (bends, twists),
        (2 * n / 3, n / 3),
        "slow eigenvalues {:?}",
        &eig[..n]
    );
    assert!(
        eig[n] < 10.0 * bend,
        "the next eigenvalue {} is not slow",
        eig[n]
    );
}

//! Helpers shared by the integration tests.
#![allow(dead_code)]

pub mod pcc3d;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A small deterministic generator (xorshift64*), so failures reproduce.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Self(seed.max(1))
    }
    pub fn next_f64(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let x = self.0.wrapping_mul(0x2545_F491_4F6C_DD1D);
        (x >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Uniform in [lo, hi).
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next_f64()
    }
    pub fn vec(&mut self, n: usize, lo: f64, hi: f64) -> Vec<f64> {
        (0..n).map(|_| self.uniform(lo, hi)).collect()
    }
    /// Random coordinates in [lo, hi), except stretches (m), which stay in
    /// [lo, hi) mm: an element stretched past its own length is outside
    /// any model's range (an incompressible section has no square root).
    pub fn coordinates(&mut self, names: &[String], lo: f64, hi: f64) -> Vec<f64> {
        names
            .iter()
            .map(|n| {
                let s = if n.starts_with("stretch") { 1e-3 } else { 1.0 };
                s * self.uniform(lo, hi)
            })
            .collect()
    }
}

/// |a - b| <= rel * max(|a|, |b|, floor): relative, with an absolute floor
/// for entries that are zero in closed form.
/// `what` is formatted only on failure: pass `format_args!` in hot loops.
pub fn assert_close(a: f64, b: f64, rel: f64, floor: f64, what: impl std::fmt::Display) {
    let scale = a.abs().max(b.abs()).max(floor);
    assert!(
        (a - b).abs() <= rel * scale,
        "{what}: {a:e} vs {b:e} (difference {:e}, allowed {:e})",
        (a - b).abs(),
        rel * scale
    );
}

pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

pub fn model_path(name: &str) -> PathBuf {
    root().join("models").join(format!("{name}.toml"))
}

/// Run the softarm binary with `args` in `cwd`.
pub fn softarm(args: &[&str], cwd: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_softarm"))
        .args(args)
        .current_dir(cwd)
        .env("SOFTARM_CACHE_DIR", cwd.join("cache"))
        .output()
        .expect("the softarm binary runs")
}

/// A run of soft_finger for 1e6 s into `cwd/o` (with `args` besides),
/// started in the background and returned once it holds its folder (its
/// list of files begun): it is integrating, and runs until it is stopped.
pub fn long_run(cwd: &Path, args: &[&str]) -> std::process::Child {
    let run = Command::new(env!("CARGO_BIN_EXE_softarm"))
        .args([
            "simulate",
            "soft_finger",
            // Longer than any test waits, within the rows a run keeps.
            "--t-end",
            "9000",
            "--out",
            "o",
            "--quiet",
        ])
        .args(args)
        .current_dir(cwd)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("the softarm binary runs");
    let held = cwd.join("o/.softarm-files");
    let start = std::time::Instant::now();
    while !held.exists() && start.elapsed() < std::time::Duration::from_secs(120) {
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    assert!(held.exists(), "the run never claimed its folder");
    run
}

pub fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The model file `text` written to `dir` and loaded (tape cache in `dir`),
/// with `--set`-style overrides.
pub fn load_text(dir: &Path, text: &str, sets: &[&str]) -> softarm::backend::Loaded {
    let path = dir.join("model.toml");
    std::fs::write(&path, text).unwrap();
    let overrides: Vec<eomgen::model::Override> = sets
        .iter()
        .map(|s| eomgen::model::Override::parse(s).unwrap())
        .collect();
    softarm::backend::load(
        path.to_str().unwrap(),
        &overrides,
        softarm::backend::BackendChoice::Auto,
        Some(dir.join("cache")),
    )
    .unwrap()
}

/// qdd of a loaded model at (t, q, qd).
pub fn accelerations(l: &softarm::backend::Loaded, t: f64, q: &[f64], qd: &[f64]) -> Vec<f64> {
    let mut ws = runtime::Workspace::new(q.len());
    let mut qdd = vec![0.0; q.len()];
    runtime::accelerations(&*l.arm, &mut ws, t, q, qd, &mut qdd).unwrap();
    qdd
}

/// The largest change of the total energy (kinetic + potential, the
/// `Outputs` kernel's) along a trajectory, relative to the larger of the
/// initial total and the largest kinetic energy.
pub fn energy_drift(arm: &dyn runtime::Dynamics, traj: &runtime::Trajectory) -> f64 {
    let n = arm.dof();
    let energy = |x: &[f64]| {
        let o = arm.outputs(0.0, &x[..n], &x[n..2 * n]);
        (o[3], o[3] + o[4])
    };
    let e0 = energy(&traj.x[0]).1;
    let ke_max = traj.x.iter().map(|x| energy(x).0).fold(0.0, f64::max);
    traj.x
        .iter()
        .map(|x| (energy(x).1 - e0).abs())
        .fold(0.0, f64::max)
        / e0.abs().max(ke_max)
}

/// The static tip of the model file `text` (written to `dir`) under
/// `--set`-style `sets`: by its lumped method, from the straight state
/// with the loads by continuation, or by the Cosserat rod when the sets
/// make it one (`segment.0.method=cosserat`).
pub fn static_tip(dir: &Path, text: &str, sets: &[String]) -> [f64; 3] {
    let sets: Vec<&str> = sets.iter().map(String::as_str).collect();
    if sets.contains(&"segment.0.method=cosserat") {
        let path = dir.join("model.toml");
        std::fs::write(&path, text).unwrap();
        let overrides: Vec<eomgen::model::Override> = sets
            .iter()
            .map(|s| eomgen::model::Override::parse(s).unwrap())
            .collect();
        let spec = path.to_str().unwrap();
        let (model, origin) = softarm::backend::read_model(spec, &overrides).unwrap();
        return softarm::continuum::solve(&model, &origin)
            .unwrap()
            .tip_position;
    }
    let mut l = load_text(dir, text, &sets);
    let n = l.arm.dof();
    let opts = runtime::StaticOptions::default();
    let sol = runtime::solve_static(&mut *l.arm, &vec![0.0; n], &opts).unwrap();
    let o = l.arm.outputs(0.0, &sol.q, &vec![0.0; n]);
    [o[0], o[1], o[2]]
}

/// `--set`s that make a model's first segment `method` at resolution `n`:
/// its elements, or a rom segment's quadrature slices.
pub fn method_sets(method: &str, n: usize) -> Vec<String> {
    let key = if method == "rom" {
        "quadrature"
    } else {
        "elements"
    };
    vec![
        format!("segment.0.method={method}"),
        format!("segment.0.{key}={n}"),
    ]
}

/// The first N bending frequencies (Hz) of a clamped-free Rayleigh beam
/// (Euler-Bernoulli with the section's rotary inertia rho I), from its
/// characteristic equation: EI W'''' + rho I w^2 W'' - rho A w^2 W = 0,
/// W = C1 cosh ax + C2 sinh ax + C3 cos bx + C4 sin bx, clamped at 0,
/// with EI W'' = 0 and EI W''' + rho I w^2 W' = 0 at L; the roots of the
/// 2 x 2 determinant left by the clamp, bracketed on a scan and bisected.
pub fn rayleigh_beam_hz<const N: usize>(ei: f64, rho_a: f64, rho_i: f64, len: f64) -> [f64; N] {
    let det = |w: f64| {
        let w2 = w * w;
        let d = (rho_i * rho_i * w2 * w2 + 4.0 * ei * rho_a * w2).sqrt();
        let a = ((d - rho_i * w2) / (2.0 * ei)).sqrt();
        let b = ((d + rho_i * w2) / (2.0 * ei)).sqrt();
        let (ch, sh) = ((a * len).cosh(), (a * len).sinh());
        let (s, c) = (b * len).sin_cos();
        let m11 = a * a * ch + b * b * c;
        let m12 = a * a * sh + a * b * s;
        let m21 = ei * (a.powi(3) * sh - b.powi(3) * s) + rho_i * w2 * (a * sh + b * s);
        let m22 = ei * (a.powi(3) * ch + a * b * b * c) + rho_i * w2 * a * (ch - c);
        m11 * m22 - m12 * m21
    };
    let mut roots = Vec::new();
    // Steps of 1e-3 of the first root's Euler-Bernoulli estimate.
    let step = 1e-3 * (ei / (rho_a * len.powi(4))).sqrt();
    let mut w = step;
    while roots.len() < N {
        if det(w).signum() != det(w + step).signum() {
            let (mut lo, mut hi) = (w, w + step);
            for _ in 0..100 {
                let mid = 0.5 * (lo + hi);
                if det(mid).signum() == det(lo).signum() {
                    lo = mid
                } else {
                    hi = mid
                }
            }
            roots.push(0.5 * (lo + hi) / (2.0 * std::f64::consts::PI));
        }
        w += step;
    }
    std::array::from_fn(|k| roots[k])
}

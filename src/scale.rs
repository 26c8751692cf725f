//! Inputs far outside their model's scale, named with their keys before a
//! run and in a failed run's hint: a chamber's pressure above its
//! segment's Young's modulus, or a tendon's tension above the axial
//! stiffness E A of the segments it runs along, strains the material past
//! 100 %. A run driven so is not a soft arm's motion; it is a typing or
//! unit slip (1e15 Pa, kPa given as Pa), and an integrator left to it
//! grinds through millions of steps before it says so.

use eomgen::model::Model;
use runtime::Dynamics;

/// Times at which the inputs are sampled over the run for their peaks.
const SAMPLES: usize = 2000;

/// One line per input out of scale over [0, t_end], naming its key.
pub fn out_of_scale(model: &Model, arm: &dyn Dynamics, t_end: f64) -> Vec<String> {
    let names = &arm.info().parameters;
    let index = |key: &str| names.iter().position(|n| n == key);
    // Only driven values vary: the parameters at each sample time.
    let samples: Vec<Vec<f64>> = (0..=SAMPLES)
        .map(|k| arm.params_at(t_end * k as f64 / SAMPLES as f64))
        .collect();
    let peak = |i: usize| samples.iter().map(|p| p[i].abs()).fold(0.0, f64::max);
    let mut found = Vec::new();
    for (s, seg) in model.segments.iter().enumerate() {
        let (Some(e), Some(chambers)) =
            (seg.youngs_modulus.as_ref().map(|e| e.min()), &seg.chambers)
        else {
            continue;
        };
        for (c, input) in chambers.inputs.iter().flatten().enumerate() {
            let Some(i) = index(&format!("chamber[{s}][{c}].pressure")) else {
                continue;
            };
            let p = peak(i);
            if p > e {
                found.push(format!(
                    "inputs.{input} reaches {p:.3e} Pa in a chamber of segment {s}, {:.1e} times its Young's modulus ({e:.3e} Pa): a strain far past the material's (check the value and its unit, Pa)",
                    p / e
                ));
            }
        }
    }
    for (t, tendon) in model.tendons.iter().enumerate() {
        let Some(i) = index(&format!("tendon[{t}].tension")) else {
            continue;
        };
        let last = tendon.end.unwrap_or(model.segments.len().saturating_sub(1));
        let ea = (model.segments.iter().take(last + 1))
            .filter_map(|g| g.ea())
            .fold(f64::INFINITY, f64::min);
        let tension = peak(i);
        if ea.is_finite() && tension > ea {
            found.push(format!(
                "inputs.{} pulls tendon {t} with {tension:.3e} N, {:.1e} times the axial stiffness E A of the segments it runs along ({ea:.3e} N): a strain far past the material's (check the value and its unit, N)",
                tendon.input,
                tension / ea
            ));
        }
    }
    found
}

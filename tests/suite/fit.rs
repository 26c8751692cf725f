//! `softarm fit`: its sensitivities against central differences of whole
//! runs; values recovered from records the model itself made with known
//! values and noise, within the standard errors the fit reports; bounds
//! kept; an inseparable pair named; bad input refused with nothing
//! written; the optimiser on Rosenbrock's valley.

use std::path::Path;

use nalgebra::{DMatrix, DVector};
use softarm::fit::{Free, Problem, lm};
use softarm::run::RunRequest;

use crate::common::{Rng, assert_close, softarm};

/// A planar finger released straight under gravity with a tip mass,
/// pulled by a tendon ramped up from 0.2 s; its tip compared with
/// `record.csv` (t, x, y, z) over 1.5 s.
const PLANAR: &str = r#"
name = "fit_finger"
gravity = [0.0, -9.81, 0.0]

[base]
position = [0.0, 0.0, 0.0]
direction = [1.0, 0.0, 0.0]

[[segment]]
method = "pcc"
length = 0.12
elements = 3
density = 1070.0
outer_radius = 0.006
youngs_modulus = E
bending_damping = B

[tip]
mass = M

[[tendon]]
input = "pull"
distance = 0.004
end = 0

[inputs.pull]
kind = "ramp"
from = 0.0
to = 2.0
start = 0.2
end = 0.4

[compare]
file = "record.csv"
position = ["x", "y", "z"]

[simulate]
t_end = 1.5
"#;

/// A 3D rod sagging under gravity (-z) and pushed sideways (y) at its tip
/// by a sine force.
const SPATIAL: &str = r#"
name = "fit_rod"
dimensions = 3
gravity = [0.0, 0.0, -9.81]

[base]
direction = [1.0, 0.0, 0.0]

[[segment]]
method = "pcc"
length = 0.2
elements = 3
density = 1000.0
outer_radius = 0.008
youngs_modulus = E
bending_damping = B

[tip]
force_inputs = ["none", "push", "none"]

[inputs.none]
kind = "constant"
value = 0.0

[inputs.push]
kind = "sine"
amplitude = A
frequency = 1.5

[compare]
file = "record.csv"
position = ["x", "y", "z"]

[simulate]
t_end = 1.5
"#;

/// The finger's true values in the records the tests make.
const FINGER: [(&str, f64); 3] = [
    ("segment.0.youngs_modulus", 5.0e6),
    ("segment.0.bending_damping", 2.0e-5),
    ("tip.mass", 0.01),
];

/// The finger's three values free, with bounds.
const FINGER_FREE: [&str; 6] = [
    "--free",
    "segment.0.youngs_modulus=1e5:1e8",
    "--free",
    "segment.0.bending_damping=1e-7:1e-3",
    "--free",
    "tip.mass=1e-3:0.1",
];

/// Both models' [compare] section.
const COMPARE: &str = "[compare]\nfile = \"record.csv\"\nposition = [\"x\", \"y\", \"z\"]\n";

/// The model text with its placeholders (E, B, M, A) given by the paths
/// of their keys.
fn model(text: &str, values: &[(&str, f64)]) -> String {
    values.iter().fold(text.to_string(), |t, (path, v)| {
        let key = match path.rsplit('.').next().unwrap() {
            "youngs_modulus" => "E",
            "bending_damping" => "B",
            "mass" => "M",
            "amplitude" => "A",
            other => panic!("no placeholder for {other}"),
        };
        t.replace(&format!("= {key}\n"), &format!("= {v:e}\n"))
    })
}

/// A record of the model at `truth`: its tip every 10 ms, with Gaussian
/// noise of `sigma` on each coordinate but the first sample's (the
/// registration's anchor: `[compare]` subtracts it).
fn record(dir: &Path, text: &str, truth: &[(&str, f64)], sigma: f64) {
    record_seeded(dir, text, truth, sigma, 7);
}

/// `record` with its noise from `seed`.
fn record_seeded(dir: &Path, text: &str, truth: &[(&str, f64)], sigma: f64, seed: u64) {
    // Without its [compare], a run samples at --output-dt.
    let truth_model = model(text, truth).replace(COMPARE, "");
    std::fs::write(dir.join("truth.toml"), truth_model).unwrap();
    let out = softarm(
        &[
            "simulate",
            "truth.toml",
            "--output-dt",
            "0.01",
            "--rtol",
            "1e-9",
            "--atol",
            "1e-12",
            "--out",
            "truth",
            "--quiet",
            "--shape-points",
            "0",
        ],
        dir,
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let traj = std::fs::read_to_string(dir.join("truth/trajectory.csv")).unwrap();
    let mut lines = traj.lines();
    let names: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |n: &str| names.iter().position(|c| *c == n).unwrap();
    let (t, x, y, z) = (col("t"), col("tip_x"), col("tip_y"), col("tip_z"));
    let mut rng = Rng::new(seed);
    let mut gauss = || {
        let (u, v) = (rng.next_f64().max(1e-300), rng.next_f64());
        (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
    };
    let mut csv = String::from("time,x,y,z\n");
    for (i, line) in lines.enumerate() {
        let v: Vec<f64> = line.split(',').map(|s| s.parse().unwrap()).collect();
        let noise = if i == 0 { 0.0 } else { sigma };
        csv += &format!(
            "{},{},{},{}\n",
            v[t],
            v[x] + noise * gauss(),
            v[y] + noise * gauss(),
            v[z] + noise * gauss()
        );
    }
    std::fs::write(dir.join("record.csv"), csv).unwrap();
}

fn fit_json(dir: &Path, args: &[&str]) -> serde_json::Value {
    let mut all = vec!["fit", "model.toml", "--out", "fitted", "--quiet"];
    all.extend_from_slice(args);
    let out = softarm(&all, dir);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_str(&std::fs::read_to_string(dir.join("fitted/fit.json")).unwrap()).unwrap()
}

/// Each value recovered within three of its reported standard errors,
/// the errors small against the values (the data determine them), and
/// the record's noise as the fitted error.
fn assert_recovered(fit: &serde_json::Value, truth: &[(&str, f64)], sigma: f64) {
    for (path, value) in truth {
        let got = fit["parameters"][path].as_f64().unwrap();
        let se = fit["std_error"][path].as_f64().unwrap();
        assert!(
            (got - value).abs() <= 3.0 * se,
            "{path}: fitted {got:e} against {value:e}, standard error {se:e}"
        );
        assert!(
            se < 0.1 * value.abs(),
            "{path}: standard error {se:e} of {value:e}"
        );
    }
    // The mean Euclidean error of 3D Gaussian noise is sigma sqrt(8/pi).
    let mean = fit["cost"]["fit"]["final"].as_f64().unwrap();
    assert_close(
        mean,
        sigma * (8.0 / std::f64::consts::PI).sqrt(),
        0.15,
        0.0,
        "mean tip error",
    );
}

#[test]
fn recovers_a_planar_fingers_stiffness_damping_and_tip_mass() {
    let dir = tempfile::tempdir().unwrap();
    let truth = FINGER;
    let sigma = 2e-4;
    record(dir.path(), PLANAR, &truth, sigma);
    let start = [truth[0].0, truth[1].0, truth[2].0]
        .into_iter()
        .zip([5.25e6, 3.0e-5, 0.011])
        .collect::<Vec<_>>();
    std::fs::write(dir.path().join("model.toml"), model(PLANAR, &start)).unwrap();
    let fit = fit_json(dir.path(), &FINGER_FREE);
    assert_recovered(&fit, &truth, sigma);
    // Checked on another record of the same arm (other noise), which the
    // fit did not see: its error is that record's noise.
    std::fs::rename(dir.path().join("record.csv"), dir.path().join("first.csv")).unwrap();
    record_seeded(dir.path(), PLANAR, &truth, sigma, 11);
    std::fs::rename(dir.path().join("record.csv"), dir.path().join("second.csv")).unwrap();
    let text = model(PLANAR, &start);
    std::fs::write(
        dir.path().join("model.toml"),
        text.replace("record.csv", "first.csv"),
    )
    .unwrap();
    std::fs::write(
        dir.path().join("other.toml"),
        text.replace("record.csv", "second.csv"),
    )
    .unwrap();
    let fit = fit_json(
        dir.path(),
        &[&FINGER_FREE[..], &["--validate", "other.toml"]].concat(),
    );
    let v = &fit["cost"]["validation"];
    assert_eq!(v["samples"], 151, "{v}");
    let noise = sigma * (8.0 / std::f64::consts::PI).sqrt();
    assert_close(
        v["final"].as_f64().unwrap(),
        noise,
        0.15,
        0.0,
        "validation error",
    );
    assert!(v["initial"].as_f64().unwrap() > 3.0 * noise, "{v}");
    // The fitted model runs as it is.
    let out = softarm(
        &[
            "simulate",
            "fitted/fitted.toml",
            "--out",
            "again",
            "--quiet",
        ],
        dir.path(),
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(dir.path().join("fitted/fit.png").exists());
}

#[test]
fn recovers_a_3d_rods_stiffness_damping_and_load() {
    let dir = tempfile::tempdir().unwrap();
    let truth = [
        ("segment.0.youngs_modulus", 5.0e6),
        ("segment.0.bending_damping", 1.0e-5),
        ("inputs.push.amplitude", 0.05),
    ];
    let sigma = 2e-4;
    record(dir.path(), SPATIAL, &truth, sigma);
    let start = [
        ("segment.0.youngs_modulus", 5.25e6),
        ("segment.0.bending_damping", 1.5e-5),
        ("inputs.push.amplitude", 0.045),
    ];
    std::fs::write(dir.path().join("model.toml"), model(SPATIAL, &start)).unwrap();
    let fit = fit_json(
        dir.path(),
        &[
            "--free",
            "segment.0.youngs_modulus",
            "--free",
            "segment.0.bending_damping=0:",
            "--free",
            "inputs.push.amplitude",
        ],
    );
    assert_recovered(&fit, &truth, sigma);
}

#[test]
fn keeps_its_bounds_and_names_a_pair_the_data_cannot_separate() {
    let dir = tempfile::tempdir().unwrap();
    let truth = FINGER;
    record(dir.path(), PLANAR, &truth, 2e-4);
    let start = [("segment.0.youngs_modulus", 2.0e6), truth[1], truth[2]];
    std::fs::write(dir.path().join("model.toml"), model(PLANAR, &start)).unwrap();
    // The modulus held below its true value ends on its bound.
    let fit = fit_json(
        dir.path(),
        &[
            "--free",
            "segment.0.youngs_modulus=1e5:3e6",
            "--free",
            "tip.mass=1e-3:0.1",
        ],
    );
    assert_eq!(
        fit["parameters"]["segment.0.youngs_modulus"].as_f64(),
        Some(3e6)
    );
    assert_eq!(fit["at_bound"][0], "segment.0.youngs_modulus");
    // A pcc arm feels its tendon only as the moment tension x distance.
    let fit = fit_json(
        dir.path(),
        &[
            "--window",
            "0.5:1.5",
            "--free",
            "tendon.0.distance=1e-3:1e-2",
            "--free",
            "inputs.pull.to=0.5:5",
        ],
    );
    let c = fit["correlation"]["tendon.0.distance"]["inputs.pull.to"]
        .as_f64()
        .unwrap();
    assert!(c.abs() > 0.99, "correlation {c}");
    let warnings = fit["warnings"].to_string();
    assert!(warnings.contains("cannot separate"), "{warnings}");
}

/// The largest difference between d(tip - measured)/d value from the
/// sensitivities and central differences of whole runs, over the samples
/// up to `t_end`, as a fraction of the largest derivative: per value.
fn sensitivity_errors(p: &Problem, t_end: f64) -> Vec<f64> {
    let theta = p.start_values();
    let e = p.evaluate(&theta, true, t_end).unwrap();
    (0..theta.len())
        .map(|j| {
            let h = 1e-4 * theta[j].abs();
            let at = |sign: f64| {
                let mut t = theta.clone();
                t[j] += sign * h;
                p.evaluate(&t, false, t_end).unwrap()
            };
            let (a, b) = (at(1.0), at(-1.0));
            let pairs = (0..e.t.len()).flat_map(|i| (0..3).map(move |k| (i, k)));
            let fd = |(i, k): (usize, usize)| {
                ((a.tip[i][k] - a.measured[i][k]) - (b.tip[i][k] - b.measured[i][k])) / (2.0 * h)
            };
            let scale = pairs.clone().map(|ik| fd(ik).abs()).fold(0.0, f64::max);
            assert!(scale > 0.0, "value {j}: the tip does not move with it");
            pairs
                .map(|(i, k)| (e.derivative[i][j][k] - fd((i, k))).abs() / scale)
                .fold(0.0, f64::max)
        })
        .collect()
}

fn tight() -> RunRequest {
    RunRequest {
        rtol: Some(1e-9),
        atol: Some(1e-12),
        ..RunRequest::default()
    }
}

/// On the planar finger, whose input is a ramp: every value to 1e-3 of
/// its largest derivative (2e-4 measured at this tolerance: the
/// sensitivities' collocation is of order 2 in the step, the state's of
/// order 5), the record's own (the start it is shifted to) included.
#[test]
fn sensitivities_match_central_differences_of_whole_runs() {
    let dir = tempfile::tempdir().unwrap();
    let truth = FINGER;
    record(dir.path(), PLANAR, &truth, 0.0);
    let file = dir.path().join("model.toml");
    std::fs::write(&file, model(PLANAR, &truth)).unwrap();
    let paths = [truth[0].0, truth[1].0, truth[2].0, "tendon.0.distance"];
    let free = paths.iter().map(|p| Free::parse(p).unwrap()).collect();
    let p = Problem::new(file.to_str().unwrap(), vec![], free, tight(), None).unwrap();
    for (path, err) in paths.iter().zip(sensitivity_errors(&p, 1.0)) {
        assert!(err < 1e-3, "{path}: {err:e} of the largest derivative");
    }
}

/// A viscoelastic finger: its relaxation's ratio and time are values like
/// any other, the relaxed forces states like any other (1e-3, as above).
#[test]
fn sensitivities_to_a_relaxation_match_central_differences() {
    let dir = tempfile::tempdir().unwrap();
    let text = PLANAR.replace(
        "bending_damping = B\n",
        "bending_damping = B\nrelaxation = [{ ratio = 0.3, time = 0.25 }]\n",
    );
    let truth = FINGER;
    record(dir.path(), &text, &truth, 0.0);
    let file = dir.path().join("model.toml");
    std::fs::write(&file, model(&text, &truth)).unwrap();
    let paths = [
        "segment.0.relaxation.0.ratio",
        "segment.0.relaxation.0.time",
        truth[0].0,
    ];
    let free = paths.iter().map(|p| Free::parse(p).unwrap()).collect();
    let p = Problem::new(file.to_str().unwrap(), vec![], free, tight(), None).unwrap();
    for (path, err) in paths.iter().zip(sensitivity_errors(&p, 1.0)) {
        eprintln!("{path}: {err:.2e} of the largest derivative");
        assert!(err < 1e-3, "{path}: {err:e} of the largest derivative");
    }
}

/// On STIFF-FLOP's record over 1 s: modulus, damping, tip mass, a
/// pressure channel's delay and the sensor offset (a value of the record,
/// not of the arm). The recorded pressures are linear between their
/// samples, 20 a second, and the state's steps do not stop at the kinks:
/// the sensitivities agree to about 2e-3 of the largest derivative at
/// any tolerance (1e-7 to 1e-10 alike), a floor of the inputs, not of
/// the method (the finger above, on a smooth input, agrees to 2e-4).
#[test]
fn sensitivities_on_a_measured_input_match_central_differences() {
    let paths = [
        "segment.0.youngs_modulus",
        "segment.0.bending_damping",
        "tip.mass",
        "inputs.p0.delay",
        "compare.sensor_offset.0",
    ];
    let free: Vec<Free> = paths.iter().map(|p| Free::parse(p).unwrap()).collect();
    let set = eomgen::model::Override::parse("inputs.p0.delay=0.05").unwrap();
    let p = Problem::new("stiff_flop", vec![set], free, tight(), None).unwrap();
    for (path, err) in paths.iter().zip(sensitivity_errors(&p, 1.0)) {
        assert!(err < 5e-3, "{path}: {err:e} of the largest derivative");
    }
}

#[test]
fn refuses_bad_input_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let truth = FINGER;
    std::fs::write(dir.path().join("model.toml"), model(PLANAR, &truth)).unwrap();
    std::fs::write(
        dir.path().join("record.csv"),
        "time,x,y,z\n0,0,0,0\n1,0,0,0\n",
    )
    .unwrap();
    let no_compare = model(PLANAR, &truth).replace(COMPARE, "");
    std::fs::write(dir.path().join("plain.toml"), no_compare).unwrap();
    let cases: &[(&[&str], &str)] = &[
        (
            &["model.toml", "--free", "segment.0.youngs_modulu"],
            "did you mean `youngs_modulus`",
        ),
        (
            &["model.toml", "--free", "segment.0.elements"],
            "structural",
        ),
        (
            &["model.toml", "--free", "segment.0.youngs_modulus=5:1"],
            "LO must be below HI",
        ),
        (
            &["model.toml", "--free", "segment.0.youngs_modulus=1:10"],
            "outside its bounds",
        ),
        (
            &["model.toml", "--free", "simulate.t_end"],
            "not a value of the arm",
        ),
        (
            &["model.toml", "--free", "tendon.0.angle"],
            "--set tendon.0.angle",
        ),
        (
            &["model.toml", "--free", "inputs.pull.delay"],
            "unknown field `delay`",
        ),
        (&["plain.toml", "--free", "tip.mass"], "no [compare]"),
        (
            &["model.toml", "--free", "segment.0.method"],
            "not a number",
        ),
        (
            &["model.toml", "--free", "tip.mass", "--window", "2:3"],
            "has 0 samples there",
        ),
        (
            &["model.toml", "--free", "tip.mass", "--validate", "5:9"],
            "has 0 samples there",
        ),
        (
            &["model.toml", "--free", "tip.mass", "--window", "3:1"],
            "expected A:B",
        ),
    ];
    for (args, expected) in cases {
        let mut all = vec!["fit"];
        all.extend_from_slice(args);
        all.extend_from_slice(&["--out", "o"]);
        let out = softarm(&all, dir.path());
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args:?} ran");
        assert!(err.contains(expected), "{args:?}: {err}");
        assert!(!dir.path().join("o").exists(), "{args:?} wrote its folder");
    }
}

/// Rosenbrock's valley as least squares, r = (10 (y - x^2), 1 - x): the
/// minimum at (1, 1); with x <= 0.5, the constrained minimum on the
/// bound, y = x^2.
#[test]
fn the_optimiser_finds_rosenbrocks_minimum_and_keeps_a_bound() {
    let mut eval = |t: &[f64]| {
        let r = DVector::from_vec(vec![10.0 * (t[1] - t[0] * t[0]), 1.0 - t[0]]);
        let j = DMatrix::from_row_slice(2, 2, &[-20.0 * t[0], 10.0, -1.0, 0.0]);
        Ok((r, j))
    };
    let inf = f64::INFINITY;
    let opts = lm::Options {
        ftol: 1e-12,
        ..lm::Options::default()
    };
    let out = lm::minimise(
        &mut eval,
        &[-1.2, 1.0],
        &[-inf; 2],
        &[inf; 2],
        &opts,
        &mut |_, _| {},
    )
    .unwrap();
    assert!(out.converged, "{}", out.status);
    assert_close(out.theta[0], 1.0, 1e-6, 1.0, "x");
    assert_close(out.theta[1], 1.0, 1e-6, 1.0, "y");
    let out = lm::minimise(
        &mut eval,
        &[-1.2, 1.0],
        &[-inf; 2],
        &[0.5, inf],
        &opts,
        &mut |_, _| {},
    )
    .unwrap();
    assert_eq!(out.theta[0], 0.5, "held at its bound");
    assert_close(out.theta[1], 0.25, 1e-6, 1.0, "y");
}

//! Every bundled model computes what it computed when its fixture was
//! recorded: M and h, the outputs, the generated solve, the stiffness and
//! the right-hand side's Jacobian (applied to a fixed vector) at fixed
//! states, in both backends; the static solution; and a trajectory (1 s,
//! less for the stiffest rods: [`horizon`]).
//!
//! The fixtures in `tests/fixtures/` (the bundled models) and
//! `tests/fixtures/variants/` (variants that exercise what the bundled
//! models do not) are the reference that a refactoring changes no
//! behaviour: values agree to 1e-13 of each vector's largest entry.
//! Re-record only for an intended change of the physics, with
//! `SOFTARM_RECORD_FIXTURES=1 cargo test --test suite unchanged::`, and say why in
//! the commit.

use std::path::PathBuf;

use crate::common::*;
use nalgebra::{DMatrix, DVector};
use runtime::{Dynamics, KernelKind, SimOptions, Solver, StaticOptions, Workspace};
use serde_json::{Map, Value, json};
use softarm::backend::{BackendChoice, load};

fn fixture_path(model: &str) -> PathBuf {
    root()
        .join("tests")
        .join("fixtures")
        .join(format!("{model}.json"))
}

/// Deterministic states: straight at rest, straight and moving, and bent.
fn states(names: &[String], seed: u64) -> Vec<(f64, Vec<f64>, Vec<f64>)> {
    let mut rng = Rng::new(seed);
    let n = names.len();
    let bent = rng.coordinates(names, -0.6, 0.6);
    let moving = rng.vec(n, -1.5, 1.5);
    let moving2 = rng.vec(n, -1.5, 1.5);
    vec![
        (0.0, vec![0.0; n], vec![0.0; n]),
        (0.3, vec![0.0; n], moving),
        (1.7, bent, moving2),
    ]
}

/// The kernel outputs of one backend at the fixed states.
fn kernels_at_states(arm: &dyn Dynamics, seed: u64) -> Value {
    let n = arm.dof();
    let names = arm.info().coordinates.clone();
    let mut rng = Rng::new(seed + 1);
    let v = rng.vec(2 * n, -1.0, 1.0);
    let mut out = Vec::new();
    for (t, q, qd) in states(&names, seed) {
        let mut entry = Map::new();
        for kind in [
            KernelKind::MassBias,
            KernelKind::Outputs,
            KernelKind::Accel,
            KernelKind::Constraints,
        ] {
            // (Only models with joints have constraint rows.)
            if kind.output_len(arm.info()) == 0 && kind == KernelKind::Constraints {
                continue;
            }
            let mut o = vec![0.0; kind.output_len(arm.info())];
            arm.eval_kernel(kind, t, &q, &qd, &mut o);
            entry.insert(kind.name().into(), json!(o));
        }
        // The n x n stiffness and 2n x 2n Jacobian, applied to a fixed
        // vector: a change of any entry changes the product.
        let mut k = vec![0.0; n * n];
        arm.stiffness(t, &q, &mut k);
        let kv = DMatrix::from_row_slice(n, n, &k) * DVector::from_column_slice(&v[..n]);
        entry.insert("stiffness_times_v".into(), json!(kv.as_slice()));
        let mut ws = Workspace::new(n);
        let mut jac = DMatrix::zeros(2 * n, 2 * n);
        let x: Vec<f64> = q.iter().chain(&qd).copied().collect();
        // (A state may be singular for joints: the error is recorded.)
        match runtime::rhs_jacobian(arm, &mut ws, t, &x, &mut jac) {
            Ok(qdd) => {
                entry.insert("qdd".into(), json!(qdd));
                let jv = &jac * DVector::from_column_slice(&v);
                entry.insert("jacobian_times_v".into(), json!(jv.as_slice()));
            }
            Err(e) => {
                entry.insert("jacobian_error".into(), json!(e.to_string()));
            }
        }
        out.push(Value::Object(entry));
    }
    Value::Array(out)
}

/// How long a bundled model's recorded trajectory is: 1 s, but shorter
/// for the 3D rods whose stiff strains (stretch, shear, rom's fields) take
/// dopri5 6,000 to 110,000 steps a second of tens of coordinates: a tenth
/// or a fiftieth of a second still runs every kernel and the step control
/// over hundreds of steps or more, in a second or two of test.
fn horizon(model: &str) -> f64 {
    match model {
        "rod_swing" | "eba_arm" => 0.02,
        "rod_swing_rom" | "rom_arm" => 0.1,
        _ => 1.0,
    }
}

/// Static solution and a trajectory over [`horizon`], compiled backend.
fn simulations(loaded: &mut softarm::backend::Loaded) -> Value {
    let n = loaded.arm.dof();
    let statics =
        match runtime::solve_static(&mut *loaded.arm, &vec![0.0; n], &StaticOptions::default()) {
            Ok(s) => json!({"q": s.q}),
            Err(e) => json!({"error": e.to_string()}),
        };
    let file = &loaded.model.simulate;
    let opts = SimOptions {
        t_end: horizon(&loaded.model.name),
        solver: Solver::parse(file.solver.as_deref().unwrap_or("dopri5")).unwrap(),
        rtol: file.rtol.unwrap_or(1e-6),
        atol: file.atol.unwrap_or(1e-9),
        dt: file.dt.unwrap_or(1e-3),
        output_dt: horizon(&loaded.model.name) / 10.0,
        ..Default::default()
    };
    // Start bent, so that every model moves; a model with joints from its
    // own start, put onto them.
    let mut x0 = vec![0.0; 2 * n];
    for (k, x) in x0.iter_mut().take(n).enumerate() {
        let stretch = loaded.arm.info().coordinates[k].starts_with("stretch");
        *x = if stretch { 1e-3 } else { 0.2 };
    }
    if !loaded.arm.info().constraints.is_empty() {
        let coords = loaded.arm.info().coordinates.clone();
        let (q, qd) = x0.split_at_mut(n);
        let start =
            eomgen::model::assembly::initial_coordinates(&loaded.model, &coords, "").unwrap();
        q.copy_from_slice(&start);
        softarm::joints::assemble(&*loaded.arm, "", q, qd).unwrap();
    }
    let (traj, stats) = runtime::simulate(&*loaded.arm, x0, &opts).unwrap();
    json!({"static": statics, "t": traj.t, "x": traj.x, "steps": stats.steps})
}

/// Model variants that exercise what the bundled models do not (every
/// method under actuation, torques, a moving base and tip wrenches), with
/// the segment whose method varies: each with every method of the
/// registry that the file takes, the interpreted kernels at the fixed
/// states and the static solution.
const VARIANTS: &[(&str, &str, usize)] = &[
    (
        "everything3d",
        "tests/fixtures/variants/everything3d.toml",
        1,
    ),
    (
        "everything2d",
        "tests/fixtures/variants/everything2d.toml",
        1,
    ),
    ("stiff_flop", "stiff_flop", 0),
];

/// A variant's file name (a path, or a bundled model's name).
fn variant_spec(file: &str) -> String {
    if file.ends_with(".toml") {
        root().join(file).to_string_lossy().into_owned()
    } else {
        file.to_string()
    }
}

/// The methods of the registry a variant takes at its segment (the others
/// are rejected by the model's checks).
fn variant_methods(file: &str, segment: usize) -> Vec<&'static str> {
    let path = if file.ends_with(".toml") {
        root().join(file)
    } else {
        root().join("models").join(format!("{file}.toml"))
    };
    eomgen::method::ALL
        .iter()
        .map(|m| m.name())
        .filter(|name| {
            let set = format!("segment.{segment}.method={name}");
            let set = eomgen::model::Override::parse(&set).unwrap();
            eomgen::load::load_model(&path, &[set]).is_ok()
        })
        .collect()
}

fn record_variant(file: &str, segment: usize, method: &str) -> Value {
    let dir = tempfile::tempdir().unwrap();
    let spec = variant_spec(file);
    let set =
        eomgen::model::Override::parse(&format!("segment.{segment}.method={method}")).unwrap();
    let mut l = load(
        &spec,
        &[set],
        BackendChoice::Interpreted,
        Some(dir.path().to_path_buf()),
    )
    .unwrap();
    let n = l.arm.dof();
    let statics = match runtime::solve_static(&mut *l.arm, &vec![0.0; n], &StaticOptions::default())
    {
        Ok(s) => json!({"q": s.q}),
        Err(e) => json!({"error": e.to_string()}),
    };
    json!({"interpreted": kernels_at_states(&*l.arm, 5), "static": statics})
}

fn record(name: &str) -> Value {
    let mut compiled = load(name, &[], BackendChoice::Compiled, None).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let interpreted = load(
        name,
        &[],
        BackendChoice::Interpreted,
        Some(dir.path().to_path_buf()),
    )
    .unwrap();
    let seed = 1 + name.len() as u64;
    json!({
        "model": name,
        "compiled": kernels_at_states(&*compiled.arm, seed),
        "interpreted": kernels_at_states(&*interpreted.arm, seed),
        "simulation": simulations(&mut compiled),
    })
}

/// Every number of `now` within 1e-13 of the largest entry of its array in
/// `then`; structure (keys, lengths, integers) equal.
fn compare(now: &Value, then: &Value, path: &str, failures: &mut Vec<String>) {
    match (now, then) {
        (Value::Object(a), Value::Object(b)) => {
            let (ka, kb): (Vec<_>, Vec<_>) = (a.keys().collect(), b.keys().collect());
            if ka != kb {
                failures.push(format!("{path}: keys {ka:?} vs {kb:?}"));
                return;
            }
            for (k, v) in a {
                compare(v, &b[k], &format!("{path}.{k}"), failures);
            }
        }
        (Value::Array(a), Value::Array(b)) => {
            if a.len() != b.len() {
                failures.push(format!("{path}: length {} vs {}", a.len(), b.len()));
                return;
            }
            let scale = b
                .iter()
                .filter_map(Value::as_f64)
                .fold(0.0f64, |s, x| s.max(x.abs()));
            for (k, (x, y)) in a.iter().zip(b).enumerate() {
                match (x.as_f64(), y.as_f64()) {
                    (Some(x), Some(y)) if x.is_finite() && y.is_finite() => {
                        if (x - y).abs() > 1e-13 * scale.max(x.abs()).max(1e-300) {
                            failures.push(format!("{path}[{k}]: {x:e} vs recorded {y:e}"));
                        }
                    }
                    _ => compare(x, y, &format!("{path}[{k}]"), failures),
                }
            }
        }
        (a, b) if a != b => failures.push(format!("{path}: {a} vs recorded {b}")),
        _ => {}
    }
}

/// One bundled model against its fixture (or recorded anew).
fn check_bundled(name: &str) {
    let now = record(name);
    let path = fixture_path(name);
    if std::env::var_os("SOFTARM_RECORD_FIXTURES").is_some() {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(&path, serde_json::to_string(&now).unwrap()).unwrap();
        return;
    }
    let then: Value = serde_json::from_str(
        &std::fs::read_to_string(&path)
            .unwrap_or_else(|e| panic!("{}: {e} (record it first)", path.display())),
    )
    .unwrap();
    let mut failures = Vec::new();
    compare(&now, &then, name, &mut failures);
    failures.truncate(20);
    assert!(
        failures.is_empty(),
        "behaviour changed:\n{}",
        failures.join("\n")
    );
}

/// A test a bundled model, so that they run side by side; the list is
/// every bundled model's (checked below).
macro_rules! bundled {
    ($($name:ident),* $(,)?) => {
        mod bundled {
            $(
                #[test]
                fn $name() {
                    super::check_bundled(stringify!($name));
                }
            )*

            /// Every bundled model has its test above, and every fixture
            /// is of a bundled model: a fixture left behind by a removed
            /// model would silently test nothing.
            #[test]
            fn every_bundled_model_and_no_other_is_checked() {
                let listed: std::collections::BTreeSet<&str> = [$(stringify!($name)),*].into();
                let bundled: std::collections::BTreeSet<&str> =
                    softarm::generated::MODELS.iter().map(|m| m.name).collect();
                assert_eq!(listed, bundled, "the models listed in bundled! against MODELS");
                let dir = crate::common::root().join("tests").join("fixtures");
                for e in std::fs::read_dir(dir).unwrap() {
                    let e = e.unwrap();
                    if e.file_type().unwrap().is_dir() {
                        continue;
                    }
                    let name = e.file_name().to_string_lossy().into_owned();
                    assert!(
                        bundled.contains(name.trim_end_matches(".json")),
                        "tests/fixtures/{name} belongs to no bundled model"
                    );
                }
            }
        }
    };
}

bundled!(
    ball_drop,
    cantilever,
    cantilever3d,
    chain,
    chain32,
    double_pendulum,
    eba_arm,
    ebr_arm,
    falling_ball,
    finger_free,
    finger_tap,
    hybrid_arm,
    long_arm,
    rod_swing,
    rod_swing_rom,
    rom_arm,
    soft_finger,
    stiff_flop,
    stiff_flop_rom,
    tentacle3d,
    vc_arm,
    wrap,
);

#[test]
fn every_variant_computes_what_its_fixture_recorded() {
    let recording = std::env::var_os("SOFTARM_RECORD_FIXTURES").is_some();
    let mut failures = Vec::new();
    let mut recorded = std::collections::BTreeSet::new();
    for &(name, file, segment) in VARIANTS {
        let methods = variant_methods(file, segment);
        assert!(methods.len() >= 3, "{name}: takes only {methods:?}");
        for method in methods {
            let now = record_variant(file, segment, method);
            let key = format!("{name}-{method}");
            recorded.insert(format!("{key}.json"));
            let path = root()
                .join("tests/fixtures/variants")
                .join(format!("{key}.json"));
            if recording {
                std::fs::write(&path, serde_json::to_string(&now).unwrap()).unwrap();
                continue;
            }
            let Ok(text) = std::fs::read_to_string(&path) else {
                failures.push(format!("{key}: no fixture (record it)"));
                continue;
            };
            let then: Value = serde_json::from_str(&text).unwrap();
            let before = failures.len();
            compare(&now, &then, &key, &mut failures);
            failures.truncate(before + 20);
        }
    }
    // Every variant fixture is of a method a variant takes: one left behind
    // would silently test nothing.
    for e in std::fs::read_dir(root().join("tests/fixtures/variants")).unwrap() {
        let name = e.unwrap().file_name().to_string_lossy().into_owned();
        if name.ends_with(".json") && !recording && !recorded.contains(&name) {
            failures.push(format!(
                "tests/fixtures/variants/{name}: of no variant's method"
            ));
        }
    }
    assert!(
        failures.is_empty(),
        "behaviour changed:\n{}",
        failures.join("\n")
    );
}

//! Planar pcc segments against continuum mechanics: the constant-curvature
//! arc, the small-load cantilever F L^3 / (3 E I), the large-deflection
//! elastica (our own shooting solve below), Euler-Bernoulli frequencies and
//! conservation of energy through the straight configuration.

use crate::common::*;
use eomgen::cas::{Cas, SymKind};
use eomgen::model::Override;
use runtime::{SimOptions, StaticOptions, modes, simulate, solve_static};
use softarm::backend::{BackendChoice, Loaded, load};

const L: f64 = 0.3;
const E: f64 = 1e6;
const R: f64 = 0.01;
const RHO: f64 = 1000.0;

fn ei() -> f64 {
    E * std::f64::consts::PI * R.powi(4) / 4.0
}

fn cantilever(sets: &[String]) -> Loaded {
    let overrides: Vec<Override> = sets.iter().map(|s| Override::parse(s).unwrap()).collect();
    let dir = std::env::temp_dir().join("softarm-test-cache");
    load("cantilever", &overrides, BackendChoice::Auto, Some(dir)).unwrap()
}

/// Tip position at static equilibrium under a downward tip force P.
fn static_tip(method: &str, elements: usize, p: f64) -> [f64; 2] {
    let mut l = cantilever(&[
        format!("segment.0.method={method}"),
        format!("segment.0.elements={elements}"),
        format!("tip.force=[0, {}, 0]", -p),
    ]);
    let n = l.arm.dof();
    let sol = solve_static(&mut *l.arm, &vec![0.0; n], &StaticOptions::default()).unwrap();
    assert!(sol.residual < 1e-9, "residual {}", sol.residual);
    let o = l.arm.outputs(0.0, &sol.q, &vec![0.0; n]);
    [o[0], o[1]]
}

#[test]
fn one_element_tip_is_the_closed_form_arc() {
    let l = cantilever(&["segment.0.elements=1".into()]);
    let mut thetas: Vec<f64> = (0..=60).map(|i| -3.0 + 0.1 * i as f64).collect();
    thetas.extend([0.0, 1e-9, -1e-9, 1e-12, 5e-9, -3e-13]);
    for theta in thetas {
        let o = l.arm.outputs(0.0, &[theta], &[0.0]);
        // The element frame: tangent +x, normal +y (base along +x).
        let (along, across) = if theta.abs() < 1e-8 {
            (L, L * theta / 2.0) // the limits, exact to O(theta^2)
        } else {
            ((L / theta) * theta.sin(), (L / theta) * (1.0 - theta.cos()))
        };
        assert!(
            (o[0] - along).abs() < 1e-12,
            "theta {theta}: x {} vs {along}",
            o[0]
        );
        assert!(
            (o[1] - across).abs() < 1e-12,
            "theta {theta}: y {} vs {across}",
            o[1]
        );
        // The tip frame has turned by theta about z.
        let q = [(theta / 2.0).cos(), 0.0, 0.0, (theta / 2.0).sin()];
        for k in 0..4 {
            assert!((o[5 + k] - q[k]).abs() < 1e-12, "theta {theta}: quaternion");
        }
        // M, h and K are finite there, at any rate.
        let mut m = nalgebra::DMatrix::zeros(1, 1);
        let mut h = nalgebra::DVector::zeros(1);
        l.arm.mass_bias(0.0, &[theta], &[2.5], &mut m, &mut h);
        let mut k = [0.0];
        l.arm.stiffness(0.0, &[theta], &mut k);
        assert!(m[(0, 0)].is_finite() && m[(0, 0)] > 0.0 && h[0].is_finite() && k[0].is_finite());
    }
}

#[test]
fn jacobians_of_mass_and_bias_are_finite_at_the_straight_state() {
    // Differentiate every entry of M and h in every q and qd symbolically,
    // then evaluate at theta = 0 and |theta| < 1e-8.
    let model = cantilever(&[
        "segment.0.elements=3".into(),
        "gravity=[0, -9.81, 0]".into(),
    ])
    .model;
    let mut cas = Cas::new();
    let structure = eomgen::model::Structure::of(&model);
    let layout = eomgen::model::ParamLayout::of(&structure);
    let sys = eomgen::build::system(&mut cas, &structure, &layout);
    let eq = eomgen::tmt::assemble(&mut cas, &sys);
    let mut exprs = Vec::new();
    for &e in eq.mass_upper.iter().chain(&eq.bias) {
        for &x in sys.coords.q.iter().chain(&sys.coords.qd) {
            exprs.push(cas.diff(e, x));
        }
    }
    let params = layout.values(&model);
    for q in [[0.0, 0.0, 0.0], [1e-9, -1e-12, 0.0], [0.0, 0.5, -1e-10]] {
        let qd = [0.7, -1.1, 0.4];
        let values = cas
            .eval_many(&exprs, &|s| match cas.sym_kind(s) {
                SymKind::Q(i) => Some(q[i as usize]),
                SymKind::Qd(i) => Some(qd[i as usize]),
                SymKind::Param(i) => params.get(i as usize).copied(),
                _ => None,
            })
            .unwrap();
        assert!(
            values.iter().all(|v| v.is_finite()),
            "non-finite Jacobian entry at q = {q:?}"
        );
    }
}

#[test]
fn small_tip_load_matches_beam_theory() {
    // F chosen so that F L^3 / (3 E I) is 1 % of L.
    let linear = 0.01 * L;
    let f = linear * 3.0 * ei() / L.powi(3);
    for method in ["pcc", "rigid"] {
        let tip = static_tip(method, 10, f);
        let deflection = -tip[1];
        let err = (deflection - linear).abs() / linear;
        assert!(
            err < 0.01,
            "{method}: deflection {deflection} vs {linear} ({:.3} %)",
            100.0 * err
        );
    }
}

/// The inextensible elastica under a dead tip load P (downward), by
/// shooting: theta'' = alpha cos(theta) on s in [0, 1], theta(0) = 0,
/// theta'(1) = 0, alpha = P L^2 / (E I). Returns the tip (x, y) / L.
fn elastica_tip(alpha: f64) -> [f64; 2] {
    // State (theta, theta', x, y) integrated by RK4 over 4000 steps.
    let run = |c: f64| -> [f64; 4] {
        let f = |s: [f64; 4]| [s[1], alpha * s[0].cos(), s[0].cos(), s[0].sin()];
        let n = 4000;
        let h = 1.0 / n as f64;
        let mut y = [0.0, c, 0.0, 0.0];
        for _ in 0..n {
            let add = |a: [f64; 4], b: [f64; 4], k: f64| std::array::from_fn(|i| a[i] + k * b[i]);
            let k1 = f(y);
            let k2 = f(add(y, k1, h / 2.0));
            let k3 = f(add(y, k2, h / 2.0));
            let k4 = f(add(y, k3, h));
            y = std::array::from_fn(|i| {
                y[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
            });
        }
        y
    };
    // theta'(1) rises monotonically with the initial slope c in [-alpha, 0].
    let (mut lo, mut hi) = (-alpha, 0.0);
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        if run(mid)[1] > 0.0 {
            hi = mid
        } else {
            lo = mid
        }
    }
    let y = run(0.5 * (lo + hi));
    [y[2], y[3]]
}

#[test]
fn elastica_reference_matches_the_published_table() {
    // Bisshopp and Drucker (1945): alpha = 10 gives vertical deflection
    // 0.8106 L and horizontal position 0.4450 L (to 4 digits).
    let t = elastica_tip(10.0);
    assert!(
        (-t[1] - 0.8106).abs() < 2e-4 && (t[0] - 0.4450).abs() < 2e-4,
        "{t:?}"
    );
}

#[test]
fn large_tip_load_converges_to_the_elastica() {
    for alpha in [1.0, 5.0, 10.0] {
        let p = alpha * ei() / (L * L);
        let reference = elastica_tip(alpha);
        let mut errors = Vec::new();
        for n in [5, 10, 20] {
            let tip = static_tip("pcc", n, p);
            let err =
                ((tip[0] / L - reference[0]).powi(2) + (tip[1] / L - reference[1]).powi(2)).sqrt();
            errors.push(err);
        }
        assert!(
            errors[2] < 2e-3,
            "alpha {alpha}: 20-element error {} of L",
            errors[2]
        );
        assert!(
            errors[0] > errors[1] && errors[1] > errors[2],
            "alpha {alpha}: not converging {errors:?}"
        );
    }
}

#[test]
fn bending_frequencies_match_euler_bernoulli() {
    let l = cantilever(&["segment.0.elements=20".into()]);
    let n = l.arm.dof();
    let m = modes(&*l.arm, &vec![0.0; n]).unwrap();
    let area = std::f64::consts::PI * R * R;
    let scale = (ei() / (RHO * area * L.powi(4))).sqrt();
    for (k, beta) in [1.875104f64, 4.694091].into_iter().enumerate() {
        let exact = beta * beta / (2.0 * std::f64::consts::PI) * scale;
        let err = (m.frequencies_hz[k] - exact).abs() / exact;
        assert!(
            err < 0.02,
            "mode {}: {} Hz vs {exact} Hz",
            k + 1,
            m.frequencies_hz[k]
        );
    }
}

#[test]
fn undamped_pcc_arm_conserves_energy_through_the_straight_state() {
    let l = cantilever(&["gravity=[0, -9.81, 0]".into()]);
    let arm = &*l.arm;
    let n = arm.dof();
    // Bent upwards against gravity, released from rest.
    let mut x0 = vec![0.25; n];
    x0.extend(vec![0.0; n]);
    let opts = SimOptions {
        t_end: 5.0,
        rtol: 1e-10,
        atol: 1e-12,
        output_dt: 0.002,
        ..Default::default()
    };
    let (traj, _) = simulate(arm, x0, &opts).unwrap();
    let energy: Vec<f64> = traj
        .x
        .iter()
        .map(|x| {
            assert!(x.iter().all(|v| v.is_finite()));
            let o = arm.outputs(0.0, &x[..n], &x[n..]);
            o[3] + o[4]
        })
        .collect();
    let ke_max = traj
        .x
        .iter()
        .map(|x| arm.outputs(0.0, &x[..n], &x[n..])[3])
        .fold(0.0, f64::max);
    let e0 = energy[0];
    let scale = e0.abs().max(ke_max);
    let drift = energy.iter().map(|e| (e - e0).abs()).fold(0.0, f64::max) / scale;
    assert!(drift < 1e-7, "relative energy drift {drift:e}");
    // Every element swings through theta = 0 again and again.
    for i in 0..n {
        let crossings = traj
            .x
            .windows(2)
            .filter(|w| w[0][i].signum() != w[1][i].signum())
            .count();
        assert!(
            crossings >= 4,
            "element {i} crossed theta = 0 only {crossings} times"
        );
    }
}

#[test]
fn cli_static_and_modes_report_json() {
    let dir = tempfile::tempdir().unwrap();
    let out = softarm(
        &[
            "static",
            "cantilever",
            "--set",
            "tip.force=[0,-0.05,0]",
            "--json",
        ],
        dir.path(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let v: serde_json::Value = serde_json::from_str(&stdout(&out)).unwrap();
    assert_eq!(v["q"].as_array().unwrap().len(), 10);
    assert!(v["residual"].as_f64().unwrap() < 1e-9);
    assert!(v["iterations"].as_u64().unwrap() >= 1);
    assert!(
        v["tip_position"][1].as_f64().unwrap() < 0.0,
        "a downward force bends the tip down"
    );
    let out = softarm(&["modes", "cantilever", "--shapes", "--json"], dir.path());
    assert!(out.status.success(), "{}", stderr(&out));
    let v: serde_json::Value = serde_json::from_str(&stdout(&out)).unwrap();
    let f: Vec<f64> = v["frequencies_hz"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert_eq!(f.len(), 10);
    assert!(f.windows(2).all(|w| w[0] <= w[1]), "ascending: {f:?}");
    assert_eq!(v["shapes"].as_array().unwrap().len(), 10);
}

/// Without `--json`, `static`, `modes` and `inspect` print tables a person
/// reads, with the JSON's own values.
#[test]
fn cli_static_modes_and_inspect_print_tables() {
    let dir = tempfile::tempdir().unwrap();
    let run = |args: &[&str]| {
        let out = softarm(args, dir.path());
        assert!(out.status.success(), "{}", stderr(&out));
        stdout(&out)
    };
    let table = run(&["static", "cantilever", "--set", "tip.force=[0,-0.05,0]"]);
    let v: serde_json::Value = serde_json::from_str(&run(&[
        "static",
        "cantilever",
        "--set",
        "tip.force=[0,-0.05,0]",
        "--json",
    ]))
    .unwrap();
    let y = format!("y {:.3} mm", 1e3 * v["tip_position"][1].as_f64().unwrap());
    assert!(table.contains(&y), "{y} in\n{table}");
    // The planar cantilever's coordinates are one kind (theta): the table
    // names the largest, with its value.
    let (names, q) = (
        v["coordinates"].as_array().unwrap(),
        v["q"].as_array().unwrap(),
    );
    let k = (0..q.len())
        .max_by(|&a, &b| {
            q[a].as_f64()
                .unwrap()
                .abs()
                .total_cmp(&q[b].as_f64().unwrap().abs())
        })
        .unwrap();
    let row = format!(
        "{:<24} {:>12.5e}",
        names[k].as_str().unwrap(),
        q[k].as_f64().unwrap()
    );
    assert!(table.contains(&row), "{row} in\n{table}");
    let table = run(&["modes", "cantilever"]);
    let v: serde_json::Value =
        serde_json::from_str(&run(&["modes", "cantilever", "--json"])).unwrap();
    let f1 = format!("{:>9.3} Hz", v["frequencies_hz"][0].as_f64().unwrap());
    assert!(table.contains(&f1), "{f1} in\n{table}");
    assert!(
        table.lines().filter(|l| l.contains(" Hz ")).count() == 10,
        "{table}"
    );
    let table = run(&["inspect", "stiff_flop"]);
    let v: serde_json::Value =
        serde_json::from_str(&run(&["inspect", "stiff_flop", "--json"])).unwrap();
    let ratio = format!("{:.3e}", v["stiffness_ratio"].as_f64().unwrap());
    assert!(
        table.contains(&ratio) && table.contains("recommended solver"),
        "{table}"
    );
}

#[test]
fn static_failure_names_the_last_converged_load_fraction() {
    // A chain without joint springs has no stiffness: Newton cannot start.
    let dir = tempfile::tempdir().unwrap();
    let out = softarm(
        &["static", "chain", "--set", "segment.0.joint_stiffness=0"],
        dir.path(),
    );
    assert!(!out.status.success());
    let err = stderr(&out);
    assert!(
        err.contains("last converged load fraction is 0.0000"),
        "{err}"
    );
    assert!(err.contains("singular"), "{err}");
    assert!(
        !err.contains('\\') && !err.contains("     "),
        "message is one clean line: {err}"
    );
}

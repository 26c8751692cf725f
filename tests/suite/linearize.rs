//! `softarm linearize` against closed forms and finite differences.

use crate::common::*;

/// A uniform rod (mass m, length l) on a torsional spring k and damper c
/// at its pivot, without gravity, a motor torque tau the input:
/// I theta'' = -k theta - c theta' + tau with I = m l^2 / 3, so
/// A = [[0, 1], [-k/I, -c/I]], B = [0, 1/I]; the tip (l cos, l sin)
/// gives C = [[0, 0], [l, 0], [0, 0]] at theta = 0, D = 0.
#[test]
fn a_rod_on_a_spring_linearises_to_its_closed_form() {
    let (m, l, k, c) = (0.5, 0.3, 2.0, 0.1);
    let text = format!(
        r#"
name = "sprung_rod"
gravity = [0.0, 0.0, 0.0]
[base]
direction = [1.0, 0.0, 0.0]
[[segment]]
method = "rigid"
length = {l}
elements = 1
mass = {m}
joint_stiffness = {k}
joint_damping = {c}
[[torque]]
coordinate = "theta_0_0"
input = "tau"
[inputs.tau]
kind = "constant"
value = 0.0
"#
    );
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("sprung_rod.toml");
    std::fs::write(&path, text).unwrap();
    let o = softarm(
        &[
            "linearize",
            path.to_str().unwrap(),
            "--inputs",
            "tau",
            "--json",
        ],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    let at = |key: &str, i: usize, j: usize| v[key][i][j].as_f64().unwrap();
    let inertia = m * l * l / 3.0;
    let expect_a = [[0.0, 1.0], [-k / inertia, -c / inertia]];
    for (i, row) in expect_a.iter().enumerate() {
        for (j, e) in row.iter().enumerate() {
            assert_close(at("A", i, j), *e, 1e-12, 1e-12, format_args!("A[{i}][{j}]"));
        }
    }
    assert_close(at("B", 0, 0), 0.0, 0.0, 1e-9, "B[0]");
    assert_close(at("B", 1, 0), 1.0 / inertia, 1e-8, 0.0, "B[1]");
    for (i, e) in [0.0, l, 0.0].iter().enumerate() {
        assert_close(at("C", i, 0), *e, 1e-8, 1e-9, format_args!("C[{i}][0]"));
        assert_close(at("C", i, 1), 0.0, 0.0, 1e-12, format_args!("C[{i}][1]"));
        assert_close(at("D", i, 0), 0.0, 0.0, 1e-9, format_args!("D[{i}]"));
    }
    assert_eq!(v["states"][1], "theta_0_0_dot");
}

/// A 3D soft module under pressure: A is the generated Jacobian, checked
/// against central differences of the accelerations; B against the
/// module's symmetry.
#[test]
fn the_pressed_module_linearises_as_its_differences() {
    use runtime::Workspace;
    use softarm::backend::{BackendChoice, load};
    let names = vec!["p0".to_string(), "p1".to_string(), "p2".to_string()];
    let u0 = [2e4, 5e3, 0.0];
    let mut l = load("stiff_flop", &[], BackendChoice::Auto, None).unwrap();
    let lin = softarm::linearize::linearize(&mut l, &names, Some(&u0), None).unwrap();
    let n = l.arm.dof();
    // The equilibrium: no acceleration.
    let mut ws = Workspace::new(n);
    let mut qdd = vec![0.0; n];
    let zeros = vec![0.0; n];
    runtime::accelerations(&*l.arm, &mut ws, 0.0, &lin.q0, &zeros, &mut qdd).unwrap();
    assert!(qdd.iter().all(|a| a.abs() < 1e-6), "equilibrium: {qdd:?}");
    // A's lower rows by central differences of qdd in each state.
    let x0: Vec<f64> = lin.q0.iter().copied().chain(zeros.clone()).collect();
    for j in 0..2 * n {
        let h = 1e-6;
        let mut acc = |s: f64| {
            let mut x = x0.clone();
            x[j] += s * h;
            let mut out = vec![0.0; n];
            runtime::accelerations(&*l.arm, &mut ws, 0.0, &x[..n], &x[n..], &mut out).unwrap();
            out
        };
        let (plus, minus) = (acc(1.0), acc(-1.0));
        let scale = (0..n).map(|i| lin.a[(n + i, j)].abs()).fold(1.0, f64::max);
        for i in 0..n {
            let fd = (plus[i] - minus[i]) / (2.0 * h);
            let d = (lin.a[(n + i, j)] - fd).abs();
            assert!(
                d < 1e-5 * scale,
                "A[{}][{j}]: {} vs {fd}",
                n + i,
                lin.a[(n + i, j)]
            );
        }
    }
    // B at zero pressure: the module stands straight on its axis, and its
    // three chamber pairs sit 120 degrees apart, so each pair bends the
    // first element as much as the others, in directions that sum to zero,
    // and stretches it alike.
    let mut l = load("stiff_flop", &[], BackendChoice::Auto, None).unwrap();
    let lin0 = softarm::linearize::linearize(&mut l, &names, None, None).unwrap();
    let coords = l.arm.info().coordinates.clone();
    let row = |name: &str| n + coords.iter().position(|c| c == name).unwrap();
    let (by, bz, st) = (row("bend_y_0_0"), row("bend_z_0_0"), row("stretch_0_0"));
    let bend: Vec<[f64; 2]> = (0..3).map(|k| [lin0.b[(by, k)], lin0.b[(bz, k)]]).collect();
    let size = |v: [f64; 2]| v[0].hypot(v[1]);
    for k in 1..3 {
        assert_close(size(bend[k]), size(bend[0]), 1e-6, 0.0, "bending per pair");
        assert_close(
            lin0.b[(st, k)],
            lin0.b[(st, 0)],
            1e-6,
            0.0,
            "stretch per pair",
        );
    }
    let sum = [0, 1].map(|c| bend.iter().map(|b| b[c]).sum::<f64>());
    assert!(
        size(sum) < 1e-6 * size(bend[0]),
        "bending directions sum to {sum:?}"
    );
    assert!(size(bend[0]) > 0.0);
    assert_eq!(lin.b.nrows(), 2 * n);
    assert!(
        lin.b.rows(0, n).iter().all(|v| *v == 0.0),
        "no input moves q directly"
    );
}

/// A point force at mid-span of a cantilever driven by an input channel
/// (`[[load]]` with `force_inputs`), linearised about the straight rod:
/// the tip's static gain -C A^-1 B per newton is beam theory's
/// 5 L^3 / (48 E I), the load's lever on the tip.
#[test]
fn a_load_along_the_arm_linearises_to_its_static_gain() {
    use crate::loads::{L, cantilever, ei};
    let load = format!(
        "[[load]]\nsegment = 0\ns = {}\nforce_inputs = [\"zero\", \"zero\", \"push\"]\n\
         [inputs.zero]\nkind = \"constant\"\nvalue = 0.0\n\
         [inputs.push]\nkind = \"constant\"\nvalue = 0.0",
        L / 2.0
    );
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("midspan.toml");
    std::fs::write(&path, cantilever(3, &load)).unwrap();
    let o = softarm(
        &[
            "linearize",
            path.to_str().unwrap(),
            "--inputs",
            "push",
            "--set",
            "segment.0.elements=16",
            "--json",
        ],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    let matrix = |key: &str| {
        let rows = v[key].as_array().unwrap();
        let cols = rows[0].as_array().unwrap().len();
        nalgebra::DMatrix::from_fn(rows.len(), cols, |i, j| rows[i][j].as_f64().unwrap())
    };
    let (a, b, c) = (matrix("A"), matrix("B"), matrix("C"));
    let gain = -(&c * a.lu().solve(&b).unwrap());
    let want = 5.0 * L.powi(3) / (48.0 * ei());
    // C's rows: the tip's x, y, z first.
    assert_close(gain[(2, 0)], want, 2e-3, 0.0, "the tip's z per newton");
    assert_close(
        gain[(1, 0)],
        0.0,
        0.0,
        1e-9 * want,
        "the tip's y per newton",
    );
}

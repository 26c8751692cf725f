//! `softarm export --c`: the library, compiled by the system's C compiler
//! at `-std=c99 -Wall -Werror -O1` (every bundled model at `-O2` in the
//! long checks), gives what the Rust kernels give at
//! random states: M, h, the outputs, the shape and the joints' rows to
//! 1e-12 of each block's largest entry; the state derivative and its
//! Jacobian as far as solves with M agree (below).

use std::fmt::Write;
use std::path::Path;
use std::process::Command;

use nalgebra::{DMatrix, DVector};
use runtime::Dynamics;
use softarm::backend::{BackendChoice, load};

use crate::common::{Rng, root};

/// Relative agreement asked of every kernel's block.
const TOL: f64 = 1e-12;
/// Of what comes through a solve with M (the accelerations and the
/// Jacobian's lower half): two solves in different orders agree to about
/// cond(M) times round-off, and random states of a soft finger give
/// cond(M) near 1e4. The C solve's own backward error is held to `TOL`
/// (the residual of M qdd + h, below).
const SOLVED_TOL: f64 = 1e-9;
/// Of a Jacobian by central differences (with joints, in both): each
/// column's two accelerations, equal to `SOLVED_TOL`, over a step of
/// cbrt(eps) = 6e-6.
const DIFFERENCED_TOL: f64 = 1e-5;
/// Random states a model.
const STATES: usize = 3;

/// One block of values: its name and the Rust side's numbers.
struct Block {
    name: String,
    values: Vec<f64>,
    tol: f64,
}

fn block(name: &str, values: Vec<f64>) -> Block {
    Block {
        name: name.into(),
        values,
        tol: TOL,
    }
}

/// What the Rust kernels give at (t, q, qd), in the driver's print order.
fn rust_blocks(
    arm: &dyn Dynamics,
    shape: &eomgen::shape::ShapeTape,
    t: f64,
    x: &[f64],
) -> Vec<Block> {
    let n = arm.dof();
    let (q, qd) = (&x[..n], &x[n..2 * n]);
    let mut m = DMatrix::zeros(n, n);
    let mut h = DVector::zeros(n);
    arm.mass_bias(t, q, qd, &mut m, &mut h);
    let mut blocks = vec![
        block("mass", m.transpose().iter().copied().collect()),
        block("bias", h.iter().copied().collect()),
        block("outputs", arm.outputs(t, q, qd).to_vec()),
        block("shape", shape.eval(t, q, &arm.params_at(t))),
    ];
    // The inverse dynamics' derivative along (dq, dqd) = (qd, q) at qdd = 0:
    // no solve, so the tangent's every term shows at 1e-12.
    let dir: Vec<f64> = qd.iter().chain(q).copied().collect();
    let mut dtau = vec![0.0; n];
    arm.eval_direction(runtime::KernelKind::Jvp, t, q, qd, &dir, &[], &mut dtau);
    blocks.push(block("jvp", dtau));
    let mut ws = runtime::Workspace::new(n);
    // qdd, then a viscoelastic arm's relaxed forces' rates.
    let mut dx = vec![0.0; x.len()];
    runtime::relaxed_forces::state_rate(arm, &mut ws, t, x, &mut dx)
        .expect("the Rust state derivative");
    blocks.push(Block {
        name: "qdd".into(),
        values: dx[n..2 * n].to_vec(),
        tol: SOLVED_TOL,
    });
    if x.len() > 2 * n {
        blocks.push(block("relaxed forces' rates", dx[2 * n..].to_vec()));
    }
    let mut jac = DMatrix::zeros(x.len(), x.len());
    runtime::state_jacobian(arm, &mut ws, t, x, &mut jac).expect("the Rust Jacobian");
    let values = jac.transpose().iter().copied().collect();
    let joints = !arm.info().constraints.is_empty();
    blocks.push(Block {
        name: "jacobian".into(),
        values,
        tol: if joints || arm.internal_len() > 0 || arm.contact().is_some() {
            DIFFERENCED_TOL
        } else {
            SOLVED_TOL
        },
    });
    if let Some(set) = arm.contact() {
        let forces = runtime::contact::pair_forces(arm, set, t, q, qd, true);
        blocks.push(block("gaps", forces.iter().map(|f| f.gap).collect()));
        blocks.push(Block {
            name: "normal forces".into(),
            values: forces.iter().map(|f| f.normal).collect(),
            // From the velocities, which come through no solve: 1e-12 of
            // the largest, but a pair at the surface may have no force on
            // one side and round-off on the other.
            tol: TOL,
        });
    }
    if joints {
        let c = runtime::constraints::evaluate(arm, t, q, qd);
        let jac: Vec<f64> = c.jac.transpose().iter().copied().collect();
        blocks.push(block("phi", c.phi));
        blocks.push(block("constraint jacobian", jac));
        blocks.push(block("gamma", c.gamma));
    }
    blocks
}

/// A C driver that binds the given base parameters, evaluates every
/// function at each state and prints the values one a line.
fn driver(
    prefix: &str,
    params: &[f64],
    (n, states): (usize, &[Vec<f64>]),
    (joints, impact): (bool, Option<&[f64]>),
    t: f64,
) -> String {
    let p = prefix;
    let up = p.to_ascii_uppercase();
    let (nx, no) = (states[0].len(), runtime::N_OUTPUTS);
    let mut c = format!(
        "#include <stdio.h>\n#include \"{p}.h\"\n\
         static void put(const double *v, size_t k) {{ size_t i; for (i = 0; i < k; i++) printf(\"%.17g\\n\", v[i]); }}\n\
         int main(void) {{\n  static {p}_params v; static {p}_model m;\n  \
         static double mass[{nn}], bias[{n}], out[{no}], shape[{up}_NSHAPE * 7], dx[{nx}], jac[{nxx}];\n  \
         static double zeros[{n}], dtau[{n}];\n  \
         static double phi[{up}_NCONSTRAINTS + 1], cj[({up}_NCONSTRAINTS + 1) * {n}], gamma[{up}_NCONSTRAINTS + 1];\n  \
         size_t i;\n  {p}_default_params(&v);\n  {p}_init(&m, &v);\n",
        nn = n * n,
        nxx = nx * nx,
    );
    // The parameters as the Rust side has them at t (inputs included).
    let _ = write!(c, "  {{ static const double base[] = {{");
    for v in params {
        let _ = write!(c, "{v:?}, ");
    }
    let _ = writeln!(
        c,
        "0.0 }};\n    for (i = 0; i < {}; i++) {p}_set_parameter(&m, i, base[i]);\n  }}",
        params.len()
    );
    if let Some(impact) = impact {
        // The pairs' records, as the Rust side has them.
        for (i, v) in impact.iter().enumerate() {
            let _ = writeln!(c, "  m.impact[{i}] = {v:?};");
        }
        let _ = writeln!(c, "  static double gap[{up}_NPAIRS], normal[{up}_NPAIRS];");
    }
    for x in states {
        let _ = write!(c, "  {{ static const double x[] = {{");
        for v in x {
            let _ = write!(c, "{v:?}, ");
        }
        let _ = writeln!(
            c,
            "0.0 }};\n    {p}_mass_bias(&m, {t:?}, x, x + {n}, mass, bias); put(mass, {nn}); put(bias, {n});\n    \
             {p}_outputs(&m, {t:?}, x, x + {n}, out); put(out, {no});\n    \
             {p}_shape(&m, {t:?}, x, shape); put(shape, {up}_NSHAPE * 7);\n    \
             {p}_inverse_dynamics_jvp(&m, {t:?}, x, x + {n}, zeros, x + {n}, x, dtau); put(dtau, {n});\n    \
             if ({p}_state_derivative(&m, {t:?}, x, dx)) return 3;\n    put(dx + {n}, {});",
            nx - n,
            nn = n * n,
        );
        let _ = writeln!(
            c,
            "    if ({p}_state_jacobian(&m, {t:?}, x, jac)) return 4;\n    put(jac, {});",
            nx * nx
        );
        if impact.is_some() {
            let _ = writeln!(
                c,
                "    {p}_contact(&m, {t:?}, x, gap, normal); put(gap, {up}_NPAIRS); put(normal, {up}_NPAIRS);"
            );
        }
        if joints {
            let _ = writeln!(
                c,
                "    {p}_constraints(&m, {t:?}, x, x + {n}, phi, cj, gamma);\n    \
                 put(phi, {up}_NCONSTRAINTS); put(cj, {up}_NCONSTRAINTS * {n}); put(gamma, {up}_NCONSTRAINTS);"
            );
        }
        c.push_str("  }\n");
    }
    if impact.is_some() {
        // The records from none, brought up to the first state.
        let _ = writeln!(
            c,
            "  {{\n    static const double x[] = {{{}0.0 }};\n    \
             for (i = 0; i < {up}_NPAIRS; i++) {{ m.impact[i] = 0.0; m.touching[i] = 0; }}\n    \
             {p}_contact_update(&m, {t:?}, x);\n    put(m.impact, {up}_NPAIRS);\n    \
             for (i = 0; i < {up}_NPAIRS; i++) printf(\"%d\\n\", m.touching[i]);\n  }}",
            states[0]
                .iter()
                .map(|v| format!("{v:?}, "))
                .collect::<String>()
        );
    }
    c.push_str("  (void)phi; (void)cj; (void)gamma; (void)jac;\n  return 0;\n}\n");
    c
}

/// The C accelerations solve M qdd = -h to round-off: each row's residual
/// within `TOL` of the row's own magnitudes (|M| |qdd| + |h|).
fn backward_error_is_round_off(arm: &dyn Dynamics, t: f64, x: &[f64], qdd: &[f64], model: &str) {
    let n = arm.dof();
    let (q, qd) = (&x[..n], &x[n..2 * n]);
    let mut m = DMatrix::zeros(n, n);
    let mut h = DVector::zeros(n);
    arm.mass_bias(t, q, qd, &mut m, &mut h);
    // M qdd + h = the relaxed forces' sum.
    for (k, z) in x[2 * n..].iter().enumerate() {
        h[k % n] -= z;
    }
    for i in 0..n {
        let r: f64 = (0..n).map(|j| m[(i, j)] * qdd[j]).sum::<f64>() + h[i];
        let size: f64 = (0..n).map(|j| (m[(i, j)] * qdd[j]).abs()).sum::<f64>() + h[i].abs();
        assert!(
            r.abs() <= TOL * size,
            "{model}: row {i} of M qdd + h is {r:e} of {size:e}"
        );
    }
}

/// Export `model`, compile it with a driver, and compare every block at
/// random states with the Rust kernels.
fn check_export(model: &str, dir: &Path, opt: Opt) {
    let spec = root().join("models").join(format!("{model}.toml"));
    check_export_spread(model, &spec, dir, 0.3, false, opt);
}

/// The C compiler's optimisation: the default run's exports at `-O1` (half
/// the compile of `-O2`, the same IEEE arithmetic under `-std=c99`), every
/// bundled model at `-O2` in the long checks.
#[derive(Clone, Copy)]
enum Opt {
    O1,
    O2,
}

/// [`check_export`] of the model file `spec`.
fn check_export_of(model: &str, spec: &Path, dir: &Path) {
    check_export_spread(model, spec, dir, 0.3, false, Opt::O1);
}

/// [`check_export_of`] at states whose coordinates lie within `spread`;
/// `touching`: every obstacle, self contact and body pushes at some state.
fn check_export_spread(
    model: &str,
    spec: &Path,
    dir: &Path,
    spread: f64,
    touching: bool,
    opt: Opt,
) {
    let cache = dir.join("cache");
    let out = dir.join("c");
    let spec = spec.to_str().unwrap();
    let export = softarm::export::export_c(spec, &[], &out, Some(cache.clone())).unwrap();
    let loaded = load(spec, &[], BackendChoice::Auto, Some(cache)).unwrap();
    let arm = &*loaded.arm;
    let n = arm.dof();
    let structure = eomgen::model::Structure::of(&loaded.model);
    let shape = eomgen::shape::shape_tape(&structure, 1);
    let t = 0.25;
    let mut rng = Rng::new(0x5eed ^ model.len() as u64);
    let states: Vec<Vec<f64>> = (0..STATES)
        .map(|_| {
            let mut x = rng.coordinates(&arm.info().coordinates, -spread, spread);
            x.extend(rng.vec(n, -spread / 0.3, spread / 0.3));
            x.extend(rng.vec(arm.internal_len(), -1e-3, 1e-3));
            x
        })
        .collect();
    let params = arm.params_at(t)[..arm.info().parameters.len()].to_vec();
    let joints = !arm.info().constraints.is_empty();
    // Each pair's impact speed, a record Hunt-Crossley from a restitution
    // damps by (below the floor speed for some, which then holds).
    let impact: Option<Vec<f64>> = arm.contact().map(|set| {
        let pairs = set.pairs.len();
        let impact = rng.vec(pairs, 0.0, 0.5);
        set.set_state(runtime::contact::ContactState {
            touching: vec![true; pairs],
            impact: impact.clone(),
            held: vec![false; pairs],
        });
        impact
    });
    let main = out.join("driver.c");
    std::fs::write(
        &main,
        driver(
            &export.prefix,
            &params,
            (n, &states),
            (joints, impact.as_deref()),
            t,
        ),
    )
    .unwrap();
    let exe = out.join("driver");
    let cc = Command::new("cc")
        .args(["-std=c99", "-Wall", "-Werror"])
        .arg(match opt {
            Opt::O1 => "-O1",
            Opt::O2 => "-O2",
        })
        .arg("-o")
        .arg(&exe)
        .arg(&main)
        .arg(&export.files[1])
        .arg("-lm")
        .output()
        .expect("a C compiler (cc) on the PATH");
    assert!(
        cc.status.success(),
        "{model}: cc failed:\n{}",
        String::from_utf8_lossy(&cc.stderr)
    );
    let run = Command::new(&exe).output().unwrap();
    assert!(
        run.status.success(),
        "{model}: the driver failed ({:?})",
        run.status
    );
    let text = String::from_utf8(run.stdout).unwrap();
    if let Some(set) = arm.contact().filter(|_| touching) {
        // Every obstacle, self contact and body pushes at some state, so
        // that each shape's and law's forces are compared.
        let pushes = |channel: usize| {
            states.iter().any(|x| {
                let f = runtime::contact::pair_forces(arm, set, t, &x[..n], &x[n..2 * n], true);
                (set.pairs.iter().zip(&f)).any(|(p, f)| p.channel == channel && f.normal > 0.0)
            })
        };
        for (c, name) in set.channels.iter().enumerate() {
            assert!(
                pushes(c),
                "{model}: nothing touches {name} at the test's states"
            );
        }
    }
    let mut got = text.lines().map(|l| l.parse::<f64>().unwrap());
    for (k, x) in states.iter().enumerate() {
        for b in rust_blocks(arm, &shape, t, x) {
            let c: Vec<f64> = got.by_ref().take(b.values.len()).collect();
            assert_eq!(c.len(), b.values.len(), "{model}: {} too short", b.name);
            let scale = b.values.iter().fold(1e-300_f64, |m, v| m.max(v.abs()));
            let worst = c
                .iter()
                .zip(&b.values)
                .map(|(a, r)| (a - r).abs())
                .fold(0.0, f64::max);
            if b.name == "qdd" && !joints {
                backward_error_is_round_off(arm, t, x, &c, model);
            }
            assert!(
                worst <= b.tol * scale,
                "{model}, state {k}, {}: C and Rust differ by {worst:e} of a largest entry {scale:e}",
                b.name
            );
        }
    }
    if let Some(set) = arm.contact() {
        // `contact_update` from no records: a pair that touches records its
        // speed of approach, as `ContactSet::update_records`.
        let x = &states[0];
        set.clear_records();
        let forces = runtime::contact::pair_forces(arm, set, t, &x[..n], &x[n..2 * n], true);
        set.update_records(&forces, &[]);
        let state = set.state();
        let flags = state.touching.iter().map(|&b| f64::from(u8::from(b)));
        let rust: Vec<f64> = state.impact.iter().copied().chain(flags).collect();
        let c: Vec<f64> = got.by_ref().take(rust.len()).collect();
        assert!(
            !touching || state.touching.iter().any(|&b| b),
            "{model}: no pair touches"
        );
        let scale = rust.iter().fold(1e-300_f64, |m, v| m.max(v.abs()));
        for (a, r) in c.iter().zip(&rust) {
            assert!(
                (a - r).abs() <= TOL * scale,
                "{model}: records {c:?} against {rust:?}"
            );
        }
        assert_eq!(c.len(), rust.len(), "{model}: records too short");
    }
    assert!(
        got.next().is_none(),
        "{model}: the driver printed more than asked"
    );
}

/// A planar pcc arm, a 3D rom arm (kernels large enough to go as
/// tables) and an assembly closed by joints: the default run's check.
#[test]
fn the_c_library_of_a_pcc_arm_a_rom_arm_and_joints_agrees_with_the_rust_kernels() {
    for model in ["soft_finger", "rom_arm", "falling_ball"] {
        let dir = tempfile::tempdir().unwrap();
        check_export(model, dir.path(), Opt::O1);
    }
}

/// Every bundled model, contact included.
#[test]
#[ignore = "long (every bundled model compiled at -O2): run by .ci/run's long checks"]
fn every_bundled_model_exports_c_that_agrees_with_the_rust_kernels() {
    for e in std::fs::read_dir(root().join("models")).unwrap() {
        let path = e.unwrap().path();
        let name = path.file_stem().unwrap().to_str().unwrap().to_string();
        let dir = tempfile::tempdir().unwrap();
        check_export(&name, dir.path(), Opt::O2);
    }
}

/// A viscoelastic soft finger (two Prony branches): its relaxed forces
/// are states after q and qd, M qdd + h their sum and each branch's rate
/// (ratio f_g - z) / time with f_g the finger's elastic force, as
/// `runtime::relaxed_forces` has them.
#[test]
fn a_viscoelastic_arms_relaxed_forces_are_exported_as_states() {
    let dir = tempfile::tempdir().unwrap();
    let relaxing = dir.path().join("relaxing_finger.toml");
    let finger = std::fs::read_to_string(root().join("models/soft_finger.toml")).unwrap();
    let relaxing_text = finger.replace(
        "youngs_modulus = 1.0e6",
        "youngs_modulus = 1.0e6\nrelaxation = [{ ratio = 0.3, time = 0.5 }, { ratio = 0.2, time = 0.05 }]",
    );
    assert_ne!(relaxing_text, finger);
    std::fs::write(&relaxing, relaxing_text).unwrap();
    check_export_of("relaxing_finger", &relaxing, dir.path());
}

/// Models no build has, each a chain of link cells: the right-angle frame
/// (a kink, a link without coordinates), the tapered tentacle (its
/// chambers' loads from inputs) and a planar finger of 32 arcs (an inertia
/// that changes with the coordinates). The library is the cells and the
/// recursion: its kernels agree with softarm's as every model's do; four
/// times the elements leave the cells' kernels as they were, and the C
/// grows by the parameters' names, fields and defaults and the layout's
/// tables (the whole-arm kernels took 5.7 kB more C an element).
#[test]
fn a_chain_of_link_cells_exports_its_cells_and_the_recursion() {
    for name in ["right_angle_frame", "tapered_tentacle"] {
        let dir = tempfile::tempdir().unwrap();
        let spec = root().join("examples").join(format!("{name}.toml"));
        check_export_of(name, &spec, dir.path());
    }
    // A planar pcc finger long enough for the recursion (32 elements): its
    // arcs' inertia changes with their curvature.
    let dir = tempfile::tempdir().unwrap();
    let finger = std::fs::read_to_string(root().join("models/soft_finger.toml")).unwrap();
    let long = finger.replace("elements = 8", "elements = 32");
    assert_ne!(long, finger);
    let spec = dir.path().join("long_finger.toml");
    std::fs::write(&spec, long).unwrap();
    check_export_of("long_finger", &spec, dir.path());
    let spec = root().join("examples/tapered_tentacle.toml");
    let source = |elements: usize| {
        let dir = tempfile::tempdir().unwrap();
        let set =
            [eomgen::model::Override::parse(&format!("segment.0.elements={elements}")).unwrap()];
        let export =
            softarm::export::export_c(spec.to_str().unwrap(), &set, dir.path(), None).unwrap();
        std::fs::read_to_string(&export.files[1]).unwrap()
    };
    // The cells' kernels: from each `k_cell_` function to the end of it.
    let cells = |c: &str| -> Vec<String> {
        c.split("static void k_cell_")
            .skip(1)
            .map(|f| f[..f.find("\n}\n").unwrap()].to_string())
            .collect()
    };
    let (small, large) = (source(9), source(36));
    assert!(large.contains("links_sweep"), "no recursion");
    assert!(!cells(&small).is_empty() && cells(&small) == cells(&large));
    let per_element = (large.len() - small.len()) / 27;
    assert!(
        per_element < 2_000,
        "{per_element} characters of C an element"
    );
}

/// A 3D arm among obstacles of every shape (a plane, a sphere, a capped
/// cylinder and a turned box, each crossing the arm's reach) with self
/// contact, and two arms and a ball on a floor (point-on-body pairs):
/// each pair's gap and normal force, h less J^T f and the accelerations
/// equal the Rust contact forces' at random states, with random impact
/// records (Hunt-Crossley from a restitution damps by them).
#[test]
fn contact_is_exported_for_every_shape_self_contact_and_bodies() {
    let dir = tempfile::tempdir().unwrap();
    let among = dir.path().join("among_obstacles.toml");
    std::fs::write(&among, AMONG_OBSTACLES).unwrap();
    check_export_spread("among_obstacles", &among, dir.path(), 0.3, true, Opt::O1);
    // ball_drop's floor raised into the arms' reach.
    let dir = tempfile::tempdir().unwrap();
    let drop = std::fs::read_to_string(root().join("models/ball_drop.toml")).unwrap();
    let raised = drop.replace("point = [0.0, -0.7, 0.0]", "point = [0.0, -0.05, 0.0]");
    assert_ne!(raised, drop);
    let spec = dir.path().join("ball_drop.toml");
    std::fs::write(&spec, raised).unwrap();
    // Near its straight arms, the ball by their bases (its coordinates are
    // its place), slowly: a Hunt-Crossley contact leaving fast pushes not.
    check_export_spread("ball_drop", &spec, dir.path(), 0.05, true, Opt::O1);
}

/// A 3D pcc arm along x reaching through four obstacles, with self
/// contact and friction.
const AMONG_OBSTACLES: &str = r#"
name = "among_obstacles"
dimensions = 3
gravity = [0.0, 0.0, -9.81]

[base]
direction = [1.0, 0.0, 0.0]

[[segment]]
method = "pcc"
length = 0.2
elements = 8
outer_radius = 0.02
density = 1100.0
youngs_modulus = 1.0e6
bending_damping = 1.0e-4

[[obstacle]]
name = "floor"
shape = "plane"
point = [0.0, 0.0, -0.004]
normal = [0.1, 0.0, 1.0]

[[obstacle]]
name = "ball"
shape = "sphere"
center = [0.1, 0.01, 0.0]
radius = 0.03

[[obstacle]]
name = "post"
shape = "cylinder"
center = [0.15, 0.0, 0.0]
axis = [0.0, 0.6, 0.8]
radius = 0.012
length = 0.05

[[obstacle]]
name = "block"
shape = "box"
center = [0.19, 0.0, 0.01]
size = [0.03, 0.04, 0.02]
orientation = [0.9238795325112867, 0.0, 0.0, 0.3826834323650898]
contact = { model = "hertz", stiffness = 3.0e4 }

[contact]
model = "hunt_crossley"
stiffness = 2.0e4
exponent = 1.5
restitution = 0.3
friction = 0.6
slip_velocity = 1.0e-3
points_per_element = 2
self_contact = true
"#;

/// What the export cannot carry yet is refused with the key and the
/// reason, and nothing is written.
#[test]
fn what_the_export_cannot_carry_is_refused_and_nothing_is_written() {
    let dir = tempfile::tempdir().unwrap();
    // The impulse law: a velocity jump, then a held constraint.
    let impulse = dir.path().join("impulse.toml");
    let tap = std::fs::read_to_string(root().join("models/finger_tap.toml")).unwrap();
    let impulse_text = tap.replace("model = \"hunt_crossley\"", "model = \"impulse\"");
    assert_ne!(impulse_text, tap);
    std::fs::write(&impulse, impulse_text).unwrap();
    // A moving obstacle: the table driven by an input channel.
    let moving = dir.path().join("moving.toml");
    let moving_text = tap.replace(
        "name = \"table\"",
        "name = \"table\"\ntranslation_inputs = [\"vent\", \"vent\"]",
    );
    assert_ne!(moving_text, tap);
    std::fs::write(&moving, moving_text).unwrap();
    for (spec, key) in [
        (impulse.as_path(), "[contact]"),
        (moving.as_path(), "\"table\" moves"),
    ] {
        let out = dir.path().join("c");
        let err = softarm::export::export_c(
            spec.to_str().unwrap(),
            &[],
            &out,
            Some(dir.path().join("cache")),
        )
        .unwrap_err();
        let text = format!("{err:#}");
        assert!(text.contains(key) && text.contains("not"), "{text}");
        assert!(!out.exists(), "{} was written", out.display());
    }
    // A file that cannot be put in place (a folder in the way of the
    // source): the header written before it is taken back, no temporary
    // is left, and the folder holds what it held.
    let out = dir.path().join("blocked");
    std::fs::create_dir_all(out.join("soft_finger.c").join("inside")).unwrap();
    let err = softarm::export::export_c("soft_finger", &[], &out, None).unwrap_err();
    assert!(format!("{err:#}").contains("soft_finger.c"), "{err:#}");
    let left: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(left, ["soft_finger.c"], "left behind: {left:?}");
    // Nothing asked: the three targets named.
    let none = softarm::export::Targets::default();
    let err = softarm::export::export("soft_finger", &[], &none, None).unwrap_err();
    let text = format!("{err:#}");
    assert!(
        ["--c DIR", "--fmu", "--mex"]
            .iter()
            .all(|k| text.contains(k)),
        "{text}"
    );
}

/// The FMU's archive and model description hang together (FMPy's own
/// validation and simulation run in python/tests/test_fmu.py): the
/// description, the sources and this platform's binary are there; every
/// variable has its own value reference, in order; each derivative names
/// its state; the inputs are the parameters that inputs drive.
#[test]
fn the_fmu_holds_its_description_sources_and_binary() {
    let dir = tempfile::tempdir().unwrap();
    let fmu = dir.path().join("stiff_flop.fmu");
    let targets = softarm::export::Targets {
        fmu: Some(fmu.clone()),
        ..Default::default()
    };
    let spec = root().join("models/stiff_flop.toml");
    let out = softarm::export::export(
        spec.to_str().unwrap(),
        &[],
        &targets,
        Some(dir.path().join("cache")),
    )
    .unwrap();
    let mut archive = zip::ZipArchive::new(std::fs::File::open(&fmu).unwrap()).unwrap();
    let names: Vec<String> = archive
        .file_names()
        .map(|n| n.unwrap().to_string())
        .collect();
    for want in [
        "modelDescription.xml",
        "sources/stiff_flop.c",
        "sources/stiff_flop.h",
        "sources/fmi2.c",
        "binaries/linux64/stiff_flop.so",
    ] {
        assert!(
            names.iter().any(|n| n == want),
            "{want} missing from {names:?}"
        );
    }
    let mut xml = String::new();
    std::io::Read::read_to_string(
        &mut archive.by_name("modelDescription.xml").unwrap(),
        &mut xml,
    )
    .unwrap();
    let n = out.dof;
    let vars: Vec<&str> = xml.split("<ScalarVariable ").skip(1).collect();
    let attr = |v: &str, key: &str| -> Option<String> {
        let at = v.find(&format!("{key}=\""))? + key.len() + 2;
        Some(v[at..at + v[at..].find('"')?].to_string())
    };
    for (k, v) in vars.iter().enumerate() {
        assert_eq!(
            attr(v, "valueReference"),
            Some(k.to_string()),
            "variable {k}"
        );
    }
    for k in 0..2 * n {
        let v = vars[2 * n + k];
        assert_eq!(attr(v, "derivative"), Some((k + 1).to_string()));
        let state = attr(vars[k], "name").unwrap();
        assert_eq!(attr(v, "name"), Some(format!("der({state})")));
    }
    let inputs: Vec<String> = (vars.iter())
        .filter(|v| attr(v, "causality").as_deref() == Some("input"))
        .map(|v| attr(v, "name").unwrap())
        .collect();
    let driven: Vec<String> = out.inputs.iter().map(|(_, name)| name.clone()).collect();
    assert_eq!(inputs, driven);
    assert!(
        inputs.iter().any(|i| i == "chamber[0][0].pressure"),
        "{inputs:?}"
    );
    assert_eq!(
        vars.len(),
        4 * n + runtime::N_OUTPUTS + out_parameters(&xml)
    );
}

/// Parameters and inputs in a model description (after the states, their
/// derivatives and the outputs).
fn out_parameters(xml: &str) -> usize {
    xml.matches("causality=\"parameter\"").count() + xml.matches("causality=\"input\"").count()
}

//! Assemblies with joints against independent references: a pendulum built
//! as a loop (a free body pinned to the world) against the same pendulum
//! built as a tree (a rigid arm); the undamped falling ball's energy and
//! constraint drift; the mirror symmetry of a symmetric release; the
//! equilibrium of the ball on straight arms against clamped-guided beam
//! theory, and its joint forces against the weights; a compliant base
//! against the closed-form steady response of a mass-spring-damper.

use crate::common::*;
use runtime::{SimOptions, Solver, simulate};

const FALLING_BALL: &str = include_str!("../../models/falling_ball.toml");

/// The model's initial state put onto its joints.
fn start(l: &softarm::backend::Loaded) -> Vec<f64> {
    let arm = &*l.arm;
    let n = arm.dof();
    let mut q =
        eomgen::model::assembly::initial_coordinates(&l.model, &arm.info().coordinates, &l.origin)
            .unwrap();
    let mut qd = vec![0.0; n];
    softarm::joints::assemble(arm, &l.origin, &mut q, &mut qd).unwrap();
    q.extend(qd);
    q
}

/// |a - b| <= tol.
fn assert_abs(a: f64, b: f64, tol: f64, what: &str) {
    assert!(
        (a - b).abs() <= tol,
        "{what}: {a:e} vs {b:e} (difference {:e}, allowed {tol:e})",
        (a - b).abs()
    );
}

fn coordinate(l: &softarm::backend::Loaded, name: &str) -> usize {
    let coords = &l.arm.info().coordinates;
    coords
        .iter()
        .position(|c| c == name)
        .unwrap_or_else(|| panic!("no coordinate {name} in {coords:?}"))
}

/// A uniform rod of length L, mass M swinging about one end, built twice.
const L: f64 = 0.4;
const M: f64 = 0.3;

const TREE: &str = r#"
name = "tree"
gravity = [0.0, -9.81, 0.0]
[base]
direction = [1.0, 0.0, 0.0]
[[segment]]
method = "rigid"
length = 0.4
mass = 0.3
elements = 1
joint_stiffness = 0.0
"#;

/// The same rod as a free body (a box 0.4 long, its inertia given as the
/// rod's, M L^2 / 12), its end pinned to the world at the origin.
const LOOP: &str = r#"
name = "loop"
gravity = [0.0, -9.81, 0.0]
[[body]]
name = "rod"
shape = "box"
size = [0.4, 0.01, 0.01]
mass = 0.3
inertia = 0.004
position = [0.2, 0.0, 0.0]
[[joint]]
name = "hinge"
kind = "pin"
a = "world"
b = "rod"
offset_b = [-0.2, 0.0, 0.0]
"#;

#[test]
fn a_pendulum_built_as_a_loop_swings_as_the_tree() {
    assert!((M * L * L / 12.0 - 0.004).abs() < 1e-15);
    let dir = tempfile::tempdir().unwrap();
    let tree = load_text(dir.path(), TREE, &[]);
    let dir2 = tempfile::tempdir().unwrap();
    let closed = load_text(dir2.path(), LOOP, &[]);
    assert_eq!(closed.arm.info().constraints, ["hinge.x", "hinge.y"]);
    let opts = SimOptions {
        t_end: 2.0,
        output_dt: 0.05,
        rtol: 1e-10,
        atol: 1e-12,
        solver: Solver::Dopri5,
        ..SimOptions::default()
    };
    // Released horizontal, from rest.
    let (a, _) = simulate(&*tree.arm, vec![0.0, 0.0], &opts).unwrap();
    let (b, stats) = simulate(&*closed.arm, start(&closed), &opts).unwrap();
    let angle = coordinate(&closed, "rod.angle");
    let (x, y) = (coordinate(&closed, "rod.x"), coordinate(&closed, "rod.y"));
    assert_eq!(a.t.len(), b.t.len());
    for (xa, xb) in a.x.iter().zip(&b.x) {
        // Two integrations at rtol 1e-10 agree to about 1e-8.
        assert_abs(xb[angle], xa[0], 1e-7, "rod angle");
        // The centre half a rod from the pin, along the rod.
        assert_abs(xb[x], 0.5 * L * xa[0].cos(), 2e-8, "centre x");
        assert_abs(xb[y], 0.5 * L * xa[0].sin(), 2e-8, "centre y");
    }
    let drift = stats.constraints.unwrap();
    assert!(drift.drift_max_m < 1e-9, "{drift:?}");
}

/// The pin's force on the rod at rest hanging straight down holds its
/// weight: lambda is the physical force.
#[test]
fn the_pin_carries_the_hanging_rod() {
    let dir = tempfile::tempdir().unwrap();
    let closed = load_text(dir.path(), LOOP, &[]);
    let n = closed.arm.dof();
    // Hanging: centre below the pin, angle -pi/2.
    let mut q = vec![0.0; n];
    q[coordinate(&closed, "rod.y")] = -0.5 * L;
    q[coordinate(&closed, "rod.angle")] = -std::f64::consts::FRAC_PI_2;
    let f = runtime::constraints::forces(&*closed.arm, 0.0, &q, &vec![0.0; n]).unwrap();
    assert_abs(f[0], 0.0, 1e-12, "horizontal force");
    assert_close(f[1], M * 9.81, 1e-12, 0.0, "vertical force on the rod");
}

/// One second: the fall, the catch and the swings after it (the kinetic
/// energy reaches 0.85 J by 0.25 s, then swings between about 0.15 and
/// 0.8 J several times by 1 s).
#[test]
fn the_undamped_falling_ball_keeps_its_energy_and_its_joints() {
    undamped_falling_ball(1.0);
}

/// Ten seconds of swinging: the drift does not grow.
#[test]
#[ignore = "long (about 45 s): run by .ci/run's long checks"]
fn the_undamped_falling_ball_keeps_its_energy_and_its_joints_for_ten_seconds() {
    undamped_falling_ball(10.0);
}

/// The falling ball without damping over `t_end`: energy within 1e-7 of
/// the swing's largest kinetic energy, the joints within 1e-9 m.
fn undamped_falling_ball(t_end: f64) {
    let dir = tempfile::tempdir().unwrap();
    let sets: Vec<String> = ["left", "right"]
        .iter()
        .flat_map(|a| (0..2).map(move |s| format!("arm.{a}.segment.{s}.bending_damping=0.0")))
        .collect();
    let sets: Vec<&str> = sets.iter().map(String::as_str).collect();
    let l = load_text(dir.path(), FALLING_BALL, &sets);
    assert_eq!(l.arm.backend(), "compiled");
    let x0 = start(&l);
    let opts = SimOptions {
        t_end,
        output_dt: 0.02,
        rtol: 1e-11,
        atol: 1e-13,
        solver: Solver::Radau5,
        ..SimOptions::default()
    };
    let (traj, stats) = simulate(&*l.arm, x0, &opts).unwrap();
    assert_eq!(traj.t.last().copied(), Some(t_end));
    let n = l.arm.dof();
    let energy: Vec<f64> = traj
        .t
        .iter()
        .zip(&traj.x)
        .map(|(t, x)| {
            let o = l.arm.outputs(*t, &x[..n], &x[n..]);
            o[3] + o[4]
        })
        .collect();
    // The scale: the largest kinetic energy of the swing.
    let scale = traj
        .t
        .iter()
        .zip(&traj.x)
        .map(|(t, x)| l.arm.outputs(*t, &x[..n], &x[n..])[3])
        .fold(0.0, f64::max);
    assert!(
        scale > 0.1,
        "the ball falls and swings: kinetic energy {scale}"
    );
    let worst = energy
        .iter()
        .map(|e| (e - energy[0]).abs())
        .fold(0.0, f64::max);
    eprintln!(
        "undamped falling ball: energy drift {worst:.3e} J of {scale:.3e} J; {:?}",
        stats.constraints
    );
    assert!(
        worst < 1e-7 * scale,
        "energy drift {worst:.3e} J of {scale:.3e} J"
    );
    let c = stats.constraints.unwrap();
    assert!(c.drift_max_m < 1e-9, "{c:?}");
}

#[test]
fn a_symmetric_release_stays_symmetric() {
    let dir = tempfile::tempdir().unwrap();
    let l = load_text(dir.path(), FALLING_BALL, &[]);
    let x0 = start(&l);
    let opts = SimOptions {
        t_end: 3.0,
        output_dt: 0.05,
        solver: Solver::Radau5,
        rtol: 1e-9,
        atol: 1e-11,
        ..SimOptions::default()
    };
    let (traj, _) = simulate(&*l.arm, x0, &opts).unwrap();
    assert_eq!(traj.t.last().copied(), Some(3.0));
    let mut worst: f64 = 0.0;
    let coords = l.arm.info().coordinates.clone();
    let (bx, ba) = (coordinate(&l, "ball.x"), coordinate(&l, "ball.angle"));
    for x in &traj.x {
        for (i, c) in coords.iter().enumerate() {
            if let Some(rest) = c.strip_prefix("left.") {
                let j = coordinate(&l, &format!("right.{rest}"));
                worst = worst.max((x[i] + x[j]).abs());
                assert_abs(x[i], -x[j], 1e-9, c);
            }
        }
        assert_abs(x[bx], 0.5, 1e-9, "ball x");
        assert_abs(x[ba], 0.0, 1e-9, "ball angle");
    }
    eprintln!("symmetric release: largest mirror mismatch {worst:.3e}");
}

/// A cantilever (the falling ball's arm: 0.6 m, 2.5 kg, E I = 0.6 N m^2,
/// 10 pcc elements) with a 1 kg ball welded at its tip, under a small
/// gravity: the equivalent clamped beam's tip sinks by
/// P L^3 / (3 EI) + w L^4 / (8 EI).
const HELD_BALL: &str = r#"
name = "held_ball"
gravity = [0.0, -0.01, 0.0]
[base]
direction = [1.0, 0.0, 0.0]
[[segment]]
method = "pcc"
length = 0.6
elements = 10
mass = 2.5
bending_stiffness = 0.6
[[body]]
name = "ball"
shape = "sphere"
radius = 0.05
mass = 1.0
position = [0.6, 0.0, 0.0]
[[joint]]
name = "grip"
kind = "weld"
a = "tip"
b = "ball"
"#;

#[test]
fn a_ball_welded_to_a_cantilever_sinks_as_the_clamped_beam() {
    let dir = tempfile::tempdir().unwrap();
    let l = load_text(dir.path(), HELD_BALL, &[]);
    let n = l.arm.dof();
    let mut q0 = vec![0.0; n];
    q0[coordinate(&l, "ball.x")] = 0.6;
    let by = coordinate(&l, "ball.y");
    let mut arm = l.arm;
    let sol = runtime::solve_static(&mut *arm, &q0, &runtime::StaticOptions::default()).unwrap();
    let (g, ei, len, w, p): (f64, f64, f64, f64, f64) = (0.01, 0.6, 0.6, 2.5 / 0.6, 1.0);
    let sag = p * g * len.powi(3) / (3.0 * ei) + w * g * len.powi(4) / (8.0 * ei);
    eprintln!(
        "welded ball: sag {:.6e} m, beam theory {sag:.6e} m ({:.3} %)",
        -sol.q[by],
        100.0 * (-sol.q[by] / sag - 1.0)
    );
    assert_close(-sol.q[by], sag, 0.01, 0.0, "tip sag against beam theory");
    // The weld holds the ball up with its weight.
    assert_close(sol.lambda[1], p * g, 1e-9, 0.0, "weld force on the ball");
}

/// The falling ball at rest in its bent equilibrium: the welds hold the
/// ball up with its weight, so the walls (each arm's weight plus what the
/// ball hangs on it) carry the whole weight; the horizontal pulls cancel.
#[test]
fn in_equilibrium_the_walls_carry_the_whole_weight() {
    let dir = tempfile::tempdir().unwrap();
    let l = load_text(dir.path(), FALLING_BALL, &[]);
    let n = l.arm.dof();
    let x0 = start(&l);
    let mut arm = l.arm;
    let sol =
        runtime::solve_static(&mut *arm, &x0[..n], &runtime::StaticOptions::default()).unwrap();
    let (g, arm_mass, ball) = (9.81, 2.5, 1.0);
    let rows = &arm.info().constraints;
    let sum = |axis: &str| -> f64 {
        rows.iter()
            .zip(&sol.lambda)
            .filter(|(r, _)| r.ends_with(axis))
            .map(|(_, f)| f)
            .sum()
    };
    let walls = 2.0 * arm_mass * g + sum(".y");
    let weight = (2.0 * arm_mass + ball) * g;
    eprintln!("walls carry {walls:.15} N of {weight:.15} N");
    assert_close(walls, weight, 1e-9, 0.0, "vertical wall reactions");
    assert_abs(
        sum(".x"),
        0.0,
        1e-9 * weight,
        "horizontal forces on the ball",
    );
    // The constraint forces hold: the residual is at round-off.
    assert!(sol.residual < 1e-9, "{}", sol.residual);
}

/// A rigid arm hanging from a compliant base shaken vertically along the
/// arm: the arm cannot swing (the base's motion is along it), so base and
/// arm move as one mass M = m_b + m_a on the spring k and damper c to the
/// driven point f = A sin(w t): steady response
/// y = -M g / k + Re[(k + i c w) / (k - M w^2 + i c w) A e^{i w t}].
#[test]
fn a_compliant_base_follows_its_driven_point_as_a_mass_spring_damper() {
    for dimensions in [2, 3] {
        compliant_base_in(dimensions);
    }
}

fn compliant_base_in(dimensions: u8) {
    let (mb, ma, k, c, amp, hz) = (0.5, 0.3, 200.0, 4.0, 0.01, 2.0);
    let (follow, axes) = match dimensions {
        2 => (r#"["still", "shake"]"#, ""),
        _ => (
            r#"["still", "shake", "still"]"#,
            r#"joint_axes = ["z", "y"]"#,
        ),
    };
    let text = format!(
        r#"
name = "shaken"
dimensions = {dimensions}
gravity = [0.0, -9.81, 0.0]
[base]
direction = [0.0, -1.0, 0.0]
mass = {mb}
stiffness = {k}
damping = {c}
follow = {follow}
[[segment]]
method = "rigid"
length = 0.3
mass = {ma}
elements = 1
joint_stiffness = 1.0
{axes}
[inputs.still]
kind = "constant"
value = 0.0
[inputs.shake]
kind = "sine"
amplitude = {amp}
frequency = {hz}
"#
    );
    let dir = tempfile::tempdir().unwrap();
    let l = load_text(dir.path(), &text, &[]);
    let n = l.arm.dof();
    let total = mb + ma;
    let by = coordinate(&l, "base_y");
    let mut x0 = vec![0.0; 2 * n];
    x0[by] = -total * 9.81 / k;
    let t_end = 12.0;
    let opts = SimOptions {
        t_end,
        output_dt: 0.01,
        rtol: 1e-10,
        atol: 1e-12,
        solver: Solver::Dopri5,
        ..SimOptions::default()
    };
    let (traj, _) = simulate(&*l.arm, x0, &opts).unwrap();
    let w = 2.0 * std::f64::consts::PI * hz;
    // (k + i c w) / (k - M w^2 + i c w)
    let (nr, ni) = (k, c * w);
    let (dr, di) = (k - total * w * w, c * w);
    let d2 = dr * dr + di * di;
    let (gr, gi) = ((nr * dr + ni * di) / d2, (ni * dr - nr * di) / d2);
    // Decay rate c / (2 M): e^{-2.5 * 10} by t = 10 s.
    for (t, x) in traj.t.iter().zip(&traj.x).filter(|(t, _)| **t >= 10.0) {
        let expected = -total * 9.81 / k + amp * (gr * (w * t).sin() + gi * (w * t).cos());
        assert_abs(x[by], expected, 1e-4 * amp, "base y");
        for (i, name) in l.arm.info().coordinates.iter().enumerate() {
            if !name.starts_with("base_") {
                assert_abs(x[i], 0.0, 1e-12, name);
            }
        }
    }
}

/// Modes of a system with joints are those of the motions the joints
/// allow: the pinned rod hanging at rest swings at sqrt(3 g / (2 L)), its
/// restoring moment coming from the pin's force alone (the free body's own
/// stiffness is zero).
#[test]
fn the_pinned_rod_swings_at_the_compound_pendulum_frequency() {
    let dir = tempfile::tempdir().unwrap();
    let closed = load_text(dir.path(), LOOP, &[]);
    let n = closed.arm.dof();
    let mut q = vec![0.0; n];
    q[coordinate(&closed, "rod.y")] = -0.5 * L;
    q[coordinate(&closed, "rod.angle")] = -std::f64::consts::FRAC_PI_2;
    let modes = runtime::modes(&*closed.arm, &q).unwrap();
    assert_eq!(modes.frequencies_hz.len(), 1, "one freedom left by the pin");
    eprintln!("pinned rod: {:.12} Hz", modes.frequencies_hz[0]);
    let expected = (3.0 * 9.81 / (2.0 * L)).sqrt() / (2.0 * std::f64::consts::PI);
    assert_close(
        modes.frequencies_hz[0],
        expected,
        1e-7,
        0.0,
        "pendulum frequency",
    );
    // The shape turns the rod and carries its centre along the circle.
    let shape = &modes.shapes[0];
    let (x, a) = (
        coordinate(&closed, "rod.x"),
        coordinate(&closed, "rod.angle"),
    );
    assert_close(
        shape[x],
        0.5 * L * shape[a],
        1e-7,
        1e-12,
        "centre moves with the turn",
    );
}

/// A 3D rod (0.4 m, 0.3 kg, radius 1 cm) on a ball-and-socket at one end,
/// built as a tree (a rigid link turning about z, then y, then its own x:
/// a spherical joint) and as a free
/// body on quaternion coordinates pinned to the world; released from rest
/// tilted 0.5 rad out of the horizontal plane: a spherical pendulum.
const TREE_3D: &str = r#"
name = "tree3d"
dimensions = 3
gravity = [0.0, -9.81, 0.0]
[base]
direction = [1.0, 0.0, 0.0]
[[segment]]
method = "rigid"
length = 0.4
mass = 0.3
outer_radius = 0.01
elements = 1
joint_stiffness = 0.0
joint_axes = ["z", "y", "x"]
"#;

const LOOP_3D: &str = r#"
name = "loop3d"
dimensions = 3
gravity = [0.0, -9.81, 0.0]
[[body]]
name = "rod"
shape = "cylinder"
radius = 0.01
length = 0.4
mass = 0.3
position = [0.17551651237807456, 0.0, -0.09588510772084060]
orientation = [0.9689124217106447, 0.0, 0.24740395925452294, 0.0]
[[joint]]
name = "socket"
kind = "pin"
a = "world"
b = "rod"
offset_b = [-0.2, 0.0, 0.0]
"#;

#[test]
fn a_3d_pendulum_on_quaternions_swings_as_the_tree() {
    // The body starts where the tree's link is at (theta_z, theta_y) =
    // (0, 0.5): centre R (L/2, 0, 0), R = Ry(0.5).
    let half: f64 = 0.25;
    assert!((half.cos() - 0.9689124217106447).abs() < 1e-15);
    assert!((0.2 * 0.5f64.cos() - 0.17551651237807456).abs() < 1e-15);
    let dir = tempfile::tempdir().unwrap();
    let tree = load_text(dir.path(), TREE_3D, &[]);
    let dir2 = tempfile::tempdir().unwrap();
    let body = load_text(dir2.path(), LOOP_3D, &[]);
    assert_eq!(
        body.arm.info().constraints,
        ["socket.x", "socket.y", "socket.z", "rod.unit"]
    );
    let opts = SimOptions {
        t_end: 2.0,
        output_dt: 0.05,
        rtol: 1e-10,
        atol: 1e-12,
        solver: Solver::Dopri5,
        ..SimOptions::default()
    };
    let n_tree = tree.arm.dof();
    let mut x_tree = vec![0.0; 2 * n_tree];
    x_tree[1] = 0.5;
    let (a, _) = simulate(&*tree.arm, x_tree, &opts).unwrap();
    let (b, stats) = simulate(&*body.arm, start(&body), &opts).unwrap();
    let centre = ["rod.x", "rod.y", "rod.z"].map(|c| coordinate(&body, c));
    let mut swing: f64 = 0.0;
    for ((t, xa), xb) in a.t.iter().zip(&a.x).zip(&b.x) {
        let tip = tree.arm.outputs(*t, &xa[..n_tree], &xa[n_tree..]);
        for c in 0..3 {
            assert_abs(xb[centre[c]], 0.5 * tip[c], 2e-8, "centre");
        }
        swing = swing.max((xb[centre[1]]).abs());
    }
    assert!(swing > 0.1, "it swings: {swing}");
    let c = stats.constraints.unwrap();
    assert!(c.drift_max_m < 1e-9 && c.drift_max_rad < 1e-9, "{c:?}");
}

/// A free box (distinct principal moments) spinning without gravity or
/// joints: its kinetic energy and its angular momentum in the world,
/// L = R diag(I) R^T w, are constants of the motion.
#[test]
fn a_free_body_keeps_its_energy_and_angular_momentum() {
    let text = r#"
name = "tumbling"
dimensions = 3
gravity = [0.0, 0.0, 0.0]
[[body]]
name = "brick"
shape = "box"
size = [0.3, 0.2, 0.1]
mass = 2.0
orientation = [1.0, 0.2, -0.3, 0.1]
"#;
    let dir = tempfile::tempdir().unwrap();
    let l = load_text(dir.path(), text, &[]);
    let n = l.arm.dof();
    assert_eq!(n, 7);
    let mut x0 = start(&l);
    // Spinning mostly about the intermediate axis (the unstable one): the
    // body tumbles. q' = (1/2) (0, w) q for a world angular velocity w.
    let w = [0.3, 5.0, 0.2];
    let q = [x0[3], x0[4], x0[5], x0[6]];
    let qd = [
        -0.5 * (w[0] * q[1] + w[1] * q[2] + w[2] * q[3]),
        0.5 * (w[0] * q[0] + w[1] * q[3] - w[2] * q[2]),
        0.5 * (-w[0] * q[3] + w[1] * q[0] + w[2] * q[1]),
        0.5 * (w[0] * q[2] - w[1] * q[1] + w[2] * q[0]),
    ];
    x0[n + 3..n + 7].copy_from_slice(&qd);
    let opts = SimOptions {
        t_end: 5.0,
        output_dt: 0.05,
        rtol: 1e-11,
        atol: 1e-13,
        solver: Solver::Dopri5,
        ..SimOptions::default()
    };
    let (traj, stats) = simulate(&*l.arm, x0, &opts).unwrap();
    let (m, s) = (2.0, [0.09, 0.04, 0.01]);
    let moments = [
        m * (s[1] + s[2]) / 12.0,
        m * (s[0] + s[2]) / 12.0,
        m * (s[0] + s[1]) / 12.0,
    ];
    let momentum = |x: &[f64]| -> [f64; 3] {
        let (q, qd) = (&x[3..7], &x[n + 3..n + 7]);
        // w = 2 (qw u' - qw' u + u x u')
        let (u, du) = ([q[1], q[2], q[3]], [qd[1], qd[2], qd[3]]);
        let cross = [
            u[1] * du[2] - u[2] * du[1],
            u[2] * du[0] - u[0] * du[2],
            u[0] * du[1] - u[1] * du[0],
        ];
        let w: Vec<f64> = (0..3)
            .map(|c| 2.0 * (q[0] * du[c] - qd[0] * u[c] + cross[c]))
            .collect();
        // Columns of R: the body axes in the world.
        let r = |v: [f64; 3]| -> [f64; 3] {
            let uv = [
                u[1] * v[2] - u[2] * v[1],
                u[2] * v[0] - u[0] * v[2],
                u[0] * v[1] - u[1] * v[0],
            ];
            let uuv = [
                u[1] * uv[2] - u[2] * uv[1],
                u[2] * uv[0] - u[0] * uv[2],
                u[0] * uv[1] - u[1] * uv[0],
            ];
            std::array::from_fn(|c| v[c] + 2.0 * (q[0] * uv[c] + uuv[c]))
        };
        let mut l = [0.0; 3];
        for (k, &i_k) in moments.iter().enumerate() {
            let mut e = [0.0; 3];
            e[k] = 1.0;
            let a = r(e);
            let aw: f64 = (0..3).map(|c| a[c] * w[c]).sum();
            for c in 0..3 {
                l[c] += i_k * aw * a[c];
            }
        }
        l
    };
    let l0 = momentum(&traj.x[0]);
    let scale = l0.iter().map(|v| v * v).sum::<f64>().sqrt();
    let e0 = l.arm.outputs(0.0, &traj.x[0][..n], &traj.x[0][n..])[3];
    let axis = coordinate(&l, "brick.qx");
    let mut turned: f64 = 0.0;
    for (t, x) in traj.t.iter().zip(&traj.x) {
        let lt = momentum(x);
        for c in 0..3 {
            assert_abs(lt[c], l0[c], 1e-8 * scale, "angular momentum");
        }
        let e = l.arm.outputs(*t, &x[..n], &x[n..])[3];
        assert_abs(e, e0, 1e-8 * e0, "kinetic energy");
        turned = turned.max((x[axis] - traj.x[0][axis]).abs());
    }
    assert!(turned > 0.5, "the brick tumbles: {turned}");
    assert!(stats.constraints.unwrap().drift_max_rad < 1e-9);
}

/// The held ball in 3D: the arm (3D pcc, bending both ways) welded to a
/// free 3D ball sinks as the clamped beam, and the weld's moment on the
/// ball is zero (its centre at the tip).
#[test]
fn a_ball_welded_to_a_3d_cantilever_sinks_as_the_clamped_beam() {
    let text = HELD_BALL
        .replace(
            "name = \"held_ball\"",
            "name = \"held_ball_3d\"\ndimensions = 3",
        )
        .replace(
            "bending_stiffness = 0.6",
            "bending_stiffness = 0.6\ntwist = false",
        );
    let dir = tempfile::tempdir().unwrap();
    let l = load_text(dir.path(), &text, &[]);
    let n = l.arm.dof();
    let mut q0 = vec![0.0; n];
    q0[coordinate(&l, "ball.x")] = 0.6;
    q0[coordinate(&l, "ball.qw")] = 1.0;
    let by = coordinate(&l, "ball.y");
    let mut arm = l.arm;
    let sol = runtime::solve_static(&mut *arm, &q0, &runtime::StaticOptions::default()).unwrap();
    let (g, ei, len, w, p): (f64, f64, f64, f64, f64) = (0.01, 0.6, 0.6, 2.5 / 0.6, 1.0);
    let sag = p * g * len.powi(3) / (3.0 * ei) + w * g * len.powi(4) / (8.0 * ei);
    eprintln!(
        "3D welded ball: sag {:.6e} m, beam theory {sag:.6e} m",
        -sol.q[by]
    );
    assert_close(-sol.q[by], sag, 0.01, 0.0, "tip sag against beam theory");
    let rows = arm.info().constraints.clone();
    let force = |r: &str| sol.lambda[rows.iter().position(|x| x == r).unwrap()];
    assert_close(force("grip.y"), p * g, 1e-9, 0.0, "weld force on the ball");
    for r in ["grip.rx", "grip.ry", "grip.rz"] {
        assert_abs(force(r), 0.0, 1e-12, r);
    }
}

/// Every adaptive solver, explicit or implicit (with the constrained
/// system's Jacobian), runs the pinned rod as the tree swings.
#[test]
fn every_adaptive_solver_holds_the_joints() {
    let dir = tempfile::tempdir().unwrap();
    let tree = load_text(dir.path(), TREE, &[]);
    let dir2 = tempfile::tempdir().unwrap();
    let closed = load_text(dir2.path(), LOOP, &[]);
    let reference = SimOptions {
        t_end: 1.0,
        output_dt: 0.1,
        rtol: 1e-11,
        atol: 1e-13,
        solver: Solver::Dopri5,
        ..SimOptions::default()
    };
    let (a, _) = simulate(&*tree.arm, vec![0.0, 0.0], &reference).unwrap();
    let angle = coordinate(&closed, "rod.angle");
    for solver in [
        Solver::Dopri5,
        Solver::Dop853,
        Solver::Bs23,
        Solver::Radau5,
        Solver::Trbdf2,
        Solver::Bdf,
        Solver::Esdirk,
        Solver::Auto,
    ] {
        let opts = SimOptions {
            rtol: 1e-8,
            atol: 1e-10,
            solver,
            ..reference.clone()
        };
        let (b, stats) = simulate(&*closed.arm, start(&closed), &opts).unwrap();
        assert_eq!(b.t.len(), a.t.len(), "{solver:?}");
        for (xa, xb) in a.x.iter().zip(&b.x) {
            assert_abs(xb[angle], xa[0], 1e-5, &format!("{solver:?} angle"));
        }
        let c = stats.constraints.unwrap();
        assert!(c.drift_max_m < 1e-8, "{solver:?}: {c:?}");
    }
}

/// A compliant base that turns, holding an arm with a tip load and no
/// gravity: in equilibrium the translational spring carries the whole load,
/// k s = F, and the rotational spring the load's moment about the base,
/// k_r rho = M = (tip - base) x F, exactly (rho is parallel to M here, where
/// the left Jacobian of exp is the identity), however far the arm bends.
#[test]
fn a_turning_base_carries_the_moment_of_the_tip_load() {
    // (dimensions, tip force, tip moment)
    let cases: [(u8, [f64; 3], [f64; 3]); 4] = [
        (2, [0.0, 0.4, 0.0], [0.0; 3]),
        (3, [0.0, 0.4, 0.0], [0.0; 3]),
        (3, [0.0, 0.0, -0.4], [0.0; 3]),
        (3, [0.0; 3], [0.05, 0.0, 0.0]),
    ];
    let (k, k_r) = (80.0, 3.0);
    for (dimensions, f, m) in cases {
        // In 3D the arm does not twist: a moment along it is the base's.
        let (z, twist) = if dimensions == 2 {
            (0.0, "")
        } else {
            (0.3, "twist = false")
        };
        let text = format!(
            r#"
name = "sway"
dimensions = {dimensions}
gravity = [0.0, 0.0, 0.0]
[base]
position = [0.1, 0.2, {z}]
direction = [1.0, 0.0, 0.0]
mass = 0.5
stiffness = {k}
damping = 1.0
rotational_stiffness = {k_r}
rotational_damping = 0.2
inertia = 0.01
[[segment]]
method = "pcc"
length = 0.5
mass = 0.4
elements = 4
bending_stiffness = 0.5
bending_damping = 0.01
{twist}
[tip]
force = {f:?}
moment = {m:?}
"#
        );
        let dir = tempfile::tempdir().unwrap();
        let l = load_text(dir.path(), &text, &[]);
        let n = l.arm.dof();
        let mut arm = l.arm;
        let q0 = vec![0.0; n];
        let sol = runtime::solve_static(&mut *arm, &q0, &runtime::StaticOptions::default())
            .unwrap_or_else(|e| panic!("{dimensions}D {f:?} {m:?}: {e}"));
        let at = |name: &str| {
            let coords = &arm.info().coordinates;
            let i = coords.iter().position(|c| c == name);
            i.map_or(0.0, |i| sol.q[i])
        };
        let o = arm.outputs(0.0, &sol.q, &vec![0.0; n]);
        let base = [0.1 + at("base_x"), 0.2 + at("base_y"), z + at("base_z")];
        let d = [o[0] - base[0], o[1] - base[1], o[2] - base[2]];
        let moment = [
            m[0] + d[1] * f[2] - d[2] * f[1],
            m[1] + d[2] * f[0] - d[0] * f[2],
            m[2] + d[0] * f[1] - d[1] * f[0],
        ];
        let what = format!("{dimensions}D, tip force {f:?}, moment {m:?}");
        eprintln!(
            "{what}: base {:?} turn {:?}",
            [at("base_x"), at("base_y"), at("base_z")],
            if dimensions == 2 {
                vec![at("base_angle")]
            } else {
                vec![at("base_rx"), at("base_ry"), at("base_rz")]
            }
        );
        for (c, axis) in ["x", "y", "z"].iter().enumerate().take(dimensions as usize) {
            assert_abs(at(&format!("base_{axis}")), f[c] / k, 1e-10, &what);
        }
        if dimensions == 2 {
            assert_abs(at("base_angle"), moment[2] / k_r, 1e-10, &what);
        } else {
            for (c, axis) in ["x", "y", "z"].iter().enumerate() {
                assert_abs(at(&format!("base_r{axis}")), moment[c] / k_r, 1e-10, &what);
            }
        }
        // The load turns the base visibly: the check is not of zeros.
        let turned = moment.iter().map(|v| (v / k_r).abs()).fold(0.0, f64::max);
        assert!(turned > 1e-3, "{what}: turn {turned}");
    }
}

/// The undamped arm on a base that sways and turns in 3D, released from a
/// twisted, bent start under gravity: the springs of the base exchange
/// energy with the arm and the total is conserved.
#[test]
fn an_undamped_turning_base_keeps_its_energy() {
    let text = r#"
name = "sway"
dimensions = 3
gravity = [0.0, -9.81, 0.0]
[base]
direction = [1.0, 0.0, 0.0]
mass = 0.5
stiffness = 60.0
rotational_stiffness = 2.0
inertia = 0.002
[[segment]]
method = "pcc"
length = 0.5
mass = 0.4
elements = 3
bending_stiffness = 0.3
twist = true
torsional_stiffness = 0.2
outer_radius = 0.02
"#;
    let dir = tempfile::tempdir().unwrap();
    let l = load_text(dir.path(), text, &[]);
    let n = l.arm.dof();
    let mut x0 = vec![0.0; 2 * n];
    for (name, v) in [("base_rx", 0.4), ("base_ry", -0.3), ("base_rz", 0.5)] {
        x0[coordinate(&l, name)] = v;
    }
    x0[n + coordinate(&l, "base_rz")] = 1.0;
    let opts = SimOptions {
        t_end: 1.0,
        output_dt: 0.01,
        rtol: 1e-11,
        atol: 1e-13,
        solver: Solver::Dopri5,
        ..SimOptions::default()
    };
    let (traj, _) = simulate(&*l.arm, x0, &opts).unwrap();
    let outputs: Vec<[f64; 9]> = traj
        .t
        .iter()
        .zip(&traj.x)
        .map(|(t, x)| l.arm.outputs(*t, &x[..n], &x[n..]))
        .collect();
    let energy: Vec<f64> = outputs.iter().map(|o| o[3] + o[4]).collect();
    let scale = outputs.iter().map(|o| o[3]).fold(0.0, f64::max);
    assert!(scale > 0.1, "the arm swings: kinetic energy {scale}");
    let worst = energy
        .iter()
        .map(|e| (e - energy[0]).abs())
        .fold(0.0, f64::max);
    eprintln!("turning base: energy drift {worst:.3e} J of {scale:.3e} J");
    assert!(
        worst < 1e-8 * scale,
        "energy drift {worst:.3e} J of {scale:.3e} J"
    );
}

/// In a model of several arms every arm's tip is in trajectory.csv: the
/// first arm's equals the `Outputs` kernel's tip (a second computation),
/// and each sits where its weld holds it on the ball, 5 cm to either side
/// of the ball's centre (falling_ball's arms mirror each other).
#[test]
fn every_arms_tip_is_in_the_trajectory() {
    let dir = tempfile::tempdir().unwrap();
    let out = softarm(
        &[
            "simulate",
            "falling_ball",
            "--t-end",
            "0.3",
            "--out",
            "o",
            "--quiet",
        ],
        dir.path(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let text = std::fs::read_to_string(dir.path().join("o/trajectory.csv")).unwrap();
    let mut lines = text.lines();
    let names: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |n: &str| {
        names
            .iter()
            .position(|c| *c == n)
            .unwrap_or_else(|| panic!("no column {n} in {names:?}"))
    };
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert!(rows.len() > 10);
    for r in &rows {
        let (bx, by, a) = (r[col("ball.x")], r[col("ball.y")], r[col("ball.angle")]);
        // The welds' points on the ball: -+5 cm along its turned x axis.
        let (cx, cy) = (0.05 * a.cos(), 0.05 * a.sin());
        assert_close(
            r[col("left.tip_x")],
            r[col("tip_x")],
            1e-9,
            1.0,
            "left tip x",
        );
        assert_close(
            r[col("left.tip_y")],
            r[col("tip_y")],
            1e-9,
            1.0,
            "left tip y",
        );
        assert_close(
            r[col("left.tip_x")],
            bx - cx,
            1e-5,
            1.0,
            "left tip on the ball",
        );
        assert_close(
            r[col("left.tip_y")],
            by - cy,
            1e-5,
            1.0,
            "left tip on the ball",
        );
        assert_close(
            r[col("right.tip_x")],
            bx + cx,
            1e-5,
            1.0,
            "right tip on the ball",
        );
        assert_close(
            r[col("right.tip_y")],
            by + cy,
            1e-5,
            1.0,
            "right tip on the ball",
        );
        assert_close(r[col("right.tip_z")], 0.0, 1e-12, 1.0, "in the plane");
    }
}

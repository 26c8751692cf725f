//! A prescribed base motion against closed forms. A rigid link on a
//! translating base feels the inertial force -m a_base at its centre of
//! mass; on a turning base its absolute angle obeys I_O (alpha'' +
//! theta'') = -k theta; a soft arm carried at constant velocity moves as
//! the same arm at rest (Galilean invariance).

use std::f64::consts::PI;

use crate::common::*;

const L: f64 = 0.2;
const M: f64 = 0.05;
const R: f64 = 0.01;
/// The base joint's inertia: m l^2 / 3 plus the section's m r^2 / 4.
const I_O: f64 = M * L * L / 3.0 + M * R * R / 4.0;

/// One rigid link with its joint at the base, free (no spring, no
/// gravity) unless `extra` says otherwise; planar, or 3D with a joint
/// about z.
fn link(dimensions: u8, base: &str, extra: &str) -> String {
    let axes = if dimensions == 3 {
        "joint_axes = [\"z\"]"
    } else {
        ""
    };
    format!(
        r#"
name = "carried"
dimensions = {dimensions}
gravity = [0.0, 0.0, 0.0]
[base]
direction = [1.0, 0.0, 0.0]
{base}
[[segment]]
method = "rigid"
length = {L}
mass = {M}
outer_radius = {R}
elements = 1
joint_stiffness = 0.0
{axes}
{extra}
"#
    )
}

const SHAKE: &str = r#"
[inputs.sx]
kind = "sine"
amplitude = 0.02
frequency = 3.0
[inputs.sy]
kind = "sine"
amplitude = 0.01
frequency = 2.0
phase = 30.0
[inputs.still]
kind = "constant"
value = 0.0
"#;

/// d^2/dt^2 of a sin(2 pi f t + phase).
fn sine_accel(a: f64, f: f64, phase_deg: f64, t: f64) -> f64 {
    let w = 2.0 * PI * f;
    -a * w * w * (w * t + phase_deg.to_radians()).sin()
}

#[test]
fn a_link_on_a_shaken_base_feels_minus_m_a_at_its_centre_of_mass() {
    let dir = tempfile::tempdir().unwrap();
    for dimensions in [2, 3] {
        let inputs = if dimensions == 3 {
            r#"translation_inputs = ["sx", "sy", "still"]"#
        } else {
            r#"translation_inputs = ["sx", "sy"]"#
        };
        let l = load_text(dir.path(), &link(dimensions, inputs, SHAKE), &[]);
        for (t, theta, rate) in [(0.03, 0.4, -2.0), (0.11, -1.2, 0.5), (0.4, 2.5, 3.0)] {
            let (ax, ay) = (
                sine_accel(0.02, 3.0, 0.0, t),
                sine_accel(0.01, 2.0, 30.0, t),
            );
            // Moment about the joint of -m a at (l/2)(cos, sin).
            let (c, s) = (f64::cos(theta), f64::sin(theta));
            let want = -M * (L / 2.0) * (c * ay - s * ax) / I_O;
            let got = accelerations(&l, t, &[theta], &[rate])[0];
            assert_close(
                got,
                want,
                1e-10,
                1e-12,
                format_args!("{dimensions}D theta'' at t = {t}"),
            );
        }
    }
}

#[test]
fn a_link_on_a_turning_base_keeps_its_absolute_angle_against_its_spring() {
    // I_O (alpha'' + theta'') = -k theta, whatever the base's turn rate.
    let dir = tempfile::tempdir().unwrap();
    let k = 0.3;
    let turn = r#"
[inputs.turn]
kind = "sine"
amplitude = 0.5
frequency = 1.5
phase = 10.0
[inputs.turn2]
kind = "sine"
amplitude = 0.2
frequency = 0.7
"#;
    // In 3D also as two turns about z (the second after the first): the
    // angles add.
    let cases = [
        (2, "rotation_inputs = [\"turn\"]"),
        (
            3,
            "rotation_inputs = [\"turn\"]\nrotation_axes = [[0.0, 0.0, 2.0]]",
        ),
        (
            3,
            "rotation_inputs = [\"turn\", \"turn2\"]\nrotation_axes = [[0.0, 0.0, 1.0], [0.0, 0.0, 3.0]]",
        ),
    ];
    for (dimensions, base) in cases {
        let l = load_text(
            dir.path(),
            &link(dimensions, base, turn),
            &[&format!("segment.0.joint_stiffness={k}")],
        );
        let two = base.contains("turn2");
        for (t, theta, rate) in [(0.05, 0.3, 1.0), (0.5, -0.8, -4.0)] {
            let mut alpha_dd = sine_accel(0.5, 1.5, 10.0, t);
            if two {
                alpha_dd += sine_accel(0.2, 0.7, 0.0, t);
            }
            let want = -k * theta / I_O - alpha_dd;
            let got = accelerations(&l, t, &[theta], &[rate])[0];
            assert_close(
                got,
                want,
                1e-10,
                1e-12,
                format_args!("{dimensions}D ({base}) theta'' at t = {t}"),
            );
        }
    }
}

#[test]
fn base_turns_compose_in_sequence_about_the_turned_axes() {
    // Yaw 90 degrees about z, then pitch 90 degrees about the turned y:
    // Rz(90) Ry(90) takes the arm's +x to -z. A straight arm without loads
    // stays straight, so its tip is L below the base.
    let dir = tempfile::tempdir().unwrap();
    let base = r#"position = [0.1, 0.2, 0.3]
rotation_inputs = ["yaw", "pitch"]"#;
    let inputs = r#"
[inputs.yaw]
kind = "constant"
value = 1.5707963267948966
[inputs.pitch]
kind = "constant"
value = 1.5707963267948966
"#;
    let l = load_text(dir.path(), &link(3, base, inputs), &[]);
    let o = l.arm.outputs(0.0, &[0.0], &[0.0]);
    for (k, want) in [0.1, 0.2, 0.3 - L].into_iter().enumerate() {
        assert_close(o[k], want, 1e-12, 1e-15, format_args!("tip component {k}"));
    }
}

#[test]
fn a_soft_arm_carried_at_constant_velocity_moves_as_at_rest() {
    // Galilean invariance: a ramp (constant velocity, zero acceleration)
    // changes no acceleration of a 3D pcc arm under gravity, and the tip
    // output moves with the base.
    let dir = tempfile::tempdir().unwrap();
    let arm = |base: &str| {
        format!(
            r#"
name = "carried"
dimensions = 3
gravity = [0.0, -9.81, 0.0]
[base]
direction = [1.0, 0.0, 0.0]
{base}
[[segment]]
method = "pcc"
length = 0.3
elements = 3
density = 1000.0
outer_radius = 0.01
youngs_modulus = 1e6
[inputs.slide]
kind = "ramp"
from = 0.0
to = 0.5
start = 0.0
end = 10.0
[inputs.still]
kind = "constant"
value = 0.0
"#
        )
    };
    let still = load_text(dir.path(), &arm(""), &[]);
    let carried = load_text(
        dir.path(),
        &arm(r#"translation_inputs = ["slide", "still", "slide"]"#),
        &[],
    );
    let n = still.arm.dof();
    let mut rng = Rng::new(11);
    let names = still.arm.info().coordinates.clone();
    for t in [1.0, 4.0] {
        let q = rng.coordinates(&names, -0.5, 0.5);
        let qd = rng.vec(n, -1.0, 1.0);
        let (a, b) = (
            accelerations(&still, t, &q, &qd),
            accelerations(&carried, t, &q, &qd),
        );
        for i in 0..n {
            assert_close(b[i], a[i], 1e-10, 1e-9, format_args!("qdd[{i}] at t = {t}"));
        }
        let (oa, ob) = (
            still.arm.outputs(t, &q, &qd),
            carried.arm.outputs(t, &q, &qd),
        );
        let shift = 0.05 * t;
        assert_close(
            ob[0] - oa[0],
            shift,
            1e-12,
            1e-12,
            "tip x moves with the base",
        );
        assert_close(
            ob[2] - oa[2],
            shift,
            1e-12,
            1e-12,
            "tip z moves with the base",
        );
    }
}

#[test]
fn a_base_accelerating_up_at_g_is_gravity_for_every_method() {
    // The equivalence principle: without gravity, a base whose height
    // follows g t^2 / 2 (a measured-style CSV table: its central
    // differences are exact for a parabola inside the record) gives every
    // method the accelerations that gravity gives it on a still base.
    let dir = tempfile::tempdir().unwrap();
    let g = 9.81;
    let mut csv = String::from("time,height\n");
    for i in 0..=40 {
        let t = 0.05 * f64::from(i);
        csv.push_str(&format!("{t},{}\n", 0.5 * g * t * t));
    }
    std::fs::write(dir.path().join("lift.csv"), csv).unwrap();
    let arm = |method: &str, gravity: f64, base: &str| {
        format!(
            r#"
name = "lifted"
dimensions = 3
gravity = [0.0, {gravity}, 0.0]
[base]
direction = [1.0, 0.0, 0.0]
{base}
[[segment]]
method = "{method}"
length = 0.3
elements = 2
density = 1000.0
outer_radius = 0.01
youngs_modulus = 1e6
[inputs.lift]
kind = "csv"
file = "{}"
column = "height"
[inputs.still]
kind = "constant"
value = 0.0
"#,
            dir.path().join("lift.csv").display()
        )
    };
    let lifted = r#"translation_inputs = ["still", "lift", "still"]"#;
    let methods = (eomgen::method::ALL.iter()).filter(|m| !m.statics_only());
    for method in methods.map(|m| m.name()) {
        let still = load_text(dir.path(), &arm(method, -g, ""), &[]);
        let moving = load_text(dir.path(), &arm(method, 0.0, lifted), &[]);
        let n = still.arm.dof();
        let names = still.arm.info().coordinates.clone();
        let mut rng = Rng::new(5);
        for t in [0.52, 1.23] {
            let q: Vec<f64> = rng.coordinates(&names, -0.3, 0.3);
            let q: Vec<f64> = q.iter().map(|v| 0.2 * v).collect();
            let qd = rng.vec(n, -0.5, 0.5);
            let (a, b) = (
                accelerations(&still, t, &q, &qd),
                accelerations(&moving, t, &q, &qd),
            );
            // The table's second differences are g to its samples'
            // rounding (3e-15 of it at t = 1.23), which a pcc arm's M,
            // conditioned about 1e5 by its twist's small inertia, makes
            // 1e-9 of qdd: the flat tapes and the link cells of the same
            // still arm differ by 5e-10 there.
            for i in 0..n {
                assert_close(
                    b[i],
                    a[i],
                    1e-8,
                    1e-9,
                    format_args!("{method}: qdd[{i}] ({}) at t = {t}", names[i]),
                );
            }
        }
    }
}

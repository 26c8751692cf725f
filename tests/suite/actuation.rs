//! Actuators and measured inputs against closed forms: a pressurised
//! chamber and a pulled tendon bend a one-element arm into the arc of
//! curvature M / (E I) away from (towards) them, a slack tendon pulls
//! nothing, inputs drive parameters exactly as constants do, the measured
//! tip transform removes a turning sensor offset, and the STIFF-FLOP run
//! beats TMTDyn's best published tip error.

use std::f64::consts::PI;
use std::path::Path;

use crate::common::*;
use eomgen::model::{Compare, Override};
use runtime::{StaticOptions, solve_static};
use softarm::backend::{BackendChoice, load};
use softarm::compare::{measured, tip_error};

const L: f64 = 0.1;
const E: f64 = 1e6;
const R: f64 = 0.01;

fn arm(body: &str) -> String {
    format!(
        r#"
name = "actuated"
dimensions = 3
gravity = [0.0, 0.0, 0.0]
[base]
direction = [1.0, 0.0, 0.0]
{body}
"#
    )
}

fn segment(length: f64, extra: &str) -> String {
    format!(
        r#"
[[segment]]
method = "pcc"
length = {length}
elements = 1
density = 1000.0
outer_radius = {R}
youngs_modulus = {E}
{extra}
"#
    )
}

/// An untwisting one-segment arm with chambers at `angles` (degrees) of
/// `radius` (a TOML number or list) at `distance`, every position at the
/// constant pressure `p`.
fn chambered(angles: &str, radius: &str, distance: &str, p: f64) -> String {
    let n = angles.split(',').count();
    let inputs = vec!["\"p\""; n].join(", ");
    arm(&(segment(L, "twist = false")
        + &format!(
            "[segment.chambers]\nangles = [{angles}]\nradius = {radius}\ndistance = {distance}\ninputs = [{inputs}]\n[inputs.p]\nkind = \"constant\"\nvalue = {p}\n"
        )))
}

/// Static tip and coordinates of a model file written to `dir`.
fn static_tip(dir: &Path, text: &str, sets: &[&str]) -> ([f64; 3], Vec<f64>) {
    let mut l = load_text(dir, text, sets);
    let n = l.arm.dof();
    let sol = solve_static(&mut *l.arm, &vec![0.0; n], &StaticOptions::default()).unwrap();
    let o = l.arm.outputs(0.0, &sol.q, &vec![0.0; n]);
    ([o[0], o[1], o[2]], sol.q)
}

/// The tip of an arc of length `len` along +x turned by `theta` about the
/// unit axis `n` (normal to x): (len / theta) (sin theta x + (1 - cos theta) n x x).
fn arc(len: f64, theta: f64, n: [f64; 3]) -> [f64; 3] {
    let nx = [0.0, n[2], -n[1]]; // n x e_x
    let (a, b) = (len * theta.sin() / theta, len * (1.0 - theta.cos()) / theta);
    [a + b * nx[0], b * nx[1], b * nx[2]]
}

fn assert_tip(got: [f64; 3], want: [f64; 3], what: &str) {
    for k in 0..3 {
        assert_close(
            got[k],
            want[k],
            1e-9,
            L,
            format_args!("{what}, component {k}"),
        );
    }
}

#[test]
fn one_pressurised_chamber_bends_the_arm_away_from_it_with_curvature_m_over_ei() {
    let dir = tempfile::tempdir().unwrap();
    let (rc, d, p) = (0.002, 0.006, 2.0e5);
    // Three holes (an isotropic section), only the first pressurised, at a
    // skew angle.
    let alpha: f64 = 35.0;
    let text = arm(&(segment(L, "twist = false")
        + &format!(
            r#"
[segment.chambers]
angles = [{alpha}, {}, {}]
radius = {rc}
distance = {d}
inputs = ["p", "none", "none"]
[inputs.p]
kind = "constant"
value = {p}
[inputs.none]
kind = "constant"
value = 0.0
"#,
            alpha + 120.0,
            alpha + 240.0
        )));
    let (tip, _) = static_tip(dir.path(), &text, &[]);
    // Closed form: M = p a r about the section axis normal to the chamber,
    // I of the section with its three holes.
    let a = PI * rc * rc;
    let i = PI * R.powi(4) / 4.0 - 3.0 * (a * rc * rc / 4.0 + a * d * d / 2.0);
    let theta = p * a * d * L / (E * i);
    let al = alpha.to_radians();
    // Chamber direction (0, cos, sin): the bend turns x away from it.
    let n = [0.0, al.sin(), -al.cos()];
    assert_tip(tip, arc(L, theta, n), "pressurised chamber");
    let lateral = tip[1] * al.cos() + tip[2] * al.sin();
    assert!(lateral < 0.0, "bends away from the chamber: {lateral}");
}

/// The standard bending actuator: a planar arm with two opposed chambers
/// (no dummy holes), one pressurised, bends into the arc of curvature
/// M / (E I_z) away from it, I_z less both holes about the bending axis
/// (each at y = +-d: a d^2 each, where an isotropic pattern takes a d^2 / 2);
/// both at one pressure leave it straight.
#[test]
fn two_opposed_chambers_bend_a_planar_arm_with_curvature_m_over_ei() {
    let dir = tempfile::tempdir().unwrap();
    let (rc, d, p) = (0.002, 0.006, 1.0e5);
    let text = format!(
        r#"
name = "bender"
dimensions = 2
gravity = [0.0, 0.0, 0.0]
[base]
direction = [1.0, 0.0, 0.0]
{}
[segment.chambers]
count = 2
radius = {rc}
distance = {d}
inputs = ["p", "none"]
[inputs.p]
kind = "constant"
value = {p}
[inputs.none]
kind = "constant"
value = 0.0
"#,
        segment(L, "")
    );
    let (tip, _) = static_tip(dir.path(), &text, &[]);
    let a = PI * rc * rc;
    let i = PI * R.powi(4) / 4.0 - 2.0 * (a * rc * rc / 4.0 + a * d * d);
    let theta = p * a * d * L / (E * i);
    // The pressurised hole at y = +d: the bend turns x about -z, away.
    assert_tip(tip, arc(L, theta, [0.0, 0.0, -1.0]), "two opposed chambers");
    // Both at the same pressure: their moments cancel, no bend (a planar
    // pcc arm does not stretch).
    let equal = text.replace("inputs = [\"p\", \"none\"]", "inputs = [\"p\", \"p\"]");
    let (tip, _) = static_tip(dir.path(), &equal, &[]);
    assert_tip(tip, [L, 0.0, 0.0], "two chambers at one pressure");
}

/// The same two opposed chambers in 3D: the section is anisotropic (the
/// holes at y = +-d weaken the bend about z by 2 a d^2, about y not at
/// all), one pressurised bends the arm by M / (E I_z) about z; both at
/// one pressure stretch it by 2 p a L / (E A), without a bend; turned to
/// z = +-d they bend it about y by I_y alike; and a tip moment about z
/// meets I_z less the holes' a d^2 only where they sit at y = +-d.
#[test]
fn two_opposed_chambers_in_3d_bend_by_m_over_ei_and_stretch_straight_at_one_pressure() {
    let dir = tempfile::tempdir().unwrap();
    let (rc, d, p) = (0.002, 0.006, 1.0e5);
    let a = PI * rc * rc;
    let ring = PI * R.powi(4) / 4.0;
    let i_across = ring - 2.0 * (a * rc * rc / 4.0 + a * d * d);
    let i_along = ring - 2.0 * (a * rc * rc / 4.0);
    let area = PI * R * R - 2.0 * a;
    for (angles, n, i) in [
        ("[0.0, 180.0]", [0.0, 0.0, -1.0], i_across),
        ("[90.0, 270.0]", [0.0, 1.0, 0.0], i_across),
    ] {
        let text = arm(&(segment(L, "twist = false\nextension = true")
            + &format!(
                r#"
[segment.chambers]
angles = {angles}
radius = {rc}
distance = {d}
inputs = ["p", "none"]
[inputs.p]
kind = "constant"
value = {p}
[inputs.none]
kind = "constant"
value = 0.0
"#
            )));
        // The bend alone (no stretch: the stretch stiffens to nothing).
        let stiff = ["segment.0.axial_stiffness=1e12"];
        let (tip, _) = static_tip(dir.path(), &text, &stiff);
        let theta = p * a * d * L / (E * i);
        assert_tip(
            tip,
            arc(L, theta, n),
            &format!("one of {angles} pressurised"),
        );
        let equal = text.replace("inputs = [\"p\", \"none\"]", "inputs = [\"p\", \"p\"]");
        let (tip, _) = static_tip(dir.path(), &equal, &[]);
        let stretch = 2.0 * p * a * L / (E * area);
        assert_tip(
            tip,
            [L + stretch, 0.0, 0.0],
            &format!("both of {angles} at one pressure"),
        );
        // A moment about z: the holes at y weaken it, those at z do not.
        let (bent, _) = static_tip(dir.path(), &equal, &["tip.moment=[0, 0, 1e-3]"]);
        let theta = 1e-3 * L / (E * if angles.starts_with("[0") { i } else { i_along });
        let want = arc(L + stretch, theta, [0.0, 0.0, 1.0]);
        assert_close(
            bent[1],
            want[1],
            1e-6,
            L,
            format_args!("{angles}: a moment about z"),
        );
    }
}

/// One chamber alone (count = 1) moves the section's centroid away from
/// it, by z_c = -a d / A; the arm bends about its centroid, where its
/// second moment is I_y = (ring - a r^2 / 4 - a d^2) - A z_c^2 and the
/// pressure's lever d - z_c.
#[test]
fn one_chamber_alone_bends_the_arm_about_its_shifted_centroid() {
    let dir = tempfile::tempdir().unwrap();
    let (rc, d, p) = (0.003, 0.005, 1.0e5);
    let text = chambered("90.0", &rc.to_string(), &d.to_string(), p);
    let (tip, _) = static_tip(dir.path(), &text, &[]);
    let a = PI * rc * rc;
    let area = PI * R * R - a;
    let zc = -a * d / area;
    let i_y = PI * R.powi(4) / 4.0 - (a * rc * rc / 4.0 + a * d * d) - area * zc * zc;
    let theta = p * a * (d - zc) * L / (E * i_y);
    // The hole at +z: the bend turns x about +y, towards -z.
    assert_tip(tip, arc(L, theta, [0.0, 1.0, 0.0]), "one chamber");
    assert!(tip[2] < 0.0, "bends away from the chamber: {tip:?}");
    // Without the centroid's shift the lever and I_y differ by 6 % and
    // 12 %: the test tells them apart.
    let naive = p * a * d * L / (E * (PI * R.powi(4) / 4.0 - (a * rc * rc / 4.0 + a * d * d)));
    assert!((naive - theta).abs() > 0.05 * theta, "{naive} {theta}");
}

/// Two opposed chambers of unequal radii (`radius = [r1, r2]`) at one
/// pressure: the larger pushes harder and the section's centroid moves
/// away from it, z_c = -(a1 - a2) d / A; the arm bends about the centroid
/// by the net lever p (a1 (d - z_c) - a2 (d + z_c)) over E I_y, I_y the
/// ring less each hole's own and parallel-axis moments, less A z_c^2.
#[test]
fn two_opposed_chambers_of_unequal_radii_bend_the_arm_away_from_the_larger() {
    let dir = tempfile::tempdir().unwrap();
    let (r1, r2, d, p) = (0.003, 0.002, 0.005, 1.0e5);
    let text = chambered("90.0, 270.0", &format!("[{r1}, {r2}]"), &d.to_string(), p);
    let (tip, _) = static_tip(dir.path(), &text, &[]);
    let (a1, a2) = (PI * r1 * r1, PI * r2 * r2);
    let area = PI * R * R - a1 - a2;
    let zc = -(a1 - a2) * d / area;
    let own = a1 * r1 * r1 / 4.0 + a2 * r2 * r2 / 4.0;
    let i_y = PI * R.powi(4) / 4.0 - own - (a1 + a2) * d * d - area * zc * zc;
    let theta = p * (a1 * (d - zc) - a2 * (d + zc)) * L / (E * i_y);
    assert_tip(tip, arc(L, theta, [0.0, 1.0, 0.0]), "unequal chambers");
    assert!(tip[2] < 0.0, "bends away from the larger chamber: {tip:?}");
}

/// A chamber whose distance from the axis varies along the segment
/// (`distance = [d0, d1]`): at each s the section loses the hole there, so
/// the centroid sits at z_c(s) = -a d(s) / A, I_y(s) about it, and the arm
/// bends by kappa(s) = p a (d(s) - z_c(s)) / (E I_y(s)). Reference: the
/// plane curve of that curvature, theta(s) = int kappa, x = int cos theta,
/// z = -int sin theta, by Simpson's rule in the test. Each element reads
/// its section and lever at its middle: pcc and ebr converge to it at
/// second order, and rom by its slices.
#[test]
fn a_chamber_whose_offset_tapers_bends_the_arm_by_its_local_lever() {
    let dir = tempfile::tempdir().unwrap();
    let (rc, d0, d1, p) = (0.002, 0.007, 0.004, 1.0e5);
    let text = chambered("90.0", &rc.to_string(), &format!("[{d0}, {d1}]"), p);
    let a = PI * rc * rc;
    let area = PI * R * R - a;
    let kappa = |s: f64| {
        let d = d0 + (d1 - d0) * s / L;
        let zc = -a * d / area;
        let i_y = PI * R.powi(4) / 4.0 - (a * rc * rc / 4.0 + a * d * d) - area * zc * zc;
        p * a * (d - zc) / (E * i_y)
    };
    // theta(s) is a cubic-free integral: Simpson on a fine grid, then the
    // position by Simpson again.
    let steps = 2000;
    let h = L / steps as f64;
    let mut theta = vec![0.0; steps + 1];
    for i in 0..steps {
        let s = i as f64 * h;
        theta[i + 1] = theta[i] + h / 6.0 * (kappa(s) + 4.0 * kappa(s + h / 2.0) + kappa(s + h));
    }
    let simpson = |f: &dyn Fn(f64) -> f64| {
        (0..=steps)
            .map(|i| {
                let w = if i == 0 || i == steps {
                    1.0
                } else if i % 2 == 1 {
                    4.0
                } else {
                    2.0
                };
                w * f(theta[i])
            })
            .sum::<f64>()
            * h
            / 3.0
    };
    let want = [simpson(&|t: f64| t.cos()), 0.0, -simpson(&|t: f64| t.sin())];
    // The lever and stiffness differ by half from base to tip.
    assert!(kappa(0.0) > 1.5 * kappa(L), "{} {}", kappa(0.0), kappa(L));
    let err = |method: &str, key: &str, n: usize| {
        let sets = [
            format!("segment.0.method={method}"),
            format!("segment.0.{key}={n}"),
        ];
        let sets: Vec<&str> = sets.iter().map(String::as_str).collect();
        let (tip, _) = static_tip(dir.path(), &text, &sets);
        (0..3)
            .map(|k| (tip[k] - want[k]).powi(2))
            .sum::<f64>()
            .sqrt()
            / L
    };
    for (method, key) in [
        ("pcc", "elements"),
        ("ebr", "elements"),
        ("rom", "quadrature"),
    ] {
        let (coarse, fine) = (err(method, key, 4), err(method, key, 8));
        assert!(
            fine < 1e-4 && fine * 3.5 < coarse,
            "{method}: {coarse:e} of L off at 4, {fine:e} at 8"
        );
    }
}

#[test]
fn a_pulled_tendon_bends_its_segments_towards_it_and_a_slack_one_pulls_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let (dist, beta, t) = (0.008, 200.0f64, 2.0);
    // Two segments; the tendon ends at the first one's end.
    let text = arm(&(segment(L, "twist = false")
        + &segment(L, "twist = false")
        + &format!(
            r#"
[[tendon]]
input = "t"
distance = {dist}
angle = {beta}
end = 0
[inputs.t]
kind = "constant"
value = {t}
"#
        )));
    let (tip, q) = static_tip(dir.path(), &text, &[]);
    let i = PI * R.powi(4) / 4.0;
    let theta = t * dist * L / (E * i);
    let b = beta.to_radians();
    let n = [0.0, -b.sin(), b.cos()];
    // Segment 0 is the arc; segment 1 stays straight along its end tangent.
    let first = arc(L, theta, n);
    let nx = [0.0, n[2], -n[1]];
    let tangent = [theta.cos(), theta.sin() * nx[1], theta.sin() * nx[2]];
    let want: [f64; 3] = std::array::from_fn(|k| first[k] + L * tangent[k]);
    assert_tip(tip, want, "tendon over segment 0");
    assert!(
        q[2].abs() < 1e-12 && q[3].abs() < 1e-12,
        "segment 1 unbent: {q:?}"
    );
    let towards = tip[1] * b.cos() + tip[2] * b.sin();
    assert!(towards > 0.0, "bends towards the tendon: {towards}");
    // A negative command is a slack tendon: the arm stays straight.
    let (tip, q) = static_tip(dir.path(), &text, &["inputs.t.value=-2.0"]);
    assert!(
        q.iter().all(|v| v.abs() < 1e-14),
        "slack tendon pushed: {q:?}"
    );
    assert_tip(tip, [2.0 * L, 0.0, 0.0], "slack tendon");
}

#[test]
fn tip_loads_driven_by_inputs_act_as_the_same_constant_loads() {
    let dir = tempfile::tempdir().unwrap();
    let constant =
        arm(&(segment(L, "") + "[tip]\nforce = [0.0, 0.02, -0.01]\nmoment = [0.0, 0.0, 0.0005]\n"));
    let driven = arm(&(segment(L, "")
        + r#"
[tip]
force_inputs = ["fx", "fy", "fz"]
moment_inputs = ["mx", "my", "mz"]
[inputs.fx]
kind = "constant"
value = 0.0
[inputs.fy]
kind = "step"
before = 0.0
after = 0.02
time = -1.0
[inputs.fz]
kind = "ramp"
from = 0.0
to = -0.02
start = -1.0
end = 1.0
[inputs.mx]
kind = "constant"
value = 0.0
[inputs.my]
kind = "constant"
value = 0.0
[inputs.mz]
kind = "sine"
amplitude = 0.0005
frequency = 0.25
start = -1.0
"#));
    // At t = 0 the step is on, the ramp half way (-0.01) and the sine at
    // its crest (a quarter period after its start).
    let (a, qa) = static_tip(dir.path(), &constant, &[]);
    let (b, qb) = static_tip(dir.path(), &driven, &[]);
    for (x, y) in qa.iter().zip(&qb) {
        assert_close(*x, *y, 1e-10, 1e-9, "coordinates");
    }
    assert_tip(a, b, "driven vs constant");
}

fn quat_z(phi: f64, q0: [f64; 4]) -> [f64; 4] {
    // qz(phi) (x) q0
    let (c, s) = ((phi / 2.0).cos(), (phi / 2.0).sin());
    let [w, x, y, z] = q0;
    [c * w - s * z, c * x - s * y, c * y + s * x, c * z + s * w]
}

#[test]
fn measured_tip_transform_removes_a_turning_sensor_offset() {
    let dir = tempfile::tempdir().unwrap();
    // The tip point moves along +y by 2 mm/s while the tip turns about z
    // by 0.5 rad/s; the marker sits s = 10 mm along the initial x, turning
    // with the tip; the base marker is at (5, 6, 7) mm.
    let q0 = {
        let v: [f64; 4] = [0.3, -0.5, 0.7, 0.2];
        let n = v.iter().map(|x| x * x).sum::<f64>().sqrt();
        v.map(|x| x / n)
    };
    let mut csv = String::from("time,X,Y,Z,X1,Y1,Z1,QW,QX,QY,QZ\n");
    for i in 0..=20 {
        let t = 0.1 * i as f64;
        let phi = 0.5 * t;
        let p = [1.0, 2.0 + 2.0 * t, 40.0];
        let m = [
            5.0 + p[0] + 10.0 * phi.cos(),
            6.0 + p[1] + 10.0 * phi.sin(),
            7.0 + p[2],
        ];
        let q = quat_z(phi, q0);
        csv.push_str(&format!(
            "{t},5,6,7,{},{},{},{},{},{},{}\n",
            m[0], m[1], m[2], q[0], q[1], q[2], q[3]
        ));
    }
    std::fs::write(dir.path().join("m.csv"), csv).unwrap();
    let spec: Compare = toml::from_str(
        r#"
file = "m.csv"
position = ["X1", "Y1", "Z1"]
reference = ["X", "Y", "Z"]
scale = 1.0e-3
orientation = ["QW", "QX", "QY", "QZ"]
sensor_offset = [0.010, 0.0, 0.0]
"#,
    )
    .unwrap();
    let initial = [0.0, 0.0, 0.05];
    let m = measured(&spec, dir.path(), initial).unwrap();
    for (t, p) in m.t.iter().zip(&m.tip) {
        let want = [0.0, 0.002 * t, 0.05];
        for k in 0..3 {
            assert_close(
                p[k],
                want[k],
                1e-12,
                1e-3,
                format_args!("t = {t}, component {k}"),
            );
        }
    }
    // The error statistics of a constant offset are that offset.
    let e = tip_error(&m, [0.5, 1.5], 0.1, |t| {
        let p = m.tip[m.t.iter().position(|x| (x - t).abs() < 1e-12).unwrap()];
        Some([p[0] + 0.003, p[1] - 0.004, p[2]])
    })
    .unwrap();
    assert_eq!(e.samples, 11);
    for v in [e.mean_m, e.rms_m, e.max_m] {
        assert_close(v, 0.005, 1e-12, 0.0, "constant 5 mm offset");
    }
    assert_close(e.mean_percent_length, 5.0, 1e-12, 0.0, "percent of 0.1 m");
}

#[test]
fn stiff_flop_from_its_recorded_pressures_beats_tmtdyns_best_tip_error() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let o = softarm(
        &["simulate", "stiff_flop", "--out", out.to_str().unwrap()],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let e = &s["tip_error"];
    assert_eq!(e["window_s"][0].as_f64(), Some(7.0));
    let mean = e["mean_m"].as_f64().unwrap();
    // TMTDyn's best on this data set: 2.57 mm (series rigid links).
    assert!(mean < 2.57e-3, "mean tip error {mean} m");
    assert!(out.join("tip.png").exists() && out.join("tip.svg").exists());
}

#[test]
fn stiff_flop_takes_a_measured_tip_wrench_by_swapping_in_a_data_file() {
    // A load cell record (tip frame) of 0.5 N along the tip axis: the
    // straight arm hanging under gravity stretches by a further F L / (E A).
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("loads.csv");
    std::fs::write(
        &csv,
        "time,Fx,Fy,Fz,Mx,My,Mz\n0,0.5,0,0,0,0,0\n1,0.5,0,0,0,0,0\n",
    )
    .unwrap();
    let tip_z = |sets: &[String]| {
        let overrides: Vec<Override> = sets.iter().map(|s| Override::parse(s).unwrap()).collect();
        let mut l = load(
            "stiff_flop",
            &overrides,
            BackendChoice::Auto,
            Some(dir.path().join("cache")),
        )
        .unwrap();
        assert_eq!(
            l.arm.backend(),
            "compiled",
            "an input swap needs no rebuild"
        );
        let n = l.arm.dof();
        let sol = solve_static(&mut *l.arm, &vec![0.0; n], &StaticOptions::default()).unwrap();
        l.arm.outputs(0.0, &sol.q, &vec![0.0; n])
    };
    let free = tip_z(&[]);
    let loaded = tip_z(&[format!(
        "inputs.fx={{kind = \"csv\", file = \"{}\", column = \"Fx\"}}",
        csv.display()
    )]);
    let (ro, ri, rc) = (0.0125f64, 0.0045f64, 0.0025f64);
    let ea = 1.2e5 * PI * (ro * ro - ri * ri - 6.0 * rc * rc);
    assert_close(loaded[2] - free[2], 0.5 * 0.044 / ea, 1e-9, 0.0, "stretch");
    assert!(
        free[0].abs() < 1e-12 && loaded[1].abs() < 1e-12,
        "stays straight"
    );
}

#[test]
fn joint_torques_bend_a_soft_element_and_spin_a_rigid_link_as_closed_forms_say() {
    let dir = tempfile::tempdir().unwrap();
    // A generalised force on a pcc element's bending angle is a moment at
    // its end: the arc of curvature tau / (E I), about z and about y.
    let tau = 2e-4;
    let text = arm(&(segment(L, "twist = false")
        + r#"
[[torque]]
coordinate = "bend_z_0_0"
input = "tau"
[inputs.tau]
kind = "constant"
value = 2e-4
"#));
    let ei = E * PI * R.powi(4) / 4.0;
    let (tip, _) = static_tip(dir.path(), &text, &[]);
    assert_tip(tip, arc(L, tau * L / ei, [0.0, 0.0, 1.0]), "torque about z");
    let (tip, _) = static_tip(dir.path(), &text, &["torque.0.coordinate=bend_y_0_0"]);
    assert_tip(tip, arc(L, tau * L / ei, [0.0, 1.0, 0.0]), "torque about y");

    // A free rigid link (planar, joint at its base, no gravity or spring)
    // under a sine torque: theta'' = tau(t) / (m l^2 / 3 + m r^2 / 4).
    let (l, m, r) = (0.2, 0.05, 0.01);
    let link = format!(
        r#"
name = "link"
gravity = [0.0, 0.0, 0.0]
[base]
direction = [1.0, 0.0, 0.0]
[[segment]]
method = "rigid"
length = {l}
mass = {m}
outer_radius = {r}
elements = 1
joint_stiffness = 0.0
[[torque]]
coordinate = "theta_0_0"
input = "drive"
[inputs.drive]
kind = "sine"
amplitude = 0.03
frequency = 2.0
"#
    );
    let loaded = load_text(dir.path(), &link, &[]);
    let inertia = m * l * l / 3.0 + m * r * r / 4.0;
    for t in [0.05, 0.1, 0.3] {
        let qdd = accelerations(&loaded, t, &[0.7], &[-1.1]);
        let want = 0.03 * (2.0 * PI * 2.0 * t).sin() / inertia;
        assert_close(qdd[0], want, 1e-12, 0.0, format_args!("theta'' at t = {t}"));
    }
}

/// R(q) of a unit quaternion (w, x, y, z).
fn rotation_of(q: [f64; 4]) -> [[f64; 3]; 3] {
    let [w, x, y, z] = q;
    [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ]
}

fn transpose_times(r: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| (0..3).map(|k| r[k][i] * v[k]).sum())
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn toml3(v: [f64; 3]) -> String {
    format!("[{:e}, {:e}, {:e}]", v[0], v[1], v[2])
}

/// One physical load on a bent 3D arm, given three ways: in the world
/// frame (a force W and a moment M at the tip point), in the tip frame
/// (R_tip^T W, R_tip^T M, at the equilibrium's tip orientation), and as a
/// load cell's reading in a sensor frame turned on the tip (axes
/// ["z", "x", "y"], or a quaternion) and offset from it (the force acts at
/// the sensor's origin, so its reading's moment is the tip moment less
/// r x F): all three have the same equilibrium, to 1e-12, constant or
/// driven by input channels (a weighted sum of the six channels).
#[test]
fn a_load_in_the_world_the_tip_and_a_sensor_frame_bends_the_arm_alike() {
    let dir = tempfile::tempdir().unwrap();
    let seg = segment(L, "twist = true");
    let (w, m_w) = ([0.01, 0.03, -0.02], [0.0004, -0.0002, 0.0006]);
    let world = arm(&format!(
        "{seg}[tip]\nforce = {}\nmoment = {}\n",
        toml3(w),
        toml3(m_w)
    ));
    let mut l = load_text(dir.path(), &world, &[]);
    let n = l.arm.dof();
    let sol = solve_static(&mut *l.arm, &vec![0.0; n], &StaticOptions::default()).unwrap();
    let o = l.arm.outputs(0.0, &sol.q, &vec![0.0; n]);
    let tip_w = [o[0], o[1], o[2]];
    let r_tip = rotation_of([o[5], o[6], o[7], o[8]]);
    let (f_t, m_t) = (transpose_times(&r_tip, w), transpose_times(&r_tip, m_w));
    // The sensor: its x along the tip's z, y along the tip's x, z along
    // the tip's y; its origin 2 cm along the tip's axis, 1 cm aside.
    let r_s = [[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]];
    let offset = [0.02, 0.01, 0.0];
    let f_s = transpose_times(&r_s, f_t);
    let m_s = transpose_times(
        &r_s,
        std::array::from_fn(|i| m_t[i] - cross(offset, f_t)[i]),
    );
    // The same rotation as a quaternion: -120 degrees about (1, 1, 1).
    let h = 0.5;
    let tip = format!(
        "{seg}[tip]\nwrench_frame = \"tip\"\nforce = {}\nmoment = {}\n",
        toml3(f_t),
        toml3(m_t)
    );
    let sensor = |rotation: &str| {
        format!(
            "{seg}[tip]\nsensor_rotation = {rotation}\nsensor_offset = {}\nforce = {}\nmoment = {}\n",
            toml3(offset),
            toml3(f_s),
            toml3(m_s)
        )
    };
    let channels = |v: [f64; 3], names: [&str; 3]| -> String {
        (0..3)
            .map(|k| {
                format!(
                    "[inputs.{}]\nkind = \"constant\"\nvalue = {:e}\n",
                    names[k], v[k]
                )
            })
            .collect()
    };
    let driven = format!(
        "{seg}[tip]\nsensor_rotation = [\"z\", \"x\", \"y\"]\nsensor_offset = {}\nforce_inputs = [\"fx\", \"fy\", \"fz\"]\nmoment_inputs = [\"mx\", \"my\", \"mz\"]\n{}{}",
        toml3(offset),
        channels(f_s, ["fx", "fy", "fz"]),
        channels(m_s, ["mx", "my", "mz"]),
    );
    for (what, text) in [
        ("tip frame", arm(&tip)),
        ("sensor axes", arm(&sensor("[\"z\", \"x\", \"y\"]"))),
        (
            "sensor quaternion",
            arm(&sensor(&format!("[{h}, -{h}, -{h}, -{h}]"))),
        ),
        ("sensor channels", arm(&driven)),
    ] {
        let (tip_pos, q) = static_tip(dir.path(), &text, &[]);
        eprintln!("{what}: tip {tip_pos:?} against {tip_w:?}");
        for k in 0..3 {
            assert_close(
                tip_pos[k],
                tip_w[k],
                1e-12,
                L,
                format_args!("{what}: tip {k}"),
            );
        }
        for (a, b) in q.iter().zip(&sol.q) {
            assert_close(*a, *b, 1e-10, 1e-6, format_args!("{what}: coordinates"));
        }
    }
}

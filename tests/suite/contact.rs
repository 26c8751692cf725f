//! Contact against independent references: a sphere dropped on a plane
//! rebounds with the coefficient of restitution it was given (the exact
//! Hunt-Crossley damping law); a Hertz contact settles at its static depth
//! (m g / k)^(1/n); a block on an incline slides with g (sin a - mu cos a)
//! or creeps at the regularised law's closed-form speed; the contact
//! forces' analytic Jacobian against central differences.

use crate::common::*;
use runtime::contact::Distance;
use runtime::{SimOptions, Solver, simulate};

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

/// A 0.2 kg ball of radius 5 cm above a floor at y = 0, and `contact`.
fn ball_on_floor(gravity: f64, height: f64, contact: &str) -> String {
    format!(
        r#"
name = "drop"
gravity = [0.0, {gravity}, 0.0]
[[body]]
name = "ball"
shape = "sphere"
radius = 0.05
mass = 0.2
position = [0.0, {height}, 0.0]
[[obstacle]]
name = "floor"
shape = "plane"
point = [0.0, 0.0, 0.0]
normal = [0.0, 1.0, 0.0]
[contact]
{contact}
"#
    )
}

/// Without gravity the ball meets the floor at 1 m/s and leaves it at e
/// m/s: the Hunt-Crossley damping solved from e (a (1 + e) - ln(1 + a) +
/// ln(1 - a e) = 0, a = alpha v_in) makes that exact, not a first-order
/// approximation; the contact switches (touch, release) are located on
/// the dense output and carry the velocities.
#[test]
fn a_ball_rebounds_with_the_restitution_it_was_given() {
    for e in [0.2, 0.5, 0.9] {
        let text = ball_on_floor(
            0.0,
            0.1,
            &format!("model = \"hunt_crossley\"\nstiffness = 1e5\nrestitution = {e}"),
        );
        let dir = tempfile::tempdir().unwrap();
        let l = load_text(dir.path(), &text, &[]);
        let n = l.arm.dof();
        let y = coordinate(&l, "ball.y");
        let mut x0 = vec![0.0; 2 * n];
        x0[y] = 0.1;
        x0[n + y] = -1.0;
        let opts = SimOptions {
            t_end: 0.2,
            output_dt: 0.01,
            rtol: 1e-10,
            atol: 1e-12,
            solver: Solver::Radau5,
            ..SimOptions::default()
        };
        let (traj, stats) = simulate(&*l.arm, x0, &opts).unwrap();
        // The energy the contact took: m v_in^2 (1 - e^2) / 2.
        let meter = stats.contact.unwrap();
        let lost = 0.5 * 0.2 * (1.0 - e * e);
        eprintln!(
            "e = {e}: dissipated {:.9} J of {lost:.9} J, deepest {:.6e} m",
            meter.dissipated_j, meter.max_penetration_m
        );
        assert_close(meter.dissipated_j, lost, 1e-5, 0.0, "dissipated energy");
        let switches: Vec<_> = traj.events.iter().filter(|h| h.name == "contact").collect();
        assert!(
            switches.len() >= 2,
            "e = {e}: touch and release, got {switches:?}"
        );
        let (v_in, v_out) = (switches[0].x[n + y], switches[1].x[n + y]);
        let measured = -v_out / v_in;
        eprintln!(
            "e = {e}: touch at {:.6} s ({v_in:.9} m/s), release at {:.6} s ({v_out:.9} m/s): e = {measured:.9}",
            switches[0].t, switches[1].t
        );
        // The switch's state is the dense output's: 1e-7 is its accuracy.
        assert_abs(v_in, -1.0, 1e-7, "impact speed");
        assert_abs(measured, e, 1e-4 * e, "measured restitution");
        // The momentum the floor gave: m (1 + e) |v_in|, the metered
        // integral of the normal force, in summary.json's release.
        let summary = softarm::contact::summary(&*l.arm, &traj, stats.contact);
        let release = &summary["switches"][1];
        assert_eq!(release["kind"], "release", "e = {e}: {summary}");
        let impulse = release["impulse_ns"].as_f64().expect("a release's impulse");
        eprintln!(
            "e = {e}: impulse {impulse:.9} N s of {:.9}",
            0.2 * (1.0 + e)
        );
        assert_close(
            impulse,
            0.2 * (1.0 + e),
            1e-6,
            0.0,
            "impulse of the rebound",
        );
        assert_close(
            meter.normal_impulse_ns,
            0.2 * (1.0 + e),
            1e-6,
            0.0,
            "run's impulse",
        );
    }
}

/// A damped Hertz contact (Hunt-Crossley with its damping given) comes to
/// rest where k delta^n = m g.
#[test]
fn a_hertz_contact_settles_at_its_static_depth() {
    let (k, n_exp, m, g, r) = (1e4, 1.5, 0.2, 9.81, 0.05);
    let text = ball_on_floor(
        -g,
        r,
        &format!("model = \"hunt_crossley\"\nstiffness = {k}\nexponent = {n_exp}\ndamping = 1e5"),
    );
    let dir = tempfile::tempdir().unwrap();
    let l = load_text(dir.path(), &text, &[]);
    let n = l.arm.dof();
    let y = coordinate(&l, "ball.y");
    let mut x0 = vec![0.0; 2 * n];
    x0[y] = r;
    let opts = SimOptions {
        t_end: 3.0,
        output_dt: 0.1,
        rtol: 1e-10,
        atol: 1e-13,
        solver: Solver::Radau5,
        ..SimOptions::default()
    };
    let (traj, _) = simulate(&*l.arm, x0, &opts).unwrap();
    let depth = r - traj.x.last().unwrap()[y];
    let expected = (m * g / k).powf(1.0 / n_exp);
    eprintln!("hertz: depth {depth:.12e} m, (m g / k)^(1/n) = {expected:.12e} m");
    assert_close(depth, expected, 1e-6, 0.0, "static depth");
}

/// A ball set down on the floor at rest, touching it, settles at its
/// static depth, (m g / k)^(1/n), within ten of the contact's natural
/// periods 2 pi sqrt(m / (n k delta^(n-1))), under Hunt-Crossley from a
/// restitution (the case that crept: damped as an impact at 1 mm/s, it
/// was still 6 % short after 3 s), Hunt-Crossley with its damping given
/// and a spring and dashpot. Hertz stores and returns every joule: it
/// oscillates about the depth for ever (not asked to settle).
#[test]
fn a_contact_that_begins_at_rest_settles_within_ten_periods() {
    let (m, g, r) = (0.2, 9.81, 0.05);
    for (law, k, n_exp) in [
        ("model = \"hunt_crossley\"\nrestitution = 0.2", 2e5, 1.5),
        ("model = \"hunt_crossley\"\nrestitution = 0.5", 1e4, 1.5),
        ("model = \"hunt_crossley\"\nrestitution = 0.2", 5e4, 1.0),
        ("model = \"hunt_crossley\"\ndamping = 5e6", 2e5, 1.5),
        ("model = \"spring_dashpot\"\ndamping = 20.0", 2e4, 1.0),
    ] {
        let exponent = match n_exp {
            1.0 if law.contains("spring") => String::new(),
            _ => format!("\nexponent = {n_exp}"),
        };
        let contact = format!("{law}\nstiffness = {k}{exponent}");
        let text = ball_on_floor(-g, r, &contact);
        let dir = tempfile::tempdir().unwrap();
        let l = load_text(dir.path(), &text, &[]);
        let n = l.arm.dof();
        let y = coordinate(&l, "ball.y");
        let mut x0 = vec![0.0; 2 * n];
        x0[y] = r;
        let depth = (m * g / k).powf(1.0 / n_exp);
        let period =
            2.0 * std::f64::consts::PI * (m / (n_exp * k * depth.powf(n_exp - 1.0))).sqrt();
        let opts = SimOptions {
            t_end: 10.0 * period,
            output_dt: period / 4.0,
            rtol: 1e-9,
            atol: 1e-12,
            solver: Solver::Radau5,
            ..SimOptions::default()
        };
        let (traj, _) = simulate(&*l.arm, x0, &opts).unwrap();
        let last = traj.x.last().unwrap();
        let got = r - last[y];
        eprintln!(
            "{contact:?}: depth {got:.6e} m against {depth:.6e} m after 10 periods of {period:.3e} s"
        );
        assert_close(
            got,
            depth,
            0.01,
            0.0,
            format_args!("{contact}: depth after ten periods"),
        );
        // At rest there: the speed a hundredth of the settling scale.
        let scale = depth / period;
        assert!(
            last[n + y].abs() < 0.01 * scale,
            "{contact}: still moving at {} m/s",
            last[n + y]
        );
    }
}

/// A rigid rod pinned at one end, set down horizontal at rest with its tip
/// on a support (Hunt-Crossley from a restitution of 0.2): within ten of
/// the contact's periods (its tip's effective mass m / 3 on the law's
/// stiffness at its depth) it rests where the static solve puts it, and
/// where the moments balance in closed form: the support's k delta^n at
/// the tip, delta = -L sin(theta), against the weight's m g L / 2 and the
/// joint's spring k_j theta (which gives the static solve's load steps a
/// stiffness where the support has none, at zero depth), all times cos
/// theta but the spring's.
#[test]
fn an_arm_set_down_on_a_support_settles_where_the_static_solve_puts_it() {
    let (m, g, len, k, n_exp, k_joint): (f64, f64, f64, f64, f64, f64) =
        (0.3, 9.81, 0.4, 1e5, 1.5, 1.0);
    let law = format!(
        "model = \"hunt_crossley\"\nrestitution = 0.2\nstiffness = {k}\nexponent = {n_exp}"
    );
    let text = rod_on_support(m, g, len, k_joint, &law);
    let dir = tempfile::tempdir().unwrap();
    let l = load_text(dir.path(), &text, &[]);
    // The closed form by bisection on the moment balance (theta < 0).
    let moment = |th: f64| {
        let (s, c) = th.sin_cos();
        k * (-len * s).max(0.0).powf(n_exp) * len * c - m * g * len / 2.0 * c - k_joint * th
    };
    let (mut lo, mut hi) = (-0.1, 0.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if moment(mid) > 0.0 {
            lo = mid
        } else {
            hi = mid
        }
    }
    let angle_closed = 0.5 * (lo + hi);
    let depth = -len * angle_closed.sin();
    let stiffness = n_exp * k * depth.powf(n_exp - 1.0);
    let period = 2.0 * std::f64::consts::PI * (m / 3.0 / stiffness).sqrt();
    let opts = SimOptions {
        t_end: 10.0 * period,
        output_dt: period / 4.0,
        rtol: 1e-9,
        atol: 1e-12,
        solver: Solver::Radau5,
        ..SimOptions::default()
    };
    let mut arm = l.arm;
    let (traj, _) = simulate(&*arm, vec![0.0, 0.0], &opts).unwrap();
    let angle = traj.x.last().unwrap()[0];
    let statics =
        runtime::solve_static(&mut *arm, &[0.0], &runtime::StaticOptions::default()).unwrap();
    eprintln!(
        "rod: angle {angle:.6e} rad after 10 periods of {period:.3e} s; static {:.6e}; closed form {angle_closed:.6e}",
        statics.q[0]
    );
    assert_close(angle, angle_closed, 0.01, 0.0, "angle after ten periods");
    assert_close(angle, statics.q[0], 0.01, 0.0, "the static solve's angle");
    assert_close(statics.q[0], angle_closed, 1e-8, 0.0, "static angle");
}

/// A ball on a plane tilted by a (no rolling: the contact force acts at
/// the sampled point, the centre). Steeper than its friction angle it
/// slides with g (sin a - mu cos a); shallower, the regularised law
/// F_t = -mu F_n v / sqrt(v^2 + v_s^2) lets it creep at the speed where
/// friction balances the slope, v_s t / sqrt(1 - t^2), t = tan a / mu.
#[test]
fn a_ball_on_an_incline_slides_or_creeps_by_coulomb() {
    let (mu, g, r, v_s) = (0.4_f64, 9.81, 0.05, 1e-4);
    for degrees in [35.0_f64, 11.0] {
        let a = degrees.to_radians();
        let (s, c) = a.sin_cos();
        let text = format!(
            r#"
name = "incline"
gravity = [0.0, {gy}, 0.0]
[[body]]
name = "ball"
shape = "sphere"
radius = {r}
mass = 0.2
position = [0.0, {r}, 0.0]
[[obstacle]]
name = "slope"
shape = "plane"
point = [0.0, 0.0, 0.0]
normal = [{nx}, {ny}, 0.0]
[contact]
model = "hunt_crossley"
stiffness = 1e5
damping = 1e6
friction = {mu}
slip_velocity = {v_s}
"#,
            gy = -g,
            nx = -s,
            ny = c,
        );
        let dir = tempfile::tempdir().unwrap();
        let l = load_text(dir.path(), &text, &[]);
        let n = l.arm.dof();
        let (ix, iy) = (coordinate(&l, "ball.x"), coordinate(&l, "ball.y"));
        let mut x0 = vec![0.0; 2 * n];
        // At rest on the surface, at its static depth (m g cos a / k)^(2/3).
        let depth = (0.2 * g * c / 1e5_f64).powf(1.0 / 1.5);
        x0[ix] = -s * (r - depth);
        x0[iy] = c * (r - depth);
        let opts = SimOptions {
            t_end: 1.0,
            output_dt: 0.05,
            rtol: 1e-9,
            atol: 1e-12,
            solver: Solver::Radau5,
            ..SimOptions::default()
        };
        let (traj, _) = simulate(&*l.arm, x0, &opts).unwrap();
        let x = traj.x.last().unwrap();
        // Speed down the slope (along (-c, -s)).
        let v = -(c * x[n + ix] + s * x[n + iy]);
        let t = a.tan() / mu;
        if t > 1.0 {
            let expected = g * (s - mu * c) * 1.0;
            eprintln!(
                "{degrees} degrees: slides at {v:.6} m/s after 1 s, g (sin a - mu cos a) t = {expected:.6}"
            );
            assert_close(v, expected, 0.01, 0.0, "sliding speed");
        } else {
            let creep = v_s * t / (1.0 - t * t).sqrt();
            eprintln!("{degrees} degrees: creeps at {v:.6e} m/s, closed form {creep:.6e}");
            assert_close(v, creep, 0.01, 0.0, "creep speed");
        }
    }
}

/// The analytic Jacobian of the right-hand side with contacts (the
/// `ContactJvp` kernel's turning of J, the laws' derivatives by dual
/// numbers) against central differences of the accelerations, at states
/// where several points of a soft arm press into a plane and a sphere,
/// sliding with friction; planar and 3D.
#[test]
fn the_contact_jacobian_is_the_derivative_of_the_forces() {
    for dimensions in [2, 3] {
        let twist = if dimensions == 3 {
            "torsional_stiffness = 0.3"
        } else {
            ""
        };
        let text = format!(
            r#"
name = "pressed"
dimensions = {dimensions}
gravity = [0.0, -9.81, 0.0]
[base]
direction = [1.0, 0.0, 0.0]
[[segment]]
method = "pcc"
length = 0.4
elements = 3
mass = 0.2
outer_radius = 0.02
bending_stiffness = 0.5
bending_damping = 0.01
{twist}
[[obstacle]]
name = "table"
shape = "plane"
point = [0.0, -0.03, 0.0]
normal = [0.1, 1.0, 0.0]
[[obstacle]]
name = "knob"
shape = "sphere"
center = [0.3, -0.01, 0.0]
radius = 0.04
contact = {{ model = "spring_dashpot", stiffness = 3000.0, damping = 2.0, friction = 0.2 }}
[contact]
model = "hunt_crossley"
stiffness = 2e4
damping = 3e3
friction = 0.5
slip_velocity = 0.05
points_per_element = 2
"#
        );
        let dir = tempfile::tempdir().unwrap();
        let l = load_text(dir.path(), &text, &[]);
        let n = l.arm.dof();
        let mut rng = Rng::new(7 + dimensions as u64);
        let mut x: Vec<f64> = (0..n).map(|_| rng.uniform(-0.25, -0.15)).collect();
        x.extend((0..n).map(|_| rng.uniform(-0.5, 0.5)));
        // Several points press in: the Jacobian has contact terms.
        let set = l.arm.contact().unwrap();
        let forces = runtime::contact::pair_forces(&*l.arm, set, 0.0, &x[..n], &x[n..], false);
        let touching = forces.iter().filter(|f| f.normal > 0.0).count();
        assert!(touching >= 2, "{dimensions}D: {touching} points touch");
        let mut ws = runtime::Workspace::new(n);
        let mut jac = nalgebra::DMatrix::zeros(2 * n, 2 * n);
        runtime::rhs_jacobian(&*l.arm, &mut ws, 0.0, &x, &mut jac).unwrap();
        let h = 1e-6;
        let mut worst: f64 = 0.0;
        let scale = jac.amax();
        for j in 0..2 * n {
            let (mut a, mut b) = (x.clone(), x.clone());
            a[j] += h;
            b[j] -= h;
            let fa = accelerations(&l, 0.0, &a[..n], &a[n..]);
            let fb = accelerations(&l, 0.0, &b[..n], &b[n..]);
            for i in 0..n {
                let fd = (fa[i] - fb[i]) / (2.0 * h);
                worst = worst.max((jac[(n + i, j)] - fd).abs());
            }
        }
        eprintln!(
            "{dimensions}D: {touching} touching, Jacobian vs central differences {worst:.3e} of {scale:.3e}"
        );
        assert!(worst < 1e-6 * scale, "{worst:e} of {scale:e}");
    }
}

/// The chapter's impact stage (`impulse`): without gravity a ball meets
/// the floor at 1 m/s and leaves at e m/s, the jump exact; a glancing hit
/// keeps its tangential velocity when frictionless and loses it when the
/// law has friction (no slip, the chapter's case, held after e = 0).
#[test]
fn an_impulse_reverses_the_normal_velocity_by_e() {
    for (e, friction, vx) in [(0.5, 0.0, 0.0), (0.3, 0.0, 0.7), (0.0, 0.5, 0.7)] {
        let text = ball_on_floor(
            0.0,
            0.1,
            &format!("model = \"impulse\"\nrestitution = {e}\nfriction = {friction}"),
        );
        let dir = tempfile::tempdir().unwrap();
        let l = load_text(dir.path(), &text, &[]);
        let n = l.arm.dof();
        let (ix, iy) = (coordinate(&l, "ball.x"), coordinate(&l, "ball.y"));
        let mut x0 = vec![0.0; 2 * n];
        x0[iy] = 0.1;
        x0[n + iy] = -1.0;
        x0[n + ix] = vx;
        let opts = SimOptions {
            t_end: 0.1,
            output_dt: 0.01,
            rtol: 1e-10,
            atol: 1e-12,
            solver: Solver::Dopri5,
            ..SimOptions::default()
        };
        let (traj, stats) = simulate(&*l.arm, x0, &opts).unwrap();
        let hit = traj
            .events
            .iter()
            .find(|h| h.name == "contact")
            .expect("the ball hits");
        assert_abs(hit.t, 0.05, 1e-9, "time of impact");
        // The jump's normal impulse, m (1 + e) |v_in|, in summary.json.
        let summary = softarm::contact::summary(&*l.arm, &traj, stats.contact);
        let touch = &summary["switches"][0];
        assert_eq!(touch["kind"], "touch", "{summary}");
        let impulse = touch["impulse_ns"]
            .as_f64()
            .expect("an impulse law's impulse");
        assert_abs(impulse, 0.2 * (1.0 + e), 1e-12, "impulse of the jump");
        let last = traj.x.last().unwrap();
        let what = format!("e = {e}, friction {friction}");
        eprintln!(
            "{what}: after the impact v = ({:.12}, {:.12})",
            last[n + ix],
            last[n + iy]
        );
        assert_abs(last[n + iy], e, 1e-9, &format!("{what}: normal velocity"));
        let tangential = if friction > 0.0 { 0.0 } else { vx };
        assert_abs(
            last[n + ix],
            tangential,
            1e-9,
            &format!("{what}: tangential velocity"),
        );
    }
}

/// A rigid rod of mass `m` and length `len` pinned at the origin on a
/// joint spring `k_joint`, pointing along x, gravity `g` down, its tip (one
/// contact point) over a support plane y = 0 under the contact `law`.
fn rod_on_support(m: f64, g: f64, len: f64, k_joint: f64, law: &str) -> String {
    format!(
        r#"
name = "rod"
gravity = [0.0, {gy}, 0.0]
[base]
direction = [1.0, 0.0, 0.0]
[[segment]]
method = "rigid"
length = {len}
mass = {m}
elements = 1
joint_stiffness = {k_joint}
[[obstacle]]
name = "support"
shape = "plane"
point = [0.0, 0.0, 0.0]
normal = [0.0, 1.0, 0.0]
[contact]
{law}
points_per_element = 1
"#,
        gy = -g
    )
}

/// A rigid rod pinned at one end swings down onto a support under its
/// tip: with e = 0 it stops dead at the impact (one freedom, so the whole
/// velocity is normal at the tip) and rests held there, the support
/// carrying half the rod's weight, m g / 2.
#[test]
fn a_rod_struck_on_its_support_stops_and_rests_on_it() {
    let (m, g, len) = (0.3, 9.81, 0.4);
    let text = rod_on_support(m, g, len, 0.0, "model = \"impulse\"\nrestitution = 0.0");
    let dir = tempfile::tempdir().unwrap();
    let l = load_text(dir.path(), &text, &[]);
    let n = l.arm.dof();
    assert_eq!(n, 1);
    // From 0.3 rad up, at rest: the tip falls onto y = 0 (horizontal).
    let x0 = vec![0.3, 0.0];
    let opts = SimOptions {
        t_end: 1.0,
        output_dt: 0.01,
        rtol: 1e-10,
        atol: 1e-12,
        solver: Solver::Radau5,
        ..SimOptions::default()
    };
    let (traj, _) = simulate(&*l.arm, x0, &opts).unwrap();
    let hit = traj
        .events
        .iter()
        .find(|h| h.name == "contact")
        .expect("the rod hits its support");
    let last = traj.x.last().unwrap();
    eprintln!(
        "rod: impact at {:.6} s, at the end angle {:.3e}, rate {:.3e}",
        hit.t, last[0], last[1]
    );
    assert_abs(last[0], 0.0, 1e-9, "rests horizontal");
    assert_abs(last[1], 0.0, 1e-9, "at rest");
    let set = l.arm.contact().unwrap();
    let held = set.held_pairs();
    assert_eq!(held.len(), 1, "held on its support");
    let (_, forces) = runtime::contact::impact::held_accelerations(
        &*l.arm,
        set,
        1.0,
        &last[..n],
        &last[n..],
        &held,
    )
    .unwrap();
    eprintln!(
        "rod: support force {:.12} N, m g / 2 = {:.12} N",
        forces[0],
        m * g / 2.0
    );
    assert_close(forces[0], m * g / 2.0, 1e-9, 0.0, "support force");
    // The recorded output column carries it: zero before the impact, m g / 2
    // once resting (the rod at rest by 0.5 s).
    assert_eq!(traj.contact.len(), traj.t.len(), "a column row per sample");
    for (t, c) in traj.t.iter().zip(&traj.contact) {
        if *t < hit.t - 1e-9 {
            assert_abs(
                c[0],
                0.0,
                0.0,
                &format!("support force before the impact (t = {t})"),
            );
        } else if *t >= 0.5 {
            assert_close(
                c[0],
                m * g / 2.0,
                1e-6,
                0.0,
                format_args!("support force column at {t}"),
            );
        }
    }
}

/// An undamped soft arm swings under gravity onto a table and a knob
/// (Hunt-Crossley, e = 0.5, friction): its energy (kinetic, gravity,
/// bending, and the contacts' elastic energy) never rises, and what it
/// loses is what the contact meter says the contacts dissipated.
#[test]
fn contact_only_takes_energy_and_the_meter_accounts_for_it() {
    let text = r#"
name = "swing"
gravity = [0.0, -9.81, 0.0]
[base]
direction = [1.0, 0.0, 0.0]
[[segment]]
method = "pcc"
length = 0.3
elements = 5
mass = 0.1
outer_radius = 0.01
bending_stiffness = 0.05
[[obstacle]]
name = "table"
shape = "plane"
point = [0.0, -0.12, 0.0]
normal = [0.0, 1.0, 0.0]
[[obstacle]]
name = "knob"
shape = "sphere"
center = [0.15, -0.1, 0.0]
radius = 0.02
[contact]
model = "hunt_crossley"
stiffness = 1e4
restitution = 0.5
friction = 0.3
slip_velocity = 0.01
"#;
    let dir = tempfile::tempdir().unwrap();
    let l = load_text(dir.path(), text, &[]);
    let n = l.arm.dof();
    let opts = SimOptions {
        t_end: 1.0,
        output_dt: 0.002,
        rtol: 1e-10,
        atol: 1e-12,
        solver: Solver::Radau5,
        ..SimOptions::default()
    };
    let (traj, stats) = simulate(&*l.arm, vec![0.0; 2 * n], &opts).unwrap();
    let set = l.arm.contact().unwrap();
    let energy: Vec<f64> = traj
        .t
        .iter()
        .zip(&traj.x)
        .map(|(t, x)| {
            let o = l.arm.outputs(*t, &x[..n], &x[n..]);
            o[3] + o[4] + runtime::contact::potential_energy(&*l.arm, set, *t, &x[..n], &x[n..])
        })
        .collect();
    let scale = traj
        .t
        .iter()
        .zip(&traj.x)
        .map(|(t, x)| l.arm.outputs(*t, &x[..n], &x[n..])[3])
        .fold(0.0, f64::max);
    let rise = energy
        .windows(2)
        .map(|w| w[1] - w[0])
        .fold(f64::NEG_INFINITY, f64::max);
    let meter = stats.contact.unwrap();
    let lost = energy[0] - energy.last().unwrap();
    eprintln!(
        "swing: kinetic up to {scale:.4} J, largest rise {rise:.3e} J, lost {lost:.6e} J, metered {:.6e} J, deepest {:.3e} m",
        meter.dissipated_j, meter.max_penetration_m
    );
    assert!(meter.dissipated_j > 0.1 * scale, "the contacts take energy");
    assert!(rise < 1e-8 * scale, "energy rose by {rise:e} J");
    assert_close(lost, meter.dissipated_j, 1e-5, 0.0, "energy balance");
}

/// A soft arm hanging from a compliant base, its tip pressed onto a table
/// by a tip load, in static equilibrium: the table and the base's spring
/// together carry the whole load (1e-9 relative), and the tip sinks into
/// the table exactly as deep as the law gives for the force it carries,
/// (F_c / k)^(1/n).
#[test]
fn a_tip_load_pressing_on_a_table_is_carried_by_it() {
    let (k_base, k_c, n_exp, load, r) = (100.0, 1e4, 1.5, 2.0, 0.01);
    let text = format!(
        r#"
name = "pressed"
gravity = [0.0, 0.0, 0.0]
[base]
direction = [0.0, -1.0, 0.0]
mass = 0.1
stiffness = {k_base}
damping = 1.0
[[segment]]
method = "pcc"
length = 0.2
elements = 4
mass = 0.05
outer_radius = {r}
bending_stiffness = 0.1
[tip]
force = [0.0, -{load}, 0.0]
[[obstacle]]
name = "table"
shape = "plane"
point = [0.0, -0.21, 0.0]
normal = [0.0, 1.0, 0.0]
[contact]
model = "hertz"
stiffness = {k_c}
exponent = {n_exp}
"#
    );
    let dir = tempfile::tempdir().unwrap();
    let l = load_text(dir.path(), &text, &[]);
    let n = l.arm.dof();
    let by = coordinate(&l, "base_y");
    let mut arm = l.arm;
    let sol = runtime::solve_static(&mut *arm, &vec![0.0; n], &runtime::StaticOptions::default())
        .unwrap();
    let mut x = sol.q.clone();
    x.extend(vec![0.0; n]);
    let set = arm.contact().unwrap();
    let columns = runtime::contact::channel_columns(&*arm, set, 0.0, &x[..n], &x[n..]);
    let table = columns[0];
    let spring = -k_base * sol.q[by];
    let tip_y = arm.outputs(0.0, &sol.q, &vec![0.0; n])[1];
    let depth = -0.21 - (tip_y - r);
    eprintln!(
        "pressed: table {table:.12} N + base spring {spring:.12} N = {:.12} N of {load} N; depth {depth:.6e} m, (F/k)^(1/n) = {:.6e} m",
        table + spring,
        (table / k_c).powf(1.0 / n_exp)
    );
    assert!(table > 0.5 * load, "the table carries most of it: {table}");
    assert_close(
        table + spring,
        load,
        1e-9,
        0.0,
        "table and base carry the load",
    );
    assert_close(
        depth,
        (table / k_c).powf(1.0 / n_exp),
        1e-9,
        0.0,
        "depth of the law",
    );
}

/// The same in 3D for every 3D method, rom's shared coordinates and eba's
/// absolute ones included: a straight arm hanging from a compliant base,
/// pushed onto a table by a tip load; the table and the base's spring
/// carry the whole load (1e-9), the tip sinks as deep as the law gives.
#[test]
fn every_3d_method_presses_its_tip_load_onto_a_table() {
    let (k_base, k_c, n_exp, load, r) = (100.0, 1e4, 1.5, 2.0, 0.01);
    let methods = (eomgen::method::ALL.iter()).filter(|m| !m.statics_only());
    for method in methods.map(|m| m.name()) {
        // rom's fields of order 2; four elements of the others.
        let count = if method == "rom" {
            "order = 2"
        } else {
            "elements = 4"
        };
        let text = format!(
            r#"
name = "pressed3d"
dimensions = 3
gravity = [0.0, 0.0, 0.0]
[base]
direction = [0.0, 0.0, -1.0]
mass = 0.1
stiffness = {k_base}
damping = 1.0
[[segment]]
method = "{method}"
length = 0.2
{count}
mass = 0.05
outer_radius = {r}
youngs_modulus = 1.0e6
[tip]
force = [0.0, 0.0, -{load}]
[[obstacle]]
name = "table"
shape = "plane"
point = [0.0, 0.0, -0.21]
normal = [0.0, 0.0, 1.0]
[contact]
model = "hertz"
stiffness = {k_c}
exponent = {n_exp}
"#
        );
        let dir = tempfile::tempdir().unwrap();
        let l = load_text(dir.path(), &text, &[]);
        let n = l.arm.dof();
        let bz = coordinate(&l, "base_z");
        let mut arm = l.arm;
        let sol =
            runtime::solve_static(&mut *arm, &vec![0.0; n], &runtime::StaticOptions::default())
                .unwrap();
        let set = arm.contact().unwrap();
        let zeros = vec![0.0; n];
        let table = runtime::contact::channel_columns(&*arm, set, 0.0, &sol.q, &zeros)[0];
        let spring = -k_base * sol.q[bz];
        let tip_z = arm.outputs(0.0, &sol.q, &zeros)[2];
        let depth = -0.21 - (tip_z - r);
        eprintln!(
            "{method}: table {table:.12} N + base {spring:.12} N of {load} N, depth {depth:.6e} m"
        );
        assert!(
            table > 0.5 * load,
            "{method}: the table carries most: {table}"
        );
        assert_close(
            table + spring,
            load,
            1e-9,
            0.0,
            format_args!("{method}: balance"),
        );
        let law = (table / k_c).powf(1.0 / n_exp);
        assert_close(depth, law, 1e-6, 0.0, format_args!("{method}: depth"));
    }
}

/// The sampled points of an arm bent to one circle (every element by the
/// same angle, planar pcc and 3D pcc) lie where the circle puts them:
/// (sin(k s) / k, (1 - cos(k s)) / k) at arc length s, at curvatures from
/// straight to a half turn.
#[test]
fn sampled_points_lie_on_the_arc() {
    for dimensions in [2, 3] {
        let twist = if dimensions == 3 { "twist = false" } else { "" };
        let text = format!(
            r#"
name = "arc"
dimensions = {dimensions}
gravity = [0.0, 0.0, 0.0]
[base]
direction = [1.0, 0.0, 0.0]
[[segment]]
method = "pcc"
length = 0.4
elements = 4
mass = 0.1
bending_stiffness = 0.5
{twist}
[[obstacle]]
name = "far"
shape = "plane"
point = [0.0, -10.0, 0.0]
normal = [0.0, 1.0, 0.0]
[contact]
model = "hertz"
stiffness = 1.0
points_per_element = 3
"#
        );
        let dir = tempfile::tempdir().unwrap();
        let l = load_text(dir.path(), &text, &[]);
        let n = l.arm.dof();
        let names = l.arm.info().coordinates.clone();
        for kappa in [0.0, 1.0, 7.85] {
            // Bend about z: theta_k (planar) or bend_z (3D) = kappa l_e.
            let q: Vec<f64> = names
                .iter()
                .map(|c| {
                    if c.starts_with("theta") || c.starts_with("bend_z") {
                        kappa * 0.1
                    } else {
                        0.0
                    }
                })
                .collect();
            // A chain of pcc arcs: the points come with contact frames.
            assert!(l.arm.info().contact_frames > 0, "{dimensions}D: frames");
            let mut buf = vec![0.0; runtime::KernelKind::Contact.output_len(l.arm.info())];
            l.arm.eval_kernel(
                runtime::KernelKind::Contact,
                0.0,
                &q,
                &vec![0.0; n],
                &mut buf,
            );
            buf.truncate(3 * l.arm.info().contact_points);
            for (i, p) in buf.chunks(3).enumerate() {
                let s = 0.4 * (i + 1) as f64 / 12.0;
                let (x, y) = if kappa == 0.0 {
                    (s, 0.0)
                } else {
                    ((kappa * s).sin() / kappa, (1.0 - (kappa * s).cos()) / kappa)
                };
                let what = format!("{dimensions}D kappa {kappa} point {i}");
                assert_abs(p[0], x, 1e-14, &what);
                assert_abs(p[1], y, 1e-14, &what);
                assert_abs(p[2], 0.0, 1e-14, &what);
            }
        }
    }
}

/// finger_tap is finger_free with a table: above the table their
/// right-hand sides agree (the generated solve that carries the contact
/// frames changes nothing), and pressed into it finger_tap's is the
/// dense solve of M qdd = Q_c - h, with Q_c found from the `Contact`
/// kernel's points and M, h from `MassBias` (a second path through the
/// contact forces and the mass solve: the hot path takes the frames from
/// the `Accel` kernel, keeps the elements near the table and solves by
/// its L D L^T factors).
#[test]
fn finger_tap_is_finger_free_until_it_touches() {
    use softarm::backend::{BackendChoice, load};
    let tap = load("finger_tap", &[], BackendChoice::Compiled, None).unwrap();
    let free = load("finger_free", &[], BackendChoice::Compiled, None).unwrap();
    let n = tap.arm.dof();
    let qd: Vec<f64> = (0..n).map(|i| 0.3 * (i as f64 * 0.9).cos()).collect();
    // Bent up (away from the table), then down onto it by 0.02 to 0.08 rad
    // an element: the tip goes from well above to well into the table.
    let mut touched = 0;
    for bend in [0.05, -0.02, -0.05, -0.065, -0.08] {
        let q: Vec<f64> = (0..n).map(|i| bend * (1.0 + 0.05 * i as f64)).collect();
        let a_tap = accelerations(&tap, 0.5, &q, &qd);
        let a_free = accelerations(&free, 0.5, &q, &qd);
        let mut m = nalgebra::DMatrix::zeros(n, n);
        let mut h = nalgebra::DVector::zeros(n);
        tap.arm.mass_bias(0.5, &q, &qd, &mut m, &mut h);
        let dense = m.cholesky().expect("M is SPD").solve(&(-h));
        let tip_y = tap.arm.outputs(0.5, &q, &qd)[1];
        let touches = tip_y - 0.008 < -0.035;
        let scale = dense.amax();
        for i in 0..n {
            let what = format!("bend {bend} (tip y {tip_y:.4}) qdd[{i}]");
            assert_close(a_tap[i], dense[i], 1e-9, scale, &what);
            if !touches {
                assert_close(a_tap[i], a_free[i], 1e-12, scale, &what);
            }
        }
        if touches {
            // At rest (moving away, the damped law may not push at all).
            let rest = vec![0.0; n];
            let (a_tap, a_free) = (
                accelerations(&tap, 0.5, &q, &rest),
                accelerations(&free, 0.5, &q, &rest),
            );
            let differs = (0..n).any(|i| (a_tap[i] - a_free[i]).abs() > 1e-6 * scale);
            assert!(differs, "bend {bend}: the table pushes");
            touched += 1;
        }
    }
    assert_eq!(touched, 3, "states pressed into the table");
}

/// 3D pcc arms hanging from a base, a floor far below: with twist, and
/// with stretch and shear (the centreline longer than the element).
fn hanging_pcc(extra: &str) -> String {
    format!(
        r#"
name = "hanging"
dimensions = 3
gravity = [0.0, 0.0, -9.81]
[base]
direction = [0.3, 0.2, -1.0]
[[segment]]
method = "pcc"
length = 0.3
elements = 5
density = 1000.0
outer_radius = 0.01
youngs_modulus = 1.0e6
{extra}
[[obstacle]]
name = "floor"
shape = "plane"
point = [0.0, 0.0, -1.0]
normal = [0.0, 0.0, 1.0]
[contact]
model = "hertz"
stiffness = 1.0
points_per_element = 3
"#
    )
}

/// A planar vc arm of two segments (one arc each, lengths 0.4 and 0.2 m).
fn two_vc_segments() -> String {
    let segment = |length: f64| {
        format!(
            "[[segment]]\nmethod = \"vc\"\nlength = {length}\nelements = 1\nmass = 0.1\nbending_stiffness = 0.5\n"
        )
    };
    format!(
        r#"
name = "vc2"
gravity = [0.0, -9.81, 0.0]
[base]
direction = [1.0, 0.0, 0.0]
{}{}
[[obstacle]]
name = "floor"
shape = "plane"
point = [0.0, -10.0, 0.0]
normal = [0.0, 1.0, 0.0]
[contact]
model = "hertz"
stiffness = 1.0
points_per_element = 3
"#,
        segment(0.4),
        segment(0.2)
    )
}

/// The contact frames the kernel reads: the `Accel` kernel's where the
/// model has one (the hot path), else the `Contact` kernel's.
fn contact_frames(arm: &dyn runtime::Dynamics, q: &[f64], qd: &[f64]) -> Vec<f64> {
    use runtime::KernelKind;
    let info = arm.info();
    let kind = match info.accel {
        true => KernelKind::Accel,
        false => KernelKind::Contact,
    };
    let mut out = vec![0.0; kind.output_len(info)];
    arm.eval_kernel(kind, 0.0, q, qd, &mut out);
    out.split_off(out.len() - info.contact_frames)
}

/// A chain's `ContactJacobian` groups start from the contact frames (each
/// element's base frame and the earlier coordinates' twists), not from
/// the base: they must place every point where the flat kinematics (the
/// `Contact` kernel, the whole chain's expressions) does, with dp/dq the
/// central differences of those positions and v their rate along qd. For
/// finger_tap and wrap (planar pcc), a planar vc arm of two segments and
/// 3D pcc arms with twist, and with stretch and shear.
#[test]
fn the_contact_frames_place_the_points_as_the_flat_kinematics_does() {
    use runtime::KernelKind;
    use softarm::backend::{BackendChoice, load};
    let dir = tempfile::tempdir().unwrap();
    // The files on the interpreter, whose tapes carry the frames (on
    // linked cells their contact is the recursion's: tests/suite/backends.rs).
    let interpreted_text = |dir: &std::path::Path, name: &str, text: &str| {
        let path = dir.join(format!("{name}.toml"));
        std::fs::write(&path, text).unwrap();
        let cache = Some(dir.join("cache"));
        load(
            &path.to_string_lossy(),
            &[],
            BackendChoice::Interpreted,
            cache,
        )
        .unwrap()
    };
    let models = [
        (
            "finger_tap",
            load("finger_tap", &[], BackendChoice::Compiled, None).unwrap(),
        ),
        (
            "wrap",
            load("wrap", &[], BackendChoice::Compiled, None).unwrap(),
        ),
        (
            "3D twist",
            interpreted_text(dir.path(), "twist", &hanging_pcc("")),
        ),
        (
            "vc, two segments",
            interpreted_text(dir.path(), "vc", &two_vc_segments()),
        ),
        (
            "3D stretch and shear",
            interpreted_text(
                dir.path(),
                "shear",
                &hanging_pcc("extension = true\nshear = true"),
            ),
        ),
    ];
    let mut rng = Rng::new(21);
    for (name, l) in &models {
        let arm = &*l.arm;
        let info = arm.info();
        assert!(
            info.contact_frames > 0,
            "{name}: a chain has contact frames"
        );
        let (n, points) = (arm.dof(), info.contact_points);
        let flat = |q: &[f64], qd: &[f64]| {
            let mut b = vec![0.0; KernelKind::Contact.output_len(info)];
            arm.eval_kernel(KernelKind::Contact, 0.0, q, qd, &mut b);
            b.truncate(3 * points);
            b
        };
        for _ in 0..4 {
            let q = rng.coordinates(&info.coordinates, -0.8, 0.8);
            let qd = rng.vec(n, -2.0, 2.0);
            let frames = contact_frames(arm, &q, &qd);
            let mut out = vec![0.0; KernelKind::ContactJacobian.output_len(info)];
            arm.eval_direction(
                KernelKind::ContactJacobian,
                0.0,
                &q,
                &qd,
                &[],
                &frames,
                &mut out,
            );
            let width = 6 + 3 * n;
            let p0 = flat(&q, &qd);
            let h = 1e-6;
            let moved = |dq: &dyn Fn(usize) -> f64, sign: f64| {
                let q: Vec<f64> = (0..n).map(|j| q[j] + sign * h * dq(j)).collect();
                flat(&q, &qd)
            };
            let rate = |dq: &dyn Fn(usize) -> f64| -> Vec<f64> {
                let (a, b) = (moved(dq, 1.0), moved(dq, -1.0));
                a.iter().zip(&b).map(|(a, b)| (a - b) / (2.0 * h)).collect()
            };
            let along_qd = rate(&|j| qd[j]);
            let columns: Vec<Vec<f64>> = (0..n)
                .map(|k| rate(&|j| if j == k { 1.0 } else { 0.0 }))
                .collect();
            for i in 0..points {
                let o = &out[i * width..(i + 1) * width];
                for c in 0..3 {
                    let what = format!("{name} point {i} axis {c}");
                    assert_abs(o[c], p0[3 * i + c], 1e-12, &format!("{what}: position"));
                    assert_abs(o[3 + c], along_qd[3 * i + c], 1e-7, &format!("{what}: v"));
                    for (k, col) in columns.iter().enumerate() {
                        let got = o[6 + c * n + k];
                        assert_abs(got, col[3 * i + c], 1e-7, &format!("{what}: dp/dq{k}"));
                    }
                }
            }
        }
    }
}

/// Q_c by the hot path from the contact frames (the broad phase, then the
/// groups it keeps: the `Accel` kernel's frames, or the bounds alone where
/// the kernels give them without it, linked cells') and from every
/// point's position (the `Contact` kernel, of `reference`: the same arm,
/// or for linked cells the interpreter's): whether they push must agree,
/// and Q_c to 1e-9. True if they push.
fn both_routes_agree(
    arm: &dyn runtime::Dynamics,
    reference: &dyn runtime::Dynamics,
    q: &[f64],
    qd: &[f64],
    what: &str,
) -> bool {
    use runtime::contact::generalised_force_at;
    let n = q.len();
    let frames = arm.info().accel.then(|| contact_frames(arm, q, qd));
    if frames.is_none() {
        let mut bounds = vec![0.0; arm.info().contact_frames];
        assert!(
            arm.contact_bounds(0.0, q, qd, &mut bounds),
            "{what}: no bounds"
        );
    }
    let (mut from_frames, mut from_points) = (vec![0.0; n], vec![0.0; n]);
    let a = generalised_force_at(arm, 0.0, q, qd, frames.as_deref(), &mut from_frames);
    let b = generalised_force_at(reference, 0.0, q, qd, None, &mut from_points);
    assert_eq!(a, b, "{what}: pushes");
    if a {
        let scale = from_points.iter().fold(0.0, |m: f64, x| m.max(x.abs()));
        for j in 0..n {
            let what = format!("{what} Q_c[{j}]");
            assert_close(from_frames[j], from_points[j], 1e-9, scale, &what);
        }
    }
    a
}

/// The broad phase of the contact frames skips an element only when its
/// points cannot touch: with an obstacle put at random close to the arm
/// (planes, spheres, capped cylinders and boxes, some deep in it, some
/// clear), the generalised contact force from the `Accel` kernel's frames
/// (the broad phase, then the groups it keeps) equals the one found from
/// every point's position (the `Contact` kernel), at random states of
/// finger_tap and wrap.
#[test]
fn the_broad_phase_misses_no_contact() {
    use runtime::KernelKind;
    use runtime::contact::Shape;
    use softarm::backend::{BackendChoice, load};
    let mut rng = Rng::new(5);
    // Compiled in (the `Accel` kernel's frames), and on linked cells (their
    // bounds alone) against the interpreter's points.
    let linked = [eomgen::model::Override::parse("segment.0.elements=7").unwrap()];
    for (name, sets) in [
        ("finger_tap", &[][..]),
        ("wrap", &[]),
        ("finger_tap", &linked),
        ("wrap", &linked),
    ] {
        let mut l = load(name, sets, BackendChoice::Auto, None).unwrap();
        let mut reference = match l.arm.info().accel {
            true => None,
            false => Some(load(name, sets, BackendChoice::Interpreted, None).unwrap()),
        };
        let base_set = l.arm.contact().unwrap().clone();
        let n = l.arm.dof();
        let points = l.arm.info().contact_points;
        let (mut pushed, mut skipped) = (0, 0);
        for trial in 0..400 {
            let q = rng.coordinates(&l.arm.info().coordinates, -0.4, 0.4);
            let qd = rng.vec(n, -1.0, 1.0);
            let mut flat = vec![0.0; KernelKind::Contact.output_len(l.arm.info())];
            l.arm
                .eval_kernel(KernelKind::Contact, 0.0, &q, &qd, &mut flat);
            // Its surface at a gap delta from a random point of the arm:
            // within a third of the tube's radius every other trial (the
            // broad phase's margin decides there), else up to 3 cm either
            // way (deep in, or clear).
            let k = (rng.next_f64() * points as f64) as usize;
            let p: [f64; 3] = std::array::from_fn(|c| flat[3 * k + c]);
            let r = base_set.points[k].radius;
            let delta = match trial % 2 {
                0 => rng.uniform(-0.3, 0.3) * r,
                _ => rng.uniform(-0.03, 0.03),
            };
            let mut unit = || {
                let v = [0, 1, 2].map(|_| rng.uniform(-1.0, 1.0));
                let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt().max(1e-3);
                v.map(|x| x / len)
            };
            // Across the arm (the surface along it, where an element's
            // bound is tightest), every other placement; else any way.
            let u = match (trial / 8) % 2 {
                0 => {
                    let (i, j) = (k.saturating_sub(1), (k + 1).min(points - 1));
                    let t: [f64; 3] = std::array::from_fn(|c| flat[3 * j + c] - flat[3 * i + c]);
                    let tt = t[0] * t[0] + t[1] * t[1] + t[2] * t[2];
                    let w = unit();
                    let wt = w[0] * t[0] + w[1] * t[1] + w[2] * t[2];
                    let v = [0, 1, 2].map(|c| w[c] - wt / tt * t[c]);
                    let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                    v.map(|c| c / len)
                }
                _ => unit(),
            };
            // p at distance r + delta from the surface, along u.
            let back =
                |d: f64| -> [f64; 3] { std::array::from_fn(|c| p[c] - (r + delta + d) * u[c]) };
            let shape = match (trial / 2) % 4 {
                0 => Shape::Plane {
                    point: back(0.0),
                    normal: u,
                },
                1 => {
                    let radius = rng.uniform(0.002, 0.03);
                    Shape::Sphere {
                        center: back(radius),
                        radius,
                    }
                }
                2 => {
                    // The axis normal to u.
                    let w = unit();
                    let along = w[0] * u[0] + w[1] * u[1] + w[2] * u[2];
                    let axis = [0, 1, 2].map(|c| w[c] - along * u[c]);
                    let len = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
                    let radius = rng.uniform(0.002, 0.02);
                    Shape::Cylinder {
                        center: back(radius),
                        axis: axis.map(|c| c / len),
                        radius,
                        half_length: rng.uniform(0.005, 0.05),
                    }
                }
                _ => {
                    // A box turned about z, its first axis along u's
                    // projection (the face p is nearest).
                    let a = u[1].atan2(u[0]);
                    let half = [0, 1, 2].map(|_| rng.uniform(0.002, 0.02));
                    let flat_u = [a.cos(), a.sin(), 0.0];
                    // Off p's mid-planes across the box by a tenth of its
                    // size: a point deep in on a mid-plane has two nearest
                    // faces, and round-off would pick one.
                    let across = [-a.sin(), a.cos(), 0.0];
                    let center = std::array::from_fn(|c| {
                        p[c] - (r + delta + half[0]) * flat_u[c]
                            + 0.1 * half[1] * across[c]
                            + if c == 2 { 0.1 * half[2] } else { 0.0 }
                    });
                    Shape::Box {
                        center,
                        rotation: [
                            [a.cos(), -a.sin(), 0.0],
                            [a.sin(), a.cos(), 0.0],
                            [0.0, 0.0, 1.0],
                        ],
                        half,
                    }
                }
            };
            let mut set = base_set.clone();
            set.obstacles[0].shape = shape.clone();
            if let Some(r) = reference.as_mut() {
                r.arm.set_contact(Some(set.clone()));
            }
            l.arm.set_contact(Some(set));
            let what = format!("{name} {sets:?} trial {trial} ({shape:?})");
            let reference = reference.as_ref().map_or(&*l.arm, |r| &*r.arm);
            if both_routes_agree(&*l.arm, reference, &q, &qd, &what) {
                pushed += 1;
            }
            // How many elements the broad phase could skip: those whose
            // points are all clear of the obstacle.
            let r = base_set.points[0].radius;
            skipped += l
                .arm
                .info()
                .contact_group_ranges()
                .filter(|&(first, len)| {
                    (first..first + len).all(|i| {
                        let p = [0, 1, 2].map(|c| flat[3 * i + c]);
                        shape.distance(p, [0.0; 3]).0 - r > 0.0
                    })
                })
                .count();
        }
        assert!(pushed > 60, "{name}: {pushed} of 400 states touch");
        assert!(skipped > 400, "{name}: {skipped} elements clear");
    }
}

/// The broad phase between elements (self contact): two elements are
/// skipped only when their spheres (about the middle of their ends,
/// radius half the centreline's length plus the tube's) are apart.
/// finger_tap with self contact and a 2 mm tube, bent at random (-2.5 to
/// 2.5 rad an element: loops and knots), its table far below: Q_c from
/// the frames equals Q_c from every point's position, 2000 shapes.
#[test]
fn the_broad_phase_between_elements_misses_no_contact() {
    use runtime::contact::Shape;
    use softarm::backend::{BackendChoice, load};
    let sets = [eomgen::model::Override::parse("contact.self_contact=true").unwrap()];
    let mut l = load("finger_tap", &sets, BackendChoice::Compiled, None).unwrap();
    let mut set = l.arm.contact().unwrap().clone();
    set.obstacles[0].shape = Shape::Plane {
        point: [0.0, -10.0, 0.0],
        normal: [0.0, 1.0, 0.0],
    };
    // The tube thinned (runtime data: the finger's chambers need its 8 mm).
    for p in &mut set.points {
        p.radius = 0.002;
    }
    l.arm.set_contact(Some(set));
    let n = l.arm.dof();
    let mut rng = Rng::new(17);
    let mut pushed = 0;
    for trial in 0..2000 {
        let q = rng.vec(n, -2.5, 2.5);
        let qd = rng.vec(n, -1.0, 1.0);
        if both_routes_agree(&*l.arm, &*l.arm, &q, &qd, &format!("trial {trial}")) {
            pushed += 1;
        }
    }
    assert!(pushed > 500, "{pushed} of 2000 shapes touch themselves");
}

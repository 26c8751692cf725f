//! Arms on other arms' frames (`[arm.base] on = "ARM.tip"`), in 3D and in
//! the plane: carried by the structure in minimal coordinates, no
//! constraint. An arm on another's
//! tip is the same mechanism as one arm of two segments, so against that
//! arm (a second derivation: one chain), coordinate by coordinate, in
//! statics and in motion; turned on the tip, against the same arm with a
//! kink (`turn`); two arms on one tip (a palm's fingers) keep the energy of
//! an undamped swing.

use crate::common::*;
use runtime::{SimOptions, StaticOptions, simulate, solve_static};

const SEGMENT: &str = "method = \"pcc\"\ndensity = 1000.0\nouter_radius = 0.01\nyoungs_modulus = 1e5\nbending_damping = 1e-4";

/// The first line of a model: 3D with gravity across both axes, or the
/// plane.
const SPACE: &str = "dimensions = 3\ngravity = [0.0, -4.0, -9.81]";
const PLANE: &str = "dimensions = 2\ngravity = [-2.0, -9.81, 0.0]";

fn tree(direction: &str, more: &str) -> String {
    tree_in(SPACE, direction, more)
}

fn tree_in(space: &str, direction: &str, more: &str) -> String {
    format!(
        r#"
name = "tree"
{space}
[[arm]]
name = "upper"
[arm.base]
direction = [1.0, 0.0, 0.0]
[[arm.segment]]
length = 0.2
elements = 4
{SEGMENT}
[[arm]]
name = "lower"
[arm.base]
on = "upper.tip"
direction = {direction}
[[arm.segment]]
length = 0.15
elements = 3
{SEGMENT}
{more}
"#
    )
}

fn chain(turn: &str) -> String {
    chain_in(SPACE, turn)
}

fn chain_in(space: &str, turn: &str) -> String {
    format!(
        r#"
name = "chain"
{space}
[base]
direction = [1.0, 0.0, 0.0]
[[segment]]
length = 0.2
elements = 4
{SEGMENT}
[[segment]]
length = 0.15
elements = 3
{SEGMENT}
{turn}
"#
    )
}

/// 0.3 s from straight, at tolerances far below the differences tested.
fn tight() -> SimOptions {
    SimOptions {
        t_end: 0.3,
        output_dt: 0.01,
        rtol: 1e-10,
        atol: 1e-12,
        ..Default::default()
    }
}

/// The largest difference of the coordinates, statically and over 0.3 s
/// of motion from straight.
fn differences(a: &str, b: &str) -> (f64, f64, f64) {
    let dir = tempfile::tempdir().unwrap();
    let (da, db) = (dir.path().join("a"), dir.path().join("b"));
    std::fs::create_dir_all(&da).unwrap();
    std::fs::create_dir_all(&db).unwrap();
    let (mut la, mut lb) = (load_text(&da, a, &[]), load_text(&db, b, &[]));
    let n = la.arm.dof();
    assert_eq!(n, lb.arm.dof());
    let sa = solve_static(&mut *la.arm, &vec![0.0; n], &StaticOptions::default()).unwrap();
    let sb = solve_static(&mut *lb.arm, &vec![0.0; n], &StaticOptions::default()).unwrap();
    let statics =
        sa.q.iter()
            .zip(&sb.q)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max);
    let scale = sb.q.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let (ta, _) = simulate(&*la.arm, vec![0.0; 2 * n], &tight()).unwrap();
    let (tb, _) = simulate(&*lb.arm, vec![0.0; 2 * n], &tight()).unwrap();
    assert_eq!(ta.t.len(), tb.t.len());
    let motion = (ta.x.iter().zip(&tb.x))
        .flat_map(|(x, y)| x[..n].iter().zip(&y[..n]).map(|(p, q)| (p - q).abs()))
        .fold(0.0, f64::max);
    (statics, motion, scale)
}

#[test]
fn an_arm_on_anothers_tip_moves_as_one_arm_of_two_segments() {
    let (statics, motion, scale) = differences(&tree("[1.0, 0.0, 0.0]", ""), &chain(""));
    assert!(scale > 0.1, "the arm sags: {scale}");
    assert!(statics < 1e-9 * scale, "statics differ by {statics:e}");
    assert!(motion < 1e-7 * scale, "motion differs by {motion:e}");
}

#[test]
fn an_arm_turned_on_anothers_tip_moves_as_one_arm_with_a_kink() {
    let (statics, motion, scale) =
        differences(&tree("[0.0, 1.0, 0.0]", ""), &chain("turn = [0.0, 90.0]"));
    assert!(scale > 0.1, "the arm sags: {scale}");
    assert!(statics < 1e-9 * scale, "statics differ by {statics:e}");
    assert!(motion < 1e-7 * scale, "motion differs by {motion:e}");
}

/// In the plane: an arm on another's tip, straight on and turned a right
/// angle, against one planar arm of two segments (with a kink).
#[test]
fn a_planar_arm_on_anothers_tip_moves_as_one_planar_arm() {
    for (direction, turn) in [
        ("[1.0, 0.0, 0.0]", ""),
        ("[0.0, 1.0, 0.0]", "turn = [90.0]"),
    ] {
        let (statics, motion, scale) =
            differences(&tree_in(PLANE, direction, ""), &chain_in(PLANE, turn));
        eprintln!("{direction}: statics {statics:.1e}, motion {motion:.1e}, of {scale:.2}");
        assert!(scale > 0.1, "{direction}: the arm sags: {scale}");
        assert!(
            statics < 1e-9 * scale,
            "{direction}: statics differ by {statics:e}"
        );
        assert!(
            motion < 1e-7 * scale,
            "{direction}: motion differs by {motion:e}"
        );
    }
}

/// A palm with two fingers: both on the upper arm's tip, turned 45 degrees
/// either way; undamped, released straight under gravity, the whole keeps
/// its energy (kinetic plus potential) while the fingers swing.
#[test]
fn two_arms_on_one_tip_keep_the_energy_of_an_undamped_swing() {
    let finger = |name: &str, y: f64| {
        format!(
            "[[arm]]\nname = \"{name}\"\n[arm.base]\non = \"upper.tip\"\ndirection = [1.0, {y}, 0.0]\n[[arm.segment]]\nlength = 0.1\nelements = 2\n{SEGMENT}\n"
        )
    };
    let text = tree("[1.0, 0.0, 0.0]", "")
        .replace("name = \"lower\"", "name = \"thumb\"")
        .replace(
            "direction = [1.0, 0.0, 0.0]\n[[arm.segment]]\nlength = 0.15",
            "direction = [1.0, 0.0, 0.5]\n[[arm.segment]]\nlength = 0.15",
        )
        + &finger("index", 1.0)
        + &finger("ring", -1.0);
    let text = text.replace("bending_damping = 1e-4", "");
    let dir = tempfile::tempdir().unwrap();
    let l = load_text(dir.path(), &text, &[]);
    let n = l.arm.dof();
    assert_eq!(n, 3 * (4 + 3 + 2 + 2), "{:?}", l.arm.info().coordinates);
    let (traj, _) = simulate(&*l.arm, vec![0.0; 2 * n], &tight()).unwrap();
    let names = runtime::OUTPUT_NAMES;
    let at = |k: &str| names.iter().position(|n| *n == k).unwrap();
    let energy: Vec<(f64, f64)> = (traj.x.iter())
        .map(|x| {
            let o = l.arm.outputs(0.0, &x[..n], &x[n..]);
            (o[at("kinetic")], o[at("potential")])
        })
        .collect();
    let total: Vec<f64> = energy.iter().map(|(k, p)| k + p).collect();
    let swing = energy.iter().map(|e| e.0).fold(0.0, f64::max);
    let drift = total
        .iter()
        .map(|e| (e - total[0]).abs())
        .fold(0.0, f64::max);
    assert!(swing > 1e-4, "it swings: {swing}");
    assert!(
        drift < 1e-6 * swing,
        "energy drifts by {drift:e} of a swing of {swing:e}"
    );
}

/// Bad bases on frames (run by `bad_input::assembly_mistakes_name_the_key`):
/// a label, the model, what its error must say.
pub fn bad_cases() -> Vec<(&'static str, String, Vec<&'static str>)> {
    let good = tree("[1.0, 0.0, 0.0]", "");
    let r = |a: &str, b: &str| {
        assert!(good.contains(a), "{a}");
        good.replacen(a, b, 1)
    };
    let single = chain("").replace("[base]\n", "[base]\non = \"tip\"\n");
    vec![
        (
            "a single arm on a frame",
            single,
            vec!["base.on", "[[arm]]"],
        ),
        (
            "on the world",
            r("on = \"upper.tip\"", "on = \"world\""),
            vec!["arm.lower.base.on", "another arm's"],
        ),
        (
            "on an unknown arm",
            r("on = \"upper.tip\"", "on = \"middle.tip\""),
            vec!["arm.lower.base.on", "no frame \"middle.tip\""],
        ),
        (
            "on itself",
            r("on = \"upper.tip\"", "on = \"lower.tip\""),
            vec!["arm.lower.base.on", "declare the arm it sits on first"],
        ),
        (
            "on a body, on a compliant base",
            r("on = \"upper.tip\"", "on = \"hub\"\nmass = 0.1")
                + "[[body]]\nname = \"hub\"\nshape = \"sphere\"\nradius = 0.01\nmass = 0.1\n",
            vec!["arm.lower.base.on", "no compliant base"],
        ),
        (
            "on a compliant base",
            r("on = \"upper.tip\"", "on = \"upper.tip\"\nmass = 0.1"),
            vec!["arm.lower.base.on", "no compliant base"],
        ),
    ]
}

/// An arm on a free body (a cart, a palm): the body carries it in minimal
/// coordinates. The same mechanism is an arm whose compliant base has the
/// body's mass and inertia and no springs (a second derivation: the base
/// coordinates move the arm as the body's do), coordinate by coordinate,
/// released bent in the plane with no gravity: the arm rings and the body
/// recoils and turns.
#[test]
fn an_arm_on_a_free_planar_body_moves_as_an_arm_on_a_free_base() {
    let arm = |base: &str, name: &str| {
        format!("{base}\n[[{name}segment]]\nlength = 0.2\nelements = 4\n{SEGMENT}\n")
    };
    let on_body = format!(
        "name = \"cart\"\ngravity = [0.0, 0.0, 0.0]\n\
         [[body]]\nname = \"cart\"\nshape = \"sphere\"\nradius = 0.05\nmass = 0.3\ninertia = 2e-4\n\
         [[arm]]\nname = \"arm\"\n{}",
        arm(
            "[arm.base]\non = \"cart\"\ndirection = [1.0, 0.0, 0.0]",
            "arm."
        )
    );
    let on_base = format!(
        "name = \"free\"\ngravity = [0.0, 0.0, 0.0]\n{}",
        arm(
            "[base]\ndirection = [1.0, 0.0, 0.0]\nmass = 0.3\nstiffness = 0.0\n\
             rotational_stiffness = 0.0\ninertia = 2e-4",
            ""
        )
    );
    let dir = tempfile::tempdir().unwrap();
    let (da, db) = (dir.path().join("a"), dir.path().join("b"));
    std::fs::create_dir_all(&da).unwrap();
    std::fs::create_dir_all(&db).unwrap();
    let (la, lb) = (load_text(&da, &on_body, &[]), load_text(&db, &on_base, &[]));
    let n = la.arm.dof();
    assert_eq!(n, 3 + 4);
    assert_eq!(lb.arm.dof(), n);
    // Bent: 0.3 rad an element.
    let mut x0 = vec![0.0; 2 * n];
    x0[3..7].fill(0.3);
    let (ta, _) = simulate(&*la.arm, x0.clone(), &tight()).unwrap();
    let (tb, _) = simulate(&*lb.arm, x0, &tight()).unwrap();
    let worst = |range: std::ops::Range<usize>| {
        (ta.x.iter().zip(&tb.x))
            .flat_map(|(x, y)| range.clone().map(move |i| (x[i] - y[i]).abs()))
            .fold(0.0, f64::max)
    };
    let moved = (ta.x.iter()).map(|x| x[2].abs()).fold(0.0, f64::max);
    eprintln!(
        "body turned {moved:.3} rad; the two differ by {:.1e}",
        worst(0..2 * n)
    );
    assert!(moved > 0.05, "the body barely turns: {moved}");
    assert!(worst(0..2 * n) < 1e-8, "differ by {:e}", worst(0..2 * n));
}

/// In 3D: an arm on a free body (quaternion coordinates held to unit norm)
/// against an arm on a free base (a rotation vector), the body's inertia
/// the same about every axis as the base's is: the tips agree over the
/// motion of an arm released bent about both axes, with no gravity.
#[test]
fn an_arm_on_a_free_body_in_3d_moves_as_an_arm_on_a_free_base() {
    let segment = format!("length = 0.2\nelements = 4\n{SEGMENT}\n");
    let on_body = format!(
        "name = \"palm\"\ndimensions = 3\ngravity = [0.0, 0.0, 0.0]\n\
         [[body]]\nname = \"palm\"\nshape = \"sphere\"\nradius = 0.05\nmass = 0.3\n\
         principal_inertia = [2e-4, 2e-4, 2e-4]\n\
         [[arm]]\nname = \"arm\"\n[arm.base]\non = \"palm\"\ndirection = [1.0, 0.0, 0.0]\n\
         [[arm.segment]]\n{segment}"
    );
    let on_base = format!(
        "name = \"free\"\ndimensions = 3\ngravity = [0.0, 0.0, 0.0]\n\
         [base]\ndirection = [1.0, 0.0, 0.0]\nmass = 0.3\nstiffness = 0.0\n\
         rotational_stiffness = 0.0\ninertia = 2e-4\n[[segment]]\n{segment}"
    );
    let dir = tempfile::tempdir().unwrap();
    let (da, db) = (dir.path().join("a"), dir.path().join("b"));
    std::fs::create_dir_all(&da).unwrap();
    std::fs::create_dir_all(&db).unwrap();
    let (la, lb) = (load_text(&da, &on_body, &[]), load_text(&db, &on_base, &[]));
    let (na, nb) = (la.arm.dof(), lb.arm.dof());
    assert_eq!((na, nb), (7 + 12, 6 + 12));
    // The arm's bends: 0.3 rad about y and 0.2 about z an element (each
    // element's coordinates: bend_y, bend_z, twist).
    let bent = |n: usize, first: usize, qw: Option<usize>| {
        let mut x = vec![0.0; 2 * n];
        for e in 0..4 {
            x[first + 3 * e] = 0.3;
            x[first + 3 * e + 1] = 0.2;
        }
        if let Some(i) = qw {
            x[i] = 1.0;
        }
        x
    };
    let names = la.arm.info().coordinates.clone();
    assert_eq!(names[7], "arm.bend_y_0_0", "{names:?}");
    let (ta, _) = simulate(&*la.arm, bent(na, 7, Some(3)), &tight()).unwrap();
    let (tb, _) = simulate(&*lb.arm, bent(nb, 6, None), &tight()).unwrap();
    assert_eq!(ta.t.len(), tb.t.len());
    let tip = |l: &softarm::backend::Loaded, n: usize, x: &[f64]| {
        let o = l.arm.outputs(0.0, &x[..n], &x[n..2 * n]);
        [o[0], o[1], o[2]]
    };
    let (mut worst, mut turned) = (0.0f64, 0.0f64);
    for (xa, xb) in ta.x.iter().zip(&tb.x) {
        let (a, b) = (tip(&la, na, xa), tip(&lb, nb, xb));
        worst = worst.max((0..3).map(|c| (a[c] - b[c]).abs()).fold(0.0, f64::max));
        turned = turned.max(xa[4].abs().max(xa[5].abs()).max(xa[6].abs()));
    }
    eprintln!("the palm's quaternion reaches {turned:.3}; the tips differ by {worst:.1e} m");
    assert!(turned > 0.02, "the palm barely turns: {turned}");
    assert!(worst < 1e-8, "the tips differ by {worst:e} m");
}

/// The tree's arm on the upper arm's tip against the same system welded:
/// the lower arm on a hub that a weld joint holds to the upper arm's tip,
/// a constraint solved at every step where the tree has none. The hub is
/// a 10 g ball of 1 mm radius, the tree's upper arm carries 10 g at its
/// tip: they differ by the ball's rotary inertia (4e-9 kg m^2, 6e-5 of
/// the lower arm's about the tip).
#[test]
fn an_arm_on_anothers_tip_moves_as_the_same_arms_welded() {
    let welded = format!(
        "name = \"welded\"\n{SPACE}\n\
         [[arm]]\nname = \"upper\"\n[arm.base]\ndirection = [1.0, 0.0, 0.0]\n\
         [[arm.segment]]\nlength = 0.2\nelements = 4\n{SEGMENT}\n\
         [[body]]\nname = \"hub\"\nshape = \"sphere\"\nradius = 0.001\nmass = 0.01\nposition = [0.2, 0.0, 0.0]\n\
         [[joint]]\nname = \"weld\"\nkind = \"weld\"\na = \"upper.tip\"\nb = \"hub\"\n\
         [[arm]]\nname = \"lower\"\n[arm.base]\non = \"hub\"\ndirection = [1.0, 0.0, 0.0]\n\
         [[arm.segment]]\nlength = 0.15\nelements = 3\n{SEGMENT}\n"
    );
    let dir = tempfile::tempdir().unwrap();
    let (da, db) = (dir.path().join("a"), dir.path().join("b"));
    std::fs::create_dir_all(&da).unwrap();
    std::fs::create_dir_all(&db).unwrap();
    let (la, lb) = (
        load_text(
            &da,
            &tree("[1.0, 0.0, 0.0]", "").replacen(
                "[[arm]]\nname = \"lower\"",
                "[arm.tip]\nmass = 0.01\n[[arm]]\nname = \"lower\"",
                1,
            ),
            &[],
        ),
        load_text(&db, &welded, &[]),
    );
    let (na, nb) = (la.arm.dof(), lb.arm.dof());
    assert_eq!(nb, na + 7, "{:?}", lb.arm.info().coordinates);
    // The hub where the straight upper arm ends, unturned.
    let mut xb = vec![0.0; 2 * nb];
    xb[0] = 0.2;
    xb[3] = 1.0;
    let (ta, _) = simulate(&*la.arm, vec![0.0; 2 * na], &tight()).unwrap();
    let (tb, _) = simulate(&*lb.arm, xb, &tight()).unwrap();
    assert_eq!(ta.t.len(), tb.t.len());
    let (mut worst, mut scale) = (0.0f64, 0.0f64);
    for (a, b) in ta.x.iter().zip(&tb.x) {
        for i in 0..na {
            worst = worst.max((a[i] - b[7 + i]).abs());
            scale = scale.max(a[i].abs());
        }
    }
    eprintln!("welded against the tree: {worst:.1e} of {scale:.2}");
    assert!(scale > 0.1, "the arms sag: {scale}");
    assert!(worst < 2e-5 * scale, "differ by {worst:e}");
}

/// An arm on a segment's end (`on = "ARM.segment.K.end"`) of a two-segment
/// arm is the same mechanism as a one-segment arm whose tip carries two
/// arms: the second segment continued straight, and the branch.
#[test]
fn an_arm_on_a_segments_end_moves_as_a_branch_at_that_point() {
    let arm = |name: &str, on: &str, direction: &str, length: f64, elements: usize| {
        let base = match on {
            "" => String::new(),
            on => format!("on = \"{on}\"\n"),
        };
        format!(
            "[[arm]]\nname = \"{name}\"\n[arm.base]\n{base}direction = {direction}\n[[arm.segment]]\nlength = {length}\nelements = {elements}\n{SEGMENT}\n"
        )
    };
    let on_segment = format!(
        "name = \"a\"\n{SPACE}\n{}[[arm.segment]]\nlength = 0.15\nelements = 3\n{SEGMENT}\n{}",
        arm("upper", "", "[1.0, 0.0, 0.0]", 0.2, 4),
        arm("lower", "upper.segment.0.end", "[0.0, 1.0, 0.5]", 0.1, 2)
    );
    let branched = format!(
        "name = \"b\"\n{SPACE}\n{}{}{}",
        arm("upper", "", "[1.0, 0.0, 0.0]", 0.2, 4),
        arm("rest", "upper.tip", "[1.0, 0.0, 0.0]", 0.15, 3),
        arm("lower", "upper.tip", "[0.0, 1.0, 0.5]", 0.1, 2)
    );
    let (statics, motion, scale) = differences(&on_segment, &branched);
    assert!(scale > 0.1, "the arms sag: {scale}");
    assert!(statics < 1e-9 * scale, "statics differ by {statics:e}");
    assert!(motion < 1e-7 * scale, "motion differs by {motion:e}");
}

//! shape.csv's rows against independent references: the arm's last point
//! and frame are the tip that the compiled `Outputs` kernel computes (a
//! different derivation of the same kinematics), for every method; the
//! centreline's length converges at second order to the arm's length for
//! inextensible arcs (the chords of a circle); a body's row is its
//! coordinates; an obstacle's row its declared place.

use crate::common::*;
use softarm::backend::{BackendChoice, Loaded, load};
use softarm::shape::{Shape, ShapeRow};

fn loaded(name: &str) -> Loaded {
    load(name, &[], BackendChoice::Auto, None).expect("bundled model loads")
}

fn rows_of<'a>(rows: &'a [ShapeRow], part: &str) -> Vec<&'a ShapeRow> {
    rows.iter().filter(|r| r.part == part).collect()
}

/// The same rotation: q or -q.
fn same_rotation(a: &[f64], b: &[f64]) -> f64 {
    let d = |s: f64| (0..4).map(|i| (a[i] - s * b[i]).abs()).fold(0.0, f64::max);
    d(1.0).min(d(-1.0))
}

#[test]
fn every_methods_centreline_ends_at_the_tip_the_outputs_kernel_computes() {
    // Models whose tip point is the arm's end (no tip body length).
    let models = [
        "soft_finger",
        "cantilever",
        "cantilever3d",
        "chain",
        "hybrid_arm",
        "long_arm",
        "vc_arm",
        "ebr_arm",
        "eba_arm",
        "rom_arm",
        "tentacle3d",
    ];
    let mut rng = Rng::new(7);
    for name in models {
        let l = loaded(name);
        let arm = &*l.arm;
        let shape = Shape::new(&l, 5).unwrap();
        for _ in 0..3 {
            let q = rng.coordinates(&arm.info().coordinates, -0.4, 0.4);
            let qd = vec![0.0; q.len()];
            let rows = shape.at(arm, 0.3, &q);
            let arm_rows = rows_of(&rows, "arm");
            // rom: one element a quadrature slice.
            let elements = eomgen::model::Structure::of(&l.model).elements();
            assert_eq!(arm_rows.len(), 1 + 5 * elements, "{name}: rows");
            let end = arm_rows.last().unwrap();
            let out = arm.outputs(0.3, &q, &qd);
            for (c, (a, b)) in end.pose.iter().zip(&out[..3]).enumerate() {
                assert_close(*a, *b, 1e-12, 1e-12, format_args!("{name} tip {c}"));
            }
            let tip_quat = &out[5..9];
            let d = same_rotation(&end.pose[3..], tip_quat);
            assert!(
                d < 1e-12,
                "{name}: end frame {:?} vs tip {tip_quat:?}",
                end.pose
            );
            // Material coordinate: from 0 to the arm's length.
            let length: f64 = l.model.segments.iter().map(|s| s.length).sum();
            assert_close(end.s, length, 1e-12, 0.0, format_args!("{name} s"));
            assert_eq!(arm_rows[0].s, 0.0);
        }
    }
}

/// The centreline's polyline length.
fn polyline(rows: &[&ShapeRow]) -> f64 {
    rows.windows(2)
        .map(|w| {
            let d: Vec<f64> = (0..3).map(|c| w[1].pose[c] - w[0].pose[c]).collect();
            (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
        })
        .sum()
}

#[test]
fn an_inextensible_arcs_centreline_length_converges_at_second_order() {
    // pcc in the plane and in 3D, rom slices: arcs of the arm's length, so
    // the chords of P points per element fall short by L (theta / P)^2 / 24
    // per element.
    for name in ["soft_finger", "tentacle3d", "rom_arm"] {
        let l = loaded(name);
        let arm = &*l.arm;
        let length: f64 = l.model.segments.iter().map(|s| s.length).sum();
        let q: Vec<f64> = (0..arm.dof())
            .map(|k| 0.3 * (1.7 * k as f64 + 0.3).sin())
            .collect();
        let shortfall = |p: usize| {
            let shape = Shape::new(&l, p).unwrap();
            let rows = shape.at(arm, 0.0, &q);
            length - polyline(&rows_of(&rows, "arm"))
        };
        let (coarse, fine) = (shortfall(4), shortfall(16));
        assert!(coarse > 0.0 && fine > 0.0, "{name}: chords are shorter");
        let order = (coarse / fine).log(4.0);
        assert!((order - 2.0).abs() < 0.05, "{name}: order {order}");
        assert!(fine < 1e-3 * length, "{name}: {fine} m short at 16 points");
    }
}

#[test]
fn a_bodys_row_is_its_coordinates_and_an_obstacles_its_place() {
    let l = loaded("ball_drop");
    let arm = &*l.arm;
    let shape = Shape::new(&l, 3).unwrap();
    let mut rng = Rng::new(3);
    let q = rng.coordinates(&arm.info().coordinates, -0.2, 0.2);
    let rows = shape.at(arm, 0.0, &q);
    let names: Vec<String> = l.model.bodies.iter().map(|b| b.name.clone()).collect();
    let free = softarm::joints::free_bodies(arm, &names);
    assert!(!free.is_empty());
    for (body, ix) in free {
        let r = rows_of(&rows, &body);
        assert_eq!(r.len(), 1, "{body}");
        assert_close(r[0].pose[0], q[ix], 1e-14, 1e-14, "x");
        assert_close(r[0].pose[1], q[ix + 1], 1e-14, 1e-14, "y");
    }
    // finger_tap's table: a plane whose row is its declared point.
    let l = loaded("finger_tap");
    let shape = Shape::new(&l, 2).unwrap();
    let q = vec![0.0; l.arm.dof()];
    let rows = shape.at(&*l.arm, 0.0, &q);
    let set = l.arm.contact().expect("finger_tap has contact");
    for o in &set.obstacles {
        let r = rows_of(&rows, &o.name);
        assert_eq!(r.len(), 1, "{}", o.name);
        if let runtime::contact::Shape::Plane { point, normal } = o.shape {
            assert_eq!(r[0].pose[..3], point);
            // The row's x axis is the normal: rotate (1, 0, 0) by q.
            let [w, x, y, z] = [r[0].pose[3], r[0].pose[4], r[0].pose[5], r[0].pose[6]];
            let axis = [
                1.0 - 2.0 * (y * y + z * z),
                2.0 * (x * y + w * z),
                2.0 * (x * z - w * y),
            ];
            for c in 0..3 {
                assert_close(axis[c], normal[c], 1e-14, 1e-14, "plane normal");
            }
        }
    }
}

#[test]
fn the_static_equilibriums_shape_ends_at_its_tip() {
    let dir = tempfile::tempdir().unwrap();
    let o = softarm(
        &["static", "cantilever3d", "--shape-points", "3", "--json"],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    let shape = v["shape"].as_array().unwrap();
    assert_eq!(shape.len(), 1 + 3 * 5);
    let end = &shape.last().unwrap()["pose"];
    for c in 0..3 {
        let (a, b) = (
            end[c].as_f64().unwrap(),
            v["tip_position"][c].as_f64().unwrap(),
        );
        assert_close(a, b, 1e-12, 1e-12, "static tip");
    }
}

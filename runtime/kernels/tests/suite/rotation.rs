//! A unit quaternion's rotation against Rodrigues' formula (`rotation`).

use runtime_kernels::rotation::from_unit_quaternion;

/// Against Rodrigues' formula R = I + sin(a) K + (1 - cos(a)) K^2 for
/// the quaternion (cos(a/2), sin(a/2) n) of a turn by a about n.
#[test]
fn a_quaternion_turns_as_its_axis_and_angle_say() {
    let (a, n) = (1.1f64, [2.0f64 / 7.0, 3.0 / 7.0, 6.0 / 7.0]);
    let s = (a / 2.0).sin();
    let r = from_unit_quaternion([(a / 2.0).cos(), s * n[0], s * n[1], s * n[2]]);
    let k = [[0.0, -n[2], n[1]], [n[2], 0.0, -n[0]], [-n[1], n[0], 0.0]];
    for i in 0..3 {
        for j in 0..3 {
            let k2: f64 = (0..3).map(|m| k[i][m] * k[m][j]).sum();
            let want = f64::from(u8::from(i == j)) + a.sin() * k[i][j] + (1.0 - a.cos()) * k2;
            assert!(
                (r[i][j] - want).abs() < 1e-15,
                "{i}{j}: {} vs {want}",
                r[i][j]
            );
        }
    }
}

/// A rotation's quaternion is the quaternion it was made from (its sign
/// chosen w >= 0), in each of Shepperd's four branches: turns by up to
/// nearly a half turn about axes along and between the three axes.
#[test]
fn a_rotations_quaternion_is_the_one_it_was_made_from() {
    use runtime_kernels::rotation::to_unit_quaternion;
    let axes = [
        [2.0f64 / 7.0, 3.0 / 7.0, 6.0 / 7.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.6, -0.8, 0.0],
    ];
    for n in axes {
        for a in [0.0f64, 0.3, 1.1, 2.5, 3.1, -2.9] {
            let s = (a / 2.0).sin();
            let q = [(a / 2.0).cos(), s * n[0], s * n[1], s * n[2]];
            let q = if q[0] < 0.0 { q.map(|c| -c) } else { q };
            let back = to_unit_quaternion(&from_unit_quaternion(q));
            for k in 0..4 {
                assert!(
                    (back[k] - q[k]).abs() < 1e-15,
                    "axis {n:?}, angle {a}: {back:?} vs {q:?}"
                );
            }
        }
    }
}

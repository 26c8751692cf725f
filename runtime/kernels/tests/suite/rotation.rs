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

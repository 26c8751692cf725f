//! Rotations given as unit quaternions, written once for the model's
//! sensor frames and the obstacles' orientations.

/// The rotation matrix (rows) of a unit quaternion (w, x, y, z).
pub fn from_unit_quaternion([w, x, y, z]: [f64; 4]) -> [[f64; 3]; 3] {
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

/// The unit quaternion (w, x, y, z), w >= 0, of a rotation matrix (rows),
/// by Shepperd's choice of the largest of 1 + trace and the diagonal's
/// pivots, which keeps every division away from zero.
pub fn to_unit_quaternion(r: &[[f64; 3]; 3]) -> [f64; 4] {
    let trace = r[0][0] + r[1][1] + r[2][2];
    let q = if trace >= r[0][0].max(r[1][1]).max(r[2][2]) {
        let w = 0.5 * (1.0 + trace).sqrt();
        let f = 0.25 / w;
        [
            w,
            f * (r[2][1] - r[1][2]),
            f * (r[0][2] - r[2][0]),
            f * (r[1][0] - r[0][1]),
        ]
    } else if r[0][0] >= r[1][1] && r[0][0] >= r[2][2] {
        let x = 0.5 * (1.0 + r[0][0] - r[1][1] - r[2][2]).sqrt();
        let f = 0.25 / x;
        [
            f * (r[2][1] - r[1][2]),
            x,
            f * (r[0][1] + r[1][0]),
            f * (r[0][2] + r[2][0]),
        ]
    } else if r[1][1] >= r[2][2] {
        let y = 0.5 * (1.0 + r[1][1] - r[0][0] - r[2][2]).sqrt();
        let f = 0.25 / y;
        [
            f * (r[0][2] - r[2][0]),
            f * (r[0][1] + r[1][0]),
            y,
            f * (r[1][2] + r[2][1]),
        ]
    } else {
        let z = 0.5 * (1.0 + r[2][2] - r[0][0] - r[1][1]).sqrt();
        let f = 0.25 / z;
        [
            f * (r[1][0] - r[0][1]),
            f * (r[0][2] + r[2][0]),
            f * (r[1][2] + r[2][1]),
            z,
        ]
    };
    if q[0] < 0.0 { q.map(|c| -c) } else { q }
}

/// The Hamilton product a b, (w, x, y, z).
pub fn quat_mul(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}

//! A tip wrench given in a sensor's frame: a load cell bolted to the tip
//! with its own axes (`tip.sensor_rotation`) and origin
//! (`tip.sensor_offset`, in the tip frame).
//!
//! The sensor's reading (F_s, M_s) at its origin is, in the tip frame and
//! about the tip point,
//!
//! ```text
//! F_t = R F_s,    M_t = R M_s + r x (R F_s),
//! ```
//!
//! a constant linear map of the six readings. The kinematics never sees
//! the sensor: the tip wrench parameters turn with the tip as for
//! `wrench_frame = "tip"`, and the map is applied to their values
//! (constants) or to the channels that drive them (a weighted sum of
//! signals, `wrench_sources`).

use super::error::ModelError;
pub use super::schema::SensorRotation;
use super::schema::{Model, Tip};

impl SensorRotation {
    /// R (v_tip = R v_sensor), or what is wrong with it.
    pub fn matrix(&self) -> Result<[[f64; 3]; 3], String> {
        let r = match self {
            SensorRotation::Matrix(m) => *m,
            SensorRotation::Quaternion([w, x, y, z]) => {
                let n = (w * w + x * x + y * y + z * z).sqrt();
                if (n - 1.0).abs() > 1e-6 {
                    return Err(format!(
                        "a quaternion [w, x, y, z] must have unit norm; this one has {n}"
                    ));
                }
                runtime::rotation::from_unit_quaternion([w / n, x / n, y / n, z / n])
            }
            SensorRotation::Axes(names) => {
                let mut r = [[0.0; 3]; 3];
                for (col, name) in names.iter().enumerate() {
                    let (sign, axis) = match name.trim().strip_prefix('-') {
                        Some(a) => (-1.0, a),
                        None => (1.0, name.trim().trim_start_matches('+')),
                    };
                    let row = match axis {
                        "x" => 0,
                        "y" => 1,
                        "z" => 2,
                        _ => {
                            return Err(format!(
                                "`{name}` is not an axis: use x, y, z, -x, -y or -z"
                            ));
                        }
                    };
                    r[row][col] = sign;
                }
                r
            }
        };
        check_rotation(&r)?;
        Ok(r)
    }
}

/// Orthonormal with determinant +1, to 1e-6.
fn check_rotation(r: &[[f64; 3]; 3]) -> Result<(), String> {
    for i in 0..3 {
        for j in 0..3 {
            let dot: f64 = (0..3).map(|k| r[k][i] * r[k][j]).sum();
            let want = if i == j { 1.0 } else { 0.0 };
            if (dot - want).abs() > 1e-6 || !dot.is_finite() {
                return Err(
                    "not a rotation: its columns (the sensor's axes) must be orthonormal".into(),
                );
            }
        }
    }
    let det = r[0][0] * (r[1][1] * r[2][2] - r[1][2] * r[2][1])
        - r[0][1] * (r[1][0] * r[2][2] - r[1][2] * r[2][0])
        + r[0][2] * (r[1][0] * r[2][1] - r[1][1] * r[2][0]);
    if det < 0.0 {
        return Err("a reflection, not a rotation: the sensor's axes must be right-handed".into());
    }
    Ok(())
}

impl Tip {
    /// Whether the tip wrench is given in a sensor frame.
    pub fn has_sensor(&self) -> bool {
        self.sensor_rotation.is_some() || self.sensor_offset.is_some()
    }

    /// The 6 x 6 map from the sensor's reading (F_s, M_s) to the tip-frame
    /// wrench about the tip point (F_t, M_t); None without a sensor.
    pub fn sensor_map(&self) -> Option<[[f64; 6]; 6]> {
        if !self.has_sensor() {
            return None;
        }
        let identity = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        // Checked by validation; a bad rotation reads as the identity here.
        let r = self
            .sensor_rotation
            .as_ref()
            .and_then(|s| s.matrix().ok())
            .unwrap_or(identity);
        let o = self.sensor_offset.unwrap_or([0.0; 3]);
        // [r]x R: the moment of the force at the offset.
        let cross = [[0.0, -o[2], o[1]], [o[2], 0.0, -o[0]], [-o[1], o[0], 0.0]];
        let mut a = [[0.0; 6]; 6];
        for i in 0..3 {
            for j in 0..3 {
                a[i][j] = r[i][j];
                a[3 + i][3 + j] = r[i][j];
                a[3 + i][j] = (0..3).map(|k| cross[i][k] * r[k][j]).sum();
            }
        }
        Some(a)
    }
}

/// Where a sensor reading's component comes from: a channel, or a
/// constant (`tip.force` / `tip.moment`, else zero).
#[derive(Clone, Debug, PartialEq)]
pub enum Source<'a> {
    Channel(&'a str),
    Constant(f64),
}

/// With a sensor frame, the tip-frame wrench component `row` (0..3 force,
/// 3..6 moment) as a weighted sum of the six readings' sources; None
/// without a sensor.
pub fn wrench_sources(m: &Model, row: usize) -> Option<Vec<(f64, Source<'_>)>> {
    let a = m.tip.sensor_map()?;
    let reading = |j: usize| -> Source<'_> {
        let (inputs, values, k) = if j < 3 {
            (&m.tip.force_inputs, m.tip.force, j)
        } else {
            (&m.tip.moment_inputs, m.tip.moment, j - 3)
        };
        match inputs {
            Some(names) => Source::Channel(names[k].as_str()),
            None => Source::Constant(values.map_or(0.0, |v| v[k])),
        }
    };
    Some(
        (0..6)
            .filter(|&j| a[row][j] != 0.0)
            .map(|j| (a[row][j], reading(j)))
            .collect(),
    )
}

/// The sensor keys: a rotation that is one, a finite offset, and a frame
/// that can carry them (the sensor sits on the tip).
pub fn check(m: &Model, file: &str) -> Result<(), ModelError> {
    let tip = &m.tip;
    if !tip.has_sensor() {
        return Ok(());
    }
    let err = |key: &str, msg: String| ModelError::new(file, key, msg);
    if let Some(rot) = &tip.sensor_rotation {
        rot.matrix().map_err(|e| err("tip.sensor_rotation", e))?;
    }
    if let Some(o) = tip.sensor_offset
        && o.iter().any(|v| !v.is_finite())
    {
        return Err(err(
            "tip.sensor_offset",
            "must be three finite numbers (m)".into(),
        ));
    }
    if tip.wrench_frame == Some(super::schema::WrenchFrame::World) {
        return Err(err(
            "tip.wrench_frame",
            "a sensor frame sits on the tip and turns with it: leave out wrench_frame (or say \"tip\") with sensor_rotation or sensor_offset".into(),
        ));
    }
    if tip.force.is_none()
        && tip.force_inputs.is_none()
        && tip.moment.is_none()
        && tip.moment_inputs.is_none()
    {
        return Err(err(
            "tip.sensor_rotation",
            "a sensor frame with no wrench to read in it: give tip.force / tip.moment or their _inputs".into(),
        ));
    }
    Ok(())
}

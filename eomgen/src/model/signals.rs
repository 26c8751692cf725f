//! Input channels and measured data in a model file: the `[inputs.NAME]`
//! signals that drive pressures, tensions and tip loads at run time, and the
//! `[compare]` section that maps measured tip motion into the model frame.
//!
//! Neither is structural: the generated code sees a driven quantity as a
//! runtime parameter, so swapping a data file or a signal needs no rebuild.

use serde::{Deserialize, Serialize};

/// One input channel: a signal of time.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum Input {
    /// A constant value.
    Constant { value: f64 },
    /// `before` until `time`, then `after`.
    Step {
        #[serde(default)]
        before: f64,
        after: f64,
        time: f64,
    },
    /// `from` until `start`, linearly to `to` at `end`, then `to`.
    Ramp {
        #[serde(default)]
        from: f64,
        to: f64,
        start: f64,
        end: f64,
    },
    /// bias + amplitude sin(2 pi frequency (t - start) + phase), from `start`
    /// (bias before it).
    Sine {
        amplitude: f64,
        /// Hz.
        frequency: f64,
        /// Degrees.
        #[serde(default)]
        phase: f64,
        #[serde(default)]
        bias: f64,
        #[serde(default)]
        start: f64,
    },
    /// A column of a CSV file, linearly interpolated in time (held at the
    /// first and last values outside the record).
    Csv {
        /// Path, relative to the model file.
        file: String,
        column: String,
        /// The time column (s).
        #[serde(default = "time_column")]
        time: String,
        /// Multiplies the column (after `offset`): unit conversion.
        #[serde(default = "unit")]
        scale: f64,
        /// Subtracted from the column: a number, or "first" (the value at
        /// the first row: gauge pressure from absolute, say).
        #[serde(default)]
        offset: Option<Offset>,
        /// Centred moving average over this many samples (an even count
        /// uses one fewer, as MATLAB's `smooth` does): no lag.
        #[serde(default = "one")]
        smooth: usize,
        /// The channel arrives this many seconds after its time column
        /// says (s): u(t) is the record's value at t - delay. A sensor's
        /// or a valve's lag, and a value `softarm fit` can find.
        #[serde(default)]
        delay: f64,
    },
}

/// What `offset` subtracts.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(untagged)]
pub enum Offset {
    Value(f64),
    /// "first"
    Named(String),
}

/// `[compare]`: measured tip positions (and orientations) in a CSV file,
/// mapped into the model frame:
///
/// p = rotation (scale (position - reference) - R_c offset - (p_0 - offset)) + initial,
///
/// with R_c the tip rotation relative to the first sample (from the
/// orientation columns; identity without them) and p_0 the first sample.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Compare {
    /// Path, relative to the model file.
    pub file: String,
    #[serde(default = "time_column")]
    pub time: String,
    /// Tip marker position columns.
    pub position: [String; 3],
    /// Columns subtracted from the position (a base marker).
    #[serde(default)]
    pub reference: Option<[String; 3]>,
    /// Multiplies positions into metres (1e-3 for mm).
    #[serde(default = "unit")]
    pub scale: f64,
    /// Tip marker orientation as a quaternion (w, x, y, z).
    #[serde(default)]
    pub orientation: Option<[String; 4]>,
    /// Marker offset from the tip point in the tip frame (m), removed with
    /// the orientation relative to the first sample.
    #[serde(default)]
    pub sensor_offset: Option<[f64; 3]>,
    /// Rotation from the measurement frame to the model frame (rows).
    #[serde(default)]
    pub rotation: Option<[[f64; 3]; 3]>,
    /// Where the first sample sits in the model frame (m); default the
    /// simulated tip at the start of the run (t = 0).
    #[serde(default)]
    pub initial: Option<[f64; 3]>,
    /// Time window of the error statistics (s); default the whole record.
    #[serde(default)]
    pub window: Option<[f64; 2]>,
    /// Centred moving average over this many samples.
    #[serde(default = "one")]
    pub smooth: usize,
}

fn time_column() -> String {
    "time".to_string()
}

fn unit() -> f64 {
    1.0
}

fn one() -> usize {
    1
}

/// Checks of one input channel that the types cannot express.
pub(crate) fn check_input(
    name: &str,
    input: &Input,
    file: &str,
) -> Result<(), super::error::ModelError> {
    let path = |k: &str| format!("inputs.{name}.{k}");
    let bad = |k: &str, msg: String| Err(super::error::ModelError::new(file, path(k), msg));
    let finite = |k: &str, v: f64| {
        if v.is_finite() {
            Ok(())
        } else {
            bad(k, format!("must be a finite number, got {v}"))
        }
    };
    if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
        return Err(super::error::ModelError::new(
            file,
            format!("inputs.{name}"),
            "channel names are letters, digits and _".to_string(),
        ));
    }
    match input {
        Input::Constant { value } => finite("value", *value),
        Input::Step {
            before,
            after,
            time,
        } => {
            finite("before", *before)?;
            finite("after", *after)?;
            finite("time", *time)
        }
        Input::Ramp {
            from,
            to,
            start,
            end,
        } => {
            for (k, v) in [("from", from), ("to", to), ("start", start), ("end", end)] {
                finite(k, *v)?;
            }
            if end <= start {
                return bad("end", format!("must be after start ({start} s), got {end}"));
            }
            Ok(())
        }
        Input::Sine {
            amplitude,
            frequency,
            phase,
            bias,
            start,
        } => {
            for (k, v) in [
                ("amplitude", amplitude),
                ("phase", phase),
                ("bias", bias),
                ("start", start),
            ] {
                finite(k, *v)?;
            }
            if !(frequency.is_finite() && *frequency >= 0.0) {
                return bad(
                    "frequency",
                    format!("must be zero or positive (Hz), got {frequency}"),
                );
            }
            Ok(())
        }
        Input::Csv {
            file: f,
            column,
            time,
            scale,
            offset,
            smooth,
            delay,
        } => {
            if f.trim().is_empty() {
                return bad(
                    "file",
                    "must name a CSV file (relative to the model file)".into(),
                );
            }
            for (k, v) in [("column", column), ("time", time)] {
                if v.trim().is_empty() {
                    return bad(k, "must name a column of the CSV file's header".into());
                }
            }
            finite("scale", *scale)?;
            finite("delay", *delay)?;
            match offset {
                Some(Offset::Value(v)) => finite("offset", *v)?,
                Some(Offset::Named(s)) if s != "first" => {
                    return bad(
                        "offset",
                        format!(
                            "must be a number or \"first\" (the first row's value), got \"{s}\""
                        ),
                    );
                }
                _ => {}
            }
            if *smooth == 0 || *smooth > 1000 {
                return bad("smooth", format!("must be 1 to 1000 samples, got {smooth}"));
            }
            Ok(())
        }
    }
}

/// Checks of `[compare]`.
pub(crate) fn check_compare(c: &Compare, file: &str) -> Result<(), super::error::ModelError> {
    let bad = |k: &str, msg: String| {
        Err(super::error::ModelError::new(
            file,
            format!("compare.{k}"),
            msg,
        ))
    };
    if c.file.trim().is_empty() {
        return bad(
            "file",
            "must name a CSV file (relative to the model file)".into(),
        );
    }
    if !(c.scale.is_finite() && c.scale != 0.0) {
        return bad(
            "scale",
            format!("must be a non-zero number, got {}", c.scale),
        );
    }
    for (k, v) in [("sensor_offset", c.sensor_offset), ("initial", c.initial)] {
        if let Some(v) = v
            && v.iter().any(|x| !x.is_finite())
        {
            return bad(k, format!("must be finite numbers, got {v:?}"));
        }
    }
    if c.sensor_offset.is_some() && c.orientation.is_none() {
        return bad(
            "sensor_offset",
            "needs the tip `orientation` columns to turn the offset with the tip".into(),
        );
    }
    if let Some(r) = c.rotation {
        // Orthonormal with determinant +1.
        let mut worst = 0.0f64;
        for i in 0..3 {
            for j in 0..3 {
                let d: f64 = (0..3).map(|k| r[i][k] * r[j][k]).sum();
                worst = worst.max((d - f64::from(u8::from(i == j))).abs());
            }
        }
        let det = r[0][0] * (r[1][1] * r[2][2] - r[1][2] * r[2][1])
            - r[0][1] * (r[1][0] * r[2][2] - r[1][2] * r[2][0])
            + r[0][2] * (r[1][0] * r[2][1] - r[1][1] * r[2][0]);
        if !(worst < 1e-6 && det > 0.0) {
            return bad(
                "rotation",
                "must be a rotation matrix (orthonormal rows, determinant +1)".into(),
            );
        }
    }
    if let Some([a, b]) = c.window
        && !(a.is_finite() && b.is_finite() && b > a)
    {
        return bad(
            "window",
            format!("must be [start, end] with end > start (s), got [{a}, {b}]"),
        );
    }
    if c.smooth == 0 || c.smooth > 1000 {
        return bad(
            "smooth",
            format!("must be 1 to 1000 samples, got {}", c.smooth),
        );
    }
    Ok(())
}

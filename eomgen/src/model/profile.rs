//! A value along a segment: one number, a linear taper `[start, end]`, or a
//! table `{ s = [...], value = [...] }` over the fraction s/L, linear
//! between its points. Section dimensions and material values take it, so
//! that a tapered tentacle is one segment; each element reads the value at
//! its middle (`Segment::at`).

use std::fmt;

use serde::de::{self, Deserializer, MapAccess, SeqAccess, Visitor};
use serde::ser::{SerializeMap, Serializer};
use serde::{Deserialize, Serialize};

/// A value along a segment, by the fraction x = s/L in [0, 1].
#[derive(Clone, Debug, PartialEq)]
pub enum Profile {
    Uniform(f64),
    /// Linear from the base's value to the tip's.
    Linear([f64; 2]),
    /// Piecewise linear through (s, value), s rising from 0 to 1.
    Table {
        s: Vec<f64>,
        value: Vec<f64>,
    },
}

impl Profile {
    /// The value at the fraction `x` (clamped to [0, 1]).
    pub fn at(&self, x: f64) -> f64 {
        let x = x.clamp(0.0, 1.0);
        match self {
            Self::Uniform(v) => *v,
            Self::Linear([a, b]) => a + (b - a) * x,
            Self::Table { s, value } => {
                let k = s.partition_point(|&si| si <= x).clamp(1, s.len() - 1);
                let (s0, s1) = (s[k - 1], s[k]);
                let w = if s1 > s0 { (x - s0) / (s1 - s0) } else { 1.0 };
                value[k - 1] + (value[k] - value[k - 1]) * w
            }
        }
    }

    /// The uniform value, if the profile is one.
    pub fn uniform(&self) -> Option<f64> {
        match self {
            Self::Uniform(v) => Some(*v),
            _ => None,
        }
    }

    /// The values it passes through (its extremes are among them).
    pub fn knots(&self) -> Vec<f64> {
        match self {
            Self::Uniform(v) => vec![*v],
            Self::Linear(ab) => ab.to_vec(),
            Self::Table { value, .. } => value.clone(),
        }
    }

    /// The smallest value along the segment.
    pub fn min(&self) -> f64 {
        self.knots().into_iter().fold(f64::INFINITY, f64::min)
    }

    /// The largest value along the segment.
    pub fn max(&self) -> f64 {
        self.knots().into_iter().fold(f64::NEG_INFINITY, f64::max)
    }

    /// The fractions where it bends (the ends and a table's points): a
    /// value linear between them is extreme at one of them.
    pub fn breaks(&self) -> Vec<f64> {
        match self {
            Self::Table { s, .. } => s.clone(),
            _ => vec![0.0, 1.0],
        }
    }

    /// What is wrong with a table's points, if anything.
    fn table_error(s: &[f64], value: &[f64]) -> Option<String> {
        if s.len() != value.len() || s.len() < 2 {
            return Some(format!(
                "a table needs as many s as values, at least two ({} s, {} values)",
                s.len(),
                value.len()
            ));
        }
        let rising = s.windows(2).all(|w| w[0] < w[1]);
        if s[0] != 0.0 || s[s.len() - 1] != 1.0 || !rising {
            return Some(format!(
                "a table's s are fractions of the segment's length, rising from 0 to 1 (got {s:?})"
            ));
        }
        None
    }
}

impl From<f64> for Profile {
    fn from(v: f64) -> Self {
        Self::Uniform(v)
    }
}

const EXPECTED: &str = "a number, a linear taper [start, end], or a table { s = [0.0, ..., 1.0], value = [...] } over the fraction of the segment's length";

impl<'de> Deserialize<'de> for Profile {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct ProfileVisitor;

        impl<'de> Visitor<'de> for ProfileVisitor {
            type Value = Profile;

            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str(EXPECTED)
            }

            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Profile, E> {
                Ok(Profile::Uniform(v))
            }

            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Profile, E> {
                Ok(Profile::Uniform(v as f64))
            }

            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Profile, E> {
                Ok(Profile::Uniform(v as f64))
            }

            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Profile, A::Error> {
                let mut ends = Vec::new();
                while let Some(v) = seq.next_element::<f64>()? {
                    ends.push(v);
                }
                match ends[..] {
                    [a, b] => Ok(Profile::Linear([a, b])),
                    _ => Err(de::Error::custom(format!(
                        "a linear taper is [start, end], two numbers (got {}); for more points give a table {{ s = [...], value = [...] }}",
                        ends.len()
                    ))),
                }
            }

            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Profile, A::Error> {
                let (mut s, mut value) = (None, None);
                while let Some(key) = map.next_key::<String>()? {
                    match key.as_str() {
                        "s" => s = Some(map.next_value::<Vec<f64>>()?),
                        "value" => value = Some(map.next_value::<Vec<f64>>()?),
                        other => {
                            return Err(de::Error::custom(format!(
                                "unknown key `{other}` in a table: it takes `s` and `value`"
                            )));
                        }
                    }
                }
                let (Some(s), Some(value)) = (s, value) else {
                    return Err(de::Error::custom("a table takes both `s` and `value`"));
                };
                match Profile::table_error(&s, &value) {
                    Some(e) => Err(de::Error::custom(e)),
                    None => Ok(Profile::Table { s, value }),
                }
            }
        }

        d.deserialize_any(ProfileVisitor)
    }
}

impl Serialize for Profile {
    fn serialize<S: Serializer>(&self, ser: S) -> Result<S::Ok, S::Error> {
        match self {
            Self::Uniform(v) => ser.serialize_f64(*v),
            Self::Linear(ab) => ab.serialize(ser),
            Self::Table { s, value } => {
                let mut map = ser.serialize_map(Some(2))?;
                map.serialize_entry("s", s)?;
                map.serialize_entry("value", value)?;
                map.end()
            }
        }
    }
}

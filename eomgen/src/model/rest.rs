//! A segment's shape at rest: its curvature (one value in the plane; in 3D
//! `[k_y, k_z]` about the section's y and z axes, or one value about z),
//! twist and stretch, each a `Profile` along the segment.

use std::fmt;

use serde::de::{self, Deserializer, SeqAccess, Visitor};
use serde::{Deserialize, Serialize, Serializer};

use super::profile::Profile;

/// `rest_curvature` as written: one profile, or two. A pair of numbers is
/// a taper in the plane and `[k_y, k_z]` in 3D (`RestCurvature::axes`).
#[derive(Clone, Debug, PartialEq)]
pub enum RestCurvature {
    One(Profile),
    Two([Profile; 2]),
}

impl Default for RestCurvature {
    fn default() -> Self {
        Self::One(Profile::Uniform(0.0))
    }
}

impl RestCurvature {
    /// The curvatures about y and z (3D) or about the plane's normal (in
    /// slot z, y zero), and whether y was given (a 3D rest shape).
    pub fn axes(&self, spatial: bool) -> ([Profile; 2], bool) {
        let zero = Profile::Uniform(0.0);
        match self {
            Self::One(p) => ([zero, p.clone()], false),
            Self::Two(pair) if spatial => (pair.clone(), true),
            Self::Two([a, b]) => match (a.uniform(), b.uniform()) {
                (Some(a), Some(b)) => ([zero, Profile::Linear([a, b])], false),
                // Refused by validation (`planar_error`).
                _ => ([zero, a.clone()], false),
            },
        }
    }

    /// What is wrong with it in a planar arm, if anything.
    pub fn planar_error(&self) -> Option<&'static str> {
        match self {
            Self::Two([a, b]) if a.uniform().is_none() || b.uniform().is_none() => Some(
                "a planar arm bends about one axis: give one curvature, a taper [base, tip] or a table",
            ),
            _ => None,
        }
    }
}

impl<'de> Deserialize<'de> for RestCurvature {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct RestVisitor;

        impl<'de> Visitor<'de> for RestVisitor {
            type Value = RestCurvature;

            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a curvature (1/m): a number, [k_y, k_z] in 3D (each a number, a taper or a table), or in the plane a taper [base, tip] or a table")
            }

            fn visit_f64<E: de::Error>(self, v: f64) -> Result<RestCurvature, E> {
                Ok(RestCurvature::One(Profile::Uniform(v)))
            }

            fn visit_i64<E: de::Error>(self, v: i64) -> Result<RestCurvature, E> {
                self.visit_f64(v as f64)
            }

            fn visit_u64<E: de::Error>(self, v: u64) -> Result<RestCurvature, E> {
                self.visit_f64(v as f64)
            }

            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<RestCurvature, A::Error> {
                let mut items = Vec::new();
                while let Some(p) = seq.next_element::<Profile>()? {
                    items.push(p);
                }
                match <[Profile; 2]>::try_from(items) {
                    Ok(pair) => Ok(RestCurvature::Two(pair)),
                    Err(items) => Err(de::Error::custom(format!(
                        "give two values, [k_y, k_z] in 3D or [base, tip] in the plane (got {})",
                        items.len()
                    ))),
                }
            }

            fn visit_map<A: de::MapAccess<'de>>(self, map: A) -> Result<RestCurvature, A::Error> {
                let p = Profile::deserialize(de::value::MapAccessDeserializer::new(map))?;
                Ok(RestCurvature::One(p))
            }
        }

        d.deserialize_any(RestVisitor)
    }
}

impl Serialize for RestCurvature {
    fn serialize<S: Serializer>(&self, ser: S) -> Result<S::Ok, S::Error> {
        match self {
            Self::One(p) => p.serialize(ser),
            Self::Two(pair) => pair.serialize(ser),
        }
    }
}

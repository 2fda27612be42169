//! Floating-point numbers in JSON. JSON has no infinities or NaN, and
//! serde_json writes them as `null`, which reads back as "missing" — a
//! diverged run's `max_abs_phi = inf` would silently vanish. Here finite
//! values stay numbers (byte for byte as serde_json writes them) and the
//! others become the strings `"inf"`, `"-inf"` and `"NaN"`, which read back
//! as the same values.
//!
//! Use it on a field of type `f64`, `Option<f64>` or `Vec<f64>`:
//!
//! ```
//! #[derive(serde::Serialize, serde::Deserialize)]
//! struct Point {
//!     #[serde(with = "cdyn::json_float")]
//!     max_abs_phi: f64,
//! }
//! ```
//!
//! or wrap a single value in [`JsonFloat`].

use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// An `f64` that serializes as a number when finite and as `"inf"`,
/// `"-inf"` or `"NaN"` otherwise, and deserializes from either.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JsonFloat(pub f64);

impl Serialize for JsonFloat {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let x = self.0;
        if x.is_finite() {
            s.serialize_f64(x)
        } else if x.is_nan() {
            s.serialize_str("NaN")
        } else if x > 0.0 {
            s.serialize_str("inf")
        } else {
            s.serialize_str("-inf")
        }
    }
}

impl<'de> Deserialize<'de> for JsonFloat {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        /// What a JSON float may be written as.
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum Written {
            Number(f64),
            Text(String),
        }
        match Written::deserialize(d)? {
            Written::Number(x) => Ok(JsonFloat(x)),
            Written::Text(t) => match t.as_str() {
                "inf" => Ok(JsonFloat(f64::INFINITY)),
                "-inf" => Ok(JsonFloat(f64::NEG_INFINITY)),
                "NaN" => Ok(JsonFloat(f64::NAN)),
                _ => Err(serde::de::Error::custom(format!(
                    "expected a number, \"inf\", \"-inf\" or \"NaN\", found {t:?}"
                ))),
            },
        }
    }
}

/// The field types [`serialize`] and [`deserialize`] handle.
pub trait Floats: Sized {
    /// Serializes, with every `f64` as a [`JsonFloat`].
    fn serialize_floats<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error>;
    /// Deserializes, reading every `f64` as a [`JsonFloat`].
    fn deserialize_floats<'de, D: Deserializer<'de>>(d: D) -> Result<Self, D::Error>;
}

impl Floats for f64 {
    fn serialize_floats<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        JsonFloat(*self).serialize(s)
    }
    fn deserialize_floats<'de, D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        Ok(JsonFloat::deserialize(d)?.0)
    }
}

impl Floats for Option<f64> {
    fn serialize_floats<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.map(JsonFloat).serialize(s)
    }
    fn deserialize_floats<'de, D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        Ok(Option::<JsonFloat>::deserialize(d)?.map(|x| x.0))
    }
}

impl Floats for Vec<f64> {
    fn serialize_floats<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(self.iter().map(|&x| JsonFloat(x)))
    }
    fn deserialize_floats<'de, D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        Ok(Vec::<JsonFloat>::deserialize(d)?.into_iter().map(|x| x.0).collect())
    }
}

/// `#[serde(with = "cdyn::json_float")]`: serializes the field's floats as [`JsonFloat`]s.
pub fn serialize<T: Floats, S: Serializer>(value: &T, s: S) -> Result<S::Ok, S::Error> {
    value.serialize_floats(s)
}

/// `#[serde(with = "cdyn::json_float")]`: deserializes the field's floats as [`JsonFloat`]s.
pub fn deserialize<'de, T: Floats, D: Deserializer<'de>>(d: D) -> Result<T, D::Error> {
    T::deserialize_floats(d)
}

//! Functions of time for drives and applied loads, written once for every
//! scalar type so that `Φ_t`, `Φ_tt` come from the same dual passes as
//! everything else; one may add an input's value, set from outside between
//! steps (a controller's torque, a drive's target).

use crate::ad::scalar::Scalar;
use crate::model::input::Input;

/// `f(t) = Σ_k c_k t^k + Σ_j a_j sin(ω_j t + φ_j) + g u`, `u` the current
/// value of an [`Input`] and `g` its gain, where one is given.
///
/// The input's term is a constant within a step, with no time derivative:
/// a drive whose target is an input holds `Φ_t = 0` between changes, and a
/// change shows as a jump of `Φ` that the constraint stabilization (or the
/// projection, or the scheme that holds `Φ = 0` itself) removes.
#[derive(Debug, Clone, PartialEq, Default)]
#[non_exhaustive]
pub struct TimeFn {
    /// Polynomial coefficients `c_0, c_1, …`.
    pub polynomial: Vec<f64>,
    /// Sine terms `(amplitude, angular frequency, phase)`.
    pub sines: Vec<[f64; 3]>,
    /// An input and its gain `g`. Not part of the scenario format: a
    /// scenario's `[[inputs]]` put it in.
    pub input: Option<(Input, f64)>,
}

crate::setters!(TimeFn {
    /// With these polynomial coefficients `c_0, c_1, …`.
    with_polynomial => polynomial: Vec<f64>,
    /// With these sine terms `(amplitude, angular frequency, phase)`.
    with_sines => sines: Vec<[f64; 3]>,
    /// Plus this input times this gain.
    with_input => input(Some): (Input, f64),
});

impl TimeFn {
    /// `f(t) = c`.
    pub fn constant(c: f64) -> Self {
        Self::polynomial(vec![c])
    }

    /// `c0 + c1 t`.
    pub fn linear(c0: f64, c1: f64) -> Self {
        Self::polynomial(vec![c0, c1])
    }

    /// `Σ_k c_k t^k` with these coefficients `c_0, c_1, …`.
    pub fn polynomial(coefficients: Vec<f64>) -> Self {
        Self { polynomial: coefficients, sines: Vec::new(), input: None }
    }

    /// `a sin(ω t + φ)`.
    pub fn sine(amplitude: f64, omega: f64, phase: f64) -> Self {
        Self { polynomial: Vec::new(), sines: vec![[amplitude, omega, phase]], input: None }
    }

    /// `f(t) = u`, the current value of `input`.
    pub fn input(input: &Input) -> Self {
        Self { polynomial: Vec::new(), sines: Vec::new(), input: Some((input.clone(), 1.0)) }
    }

    /// `−f(t)`.
    pub fn negated(&self) -> Self {
        Self {
            polynomial: self.polynomial.iter().map(|c| -c).collect(),
            sines: self.sines.iter().map(|&[a, w, phase]| [-a, w, phase]).collect(),
            input: self.input.as_ref().map(|(u, g)| (u.clone(), -g)),
        }
    }

    /// `ḟ(t)` as a function of its own: the polynomial and sine terms
    /// differentiated; the input's term, constant between steps, drops out
    /// (as it does from a drive's `Φ_t`).
    pub fn derivative(&self) -> Self {
        let polynomial = self.polynomial.iter().enumerate().skip(1).map(|(k, c)| k as f64 * c).collect();
        let quarter = std::f64::consts::FRAC_PI_2;
        let sines = self.sines.iter().map(|&[a, w, phase]| [a * w, w, phase + quarter]).collect();
        Self { polynomial, sines, input: None }
    }

    /// `f(t)`, for any scalar type (dual numbers give `ḟ`, `f̈`).
    pub fn eval<D: Scalar>(&self, t: D) -> D {
        // Horner for the polynomial.
        let mut p = D::from(0.0);
        for &c in self.polynomial.iter().rev() {
            p = p * t + c;
        }
        for &[a, w, phase] in &self.sines {
            p += (t * w + phase).sin() * a;
        }
        if let Some((u, g)) = &self.input {
            p += g * u.value();
        }
        p
    }

    /// Whether every coefficient is finite (an input's value is checked when it is set).
    pub fn is_finite(&self) -> bool {
        let gain = self.input.as_ref().map(|(_, g)| *g);
        self.polynomial.iter().chain(self.sines.iter().flatten()).chain(&gain).all(|c| c.is_finite())
    }
}

/// In scenario files a function of time is a number (a constant) or a table
/// `{ polynomial = [c0, c1, …], sine = [[amplitude, ω, phase], …] }` with at
/// least one of the two keys; any other key is refused, so a misspelt key
/// cannot silently leave `f(t) = 0`.
#[cfg(feature = "serde")]
mod serde_format {
    use super::TimeFn;
    use serde::de::{self, Deserializer, MapAccess, Visitor, value::MapAccessDeserializer};
    use serde::{Deserialize, Serialize, Serializer};

    #[derive(Deserialize, Serialize)]
    #[serde(deny_unknown_fields)]
    struct Terms {
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        polynomial: Vec<f64>,
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        sine: Vec<[f64; 3]>,
    }

    struct TimeFnVisitor;

    impl<'de> Visitor<'de> for TimeFnVisitor {
        type Value = TimeFn;

        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            f.write_str("a number, or a table with `polynomial` and/or `sine`")
        }

        fn visit_f64<E: de::Error>(self, c: f64) -> Result<TimeFn, E> {
            Ok(TimeFn::constant(c))
        }

        fn visit_i64<E: de::Error>(self, c: i64) -> Result<TimeFn, E> {
            Ok(TimeFn::constant(c as f64))
        }

        fn visit_u64<E: de::Error>(self, c: u64) -> Result<TimeFn, E> {
            Ok(TimeFn::constant(c as f64))
        }

        fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<TimeFn, A::Error> {
            let Terms { polynomial, sine } = Terms::deserialize(MapAccessDeserializer::new(map))?;
            if polynomial.is_empty() && sine.is_empty() {
                return Err(de::Error::custom(
                    "a function of time needs `polynomial` or `sine` terms (write 0.0 for f(t) = 0)",
                ));
            }
            Ok(TimeFn { polynomial, sines: sine, input: None })
        }
    }

    impl<'de> Deserialize<'de> for TimeFn {
        fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
            deserializer.deserialize_any(TimeFnVisitor)
        }
    }

    impl Serialize for TimeFn {
        fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
            Terms { polynomial: self.polynomial.clone(), sine: self.sines.clone() }.serialize(serializer)
        }
    }
}

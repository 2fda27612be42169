//! Inputs of a planar mechanism: an [`Input`] drives one key of one
//! element — a force's `fx` or `fy`, a torque's `torque`, a drive's
//! `function`, a spring's `rest_length`, a torsion spring's `rest_angle` —
//! and takes that key's place: the key's value is the input's.

use super::element::Element;
use crate::error::{Problem, Result};
use crate::model::input::{Input, Parameter};
use crate::model::timefn::TimeFn;

/// An input driving the key `key` of element `element` (its position in
/// [`Mechanism::elements`](super::Mechanism::elements)); see [`Mechanism::drive`](super::Mechanism::drive).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Driven {
    /// The element's position.
    pub element: usize,
    /// The key, as scenario files write it (`rest_length`).
    pub key: String,
    /// The input.
    pub input: Input,
}

impl<B> Element<B> {
    /// The keys of this element that an input may drive ([`input_keys`]).
    pub fn input_keys(&self) -> &'static [&'static str] {
        input_keys(self.kind())
    }
}

/// The keys that an input may drive of an element of `kind` (its name in
/// scenario files, [`Element::kind`]).
pub fn input_keys(kind: &str) -> &'static [&'static str] {
    match kind {
        "force" => &["fx", "fy"],
        "torque" => &["torque"],
        "coordinate" | "relative_angle" => &["function"],
        "spring" => &["rest_length"],
        "torsion_spring" => &["rest_angle"],
        _ => &[],
    }
}

/// `e` with the keys in `driven` given to their inputs: a function of time
/// becomes the input's value ([`TimeFn::input`]); a constant (a rest length
/// or angle) is returned as the [`Parameter`] its element reads.
pub(super) fn wire(e: &Element, driven: &[&Driven]) -> Result<(Element, Option<Parameter>)> {
    let mut e = e.clone();
    let mut constant = None;
    for (j, d) in driven.iter().enumerate() {
        let refuse = |reason: String| Problem::InputKey { input: d.input.name().into(), key: d.key.clone(), reason };
        if !e.input_keys().contains(&d.key.as_str()) {
            let keys = e.input_keys();
            let takes = if keys.is_empty() { "none".to_string() } else { keys.join(", ") };
            return Err(
                refuse(format!("a {} has no key an input drives by that name (it has: {takes})", e.kind())).into()
            );
        }
        if driven[..j].iter().any(|earlier| earlier.key == d.key) {
            return Err(refuse("driven by two inputs".into()).into());
        }
        let function = TimeFn::input(&d.input);
        match (&mut e, d.key.as_str()) {
            (Element::AppliedForce { fx, .. }, "fx") => *fx = function,
            (Element::AppliedForce { fy, .. }, "fy") => *fy = function,
            (Element::AppliedTorque { f, .. }, _) | (Element::DriveCoordinate { f, .. }, _) => *f = function,
            (Element::DriveAngle { f, .. }, _) => *f = function,
            _ => constant = Some(Parameter::Input(d.input.clone())),
        }
    }
    Ok((e, constant))
}

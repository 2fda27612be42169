//! The invariants a scenario declares (`[[invariants]]`), declared on the
//! model it builds.

use crate::case::scenario::InvariantSpec;
use cdyn::models::Example;

impl InvariantSpec {
    /// Declares it on `example`'s model.
    pub(super) fn declare(&self, example: &mut Example) -> std::result::Result<(), String> {
        let names = example.model.coordinate_names().ok_or("needs a mechanism, whose coordinates have names")?;
        let spatial = example.sketch.is_some();
        let (name, direction) = match self {
            InvariantSpec::Momentum { axis, name } => {
                let suffixes: &[&str] = if spatial { &[".x", ".y", ".z"] } else { &[".x", ".y"] };
                if axis.len() != suffixes.len() || axis.iter().any(|a| !a.is_finite()) || axis.iter().all(|a| *a == 0.0)
                {
                    return Err(format!("axis = {axis:?}: must be {} finite numbers, not all zero", suffixes.len()));
                }
                let direction = names
                    .iter()
                    .enumerate()
                    .filter_map(|(i, n)| suffixes.iter().position(|s| n.ends_with(s)).map(|k| (i, axis[k])))
                    .filter(|(_, w)| *w != 0.0)
                    .collect();
                (name.clone().unwrap_or_else(|| format!("linear momentum along {axis:?}")), direction)
            }
            InvariantSpec::AngularMomentum { axis, point, name } => {
                let axis = match axis.as_deref() {
                    None => [0.0, 0.0, 1.0],
                    Some(&[x, y, z]) if spatial => [x, y, z],
                    Some(a) => {
                        let expected = if spatial { "3 numbers" } else { "left out: a planar mechanism turns about z" };
                        return Err(format!("axis = {a:?}: must be {expected}"));
                    }
                };
                let width = if spatial { 3 } else { 2 };
                let point = match point.as_deref() {
                    None => [0.0; 3],
                    Some(p) if p.len() == width => std::array::from_fn(|i| p.get(i).copied().unwrap_or(0.0)),
                    Some(p) => return Err(format!("point = {p:?}: must be {width} numbers")),
                };
                let label =
                    name.clone().unwrap_or_else(|| format!("angular momentum about {axis:?} through {point:?}"));
                let g = cdyn::model::angular::Generator::rotation(&label, names, axis, point, true)?;
                return example.model.declare_angular_momentum(g).map_err(|e| e.to_string());
            }
            InvariantSpec::Coordinate { coordinate, name } => {
                let i = names.iter().position(|n| n == coordinate).ok_or_else(|| {
                    format!("coordinate = \"{coordinate}\": no such coordinate (they are {})", names.join(", "))
                })?;
                (name.clone().unwrap_or_else(|| format!("momentum of {coordinate}")), vec![(i, 1.0)])
            }
        };
        example.model.declare_momentum(&name, &direction).map_err(|e| e.to_string())
    }
}

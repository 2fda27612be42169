//! A spatial scenario's model: its mechanism (entries and URDF robot)
//! built, started at `[initial] joints` and `rates` if given, with where
//! its joint columns are and the joint limits the run holds.

use super::Described;
use crate::case::runner::JointColumns;
use crate::case::runner::limits::{Limits, StopName};
use crate::case::scenario::{GravitySpec, InitialSpec, Scenario};
use anyhow::{Result, anyhow, bail};
use cdyn::error::Part;
use cdyn::models::Example;
use cdyn::stops::MechanismStops;
use std::sync::Arc;

impl Scenario {
    /// The spatial mechanism's example, described (see [`Described`]).
    pub(super) fn spatial_example(&self, file: &str) -> Result<Described> {
        let gravity = match self.model.gravity {
            None => [0.0; 3],
            Some(GravitySpec::Vector3(g)) if g.iter().all(|x| x.is_finite()) => g,
            _ => bail!("{file}: [model] gravity: a spatial mechanism takes a finite vector [gx, gy, gz]"),
        };
        let mut entries = self.spatial.clone().unwrap_or_default();
        crate::case::inputs::drive_actuators(&self.inputs, &mut entries.actuators, file)?;
        let (mechanism, counts) = self.spatial_mechanism(file, entries, gravity)?;
        let part = |part: &Part| counts.entry(part);
        let built = mechanism.and_then(|m| m.build().map(|b| (m, b))).map_err(|e| match e {
            cdyn::Error::InvalidModel { at: at @ (Part::Body { .. } | Part::Element { .. }), problem } => {
                anyhow!("{file}: {}: {problem}", part(&at))
            }
            other => anyhow!("{file}: {other}"),
        })?;
        let (mechanism, mut built) = built;
        let mut start = Vec::new();
        if let Some((coordinates, q0, v0)) = self.initial.joint_state(&mechanism, |k| counts.joint_name(k), file)? {
            (start, built.q0, built.v0) = (coordinates, q0, v0);
        }
        let rows = built.rows.iter().map(part).collect();
        let forces = built.forces.iter().map(part).collect();
        let first = built.model.n();
        let example = Example::from_spatial_named(&mechanism, built, |k| counts.joint_name(k));
        let joint_columns = (example.observables.len() > first).then(|| JointColumns {
            first,
            efforts: mechanism
                .actuators
                .iter()
                .map(|a| mechanism.joints[a.joint].limit.map_or(f64::INFINITY, |l| l.effort))
                .collect(),
        });
        let limits = spatial_limits(mechanism, &start, |k| counts.joint_name(k)).map_err(|e| anyhow!("{file}: {e}"))?;
        let notes = counts.notes;
        Ok(Described { example, rows, notes, force_entries: forces, limits, joint_columns })
    }
}

/// The joints' coordinates given, `(index, value)`, and the positions and
/// velocities they place the mechanism at.
type JointStart = (Vec<(usize, f64)>, Vec<f64>, Vec<f64>);

impl InitialSpec {
    /// The state of `mechanism` at `[initial] joints` and `rates`, if given,
    /// each joint named as its output columns are (`name(k)` of joint `k`).
    fn joint_state(
        &self,
        mechanism: &cdyn::spatial::Mechanism,
        name: impl Fn(usize) -> String,
        file: &str,
    ) -> Result<Option<JointStart>> {
        if self.joints.is_none() && self.rates.is_none() {
            return Ok(None);
        }
        let space = mechanism.joint_space().map_err(|e| anyhow!("{file}: {e}"))?;
        let known: Vec<(usize, String)> = space.joints().map(|k| (k, name(k))).collect();
        let pick = |key: &str, given: &Option<std::collections::BTreeMap<String, f64>>| {
            let values = given.iter().flatten().map(|(joint, &value)| match known.iter().find(|(_, n)| n == joint) {
                Some(&(k, _)) => Ok((k, value)),
                None => {
                    let names: Vec<&str> = known.iter().map(|(_, n)| n.as_str()).collect();
                    bail!(
                        "{file}: [initial] {key}: no revolute or prismatic joint {joint:?}; the joints are {}",
                        names.join(", ")
                    )
                }
            });
            values.collect::<Result<Vec<_>>>()
        };
        let (coordinates, rates) = (pick("joints", &self.joints)?, pick("rates", &self.rates)?);
        let (q0, v0) = mechanism.state_at_joints(&coordinates, &rates).map_err(|e| anyhow!("{file}: [initial] {e}"))?;
        Ok(Some((coordinates, q0, v0)))
    }
}

/// The limits of a spatial mechanism's joints, if any has one (a stop, or
/// a velocity bound to report), its joints named by `name`; a multi-turn
/// joint's stops read at the turn of its `[initial] joints` value in `start`.
fn spatial_limits(
    mechanism: cdyn::spatial::Mechanism,
    start: &[(usize, f64)],
    name: impl Fn(usize) -> String,
) -> cdyn::Result<Option<Limits>> {
    if mechanism.joints.iter().all(|j| j.limit.is_none()) {
        return Ok(None);
    }
    let stops = mechanism
        .stops()
        .into_iter()
        .map(|stop| StopName { joint: name(stop.joint), upper: stop.upper, bound: mechanism.stop_bound(stop).0 })
        .collect();
    let joints = (0..mechanism.joints.len()).map(name).collect();
    let system = MechanismStops::new(mechanism)?.starting_at(start)?;
    Ok(Some(Limits { system: Arc::new(system), stops, joints }))
}

//! A spatial scenario's model: its mechanism (entries and URDF robot)
//! built in body coordinates or, with `[model] coordinates = "joints"`, in
//! joint coordinates, started at `[initial] joints` and `rates` if given,
//! with where its joint columns are and the joint limits the run holds.

use super::Described;
use crate::case::runner::JointColumns;
use crate::case::runner::limits::{Limits, StopName};
use crate::case::scenario::{GravitySpec, InitialSpec, Scenario};
use anyhow::{Result, anyhow, bail};
use cdyn::error::Part;
use cdyn::models::Example;
use cdyn::stops::{MechanismStops, TreeStops, Unilateral};
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
        let refused = |e: cdyn::Error| match e {
            cdyn::Error::InvalidModel { at: at @ (Part::Body { .. } | Part::Element { .. }), problem } => {
                anyhow!("{file}: {}: {problem}", part(&at))
            }
            other => anyhow!("{file}: {other}"),
        };
        let mechanism = mechanism.map_err(refused)?;
        let in_joints = match self.model.pendulum_keys.get("coordinates") {
            None => false,
            Some(toml::Value::String(c)) if c == "bodies" => false,
            Some(toml::Value::String(c)) if c == "joints" => true,
            Some(other) => bail!("{file}: [model] coordinates = {other}: expected \"bodies\" or \"joints\""),
        };
        let first = 7 * mechanism.bodies.len();
        let name = |k: usize| counts.joint_name(k);
        let (example, rows, forces, limits, poses) = if in_joints {
            let mut built = mechanism.in_joint_coordinates().map_err(refused)?;
            // The coordinates themselves: a value past a turn is that many turns.
            if let Some((coordinates, rates)) = self.initial.joint_values(&mechanism, name, file)? {
                for (values, state) in [(&coordinates, &mut built.q0), (&rates, &mut built.v0)] {
                    for &(joint, value) in values {
                        let c = built.joints.iter().position(|&j| j == joint).expect("a joint with a coordinate");
                        state[c] = value;
                    }
                }
            }
            let (rows, forces) = (built.rows.iter().map(part).collect(), built.forces.iter().map(part).collect());
            let poses = Some(built.poses.clone());
            let example = Example::from_joint_coordinates(&mechanism, built, name);
            let limits =
                spatial_limits(mechanism.clone(), |k| counts.joint_name(k), |m| Ok(Arc::new(TreeStops::new(m)?)));
            (example, rows, forces, limits, poses)
        } else {
            let mut built = mechanism.build().map_err(refused)?;
            let mut start = Vec::new();
            if let Some((coordinates, rates)) = self.initial.joint_values(&mechanism, name, file)? {
                let (q0, v0) =
                    mechanism.state_at_joints(&coordinates, &rates).map_err(|e| anyhow!("{file}: [initial] {e}"))?;
                (start, built.q0, built.v0) = (coordinates, q0, v0);
            }
            let (rows, forces) = (built.rows.iter().map(part).collect(), built.forces.iter().map(part).collect());
            let example = Example::from_spatial_named(&mechanism, built, name);
            let starting = start.clone();
            let limits = spatial_limits(
                mechanism.clone(),
                |k| counts.joint_name(k),
                move |m| Ok(Arc::new(MechanismStops::new(m)?.starting_at(&starting)?)),
            );
            (example, rows, forces, limits, None)
        };
        let joint_columns = (example.observables.len() > first).then(|| JointColumns {
            first,
            efforts: mechanism
                .actuators
                .iter()
                .map(|a| mechanism.joints[a.joint].limit.map_or(f64::INFINITY, |l| l.effort))
                .collect(),
        });
        let limits = limits.map_err(|e| anyhow!("{file}: {e}"))?;
        let notes = counts.notes;
        Ok(Described { example, rows, notes, force_entries: forces, limits, joint_columns, poses })
    }
}

/// The joints' coordinates and rates given, each `(joint index, value)`.
type JointValues = (Vec<(usize, f64)>, Vec<(usize, f64)>);

impl InitialSpec {
    /// `[initial] joints` and `rates` of `mechanism`, if given, each joint
    /// named as its output columns are (`name(k)` of joint `k`).
    fn joint_values(
        &self,
        mechanism: &cdyn::spatial::Mechanism,
        name: impl Fn(usize) -> String,
        file: &str,
    ) -> Result<Option<JointValues>> {
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
        Ok(Some((pick("joints", &self.joints)?, pick("rates", &self.rates)?)))
    }
}

/// The limits of a spatial mechanism's joints, if any has one (a stop, or
/// a velocity bound to report), its joints named by `name`, its stops
/// those of the system `stops` makes of it (in body or joint coordinates).
fn spatial_limits(
    mechanism: cdyn::spatial::Mechanism,
    name: impl Fn(usize) -> String,
    stops: impl FnOnce(cdyn::spatial::Mechanism) -> cdyn::Result<Arc<dyn Unilateral + Send + Sync>>,
) -> cdyn::Result<Option<Limits>> {
    if mechanism.joints.iter().all(|j| j.limit.is_none()) {
        return Ok(None);
    }
    let named = mechanism
        .stops()
        .into_iter()
        .map(|stop| StopName { joint: name(stop.joint), upper: stop.upper, bound: mechanism.stop_bound(stop).0 })
        .collect();
    let joints = (0..mechanism.joints.len()).map(name).collect();
    Ok(Some(Limits { system: stops(mechanism)?, stops: named, joints }))
}

//! The mechanisms of a scenario's entries: planar from `[[bodies]]`,
//! `[[joints]]`, `[[drives]]`, `[[forces]]`, spatial from those and a URDF
//! robot's; the entry (or URDF element) behind each part, for errors; and
//! a planar mechanism's joint limits, for the run to hold.

use crate::case::runner::limits::{Limits, StopName};
use crate::case::scenario::{Scenario, SpatialEntries, read_bounded};
use anyhow::{Result, anyhow, bail};
use cdyn::error::Part;
use cdyn::planar::{Element, Group, Mechanism};
use cdyn::spatial::{Actuator, JointKind};
use cdyn::stops::PlanarStops;
use std::path::Path;
use std::sync::Arc;

impl Scenario {
    /// The spatial mechanism of the `urdf` file named in `[model]` (relative
    /// to the scenario's folder), if any, and of the `[[bodies]]` and
    /// `[[joints]]` entries, which may name the robot's links; with the
    /// numbers of bodies and joints that come from the robot (first).
    pub(super) fn spatial_mechanism(
        &self,
        file: &str,
        entries: SpatialEntries,
        gravity: [f64; 3],
    ) -> Result<(cdyn::Result<cdyn::spatial::Mechanism>, Counts)> {
        let mut robot = cdyn::spatial::Mechanism::default();
        let (mut joint_names, mut notes, mut merged) = (Vec::new(), Vec::new(), Vec::new());
        match self.model.pendulum_keys.get("urdf") {
            None => {}
            Some(toml::Value::String(name)) => {
                let path = Path::new(file).parent().unwrap_or(Path::new("")).join(name);
                let text = read_bounded(&path).map_err(|e| anyhow!("{file}: [model] urdf = {name:?}: {e}"))?;
                let read = cdyn::spatial::read_urdf(&text, gravity)
                    .map_err(|e| anyhow!("{file}: [model] urdf = {name:?}: {e}"))?;
                (robot, joint_names, merged) = (read.mechanism, read.joint_names, read.merged);
                if robot.bodies.is_empty() {
                    bail!(
                        "{file}: [model] urdf = {name:?}: nothing moves: every link with a mass is the root or welded to it (the fixed base)"
                    );
                }
                if !read.notes.is_empty() {
                    notes.push(format!("{name}: not modelled: {}", read.notes.join(", ")));
                }
            }
            Some(other) => bail!("{file}: [model] urdf = {other}: expected the path of a URDF file"),
        }
        if robot.bodies.is_empty() && entries.bodies.is_empty() {
            bail!("{file}: a spatial mechanism needs at least one [[bodies]] entry or a urdf file");
        }
        // The robot's joints by name, then the scenario's: one list, so that
        // errors name joints[k] counting the scenario's own from 0 after the robot's.
        let name = |i: usize| robot.bodies[i].name.clone();
        let mut joints: Vec<cdyn::spatial::Joint<String>> =
            robot.joints.iter().map(|j| j.clone().map_bodies(name)).collect();
        let couplings = robot.couplings.clone();
        let counts = Counts {
            robot_bodies: robot.bodies.len(),
            joints: joints.len() + entries.joints.len(),
            loads: entries.forces.len(),
            couplings: couplings.iter().map(|c| joint_names[c.follower].clone()).collect(),
            robot_joints: joint_names,
            notes,
        };
        joints.extend(entries.joints);
        let actuators = counts.actuated_joints(&entries.actuators, &joints, file)?;
        let mut bodies = robot.bodies;
        bodies.extend(entries.bodies);
        let mechanism = cdyn::spatial::Mechanism::named_with_links(bodies, joints, entries.forces, gravity, &merged)
            .map(|m| m.with_couplings(couplings).with_actuators(actuators).with_ground(robot.ground));
        Ok((mechanism, counts))
    }

    /// The entries of one list.
    pub(crate) fn element_list(&self, group: Group) -> &[Element<String>] {
        match group {
            Group::Joints => &self.joints,
            Group::Drives => &self.drives,
            _ => &self.forces,
        }
    }

    /// The element lists in the order the mechanism takes them.
    fn element_lists(&self) -> [(Group, &[Element<String>]); 3] {
        [(Group::Joints, &self.joints), (Group::Drives, &self.drives), (Group::Forces, &self.forces)]
    }

    /// For every element of the mechanism, the entry that describes it (`joints[2] (revolute)`).
    pub(super) fn entries(&self) -> Vec<String> {
        let entry = |group: Group, (i, e): (usize, &Element<String>)| format!("{}[{i}] ({})", group.name(), e.kind());
        self.element_lists()
            .into_iter()
            .flat_map(|(group, list)| list.iter().enumerate().map(move |e| entry(group, e)))
            .collect()
    }

    /// The mechanism of the `[[bodies]]`, `[[joints]]`, `[[drives]]` and
    /// `[[forces]]` entries, its elements in the order of [`Scenario::entries`].
    pub(super) fn mechanism(&self, gravity: [f64; 2]) -> cdyn::Result<Mechanism> {
        let mut m = Mechanism::new(gravity);
        for body in &self.bodies {
            m.push(body.clone());
        }
        for (_, list) in self.element_lists() {
            for element in list {
                m.add_named(element.clone())?;
            }
        }
        Ok(m)
    }

    /// The joint limits of a planar mechanism of the entries, if any joint
    /// has one: its stops and joints named as `joints[k]`.
    pub(super) fn planar_limits(&self, mechanism: Mechanism) -> cdyn::Result<Option<Limits>> {
        if mechanism.elements.iter().all(|e| e.limit().is_none()) {
            return Ok(None);
        }
        let names: Vec<String> = self
            .element_lists()
            .into_iter()
            .flat_map(|(group, list)| (0..list.len()).map(move |i| format!("{}[{i}]", group.name())))
            .collect();
        let stops = mechanism
            .stops()
            .into_iter()
            .map(|stop| StopName {
                joint: names[stop.joint].clone(),
                upper: stop.upper,
                bound: mechanism.stop_bound(stop).0,
            })
            .collect();
        Ok(Some(Limits { system: Arc::new(PlanarStops::new(mechanism)?), stops, joints: names }))
    }
}

/// How many of a spatial mechanism's parts come from its URDF robot,
/// which come first in each list: bodies, joints; then, in the numbering of
/// `Part::Element`, the scenario's loads and the robot's `<mimic>` couplings.
pub(super) struct Counts {
    pub(super) robot_bodies: usize,
    /// Every joint, the robot's and the scenario's.
    pub(super) joints: usize,
    /// The scenario's loads.
    pub(super) loads: usize,
    /// The URDF joint behind each of the robot's joints, and each coupling's follower.
    pub(super) robot_joints: Vec<String>,
    pub(super) couplings: Vec<String>,
    /// What the robot's file holds that is not modelled, for the run to say.
    pub(super) notes: Vec<String>,
}

impl Counts {
    /// Joint `k` as its output columns name it: a robot's by its URDF name,
    /// the scenario's as `joints[i]`, counting them from 0 (as errors do).
    pub(super) fn joint_name(&self, k: usize) -> String {
        let robot_joints = self.robot_joints.len();
        self.robot_joints.get(k).cloned().unwrap_or_else(|| format!("joints[{}]", k - robot_joints))
    }

    /// Each `[[actuators]]` entry on the joint it names as the output
    /// columns do (`shoulder`, `joints[2]`): a revolute or prismatic one,
    /// at most one actuator each (one `NAME.tau` column).
    fn actuated_joints(
        &self,
        actuators: &[Actuator<String>],
        joints: &[cdyn::spatial::Joint<String>],
        file: &str,
    ) -> Result<Vec<Actuator>> {
        let names: Vec<String> = (0..joints.len()).map(|k| self.joint_name(k)).collect();
        let mut taken: Vec<usize> = Vec::new();
        actuators
            .iter()
            .enumerate()
            .map(|(i, actuator)| {
                let at = format!("{file}: actuators[{i}]: joint = {:?}", actuator.joint);
                let Some(k) = names.iter().position(|n| *n == actuator.joint) else {
                    bail!("{at}: no joint of that name; the joints are {}", names.join(", "));
                };
                let kind = joints[k].kind;
                if !matches!(kind, JointKind::Revolute | JointKind::Prismatic) {
                    bail!("{at}: a {} joint: an actuator drives a revolute or prismatic joint", kind.name());
                }
                if let Some(earlier) = taken.iter().position(|&j| j == k) {
                    bail!("{at}: actuators[{earlier}] drives it already: give a joint one actuator");
                }
                taken.push(k);
                Ok(actuator.clone().map_joint(|_| k))
            })
            .collect()
    }

    /// The part as the scenario or the robot names it: `bodies[0] (top)`,
    /// `joints[2] (revolute)`, `forces[1] (spring)`, `urdf link "hand"`,
    /// `urdf joint "elbow" (revolute)`, `urdf joint "finger2" <mimic>`.
    pub(super) fn entry(&self, part: &Part) -> String {
        let robot_joints = self.robot_joints.len();
        let couplings = self.joints + self.loads;
        match part {
            Part::Body { index, name } if *index < self.robot_bodies => format!("urdf link {name:?}"),
            Part::Body { index, name } => format!("bodies[{}] ({name})", index - self.robot_bodies),
            Part::Element { index, kind } if *index < robot_joints => {
                format!("urdf joint {:?} ({kind})", self.robot_joints[*index])
            }
            Part::Element { index, kind } if *index < self.joints => {
                format!("joints[{}] ({kind})", index - robot_joints)
            }
            Part::Element { index, kind } if *index < couplings => format!("forces[{}] ({kind})", index - self.joints),
            Part::Element { index, .. } if *index < couplings + self.couplings.len() => {
                format!("urdf joint {:?} <mimic>", self.couplings[index - couplings])
            }
            Part::Element { index, kind: "actuator" } => {
                format!("actuators[{}]", index - couplings - self.couplings.len())
            }
            other => other.to_string(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_robots_parts_are_named_as_its_urdf_names_them() {
        // A robot of two links, joints "shoulder" and "elbow" (which
        // mimics the shoulder), then the scenario's one body, two joints and one force.
        let counts = Counts {
            robot_bodies: 2,
            joints: 4,
            loads: 1,
            robot_joints: vec!["shoulder".into(), "elbow".into()],
            couplings: vec!["elbow".into()],
            notes: Vec::new(),
        };
        let element = |index, kind| counts.entry(&Part::Element { index, kind });
        assert_eq!(counts.entry(&Part::Body { index: 1, name: "fore".into() }), "urdf link \"fore\"");
        assert_eq!(counts.entry(&Part::Body { index: 2, name: "weight".into() }), "bodies[0] (weight)");
        assert_eq!(element(1, "revolute"), "urdf joint \"elbow\" (revolute)");
        assert_eq!(element(3, "distance"), "joints[1] (distance)");
        assert_eq!(element(4, "spring"), "forces[0] (spring)");
        assert_eq!(element(5, "mimic"), "urdf joint \"elbow\" <mimic>");
    }
}

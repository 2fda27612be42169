//! A mechanism's actuators as force elements on its joints, and the
//! reader of the torques they apply.

use super::actuator::{Actuator, ActuatorTorques, JointActuator};
use super::mechanism::{Mechanism, Pose, Reads, reads};
use crate::error::{Part, Problem, Result};
use crate::model::ModelBuilder;
use crate::model::input::Input;

impl Mechanism {
    /// Adds every actuator's element, the inputs its functions read
    /// declared once each, and its part (`actuator`, numbered after the
    /// joints, loads and couplings) to `forces`.
    pub(super) fn add_actuators(
        &self,
        mut builder: ModelBuilder,
        poses: &[Pose],
        forces: &mut Vec<Part>,
    ) -> Result<ModelBuilder> {
        builder = self.declare_inputs(builder);
        for (k, actuator) in self.actuators.iter().enumerate() {
            let at = self.actuator_part(k);
            let element = self.joint_actuator(actuator, poses).map_err(|e| e.at(at.clone()))?;
            builder = match reads(&self.joints[actuator.joint]) {
                Reads::Ground(at) => builder.force(element, at),
                Reads::Bodies(at) => builder.force(element, at),
            };
            forces.push(at);
        }
        Ok(builder)
    }

    /// Declares every input the actuators read, once each.
    pub(super) fn declare_inputs(&self, mut builder: ModelBuilder) -> ModelBuilder {
        let mut declared: Vec<&Input> = Vec::new();
        for (input, _) in self.actuators.iter().flat_map(|a| a.functions()).filter_map(|f| f.input.as_ref()) {
            if !declared.contains(&input) {
                builder = builder.input(input);
                declared.push(input);
            }
        }
        builder
    }

    /// How errors name actuator `k`: after the joints, loads and couplings.
    pub(super) fn actuator_part(&self, k: usize) -> Part {
        Part::Element { index: self.joints.len() + self.loads.len() + self.couplings.len() + k, kind: "actuator" }
    }

    /// Actuator `actuator`'s element, checked: on a revolute or prismatic joint.
    fn joint_actuator(&self, actuator: &Actuator, poses: &[Pose]) -> Result<JointActuator> {
        let coordinate = self.coordinate(actuator.joint, poses)?;
        let limit = self.joints[actuator.joint].limit;
        let effort = limit.map_or(f64::INFINITY, |l| l.effort);
        Ok(JointActuator { law: actuator.law(effort)?, coordinate, range: coordinate.range(limit) })
    }

    /// The reader of the torque each actuator applies (see
    /// [`ActuatorTorques::at`]), for reading it at many states.
    pub fn actuator_torques(&self) -> Result<ActuatorTorques> {
        let poses = self.poses()?;
        let read = self.actuators.iter().map(|act| {
            let j = self.joints.get(act.joint).ok_or(Problem::NoSuchJoint { index: act.joint })?;
            Ok((act.joint, self.joint_actuator(act, &poses)?, j.a, j.b))
        });
        Ok(ActuatorTorques::new(read.collect::<Result<_>>()?))
    }
}

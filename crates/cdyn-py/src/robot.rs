//! A URDF robot's joint coordinates at states given from Python, in body
//! coordinates and in joint coordinates: what the
//! tests against Pinocchio compare (`python/tests/test_robots.py`).

use crate::ScenarioError;
use pyo3::prelude::*;
use std::path::PathBuf;

/// What `urdf_joints` returns: the bodies' names, the zero pose's state,
/// the joints' names, their `(θ, θ̇, θ̈)` at each state, and the seconds the
/// dynamics' evaluations took.
type UrdfJoints = (Vec<String>, Vec<f64>, Vec<f64>, Vec<String>, Vec<Vec<[f64; 3]>>, f64);

/// A URDF robot's joints at given states of its bodies: the robot as
/// `cdyn run robot.urdf` builds it, each state `(q, v)` in its redundant
/// coordinates evaluated by the library's dynamics (no control: the
/// accelerations of Eq. 8), and every revolute and prismatic joint's
/// coordinate, rate and acceleration there
/// (`spatial::Mechanism::joint_coordinates`).
#[pyfunction]
#[pyo3(signature = (path, gravity, q, v))]
pub(crate) fn urdf_joints(
    py: Python<'_>,
    path: PathBuf,
    gravity: [f64; 3],
    q: Vec<Vec<f64>>,
    v: Vec<Vec<f64>>,
) -> PyResult<UrdfJoints> {
    let fail = |e: String| ScenarioError::new_err(format!("{}: {e}", path.display()));
    let text = std::fs::read_to_string(&path).map_err(|e| fail(e.to_string()))?;
    py.detach(|| {
        let robot = cdyn::spatial::read_urdf(&text, gravity).map_err(|e| e.to_string())?;
        let mechanism = &robot.mechanism;
        let built = mechanism.build().map_err(|e| e.to_string())?;
        let model = &built.model;
        let mut dynamics = cdyn::dynamics::Dynamics::new(model);
        if q.len() != v.len() {
            return Err(format!("{} positions and {} velocities: one of each per state", q.len(), v.len()));
        }
        let (mut seconds, mut joints) = (0.0, Vec::with_capacity(q.len()));
        for (q, v) in q.iter().zip(&v) {
            if q.len() != model.n() || v.len() != model.n() {
                return Err(format!(
                    "a state of {} and {} values, the robot has {} coordinates",
                    q.len(),
                    v.len(),
                    model.n()
                ));
            }
            let start = std::time::Instant::now();
            dynamics.evaluate(model, q, v, 0.0).map_err(|e| format!("{e:?}"))?;
            seconds += start.elapsed().as_secs_f64();
            let theta = mechanism.joint_coordinates(q, v, dynamics.acc()).map_err(|e| e.to_string())?;
            joints.push(theta.into_iter().flatten().collect());
        }
        let bodies = mechanism.bodies.iter().map(|b| b.name.clone()).collect();
        let names = mechanism
            .joints
            .iter()
            .zip(&robot.joint_names)
            .filter(|(j, _)| matches!(j.kind, cdyn::spatial::JointKind::Revolute | cdyn::spatial::JointKind::Prismatic))
            .map(|(_, n)| n.clone())
            .collect();
        Ok((bodies, built.q0.clone(), built.v0.clone(), names, joints, seconds))
    })
    .map_err(fail)
}

/// What `urdf_tree` returns: the coordinates' joint names, `θ̈` at each
/// state, and the seconds the dynamics' evaluations took.
type UrdfTree = (Vec<String>, Vec<Vec<f64>>, f64);

/// A URDF robot in joint coordinates
/// (`spatial::Mechanism::in_joint_coordinates`): at each state `(θ, θ̇)`,
/// one value per coordinate in the order of the names returned, the
/// accelerations `θ̈` of its dynamics (no control).
#[pyfunction]
#[pyo3(signature = (path, gravity, theta, rate))]
pub(crate) fn urdf_tree(
    py: Python<'_>,
    path: PathBuf,
    gravity: [f64; 3],
    theta: Vec<Vec<f64>>,
    rate: Vec<Vec<f64>>,
) -> PyResult<UrdfTree> {
    let fail = |e: String| ScenarioError::new_err(format!("{}: {e}", path.display()));
    let text = std::fs::read_to_string(&path).map_err(|e| fail(e.to_string()))?;
    py.detach(|| {
        let robot = cdyn::spatial::read_urdf(&text, gravity).map_err(|e| e.to_string())?;
        let built = robot.mechanism.in_joint_coordinates().map_err(|e| e.to_string())?;
        let model = &built.model;
        if theta.len() != rate.len() {
            return Err(format!("{} positions and {} rates: one of each per state", theta.len(), rate.len()));
        }
        let mut dynamics = cdyn::dynamics::Dynamics::new(model);
        let (mut seconds, mut accelerations) = (0.0, Vec::with_capacity(theta.len()));
        for (q, v) in theta.iter().zip(&rate) {
            if q.len() != model.n() || v.len() != model.n() {
                let n = model.n();
                return Err(format!(
                    "a state of {} and {} values, the robot has {n} joint coordinates",
                    q.len(),
                    v.len()
                ));
            }
            let start = std::time::Instant::now();
            dynamics.evaluate(model, q, v, 0.0).map_err(|e| format!("{e:?}"))?;
            seconds += start.elapsed().as_secs_f64();
            accelerations.push(dynamics.acc().to_vec());
        }
        let names = built.joints.iter().map(|&k| robot.joint_names[k].clone()).collect();
        Ok((names, accelerations, seconds))
    })
    .map_err(fail)
}

//! From a scenario to the case it runs: the model (built-in, planar or
//! spatial mechanism, URDF robot), its consistent initial state, the method
//! and the settings; a model's error names the scenario entry that made it.

use crate::case::runner::Case;
use crate::case::scenario::{GravitySpec, InvariantSpec, Scenario, SpatialEntries, read_bounded};
use crate::case::wording::{locate, reason};
use anyhow::{Result, anyhow, bail};
use cdyn::Settings;
use cdyn::control::methods::{MethodKeys, Preset};
use cdyn::dynamics::assemble::assemble_with;
use cdyn::error::{Part, positive};
use cdyn::models::{Example, Kind};
use cdyn::planar::{Element, Group, Mechanism};
use cdyn::simulate::{nearest_valid_t_end, steps_to};
use std::path::Path;

/// The built-in model `kind`, its parameters read from `parameters`, which
/// the file writes as the table `[within]`; errors name the table, the key
/// and the value.
fn builtin(file: &str, kind: Kind, within: &str, parameters: toml::Table) -> Result<Example> {
    let mut track = serde_path_to_error::Track::new();
    let tracked = serde_path_to_error::Deserializer::new(toml::Value::Table(parameters.clone()), &mut track);
    let built = kind.example(tracked).map_err(|e| {
        let place = locate(&[within], &parameters, &track.path());
        anyhow!("{file}: {place}{}", reason(&e))
    })?;
    built.map_err(|e| anyhow!("{file}: [{within}]: {e}"))
}

impl Scenario {
    /// Refuses a `[sweep]` table for a `command` that runs the scenario as
    /// written (`run`, `compare`): it would be ignored without a word.
    pub fn refuse_sweep(&self, path: &Path, command: &str) -> Result<()> {
        if self.sweep.is_some() {
            bail!(
                "{}: [sweep] is read by `cdyn sweep` only; `cdyn {command}` would ignore it: run `cdyn sweep`, or remove the table",
                path.display()
            );
        }
        Ok(())
    }

    /// The method as written; without `[method]`, the `robust` preset, or
    /// no control for `rattle` and `generalized_alpha`, which hold the
    /// constraints themselves.
    pub fn method(&self) -> MethodKeys {
        let default = match self.integrator.scheme {
            s if s.steps_model() => MethodKeys::default(),
            _ => MethodKeys::default().with_preset(Preset::Robust),
        };
        self.method.clone().unwrap_or(default)
    }

    /// The case this scenario describes; `path` names it in errors.
    pub fn case(&self, path: &Path) -> Result<Case> {
        let file = &path.display().to_string();
        let control = self.method().control().map_err(|e| anyhow!("{file}: [method] {e}"))?;
        let i = &self.integrator;
        let integrator = |e| anyhow!("{file}: [integrator] {e}");
        let h = positive("h", i.h).map_err(integrator)?;
        let t_end = positive("t_end", i.t_end).map_err(integrator)?;
        if t_end / h > 1e9 {
            bail!("{file}: [integrator] t_end / h = {:e} steps is more than 1e9", t_end / h);
        }
        // The library's rule: t_end is a whole number of steps h.
        steps_to(t_end, h).map_err(|e| match e {
            cdyn::Error::InvalidParameter { name, reason, .. } => anyhow!(
                "{file}: [integrator] h = {h}, t_end = {t_end}: {name} {reason}; the nearest valid t_end is {}",
                nearest_valid_t_end(t_end, h)
            ),
            other => integrator(other),
        })?;
        let mut settings = Settings::new(i.scheme, h, control)
            .with_dependent_rows(i.dependent_rows)
            .with_generalized_alpha(i.generalized_alpha().map_err(|e| anyhow!("{file}: [integrator] {e}"))?);
        let init = &self.initial;
        if let Some(tol) = init.tolerance {
            settings.consistency_tolerance =
                Some(positive("tolerance", tol).map_err(|e| anyhow!("{file}: [initial] {e}"))?);
        }
        if init.off_constraint {
            settings.consistency_tolerance = None;
        }
        let (mut example, rows) = self.example(file)?;
        for (k, spec) in self.invariants.iter().enumerate() {
            spec.declare(&mut example).map_err(|e| anyhow!("{file}: invariants[{k}]: {e}"))?;
        }
        let mut changed = false;
        for (key, given, default) in [("q", &init.q, &mut example.q0), ("v", &init.v, &mut example.v0)] {
            if let Some(given) = given {
                if given.len() != default.len() {
                    bail!(
                        "{file}: [initial] {key} has {} values, the model has {} coordinates",
                        given.len(),
                        default.len()
                    );
                }
                if let Some(x) = given.iter().find(|x| !x.is_finite()) {
                    bail!("{file}: [initial] {key} contains {x}: must be finite");
                }
                if given != default {
                    // The model's reference solves its own initial state, not this one.
                    changed = true;
                }
                default.clone_from(given);
            }
        }
        if changed {
            example.reference = None;
        }
        let assembly = if init.assemble.unwrap_or(self.model.kind.is_described()) {
            let tolerance = settings.consistency_tolerance.unwrap_or(1e-9).min(1e-10);
            let Example { model, q0, v0, .. } = &mut example;
            Some(assemble_with(model, q0, v0, 0.0, tolerance, settings.dependent_rows).map_err(|e| {
                // A dependent row is named; otherwise the worst violated one.
                let entry = e.row().and_then(|r| rows.get(r)).map(|e| format!(" ({e})"));
                anyhow!("{file}: [initial]: {e}{}", entry.unwrap_or_else(|| worst_entry(&example, &rows)))
            })?)
        } else {
            None
        };
        if let Some(tolerance) = settings.consistency_tolerance {
            let mut probe = cdyn::dynamics::diagnostics::Probe::new(&example.model);
            let m = probe.measure(&example.model, &example.q0, &example.v0, 0.0, 0.0, 0.0);
            if m.phi.abs() > tolerance || m.phi_dot > tolerance {
                bail!(
                    "{file}: [initial]: the initial state violates the constraints: max |Φ| = {:.3e}, max |Φ̇| = {:.3e} (tolerance {tolerance:.1e}){}; set assemble = true to project it, or off_constraint = true to start there anyway",
                    m.phi.abs(),
                    m.phi_dot,
                    worst_entry(&example, &rows)
                );
            }
        }
        let every = match self.output.every {
            None => 1,
            Some(e) if e >= 1 => e as u64,
            Some(e) => bail!("{file}: [output] every = {e}: must be at least 1"),
        };
        let name = match &self.output.name {
            Some(n) if !n.is_empty() && n.chars().all(|c| c.is_ascii_alphanumeric() || "_-.".contains(c)) => n.clone(),
            Some(n) => bail!("{file}: [output] name = {n:?}: use letters, digits, '_', '-', '.'"),
            None => path.file_stem().map_or("run".into(), |s| s.to_string_lossy().into_owned()),
        };
        Ok(Case { name, example, settings, t_end, every, assembly, row_entries: rows })
    }

    /// The model with its initial state, and for mechanisms the entry
    /// (`joints[2] (revolute)`) behind every constraint row.
    fn example(&self, file: &str) -> Result<(Example, Vec<String>)> {
        let m = &self.model;
        let mechanism_tables =
            !(self.bodies.is_empty() && self.joints.is_empty() && self.drives.is_empty() && self.forces.is_empty());
        if mechanism_tables && m.kind != Kind::Mechanism {
            bail!("{file}: [[bodies]], [[joints]], [[drives]] and [[forces]] need [model] kind = \"mechanism\"");
        }
        let pendulum = matches!(m.kind, Kind::Pendulum | Kind::PendulumTheta);
        if m.parameters.is_some() && (pendulum || m.kind.is_described()) {
            bail!(
                "{file}: [model.parameters] is for the other built-in models; this kind takes its keys in [model] or none"
            );
        }
        let own_keys = |key: &String| pendulum || (m.kind == Kind::Spatial && key == "urdf");
        if let Some(key) = m.pendulum_keys.keys().find(|k| !own_keys(k)) {
            bail!(
                "{file}: [model] {key}: only the pendulum models take parameters in [model]; the other built-in models take theirs in [model.parameters]"
            );
        }
        match m.kind {
            Kind::Pendulum | Kind::PendulumTheta => {
                let mut parameters = m.pendulum_keys.clone();
                match m.gravity {
                    None => {}
                    Some(GravitySpec::Magnitude(g)) => {
                        parameters.insert("gravity".into(), toml::Value::Float(g));
                    }
                    Some(GravitySpec::Vector(_) | GravitySpec::Vector3(_)) => {
                        bail!("{file}: [model] gravity: the pendulum takes a magnitude (gravity acts along −Y)")
                    }
                }
                Ok((builtin(file, m.kind, "model", parameters)?, Vec::new()))
            }
            Kind::Mechanism => {
                let gravity = match m.gravity {
                    None => [0.0, 0.0],
                    Some(GravitySpec::Vector(g)) if g.iter().all(|x| x.is_finite()) => g,
                    Some(GravitySpec::Vector([gx, gy])) => {
                        bail!("{file}: [model] gravity = [{gx}, {gy}]: a mechanism takes a finite vector [gx, gy]")
                    }
                    Some(GravitySpec::Magnitude(g)) => {
                        bail!("{file}: [model] gravity = {g}: a mechanism takes a finite vector [gx, gy]")
                    }
                    Some(GravitySpec::Vector3(_)) => {
                        bail!(
                            "{file}: [model] gravity: a planar mechanism takes a vector [gx, gy]; kind = \"spatial\" takes [gx, gy, gz]"
                        )
                    }
                };
                if self.bodies.is_empty() {
                    bail!("{file}: a mechanism needs at least one [[bodies]] entry");
                }
                let entries = self.entries();
                let built = self.mechanism(gravity).and_then(|m| m.build());
                let built = built.map_err(|e| anyhow!("{file}: {}", name_entry(e, &entries)))?;
                let rows = built.row_elements.iter().map(|&k| entries[k].clone()).collect();
                Ok((Example::from_mechanism(built, None), rows))
            }
            Kind::Spatial => {
                let gravity = match m.gravity {
                    None => [0.0; 3],
                    Some(GravitySpec::Vector3(g)) if g.iter().all(|x| x.is_finite()) => g,
                    _ => bail!("{file}: [model] gravity: a spatial mechanism takes a finite vector [gx, gy, gz]"),
                };
                let entries = self.spatial.clone().unwrap_or_default();
                let (mechanism, counts) = self.spatial_mechanism(file, entries, gravity)?;
                let part = |part: &Part| counts.entry(part);
                let built = mechanism.and_then(|m| m.build().map(|b| (m, b))).map_err(|e| match e {
                    cdyn::Error::InvalidModel { at: at @ (Part::Body { .. } | Part::Element { .. }), problem } => {
                        anyhow!("{file}: {}: {problem}", part(&at))
                    }
                    other => anyhow!("{file}: {other}"),
                })?;
                let (mechanism, built) = built;
                let rows = built.rows.iter().map(part).collect();
                Ok((Example::from_spatial(&mechanism, built), rows))
            }
            built_in => {
                if m.gravity.is_some() {
                    bail!("{file}: [model] gravity: this model takes its parameters in [model.parameters]");
                }
                let parameters = m.parameters.clone().unwrap_or_default();
                Ok((builtin(file, built_in, "model.parameters", parameters)?, Vec::new()))
            }
        }
    }

    /// The spatial mechanism of the `urdf` file named in `[model]` (relative
    /// to the scenario's folder), if any, and of the `[[bodies]]` and
    /// `[[joints]]` entries, which may name the robot's links; with the
    /// numbers of bodies and joints that come from the robot (first).
    fn spatial_mechanism(
        &self,
        file: &str,
        entries: SpatialEntries,
        gravity: [f64; 3],
    ) -> Result<(cdyn::Result<cdyn::spatial::Mechanism>, Counts)> {
        let mut robot = cdyn::spatial::Mechanism::default();
        let (mut joint_names, mut load_names) = (Vec::new(), Vec::new());
        match self.model.pendulum_keys.get("urdf") {
            None => {}
            Some(toml::Value::String(name)) => {
                let path = Path::new(file).parent().unwrap_or(Path::new("")).join(name);
                let text = read_bounded(&path).map_err(|e| anyhow!("{file}: [model] urdf = {name:?}: {e}"))?;
                let read = cdyn::spatial::read_urdf(&text, gravity)
                    .map_err(|e| anyhow!("{file}: [model] urdf = {name:?}: {e}"))?;
                (robot, joint_names, load_names) = (read.mechanism, read.joint_names, read.load_names);
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
        let robot_loads: Vec<cdyn::spatial::Load<String>> = robot
            .loads
            .iter()
            .map(|l| match l {
                cdyn::spatial::Load::RotaryDamper { a, b, axis, damping } => cdyn::spatial::Load::RotaryDamper {
                    a: name(*a),
                    b: Some(b.map_or(cdyn::planar::GROUND.to_string(), name)),
                    axis: *axis,
                    damping: *damping,
                },
                other => unreachable!("a URDF gives rotary dampers only, not {}", other.kind()),
            })
            .collect();
        let counts = Counts {
            robot_bodies: robot.bodies.len(),
            joints: joints.len() + entries.joints.len(),
            robot_joints: joint_names,
            robot_loads: load_names,
        };
        joints.extend(entries.joints);
        let mut bodies = robot.bodies;
        bodies.extend(entries.bodies);
        let loads = robot_loads.into_iter().chain(entries.forces).collect();
        let mechanism = cdyn::spatial::Mechanism::named(bodies, joints, loads, gravity);
        Ok((mechanism, counts))
    }

    /// The element lists in the order the mechanism takes them.
    fn element_lists(&self) -> [(Group, &[Element<String>]); 3] {
        [(Group::Joints, &self.joints), (Group::Drives, &self.drives), (Group::Forces, &self.forces)]
    }

    /// For every element of the mechanism, the entry that describes it (`joints[2] (revolute)`).
    fn entries(&self) -> Vec<String> {
        let entry = |group: Group, (i, e): (usize, &Element<String>)| format!("{}[{i}] ({})", group.name(), e.kind());
        self.element_lists()
            .into_iter()
            .flat_map(|(group, list)| list.iter().enumerate().map(move |e| entry(group, e)))
            .collect()
    }

    /// The mechanism of the `[[bodies]]`, `[[joints]]`, `[[drives]]` and
    /// `[[forces]]` entries, its elements in the order of [`Scenario::entries`].
    fn mechanism(&self, gravity: [f64; 2]) -> cdyn::Result<Mechanism> {
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
}

/// How many of a spatial mechanism's parts come from its URDF robot,
/// which come first in each list: bodies, joints, then the loads (after
/// every joint in the numbering of `Part::Element`).
struct Counts {
    robot_bodies: usize,
    /// Every joint, the robot's and the scenario's.
    joints: usize,
    /// The URDF joint behind each of the robot's joints, and behind each of
    /// its loads (a joint's damping).
    robot_joints: Vec<String>,
    robot_loads: Vec<String>,
}

impl Counts {
    /// The part as the scenario or the robot names it: `bodies[0] (top)`,
    /// `joints[2] (revolute)`, `forces[1] (spring)`, `urdf link "hand"`,
    /// `urdf joint "elbow" (revolute)`.
    fn entry(&self, part: &Part) -> String {
        let (robot_joints, robot_loads) = (self.robot_joints.len(), self.robot_loads.len());
        match part {
            Part::Body { index, name } if *index < self.robot_bodies => format!("urdf link {name:?}"),
            Part::Body { index, name } => format!("bodies[{}] ({name})", index - self.robot_bodies),
            Part::Element { index, kind } if *index < robot_joints => {
                format!("urdf joint {:?} ({kind})", self.robot_joints[*index])
            }
            Part::Element { index, kind } if *index < self.joints => {
                format!("joints[{}] ({kind})", index - robot_joints)
            }
            Part::Element { index, kind } if *index < self.joints + robot_loads => {
                format!("urdf joint {:?} damping ({kind})", self.robot_loads[index - self.joints])
            }
            Part::Element { index, kind } => format!("forces[{}] ({kind})", index - self.joints - robot_loads),
            other => other.to_string(),
        }
    }
}

/// The library's error, naming the scenario's entry (`joints[2] (revolute)`,
/// `bodies[0] (crank)`) where it is about a part of the mechanism.
fn name_entry(error: cdyn::Error, entries: &[String]) -> String {
    match error {
        cdyn::Error::InvalidModel { at: Part::Element { index, .. }, problem } if index < entries.len() => {
            format!("{}: {problem}", entries[index])
        }
        cdyn::Error::InvalidModel { at: Part::Body { index, name }, problem } => {
            format!("bodies[{index}] ({name}): {problem}")
        }
        other => other.to_string(),
    }
}

/// The entry behind the worst-violated constraint row, if known.
fn worst_entry(example: &Example, rows: &[String]) -> String {
    let model = &example.model;
    let mut phi = vec![0.0; model.m()];
    model.constraint_values(&example.q0, 0.0, &mut phi);
    let worst = (0..phi.len()).max_by(|&a, &b| phi[a].abs().total_cmp(&phi[b].abs()));
    worst.and_then(|r| rows.get(r)).map_or(String::new(), |e| format!(" (worst: {e})"))
}

impl InvariantSpec {
    /// Declares it on `example`'s model.
    fn declare(&self, example: &mut Example) -> std::result::Result<(), String> {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_robots_parts_are_named_as_its_urdf_names_them() {
        // A robot of two links, joints "shoulder" and "elbow" (damped), then
        // the scenario's one body, two joints and one force.
        let counts = Counts {
            robot_bodies: 2,
            joints: 4,
            robot_joints: vec!["shoulder".into(), "elbow".into()],
            robot_loads: vec!["elbow".into()],
        };
        let element = |index, kind| counts.entry(&Part::Element { index, kind });
        assert_eq!(counts.entry(&Part::Body { index: 1, name: "fore".into() }), "urdf link \"fore\"");
        assert_eq!(counts.entry(&Part::Body { index: 2, name: "weight".into() }), "bodies[0] (weight)");
        assert_eq!(element(1, "revolute"), "urdf joint \"elbow\" (revolute)");
        assert_eq!(element(3, "distance"), "joints[1] (distance)");
        assert_eq!(element(4, "rotary_damper"), "urdf joint \"elbow\" damping (rotary_damper)");
        assert_eq!(element(5, "spring"), "forces[0] (spring)");
    }
}

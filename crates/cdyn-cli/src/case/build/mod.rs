//! From a scenario to the case it runs: the model (built-in, planar or
//! spatial mechanism, URDF robot), its consistent initial state, the method
//! and the settings; a model's error names the scenario entry that made it.
//!
//! Here the case and its model; `mechanisms` the planar and spatial
//! mechanisms of the entries (and a URDF robot's), the entry behind each
//! part and a planar mechanism's limits; `spatial` a spatial scenario's model with its initial joint
//! state, joint columns and limits; `invariants` the declared `[[invariants]]`.
//!
//! May import: `io` (and `case`'s scenario, runner and wording).

mod invariants;
mod mechanisms;
mod spatial;

use crate::case::runner::Case;
use crate::case::runner::JointColumns;
use crate::case::runner::limits::Limits;
use crate::case::scenario::{GravitySpec, Scenario};
use crate::case::wording::{locate, reason};
use anyhow::{Result, anyhow, bail};
use cdyn::Settings;
use cdyn::control::methods::{MethodKeys, Preset};
use cdyn::dynamics::assemble::assemble_with;
use cdyn::error::{Part, positive};
use cdyn::models::{Example, Kind};
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
        let joint_keys = [
            ("joints", init.joints.is_some(), "q", init.q.is_some()),
            ("rates", init.rates.is_some(), "v", init.v.is_some()),
        ];
        for (key, given, state, overridden) in joint_keys {
            if given && self.model.kind != Kind::Spatial {
                bail!("{file}: [initial] {key}: joint coordinates are for kind = \"spatial\" mechanisms");
            }
            if given && overridden {
                bail!(
                    "{file}: [initial] {key} and {state} exclude each other: give the joints' values or the coordinates"
                );
            }
        }
        let Described { mut example, rows, notes, force_entries, limits, joint_columns, poses } = self.example(file)?;
        // A run with limits rebuilds its model at each stop, from the
        // mechanism: what was added to the built model would be lost. The
        // inputs are not: the mechanism's actuators hold them (the same
        // handles in every rebuilt model).
        if let Some(limits) = &limits
            && !self.invariants.is_empty()
        {
            bail!("{file}: [[invariants]] with joint limits (joint {}): not supported yet", limits.first_joint());
        }
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
        if let Some(limits) = &limits {
            limits.check_start(&example.q0, &example.v0).map_err(|e| anyhow!("{file}: {e}"))?;
        }
        if !self.inputs.is_empty() && !matches!(self.model.kind, Kind::Mechanism | Kind::Spatial) {
            bail!(
                "{file}: [[inputs]] drive keys of a mechanism's entries: they need [model] kind = \"mechanism\" or \"spatial\""
            );
        }
        crate::case::inputs::selected(self.output.select.as_deref(), &crate::case::runner::columns(&example), file)?;
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
        let row_entries = rows;
        Ok(Case {
            name,
            example,
            settings,
            t_end,
            every,
            assembly,
            row_entries,
            notes,
            force_entries,
            limits,
            joint_columns,
            poses,
        })
    }

    /// The model with its initial state, for mechanisms the entry
    /// (`joints[2] (revolute)`) behind every constraint row, what a
    /// robot's file holds that is not modelled, and the entry behind each
    /// force element where known.
    fn example(&self, file: &str) -> Result<Described> {
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
        let own_keys = |key: &String| pendulum || (m.kind == Kind::Spatial && (key == "urdf" || key == "coordinates"));
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
                Ok(Described::plain(builtin(file, m.kind, "model", parameters)?))
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
                let mut mechanism =
                    self.mechanism(gravity).map_err(|e| anyhow!("{file}: {}", name_entry(e, &entries)))?;
                crate::case::inputs::drive(&self.inputs, |g| self.element_list(g).len(), &mut mechanism, file)?;
                let built = mechanism.build();
                let built = built.map_err(|e| anyhow!("{file}: {}", name_entry(e, &entries)))?;
                let rows = built.row_elements.iter().map(|&k| entries[k].clone()).collect();
                let limits =
                    self.planar_limits(mechanism).map_err(|e| anyhow!("{file}: {}", name_entry(e, &entries)))?;
                Ok(Described { rows, limits, ..Described::plain(Example::from_mechanism(built, None)) })
            }
            Kind::Spatial => self.spatial_example(file),
            built_in => {
                if m.gravity.is_some() {
                    bail!("{file}: [model] gravity: this model takes its parameters in [model.parameters]");
                }
                let parameters = m.parameters.clone().unwrap_or_default();
                Ok(Described::plain(builtin(file, built_in, "model.parameters", parameters)?))
            }
        }
    }
}

/// A model with its initial state and, for mechanisms, the entries behind
/// its rows and force elements, and what a robot's file holds that is not modelled.
struct Described {
    example: Example,
    rows: Vec<String>,
    notes: Vec<String>,
    force_entries: Vec<String>,
    limits: Option<Limits>,
    joint_columns: Option<JointColumns>,
    poses: Option<cdyn::spatial::BodyPoses>,
}

impl Described {
    /// A built-in model: no entries, nothing left out.
    fn plain(example: Example) -> Self {
        let (rows, notes, force_entries) = (Vec::new(), Vec::new(), Vec::new());
        Self { example, rows, notes, force_entries, limits: None, joint_columns: None, poses: None }
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

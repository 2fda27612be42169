//! One FMU instance: its scenario (from `resources/`), the case it steps,
//! its variables by value reference — parameters, then inputs, then
//! outputs ([`variables`]) — its mode, and the messages it logs.

use super::{CallbackFunctions, ERROR, FmiString, Logger, Status};
use cdyn_cli::case::live::{Live, LiveSnapshot};
use cdyn_cli::case::scenario;
use cdyn_cli::export::fmu::SCENARIO_RESOURCE;
use cdyn_cli::export::variables::{Causality, Variable, guid, load, parameters, set_parameter, urdf_path};
use std::ffi::{CString, c_void};
use std::path::PathBuf;

/// Where an instance is in FMI's state machine (co-simulation).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Mode {
    Instantiated,
    Initialization,
    Stepping,
    Terminated,
}

/// An FMU instance.
pub(super) struct Instance {
    name: CString,
    logger: Option<Logger>,
    environment: *mut c_void,
    /// The scenario as shipped, and its path (which URDF files are read relative to).
    text: String,
    path: PathBuf,
    /// The scenario with the parameters set so far.
    table: toml::Table,
    parameters_changed: bool,
    live: Live,
    variables: Vec<Variable>,
    /// The inputs' values as last set (applied again when the case is rebuilt).
    inputs: Vec<f64>,
    outputs: Vec<f64>,
    pub(super) mode: Mode,
}

/// A saved instance: the case's snapshot and the inputs' values.
pub(super) struct Saved {
    snapshot: LiveSnapshot,
    inputs: Vec<f64>,
}

/// A refused call: its status and message.
pub(super) type Refusal = (Status, String);

pub(super) fn refuse<T>(message: impl Into<String>) -> Result<T, Refusal> {
    Err((ERROR, message.into()))
}

/// The folder a `file:` URI names (`file:///a/b`, `file:/a/b`, `file://localhost/a/b`), percent-decoded.
fn folder(uri: &str) -> Option<PathBuf> {
    let rest = uri
        .strip_prefix("file://")
        .map(|r| r.strip_prefix("localhost").unwrap_or(r))
        .or_else(|| uri.strip_prefix("file:"))?;
    let mut bytes = Vec::new();
    let mut it = rest.bytes();
    while let Some(b) = it.next() {
        if b == b'%' {
            let hex: Vec<u8> = it.by_ref().take(2).collect();
            bytes.push(u8::from_str_radix(std::str::from_utf8(&hex).ok()?, 16).ok()?);
        } else {
            bytes.push(b);
        }
    }
    Some(PathBuf::from(String::from_utf8(bytes).ok()?))
}

impl Instance {
    /// Reads the scenario from `resources` (a `file:` URI), checks `guid`, builds the case.
    pub(super) fn new(
        name: &str,
        guid_given: &str,
        resources: &str,
        callbacks: &CallbackFunctions,
    ) -> Result<Self, Refusal> {
        let dir = folder(resources)
            .ok_or_else(|| (ERROR, format!("fmuResourceLocation {resources:?}: expected a file: URI")))?;
        let path = dir.join(SCENARIO_RESOURCE);
        let text =
            std::fs::read_to_string(&path).map_err(|e| (ERROR, format!("cannot read {}: {e}", path.display())))?;
        let (_, table, live, variables) = load(&text, &path).map_err(|e| (ERROR, format!("{e:#}")))?;
        let urdf = urdf_path(&table, &path)
            .map(|p| std::fs::read_to_string(&p).map_err(|e| (ERROR, format!("cannot read {}: {e}", p.display()))));
        let urdf = urdf.transpose()?;
        let expected = guid(&table, urdf.as_deref());
        if expected != guid_given {
            return refuse(format!("GUID {guid_given} is not that of the scenario in {} ({expected})", path.display()));
        }
        let inputs =
            variables.iter().filter(|v| v.causality == Causality::Input).map(|v| v.start.unwrap_or(0.0)).collect();
        Ok(Instance {
            name: CString::new(name.replace('\0', "")).unwrap_or_default(),
            logger: callbacks.logger,
            environment: callbacks.component_environment,
            text,
            path,
            table,
            parameters_changed: false,
            outputs: vec![0.0; live.output_names().len()],
            live,
            variables,
            inputs,
            mode: Mode::Instantiated,
        })
    }

    /// Logs `message` with `status` through the importer's logger.
    pub(super) fn log(&self, status: Status, message: &str) {
        log(self.logger, self.environment, self.name.as_ptr(), status, message);
    }

    /// The variable `vr` and its position within its kind.
    fn variable(&self, vr: u32) -> Result<(Causality, usize), Refusal> {
        let v = self.variables.get(vr as usize).ok_or_else(|| {
            (ERROR, format!("no Real variable has value reference {vr} (there are {})", self.variables.len()))
        })?;
        let first = self.variables.iter().position(|w| w.causality == v.causality).unwrap_or(0);
        Ok((v.causality, vr as usize - first))
    }

    /// Sets the Real `vr` to `value`.
    pub(super) fn set_real(&mut self, vr: u32, value: f64) -> Result<(), Refusal> {
        let (causality, k) = self.variable(vr)?;
        let name = &self.variables[vr as usize].name;
        if !value.is_finite() {
            return refuse(format!("{name} = {value}: must be finite"));
        }
        match causality {
            Causality::Parameter if matches!(self.mode, Mode::Instantiated | Mode::Initialization) => {
                set_parameter(&mut self.table, name, value).map_err(|e| (ERROR, e.to_string()))?;
                self.parameters_changed = true;
                Ok(())
            }
            Causality::Parameter => {
                refuse(format!("{name} is a fixed parameter: it is set before initialization only"))
            }
            Causality::Input => {
                self.live.set_input(k, value).map_err(|e| (ERROR, e.to_string()))?;
                self.inputs[k] = value;
                Ok(())
            }
            Causality::Output => refuse(format!("{name} is an output: it cannot be set")),
        }
    }

    /// The Reals of `vrs` into `values`.
    pub(super) fn get_reals(&mut self, vrs: &[u32], values: &mut [f64]) -> Result<(), Refusal> {
        let mut computed = false;
        for (vr, value) in vrs.iter().zip(values) {
            let (causality, k) = self.variable(*vr)?;
            *value = match causality {
                Causality::Parameter => parameters(&self.table)[k].1,
                Causality::Input => self.inputs[k],
                Causality::Output => {
                    if !std::mem::replace(&mut computed, true) {
                        self.live.outputs(&mut self.outputs);
                    }
                    self.outputs[k]
                }
            };
        }
        Ok(())
    }

    /// Builds the case again from the scenario with the parameters set, if any were.
    pub(super) fn apply_parameters(&mut self) -> Result<(), Refusal> {
        if !std::mem::take(&mut self.parameters_changed) {
            return Ok(());
        }
        let file = self.path.display().to_string();
        let built =
            scenario::from_table(self.table.clone(), &file).and_then(|(s, _)| Live::from_scenario(&s, &self.path));
        self.live = built.map_err(|e| (ERROR, format!("{e:#}")))?;
        for (k, &value) in self.inputs.iter().enumerate() {
            self.live.set_input(k, value).map_err(|e| (ERROR, e.to_string()))?;
        }
        Ok(())
    }

    /// Back to the state after instantiation: the scenario as shipped.
    pub(super) fn reset(&mut self) -> Result<(), Refusal> {
        let (_, table, live, variables) = load(&self.text, &self.path).map_err(|e| (ERROR, format!("{e:#}")))?;
        self.inputs =
            variables.iter().filter(|v| v.causality == Causality::Input).map(|v| v.start.unwrap_or(0.0)).collect();
        (self.table, self.live, self.variables, self.parameters_changed) = (table, live, variables, false);
        self.mode = Mode::Instantiated;
        Ok(())
    }

    /// One communication step from `t` of size `step`, a multiple of `h`.
    pub(super) fn do_step(&mut self, t: f64, step: f64) -> Result<(), Refusal> {
        if self.mode != Mode::Stepping {
            return refuse(format!("fmi2DoStep in {:?} mode: exit initialization mode first", self.mode));
        }
        let (now, h) = (self.live.t(), self.live.h());
        if (t - now).abs() > 1e-9 * now.abs().max(1.0) {
            return refuse(format!("fmi2DoStep from t = {t}: the FMU is at t = {now}"));
        }
        let steps = (step / h).round();
        if !(steps >= 1.0 && (steps * h - step).abs() <= 1e-9 * step) {
            return refuse(format!("communication step {step} is not a whole number of the scenario's steps h = {h}"));
        }
        self.live.step(steps as u64).map_err(|e| (ERROR, e.to_string()))
    }

    /// The time reached.
    pub(super) fn time(&self) -> f64 {
        self.live.t()
    }

    pub(super) fn save(&self) -> Saved {
        Saved { snapshot: self.live.snapshot(), inputs: self.inputs.clone() }
    }

    pub(super) fn restore(&mut self, saved: &Saved) -> Result<(), Refusal> {
        self.live
            .restore(&saved.snapshot)
            .map_err(|e| (ERROR, format!("{e} (a state of another instance, or from before a reset)")))?;
        self.inputs.clone_from(&saved.inputs);
        Ok(())
    }
}

/// Logs through `logger` (if any) as instance `name`: the message passed
/// as the argument of a `"%s"` format, never as a format itself.
pub(super) fn log(logger: Option<Logger>, environment: *mut c_void, name: FmiString, status: Status, message: &str) {
    let Some(logger) = logger else { return };
    let message = CString::new(message.replace('\0', "")).unwrap_or_default();
    let category: &std::ffi::CStr = if status >= ERROR { c"logStatusError" } else { c"logAll" };
    // SAFETY: the importer's logger, called as fmi2CallbackLogger is declared.
    unsafe { logger(environment, name, status, category.as_ptr(), c"%s".as_ptr(), message.as_ptr()) };
}

//! A scenario's inputs and outputs: `[[inputs]]` — each a name, the key of
//! a mechanism's entry it drives (`drives = "forces[0].torque"`) and a
//! start value — and `[output] select`, the outputs that the stepping
//! interfaces (Python's `Simulation`, the C API, an FMU) give, by their CSV
//! column names (default: every column).
//!
//! An input takes the place of the key it drives: the entry leaves that
//! key out (a required one, as a drive's `function`, included). In a
//! spatial mechanism an input drives an actuator's `torque` or `target`
//! (`drives = "actuators[0].torque"`).

use anyhow::{Result, anyhow, bail};
use cdyn::model::input::Input;
use cdyn::model::timefn::TimeFn;
use cdyn::planar::{Group, Mechanism};
use cdyn::spatial::Actuator;
use serde::Deserialize;

/// `[[inputs]]`: an input of the scenario.
#[derive(Debug, Deserialize, Clone)]
#[serde(deny_unknown_fields)]
pub struct InputSpec {
    /// Its name, by which it is set.
    pub name: String,
    /// The key it drives: `forces[0].torque`, `drives[1].function`,
    /// `forces[2].rest_length` (see `cdyn::planar::Element::input_keys`).
    pub drives: String,
    /// Its value until it is set.
    pub start: f64,
}

/// The entry and key an input drives.
struct Target<'a> {
    group: Group,
    index: usize,
    key: &'a str,
}

impl InputSpec {
    /// Where `drives` points, checked against the number of entries of each list.
    fn target(&self, k: usize, file: &str, entries: &dyn Fn(Group) -> usize) -> Result<Target<'_>> {
        let at = || format!("{file}: inputs[{k}] ({}): drives = {:?}", self.name, self.drives);
        let groups = [Group::Joints, Group::Drives, Group::Forces];
        let parsed = self.drives.split_once('.').and_then(|(entry, key)| {
            let (list, index) = entry.strip_suffix(']')?.split_once('[')?;
            let group = groups.into_iter().find(|g| g.name() == list)?;
            Some(Target { group, index: index.parse().ok()?, key })
        });
        let Some(target) = parsed else {
            bail!("{}: expected an entry and one of its keys, as forces[0].torque or drives[1].function", at());
        };
        let entries = entries(target.group);
        if target.index >= entries {
            bail!("{}: the scenario has {entries} [[{}]] entries", at(), target.group.name());
        }
        Ok(target)
    }
}

/// The scenario `table` as its entries are read when inputs take keys'
/// places: each key an input drives is checked to be left out, then given
/// a placeholder 0 (which the input replaces when the model is built).
/// Anything else wrong with an input is said after the scenario is read
/// ([`drive`]), so that a misspelt key elsewhere is named first.
pub(crate) fn placeholders(table: &toml::Table, file: &str) -> Result<toml::Table> {
    let inputs = table.get("inputs").and_then(|i| Vec::<InputSpec>::deserialize(i.clone()).ok()).unwrap_or_default();
    let mut read = table.clone();
    let count = |g: Group| table.get(g.name()).and_then(|v| v.as_array()).map_or(0, |a| a.len());
    for (k, input) in inputs.iter().enumerate() {
        let Ok(target) = input.target(k, file, &count) else { continue };
        let entries = read.get_mut(target.group.name()).and_then(|v| v.as_array_mut());
        let Some(entry) = entries.and_then(|a| a.get_mut(target.index)).and_then(|e| e.as_table_mut()) else {
            continue;
        };
        let kind = entry.get("kind").and_then(|k| k.as_str()).unwrap_or_default();
        if !cdyn::planar::input_keys(kind).contains(&target.key) {
            continue;
        }
        if entry.contains_key(target.key) {
            bail!(
                "{file}: {}[{}] ({kind}): {} is driven by the input {:?} (inputs[{k}]): leave the key out",
                target.group.name(),
                target.index,
                target.key,
                input.name
            );
        }
        entry.insert(target.key.to_string(), toml::Value::Float(0.0));
    }
    Ok(read)
}

/// Lets each input of `specs` drive its key of `mechanism`, whose elements
/// are the scenario's joints, drives and forces in that order (`entries`
/// counts each list).
pub(crate) fn drive(
    specs: &[InputSpec],
    entries: impl Fn(Group) -> usize,
    mechanism: &mut Mechanism,
    file: &str,
) -> Result<()> {
    for (k, spec) in specs.iter().enumerate() {
        let target = spec.target(k, file, &entries)?;
        let before = match target.group {
            Group::Joints => 0,
            Group::Drives => entries(Group::Joints),
            _ => entries(Group::Joints) + entries(Group::Drives),
        };
        let earlier = mechanism.inputs.iter().map(|d| &d.input).find(|u| u.name() == spec.name);
        let input = spec.input(k, file, earlier)?;
        mechanism.drive(before + target.index, target.key, &input);
    }
    Ok(())
}

impl InputSpec {
    /// The input: the one of the same name declared `earlier`, if any
    /// (inputs of one name are one input, of one start value), else a new one.
    fn input(&self, k: usize, file: &str, earlier: Option<&Input>) -> Result<Input> {
        match earlier {
            Some(u) if u.start() != self.start => bail!(
                "{file}: inputs[{k}] ({}): start = {}: the input has start = {} already",
                self.name,
                self.start,
                u.start()
            ),
            Some(u) => Ok(u.clone()),
            None => Ok(Input::new(&self.name, self.start)),
        }
    }
}

/// Lets each input of `specs` drive the `torque` or `target` of a spatial
/// mechanism's actuator (`drives = "actuators[0].torque"`), a function of
/// time that is the input's value; the entry leaves that key out.
pub(crate) fn drive_actuators(specs: &[InputSpec], actuators: &mut [Actuator<String>], file: &str) -> Result<()> {
    let mut made: Vec<Input> = Vec::new();
    for (k, spec) in specs.iter().enumerate() {
        let at = || format!("{file}: inputs[{k}] ({}): drives = {:?}", spec.name, spec.drives);
        let parsed = spec.drives.split_once('.').and_then(|(entry, key)| {
            Some((entry.strip_prefix("actuators[")?.strip_suffix(']')?.parse::<usize>().ok()?, key))
        });
        let Some((index, key)) = parsed else {
            bail!("{}: expected an actuator and its key, actuators[0].torque or actuators[0].target", at());
        };
        let count = actuators.len();
        let Some(actuator) = actuators.get_mut(index) else {
            bail!("{}: the scenario has {count} [[actuators]] entries", at());
        };
        let slot = match key {
            "torque" => &mut actuator.torque,
            "target" => &mut actuator.target,
            other => bail!("{}: an actuator's input drives its torque or target, not {other}", at()),
        };
        if slot.is_some() {
            bail!(
                "{file}: actuators[{index}]: {key} is driven by the input {:?} (inputs[{k}]): leave the key out",
                spec.name
            );
        }
        let input = spec.input(k, file, made.iter().find(|u| u.name() == spec.name))?;
        *slot = Some(TimeFn::input(&input));
        made.push(input);
    }
    Ok(())
}

/// The positions among `columns` of the outputs that `select` (`[output]
/// select`) names, all of them without it.
pub fn selected(select: Option<&[String]>, columns: &[String], file: &str) -> Result<Vec<usize>> {
    let Some(select) = select else { return Ok((0..columns.len()).collect()) };
    select
        .iter()
        .map(|name| {
            columns.iter().position(|c| c == name).ok_or_else(|| {
                anyhow!("{file}: [output] select: no output {name:?}; the outputs are {}", columns.join(", "))
            })
        })
        .collect()
}

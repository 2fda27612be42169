//! The variables of a scenario's case as an FMU (and its importer) sees
//! them, in value-reference order: the parameters — every float of the
//! model's keys (`[model]`, `[method]`, `[[bodies]]`, `[[joints]]`,
//! `[[drives]]`, `[[forces]]`), named by their path (`bodies[0].mass`,
//! `bodies[0].position[1]`), settable before initialization — then the
//! `[[inputs]]`, then the outputs (`[output] select`, by default every CSV
//! column). Also the scenario's GUID, from its content.

use crate::case::live::Live;
use crate::case::scenario::{self, Scenario};
use crate::study::sweep::content_hash;
use anyhow::{Result, bail};
use std::path::Path;

/// The tables whose floats are parameters.
const PARAMETER_TABLES: [&str; 6] = ["model", "method", "bodies", "joints", "drives", "forces"];

/// What a variable is to the importer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Causality {
    /// A scenario key, set before initialization.
    Parameter,
    /// An `[[inputs]]` entry, set between steps.
    Input,
    /// An output, read after each step.
    Output,
}

/// One variable: its name, what it is, and its start value (parameters, inputs).
#[derive(Debug, Clone, PartialEq)]
pub struct Variable {
    /// Its name.
    pub name: String,
    /// What it is.
    pub causality: Causality,
    /// Its value before anything is set (outputs: none).
    pub start: Option<f64>,
}

/// Every float of the parameter tables of `table`, with its path.
pub fn parameters(table: &toml::Table) -> Vec<(String, f64)> {
    fn walk(value: &toml::Value, at: String, out: &mut Vec<(String, f64)>) {
        match value {
            toml::Value::Float(x) => out.push((at, *x)),
            toml::Value::Array(items) => {
                for (i, v) in items.iter().enumerate() {
                    walk(v, format!("{at}[{i}]"), out);
                }
            }
            toml::Value::Table(t) => {
                for (k, v) in t {
                    walk(v, if at.is_empty() { k.clone() } else { format!("{at}.{k}") }, out);
                }
            }
            _ => {}
        }
    }
    let mut out = Vec::new();
    for key in PARAMETER_TABLES {
        if let Some(value) = table.get(key) {
            walk(value, key.to_string(), &mut out);
        }
    }
    out
}

/// `table` with the parameter `name` (a path of [`parameters`]) set to `value`.
pub fn set_parameter(table: &mut toml::Table, name: &str, value: f64) -> Result<()> {
    let mut here: Option<&mut toml::Value> = None;
    let mut rest = name;
    while !rest.is_empty() {
        let end = rest.find(['.', '[']).unwrap_or(rest.len());
        let (key, after) = if let Some(r) = rest.strip_prefix('[') {
            let close = r.find(']').unwrap_or(r.len());
            (&r[..close], r.get(close + 1..).unwrap_or(""))
        } else {
            (&rest[..end], &rest[end..])
        };
        let next = match here {
            None => table.get_mut(key),
            Some(toml::Value::Table(t)) => t.get_mut(key),
            Some(toml::Value::Array(a)) => key.parse::<usize>().ok().and_then(|i| a.get_mut(i)),
            Some(_) => None,
        };
        let Some(next) = next else { bail!("no parameter {name:?}") };
        here = Some(next);
        rest = after.strip_prefix('.').unwrap_or(after);
    }
    match here {
        Some(v @ toml::Value::Float(_)) => *v = toml::Value::Float(value),
        _ => bail!("no parameter {name:?}"),
    }
    Ok(())
}

/// Every variable of the case of `scenario` (read from `table`), as [`Live`] shows it.
pub fn variables(table: &toml::Table, scenario: &Scenario, live: &Live) -> Vec<Variable> {
    let parameter = |(name, x): (String, f64)| Variable { name, causality: Causality::Parameter, start: Some(x) };
    let input = |i: &crate::case::inputs::InputSpec| Variable {
        name: i.name.clone(),
        causality: Causality::Input,
        start: Some(i.start),
    };
    let output = |name: &String| Variable { name: name.clone(), causality: Causality::Output, start: None };
    let mut all: Vec<Variable> = parameters(table).into_iter().map(parameter).collect();
    let mut seen = std::collections::HashSet::new();
    all.extend(scenario.inputs.iter().filter(|i| seen.insert(i.name.clone())).map(input));
    all.extend(live.output_names().iter().map(output));
    all
}

/// The scenario's GUID, `{8-4-4-4-12}` hex digits of [`content_hash`] of
/// its table and the text of the URDF file it names (`urdf`).
pub fn guid(table: &toml::Table, urdf: Option<&str>) -> String {
    let mut content = table.clone();
    if let Some(text) = urdf {
        content.insert("urdf file".into(), toml::Value::String(text.into()));
    }
    let h = content_hash(&content);
    format!("{{{}-{}-{}-{}-{}}}", &h[..8], &h[8..12], &h[12..16], &h[16..20], &h[20..])
}

/// The URDF file the scenario at `path` names in `[model] urdf`, relative to its folder.
pub fn urdf_path(table: &toml::Table, path: &Path) -> Option<std::path::PathBuf> {
    let name = table.get("model")?.get("urdf")?.as_str()?;
    Some(path.parent().unwrap_or(Path::new("")).join(name))
}

/// Reads the scenario `text` (named `file`), builds its case and checks
/// its variables' names are distinct: what an FMU of it runs.
pub fn load(text: &str, path: &Path) -> Result<(Scenario, toml::Table, Live, Vec<Variable>)> {
    let file = path.display().to_string();
    let (parsed, table) = scenario::parse(text, &file)?;
    let live = Live::from_scenario(&parsed, path)?;
    let all = variables(&table, &parsed, &live);
    let mut names = std::collections::HashSet::new();
    if let Some(twice) = all.iter().find(|v| !names.insert(v.name.as_str())) {
        bail!(
            "{file}: the variable name {:?} is used twice (an input or output named as another variable)",
            twice.name
        );
    }
    Ok((parsed, table, live, all))
}

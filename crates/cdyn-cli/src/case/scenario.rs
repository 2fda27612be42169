//! Scenario files: a built-in model and its parameters, the method, the
//! integrator and the output sampling, in TOML. Every mistake becomes one
//! line naming the file and the key.

use crate::case::inputs::{InputSpec, placeholders};
use crate::case::wording::{locate, reason};
use anyhow::{Result, anyhow, bail};
use cdyn::Scheme;
use cdyn::control::methods::MethodKeys;
use cdyn::dynamics::DependentRows;
use cdyn::models::Kind;
use cdyn::planar::{Body, Element};
use cdyn::simulate::generalized_alpha::{GeneralizedAlpha, Newton};
use serde::Deserialize;
use std::path::Path;

/// A scenario file, as read: every table and list it may have.
#[derive(Debug, Deserialize, Clone)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// `[model]`.
    pub model: ModelSpec,
    /// `[initial]`.
    #[serde(default)]
    pub initial: InitialSpec,
    /// `[method]`; without it, the `robust` preset.
    pub method: Option<MethodKeys>,
    /// `[integrator]`.
    pub integrator: IntegratorSpec,
    /// `[output]`.
    #[serde(default)]
    pub output: OutputSpec,
    /// `[[bodies]]` of a planar mechanism.
    #[serde(default)]
    pub bodies: Vec<Body>,
    /// `[[joints]]` of a planar mechanism.
    #[serde(default, deserialize_with = "cdyn::planar::format::joints")]
    pub joints: Vec<Element<String>>,
    /// `[[drives]]` of a planar mechanism.
    #[serde(default, deserialize_with = "cdyn::planar::format::drives")]
    pub drives: Vec<Element<String>>,
    /// `[[forces]]` of a planar mechanism.
    #[serde(default, deserialize_with = "cdyn::planar::format::forces")]
    pub forces: Vec<Element<String>>,
    /// Axes of a parameter sweep (`cdyn sweep`): key → values.
    pub sweep: Option<toml::Table>,
    /// Inputs set between steps (`[[inputs]]`), each driving a key of a
    /// mechanism's entry.
    #[serde(default)]
    pub inputs: Vec<InputSpec>,
    /// Momenta the model is declared to keep (`[[invariants]]`): checked
    /// and held like those a run finds, reported where the model breaks them.
    #[serde(default)]
    pub invariants: Vec<InvariantSpec>,
    /// The `[[bodies]]` and `[[joints]]` of a spatial mechanism (`kind =
    /// "spatial"`), read by the spatial types instead of the planar ones.
    #[serde(skip)]
    pub spatial: Option<SpatialEntries>,
}

/// A declared invariant: `kind = "momentum"` with an `axis` (every body
/// translated along it), `kind = "angular_momentum"` with an `axis`
/// (default z) and a `point` on it (default the origin), or
/// `kind = "coordinate"` with the `coordinate`'s name (its generalized
/// momentum); `name` names it in the output.
#[derive(Debug, Deserialize, Clone)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum InvariantSpec {
    /// Every body translated along `axis`.
    Momentum {
        /// The direction, in the mechanism's dimension.
        axis: Vec<f64>,
        /// Its name in the output.
        name: Option<String>,
    },
    /// The rigid rotation about `axis` through `point`.
    AngularMomentum {
        /// The axis (spatial; default z).
        axis: Option<Vec<f64>>,
        /// A point on the axis (default the origin).
        point: Option<Vec<f64>>,
        /// Its name in the output.
        name: Option<String>,
    },
    /// The generalized momentum of one coordinate.
    Coordinate {
        /// The coordinate's name (`sled.angle`).
        coordinate: String,
        /// Its name in the output.
        name: Option<String>,
    },
}

/// A spatial mechanism's entries, bodies named by the joints.
#[derive(Debug, Deserialize, Clone, Default)]
pub struct SpatialEntries {
    /// `[[bodies]]`.
    #[serde(default)]
    pub bodies: Vec<cdyn::spatial::Body>,
    /// `[[joints]]`.
    #[serde(default)]
    pub joints: Vec<cdyn::spatial::Joint<String>>,
    /// `[[forces]]`.
    #[serde(default)]
    pub forces: Vec<cdyn::spatial::Load<String>>,
    /// `[[actuators]]`, each naming its joint as the output columns do.
    #[serde(default)]
    pub actuators: Vec<cdyn::spatial::Actuator<String>>,
}

/// `gravity`: a magnitude for the pendulums, a vector for mechanisms
/// (three components for spatial ones).
#[derive(Debug, Clone, Copy)]
pub enum GravitySpec {
    /// `g` for the pendulums.
    Magnitude(f64),
    /// `[gx, gy]` for planar mechanisms.
    Vector([f64; 2]),
    /// `[gx, gy, gz]` for spatial mechanisms.
    Vector3([f64; 3]),
}

impl<'de> Deserialize<'de> for GravitySpec {
    /// Read as a TOML value and matched by hand, so that a wrong one is named
    /// as the scenario writes it, not as an "untagged enum".
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let number = |v: &toml::Value| v.as_float().or_else(|| v.as_integer().map(|i| i as f64));
        let value = toml::Value::deserialize(d)?;
        match &value {
            v if number(v).is_some() => Ok(GravitySpec::Magnitude(number(v).unwrap_or_default())),
            toml::Value::Array(a) if a.len() == 2 && a.iter().all(|x| number(x).is_some()) => {
                Ok(GravitySpec::Vector([number(&a[0]).unwrap_or_default(), number(&a[1]).unwrap_or_default()]))
            }
            toml::Value::Array(a) if a.len() == 3 && a.iter().all(|x| number(x).is_some()) => {
                Ok(GravitySpec::Vector3(std::array::from_fn(|i| number(&a[i]).unwrap_or_default())))
            }
            _ => Err(serde::de::Error::custom(
                "expected a magnitude g (pendulums), a vector [gx, gy] (mechanisms) or [gx, gy, gz] (spatial mechanisms)",
            )),
        }
    }
}

/// `[model]`: the kind and, for the pendulums, their parameters; the other
/// built-in models take theirs in `[model.parameters]`. Both are read by the
/// library's parameter types when the model is built, so the keys live in
/// one place; unknown ones are refused there.
#[derive(Debug, Deserialize, Clone)]
pub struct ModelSpec {
    /// `kind`: which model.
    pub kind: Kind,
    /// `gravity`, where the kind takes one.
    pub gravity: Option<GravitySpec>,
    /// Parameters of the other built-in models.
    pub parameters: Option<toml::Table>,
    /// The other keys of `[model]`: the pendulum's parameters (so no
    /// `deny_unknown_fields` here: this table takes every other key).
    #[serde(flatten)]
    pub pendulum_keys: toml::Table,
}

/// `[initial]`: overrides and checks of the initial state.
#[derive(Debug, Deserialize, Default, Clone)]
#[serde(deny_unknown_fields)]
pub struct InitialSpec {
    /// The initial positions, overriding the model's.
    pub q: Option<Vec<f64>>,
    /// The initial velocities, overriding the model's.
    pub v: Option<Vec<f64>>,
    /// A spatial mechanism's initial joint coordinates by their output
    /// names (`shoulder = 0.3`, `"joints[1]" = -0.2`), placed by forward kinematics.
    pub joints: Option<std::collections::BTreeMap<String, f64>>,
    /// A spatial mechanism's initial joint rates by the same names.
    pub rates: Option<std::collections::BTreeMap<String, f64>>,
    /// Start even if the initial state violates the constraints.
    #[serde(default)]
    pub off_constraint: bool,
    /// Project the initial state onto the constraints first (default: on for mechanisms).
    pub assemble: Option<bool>,
    /// How far off the constraints the initial state may be (default 1e-9).
    pub tolerance: Option<f64>,
}

/// The scheme of a scenario that names none: ABM-4, the cheapest line
/// most often on the work-precision diagrams of `docs/precision.md`
/// (Example 1 to 1e-6 and 1e-9, the chain to 1e-3; AB-3 is cheapest on
/// Example 1 to 1e-3 and on the driven slider-crank, RK-4 on the chain to
/// 1e-6), and at equal cost ahead of AB-3 on 22 of the suite's 26 models
/// (`docs/schemes.md`). Stiff damping is where no explicit scheme is: a
/// run it stops says so and names generalized-α.
pub const DEFAULT_SCHEME: Scheme = Scheme::AdamsBashforthMoulton4;

fn default_scheme() -> Scheme {
    DEFAULT_SCHEME
}

/// `[integrator]`.
#[derive(Debug, Deserialize, Clone)]
#[serde(deny_unknown_fields)]
pub struct IntegratorSpec {
    /// The fixed-step scheme (default [`DEFAULT_SCHEME`]).
    #[serde(default = "default_scheme")]
    pub scheme: Scheme,
    /// The step size.
    pub h: f64,
    /// The end time, a whole number of steps.
    pub t_end: f64,
    /// A constraint row that depends on the others: `"error"` (default) or
    /// `"tolerate"` (solved without it; redundant constraints).
    #[serde(default)]
    pub dependent_rows: DependentRows,
    /// Generalized-α's spectral radius at infinite frequency, in [0, 1] (default 0.9).
    pub rho_inf: Option<f64>,
    /// Generalized-α's Newton tolerance on the accelerations' correction, relative to the largest acceleration (default 1e-10).
    pub newton_tolerance: Option<f64>,
    /// Generalized-α's Newton corrections allowed per step (default 20).
    pub newton_max_iterations: Option<u32>,
    /// Generalized-α with exactly this many Newton corrections a step
    /// (real-time runs), in place of a tolerance.
    pub newton_iterations: Option<u32>,
}

impl IntegratorSpec {
    /// Generalized-α's settings from `rho_inf` and the `newton_*` keys,
    /// which no other scheme reads (so they are refused with one).
    pub fn generalized_alpha(&self) -> Result<GeneralizedAlpha> {
        let keys = [
            ("rho_inf", self.rho_inf.is_some()),
            ("newton_tolerance", self.newton_tolerance.is_some()),
            ("newton_max_iterations", self.newton_max_iterations.is_some()),
            ("newton_iterations", self.newton_iterations.is_some()),
        ];
        let given = || keys.iter().filter(|(_, given)| *given).map(|(key, _)| *key);
        if self.scheme != Scheme::GeneralizedAlpha
            && let Some(key) = given().next()
        {
            bail!(
                "{key} is read by scheme = \"generalized_alpha\" only; scheme {} would ignore it",
                self.scheme.info().name
            );
        }
        let mut settings = GeneralizedAlpha::new();
        if let Some(rho) = self.rho_inf {
            settings = settings.with_rho_inf(rho);
        }
        let default = GeneralizedAlpha::new().newton;
        let Newton::Converge { tolerance, max_iterations } = default else { unreachable!("converges by default") };
        settings.newton = match (self.newton_iterations, self.newton_tolerance, self.newton_max_iterations) {
            (Some(_), Some(_), _) | (Some(_), _, Some(_)) => bail!(
                "newton_iterations (a fixed count) and newton_tolerance / newton_max_iterations (iterate to a tolerance) exclude each other"
            ),
            (Some(fixed), ..) => Newton::fixed(fixed),
            (None, t, k) => Newton::converge(t.unwrap_or(tolerance), k.unwrap_or(max_iterations)),
        };
        settings.validate()?;
        Ok(settings)
    }
}

/// `[output]`.
#[derive(Debug, Deserialize, Default, Clone)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Write a sample every this many steps (default 1).
    pub every: Option<i64>,
    /// Name of the case and its CSV file (default: the scenario file's stem).
    pub name: Option<String>,
    /// The outputs of a stepped simulation (Python, C API, FMU), by their
    /// CSV column names; default every column (`cdyn run` writes them all).
    pub select: Option<Vec<String>>,
}

/// Reads and checks a scenario file.
pub fn load(path: &Path) -> Result<Scenario> {
    load_with_table(path).map(|(scenario, _)| scenario)
}

/// Reads and checks a scenario file; also returns the parsed table, which
/// identifies the scenario by content (`cdyn merge`), whatever its path.
pub fn load_with_table(path: &Path) -> Result<(Scenario, toml::Table)> {
    if path.extension().is_some_and(|e| e.eq_ignore_ascii_case("urdf")) {
        return from_table(urdf_scenario(path), &path.display().to_string());
    }
    parse(&read_bounded(path)?, &path.display().to_string())
}

/// `cdyn run robot.urdf`: the robot falling from its zero pose under
/// gravity −z for 1 s, RK-4 at h = 1e-3, `robust`; a scenario file with
/// `[model] kind = "spatial"` and `urdf = "…"` chooses otherwise.
fn urdf_scenario(path: &Path) -> toml::Table {
    let text = format!(
        "[model]\nkind = \"spatial\"\nurdf = {}\ngravity = [0.0, 0.0, -9.81]\n[integrator]\nscheme = \"rk4\"\nh = 1e-3\nt_end = 1.0\n[output]\nevery = 10\n",
        // Read relative to the file's own folder, as a scenario's `urdf` is.
        toml::Value::String(path.file_name().map_or(String::new(), |n| n.to_string_lossy().into_owned()))
    );
    toml::from_str(&text).expect("a valid scenario")
}

/// Reads and checks the scenario `text`; `file` names it in errors (the
/// path, or `<string>` for text given directly). Also returns the parsed table.
pub fn parse(text: &str, file: &str) -> Result<(Scenario, toml::Table)> {
    if text.trim().is_empty() {
        bail!("{file}: the scenario is empty");
    }
    let table: toml::Table = toml::from_str(text).map_err(|e| {
        let at = e.span().map_or(String::new(), |s| {
            let line = text[..s.start].matches('\n').count() + 1;
            let col = s.start - text[..s.start].rfind('\n').map_or(0, |i| i + 1) + 1;
            format!(":{line}:{col}")
        });
        anyhow!("{file}{at}: {}", e.message().trim().replace('\n', " "))
    })?;
    from_table(table, file)
}

/// Checks the parsed scenario `table` (from a file, or built from a Python
/// dict); `file` names it in errors. Returns the table too.
pub fn from_table(table: toml::Table, file: &str) -> Result<(Scenario, toml::Table)> {
    // The library's types check every key; the path to a refused one names
    // the table, entry and key as the file writes them.
    fn read<T: serde::de::DeserializeOwned>(table: &toml::Table, file: &str) -> Result<T> {
        serde_path_to_error::deserialize(toml::Value::Table(table.clone())).map_err(|e| {
            let place = locate(&[], table, e.path());
            anyhow!("{file}: {place}{}", reason(e.inner()))
        })
    }
    // Without [model] the kind is unknown, and its entries (a spatial
    // body's inertia tensor, say) would be refused as the wrong kind's.
    if !table.contains_key("model") {
        bail!("{file}: missing field model: a scenario needs a [model] table with its kind");
    }
    // A spatial mechanism's bodies and joints have their own types.
    let spatial = table.get("model").and_then(|m| m.get("kind")).and_then(|k| k.as_str()) == Some("spatial");
    if spatial && table.contains_key("drives") {
        bail!("{file}: a spatial mechanism has no [[drives]]: a joint is driven by its angle or displacement key");
    }
    let (mut scenario, entries): (Scenario, Option<SpatialEntries>) = if spatial {
        let mut rest = table.clone();
        let entries: toml::Table = ["bodies", "joints", "forces", "actuators"]
            .into_iter()
            .filter_map(|key| rest.remove(key).map(|v| (key.to_string(), v)))
            .collect();
        (read(&rest, file)?, Some(read(&entries, file)?))
    } else {
        (read(&placeholders(&table, file)?, file)?, None)
    };
    scenario.spatial = entries;
    Ok((scenario, table))
}

/// Largest scenario file read: scenarios are a few kilobytes, and reading
/// stops here, so that a wrong path (`/dev/zero`, a data file) is refused at
/// once instead of filling the memory.
pub const MAX_SCENARIO_BYTES: u64 = 16 << 20;

/// The text of the scenario file at `path`, at most [`MAX_SCENARIO_BYTES`].
pub(crate) fn read_bounded(path: &Path) -> Result<String> {
    use std::io::Read;
    let file = path.display();
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .and_then(|f| f.take(MAX_SCENARIO_BYTES + 1).read_to_end(&mut bytes))
        .map_err(|e| anyhow!("{file}: cannot read: {e}"))?;
    if bytes.len() as u64 > MAX_SCENARIO_BYTES {
        bail!("{file}: larger than {} MB, not a scenario (a scenario is a small TOML file)", MAX_SCENARIO_BYTES >> 20);
    }
    String::from_utf8(bytes).map_err(|e| anyhow!("{file}: not UTF-8 text (byte {})", e.utf8_error().valid_up_to()))
}

//! `cdyn._cdyn`, the native part of the Python package `cdyn`: thin over the
//! CLI's library (crates/cdyn-cli), so scenarios are read, cases built and
//! run, and errors worded exactly as `cdyn run`, `compare`, `sweep`,
//! `suite`, `precision` and `paper` do. The Python layer (python/cdyn) wraps what these functions
//! return in result classes.
//!
//! Every run happens with the GIL released; failures become `cdyn.Error`
//! subclasses carrying the CLI's one-line message, never a crash.

use cdyn_cli::case::runner::{
    Case, CaseResult, Estimate, OUTPUT_LIMIT, Rows, columns, every_to_fit, run_case_in_memory,
};
use cdyn_cli::case::scenario;
use cdyn_cli::study::precision::{self, Methods, Options};
use cdyn_cli::study::{paper, suite, sweep};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::create_exception;
use pyo3::exceptions::PyException;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use std::path::PathBuf;

mod robot;
mod stepping;

create_exception!(_cdyn, Error, PyException, "Any error of cdyn; the message is the CLI's one line.");
create_exception!(_cdyn, ScenarioError, Error, "A scenario that cannot be read or run as written.");
create_exception!(_cdyn, SimulationError, Error, "A run that failed part-way (diverged, singular, ...).");

/// The CLI's one-line wording of `e` (as after `error: `).
fn line(e: &anyhow::Error) -> String {
    format!("{e:#}").replace('\n', " ")
}

pub(crate) fn scenario_error(e: anyhow::Error) -> PyErr {
    ScenarioError::new_err(line(&e))
}

/// A checked scenario, as read from a file, a TOML string or a dict.
#[pyclass(frozen, module = "cdyn._cdyn")]
pub(crate) struct Scenario {
    pub(crate) parsed: scenario::Scenario,
    table: toml::Table,
    /// What errors name: the path, `<string>` or `<dict>`.
    file: String,
}

#[pymethods]
impl Scenario {
    /// What errors name this scenario by: its path, `<string>` or `<dict>`.
    #[getter]
    fn file(&self) -> &str {
        &self.file
    }

    /// Whether the scenario has a `[sweep]` table.
    #[getter]
    fn has_sweep(&self) -> bool {
        self.parsed.sweep.is_some()
    }

    /// The scenario as TOML text (the parsed table, written back).
    fn to_toml(&self) -> PyResult<String> {
        toml::to_string(&self.table).map_err(|e| Error::new_err(e.to_string()))
    }

    fn __repr__(&self) -> String {
        format!("Scenario({:?})", self.file)
    }
}

impl Scenario {
    pub(crate) fn path(&self) -> PathBuf {
        PathBuf::from(&self.file)
    }

    /// The case `cdyn run` would run, checked as it checks it.
    fn case(&self) -> anyhow::Result<Case> {
        let path = self.path();
        self.parsed.refuse_sweep(&path, "run")?;
        let mut case = self.parsed.case(&path)?;
        case.check().map_err(|e| anyhow::anyhow!("{}: {e}", self.file))?;
        if self.parsed.output.name.is_none() && !std::path::Path::new(&self.file).exists() {
            // A string or dict has no file stem to name the case by.
            case.name = "run".into();
        }
        Ok(case)
    }
}

/// Reads and checks the scenario file at `path`.
#[pyfunction]
fn load(path: PathBuf) -> PyResult<Scenario> {
    let (parsed, table) = scenario::load_with_table(&path).map_err(scenario_error)?;
    Ok(Scenario { parsed, table, file: path.display().to_string() })
}

/// Reads and checks the scenario TOML `text`; `file` names it in errors.
#[pyfunction]
#[pyo3(signature = (text, file = "<string>"))]
fn loads(text: &str, file: &str) -> PyResult<Scenario> {
    let (parsed, table) = scenario::parse(text, file).map_err(scenario_error)?;
    Ok(Scenario { parsed, table, file: file.into() })
}

/// Reads and checks a scenario given as a dict of the file's schema; `file` names it in errors.
#[pyfunction]
#[pyo3(signature = (data, file = "<dict>"))]
fn from_dict(data: &Bound<'_, PyAny>, file: &str) -> PyResult<Scenario> {
    let table = match to_toml(data, "")? {
        toml::Value::Table(t) => t,
        _ => {
            return Err(ScenarioError::new_err(format!(
                "{file}: expected a dict of tables ([model], [integrator], ...)"
            )));
        }
    };
    let (parsed, table) = scenario::from_table(table, file).map_err(scenario_error)?;
    Ok(Scenario { parsed, table, file: file.into() })
}

/// `value` as a TOML value; `at` is its key path, for the error.
fn to_toml(value: &Bound<'_, PyAny>, at: &str) -> PyResult<toml::Value> {
    let unsupported = || {
        let kind = value.get_type().name().map(|n| n.to_string()).unwrap_or_else(|_| "?".into());
        ScenarioError::new_err(format!(
            "<dict>: {}: a value of type {kind} has no TOML form (use dict, list, str, int, float, bool)",
            if at.is_empty() { "the scenario" } else { at }
        ))
    };
    if value.is_instance_of::<PyBool>() {
        Ok(toml::Value::Boolean(value.extract()?))
    } else if value.is_instance_of::<PyInt>() {
        Ok(toml::Value::Integer(value.extract().map_err(|_| unsupported())?))
    } else if value.is_instance_of::<PyFloat>() {
        Ok(toml::Value::Float(value.extract()?))
    } else if value.is_instance_of::<PyString>() {
        Ok(toml::Value::String(value.extract()?))
    } else if let Ok(d) = value.cast::<PyDict>() {
        let mut table = toml::Table::new();
        for (k, v) in d.iter() {
            let key: String = k.extract().map_err(|_| unsupported())?;
            let here = if at.is_empty() { key.clone() } else { format!("{at}.{key}") };
            table.insert(key, to_toml(&v, &here)?);
        }
        Ok(toml::Value::Table(table))
    } else if value.is_instance_of::<PyList>() || value.is_instance_of::<PyTuple>() {
        let items = value.try_iter()?.enumerate().map(|(i, v)| to_toml(&v?, &format!("{at}[{i}]")));
        Ok(toml::Value::Array(items.collect::<PyResult<_>>()?))
    } else if let Ok(i) = value.extract::<i64>() {
        // NumPy's integers and other integers (through `__index__`).
        Ok(toml::Value::Integer(i))
    } else if let Ok(x) = value.extract::<f64>() {
        // NumPy's floats and other numbers.
        Ok(toml::Value::Float(x))
    } else {
        Err(unsupported())
    }
}

/// What a run hands to Python: the summary entry (JSON text, as in
/// `summary.json`), the column names, and the samples as flat arrays.
fn to_python<'py>(py: Python<'py>, (result, rows, lambda): Done) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let summary = serde_json::to_string(&result).map_err(|e| Error::new_err(e.to_string()))?;
    d.set_item("summary", summary)?;
    let lambda =
        lambda.map(|(values, m)| PyArray1::from_vec(py, values).reshape([rows.t_exact.len(), m])).transpose()?;
    d.set_item("lambda", lambda)?;
    d.set_item("error", result.error.clone())?;
    let (width, n) = (rows.columns.len(), result.record.q_end.len().max(1));
    d.set_item("columns", rows.columns)?;
    let samples = rows.values.len() / width.max(1);
    d.set_item("values", PyArray1::from_vec(py, rows.values).reshape([samples, width])?)?;
    let states = rows.q.len() / n;
    d.set_item("q", PyArray1::from_vec(py, rows.q).reshape([states, n])?)?;
    d.set_item("v", PyArray1::from_vec(py, rows.v).reshape([states, n])?)?;
    Ok(d)
}

/// A finished run: its summary, its samples, and where asked the multipliers
/// λ at each sample with their count per sample.
type Done = (CaseResult, Rows, Option<(Vec<f64>, usize)>);

/// Refuses cases whose samples would take more than [`OUTPUT_LIMIT`] of
/// memory (unless `force`): the interpreter would run out of memory instead of
/// raising. A sample keeps its CSV row, `q`, `v`, its time and λ where asked.
fn check_memory(cases: &[Case], file: &str, multipliers: bool, force: bool) -> PyResult<()> {
    let bytes = |c: &Case| {
        let rows = Estimate::of(std::slice::from_ref(c)).rows;
        let model = &c.example.model;
        let per_row = columns(&c.example).len() + 2 * model.n() + 1 + if multipliers { model.m() } else { 0 };
        rows.saturating_mul(8 * per_row as u64)
    };
    let total = cases.iter().map(bytes).fold(0u64, u64::saturating_add);
    if force || total <= OUTPUT_LIMIT {
        return Ok(());
    }
    let every = cases.first().map_or(1, |c| c.every);
    Err(ScenarioError::new_err(format!(
        "{file}: the run would keep about {:.1} GB of samples in memory at [output] every = {every}, above the limit of {} GB; set [output] every = {} or larger, or pass force=True",
        total as f64 / 1e9,
        OUTPUT_LIMIT / 1_000_000_000,
        every_to_fit(every, total)
    )))
}

/// Runs `cases` in turn with the GIL released; with `multipliers`, λ at every sample too.
fn run_all<'py>(py: Python<'py>, cases: Vec<Case>, multipliers: bool) -> PyResult<Vec<Bound<'py, PyDict>>> {
    // Ctrl-C: Python's signal handlers run only when asked, so a run asks
    // every few thousand steps (taking the GIL for a moment) and keeps the
    // KeyboardInterrupt to raise when it has stopped.
    let interrupt = std::sync::Mutex::new(None::<PyErr>);
    let stop = || {
        Python::attach(|py| py.check_signals())
            .map_err(|e| *interrupt.lock().unwrap_or_else(|p| p.into_inner()) = Some(e))
            .is_err()
    };
    let done = py.detach(|| {
        let mut done = Vec::new();
        for case in &cases {
            let (result, rows) = run_case_in_memory(case, &stop);
            let lambda = multipliers.then(|| (lambda_at_samples(case, &rows), case.example.model.m()));
            let interrupted = result.interrupted;
            done.push((result, rows, lambda));
            if interrupted {
                break;
            }
        }
        done
    });
    if let Some(e) = interrupt.into_inner().unwrap_or_else(|p| p.into_inner()) {
        return Err(e);
    }
    done.into_iter().map(|d| to_python(py, d)).collect()
}

/// The Lagrange multipliers λ of Eq. 7 at each sampled state (t, q, v), one
/// row of `m` per sample, NaN where the dynamics cannot be evaluated there.
fn lambda_at_samples(case: &Case, rows: &Rows) -> Vec<f64> {
    let model = &case.example.model;
    let (n, m) = (model.n(), model.m());
    let mut dynamics = cdyn::dynamics::Dynamics::new(model);
    let mut out = Vec::with_capacity(rows.t_exact.len() * m);
    for (k, &t) in rows.t_exact.iter().enumerate() {
        let (q, v) = (&rows.q[k * n..(k + 1) * n], &rows.v[k * n..(k + 1) * n]);
        match dynamics.evaluate(model, q, v, t) {
            Ok(()) => out.extend_from_slice(dynamics.lambda()),
            Err(_) => out.extend(std::iter::repeat_n(f64::NAN, m)),
        }
    }
    out
}

/// Runs the scenario as `cdyn run` does; returns the raw result (see `cdyn.run`).
#[pyfunction]
#[pyo3(signature = (scenario, multipliers = false, force = false))]
fn run<'py>(py: Python<'py>, scenario: &Scenario, multipliers: bool, force: bool) -> PyResult<Bound<'py, PyDict>> {
    let case = scenario.case().map_err(scenario_error)?;
    check_memory(std::slice::from_ref(&case), &scenario.file, multipliers, force)?;
    let mut all = run_all(py, vec![case], multipliers)?;
    Ok(all.remove(0))
}

/// Runs the scenario under every method of `cdyn compare`.
#[pyfunction]
#[pyo3(signature = (scenario, multipliers = false, force = false))]
fn compare<'py>(
    py: Python<'py>,
    scenario: &Scenario,
    multipliers: bool,
    force: bool,
) -> PyResult<Vec<Bound<'py, PyDict>>> {
    let path = scenario.path();
    scenario.parsed.refuse_sweep(&path, "compare").map_err(scenario_error)?;
    let cases = cdyn_cli::study::compare::cases(&scenario.parsed, &path).map_err(scenario_error)?;
    check_memory(&cases, &scenario.file, multipliers, force)?;
    run_all(py, cases, multipliers)
}

/// Runs every case of the paper's Example 1 (`cdyn paper`).
#[pyfunction]
#[pyo3(signature = (multipliers = false))]
fn paper_cases<'py>(py: Python<'py>, multipliers: bool) -> PyResult<Vec<Bound<'py, PyDict>>> {
    let cases = paper::cases().map_err(scenario_error)?;
    run_all(py, cases, multipliers)
}

/// Runs the scenario's `[sweep]` grid on `threads` threads (one per core by
/// default); returns `sweep.json` as text.
#[pyfunction]
#[pyo3(signature = (scenario, threads = None))]
fn run_sweep(py: Python<'_>, scenario: &Scenario, threads: Option<usize>) -> PyResult<String> {
    if threads == Some(0) {
        return Err(Error::new_err("threads = 0: need at least one thread"));
    }
    let path = scenario.path();
    let result =
        py.detach(|| sweep::run(&scenario.parsed, &scenario.table, &path, None, threads)).map_err(scenario_error)?;
    serde_json::to_string(&result).map_err(|e| Error::new_err(e.to_string()))
}

/// Runs the method suite (`cdyn suite`: the shipped models, the light part
/// of them with `light`, and `scenarios`); returns `suite.json` as text and
/// the table `cdyn suite` prints.
#[pyfunction]
#[pyo3(signature = (scenarios, light = false))]
fn run_suite(py: Python<'_>, scenarios: Vec<PathBuf>, light: bool) -> PyResult<(String, String)> {
    let result = py.detach(|| suite::run(&scenarios, light)).map_err(scenario_error)?;
    let json = serde_json::to_string_pretty(&result.json()).map_err(|e| Error::new_err(e.to_string()))? + "\n";
    Ok((json, suite::table(&result) + &suite::summary(&result)))
}

/// Runs `cdyn precision` on the scenario file `scenario`: every scheme of
/// `schemes` (all when empty) × method of `methods` (`cdyn compare`'s names;
/// none, robust and projection when empty; `["all"]` every one) at each
/// step of `h` (the scenario's h × 4, 2, 1, 1/2, 1/4 when empty); returns
/// `precision.json` as text, `precision.csv` and the table the CLI prints.
#[pyfunction]
#[pyo3(signature = (scenario, schemes = Vec::new(), methods = Vec::new(), h = Vec::new(), t_end = None, light = false))]
fn run_precision(
    py: Python<'_>,
    scenario: PathBuf,
    schemes: Vec<String>,
    methods: Vec<String>,
    h: Vec<f64>,
    t_end: Option<f64>,
    light: bool,
) -> PyResult<(String, String, String)> {
    let schemes = schemes
        .into_iter()
        .map(cdyn::Scheme::try_from)
        .collect::<Result<Vec<_>, _>>()
        .map_err(ScenarioError::new_err)?;
    let methods = Methods::from_names(&methods);
    let options = Options { schemes, methods, steps: h, t_end, light };
    let result = py.detach(|| precision::run(&scenario, &options)).map_err(scenario_error)?;
    let json = serde_json::to_string_pretty(&result).map_err(|e| Error::new_err(e.to_string()))? + "\n";
    Ok((json, precision::csv(&result), precision::table(&result)))
}

/// The native module.
#[pymodule]
fn _cdyn(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("Error", py.get_type::<Error>())?;
    m.add("ScenarioError", py.get_type::<ScenarioError>())?;
    m.add("SimulationError", py.get_type::<SimulationError>())?;
    m.add_class::<Scenario>()?;
    m.add_class::<stepping::Simulation>()?;
    m.add_class::<stepping::SimulationState>()?;
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(loads, m)?)?;
    m.add_function(wrap_pyfunction!(from_dict, m)?)?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(compare, m)?)?;
    m.add_function(wrap_pyfunction!(paper_cases, m)?)?;
    m.add_function(wrap_pyfunction!(run_sweep, m)?)?;
    m.add_function(wrap_pyfunction!(run_suite, m)?)?;
    m.add_function(wrap_pyfunction!(run_precision, m)?)?;
    m.add_function(wrap_pyfunction!(robot::urdf_joints, m)?)?;
    m.add_function(wrap_pyfunction!(robot::urdf_tree, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}

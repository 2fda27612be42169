//! `cdyn._cdyn.Simulation`: a scenario's case stepped from Python — inputs
//! set and outputs read between steps, the state read, written, saved and
//! restored — over the CLI library's [`Live`], which the C API and FMUs
//! step too. Steps run with the GIL released.

use crate::{Scenario, SimulationError, scenario_error};
use cdyn_cli::case::live::{Live, LiveSnapshot};
use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;

/// A scenario's case, stepped from outside.
#[pyclass(module = "cdyn._cdyn")]
pub(crate) struct Simulation {
    live: Live,
}

/// A saved simulation ([`Simulation::snapshot`]).
#[pyclass(frozen, module = "cdyn._cdyn")]
pub(crate) struct SimulationState {
    snapshot: LiveSnapshot,
}

fn simulation_error(e: cdyn::Error) -> PyErr {
    SimulationError::new_err(e.to_string())
}

#[pymethods]
impl Simulation {
    /// The case of `scenario` (as `cdyn run` builds it), at its initial state.
    #[new]
    fn new(scenario: &Scenario) -> PyResult<Self> {
        let live = Live::from_scenario(&scenario.parsed, &scenario.path()).map_err(scenario_error)?;
        Ok(Simulation { live })
    }

    /// The inputs' names, in order.
    #[getter]
    fn input_names(&self) -> Vec<String> {
        self.live.input_names().into_iter().map(String::from).collect()
    }

    /// The outputs' names, in order.
    #[getter]
    fn output_names(&self) -> Vec<String> {
        self.live.output_names().to_vec()
    }

    /// Current time.
    #[getter]
    fn t(&self) -> f64 {
        self.live.t()
    }

    /// Steps taken.
    #[getter]
    fn steps(&self) -> u64 {
        self.live.steps()
    }

    /// The step size.
    #[getter]
    fn h(&self) -> f64 {
        self.live.h()
    }

    /// Sets an input, by position or name.
    fn set_input(&mut self, input: &Bound<'_, PyAny>, value: f64) -> PyResult<()> {
        let set = match input.extract::<usize>() {
            Ok(index) => self.live.set_input(index, value),
            Err(_) => self.live.set_input_named(&input.extract::<String>()?, value),
        };
        set.map_err(|e| crate::Error::new_err(e.to_string()))
    }

    /// The current value of input `index`.
    fn input(&self, index: usize) -> PyResult<f64> {
        self.live.input(index).map_err(|e| crate::Error::new_err(e.to_string()))
    }

    /// Takes `n` steps (the GIL released).
    #[pyo3(signature = (n = 1))]
    fn step(&mut self, py: Python<'_>, n: u64) -> PyResult<()> {
        let live = &mut self.live;
        py.detach(|| live.step(n)).map_err(simulation_error)
    }

    /// The outputs at the current state.
    fn outputs<'py>(&mut self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let mut out = vec![0.0; self.live.output_names().len()];
        self.live.outputs(&mut out);
        PyArray1::from_vec(py, out)
    }

    /// The full state: positions, velocities and ∫Ė.
    fn state<'py>(&self, py: Python<'py>) -> (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>, f64) {
        (PyArray1::from_slice(py, self.live.q()), PyArray1::from_slice(py, self.live.v()), self.live.energy_input())
    }

    /// Puts the simulation at the state `(q, v, e)` (as `state()` returns it); the scheme starts again there.
    fn set_state(&mut self, q: PyReadonlyArray1<'_, f64>, v: PyReadonlyArray1<'_, f64>, e: f64) -> PyResult<()> {
        let (q, v) = (q.as_slice()?, v.as_slice()?);
        self.live.set_state(q, v, e).map_err(|e| crate::Error::new_err(e.to_string()))
    }

    /// What the case's joint limits did so far, as `summary.json`'s
    /// `limits` (JSON text); `None` without limits.
    fn limits_json(&self) -> PyResult<Option<String>> {
        let report = self.live.limits();
        report.map(|r| serde_json::to_string(&r).map_err(|e| crate::Error::new_err(e.to_string()))).transpose()
    }

    /// Everything needed to come back to this point of the run.
    fn snapshot(&self) -> SimulationState {
        SimulationState { snapshot: self.live.snapshot() }
    }

    /// Goes back to a snapshot of this simulation.
    fn restore(&mut self, state: &SimulationState) -> PyResult<()> {
        self.live.restore(&state.snapshot).map_err(|e| crate::Error::new_err(e.to_string()))
    }

    fn __repr__(&self) -> String {
        format!("Simulation(t = {}, inputs {:?})", self.live.t(), self.live.input_names())
    }
}

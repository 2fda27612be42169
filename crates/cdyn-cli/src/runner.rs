//! Runs one case and records it: a CSV row per sample, written as the run
//! goes so that a run which fails keeps what it wrote, plus the series and
//! statistics the summary and figures need.

use anyhow::{Context, Result};
use cdyn::models::Example;
use cdyn::{Settings, Simulation};
use serde::Serialize;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

/// One case to run.
pub struct Case {
    pub name: String,
    pub example: Example,
    pub settings: Settings,
    pub t_end: f64,
    /// Write a sample every this many steps.
    pub every: u64,
    /// What projecting the initial state onto the constraints changed, if it was done.
    pub assembly: Option<cdyn::assemble::Assembly>,
}

impl Case {
    /// Checks that the case can start: settings valid, initial state consistent.
    pub fn check(&self) -> cdyn::Result<()> {
        Simulation::new(&self.example.model, self.settings, &self.example.q0, &self.example.v0).map(|_| ())
    }
}

/// What a case produced.
#[derive(Debug, Clone, Serialize)]
pub struct CaseResult {
    pub name: String,
    /// The observable whose error against the reference is reported.
    pub error_observable: String,
    pub scheme: &'static str,
    pub h: f64,
    pub max_abs_phi: f64,
    pub max_abs_psi: f64,
    /// `null` when the model has no reference solution.
    pub max_abs_err_x: Option<f64>,
    pub err_x_final: Option<f64>,
    pub max_abs_coupling: f64,
    pub steps: u64,
    pub t_final: f64,
    pub rhs_evals: u64,
    pub q_end: Vec<f64>,
    pub v_end: Vec<f64>,
    /// `None` when the run finished; the error otherwise.
    pub error: Option<String>,
    #[serde(skip)]
    pub series: Series,
}

/// Sampled time histories, for the figures.
#[derive(Debug, Clone, Default)]
pub struct Series {
    pub t: Vec<f64>,
    pub phi: Vec<f64>,
    pub psi: Vec<f64>,
    pub err: Vec<f64>,
}

/// Header of a case's CSV: `t`, the observables, `phi`, `psi`, and
/// `err_<first observable>` when there is a reference.
fn header(example: &Example) -> String {
    let mut cols = vec!["t".to_string()];
    cols.extend(example.observables.iter().cloned());
    cols.extend(["phi".into(), "psi".into()]);
    if example.reference.is_some() {
        cols.push(format!("err_{}", example.observables[0].to_lowercase()));
    }
    cols.join(",")
}

/// Runs `case`, writing `dir/<name>.csv`. A simulation error is recorded in
/// the result (the CSV keeps every row before it); I/O errors are returned.
pub fn run_case(case: &Case, dir: &Path) -> Result<CaseResult> {
    let path = dir.join(format!("{}.csv", case.name));
    let file = File::create(&path).with_context(|| format!("cannot create {}", path.display()))?;
    let mut csv = BufWriter::new(file);
    writeln!(csv, "{}", header(&case.example))?;
    let result = simulate(case, &mut csv);
    csv.flush().with_context(|| format!("cannot write {}", path.display()))?;
    result.map_err(|e| e.context(format!("cannot write {}", path.display())))
}

/// Runs `case` keeping only its statistics (for sweeps).
pub fn run_case_quietly(case: &Case) -> CaseResult {
    simulate(case, &mut std::io::sink()).expect("writing to a sink cannot fail")
}

/// Runs `case`, writing CSV rows to `csv`; simulation errors are recorded in
/// the result, write errors returned.
fn simulate(case: &Case, csv: &mut impl Write) -> Result<CaseResult> {
    let ex = &case.example;
    let mut result = CaseResult {
        name: case.name.clone(),
        error_observable: ex.observables[0].clone(),
        scheme: case.settings.scheme.info().name,
        h: case.settings.h,
        max_abs_phi: 0.0,
        max_abs_psi: 0.0,
        max_abs_err_x: ex.reference.as_ref().map(|_| 0.0),
        err_x_final: None,
        max_abs_coupling: 0.0,
        steps: 0,
        t_final: 0.0,
        rhs_evals: 0,
        q_end: Vec::new(),
        v_end: Vec::new(),
        error: None,
        series: Series::default(),
    };
    let outcome =
        Simulation::new(&ex.model, case.settings, &ex.q0, &ex.v0).map_err(anyhow::Error::from).and_then(|mut sim| {
            let run = sim.run(case.t_end, case.every, |s| record(s, ex, csv, &mut result));
            result.steps = sim.steps();
            result.t_final = sim.t();
            result.rhs_evals = sim.evaluations();
            result.q_end = sim.q().to_vec();
            result.v_end = sim.v().to_vec();
            run
        });
    if let Err(e) = outcome {
        if e.downcast_ref::<cdyn::Error>().is_none() {
            return Err(e);
        }
        result.error = Some(format!("case {}: {e}", case.name));
    }
    Ok(result)
}

fn record(sim: &mut Simulation, ex: &Example, csv: &mut impl Write, r: &mut CaseResult) -> Result<()> {
    let m = sim.measure();
    let (t, q, v) = (sim.t(), sim.q(), sim.v());
    let err = ex.error(q, v, t);
    write!(csv, "{t:e}")?;
    for o in ex.observe(q, v) {
        write!(csv, ",{o:e}")?;
    }
    write!(csv, ",{:e},{:e}", m.phi, m.psi)?;
    if let Some(e) = err {
        write!(csv, ",{e:e}")?;
        r.max_abs_err_x = Some(r.max_abs_err_x.unwrap_or(0.0).max(e.abs()));
        r.err_x_final = Some(e);
        r.series.err.push(e);
    }
    writeln!(csv)?;
    r.max_abs_phi = r.max_abs_phi.max(m.phi.abs());
    r.max_abs_psi = r.max_abs_psi.max(m.psi.abs());
    r.max_abs_coupling = r.max_abs_coupling.max(m.coupling);
    r.series.t.push(t);
    r.series.phi.push(m.phi);
    r.series.psi.push(m.psi);
    Ok(())
}

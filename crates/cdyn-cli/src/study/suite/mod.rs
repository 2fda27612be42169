//! `cdyn suite`: every method of `cdyn compare` on many models, at AB-3,
//! RK-4 and ABM-4, and RATTLE and generalized-α with the methods they take
//! (none and projection), at the scenario's `h` and `h/2`, judged against
//! a fine reference, so that a method which makes the answer worse than no
//! control shows.
//!
//! The reference is the same model without control, RK-4 with step `h/20`
//! (`h` the scenario's, the coarser step). Every run is sampled at the
//! common times `t = k·h` (every step of the coarse runs, every second of
//! the fine ones, every twentieth of the reference), and its error is the
//! largest `|q_i − q_ref,i|` over those samples and all positions. A run that
//! stops with an error counts as infinitely wrong. The violations are the
//! largest over every step after `t = 0`; those at `t = 0` (the assembly's)
//! are kept apart.
//!
//! May import: `io`, `case`, and the rest of `study`.

use crate::case::runner::Case;
use crate::case::scenario::{self, Scenario};
use crate::study::compare;
use anyhow::{Context, Result, anyhow};
use cdyn::simulate::{nearest_valid_t_end, steps_to};
use cdyn::{Control, Scheme, Simulation};
use rayon::prelude::*;
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::time::Instant;

mod output;
mod verdicts;

pub use output::{summary, table, write};
use verdicts::verdicts;

/// The schemes every model runs at.
const SCHEMES: [Scheme; 5] = [
    Scheme::AdamsBashforth3,
    Scheme::RungeKutta4,
    Scheme::AdamsBashforthMoulton4,
    Scheme::Rattle,
    Scheme::GeneralizedAlpha,
];
/// The step sizes every model runs at, as divisors of the scenario's `h`.
const DIVISORS: [u64; 2] = [1, 2];
/// The reference step is the scenario's `h` over this.
const REFERENCE_DIVISOR: u64 = 20;
/// The shipped models of `--light`, by file stem.
const LIGHT: [&str; 4] = ["example1", "pendulum_rest", "mixed_masses", "slider_crank"];
/// `--light` runs to this fraction of each scenario's `t_end`.
const LIGHT_T_END: f64 = 0.5;

/// The largest `|Φ|` after a step of the schemes that hold the constraints
/// themselves, without control (check g): RATTLE's position tolerance is
/// 256 ε and generalized-α's Newton stops at 100 ε of the largest
/// coordinate, far below this for the suite's sizes.
pub const HELD_PHI: f64 = 1e-9;

/// The checks, by letter, as the summary states them. Checks a–d and f
/// judge `robust`, so they apply to the explicit schemes only.
pub const CHECKS: [(&str, &str); 7] = [
    ("a", "robust error <= 2 x projection error"),
    ("b", "robust error <= none error, where projection error <= none error"),
    ("c", "robust error <= none error / 10, where none error > 1e-4"),
    (
        "d",
        "robust max|phi|, max|psi| <= none's / 10, where none's > 1e-8 (psi: where some motion is free and robust's energy term is on)",
    ),
    ("e", "every method keeps each linear momentum the model keeps to 1e3 eps of its scale"),
    ("f", "robust's momentum drift <= none's (or round-off), where the model keeps a momentum"),
    ("g", "rattle and generalized_alpha hold max|phi| <= 1e-9 without control"),
];

/// The shipped suite, `examples/suite` of the source tree the binary was built from.
fn shipped_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/suite")
}

/// One model of the suite: its file, read and turned into every case to run.
struct Model {
    name: String,
    path: PathBuf,
    /// The scenario's `h`: the coarser step and the sampling interval.
    h: f64,
    t_end: f64,
    /// The cases of `compare` at each scheme and step.
    setups: Vec<(Scheme, f64, Vec<Case>)>,
}

/// One method's run at one scheme and step.
#[derive(Debug, Clone, Serialize)]
pub struct Run {
    /// The case name of `cdyn compare`.
    pub method: String,
    /// Largest `|q_i − q_ref,i|` over the samples; infinite if the run stopped.
    #[serde(serialize_with = "cdyn::json_float::serialize")]
    pub max_error: f64,
    /// `max_error` over that of `none` (`theta` for a model without constraints).
    #[serde(serialize_with = "cdyn::json_float::serialize")]
    pub error_vs_none: f64,
    /// `max_error` over that of `projection`.
    #[serde(serialize_with = "cdyn::json_float::serialize")]
    pub error_vs_projection: f64,
    /// Largest `|Φ|` over the steps after `t = 0`.
    #[serde(serialize_with = "cdyn::json_float::serialize")]
    pub max_abs_phi: f64,
    /// Largest `|Φ̇|` over the steps after `t = 0`.
    #[serde(serialize_with = "cdyn::json_float::serialize")]
    pub max_abs_phi_dot: f64,
    /// Largest `|Ψ|` over the steps after `t = 0`.
    #[serde(serialize_with = "cdyn::json_float::serialize")]
    pub max_abs_psi: f64,
    /// Largest `|Ψ| / max(1, T + |V|)`: what the projection's tolerance bounds.
    #[serde(serialize_with = "cdyn::json_float::serialize")]
    pub max_relative_psi: f64,
    /// `|Φ|`, `|Φ̇|`, `|Ψ|` at `t = 0`.
    #[serde(serialize_with = "cdyn::json_float::serialize")]
    pub initial: Vec<f64>,
    /// Steps taken.
    pub steps: u64,
    /// The largest rate × h of its control terms (`None` if it did not start).
    #[serde(serialize_with = "cdyn::json_float::serialize")]
    pub rate_h: Option<f64>,
    /// Whether its automatic energy term was left out, the damping being
    /// stiff against the step (`cdyn::control::gains::STIFF_DISSIPATION_H`).
    pub energy_left_out: bool,
    /// The most constraint rows one evaluation dropped as dependent.
    pub dependent_rows: usize,
    /// Mean Newton iterations per step of its projection, if it projects.
    #[serde(serialize_with = "cdyn::json_float::serialize")]
    pub projection_iterations_per_step: Option<f64>,
    /// The tolerance of its projection, if it projects.
    #[serde(serialize_with = "cdyn::json_float::serialize")]
    pub projection_tolerance: Option<f64>,
    /// Largest drift of a kept momentum linear in the state, over its
    /// scale (`None` where the model keeps none).
    #[serde(serialize_with = "cdyn::json_float::serialize")]
    pub linear_momentum_drift: Option<f64>,
    /// Largest drift of any kept momentum over its scale (`None` where the model keeps none).
    #[serde(serialize_with = "cdyn::json_float::serialize")]
    pub momentum_drift: Option<f64>,
    /// Why it stopped, if it did.
    pub error: Option<String>,
}

/// One check of one group: whether its condition holds there, and whether it passed.
#[derive(Debug, Clone)]
pub struct Verdict {
    /// The check's condition holds (a check that does not apply passes).
    pub applies: bool,
    /// It passed.
    pub pass: bool,
    /// The numbers it compared.
    pub numbers: String,
}

/// A model at one scheme and step: every method's run and the checks.
#[derive(Debug, Clone)]
pub struct Group {
    /// The model's name (its file stem).
    pub model: String,
    /// Its scenario file.
    pub file: String,
    /// The scheme's name.
    pub scheme: &'static str,
    /// The step.
    pub h: f64,
    /// The end time.
    pub t_end: f64,
    /// Interval of the samples compared with the reference.
    pub sample_interval: f64,
    /// The reference's step.
    pub reference_h: f64,
    /// The method without control the others are compared with (`none` or `theta`).
    pub baseline: String,
    /// Fewer independent constraint rows than coordinates. Without free motion (a fully
    /// driven mechanism) `T` and `V` follow from the drives, `Ψ` is only the
    /// quadrature error of `∫Ė`, and no method can change it: check (d)
    /// then compares `Φ` alone.
    pub free_motion: bool,
    /// One per method.
    pub runs: Vec<Run>,
    /// The checks, in the order of [`CHECKS`].
    pub verdicts: Vec<Verdict>,
}

/// Everything the suite measured.
pub struct Suite {
    /// Whether it was the `--light` suite.
    pub light: bool,
    /// Each model's name and the wall-clock seconds it took (not in suite.json).
    pub seconds: Vec<(String, f64)>,
    /// One per model, scheme and step.
    pub groups: Vec<Group>,
}

/// Reads the shipped suite (the light part of it with `light`) and `extra`,
/// and builds every case: a bad file fails here, before anything runs.
fn models(extra: &[PathBuf], light: bool) -> Result<Vec<Model>> {
    let dir = shipped_dir();
    let mut paths = Vec::new();
    for entry in std::fs::read_dir(&dir).with_context(|| format!("cannot read the suite {}", dir.display()))? {
        let path = entry.with_context(|| format!("cannot read the suite {}", dir.display()))?.path();
        let stem = path.file_stem().map_or(String::new(), |s| s.to_string_lossy().into_owned());
        if path.extension().is_some_and(|e| e == "toml") && (!light || LIGHT.contains(&stem.as_str())) {
            paths.push(path);
        }
    }
    paths.sort();
    paths.extend(extra.iter().cloned());
    let mut models: Vec<Model> = Vec::new();
    for path in paths {
        let stem = path.file_stem().map_or("model".into(), |s| s.to_string_lossy().into_owned());
        // Two files of the same stem stay apart by their paths.
        let name = if models.iter().any(|m| m.name == stem) { path.display().to_string() } else { stem };
        models.push(model(name, path, light)?);
    }
    Ok(models)
}

/// One suite file and its cases at every scheme and step.
fn model(name: String, path: PathBuf, light: bool) -> Result<Model> {
    let mut scenario: Scenario = scenario::load(&path)?;
    scenario.refuse_sweep(&path, "suite")?;
    // The file as written must be valid before --light shortens it.
    scenario.case(&path)?;
    let h = scenario.integrator.h;
    if light {
        scenario.integrator.t_end = nearest_valid_t_end(scenario.integrator.t_end * LIGHT_T_END, h);
    }
    let t_end = scenario.integrator.t_end;
    let mut setups = Vec::new();
    for scheme in SCHEMES {
        for divisor in DIVISORS {
            // The gains of `compare` depend on h: the cases are made per step.
            scenario.integrator.scheme = scheme;
            scenario.integrator.h = h / divisor as f64;
            setups.push((scheme, scenario.integrator.h, compare::cases(&scenario, &path)?));
        }
    }
    Ok(Model { name, path, h, t_end, setups })
}

/// Runs the suite: the shipped models (`light`: a few, shorter) and `extra`.
pub fn run(extra: &[PathBuf], light: bool) -> Result<Suite> {
    let models = models(extra, light)?;
    let bar = crate::io::progress::bar(models.len() as u64, "models");
    let done: Vec<(Vec<Group>, f64)> = models
        .par_iter()
        .map(|m| {
            let groups = run_model(m);
            bar.inc(1);
            groups
        })
        .collect::<Result<_>>()?;
    bar.finish_and_clear();
    let seconds = models.iter().zip(&done).map(|(m, (_, s))| (m.name.clone(), *s)).collect();
    Ok(Suite { light, seconds, groups: done.into_iter().flat_map(|(g, _)| g).collect() })
}

/// The reference, then every case of the model.
/// Its groups and the seconds they took.
fn run_model(model: &Model) -> Result<(Vec<Group>, f64)> {
    let start = Instant::now();
    let file = model.path.display().to_string();
    let first = &model.setups[0].2[0];
    let reference = reference(first, model.h, model.t_end).map_err(|e| anyhow!("{file}: the reference run: {e}"))?;
    let mut groups = Vec::new();
    for (scheme, h, cases) in &model.setups {
        let every = (model.h / h).round() as u64;
        let mut runs: Vec<Run> = cases.iter().map(|c| run_case(c, &reference, every)).collect();
        let of = |pick: &dyn Fn(&Case) -> bool, what: &str| {
            cases.iter().position(pick).ok_or_else(|| anyhow!("{file}: no {what} case"))
        };
        let none = of(&|c| c.settings.control == Control::none(), "uncontrolled")?;
        // RATTLE and generalized-α take no right-hand-side control: no robust.
        let robust = if scheme.steps_model() { None } else { Some(of(&|c| c.name == "robust", "robust")?) };
        let projection = of(&|c| c.name == "projection", "projection")?;
        let mechanism = &cases[0].example.model;
        let free_motion = mechanism.m() - runs[none].dependent_rows < mechanism.n();
        let (e_none, e_projection) = (runs[none].max_error, runs[projection].max_error);
        for r in &mut runs {
            r.error_vs_none = r.max_error / e_none;
            r.error_vs_projection = r.max_error / e_projection;
        }
        groups.push(Group {
            model: model.name.clone(),
            file: file.clone(),
            scheme: scheme.info().name,
            h: *h,
            t_end: model.t_end,
            sample_interval: model.h,
            reference_h: model.h / REFERENCE_DIVISOR as f64,
            baseline: cases[none].name.clone(),
            free_motion,
            verdicts: verdicts(&runs, none, robust, projection, free_motion),
            runs,
        });
    }
    Ok((groups, start.elapsed().as_secs_f64()))
}

/// Positions of the model without control, RK-4 at `interval / 20`, at `t = k·interval`.
fn reference(case: &Case, interval: f64, t_end: f64) -> cdyn::Result<Vec<Vec<f64>>> {
    rk4_samples(case, interval / REFERENCE_DIVISOR as f64, interval, t_end)
}

/// Positions of `case`'s model without control, RK-4 at `h`, at `t = k·interval`
/// (`interval` a whole number of steps).
pub(crate) fn rk4_samples(case: &Case, h: f64, interval: f64, t_end: f64) -> cdyn::Result<Vec<Vec<f64>>> {
    let every = (interval / h).round() as u64;
    let settings = case.settings.with_scheme(Scheme::RungeKutta4).with_h(h).with_control(Control::none());
    let ex = &case.example;
    let mut sim = Simulation::new(&ex.model, settings, &ex.q0, &ex.v0)?;
    let mut samples = Vec::new();
    sim.run(t_end, every, |s| {
        samples.push(s.q().to_vec());
        Ok::<_, cdyn::Error>(())
    })?;
    Ok(samples)
}

/// Largest `|a_i − b_i|`.
pub(crate) fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).fold(0.0, |m, (x, y)| m.max((x - y).abs()))
}

/// Runs `case`, comparing its positions with `reference` every `every` steps.
fn run_case(case: &Case, reference: &[Vec<f64>], every: u64) -> Run {
    let projection = case.settings.control.projection;
    let mut run = Run {
        method: case.name.clone(),
        max_error: f64::INFINITY,
        error_vs_none: f64::NAN,
        error_vs_projection: f64::NAN,
        max_abs_phi: 0.0,
        max_abs_phi_dot: 0.0,
        max_abs_psi: 0.0,
        max_relative_psi: 0.0,
        initial: Vec::new(),
        steps: 0,
        rate_h: None,
        energy_left_out: false,
        dependent_rows: 0,
        projection_iterations_per_step: None,
        projection_tolerance: projection.map(|p| p.tolerance),
        linear_momentum_drift: None,
        momentum_drift: None,
        error: None,
    };
    let ex = &case.example;
    let mut sim = match Simulation::new(&ex.model, case.settings, &ex.q0, &ex.v0) {
        Ok(sim) => sim,
        Err(e) => {
            run.error = Some(e.to_string());
            return run;
        }
    };
    run.rate_h = Some(sim.tuning().rate_h);
    run.energy_left_out = sim.tuning().energy_left_out;
    let m = sim.measure();
    run.initial = vec![m.phi.abs(), m.phi_dot, m.psi.abs()];
    let mut error = distance(sim.q(), &reference[0]);
    let kept = sim.symmetries().kept.clone();
    let p0: Vec<f64> = (0..kept.len()).map(|j| sim.momentum(j)).collect();
    let mut drift = vec![0.0_f64; kept.len()];
    // Whole steps were checked when the case was made.
    let steps = steps_to(case.t_end, case.settings.h).unwrap_or(0);
    while sim.steps() < steps {
        if let Err(e) = sim.step() {
            run.error = Some(e.to_string());
            break;
        }
        let m = sim.measure();
        run.max_abs_phi = run.max_abs_phi.max(m.phi.abs());
        run.max_abs_phi_dot = run.max_abs_phi_dot.max(m.phi_dot);
        run.max_abs_psi = run.max_abs_psi.max(m.psi.abs());
        let energy = ex.model.kinetic(sim.q(), sim.v()) + ex.model.potential(sim.q(), None).abs();
        run.max_relative_psi = run.max_relative_psi.max(m.psi.abs() / energy.max(1.0));
        if sim.steps().is_multiple_of(every) {
            error = error.max(distance(sim.q(), &reference[(sim.steps() / every) as usize]));
        }
        for j in 0..kept.len() {
            drift[j] = drift[j].max((sim.momentum(j) - p0[j]).abs() / kept[j].scale.max(f64::MIN_POSITIVE));
        }
    }
    let largest = |linear_only: bool| {
        let mut d = kept.iter().zip(&drift).filter(|(k, _)| k.linear || !linear_only).map(|(_, d)| *d).peekable();
        d.peek().is_some().then(|| d.fold(0.0, f64::max))
    };
    (run.linear_momentum_drift, run.momentum_drift) = (largest(true), largest(false));
    run.steps = sim.steps();
    run.dependent_rows = sim.rank_loss().map_or(0, |r| r.max);
    if run.error.is_none() {
        run.max_error = error;
    }
    if projection.is_some() {
        run.projection_iterations_per_step = Some(sim.projection_iterations() as f64 / sim.steps().max(1) as f64);
    }
    run
}

//! `cdyn precision`: work-precision diagrams. One scenario at a range of
//! steps for every scheme × method asked for; each run's error against a
//! reference and what it cost, so that schemes and methods are compared at
//! equal cost rather than at equal step.
//!
//! Every step divides the coarsest, and every run is sampled at the
//! multiples of the coarsest step; its error is the largest `|q_i − q_ref,i|`
//! over those samples and all positions. The reference is the scenario's
//! closed form where its model has one, else the model without control by
//! RK-4 at an eighth of the finest step; that RK-4 is also run at twice its
//! step, and the difference of the two bounds what the reference itself
//! gets wrong. Errors below that bound are not told apart.
//!
//! Here the runs; what they measured (precision.json's records), its
//! table and its CSV in `output`.
//!
//! May import: `io`, `case`, and the rest of `study`.

mod output;

pub use output::{Cheapest, Line, Point, Precision, Reference, csv, table};

use crate::case::runner::Case;
use crate::case::scenario::{self, Scenario};
use crate::study::compare;
use crate::study::suite::{distance, rk4_samples};
use anyhow::{Result, anyhow, bail};
use cdyn::simulate::{nearest_valid_t_end, steps_to};
use cdyn::{Control, Scheme, Simulation};
use serde::Serialize;
use std::path::Path;
use std::time::Instant;

/// The default steps, as multiples of the scenario's `h`.
const STEP_FACTORS: [f64; 5] = [4.0, 2.0, 1.0, 0.5, 0.25];
/// `--light`: the three middle ones, over a quarter of `t_end`.
const LIGHT_STEP_FACTORS: [f64; 3] = [2.0, 1.0, 0.5];
const LIGHT_T_END: f64 = 0.25;
/// The RK-4 reference's step is the finest step over this.
const REFERENCE_DIVISOR: u64 = 8;
/// Runs shorter than this are timed again, up to [`TIMING_REPEATS`] times, and the fastest kept.
const SHORT_RUN_SECONDS: f64 = 0.1;
const TIMING_REPEATS: usize = 5;
/// The errors the summary names the cheapest line for.
pub const TARGETS: [f64; 3] = [1e-3, 1e-6, 1e-9];

/// Which methods to run.
#[derive(Debug, Clone)]
pub enum Methods {
    /// No control, `robust` and `projection`: the choice a user makes.
    Default,
    /// Every method of `cdyn compare`.
    All,
    /// These, by their names in `cdyn compare`.
    Named(Vec<String>),
}

impl Methods {
    /// As `cdyn precision --methods` reads its list: none for the default,
    /// `all`, or names.
    pub fn from_names(names: &[String]) -> Self {
        match names {
            [] => Methods::Default,
            [all] if all == "all" => Methods::All,
            named => Methods::Named(named.to_vec()),
        }
    }
}

/// What `cdyn precision` was asked to run.
#[derive(Debug, Clone)]
pub struct Options {
    /// The schemes (empty: every scheme).
    pub schemes: Vec<Scheme>,
    /// The methods.
    pub methods: Methods,
    /// The steps (empty: the scenario's `h` times 4, 2, 1, 1/2, 1/4).
    pub steps: Vec<f64>,
    /// End time in place of the scenario's.
    pub t_end: Option<f64>,
    /// A quick version: three steps, a quarter of `t_end`.
    pub light: bool,
}

/// Runs the diagram's cases for the scenario at `path`.
pub fn run(path: &Path, options: &Options) -> Result<Precision> {
    let file = path.display().to_string();
    let mut scenario: Scenario = scenario::load(path)?;
    scenario.refuse_sweep(path, "precision")?;
    let base = scenario.case(path)?;
    let steps = steps(&scenario, options).map_err(|e| anyhow!("{file}: {e}"))?;
    let coarsest = steps[0];
    let t_end = options.t_end.unwrap_or(scenario.integrator.t_end * if options.light { LIGHT_T_END } else { 1.0 });
    if !(t_end.is_finite() && t_end > 0.0) {
        bail!("{file}: --t-end {t_end}: must be positive");
    }
    let t_end = nearest_valid_t_end(t_end, coarsest);
    scenario.integrator.t_end = t_end;
    let schemes = if options.schemes.is_empty() { Scheme::ALL.to_vec() } else { options.schemes.clone() };
    if let Methods::Named(named) = &options.methods {
        // The names are those of `cdyn compare` with an explicit scheme (RATTLE and generalized-α run fewer).
        let known = compare::cases(&at(&scenario, Scheme::AdamsBashforth3, coarsest), path)?;
        if let Some(unknown) = named.iter().find(|n| !known.iter().any(|c| &c.name == *n)) {
            let names: Vec<&str> = known.iter().map(|c| c.name.as_str()).collect();
            bail!("--methods {unknown}: not a method of this model (it has: {})", names.join(", "));
        }
    }
    // The lines, each with its case at every step; a bad choice fails here, before anything runs.
    let mut lines: Vec<(Scheme, String, Vec<Case>)> = Vec::new();
    for &scheme in &schemes {
        for (k, &h) in steps.iter().enumerate() {
            for case in
                compare::cases(&at(&scenario, scheme, h), path)?.into_iter().filter(|c| chosen(c, &options.methods))
            {
                if k == 0 {
                    lines.push((scheme, case.name.clone(), Vec::new()));
                }
                let line = lines.iter_mut().find(|(s, m, _)| *s == scheme && *m == case.name);
                line.ok_or_else(|| anyhow!("{file}: {} has no {} case at h = {h}", scheme.info().name, case.name))?
                    .2
                    .push(case);
            }
        }
    }
    if lines.is_empty() {
        bail!("{file}: nothing to run: none of the methods asked for runs with the schemes asked for");
    }
    let (reference, samples) = reference(&base, coarsest, steps[steps.len() - 1], t_end)
        .map_err(|e| anyhow!("{file}: the reference run: {e}"))?;
    let bar = crate::io::progress::bar(lines.len() as u64, "lines");
    let lines: Vec<Line> = lines
        .into_iter()
        .map(|(scheme, method, cases)| {
            let points: Vec<Point> = cases.iter().map(|c| run_case(c, t_end, coarsest, &samples)).collect();
            bar.inc(1);
            Line {
                scheme: scheme.info().name,
                method,
                observed_order: observed_order(&points, reference.error_bound),
                points,
            }
        })
        .collect();
    bar.finish_and_clear();
    // A target within ten times the reference's own error is not told apart from it.
    let told_apart = |target: f64| target > 10.0 * reference.error_bound;
    let cheapest = TARGETS.iter().filter(|&&t| told_apart(t)).filter_map(|&target| cheapest(&lines, target)).collect();
    Ok(Precision { scenario: file, t_end, sample_interval: coarsest, reference, lines, cheapest })
}

/// The steps, coarsest first, each dividing the coarsest.
fn steps(scenario: &Scenario, options: &Options) -> Result<Vec<f64>> {
    let h = scenario.integrator.h;
    let mut steps: Vec<f64> = match (&options.steps[..], options.light) {
        ([], false) => STEP_FACTORS.iter().map(|f| f * h).collect(),
        ([], true) => LIGHT_STEP_FACTORS.iter().map(|f| f * h).collect(),
        (given, _) => given.to_vec(),
    };
    if let Some(bad) = steps.iter().find(|h| !(h.is_finite() && **h > 0.0)) {
        bail!("--h {bad}: every step must be positive");
    }
    steps.sort_by(|a, b| b.total_cmp(a));
    steps.dedup();
    let coarsest = steps[0];
    if let Some(bad) = steps.iter().find(|h| {
        let ratio = coarsest / **h;
        (ratio - ratio.round()).abs() > 1e-9 * ratio
    }) {
        bail!(
            "--h {bad}: every step must divide the coarsest, {coarsest}, so that all runs are compared at its multiples"
        );
    }
    Ok(steps)
}

/// The scenario at `scheme` and step `h`. Generalized-α's keys are for its
/// lines; the other schemes would refuse them.
fn at(scenario: &Scenario, scheme: Scheme, h: f64) -> Scenario {
    let mut s = scenario.clone();
    let i = &mut s.integrator;
    (i.scheme, i.h) = (scheme, h);
    if scheme != Scheme::GeneralizedAlpha {
        (i.rho_inf, i.newton_tolerance, i.newton_max_iterations, i.newton_iterations) = (None, None, None, None);
    }
    s
}

/// Whether `methods` asks for `case` (one of `cdyn compare`'s).
fn chosen(case: &Case, methods: &Methods) -> bool {
    match methods {
        Methods::All => true,
        Methods::Default => {
            case.settings.control == Control::none() || case.name == "robust" || case.name == "projection"
        }
        Methods::Named(named) => named.contains(&case.name),
    }
}

/// The reference positions at `t = k·interval`, and how good they are.
fn reference(case: &Case, interval: f64, finest: f64, t_end: f64) -> cdyn::Result<(Reference, Vec<Vec<f64>>)> {
    let ex = &case.example;
    let samples = steps_to(t_end, interval)? as usize + 1;
    if let Some(exact) = &ex.reference {
        let n = ex.model.n();
        let (mut q, mut v) = (vec![0.0; n], vec![0.0; n]);
        let positions = (0..samples)
            .map(|k| {
                exact(k as f64 * interval, &mut q, &mut v);
                q.clone()
            })
            .collect();
        return Ok((Reference { kind: "closed form", h: None, error_bound: 0.0 }, positions));
    }
    let h = finest / REFERENCE_DIVISOR as f64;
    let fine = rk4_samples(case, h, interval, t_end)?;
    let coarse = rk4_samples(case, 2.0 * h, interval, t_end)?;
    let error_bound = fine.iter().zip(&coarse).fold(0.0_f64, |m, (a, b)| m.max(distance(a, b)));
    Ok((Reference { kind: "rk4", h: Some(h), error_bound }, fine))
}

/// Runs `case` to `t_end`, its error against `samples` at the multiples of
/// `interval`, and its cost.
fn run_case(case: &Case, t_end: f64, interval: f64, samples: &[Vec<f64>]) -> Point {
    let h = case.settings.h;
    let mut point = Point {
        h,
        steps: 0,
        evaluations_per_second: f64::NAN,
        wall_per_second: f64::NAN,
        max_error: f64::INFINITY,
        max_abs_phi: 0.0,
        error: None,
    };
    let every = (interval / h).round() as u64;
    let steps = match steps_to(t_end, h) {
        Ok(steps) => steps,
        Err(e) => {
            point.error = Some(e.to_string());
            return point;
        }
    };
    let mut fastest = f64::INFINITY;
    for _ in 0..TIMING_REPEATS {
        let ex = &case.example;
        let mut sim = match Simulation::new(&ex.model, case.settings, &ex.q0, &ex.v0) {
            Ok(sim) => sim,
            Err(e) => {
                point.error = Some(e.to_string());
                return point;
            }
        };
        let (mut error, mut phi, mut seconds) = (distance(sim.q(), &samples[0]), 0.0_f64, 0.0);
        let mut values = vec![0.0; ex.model.m()];
        while sim.steps() < steps {
            let start = Instant::now();
            for _ in 0..every {
                if let Err(e) = sim.step() {
                    point.error = Some(e.to_string());
                    point.steps = sim.steps();
                    return point;
                }
            }
            seconds += start.elapsed().as_secs_f64();
            ex.model.constraint_values(sim.q(), sim.t(), &mut values);
            phi = values.iter().fold(phi, |a, x| a.max(x.abs()));
            error = error.max(distance(sim.q(), &samples[(sim.steps() / every) as usize]));
        }
        fastest = fastest.min(seconds);
        (point.max_error, point.max_abs_phi, point.steps) = (error, phi, sim.steps());
        point.evaluations_per_second = sim.evaluations() as f64 / t_end;
        if seconds >= SHORT_RUN_SECONDS {
            break;
        }
    }
    point.wall_per_second = fastest / t_end;
    point
}

/// Least-squares slope of `log error` against `log h` over the finite
/// errors above ten times the reference's bound.
fn observed_order(points: &[Point], floor: f64) -> Option<f64> {
    let xy: Vec<(f64, f64)> = points
        .iter()
        .filter(|p| p.max_error.is_finite() && p.max_error > 10.0 * floor && p.max_error > 0.0)
        .map(|p| (p.h.ln(), p.max_error.ln()))
        .collect();
    if xy.len() < 2 {
        return None;
    }
    let n = xy.len() as f64;
    let (mx, my) = (xy.iter().map(|p| p.0).sum::<f64>() / n, xy.iter().map(|p| p.1).sum::<f64>() / n);
    let sxy: f64 = xy.iter().map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = xy.iter().map(|(x, _)| (x - mx).powi(2)).sum();
    Some(sxy / sxx)
}

/// The line reaching `target` at the least wall time, interpolating each
/// line log-log between the two points around `target`.
fn cheapest(lines: &[Line], target: f64) -> Option<Cheapest> {
    let cost = |line: &Line| {
        let mut points: Vec<&Point> = line.points.iter().filter(|p| p.max_error.is_finite()).collect();
        points.sort_by(|a, b| a.wall_per_second.total_cmp(&b.wall_per_second));
        let first = points.iter().position(|p| p.max_error <= target)?;
        let hit = points[first];
        let Some(before) = first.checked_sub(1).map(|k| points[k]) else { return Some(hit.wall_per_second) };
        let along = (before.max_error.ln() - target.ln()) / (before.max_error.ln() - hit.max_error.ln());
        Some((before.wall_per_second.ln() + along * (hit.wall_per_second.ln() - before.wall_per_second.ln())).exp())
    };
    lines.iter().filter_map(|l| cost(l).map(|c| (l, c))).min_by(|a, b| a.1.total_cmp(&b.1)).map(|(l, c)| Cheapest {
        target,
        scheme: l.scheme,
        method: l.method.clone(),
        wall_per_second: c,
    })
}

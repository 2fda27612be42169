//! `cdyn sweep`: a grid over gains and step sizes, run in parallel (rayon),
//! with a table (and heat maps, `render::heatmap`) of the worst error and violations — the
//! question the paper leaves open, how to choose gains.
//!
//! Every grid point is an independent, deterministic run, and results are
//! stored by grid index, so the output is bit-identical whatever the number
//! of threads. `--shard I/N` runs the points with `index % N == I`; `cdyn
//! merge` joins shard outputs into exactly what one run writes.
//!
//! Here what `sweep.json` holds, the shards and threads, the run, merging
//! and writing; `grid` the axes of the `[sweep]` table, the scenario at a
//! point and the scenario's hash; `listing` the printed table.
//!
//! May import: `io`, `case`.

mod grid;
mod listing;

pub use grid::{axes, content_hash};
pub use listing::{FULL_TABLE_LIMIT, Listing, TOP_K, listing, summary};

use crate::case::runner::run_case_quietly;
use crate::case::scenario::Scenario;
use anyhow::{Context, Result, anyhow, bail};
use grid::{at_point, values_at};
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// One axis of the grid: a key and its values.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct Axis {
    /// The `[method]` key or `h`.
    pub name: String,
    /// Its values, in the order given.
    #[serde(with = "cdyn::json_float")]
    pub values: Vec<f64>,
}

/// One grid point and how its run went.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct Point {
    /// Its index in the grid, by which points are stored and sharded.
    pub index: usize,
    /// One value per axis.
    #[serde(with = "cdyn::json_float")]
    pub values: Vec<f64>,
    /// Largest `|Φ|`.
    #[serde(with = "cdyn::json_float")]
    pub max_abs_phi: f64,
    /// Largest `|Ψ|`.
    #[serde(with = "cdyn::json_float")]
    pub max_abs_psi: f64,
    /// Largest error against the reference, where the model has one.
    #[serde(with = "cdyn::json_float")]
    pub max_abs_err: Option<f64>,
    /// Steps taken.
    pub steps: u64,
    /// Why the run stopped early, if it did.
    pub error: Option<String>,
}

/// Which part of a sharded sweep: points with `index % count == index`.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct Shard {
    /// This shard's index.
    pub index: usize,
    /// The number of shards.
    pub count: usize,
}

/// What `sweep.json` holds.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct Sweep {
    /// The scenario file as given (for people; shards may name it differently).
    pub scenario: String,
    /// What identifies the sweep: [`content_hash`] of the parsed scenario,
    /// grid included, so `merge` refuses shards of an edited file and
    /// accepts the same file given by any path.
    pub scenario_hash: String,
    /// The grid's axes.
    pub axes: Vec<Axis>,
    /// `None` for a complete sweep.
    pub shard: Option<Shard>,
    /// The points run, by index.
    pub points: Vec<Point>,
}

impl Sweep {
    /// The number of points of the whole grid.
    pub fn total(&self) -> usize {
        self.axes.iter().map(|a| a.values.len()).product()
    }
}

/// Parses `I/N`.
pub fn parse_shard(s: &str) -> Result<Shard> {
    let (i, n) = s.split_once('/').ok_or_else(|| anyhow!("--shard {s:?}: expected I/N, e.g. 0/4"))?;
    let (index, count): (usize, usize) = (
        i.parse().map_err(|_| anyhow!("--shard {s:?}: I is not a number"))?,
        n.parse().map_err(|_| anyhow!("--shard {s:?}: N is not a number"))?,
    );
    if count == 0 || index >= count {
        bail!("--shard {s:?}: need 0 ≤ I < N");
    }
    Ok(Shard { index, count })
}

/// Most worker threads for `available` cores: beyond a few per core more
/// threads only cost start-up time (100000 would take minutes to start).
fn max_threads(available: usize) -> usize {
    (4 * available).min(256)
}

/// The `--threads` to run with: `None` for one per core; a request above
/// `max_threads` (4 per core, at most 256) is capped with a notice on standard error.
pub fn worker_threads(requested: Option<usize>) -> Result<Option<usize>> {
    let Some(n) = requested else { return Ok(None) };
    if n == 0 {
        bail!("--threads 0: need at least one thread");
    }
    let cores = std::thread::available_parallelism().map_or(1, |c| c.get());
    let max = max_threads(cores);
    if n > max {
        crate::io::terminal::eprint_line(&format!(
            "notice: --threads {n} is more than {max} (4 per core on {cores} cores, at most 256); using {max}"
        ));
        return Ok(Some(max));
    }
    Ok(Some(n))
}

/// Runs the grid points of `shard` (all of them without one) on `threads`
/// threads. `table` is the parsed scenario file, hashed to identify the sweep.
///
/// Cases are built when a worker takes their point, so memory does not grow
/// with the grid (a million-point grid built in advance took 2.3 GB); each
/// axis value is checked alone first, so most mistakes still surface before
/// anything runs.
pub fn run(
    scenario: &Scenario,
    table: &toml::Table,
    path: &Path,
    shard: Option<Shard>,
    threads: Option<usize>,
) -> Result<Sweep> {
    let file = path.display().to_string();
    let axes = axes(scenario, &file)?;
    let total = axes.iter().try_fold(1usize, |n, a| n.checked_mul(a.values.len()));
    let total = total.ok_or_else(|| anyhow!("{file}: [sweep]: the grid has more points than can be counted"))?;
    let at = |values: &[f64], names: &[&Axis]| {
        let at: Vec<String> = names.iter().zip(values).map(|(a, v)| format!("{} = {v}", a.name)).collect();
        at.join(", ")
    };
    for axis in &axes {
        for &v in &axis.values {
            at_point(scenario, std::slice::from_ref(axis), &[v])
                .and_then(|s| s.case(path))
                .map_err(|e| anyhow!("{e} (at sweep point {})", at(&[v], &[axis])))?;
        }
    }
    let in_shard = |i: &usize| shard.as_ref().is_none_or(|s| i % s.count == s.index);
    let count = shard.as_ref().map_or(total, |s| total / s.count + usize::from(s.index < total % s.count));
    let bar = ProgressBar::new(count as u64).with_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} points, {elapsed} elapsed, about {eta} left")
            .expect("valid template"),
    );
    let pool =
        rayon::ThreadPoolBuilder::new().num_threads(threads.unwrap_or(0)).build().context("cannot start threads")?;
    let all: Vec<&Axis> = axes.iter().collect();
    let points: Result<Vec<Point>> = pool.install(|| {
        (0..total)
            .into_par_iter()
            .filter(in_shard)
            .map(|index| {
                let values = values_at(&axes, index);
                let case = at_point(scenario, &axes, &values)
                    .and_then(|s| s.case(path))
                    .map_err(|e| anyhow!("{e} (at sweep point {})", at(&values, &all)))?;
                let r = run_case_quietly(&case);
                bar.inc(1);
                Ok(Point {
                    index,
                    values,
                    max_abs_phi: r.record.max_abs_phi,
                    max_abs_psi: r.record.max_abs_psi,
                    max_abs_err: r.record.max_abs_error,
                    steps: r.record.steps,
                    error: r.error,
                })
            })
            .collect()
    });
    bar.finish_and_clear();
    Ok(Sweep { scenario: file, scenario_hash: content_hash(table), axes, shard, points: points? })
}

/// Joins shard outputs into the complete sweep.
pub fn merge(parts: Vec<Sweep>) -> Result<Sweep> {
    let first = parts.first().ok_or_else(|| anyhow!("merge: no sweep.json given"))?.clone();
    let mut points: Vec<Point> = Vec::new();
    for p in &parts {
        if p.scenario_hash != first.scenario_hash || p.axes != first.axes {
            bail!(
                "merge: the parts come from different sweeps: {} and {} differ in content (scenario_hash {} and {}); run every shard on the same scenario",
                first.scenario,
                p.scenario,
                first.scenario_hash,
                p.scenario_hash
            );
        }
        points.extend(p.points.iter().cloned());
    }
    points.sort_by_key(|p| p.index);
    let total = first.total();
    for (expected, p) in points.iter().enumerate() {
        if p.index != expected {
            let what = if p.index < expected { "twice" } else { "missing" };
            bail!("merge: grid point {} is {what}; give every shard exactly once", expected.min(p.index));
        }
    }
    if points.len() != total {
        bail!("merge: {} of {total} grid points present; a shard is missing", points.len());
    }
    Ok(Sweep { scenario: first.scenario, scenario_hash: first.scenario_hash, axes: first.axes, shard: None, points })
}

/// Writes `sweep.json` (the heat maps are drawn by
/// [`crate::render::heatmap::sweep_maps`]).
pub fn write(sweep: &Sweep, dir: &Path) -> Result<()> {
    let path = dir.join("sweep.json");
    crate::io::output::write(&path, (serde_json::to_string_pretty(sweep)? + "\n").as_bytes())
}

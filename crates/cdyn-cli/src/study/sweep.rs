//! `cdyn sweep`: a grid over gains and step sizes, run in parallel (rayon),
//! with a table (and heat maps, `render::heatmap`) of the worst error and violations — the
//! question the paper leaves open, how to choose gains.
//!
//! Every grid point is an independent, deterministic run, and results are
//! stored by grid index, so the output is bit-identical whatever the number
//! of threads. `--shard I/N` runs the points with `index % N == I`; `cdyn
//! merge` joins shard outputs into exactly what one run writes.

use crate::case::runner::run_case_quietly;
use crate::case::scenario::Scenario;
use anyhow::{Context, Result, anyhow, bail};
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

/// The axes of the scenario's `[sweep]` table, in file order.
pub fn axes(scenario: &Scenario, file: &str) -> Result<Vec<Axis>> {
    let table = scenario
        .sweep
        .as_ref()
        .ok_or_else(|| anyhow!("{file}: a sweep needs a [sweep] table, e.g. alpha_g = [10, 20, 40]"))?;
    if table.is_empty() {
        bail!("{file}: [sweep] is empty");
    }
    table
        .iter()
        .map(|(name, value)| {
            let values: Vec<f64> = value
                .as_array()
                .ok_or_else(|| anyhow!("{file}: [sweep] {name}: expected a list of numbers"))?
                .iter()
                .map(|v| v.as_float().or_else(|| v.as_integer().map(|i| i as f64)))
                .collect::<Option<_>>()
                .ok_or_else(|| anyhow!("{file}: [sweep] {name}: expected a list of numbers"))?;
            if values.is_empty() {
                bail!("{file}: [sweep] {name}: the list is empty");
            }
            set(&mut scenario.clone(), name, values[0])
                .map_err(|e| anyhow!("{file}: [sweep] {name}: not h or a [method] gain: {e}"))?;
            Ok(Axis { name: name.clone(), values })
        })
        .collect()
}

/// The grid values of point `index` (last axis fastest).
fn values_at(axes: &[Axis], mut index: usize) -> Vec<f64> {
    let mut out = vec![0.0; axes.len()];
    for (k, a) in axes.iter().enumerate().rev() {
        out[k] = a.values[index % a.values.len()];
        index /= a.values.len();
    }
    out
}

/// The scenario with one grid point's values set.
fn at_point(scenario: &Scenario, axes: &[Axis], values: &[f64]) -> Result<Scenario> {
    let mut s = scenario.clone();
    for (a, &v) in axes.iter().zip(values) {
        set(&mut s, &a.name, v)?;
    }
    Ok(s)
}

/// Sets one axis: `h`, or a key of the library's method table (whatever
/// [`cdyn::control::methods::MethodKeys`] accepts, so a new gain needs no change here).
fn set(scenario: &mut Scenario, name: &str, value: f64) -> Result<()> {
    if name == "h" {
        scenario.integrator.h = value;
        return Ok(());
    }
    let mut table = toml::Table::try_from(scenario.method())?;
    table.insert(name.to_string(), toml::Value::Float(value));
    scenario.method = Some(table.try_into().map_err(|e: toml::de::Error| anyhow!("{}", e.message().trim()))?);
    Ok(())
}

/// A stable hash (128-bit FNV-1a, hex) of a canonical encoding of the parsed
/// scenario `table`: keys sorted, numbers by value (so `2` and `2.0`, which
/// the scenario reads alike, agree), comments and layout ignored. It must
/// not change between releases or platforms, so it is written out here
/// rather than taken from `std`'s randomly seeded hashers.
pub fn content_hash(table: &toml::Table) -> String {
    fn encode(value: &toml::Value, out: &mut Vec<u8>) {
        let bytes = |tag: u8, b: &[u8], out: &mut Vec<u8>| {
            out.push(tag);
            out.extend_from_slice(&(b.len() as u64).to_le_bytes());
            out.extend_from_slice(b);
        };
        match value {
            toml::Value::String(s) => bytes(b'S', s.as_bytes(), out),
            toml::Value::Integer(i) if i.unsigned_abs() < 1 << 53 => {
                bytes(b'F', &(*i as f64).to_bits().to_le_bytes(), out)
            }
            toml::Value::Integer(i) => bytes(b'I', &i.to_le_bytes(), out),
            toml::Value::Float(f) => {
                let f = if f.is_nan() {
                    f64::NAN
                } else if *f == 0.0 {
                    0.0
                } else {
                    *f
                };
                bytes(b'F', &f.to_bits().to_le_bytes(), out)
            }
            toml::Value::Boolean(b) => bytes(b'B', &[u8::from(*b)], out),
            toml::Value::Datetime(d) => bytes(b'D', d.to_string().as_bytes(), out),
            toml::Value::Array(items) => {
                bytes(b'A', &(items.len() as u64).to_le_bytes(), out);
                items.iter().for_each(|v| encode(v, out));
            }
            toml::Value::Table(t) => {
                bytes(b'T', &(t.len() as u64).to_le_bytes(), out);
                let mut keys: Vec<&String> = t.keys().collect();
                keys.sort();
                for k in keys {
                    bytes(b'K', k.as_bytes(), out);
                    encode(&t[k], out);
                }
            }
        }
    }
    let mut bytes = Vec::new();
    encode(&toml::Value::Table(table.clone()), &mut bytes);
    const OFFSET: u128 = 0x6c62272e07bb014262b821756295c58d;
    const PRIME: u128 = 0x0000000001000000000000000000013B;
    let hash = bytes.iter().fold(OFFSET, |h, &b| (h ^ u128::from(b)).wrapping_mul(PRIME));
    format!("{hash:032x}")
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

/// Above this many points the printed table holds only the best
/// [`TOP_K`]: a million-line table helps nobody and cannot be read back.
pub const FULL_TABLE_LIMIT: usize = 1000;

/// Rows of the table of a large sweep.
pub const TOP_K: usize = 20;

/// How much of a sweep to print.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Listing {
    /// Only the summary line (`--quiet`).
    Summary,
    /// Every point up to [`FULL_TABLE_LIMIT`], the best [`TOP_K`] above it.
    Default,
    /// Every point (`--all`).
    All,
}

/// What the sweep is ranked by: the error against the reference where
/// there is one, else max |Φ|.
fn rank_key(sweep: &Sweep) -> (&'static str, fn(&Point) -> f64) {
    if sweep.points.iter().any(|p| p.max_abs_err.is_some()) {
        ("max|err|", |p| p.max_abs_err.unwrap_or(f64::INFINITY))
    } else {
        ("max|phi|", |p| p.max_abs_phi)
    }
}

/// Points ranked best first; failed runs and NaN last, ties by grid index.
fn ranked(sweep: &Sweep) -> Vec<&Point> {
    let (_, key) = rank_key(sweep);
    let value = |p: &Point| if p.error.is_some() || key(p).is_nan() { f64::INFINITY } else { key(p) };
    let mut points: Vec<&Point> = sweep.points.iter().collect();
    points.sort_by(|a, b| value(a).total_cmp(&value(b)).then(a.index.cmp(&b.index)));
    points
}

/// One line: how many points, how many failed, and the best one.
pub fn summary(sweep: &Sweep) -> String {
    let failed = sweep.points.iter().filter(|p| p.error.is_some()).count();
    let (what, key) = rank_key(sweep);
    let best = ranked(sweep).into_iter().next().filter(|p| p.error.is_none());
    let best = best.map_or(String::from("no point ran to the end"), |p| {
        let at: Vec<String> = sweep.axes.iter().zip(&p.values).map(|(a, v)| format!("{} = {v}", a.name)).collect();
        format!("best {what} {:.3e} at {}", key(p), at.join(", "))
    });
    format!("{} points, {failed} failed; {best}\n", sweep.points.len())
}

/// What to print of a sweep: the table as `listing` asks (with a line saying
/// when it is cut), then the summary line.
pub fn listing(sweep: &Sweep, listing: Listing) -> String {
    let n = sweep.points.len();
    match listing {
        Listing::Summary => summary(sweep),
        Listing::All => table(sweep, sweep.points.iter()) + &summary(sweep),
        Listing::Default if n <= FULL_TABLE_LIMIT => table(sweep, sweep.points.iter()) + &summary(sweep),
        Listing::Default => {
            let (what, _) = rank_key(sweep);
            table(sweep, ranked(sweep).into_iter().take(TOP_K))
                + &format!(
                    "the {TOP_K} best of {n} points by {what} (more than {FULL_TABLE_LIMIT}; --all prints every point, sweep.json holds them all)\n"
                )
                + &summary(sweep)
        }
    }
}

/// One line per given point.
fn table<'a>(sweep: &Sweep, points: impl Iterator<Item = &'a Point>) -> String {
    let mut out: String = sweep.axes.iter().map(|a| format!("{:>12}", a.name)).collect();
    out += &format!(" {:>11} {:>11} {:>11}\n", "max|phi|", "max|psi|", "max|err|");
    for p in points {
        out += &p.values.iter().map(|v| format!("{v:>12}")).collect::<String>();
        let err = p.max_abs_err.map_or("-".into(), |e| format!("{e:.3e}"));
        match &p.error {
            Some(e) => out += &format!(" failed: {e}\n"),
            None => out += &format!(" {:>11.3e} {:>11.3e} {err:>11}\n", p.max_abs_phi, p.max_abs_psi),
        }
    }
    out
}

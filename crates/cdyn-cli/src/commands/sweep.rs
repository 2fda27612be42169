//! `cdyn sweep` and `cdyn merge`: a grid over gains and steps, and joining its shards.

use super::{ListingArgs, output_dir};
use anyhow::{Context, Result, bail};
use cdyn_cli::case::scenario;
use cdyn_cli::io::terminal::print;
use cdyn_cli::render::heatmap;
use cdyn_cli::study::sweep::{self, Listing, Sweep};
use std::path::{Path, PathBuf};

/// Runs the [sweep] grid of `path` (shard `shard` of it, on `threads` workers) into `out`.
pub fn sweep(
    path: &Path,
    out: &Path,
    shard: Option<&str>,
    threads: Option<usize>,
    listing: &ListingArgs,
) -> Result<()> {
    let (parsed, table) = scenario::load_with_table(path)?;
    let shard = shard.map(sweep::parse_shard).transpose()?;
    let threads = sweep::worker_threads(threads)?;
    write(&sweep::run(&parsed, &table, path, shard, threads)?, out, listing.listing())
}

/// Joins the sweep.json files of `parts` (directories or files) into `out`.
pub fn merge(parts: &[PathBuf], out: &Path, listing: &ListingArgs) -> Result<()> {
    let parts = parts.iter().map(|p| read(p)).collect::<Result<Vec<_>>>()?;
    write(&sweep::merge(parts)?, out, listing.listing())
}

/// The sweep.json of a shard's directory or the file itself.
fn read(part: &Path) -> Result<Sweep> {
    let file = if part.is_dir() { part.join("sweep.json") } else { part.to_path_buf() };
    let text = std::fs::read_to_string(&file).with_context(|| format!("cannot read {}", file.display()))?;
    let doc: serde_json::Value =
        serde_json::from_str(&text).with_context(|| format!("{}: not a sweep.json", file.display()))?;
    if doc.get("points").is_some() && doc.get("scenario_hash").is_none() {
        bail!(
            "{}: no scenario_hash (written by an older cdyn, which merged by path); run that shard again",
            file.display()
        );
    }
    serde_json::from_value(doc).with_context(|| format!("{}: not a sweep.json", file.display()))
}

/// Writes a sweep's (or merged sweep's) `sweep.json` and heat maps into `out` and prints its table
/// (the summary line alone with `--quiet`).
fn write(result: &Sweep, out: &Path, listing: Listing) -> Result<()> {
    output_dir(out)?;
    sweep::write(result, out)?;
    heatmap::sweep_maps(result, out)?;
    print(&sweep::listing(result, listing))?;
    if listing != Listing::Summary {
        print(&format!("wrote {}\n", out.join("sweep.json").display()))?;
    }
    Ok(())
}

//! The commands of the `cdyn` binary, one file each: what they read from
//! the command line and which parts of the library (`cdyn_cli`) they call.
//! Nothing here computes or draws; the library does.
//!
//! May import: `io`, `case`, `study`, `render`, `export` (the library's folders).

pub mod bench;
pub mod compare;
pub mod fmu;
pub mod manual;
pub mod paper;
pub mod precision;
pub mod run;
pub mod suite;
pub mod sweep;

use anyhow::{Context, Result, bail};
use cdyn_cli::case::runner::CaseResult;
use cdyn_cli::io::interrupt;
use cdyn_cli::render::viewer::ViewerArgs;
use cdyn_cli::study::sweep::Listing;
use std::path::{Path, PathBuf};

/// What `run` and `compare` take: a scenario, where to write, and what else to write.
#[derive(clap::Args)]
pub struct CaseArgs {
    /// The scenario (TOML).
    pub scenario: PathBuf,
    /// Output directory (created if missing).
    #[arg(long)]
    pub out: PathBuf,
    /// Run even if the CSV output would exceed 2 GB.
    #[arg(long)]
    pub force: bool,
    #[command(flatten)]
    pub viewer: ViewerArgs,
}

/// How much of a sweep's table `sweep` and `merge` print.
#[derive(clap::Args)]
pub struct ListingArgs {
    /// Print no table, only the summary line.
    #[arg(long, conflicts_with = "all")]
    quiet: bool,
    /// Print every point, also above 1000 points (where the best 20 are printed by default).
    #[arg(long)]
    all: bool,
}

impl ListingArgs {
    /// The listing these flags ask for.
    pub fn listing(&self) -> Listing {
        match (self.quiet, self.all) {
            (true, _) => Listing::Summary,
            (false, true) => Listing::All,
            (false, false) => Listing::Default,
        }
    }
}

/// How a command ended without an error.
pub enum Ended {
    Done,
    /// SIGINT or SIGTERM stopped a run; its output is written, `line` says where it stopped.
    Interrupted {
        signal: i32,
        line: String,
    },
}

/// How a run of `results` into `out` ended: interrupted, failed (an error), or done.
pub fn ended(results: &[CaseResult], out: &Path) -> Result<Ended> {
    match (results.iter().find(|r| r.interrupted), interrupt::requested()) {
        (Some(r), Some(signal)) => Ok(Ended::Interrupted {
            signal,
            line: format!(
                "interrupted by {} at step {} (t = {}) of case {}; the output up to there is in {}",
                interrupt::name(signal),
                r.record.steps,
                cdyn::error::Time(r.record.t_final),
                r.name,
                out.display()
            ),
        }),
        _ => match results.iter().find(|r| r.error.is_some()) {
            // A run that failed part-way still wrote its output; say where, and fail.
            Some(r) => {
                let hint = cdyn_cli::render::report::stiff_hint(r).map_or(String::new(), |h| format!("; {h}"));
                bail!(
                    "{}{hint} (output up to that point is in {})",
                    r.error.as_deref().unwrap_or_default(),
                    out.display()
                )
            }
            None => Ok(Ended::Done),
        },
    }
}

/// Creates the output directory `dir`, or says why it cannot.
pub fn output_dir(dir: &Path) -> Result<()> {
    if dir.exists() && !dir.is_dir() {
        bail!("--out {} is a file, not a directory", dir.display());
    }
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create output directory {}", dir.display()))
}

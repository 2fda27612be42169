//! `cdyn`: constrained dynamics with gradient-feedback stabilization,
//! from the command line.

mod paper;
mod plot;
mod report;
mod runner;
mod scenario;

use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "cdyn",
    version,
    about = "Constrained dynamics in redundant coordinates, with constraint and energy violations pushed back (CVSGF)"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Reproduce the paper's Example 1 test: every case, CSVs, summary.json, Figs. 3–5.
    Paper {
        /// Output directory (created if missing).
        #[arg(long)]
        out: PathBuf,
    },
    /// Run a scenario file.
    Run {
        /// The scenario (TOML).
        scenario: PathBuf,
        /// Output directory (created if missing).
        #[arg(long)]
        out: PathBuf,
    },
}

fn main() -> ExitCode {
    match run(Cli::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", format!("{e:#}").replace('\n', " "));
            ExitCode::FAILURE
        }
    }
}

fn output_dir(dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot create output directory {}", dir.display()))
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Paper { out } => {
            output_dir(&out)?;
            let results = paper::run(&out)?;
            print!("{}", report::table(&results));
            println!("wrote {}", out.display());
            if let Some(e) = results.iter().find_map(|r| r.error.as_ref()) {
                bail!("{e}");
            }
        }
        Command::Run { scenario, out } => {
            let case = scenario::load(&scenario)?.case(&scenario)?;
            case.check().map_err(|e| match e {
                cdyn::Error::InconsistentInitialState { .. } => anyhow::anyhow!(
                    "{}: [initial]: {e}; set off_constraint = true to start there anyway",
                    scenario.display()
                ),
                e => anyhow::anyhow!("{}: {e}", scenario.display()),
            })?;
            output_dir(&out)?;
            let result = runner::run_case(&case, &out)?;
            let results = [result];
            report::write_summary(
                &out,
                &results,
                serde_json::json!({ "scenario": scenario.display().to_string() }),
            )?;
            report::write_figures(&out, &results[0].name, &results)?;
            print!("{}", report::table(&results));
            println!("wrote {}", out.display());
            if let Some(e) = &results[0].error {
                bail!("{e} (output up to that point is in {})", out.display());
            }
        }
    }
    Ok(())
}

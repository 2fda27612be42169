//! `cdyn`: constrained dynamics with gradient-feedback stabilization,
//! from the command line.

mod alloc_count;
mod bench;
mod builtin_spec;
mod compare;
mod mechanism_spec;
mod paper;
mod plot;
mod report;
mod runner;
mod scenario;

use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[global_allocator]
static ALLOCATOR: alloc_count::Counting = alloc_count::Counting;

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
    /// Run one model under every stabilization method of `cdyn paper`.
    Compare {
        /// The scenario (TOML); its [method] gains, if any, are used, else target rates 0.2/h.
        scenario: PathBuf,
        /// Output directory (created if missing).
        #[arg(long)]
        out: PathBuf,
    },
    /// Measure the cost of a step (Example 1 against hand-written code, the N-link chain), write bench.json.
    Bench {
        /// Output directory (created if missing).
        #[arg(long)]
        out: PathBuf,
        /// A quick smoke run with few steps (for CI; the numbers mean little).
        #[arg(long)]
        light: bool,
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
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create output directory {}", dir.display()))
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Paper { out } => {
            output_dir(&out)?;
            let results = paper::run(&out)?;
            print!("{}", report::table(&results));
            println!("wrote {}", out.display());
            fail_on_error(&results, &out)
        }
        Command::Run { scenario, out } => {
            let case = scenario::load(&scenario)?.case(&scenario)?;
            case.check().map_err(|e| anyhow::anyhow!("{}: {e}", scenario.display()))?;
            if let Some(a) = &case.assembly {
                println!("{}", report::assembly_line(a));
            }
            output_dir(&out)?;
            let results = [runner::run_case(&case, &out)?];
            let extra = serde_json::json!({
                "scenario": scenario.display().to_string(),
                "assembly": case.assembly.as_ref().map(report::assembly_json),
            });
            report::write_summary(&out, &results, extra)?;
            report::write_figures(&out, &results[0].name, &results, report::RUN_FIGURES)?;
            print!("{}", report::table(&results));
            println!("wrote {}", out.display());
            fail_on_error(&results, &out)
        }
        Command::Bench { out, light } => {
            output_dir(&out)?;
            let report = bench::run(light)?;
            let path = out.join("bench.json");
            std::fs::write(&path, serde_json::to_string_pretty(&report)? + "\n")
                .with_context(|| format!("cannot write {}", path.display()))?;
            print!("{}", bench::table(&report));
            println!("wrote {}", path.display());
            Ok(())
        }
        Command::Compare { scenario, out } => {
            let parsed = scenario::load(&scenario)?;
            let cases = compare::cases(&parsed, &scenario)?;
            output_dir(&out)?;
            let results = compare::run(&cases, &scenario, &out)?;
            print!("{}", report::table(&results));
            println!("wrote {}", out.display());
            fail_on_error(&results, &out)
        }
    }
}

/// A run that failed part-way still wrote its output; say where, and fail.
fn fail_on_error(results: &[runner::CaseResult], out: &Path) -> Result<()> {
    match results.iter().find_map(|r| r.error.as_ref()) {
        Some(e) => bail!("{e} (output up to that point is in {})", out.display()),
        None => Ok(()),
    }
}

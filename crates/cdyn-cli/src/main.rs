//! `cdyn`: constrained dynamics with gradient-feedback stabilization,
//! from the command line.

mod commands;

use anyhow::Result;
use cdyn_cli::io::{alloc_count, interrupt, terminal};
use clap::{CommandFactory, Parser, Subcommand};
use commands::{CaseArgs, Ended, ListingArgs};
use std::path::PathBuf;
use std::process::ExitCode;

#[global_allocator]
static ALLOCATOR: alloc_count::Counting = alloc_count::Counting;

#[derive(Parser)]
#[command(
    name = "cdyn",
    version,
    about = "Constrained dynamics in redundant coordinates, with constraint and energy violations pushed back (CVSGF)",
    after_help = EXIT_CODES
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// What `cdyn`'s exit status means, in `--help` and the man page.
const EXIT_CODES: &str = "Exit status: 0 done; 1 an error (bad input, a failed run: one line on standard error \
naming the file and key, or the step and time); 2 a command line clap cannot parse; 130 or 143 a run \
stopped by SIGINT or SIGTERM (its output up to there is written).";

#[derive(Subcommand)]
enum Command {
    /// Reproduce the paper's Example 1 test: every case, CSVs, summary.json, Figs. 3–5.
    #[command(after_help = "Example: cdyn paper --out out/paper")]
    Paper {
        /// Output directory (created if missing).
        #[arg(long)]
        out: PathBuf,
    },
    /// Run one model under every stabilization method of `cdyn paper`, robust and projection, with the
    /// scenario's [method] gains where given, else target rates 0.2/h.
    #[command(after_help = "Example: cdyn compare examples/four_bar.toml --out out/four_bar --html")]
    Compare {
        #[command(flatten)]
        case: CaseArgs,
    },
    /// Measure the cost of a step (Example 1 against hand-written code, the N-link chain), write bench.json.
    #[command(after_help = "Example: cdyn bench --out out/bench")]
    Bench {
        /// Output directory (created if missing).
        #[arg(long)]
        out: PathBuf,
        /// A quick smoke run with few steps (for CI; the numbers mean little).
        #[arg(long)]
        light: bool,
        /// Only the real-time figures (each step timed on its own; a co-simulation step), into realtime.json.
        #[arg(long)]
        realtime: bool,
    },
    /// Run a grid over gains and step sizes (the scenario's [sweep] table) in parallel; writes sweep.json and heat maps.
    #[command(after_help = "Example: cdyn sweep examples/sweep_gains.toml --out out/sweep --threads 2")]
    Sweep {
        /// The scenario (TOML) with a [sweep] table, e.g. alpha_g = [10, 20, 40].
        scenario: PathBuf,
        /// Output directory (created if missing).
        #[arg(long)]
        out: PathBuf,
        /// Run only shard I of N (grid points with index % N == I); join shards with `cdyn merge`.
        #[arg(long)]
        shard: Option<String>,
        /// Worker threads (default: one per core). Results do not depend on it.
        #[arg(long)]
        threads: Option<usize>,
        #[command(flatten)]
        listing: ListingArgs,
    },
    /// Join the sweep.json files of the shards of one sweep into the complete result.
    #[command(after_help = "Example: cdyn merge parts/* --out result")]
    Merge {
        /// Shard output directories (or their sweep.json files).
        #[arg(required = true)]
        parts: Vec<PathBuf>,
        /// Output directory (created if missing).
        #[arg(long)]
        out: PathBuf,
        #[command(flatten)]
        listing: ListingArgs,
    },
    /// Judge every method of `cdyn compare` on many models (examples/suite and any given) at AB-3, RK-4
    /// and ABM-4, h and h/2, against a fine reference; writes suite.json and suite.png. Misses of its checks are reported, not fatal.
    #[command(after_help = "Example: cdyn suite --out out/suite --light")]
    Suite {
        /// More scenarios (TOML) to add to the shipped ones.
        scenarios: Vec<PathBuf>,
        /// Output directory (created if missing).
        #[arg(long)]
        out: PathBuf,
        /// A quick version for CI: four models, a quarter of their t_end.
        #[arg(long)]
        light: bool,
    },
    /// Work-precision diagrams: a scenario at a range of steps for every scheme × method, its error
    /// against a reference and its cost; writes precision.json, precision.csv and precision.png.
    #[command(
        after_help = "Example: cdyn precision examples/suite/example1.toml --out out/precision --schemes ab3,rk4,abm4"
    )]
    Precision {
        #[command(flatten)]
        args: commands::precision::PrecisionArgs,
    },
    /// Export a scenario as an FMI 2.0 co-simulation FMU (its inputs, outputs and parameters as variables).
    #[command(after_help = "Example: cdyn fmu examples/pd_pendulum.toml --out pd_pendulum.fmu")]
    Fmu {
        /// The scenario (TOML).
        scenario: PathBuf,
        /// The FMU to write, NAME.fmu (NAME is its model identifier).
        #[arg(long)]
        out: PathBuf,
        /// The shared library of crates/cdyn-capi to carry (default: $CDYN_FMU_LIBRARY, else libcdyn_capi.so beside cdyn).
        #[arg(long)]
        library: Option<PathBuf>,
    },
    /// Run a scenario file.
    #[command(after_help = "Example: cdyn run examples/four_bar.toml --out out/four_bar --html")]
    Run {
        #[command(flatten)]
        case: CaseArgs,
    },
    /// Print a shell completion script for cdyn.
    #[command(after_help = "Example: cdyn completions bash > ~/.local/share/bash-completion/completions/cdyn")]
    Completions {
        /// The shell.
        shell: clap_complete::Shell,
    },
    /// Print cdyn's man page, or write one page per command into a directory.
    #[command(after_help = "Example: cdyn man --out man/ && man -l man/cdyn-run.1")]
    Man {
        /// Write cdyn.1 and cdyn-<command>.1 here (created if missing) instead of printing cdyn.1.
        #[arg(long)]
        out: Option<PathBuf>,
    },
}

fn main() -> ExitCode {
    match run(Cli::parse()) {
        Ok(Ended::Done) => ExitCode::SUCCESS,
        Ok(Ended::Interrupted { signal, line }) => {
            terminal::eprint_line(&line);
            ExitCode::from(interrupt::exit_status(signal))
        }
        Err(e) => {
            terminal::eprint_line(&format!("error: {}", format!("{e:#}").replace('\n', " ")));
            ExitCode::FAILURE
        }
    }
}

/// Hands the parsed command line to its command.
fn run(cli: Cli) -> Result<Ended> {
    let done = |()| Ended::Done;
    match cli.command {
        Command::Completions { shell } => commands::manual::completions(shell, Cli::command()).map(done),
        Command::Man { out } => commands::manual::man(Cli::command(), out.as_deref()).map(done),
        Command::Paper { out } => commands::paper::paper(&out),
        Command::Run { case } => commands::run::run(case),
        Command::Fmu { scenario, out, library } => commands::fmu::fmu(&scenario, &out, library.as_deref()).map(done),
        Command::Compare { case } => commands::compare::compare(case),
        Command::Precision { args } => commands::precision::precision(args).map(done),
        Command::Bench { out, light, realtime } => commands::bench::bench(&out, light, realtime).map(done),
        Command::Sweep { scenario, out, shard, threads, listing } => {
            commands::sweep::sweep(&scenario, &out, shard.as_deref(), threads, &listing).map(done)
        }
        Command::Merge { parts, out, listing } => commands::sweep::merge(&parts, &out, &listing).map(done),
        Command::Suite { scenarios, out, light } => commands::suite::suite(&scenarios, &out, light).map(done),
    }
}

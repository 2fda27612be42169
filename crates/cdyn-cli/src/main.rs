//! `cdyn`: constrained dynamics with gradient-feedback stabilization,
//! from the command line.

use anyhow::{Context, Result, bail};
use cdyn_cli::terminal::print;
use cdyn_cli::{
    alloc_count, bench, compare, interrupt, output, paper, report, runner, scenario, suite, suite_plot, sweep,
    terminal, view3d, viewer,
};
use clap::{CommandFactory, Parser, Subcommand};
use std::path::{Path, PathBuf};
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
    /// Judge every method of `cdyn compare` on many models (examples/suite and any given) at AB-3 and RK-4,
    /// h and h/2, against a fine reference; writes suite.json and suite.png. Misses of its checks are reported, not fatal.
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

/// What `run` and `compare` take: a scenario, where to write, and what else to write.
#[derive(clap::Args)]
struct CaseArgs {
    /// The scenario (TOML).
    scenario: PathBuf,
    /// Output directory (created if missing).
    #[arg(long)]
    out: PathBuf,
    /// Run even if the CSV output would exceed 2 GB.
    #[arg(long)]
    force: bool,
    #[command(flatten)]
    viewer: viewer::ViewerArgs,
}

/// How much of a sweep's table `sweep` and `merge` print.
#[derive(clap::Args)]
struct ListingArgs {
    /// Print no table, only the summary line.
    #[arg(long, conflicts_with = "all")]
    quiet: bool,
    /// Print every point, also above 1000 points (where the best 20 are printed by default).
    #[arg(long)]
    all: bool,
}

impl ListingArgs {
    fn listing(&self) -> sweep::Listing {
        match (self.quiet, self.all) {
            (true, _) => sweep::Listing::Summary,
            (false, true) => sweep::Listing::All,
            (false, false) => sweep::Listing::Default,
        }
    }
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

/// How a command ended without an error.
enum Ended {
    Done,
    /// SIGINT or SIGTERM stopped a run; its output is written, `line` says where it stopped.
    Interrupted {
        signal: i32,
        line: String,
    },
}

/// How a run of `results` into `out` ended: interrupted, failed (an error), or done.
fn ended(results: &[runner::CaseResult], out: &Path) -> Result<Ended> {
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
        _ => fail_on_error(results, out).map(|()| Ended::Done),
    }
}

fn output_dir(dir: &Path) -> Result<()> {
    if dir.exists() && !dir.is_dir() {
        bail!("--out {} is a file, not a directory", dir.display());
    }
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create output directory {}", dir.display()))
}

/// Writes a sweep's (or merged sweep's) `sweep.json` and heat maps into `out` and prints its table
/// (the summary line alone with `--quiet`).
fn write_sweep(result: &sweep::Sweep, out: &Path, listing: sweep::Listing) -> Result<()> {
    output_dir(out)?;
    sweep::write(result, out)?;
    print(&sweep::listing(result, listing))?;
    if listing != sweep::Listing::Summary {
        print(&format!("wrote {}\n", out.join("sweep.json").display()))?;
    }
    Ok(())
}

/// The roff man page of `command`.
fn man_page(command: clap::Command) -> Result<Vec<u8>> {
    let mut page = Vec::new();
    clap_mangen::Man::new(command).render(&mut page).context("cannot render the man page")?;
    Ok(page)
}

/// `cdyn man`: cdyn.1 to standard output, or every command's page into `out`.
fn man(out: Option<PathBuf>) -> Result<()> {
    let cli = Cli::command();
    let Some(dir) = out else {
        return print(&String::from_utf8_lossy(&man_page(cli)?));
    };
    output_dir(&dir)?;
    let name = cli.get_name().to_string();
    let mut pages = vec![(format!("{name}.1"), man_page(cli.clone())?)];
    for sub in cli.get_subcommands() {
        let sub_name = format!("{name}-{}", sub.get_name());
        pages.push((format!("{sub_name}.1"), man_page(sub.clone().name(sub_name).version(env!("CARGO_PKG_VERSION")))?));
    }
    for (file, page) in &pages {
        output::write(&dir.join(file), page)?;
    }
    print(&format!("wrote {} man pages into {}\n", pages.len(), dir.display()))
}

fn run(cli: Cli) -> Result<Ended> {
    match cli.command {
        Command::Completions { shell } => {
            let mut script = Vec::new();
            clap_complete::generate(shell, &mut Cli::command(), "cdyn", &mut script);
            print(&String::from_utf8_lossy(&script))?;
            Ok(Ended::Done)
        }
        Command::Man { out } => man(out).map(|()| Ended::Done),
        Command::Paper { out } => {
            output_dir(&out)?;
            let cases = paper::cases()?;
            output::clear(&out, &report::file_names(&cases, report::PAPER_FIGURES))?;
            interrupt::install();
            let results = paper::run(&cases, &out)?;
            print(&report::table(&results))?;
            print(&format!("wrote {}\n", out.display()))?;
            ended(&results, &out)
        }
        Command::Run { case: CaseArgs { scenario, out, force, viewer } } => {
            let parsed = scenario::load(&scenario)?;
            parsed.refuse_sweep(&scenario, "run")?;
            let mut case = parsed.case(&scenario)?;
            case.check().map_err(|e| anyhow::anyhow!("{}: {e}", scenario.display()))?;
            viewer.prepare(std::slice::from_mut(&mut case))?;
            runner::Estimate::of(std::slice::from_ref(&case)).check(
                &scenario.display().to_string(),
                case.every,
                force,
            )?;
            if let Some(a) = &case.assembly {
                print(&format!("{}\n", report::assembly_line(a)))?;
            }
            output_dir(&out)?;
            output::clear(&out, &report::file_names(std::slice::from_ref(&case), report::RUN_FIGURES))?;
            interrupt::install();
            let results = report::run_cases(std::slice::from_ref(&case), &out)?;
            let extra = serde_json::json!({
                "scenario": scenario.display().to_string(),
                "assembly": case.assembly.as_ref().map(report::assembly_json),
            });
            report::write_summary(&out, &results, extra)?;
            report::write_figures(&out, &results[0].name, &results, report::RUN_FIGURES)?;
            if let Some(sketch) = &case.example.sketch {
                view3d::write(&out, &results[0].name, sketch, &results[0].frames)?;
            }
            viewer.write(&out, &results[0].name, std::slice::from_ref(&case), &results)?;
            print(&report::table(&results))?;
            print(&format!("wrote {}\n", out.display()))?;
            ended(&results, &out)
        }
        Command::Bench { out, light } => {
            output_dir(&out)?;
            let report = bench::run(light)?;
            let path = out.join("bench.json");
            output::write(&path, (serde_json::to_string_pretty(&report)? + "\n").as_bytes())?;
            print(&bench::table(&report))?;
            print(&format!("wrote {}\n", path.display()))?;
            Ok(Ended::Done)
        }
        Command::Sweep { scenario, out, shard, threads, listing } => {
            let (parsed, table) = scenario::load_with_table(&scenario)?;
            let shard = shard.as_deref().map(sweep::parse_shard).transpose()?;
            let threads = sweep::worker_threads(threads)?;
            write_sweep(&sweep::run(&parsed, &table, &scenario, shard, threads)?, &out, listing.listing())
                .map(|()| Ended::Done)
        }
        Command::Merge { parts, out, listing } => {
            let parts = parts
                .iter()
                .map(|p| {
                    let file = if p.is_dir() { p.join("sweep.json") } else { p.clone() };
                    let text =
                        std::fs::read_to_string(&file).with_context(|| format!("cannot read {}", file.display()))?;
                    let doc: serde_json::Value = serde_json::from_str(&text)
                        .with_context(|| format!("{}: not a sweep.json", file.display()))?;
                    if doc.get("points").is_some() && doc.get("scenario_hash").is_none() {
                        bail!(
                            "{}: no scenario_hash (written by an older cdyn, which merged by path); run that shard again",
                            file.display()
                        );
                    }
                    serde_json::from_value(doc).with_context(|| format!("{}: not a sweep.json", file.display()))
                })
                .collect::<Result<Vec<_>>>()?;
            write_sweep(&sweep::merge(parts)?, &out, listing.listing()).map(|()| Ended::Done)
        }
        Command::Compare { case: CaseArgs { scenario, out, force, viewer } } => {
            let parsed = scenario::load(&scenario)?;
            parsed.refuse_sweep(&scenario, "compare")?;
            let mut cases = compare::cases(&parsed, &scenario)?;
            viewer.prepare(&mut cases)?;
            let every = cases.first().map_or(1, |c| c.every);
            runner::Estimate::of(&cases).check(&scenario.display().to_string(), every, force)?;
            output_dir(&out)?;
            output::clear(&out, &report::file_names(&cases, report::RUN_FIGURES))?;
            interrupt::install();
            let results = compare::run(&cases, &scenario, &out)?;
            let stem = scenario.file_stem().map_or("compare".into(), |s| s.to_string_lossy().into_owned());
            viewer.write(&out, &stem, &cases, &results)?;
            print(&report::table(&results))?;
            print(&format!("wrote {}\n", out.display()))?;
            ended(&results, &out)
        }
        Command::Suite { scenarios, out, light } => {
            let result = suite::run(&scenarios, light)?;
            output_dir(&out)?;
            suite_plot::write(&result, &out)?;
            suite::write(&result, &out)?;
            print(&suite::table(&result))?;
            print(&suite::summary(&result))?;
            print(&format!("wrote {}\n", out.join("suite.json").display()))?;
            Ok(Ended::Done)
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

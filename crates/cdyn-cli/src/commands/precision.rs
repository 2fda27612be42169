//! `cdyn precision`: work-precision diagrams of one scenario.

use super::output_dir;
use anyhow::{Result, anyhow};
use cdyn::Scheme;
use cdyn_cli::io::{output, terminal::print};
use cdyn_cli::render::precision_plot;
use cdyn_cli::study::precision::{self, Methods, Options};
use std::path::Path;

/// What `cdyn precision` reads from its command line.
#[derive(clap::Args)]
pub struct PrecisionArgs {
    /// The scenario (TOML).
    pub scenario: std::path::PathBuf,
    /// Output directory (created if missing).
    #[arg(long)]
    pub out: std::path::PathBuf,
    /// Schemes, comma-separated (default: every scheme).
    #[arg(long, value_delimiter = ',')]
    pub schemes: Vec<String>,
    /// Methods of `cdyn compare`, comma-separated, or `all` (default: no control, robust, projection).
    #[arg(long, value_delimiter = ',')]
    pub methods: Vec<String>,
    /// Steps, comma-separated, each dividing the coarsest (default: the scenario's h times 4, 2, 1, 1/2, 1/4).
    #[arg(long, value_delimiter = ',')]
    pub h: Vec<f64>,
    /// End time in place of the scenario's.
    #[arg(long)]
    pub t_end: Option<f64>,
    /// A quick version: three steps (2h, h, h/2) over a quarter of t_end.
    #[arg(long)]
    pub light: bool,
}

/// Runs the diagram, writes precision.json, precision.csv and the figures, prints the table.
pub fn precision(args: PrecisionArgs) -> Result<()> {
    let schemes = args
        .schemes
        .iter()
        .map(|name| {
            Scheme::from_name(name).ok_or_else(|| {
                let names: Vec<&str> = Scheme::ALL.iter().map(|s| s.info().name).collect();
                anyhow!("--schemes {name}: not a scheme (the schemes: {})", names.join(", "))
            })
        })
        .collect::<Result<Vec<_>>>()?;
    let methods = Methods::from_names(&args.methods);
    let options = Options { schemes, methods, steps: args.h, t_end: args.t_end, light: args.light };
    output_dir(&args.out)?;
    let result = precision::run(&args.scenario, &options)?;
    let json = args.out.join("precision.json");
    output::write(&json, (serde_json::to_string_pretty(&result)? + "\n").as_bytes())?;
    output::write(&args.out.join("precision.csv"), precision::csv(&result).as_bytes())?;
    precision_plot::write(&result, &args.out)?;
    print(&precision::table(&result))?;
    print(&format!("wrote {} and {}\n", json.display(), Path::new(&args.out).join("precision.png").display()))
}

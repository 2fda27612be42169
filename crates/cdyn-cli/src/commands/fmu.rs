//! `cdyn fmu`: a scenario as an FMI 2.0 co-simulation FMU.

use anyhow::Result;
use cdyn_cli::export::fmu;
use cdyn_cli::io::terminal::print;
use std::path::Path;

/// Writes the FMU of `scenario` to `out`, carrying `library` (or the one found).
pub fn fmu(scenario: &Path, out: &Path, library: Option<&Path>) -> Result<()> {
    fmu::write(scenario, out, library)?;
    print(&format!("wrote {}\n", out.display()))
}

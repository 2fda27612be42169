//! `cdyn completions` and `cdyn man`: shell completions and man pages from the clap definitions.

use super::output_dir;
use anyhow::{Context, Result};
use cdyn_cli::io::{output, terminal::print};
use std::path::Path;

/// Prints the completion script of `shell` for `cli`.
pub fn completions(shell: clap_complete::Shell, mut cli: clap::Command) -> Result<()> {
    let mut script = Vec::new();
    clap_complete::generate(shell, &mut cli, "cdyn", &mut script);
    print(&String::from_utf8_lossy(&script))
}

/// The roff man page of `command`.
fn man_page(command: clap::Command) -> Result<Vec<u8>> {
    let mut page = Vec::new();
    clap_mangen::Man::new(command).render(&mut page).context("cannot render the man page")?;
    Ok(page)
}

/// `cdyn man`: cdyn.1 to standard output, or every command's page into `out`.
pub fn man(cli: clap::Command, out: Option<&Path>) -> Result<()> {
    let Some(dir) = out else {
        return print(&String::from_utf8_lossy(&man_page(cli)?));
    };
    output_dir(dir)?;
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

//! The command line's conventions: every command's `--help` ends with an
//! example of it, the exit codes are in `cdyn --help`, and completions and
//! man pages are generated for every command.

use crate::common::{cdyn, path_str};

/// The commands, as `cdyn --help` lists them.
fn commands() -> Vec<String> {
    let out = cdyn(&["--help"]);
    let help = String::from_utf8(out.stdout).unwrap();
    let listed = help.split("Commands:").nth(1).unwrap().split("Options:").next().unwrap();
    listed.lines().filter_map(|l| l.split_whitespace().next()).filter(|c| *c != "help").map(String::from).collect()
}

#[test]
fn every_command_has_an_example_and_cdyn_names_its_exit_codes() {
    let commands = commands();
    assert!(commands.len() >= 9, "{commands:?}");
    for command in &commands {
        let out = cdyn(&[command, "--help"]);
        let help = String::from_utf8(out.stdout).unwrap();
        assert!(out.status.success(), "{command}");
        assert!(help.contains(&format!("Example: cdyn {command}")), "{command} --help has no example:\n{help}");
    }
    let help = String::from_utf8(cdyn(&["--help"]).stdout).unwrap();
    for code in ["0 done", "1 an error", "2 a command line", "130 or 143"] {
        assert!(help.contains(code), "exit code {code} not in cdyn --help");
    }
}

#[test]
fn completions_cover_every_command_and_an_unknown_shell_is_refused() {
    let commands = commands();
    for shell in ["bash", "zsh", "fish", "elvish", "powershell"] {
        let out = cdyn(&["completions", shell]);
        assert!(out.status.success(), "{shell}");
        let script = String::from_utf8(out.stdout).unwrap();
        for command in &commands {
            assert!(script.contains(command.as_str()), "{shell} completions lack {command}");
        }
    }
    let out = cdyn(&["completions", "tcsh"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("invalid value 'tcsh'"));
}

#[test]
fn man_pages_are_written_for_every_command() {
    let out = cdyn(&["man"]);
    let page = String::from_utf8(out.stdout).unwrap();
    assert!(out.status.success() && page.contains(".TH cdyn 1"), "{page}");
    let dir = tempfile::tempdir().unwrap();
    let out = cdyn(&["man", "--out", path_str(dir.path())]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    for command in commands() {
        let page = std::fs::read_to_string(dir.path().join(format!("cdyn-{command}.1"))).unwrap();
        assert!(page.contains(&format!(".TH cdyn-{command} 1")), "{command}");
        assert!(page.contains("Example"), "the man page of {command} has no example");
    }
    assert!(dir.path().join("cdyn.1").is_file());
}

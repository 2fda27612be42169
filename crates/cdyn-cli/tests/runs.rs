//! Runs that are stopped, fail to write, or are long: SIGINT/SIGTERM end a
//! run with its output complete and marked interrupted; output files are
//! written atomically and never mix two runs; a full disk leaves no
//! half-written file; long runs are refused before they start unless
//! forced; the figures' series and the memory stay bounded however long the
//! run. Each test checks the exit code, the one line on standard error, and
//! what is left on disk.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use crate::common::{cdyn, one_error_line, path_str, scenario};

/// The pendulum of the paper's Example 1 under CVSGF; `t_end` and `every` are substituted.
const PENDULUM: &str = r#"
[model]
kind = "pendulum"
[method]
geometric = "cvsgf"
alpha_g = 40.0
[integrator]
scheme = "ab3"
h = 0.001
t_end = T_END
[output]
every = EVERY
"#;

fn pendulum(t_end: &str, every: &str) -> String {
    PENDULUM.replace("T_END", t_end).replace("EVERY", every)
}

fn spawn(args: &[&str]) -> Child {
    Command::new(env!("CARGO_BIN_EXE_cdyn")).args(args).stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().unwrap()
}

/// Files in `dir` with their sizes (none if it does not exist).
fn files_in(dir: &Path) -> Vec<(String, u64)> {
    std::fs::read_dir(dir).map_or(Vec::new(), |d| {
        d.map(|e| {
            let e = e.unwrap();
            (e.file_name().to_string_lossy().into_owned(), e.metadata().unwrap().len())
        })
        .collect()
    })
}

/// Waits until the run writing into `dir` has written some rows (a file
/// there is no longer empty), so that a signal arrives mid-run.
fn wait_for_rows(dir: &Path, child: &mut Child) {
    let start = Instant::now();
    while !files_in(dir).iter().any(|(_, len)| *len > 0) {
        assert!(child.try_wait().unwrap().is_none(), "the run ended before it was interrupted");
        assert!(start.elapsed() < Duration::from_secs(120), "no output after 120 s");
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Sends `signal` to `child`.
fn signal(child: &Child, signal: i32) {
    // SAFETY: kill(2) on the pid of a child this test started and has not yet waited for.
    assert_eq!(unsafe { libc::kill(child.id() as libc::pid_t, signal) }, 0);
}

/// Checks that every line of `csv` has the header's number of fields and
/// every field of the rows parses as a number; returns the number of rows.
fn complete_rows(csv: &str) -> usize {
    assert!(csv.ends_with('\n'), "the last row is cut: {:?}", &csv[csv.len().saturating_sub(80)..]);
    let mut lines = csv.lines();
    let fields = lines.next().unwrap().split(',').count();
    let mut rows = 0;
    for line in lines {
        let values: Vec<&str> = line.split(',').collect();
        assert_eq!(values.len(), fields, "incomplete row {line:?}");
        for v in values {
            assert!(v.parse::<f64>().is_ok(), "{v:?} in {line:?} is not a number");
        }
        rows += 1;
    }
    rows
}

fn read_json(path: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// No file of the run is empty or still under its temporary name.
fn no_partial_files(dir: &Path) {
    for (name, len) in files_in(dir) {
        assert!(!name.starts_with(".cdyn-partial-"), "left {name} in {}", dir.display());
        assert!(len > 0, "left an empty {name} in {}", dir.display());
    }
}

#[test]
fn sigint_stops_a_run_with_complete_output() {
    let (dir, path) = scenario("long.toml", &pendulum("1.0e5", "100"));
    let out_dir = dir.join("out");
    let mut child = spawn(&["run", path_str(&path), "--out", path_str(&out_dir)]);
    wait_for_rows(&out_dir, &mut child);
    signal(&child, libc::SIGINT);
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{stderr}");
    assert_eq!(stderr.trim_end().lines().count(), 1, "not one line: {stderr}");
    for needle in ["interrupted by SIGINT at step", "of case long", path_str(&out_dir)] {
        assert!(stderr.contains(needle), "{stderr:?} should mention {needle:?}");
    }

    let summary = read_json(&out_dir.join("summary.json"));
    assert_eq!(summary["interrupted"], true);
    let case = &summary["cases"][0];
    assert_eq!(case["interrupted"], true);
    assert!(case["error"].is_null());
    let steps = case["steps"].as_u64().unwrap();
    let t = case["t_final"].as_f64().unwrap();
    assert!(steps > 0 && steps < 1_000_000_000, "stopped at step {steps}");
    assert!((t - steps as f64 * 0.001).abs() < 1e-6 * t.max(1.0), "t = {t} at step {steps}");
    assert_eq!(summary["interrupted_at"]["step"], steps);
    assert_eq!(summary["interrupted_at"]["case"], "long");

    // Rows every 100 steps and one where the run stopped, each complete.
    let csv = std::fs::read_to_string(out_dir.join("long.csv")).unwrap();
    let rows = complete_rows(&csv);
    assert_eq!(rows as u64, steps / 100 + 1 + u64::from(!steps.is_multiple_of(100)));
    let last: f64 = csv.lines().last().unwrap().split(',').next().unwrap().parse().unwrap();
    assert_eq!(last, t);
    for figure in ["phi.png", "phi.svg", "psi.png", "psi.svg", "err.png", "err.svg"] {
        assert!(out_dir.join(figure).exists(), "no {figure}");
    }
    no_partial_files(&out_dir);
}

#[test]
fn sigterm_stops_compare_after_the_case_it_is_in() {
    let (dir, path) = scenario("long.toml", &pendulum("1.0e5", "1000"));
    let out_dir = dir.join("out");
    let mut child = spawn(&["compare", path_str(&path), "--out", path_str(&out_dir)]);
    wait_for_rows(&out_dir, &mut child);
    signal(&child, libc::SIGTERM);
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(143), "{stderr}");
    assert_eq!(stderr.trim_end().lines().count(), 1, "not one line: {stderr}");
    assert!(stderr.contains("interrupted by SIGTERM"), "{stderr}");

    let summary = read_json(&out_dir.join("summary.json"));
    assert_eq!(summary["interrupted"], true);
    let cases = summary["cases"].as_array().unwrap();
    // The first case was interrupted; none after it ran.
    assert_eq!(cases.len(), 1, "{cases:?}");
    assert_eq!(cases[0]["interrupted"], true);
    let name = cases[0]["name"].as_str().unwrap();
    complete_rows(&std::fs::read_to_string(out_dir.join(format!("{name}.csv"))).unwrap());
    let csvs = files_in(&out_dir).into_iter().filter(|(n, _)| n.ends_with(".csv")).count();
    assert_eq!(csvs, 1);
    assert!(out_dir.join("phi.png").exists());
    no_partial_files(&out_dir);
}

#[test]
fn a_killed_run_leaves_nothing_of_the_previous_run() {
    let (dir, path) = scenario("long.toml", &pendulum("1.0", "10"));
    let out_dir = dir.join("out");
    let first = cdyn(&["run", path_str(&path), "--out", path_str(&out_dir)]);
    assert!(first.status.success(), "{}", String::from_utf8_lossy(&first.stderr));
    assert!(out_dir.join("summary.json").exists() && out_dir.join("phi.png").exists());

    // A second run, killed outright (no chance to clean up) while it writes.
    std::fs::write(&path, pendulum("1.0e5", "100")).unwrap();
    let mut child = spawn(&["run", path_str(&path), "--out", path_str(&out_dir)]);
    let start = Instant::now();
    while out_dir.join("summary.json").exists() || !files_in(&out_dir).iter().any(|(_, len)| *len > 0) {
        assert!(start.elapsed() < Duration::from_secs(120), "no output after 120 s");
        std::thread::sleep(Duration::from_millis(20));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    // Nothing under a real name: neither the first run's files nor a cut CSV.
    let left = files_in(&out_dir);
    assert!(left.iter().all(|(name, _)| name.starts_with(".cdyn-partial-")), "{left:?}");

    // The next run removes the killed run's partial file.
    std::fs::write(&path, pendulum("1.0", "10")).unwrap();
    let third = cdyn(&["run", path_str(&path), "--out", path_str(&out_dir)]);
    assert!(third.status.success(), "{}", String::from_utf8_lossy(&third.stderr));
    no_partial_files(&out_dir);
    assert_eq!(complete_rows(&std::fs::read_to_string(out_dir.join("long.csv")).unwrap()), 101);
}

/// A directory on a 64 KB tmpfs, unmounted when dropped.
struct SmallDisk(PathBuf);

impl SmallDisk {
    /// Mounts one, or says why it cannot (not root, or no permission to mount).
    fn mount() -> Result<SmallDisk, String> {
        // SAFETY: geteuid has no preconditions.
        if unsafe { libc::geteuid() } != 0 {
            return Err("not running as root".into());
        }
        let dir = tempfile::tempdir().unwrap().keep();
        let out = Command::new("mount")
            .args(["-t", "tmpfs", "-o", "size=64k", "tmpfs", path_str(&dir)])
            .output()
            .map_err(|e| format!("mount: {e}"))?;
        match out.status.success() {
            true => Ok(SmallDisk(dir)),
            false => Err(format!("mount failed: {}", String::from_utf8_lossy(&out.stderr).trim())),
        }
    }
}

impl Drop for SmallDisk {
    fn drop(&mut self) {
        let _ = Command::new("umount").arg(&self.0).status();
    }
}

#[test]
fn a_full_disk_leaves_no_half_written_file() {
    let disk = match SmallDisk::mount() {
        Ok(disk) => disk,
        Err(why) => {
            println!("skipped: the full-disk test needs a small tmpfs ({why})");
            return;
        }
    };
    let (_, path) = scenario("long.toml", &pendulum("10.0", "1"));
    // The CSV (about 1.3 MB) does not fit; then only the figures do not.
    for (t_end, every, fails_at) in [("10.0", "1", "long.csv"), ("0.1", "10", "phi.png")] {
        std::fs::write(&path, pendulum(t_end, every)).unwrap();
        let out_dir = disk.0.join(format!("out-{every}"));
        let line = one_error_line(&cdyn(&["run", path_str(&path), "--out", path_str(&out_dir)]));
        for needle in ["cannot write", fails_at, "No space left on device"] {
            assert!(line.contains(needle), "{line:?} should mention {needle:?}");
        }
        no_partial_files(&out_dir);
        for (name, _) in files_in(&out_dir) {
            let file = out_dir.join(&name);
            match name.rsplit_once('.').map(|p| p.1) {
                Some("json") => drop(read_json(&file)),
                Some("csv") => drop(complete_rows(&std::fs::read_to_string(&file).unwrap())),
                Some("png") => assert!(std::fs::read(&file).unwrap().ends_with(b"IEND\xaeB`\x82"), "cut {name}"),
                Some("svg") => assert!(std::fs::read_to_string(&file).unwrap().trim_end().ends_with("</svg>")),
                _ => panic!("unexpected {name}"),
            }
        }
        std::fs::remove_dir_all(&out_dir).unwrap();
    }
}

#[test]
fn a_run_too_large_for_the_disk_is_refused_unless_forced() {
    // 9e8 steps at every = 1: about 160 GB of CSV.
    let (dir, path) = scenario("huge.toml", &pendulum("9.0e5", "1"));
    for command in ["run", "compare"] {
        let out_dir = dir.join(command);
        let line = one_error_line(&cdyn(&[command, path_str(&path), "--out", path_str(&out_dir)]));
        // One case for `run`, nine methods for `compare`.
        let (rows, every) = if command == "run" { ("900000002 rows", "100") } else { ("8100000018 rows", "1000") };
        let suggestion = format!("set [output] every = {every} or larger");
        for needle in ["huge.toml", "GB of CSV", rows, "[output] every = 1)", &suggestion, "--force"] {
            assert!(line.contains(needle), "{command}: {line:?} should mention {needle:?}");
        }
        assert!(files_in(&out_dir).is_empty(), "{command} wrote {:?}", files_in(&out_dir));
    }
    // The suggested `every` is accepted (the run is stopped once it has started).
    std::fs::write(&path, pendulum("9.0e5", "100")).unwrap();
    let out_dir = dir.join("every");
    let mut child = spawn(&["run", path_str(&path), "--out", path_str(&out_dir)]);
    wait_for_rows(&out_dir, &mut child);
    signal(&child, libc::SIGINT);
    assert_eq!(child.wait().unwrap().code(), Some(130));
    // So is the original with --force.
    std::fs::write(&path, pendulum("9.0e5", "1")).unwrap();
    let out_dir = dir.join("forced");
    let mut child = spawn(&["run", path_str(&path), "--out", path_str(&out_dir), "--force"]);
    wait_for_rows(&out_dir, &mut child);
    signal(&child, libc::SIGINT);
    assert_eq!(child.wait().unwrap().code(), Some(130));
    assert_eq!(read_json(&out_dir.join("summary.json"))["interrupted"], true);
}

#[test]
fn a_scenario_file_is_read_with_a_bound() {
    let dir = tempfile::tempdir().unwrap().keep();
    let start = Instant::now();
    let line = one_error_line(&cdyn(&["run", "/dev/zero", "--out", path_str(&dir.join("out"))]));
    assert!(start.elapsed() < Duration::from_secs(20), "took {:?}", start.elapsed());
    for needle in ["/dev/zero", "larger than 16 MB", "not a scenario"] {
        assert!(line.contains(needle), "{line:?} should mention {needle:?}");
    }
    // A large file that is not one: refused by its size, not parsed.
    let big = dir.join("big.toml");
    std::fs::write(&big, format!("{}\n# {}\n", pendulum("1.0", "1"), "x".repeat(17 << 20))).unwrap();
    let line = one_error_line(&cdyn(&["run", path_str(&big), "--out", path_str(&dir.join("out"))]));
    assert!(line.contains("big.toml: larger than 16 MB"), "{line}");
    // Just below the bound, it is a scenario like any other.
    std::fs::write(&big, format!("{}\n# {}\n", pendulum("1.0", "1"), "x".repeat(15 << 20))).unwrap();
    let out = cdyn(&["run", path_str(&big), "--out", path_str(&dir.join("out"))]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    // Binary bytes: one line, no dump.
    std::fs::write(&big, [b'a', 0xff, 0xfe, b'\n']).unwrap();
    let line = one_error_line(&cdyn(&["run", path_str(&big), "--out", path_str(&dir.join("out"))]));
    assert!(line.contains("big.toml: not UTF-8 text"), "{line}");
    assert!(!dir.join("out").join("big.csv").exists() || files_in(&dir.join("out")).len() > 1);
}

/// Runs `args` to the end and returns its exit status and peak resident
/// memory in bytes (the kernel's count for exactly this child, from wait4).
#[allow(clippy::zombie_processes)] // waited for by wait4, which std's Child does not know
fn peak_memory(args: &[&str]) -> (i32, u64) {
    let child = Command::new(env!("CARGO_BIN_EXE_cdyn"))
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut status = 0;
    // SAFETY: an all-zero rusage is a valid value for wait4 to fill in.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: waits for a child this test started; both pointers are to live locals.
    let pid = unsafe { libc::wait4(child.id() as libc::pid_t, &mut status, 0, &mut usage) };
    assert_eq!(pid, child.id() as libc::pid_t);
    assert!(libc::WIFEXITED(status), "status {status}");
    // ru_maxrss is in kilobytes on Linux.
    (libc::WEXITSTATUS(status), usage.ru_maxrss as u64 * 1024)
}

#[test]
fn ten_million_steps_stay_below_100_mb() {
    // Example 1's pendulum, h = 0.001 to t = 10⁴: 10⁷ steps, a row every 1000.
    let (dir, path) = scenario("long.toml", &pendulum("1.0e4", "1000"));
    let out_dir = dir.join("out");
    let (code, peak) = peak_memory(&["run", path_str(&path), "--out", path_str(&out_dir)]);
    assert_eq!(code, 0);
    println!("peak RSS of a 10^7-step run: {:.1} MB", peak as f64 / 1e6);
    assert!(peak < 100_000_000, "peak RSS {peak} bytes");
    let summary = read_json(&out_dir.join("summary.json"));
    assert_eq!(summary["cases"][0]["steps"], 10_000_000);
    assert_eq!(complete_rows(&std::fs::read_to_string(out_dir.join("long.csv")).unwrap()), 10_001);
}

#[test]
fn progress_is_shown_on_a_terminal_only() {
    let (dir, path) = scenario("long.toml", &pendulum("10.0", "100"));
    // Without a terminal (as here): nothing on standard error.
    for command in ["run", "compare"] {
        let out_dir = dir.join(command);
        let out = cdyn(&[command, path_str(&path), "--out", path_str(&out_dir)]);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        assert!(out.stderr.is_empty(), "{command}: {}", String::from_utf8_lossy(&out.stderr));
    }
    // On a terminal (a pseudo-terminal from script(1)): a bar counting steps with a time estimate.
    std::fs::write(&path, pendulum("1.0e4", "1000")).unwrap();
    let line = format!("{} run {} --out {}", env!("CARGO_BIN_EXE_cdyn"), path_str(&path), path_str(&dir.join("tty")));
    let Ok(out) = Command::new("script").args(["-qec", &line, "/dev/null"]).output() else {
        println!("skipped: no script(1) to run cdyn on a pseudo-terminal");
        return;
    };
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{text}");
    for needle in ["/10,000,000 steps", "elapsed", "left"] {
        assert!(text.contains(needle), "no {needle:?} in {text:?}");
    }
    // The bar is cleared before the table: its last line is the table's.
    assert!(text.contains("case ") && text.contains("wrote"), "{text}");
}

//! Sweeps by content and at scale: `cdyn merge` identifies a sweep by a hash
//! of its parsed scenario (not the path it was given by), a large grid prints
//! a short summary, and mutated examples never panic or run with an ignored key.

use std::path::Path;
use std::process::{Command, Output};

const GRID: &str = r#"
[model]
kind = "pendulum"
[method]
geometric = "cvsgf"
alpha_g = 40.0
apply = "forward_euler"
[integrator]
scheme = "ab3"
h = 0.01
t_end = 1.0
[sweep]
alpha_g = [10.0, 40.0, 160.0]
h = [0.01, 0.02]
"#;

fn cdyn_in(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_cdyn")).current_dir(dir).args(args).output().unwrap()
}

fn ok(o: &Output) -> String {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(o.stderr.is_empty(), "{}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// The one error line of a failed command.
fn one_error_line(o: &Output) -> String {
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "not one line: {err}");
    err
}

fn sweep_json(dir: &Path, out: &str) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(dir.join(out).join("sweep.json")).unwrap()).unwrap()
}

#[test]
fn merge_accepts_the_same_file_by_any_path() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("grid.toml"), GRID).unwrap();
    ok(&cdyn_in(d, &["sweep", "grid.toml", "--out", "one"]));
    let absolute = d.join("grid.toml").display().to_string();
    for (i, path) in ["grid.toml", "./grid.toml", absolute.as_str()].iter().enumerate() {
        ok(&cdyn_in(d, &["sweep", path, "--shard", &format!("{i}/3"), "--out", &format!("part{i}")]));
    }
    let hashes: Vec<serde_json::Value> =
        (0..3).map(|i| sweep_json(d, &format!("part{i}"))["scenario_hash"].clone()).collect();
    assert!(hashes[0].as_str().is_some_and(|h| h.len() == 32), "{hashes:?}");
    assert!(hashes.iter().all(|h| *h == hashes[0]), "{hashes:?}");
    ok(&cdyn_in(d, &["merge", "part0", "part1", "part2", "--out", "merged"]));
    assert_eq!(
        std::fs::read(d.join("merged/sweep.json")).unwrap(),
        std::fs::read(d.join("one/sweep.json")).unwrap(),
        "shards given by other paths do not merge into the single run"
    );
}

#[test]
fn the_hash_follows_content_not_layout() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // Tables reordered, a comment added, 1.0 written as 1: the same scenario.
    let (head, grid) = GRID.split_once("[sweep]").unwrap();
    let (before, integrator) = head.split_once("[integrator]").unwrap();
    let same =
        format!("# a comment\n[sweep]{grid}[integrator]{}{before}", integrator.replace("t_end = 1.0", "t_end = 1"));
    std::fs::write(d.join("a.toml"), GRID).unwrap();
    std::fs::write(d.join("b.toml"), same).unwrap();
    ok(&cdyn_in(d, &["sweep", "a.toml", "--shard", "0/2", "--out", "a"]));
    ok(&cdyn_in(d, &["sweep", "b.toml", "--shard", "1/2", "--out", "b"]));
    assert_eq!(sweep_json(d, "a")["scenario_hash"], sweep_json(d, "b")["scenario_hash"]);
    ok(&cdyn_in(d, &["merge", "a", "b", "--out", "ab"]));
    assert_eq!(sweep_json(d, "ab")["points"].as_array().unwrap().len(), 6);
}

#[test]
fn merge_refuses_shards_of_an_edited_scenario() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for (what, edited) in [
        ("scheme", GRID.replace("scheme = \"ab3\"", "scheme = \"rk4\"")),
        ("t_end", GRID.replace("t_end = 1.0", "t_end = 0.5")),
        ("a gain", GRID.replace("alpha_g = 40.0", "alpha_g = 20.0")),
    ] {
        // The same path for both shards: the file was edited between them.
        std::fs::write(d.join("grid.toml"), GRID).unwrap();
        ok(&cdyn_in(d, &["sweep", "grid.toml", "--shard", "0/2", "--out", "p0"]));
        std::fs::write(d.join("grid.toml"), &edited).unwrap();
        ok(&cdyn_in(d, &["sweep", "grid.toml", "--shard", "1/2", "--out", "p1"]));
        let o = cdyn_in(d, &["merge", "p0", "p1", "--out", "bad"]);
        let err = one_error_line(&o);
        assert!(err.contains("different sweeps") && err.contains("scenario_hash"), "{what}: {err}");
        assert!(!d.join("bad/sweep.json").exists(), "{what}: a refused merge wrote output");
    }
    // A shard written before sweeps were identified by content cannot be checked: refused, saying why.
    let path = d.join("p1/sweep.json");
    let mut old: serde_json::Value = serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
    old.as_object_mut().unwrap().remove("scenario_hash");
    std::fs::write(&path, serde_json::to_string_pretty(&old).unwrap()).unwrap();
    let err = one_error_line(&cdyn_in(d, &["merge", "p0", "p1", "--out", "bad"]));
    assert!(err.contains("p1/sweep.json: no scenario_hash"), "{err}");
}

/// A grid of `na × nb` points with two steps per run.
fn big_grid(na: usize, nb: usize) -> String {
    let list = |n: usize, base: f64| (0..n).map(|i| format!("{:.1}", base + i as f64)).collect::<Vec<_>>().join(", ");
    format!(
        "[model]\nkind = \"pendulum\"\n[method]\ngeometric = \"cvsgf\"\nalpha_g = 40.0\nenergy = \"gradient\"\nalpha_e = 40.0\napply = \"forward_euler\"\n[integrator]\nscheme = \"ab3\"\nh = 0.01\nt_end = 0.02\n[sweep]\nalpha_g = [{}]\nalpha_e = [{}]\n",
        list(na, 1.0),
        list(nb, 1.0)
    )
}

fn count(text: &str, needle: &str) -> usize {
    text.matches(needle).count()
}

/// Values printed in the cells of a heat map's SVG: text `d.dde±x` (the
/// colour bar's labels have one decimal, the axes' none in exponent form here).
fn cell_labels(svg: &str) -> usize {
    svg.split('>')
        .skip(1)
        .filter(|t| {
            let b = t.trim_start().as_bytes();
            b.len() > 5
                && b[0].is_ascii_digit()
                && b[1] == b'.'
                && b[2].is_ascii_digit()
                && b[3].is_ascii_digit()
                && b[4] == b'e'
        })
        .count()
}

#[test]
fn a_large_sweep_prints_its_best_points_and_quiet_prints_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("big.toml"), big_grid(77, 13)).unwrap(); // 1001 points
    let out = ok(&cdyn_in(d, &["sweep", "big.toml", "--out", "big"]));
    let lines: Vec<&str> = out.lines().collect();
    // Header, the 20 best, the line saying so, the summary, where it wrote.
    assert_eq!(lines.len(), 24, "{out}");
    assert!(lines[21].contains("20 best of 1001 points") && lines[21].contains("--all"), "{out}");
    assert!(lines[22].starts_with("1001 points, 0 failed; best max|err|"), "{out}");
    // The rows are the best by the error against the reference, in order.
    let err: Vec<f64> = lines[1..21].iter().map(|l| l.split_whitespace().nth(4).unwrap().parse().unwrap()).collect();
    assert!(err.windows(2).all(|w| w[0] <= w[1]), "{err:?}");
    let doc = sweep_json(d, "big");
    let all: Vec<f64> = doc["points"].as_array().unwrap().iter().map(|p| p["max_abs_err"].as_f64().unwrap()).collect();
    assert_eq!(all.len(), 1001);
    let min = all.iter().copied().fold(f64::INFINITY, f64::min);
    assert!((err[0] - min).abs() <= 1e-3 * min, "{} vs {min}", err[0]);

    let quiet = ok(&cdyn_in(d, &["sweep", "big.toml", "--out", "big", "--quiet"]));
    assert_eq!(quiet.lines().count(), 1, "{quiet}");
    assert_eq!(quiet, lines[22].to_string() + "\n");
    let every = ok(&cdyn_in(d, &["sweep", "big.toml", "--out", "big", "--all"]));
    assert_eq!(every.lines().count(), 1 + 1001 + 2, "--all");
    let merged = ok(&cdyn_in(d, &["merge", "big", "--out", "merged", "--quiet"]));
    assert_eq!(merged, quiet, "merge --quiet");
    let o = cdyn_in(d, &["sweep", "big.toml", "--out", "big", "--quiet", "--all"]);
    assert!(!o.status.success() && String::from_utf8_lossy(&o.stderr).contains("--quiet"));

    // Cells of a 77 × 13 map are a few pixels wide: no values printed in
    // them (a small map prints one per cell); both get a colour bar.
    std::fs::write(d.join("small.toml"), big_grid(3, 2)).unwrap();
    let small_out = ok(&cdyn_in(d, &["sweep", "small.toml", "--out", "small"]));
    assert_eq!(small_out.lines().count(), 1 + 6 + 2, "{small_out}");
    let (big_svg, small_svg) = (
        std::fs::read_to_string(d.join("big/heat_phi.svg")).unwrap(),
        std::fs::read_to_string(d.join("small/heat_phi.svg")).unwrap(),
    );
    assert_eq!(cell_labels(&big_svg), 0, "cell labels on a 77 × 13 map");
    assert_eq!(cell_labels(&small_svg), 6, "a 3 × 2 map labels each cell");
    for svg in [&big_svg, &small_svg] {
        assert!(count(svg, "<rect") >= 100, "no colour bar: {} rectangles", count(svg, "<rect"));
    }
}

/// The shipped example directory.
fn examples() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples")
}

/// `max_abs_psi` and `max_abs_err_x` of the run of `scenario` (text).
fn psi_and_err(d: &Path, name: &str, scenario: &str) -> (f64, f64) {
    std::fs::write(d.join(format!("{name}.toml")), scenario).unwrap();
    ok(&cdyn_in(d, &["run", &format!("{name}.toml"), "--out", name]));
    let doc: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join(name).join("summary.json")).unwrap()).unwrap();
    let case = &doc["cases"][0];
    (case["max_abs_psi"].as_f64().unwrap(), case["max_abs_err_x"].as_f64().unwrap())
}

#[test]
fn theta_energy_is_better_with_its_energy_control() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let text = std::fs::read_to_string(examples().join("theta_energy.toml")).unwrap();
    assert!(text.contains("with energy control") && text.contains("energy = \"gradient\""), "{text}");
    let without: String = text
        .lines()
        .filter(|l| !l.starts_with("energy") && !l.starts_with("alpha_e"))
        .map(|l| format!("{l}\n"))
        .collect();
    let (psi_with, err_with) = psi_and_err(d, "with", &text);
    let (psi_without, err_without) = psi_and_err(d, "without", &without);
    assert!(psi_with < 0.7 * psi_without, "max|Ψ| {psi_with:e} with energy control, {psi_without:e} without");
    assert!(err_with < err_without, "max|err_x| {err_with:e} with energy control, {err_without:e} without");
}

/// Peak resident memory (VmHWM, bytes) of `cdyn args…` in `dir`, read from
/// /proc while it runs; `None` where there is no /proc.
fn peak_rss(dir: &Path, args: &[&str]) -> Option<u64> {
    let mut child = Command::new(env!("CARGO_BIN_EXE_cdyn"))
        .current_dir(dir)
        .args(args)
        .stdout(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let status = format!("/proc/{}/status", child.id());
    let mut peak = None;
    loop {
        // High-water mark: monotonic, so the last read before exit is the peak
        // up to then (the final write of sweep.json may add a little).
        if let Ok(text) = std::fs::read_to_string(&status)
            && let Some(kb) = text.lines().find_map(|l| l.strip_prefix("VmHWM:"))
        {
            peak = kb.trim().trim_end_matches("kB").trim().parse::<u64>().ok().map(|k| k * 1024).or(peak);
        }
        if let Some(s) = child.try_wait().unwrap() {
            assert!(s.success());
            return peak;
        }
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
}

#[test]
fn a_large_sweep_does_not_build_its_cases_in_advance() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("big.toml"), big_grid(500, 200)).unwrap(); // 100 000 points
    let Some(peak) = peak_rss(d, &["sweep", "big.toml", "--out", "big", "--quiet"]) else {
        eprintln!("skipped: no /proc to read the peak memory from");
        return;
    };
    assert_eq!(sweep_json(d, "big")["points"].as_array().unwrap().len(), 100_000);
    // With every case built in advance this grid peaked at 239 MB; streamed,
    // only the results stay (52 MB with sweep.json's text).
    assert!(peak < 120 << 20, "peak memory {} MB for 10⁵ points", peak >> 20);
}

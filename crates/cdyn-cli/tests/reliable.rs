//! Reliable runs: keys of another command are refused, `t_end` is a whole
//! number of steps, a closed standard output ends the printing but not the
//! run, `--threads` is capped, and infinities survive a round trip through
//! JSON. Each test checks the exit code, the one line naming the key, and
//! what is left on disk.

use std::path::Path;
use std::process::{Command, Output, Stdio};

use crate::common::{cdyn, one_error_line, path_str, scenario};

const PENDULUM: &str = r#"
[model]
kind = "pendulum"
[method]
geometric = "cvsgf"
alpha_g = 40.0
energy = "gradient"
alpha_e = 40.0
apply = "forward_euler"
[integrator]
scheme = "ab3"
h = 0.01
t_end = 1.0
"#;

const GRID: &str = r#"
[sweep]
alpha_g = [10.0, 40.0, 160.0]
h = [0.01, 0.02]
"#;

/// Files in `dir` (none if it does not exist).
fn files_in(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .map_or(Vec::new(), |d| d.map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect())
}

#[test]
fn run_and_compare_refuse_a_sweep_table() {
    let (dir, path) = scenario("grid.toml", &format!("{PENDULUM}{GRID}"));
    for command in ["run", "compare"] {
        let out_dir = dir.join(command);
        let line = one_error_line(&cdyn(&[command, path_str(&path), "--out", path_str(&out_dir)]));
        for needle in ["grid.toml", "[sweep]", "cdyn sweep", &format!("cdyn {command}")] {
            assert!(line.contains(needle), "{line:?} should mention {needle:?}");
        }
        assert!(files_in(&out_dir).is_empty(), "{command} wrote {:?}", files_in(&out_dir));
    }
    // `cdyn sweep` reads it.
    let out = cdyn(&["sweep", path_str(&path), "--out", path_str(&dir.join("sweep"))]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
}

#[test]
fn t_end_must_be_a_whole_number_of_steps() {
    let cases = [
        (
            PENDULUM.replace("t_end = 1.0", "t_end = 1.004"),
            vec![
                "bad.toml",
                "[integrator]",
                "h = 0.01",
                "t_end = 1.004",
                "whole number of steps",
                "nearest valid t_end is 1",
            ],
        ),
        (
            PENDULUM.replace("h = 0.01", "h = 0.5").replace("t_end = 1.0", "t_end = 0.1"),
            vec![
                "bad.toml",
                "[integrator]",
                "h = 0.5",
                "t_end = 0.1",
                "h must not exceed t_end",
                "nearest valid t_end is 0.5",
            ],
        ),
    ];
    for (text, needles) in cases {
        let (dir, path) = scenario("bad.toml", &text);
        let out_dir = dir.join("out");
        let line = one_error_line(&cdyn(&["run", path_str(&path), "--out", path_str(&out_dir)]));
        for needle in needles {
            assert!(line.contains(needle), "{line:?} should mention {needle:?}");
        }
        assert!(files_in(&out_dir).is_empty(), "wrote {:?}", files_in(&out_dir));
    }

    // A sweep over h names the grid point at fault, and runs none.
    let (dir, path) = scenario("grid.toml", &format!("{PENDULUM}{}", GRID.replace("[0.01, 0.02]", "[0.01, 0.03]")));
    let out_dir = dir.join("out");
    let line = one_error_line(&cdyn(&["sweep", path_str(&path), "--out", path_str(&out_dir)]));
    for needle in ["grid.toml", "[integrator]", "t_end = 1", "h = 0.03", "nearest valid t_end is 0.99", "sweep point"] {
        assert!(line.contains(needle), "{line:?} should mention {needle:?}");
    }
    assert!(files_in(&out_dir).is_empty(), "wrote {:?}", files_in(&out_dir));

    // Decimal round-off (0.3 / 0.1 = 2.9999999999999996) is a whole number of steps.
    let text = PENDULUM.replace("h = 0.01", "h = 0.1").replace("t_end = 1.0", "t_end = 0.3");
    let (dir, path) = scenario("ok.toml", &text);
    let out = cdyn(&["run", path_str(&path), "--out", path_str(&dir.join("out"))]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("out/summary.json")).unwrap()).unwrap();
    assert_eq!(summary["cases"][0]["steps"], 3);
}

/// Runs `args` with standard output a pipe whose reader is already closed:
/// every write to it fails with a broken pipe.
fn with_closed_stdout(args: &[&str]) -> Output {
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    Command::new(env!("CARGO_BIN_EXE_cdyn")).args(args).stdout(Stdio::from(writer)).output().unwrap()
}

/// Every file of `dir` with its bytes, sorted by name.
fn contents(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut files: Vec<_> =
        files_in(dir).into_iter().map(|f| (f.clone(), std::fs::read(dir.join(&f)).unwrap())).collect();
    files.sort();
    files
}

#[test]
fn a_closed_stdout_ends_the_printing_not_the_run() {
    let dir = tempfile::tempdir().unwrap();
    let out = |name: &str| dir.path().join(name);

    // A mechanism prints its assembly line before any file is written.
    let crank = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/slider_crank.toml");
    let printed = cdyn(&["run", path_str(&crank), "--out", path_str(&out("run"))]);
    assert!(printed.status.success(), "{}", String::from_utf8_lossy(&printed.stderr));
    assert!(String::from_utf8_lossy(&printed.stdout).starts_with("assembly:"));
    let closed = with_closed_stdout(&["run", path_str(&crank), "--out", path_str(&out("run_closed"))]);
    assert_eq!(closed.status.code(), Some(0), "{}", String::from_utf8_lossy(&closed.stderr));
    assert!(closed.stderr.is_empty(), "{}", String::from_utf8_lossy(&closed.stderr));
    let files = contents(&out("run"));
    assert!(files.iter().any(|(f, _)| f == "summary.json") && files.iter().any(|(f, _)| f == "phi.png"));
    assert_eq!(contents(&out("run_closed")), files, "the files differ from a run printing to a terminal");

    // A sweep prints its table after writing; `| head -1` reads one line and closes.
    let (_, grid) = scenario("grid.toml", &format!("{PENDULUM}{GRID}"));
    let printed = cdyn(&["sweep", path_str(&grid), "--out", path_str(&out("sweep"))]);
    assert!(printed.status.success(), "{}", String::from_utf8_lossy(&printed.stderr));
    let closed = with_closed_stdout(&["sweep", path_str(&grid), "--out", path_str(&out("sweep_closed"))]);
    assert_eq!(closed.status.code(), Some(0), "{}", String::from_utf8_lossy(&closed.stderr));
    assert!(closed.stderr.is_empty(), "{}", String::from_utf8_lossy(&closed.stderr));
    assert_eq!(contents(&out("sweep_closed")), contents(&out("sweep")));

    let mut child = Command::new(env!("CARGO_BIN_EXE_cdyn"))
        .args(["sweep", path_str(&grid), "--out", path_str(&out("sweep_head"))])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut first = String::new();
    std::io::BufRead::read_line(&mut std::io::BufReader::new(child.stdout.take().unwrap()), &mut first).unwrap();
    assert!(first.contains("alpha_g"), "{first}");
    let rest = child.wait_with_output().unwrap();
    assert_eq!(rest.status.code(), Some(0), "{}", String::from_utf8_lossy(&rest.stderr));
    assert!(rest.stderr.is_empty(), "{}", String::from_utf8_lossy(&rest.stderr));
    assert_eq!(contents(&out("sweep_head")), contents(&out("sweep")));
}

#[test]
fn threads_are_capped_with_a_notice() {
    let (dir, grid) = scenario("grid.toml", &format!("{PENDULUM}{GRID}"));
    let one = cdyn(&["sweep", path_str(&grid), "--out", path_str(&dir.join("one")), "--threads", "1"]);
    assert!(one.status.success() && one.stderr.is_empty(), "{}", String::from_utf8_lossy(&one.stderr));
    let many = cdyn(&["sweep", path_str(&grid), "--out", path_str(&dir.join("many")), "--threads", "100000"]);
    let stderr = String::from_utf8_lossy(&many.stderr);
    assert!(many.status.success(), "{stderr}");
    assert_eq!(stderr.trim_end().lines().count(), 1, "not one line: {stderr}");
    assert!(stderr.starts_with("notice: --threads 100000") && stderr.contains("using"), "{stderr}");
    let json = |d: &str| std::fs::read(dir.join(d).join("sweep.json")).unwrap();
    assert_eq!(json("many"), json("one"), "results depend on the number of threads");
}

#[test]
fn infinities_are_written_as_strings_and_read_back() {
    // |Φ| of q = (1e200, 0) overflows to infinity at the first sample; the
    // first step diverges, and the summary keeps the infinity.
    let text = "[model]\nkind = \"pendulum\"\n[initial]\nq = [1e200, 0.0]\noff_constraint = true\n\
                [integrator]\nscheme = \"euler\"\nh = 0.01\nt_end = 1.0\n";
    let (dir, path) = scenario("inf.toml", text);
    let line = one_error_line(&cdyn(&["run", path_str(&path), "--out", path_str(&dir.join("out"))]));
    assert!(line.contains("diverged"), "{line}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("out/summary.json")).unwrap()).unwrap();
    assert_eq!(summary["cases"][0]["max_abs_phi"], "inf", "{summary}");
    assert!(dir.join("out/inf.csv").exists());

    // A shard's infinities and NaN merge into the same strings.
    let (dir, grid) = scenario("grid.toml", &format!("{PENDULUM}{GRID}"));
    let part = |i: usize| dir.join(format!("part{i}"));
    for i in 0..2 {
        let o = cdyn(&["sweep", path_str(&grid), "--shard", &format!("{i}/2"), "--out", path_str(&part(i))]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let file = part(0).join("sweep.json");
    let mut doc: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&file).unwrap()).unwrap();
    doc["points"][0]["max_abs_phi"] = "inf".into();
    doc["points"][0]["max_abs_psi"] = "NaN".into();
    doc["points"][1]["max_abs_err"] = "-inf".into();
    std::fs::write(&file, serde_json::to_string_pretty(&doc).unwrap()).unwrap();
    let merged = dir.join("merged");
    let o = cdyn(&["merge", path_str(&part(0)), path_str(&part(1)), "--out", path_str(&merged)]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(merged.join("sweep.json")).unwrap()).unwrap();
    let points = doc["points"].as_array().unwrap();
    assert_eq!(points.len(), 6);
    assert_eq!((&points[0]["max_abs_phi"], &points[0]["max_abs_psi"]), (&"inf".into(), &"NaN".into()));
    assert_eq!(points[2]["max_abs_err"], "-inf");
    assert!(points[1]["max_abs_phi"].is_f64());

    // Any other string is refused in one line.
    let mut doc: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&file).unwrap()).unwrap();
    doc["points"][0]["max_abs_phi"] = "huge".into();
    std::fs::write(&file, serde_json::to_string_pretty(&doc).unwrap()).unwrap();
    let o = cdyn(&["merge", path_str(&part(0)), path_str(&part(1)), "--out", path_str(&dir.join("bad"))]);
    let line = one_error_line(&o);
    assert!(line.contains("sweep.json") && line.contains("huge"), "{line}");
}

#[test]
fn messages_show_values_and_times_as_people_write_them() {
    // A non-finite gravity vector: the values, not a debug dump of the type.
    let text = "[model]\nkind = \"mechanism\"\ngravity = [nan, -9.81]\n[integrator]\nscheme = \"rk4\"\nh = 0.01\n\
                t_end = 1.0\n[[bodies]]\nname = \"a\"\nmass = 1.0\ninertia = 0.1\nposition = [1.0, 0.0]\n";
    let (dir, path) = scenario("g.toml", text);
    let line = one_error_line(&cdyn(&["run", path_str(&path), "--out", path_str(&dir.join("out"))]));
    assert!(line.contains("gravity = [NaN, -9.81]") && !line.contains("Vector"), "{line}");
    let text = text.replace("[nan, -9.81]", "\"down\"");
    let (dir, path) = scenario("g.toml", &text);
    let line = one_error_line(&cdyn(&["run", path_str(&path), "--out", path_str(&dir.join("out"))]));
    assert!(line.contains("expected a magnitude g") && !line.contains("untagged"), "{line}");

    // A huge step: the time with an exponent, not 309 digits.
    let text = "[model]\nkind = \"pendulum\"\n[integrator]\nscheme = \"rk4\"\nh = 1e308\nt_end = 1e308\n";
    let (dir, path) = scenario("big.toml", text);
    let line = one_error_line(&cdyn(&["run", path_str(&path), "--out", path_str(&dir.join("out"))]));
    assert!(line.contains("t = 1e308") && line.len() < 200, "{line}");

    // `--out` naming a file.
    let file = dir.join("a_file");
    std::fs::write(&file, "").unwrap();
    let line = one_error_line(&cdyn(&["run", path_str(&path), "--out", path_str(&file)]));
    assert!(line.contains("is a file, not a directory"), "{line}");

    // 3 steps of 0.1 end at 0.3, in the summary and the CSV's last row.
    let text = "[model]\nkind = \"pendulum\"\n[integrator]\nscheme = \"rk4\"\nh = 0.1\nt_end = 0.3\n";
    let (dir, path) = scenario("t03.toml", text);
    let out = cdyn(&["run", path_str(&path), "--out", path_str(&dir.join("out"))]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("out/summary.json")).unwrap()).unwrap();
    assert_eq!(summary["cases"][0]["t_final"].as_f64(), Some(0.3), "{summary}");
    let csv = std::fs::read_to_string(dir.join("out/t03.csv")).unwrap();
    assert!(csv.lines().last().unwrap().starts_with("3e-1,"), "{csv}");
}

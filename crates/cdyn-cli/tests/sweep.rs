//! `cdyn sweep` / `cdyn merge`: results do not depend on the number of
//! threads, shards merge into exactly the single-run output, and mistakes
//! are one line.

use std::path::Path;
use std::process::{Command, Output};

const SWEEP: &str = r#"
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
t_end = 2.0
[sweep]
alpha_g = [10.0, 40.0, 160.0]
alpha_e = [10.0, 40.0]
h = [0.01, 0.02]
"#;

fn cdyn(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_cdyn")).args(args).output().unwrap()
}

fn sweep(dir: &Path, scenario: &Path, extra: &[&str], out: &str) -> Vec<u8> {
    let out_dir = dir.join(out);
    let mut args = vec!["sweep", scenario.to_str().unwrap(), "--out", out_dir.to_str().unwrap()];
    args.extend_from_slice(extra);
    let o = cdyn(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    std::fs::read(out_dir.join("sweep.json")).unwrap()
}

#[test]
fn threads_and_shards_give_the_same_bits() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = dir.path().join("s.toml");
    std::fs::write(&scenario, SWEEP).unwrap();
    let one = sweep(dir.path(), &scenario, &["--threads", "1"], "one");
    let two = sweep(dir.path(), &scenario, &["--threads", "2"], "two");
    assert_eq!(one, two, "results depend on the number of threads");
    let doc: serde_json::Value = serde_json::from_slice(&one).unwrap();
    assert_eq!(doc["points"].as_array().unwrap().len(), 12);
    assert!(dir.path().join("one/heat_err.png").exists() && dir.path().join("one/heat_phi.svg").exists());

    for i in 0..3 {
        sweep(dir.path(), &scenario, &["--shard", &format!("{i}/3")], &format!("part{i}"));
    }
    let parts: Vec<String> = (0..3).map(|i| dir.path().join(format!("part{i}")).display().to_string()).collect();
    let merged_dir = dir.path().join("merged");
    let mut args = vec!["merge"];
    args.extend(parts.iter().map(String::as_str));
    args.extend(["--out", merged_dir.to_str().unwrap()]);
    let o = cdyn(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(std::fs::read(merged_dir.join("sweep.json")).unwrap(), one, "merged shards differ from one run");

    // A missing shard is refused.
    let o = cdyn(&["merge", &parts[0], &parts[2], "--out", dir.path().join("bad").to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && err.contains("missing") && err.trim_end().lines().count() == 1, "{err}");
    // The same shard twice too.
    let o = cdyn(&[
        "merge",
        &parts[0],
        &parts[0],
        &parts[1],
        &parts[2],
        "--out",
        dir.path().join("bad2").to_str().unwrap(),
    ]);
    assert!(!o.status.success() && String::from_utf8_lossy(&o.stderr).contains("twice"));
}

#[test]
fn sweep_mistakes_are_one_line() {
    let dir = tempfile::tempdir().unwrap();
    for (text, args, needle) in [
        (SWEEP.replace("h = [0.01, 0.02]", "gain = [1.0]"), vec![], "gain"),
        (SWEEP.replace("h = [0.01, 0.02]", "h = [0.01, -0.02]"), vec![], "h = -0.02"),
        (SWEEP.replace("alpha_e = [10.0, 40.0]", "alpha_e = []"), vec![], "empty"),
        (SWEEP.to_string(), vec!["--shard", "3/3"], "--shard"),
        (SWEEP.split("[sweep]").next().unwrap().to_string(), vec![], "[sweep]"),
    ] {
        let path = dir.path().join("s.toml");
        std::fs::write(&path, &text).unwrap();
        let mut all = vec!["sweep", path.to_str().unwrap(), "--out", dir.path().to_str().unwrap()];
        all.extend(args);
        let o = cdyn(&all);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success() && err.contains(needle) && err.trim_end().lines().count() == 1, "{needle}: {err}");
    }
}

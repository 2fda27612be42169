//! Mechanism scenario files: the shipped Andrews file reproduces the test
//! set, `compare` runs every method, and mistakes name the entry.

use cdyn::models::andrews::{body_angles, constants, test_set_angles};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn examples() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples")
}

fn cdyn(args: &[&str], scenario: &Path, out: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_cdyn")).args(args).arg(scenario).arg("--out").arg(out).output().unwrap()
}

fn summary(dir: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap()
}

fn floats(v: &Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
}

#[test]
fn the_andrews_scenario_file_reproduces_the_published_positions() {
    let dir = tempfile::tempdir().unwrap();
    let out = cdyn(&["run"], &examples().join("andrews.toml"), dir.path());
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let s = summary(dir.path());
    let q = floats(&s["cases"][0]["q_end"]);
    let angles = test_set_angles(body_angles(&q));
    for (i, (a, b)) in angles.iter().zip(constants::Q_REF_003).enumerate() {
        assert!(((a - b) / b).abs() < 1e-6, "angle {i}: {a} vs published {b}");
    }
}

#[test]
fn compare_runs_every_method_and_reports_final_states() {
    let dir = tempfile::tempdir().unwrap();
    let out = cdyn(&["compare"], &examples().join("four_bar.toml"), dir.path());
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let s = summary(dir.path());
    let names: Vec<&str> = s["cases"].as_array().unwrap().iter().map(|c| c["name"].as_str().unwrap()).collect();
    let expected = cdyn::control::methods::compare_cases(&cdyn::control::methods::MethodGains::paper(), true);
    assert_eq!(names, expected.iter().map(|(n, _)| *n).collect::<Vec<_>>());
    assert_eq!(names.last(), Some(&"projection"), "the paper's cases, then robust and projection");
    for c in s["cases"].as_array().unwrap() {
        assert_eq!(floats(&c["q_end"]).len(), 9);
        assert_eq!(floats(&c["v_end"]).len(), 9);
        assert!(c["max_abs_phi"].as_f64().unwrap().is_finite());
        assert!(dir.path().join(format!("{}.csv", c["name"].as_str().unwrap())).exists());
    }
    // The gains used are recorded, and the assembly.
    assert_eq!(s["methods"].as_array().unwrap().len(), 9);
    assert!(s["assembly"]["max_abs_phi_after"].as_f64().unwrap() < 1e-10);
    for fig in ["phi.png", "psi.svg"] {
        assert!(dir.path().join(fig).exists());
    }
}

const CRANK: &str = r#"
[model]
kind = "mechanism"
gravity = [0.0, -9.81]
[integrator]
scheme = "rk4"
h = 0.001
t_end = 0.1
[[bodies]]
name = "crank"
mass = 1.0
inertia = 0.1
position = [0.5, 0.0]
[[joints]]
kind = "revolute"
a = "ground"
b = "crank"
point_b = [-0.5, 0.0]
"#;

fn error_of(text: &str) -> String {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("mech.toml");
    std::fs::write(&path, text).unwrap();
    let out = cdyn(&["run"], &path, &dir.path().join("out"));
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(!out.status.success(), "expected failure:\n{text}");
    assert!(!stderr.contains("panicked") && stderr.trim_end().lines().count() == 1, "{stderr}");
    assert!(stderr.contains("mech.toml"), "{stderr}");
    stderr
}

#[test]
fn a_good_mechanism_runs() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("mech.toml");
    std::fs::write(&path, CRANK).unwrap();
    let out = cdyn(&["run"], &path, &dir.path().join("out"));
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(String::from_utf8_lossy(&out.stdout).contains("assembly:"));
}

#[test]
fn mechanism_mistakes_name_the_entry() {
    let cases: Vec<(String, &[&str])> = vec![
        (CRANK.replace("b = \"crank\"", "b = \"crunk\""), &["joints[0] (revolute)", "crunk"]),
        (CRANK.replace("mass = 1.0", "mass = 0.0"), &["bodies[0] (crank)", "mass"]),
        (CRANK.replace("mass = 1.0\n", ""), &["mass"]),
        (CRANK.replace("kind = \"revolute\"", "kind = \"hinge\""), &["joints[0]", "hinge", "revolute"]),
        (CRANK.replace("point_b = [-0.5, 0.0]", "point_b = [-0.5, 0.0]\nlength = 2.0"), &["joints[0] (revolute)", "length"]),
        (CRANK.replace("inertia = 0.1\n", "inertia = 0.1\nangle = nan\n"), &["bodies[0] (crank)", "NaN"]),
        (format!("{CRANK}[[joints]]\nkind = \"distance\"\na = \"ground\"\nb = \"crank\"\nlength = 3.0\n"), &["[initial]", "joints[1] (distance)"]),
        (format!("{CRANK}[[forces]]\nkind = \"spring\"\na = \"crank\"\nb = \"crank\"\nstiffness = 1.0\n"), &["forces[0] (spring)", "itself"]),
        (CRANK.replace("gravity = [0.0, -9.81]", "gravity = 9.81"), &["gravity"]),
        (CRANK.replace("kind = \"mechanism\"", "kind = \"pendulum\""), &["mechanism"]),
        ("[model]\nkind = \"chain\"\n[model.parameters]\nlinks = 3\n[integrator]\nscheme = \"rk4\"\nh = 0.01\nt_end = 1.0\n".into(), &["[model.parameters]", "links", "n, mass"]),
        ("[model]\nkind = \"chain\"\n[model.parameters]\nn = 2.5\n[integrator]\nscheme = \"rk4\"\nh = 0.01\nt_end = 1.0\n".into(), &["n = 2.5"]),
    ];
    for (text, needles) in cases {
        let line = error_of(&text);
        for n in needles {
            assert!(line.contains(n), "{line:?} should mention {n:?} for:\n{text}");
        }
    }
}

#[test]
fn scenario_format_mistakes_fail_cleanly() {
    let drive = |function: &str| {
        format!("{CRANK}[[drives]]\nkind = \"relative_angle\"\na = \"ground\"\nb = \"crank\"\nfunction = {function}\n")
    };
    let cases: Vec<(String, &[&str])> = vec![
        (drive("{ polynom = [1.0] }"), &["drives[0] (relative_angle)", "polynom"]),
        (drive("{ }"), &["drives[0] (relative_angle)", "polynomial"]),
        (
            format!("{CRANK}[[joints]]\nkind = \"spring\"\na = \"ground\"\nb = \"crank\"\nstiffness = 1.0\n"),
            &["joints[1] (spring)", "[[forces]]"],
        ),
        (
            format!("{CRANK}[[bodies]]\nname = \"crank\"\nmass = 1.0\nposition = [0.0, 0.0]\n"),
            &["bodies[1] (crank)", "already exists"],
        ),
    ];
    for (text, needles) in cases {
        let line = error_of(&text);
        for n in needles {
            assert!(line.contains(n), "{line:?} should mention {n:?} for:\n{text}");
        }
    }
}

#[test]
fn knife_edge_examples_run() {
    for name in ["knife_edge_incline", "chaplygin_sleigh", "bicycle"] {
        let dir = tempfile::tempdir().unwrap();
        let out = cdyn(&["run"], &examples().join(format!("{name}.toml")), dir.path());
        assert!(out.status.success(), "{name}: {}", String::from_utf8_lossy(&out.stderr));
        assert!(dir.path().join(format!("{name}.csv")).exists(), "{name}");
        // The edges' side speeds |A q̇ + b| are reported, at round-off under these methods.
        let phi_dot = summary(dir.path())["cases"][0]["max_abs_phi_dot"].as_f64().unwrap();
        assert!(phi_dot < 1e-13, "{name}: max |Φ̇| = {phi_dot:e}");
    }
}

#[test]
fn knife_edge_mistakes_name_the_entry() {
    let edge = |body: &str, rest: &str| {
        format!("{CRANK}[[joints]]\nkind = \"knife_edge\"\nbody = \"{body}\"\nblade = [1.0, 0.0]\n{rest}")
    };
    let cases: Vec<(String, &[&str])> = vec![
        (edge("crank", "").replace("blade = [1.0, 0.0]", "blade = [0.0, 0.0]"), &["joints[1] (knife_edge)", "|blade|"]),
        (edge("crank", "").replace("blade = [1.0, 0.0]\n", ""), &["joints[1]", "blade"]),
        (edge("crank", "point = [nan, 0.0]\n"), &["joints[1] (knife_edge)", "point"]),
        (edge("ground", ""), &["joints[1] (knife_edge)", "ground"]),
        (edge("crank", "normal = [0.0, 1.0]\n"), &["joints[1]", "normal"]),
        (
            format!("{CRANK}[[drives]]\nkind = \"knife_edge\"\nbody = \"crank\"\nblade = [1.0, 0.0]\n"),
            &["drives[0] (knife_edge)", "[[joints]]"],
        ),
        (
            format!(
                "{CRANK}[[bodies]]\nname = \"bob\"\nmass = 1.0\nposition = [2.0, 0.0]\n[[joints]]\nkind = \"knife_edge\"\nbody = \"bob\"\nblade = [1.0, 0.0]\n"
            ),
            &["joints[1] (knife_edge)", "point mass"],
        ),
    ];
    for (text, needles) in cases {
        let line = error_of(&text);
        for n in needles {
            assert!(line.contains(n), "{line:?} should mention {n:?} for:\n{text}");
        }
    }
}

#[test]
fn a_redundant_crank_is_tolerated_and_reported_or_named_when_strict() {
    let dir = tempfile::tempdir().unwrap();
    let path = examples().join("parallelogram_redundant.toml");
    let out = cdyn(&["run"], &path, dir.path());
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let case = &summary(dir.path())["cases"][0];
    assert!(case["error"].is_null(), "{case}");
    let rows = &case["dependent_rows"];
    assert_eq!((rows["max"].as_u64(), rows["steps"].as_u64()), (Some(1), case["steps"].as_u64()), "{rows}");
    assert_eq!(rows["first_time"].as_f64(), Some(0.0), "{rows}");
    assert!((rows["last_time"].as_f64().unwrap() - 4.999).abs() < 1e-9, "{rows}");

    // Strict (the default): one line naming the redundant entry, at
    // assembly or, without it, at the first step.
    let text = std::fs::read_to_string(&path).unwrap();
    for (strict, at) in [
        (text.replace("\ndependent_rows = \"tolerate\"\n", "\n"), "assembly"),
        (
            text.replace(
                "\ndependent_rows = \"tolerate\"\n",
                "\ndependent_rows = \"error\"\n[initial]\nassemble = false\n",
            ),
            "step 0",
        ),
    ] {
        let file = dir.path().join("strict.toml");
        std::fs::write(&file, strict).unwrap();
        let out = cdyn(&["run"], &file, &dir.path().join("strict"));
        let stderr = String::from_utf8(out.stderr).unwrap();
        assert!(!out.status.success() && stderr.trim_end().lines().count() == 1, "{stderr}");
        for part in [at, "joints[4] (distance)", "dependent_rows = \"tolerate\""] {
            assert!(stderr.contains(part), "{part}: {stderr}");
        }
    }
}

#[test]
fn a_run_without_dependent_rows_reports_none() {
    let dir = tempfile::tempdir().unwrap();
    let out = cdyn(&["run"], &examples().join("four_bar.toml"), dir.path());
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(summary(dir.path())["cases"][0]["dependent_rows"].is_null());
}

/// `[[invariants]]` of kind `angular_momentum` on the free planar
/// satellite: about any point it is kept (and printed first, as declared);
/// a mistaken key or axis is a one-line error naming file and entry; under
/// gravity it is broken, and the run warns with its drift.
#[test]
fn declared_angular_momenta_are_kept_refused_or_reported() {
    let satellite = std::fs::read_to_string(examples().join("suite/satellite_planar.toml")).unwrap();
    let declared = |entry: &str| format!("{satellite}\n[[invariants]]\nkind = \"angular_momentum\"\n{entry}");
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("mech.toml");
    std::fs::write(&path, declared("point = [1.0, 2.0]\nname = \"L about (1, 2)\"\n")).unwrap();
    let out = cdyn(&["run"], &path, &dir.path().join("out"));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(stdout.contains("keeps: L about (1, 2), linear momentum x, linear momentum y\n"), "{stdout}");
    let momenta = &summary(&dir.path().join("out"))["cases"][0]["momenta"];
    let held = momenta.as_array().unwrap().iter().find(|m| m["name"] == "L about (1, 2)").unwrap();
    assert_eq!(held["kept"], true);
    assert!(held["max_drift"].as_f64().unwrap() <= 1e-12 * held["scale"].as_f64().unwrap(), "{held}");
    for (entry, needles) in [
        ("pont = [0.0, 0.0]\n", &["invariants[0]", "pont"][..]),
        ("axis = [1.0, 0.0, 0.0]\n", &["invariants[0]", "turns about z"][..]),
        ("point = [0.0]\n", &["invariants[0]", "2 numbers"][..]),
    ] {
        let line = error_of(&declared(entry));
        for n in needles {
            assert!(line.contains(n), "{line:?} should mention {n:?}");
        }
    }
    let heavy = declared("name = \"L_z\"\n").replace("gravity = [0.0, 0.0]", "gravity = [0.0, -9.81]");
    std::fs::write(&path, heavy).unwrap();
    let out = cdyn(&["run"], &path, &dir.path().join("heavy"));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(stdout.contains("warning: ") && stdout.contains("L_z is not kept"), "{stdout}");
}

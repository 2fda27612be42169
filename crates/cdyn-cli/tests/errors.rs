//! Bad input: one line on stderr naming the file and the key or value, a
//! non-zero exit, never a panic; a diverging run keeps what it wrote.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn cdyn(args: &[&str], scenario: Option<&Path>, out: &Path) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_cdyn"));
    cmd.args(args);
    if let Some(s) = scenario {
        cmd.arg(s);
    }
    cmd.arg("--out").arg(out).output().unwrap()
}

const GOOD: &str = r#"
[model]
kind = "pendulum"
[method]
geometric = "cvsgf"
zeta = 20.0
[integrator]
scheme = "ab3"
h = 0.01
t_end = 1.0
"#;

/// Runs `cdyn run` on a scenario with `text`; returns the one error line.
fn error_of(text: &str) -> (String, PathBuf) {
    let dir = tempfile::tempdir().unwrap().keep();
    let path = dir.join("bad.toml");
    std::fs::write(&path, text).unwrap();
    let out = cdyn(&["run"], Some(&path), &dir.join("out"));
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(!out.status.success(), "expected failure for:\n{text}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(stderr.trim_end().lines().count(), 1, "not one line: {stderr}");
    assert!(stderr.starts_with("error: "), "{stderr}");
    (stderr, dir)
}

#[test]
fn a_good_scenario_runs() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("good.toml");
    std::fs::write(&path, GOOD).unwrap();
    let out = cdyn(&["run"], Some(&path), &dir.path().join("out"));
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(dir.path().join("out/good.csv").exists() && dir.path().join("out/summary.json").exists());
}

#[test]
fn bad_scenarios_get_one_line_naming_the_problem() {
    let cases: Vec<(String, &[&str])> = vec![
        (String::new(), &["bad.toml", "empty"]),
        ("[model\nkind=".into(), &["bad.toml:1"]),
        (GOOD.replace("kind = \"pendulum\"", "kind = \"pendulumm\""), &["bad.toml", "pendulumm"]),
        (GOOD.replace("t_end = 1.0", "t_end = 1.0\nsteps = 3"), &["bad.toml", "steps"]),
        (GOOD.replace("h = 0.01", "h = 0.0"), &["bad.toml", "h", "0"]),
        (GOOD.replace("h = 0.01", "h = -0.01"), &["bad.toml", "h", "-0.01"]),
        (GOOD.replace("h = 0.01", "h = nan"), &["bad.toml", "h", "NaN"]),
        (GOOD.replace("t_end = 1.0", "t_end = inf"), &["bad.toml", "t_end", "inf"]),
        (GOOD.replace("zeta = 20.0", "zeta = -1.0"), &["bad.toml", "zeta", "-1"]),
        (GOOD.replace("zeta = 20.0", "zeta = 1.0\nalpha_g = 3.0"), &["bad.toml", "zeta", "alpha_g"]),
        (GOOD.replace("zeta = 20.0", "zeta = 1.0\neta = 3.0"), &["bad.toml", "eta"]),
        (GOOD.replace("geometric = \"cvsgf\"", "geometric = \"magic\""), &["bad.toml", "magic"]),
        (GOOD.replace("scheme = \"ab3\"", "scheme = \"rk45\""), &["bad.toml", "rk45"]),
        (
            GOOD.replace("t_end = 1.0", "t_end = 1.0\ndependent_rows = \"ignore\""),
            &["bad.toml", "dependent_rows", "ignore", "tolerate"],
        ),
        (GOOD.replace("t_end = 1.0", "t_end = 1.0\ndependent_rows = 1"), &["bad.toml", "dependent_rows"]),
        (
            GOOD.replace("[model]\nkind = \"pendulum\"", "[model]\nkind = \"pendulum\"\nlength = -2"),
            &["bad.toml", "length", "-2"],
        ),
        (GOOD.replace("[method]", "[initial]\nq = [1.2, 0.0]\n[method]"), &["bad.toml", "constraints"]),
        (GOOD.replace("[method]", "[initial]\nq = [1.0]\n[method]"), &["bad.toml", "q"]),
        (
            GOOD.replace("[method]", "[initial]\nq = [0.0, 0.0]\nv = [0.0, 0.0]\noff_constraint = true\n[method]"),
            &["singular", "step 0"],
        ),
        (GOOD.replace("t_end = 1.0", "t_end = 1.0\n[output]\nevery = 0"), &["bad.toml", "every"]),
    ];
    for (text, needles) in cases {
        let (line, _) = error_of(&text);
        for n in needles {
            assert!(line.contains(n), "error {line:?} should mention {n:?} for:\n{text}");
        }
    }
}

#[test]
fn bad_keys_of_the_robust_methods_get_one_line_naming_the_key() {
    let method = |keys: &str| GOOD.replace("geometric = \"cvsgf\"\nzeta = 20.0", keys);
    // Generalized-α with no control, and these [integrator] keys.
    let alpha = |keys: &str| {
        GOOD.replace("[method]\ngeometric = \"cvsgf\"\nzeta = 20.0\n", "")
            .replace("scheme = \"ab3\"", &format!("scheme = \"generalized_alpha\"\n{keys}"))
    };
    let velocity =
        |alpha_v: &str| method(&format!("geometric = \"cvsgf\"\nzeta = 20.0\nvelocity = \"gradient\"\n{alpha_v}"));
    let cases: Vec<(String, &[&str])> = vec![
        (method("preset = \"fast\""), &["bad.toml", "preset", "fast"]),
        (method("preset = \"robust\"\nalpha_g = 3.0"), &["bad.toml", "robust", "alpha_g"]),
        (method("preset = \"projection\"\ngeometric = \"cvsgf\""), &["bad.toml", "projection", "geometric"]),
        (velocity("alpha_v = -1.0"), &["bad.toml", "alpha_v", "-1"]),
        (velocity("alpha_v = inf"), &["bad.toml", "alpha_v", "inf"]),
        (velocity("alpha_v = \"fast\""), &["bad.toml", "alpha_v", "fast"]),
        (method("geometric = \"cvsgf\"\nalpha_g = \"fast\""), &["bad.toml", "alpha_g", "fast", "auto"]),
        (method("geometric = \"newton\"\nalpha_g = -2.0"), &["bad.toml", "alpha_g", "-2"]),
        (method("energy = \"projected\"\nposition_weight = -1.0"), &["bad.toml", "position_weight", "-1"]),
        (method("geometric = \"cvsgf\"\nzeta = 20.0\nalpha_v = 3.0"), &["bad.toml", "alpha_v", "velocity"]),
        (method("preset = \"projection\"\ntolerance = 0.0"), &["bad.toml", "tolerance", "0"]),
        (method("preset = \"projection\"\ntolerance = nan"), &["bad.toml", "tolerance", "NaN"]),
        (method("preset = \"projection\"\nmax_iterations = 0"), &["bad.toml", "max_iterations", "0"]),
        (method("preset = \"projection\"\nmax_iterations = -1"), &["bad.toml", "max_iterations", "-1"]),
        (method("preset = \"projection\"\non_failure = \"ignore\""), &["bad.toml", "on_failure", "ignore"]),
        (method("geometric = \"cvsgf\"\nzeta = 20.0\ntolerance = 1e-9"), &["bad.toml", "tolerance", "projection"]),
        (
            GOOD.replace("t_end = 1.0", "t_end = 1.0\nrho_inf = 0.5"),
            &["bad.toml", "rho_inf", "generalized_alpha", "ab3"],
        ),
        (alpha("rho_inf = 1.5"), &["bad.toml", "rho_inf", "1.5", "[0, 1]"]),
        (alpha("newton_iterations = 0"), &["bad.toml", "newton iterations", "at least 1"]),
        (alpha("newton_iterations = 2\nnewton_tolerance = 1e-8"), &["bad.toml", "newton_iterations", "exclude"]),
        (alpha("newton_tolerance = -1.0"), &["bad.toml", "newton tolerance", "positive"]),
        (alpha("newton_tolerance = 1e-300\nnewton_max_iterations = 1"), &["Newton", "step 1", "converge"]),
    ];
    for (text, needles) in cases {
        let (line, _) = error_of(&text);
        for n in needles {
            assert!(line.contains(n), "error {line:?} should mention {n:?} for:\n{text}");
        }
    }
}

#[test]
fn missing_file_and_bad_command_fail_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let out = cdyn(&["run"], Some(&dir.path().join("nope.toml")), dir.path());
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(
        !out.status.success() && stderr.contains("nope.toml") && stderr.trim_end().lines().count() == 1,
        "{stderr}"
    );
    let out = Command::new(env!("CARGO_BIN_EXE_cdyn")).arg("fly").output().unwrap();
    assert!(!out.status.success());
}

#[test]
fn a_diverging_run_names_step_and_time_and_keeps_its_output() {
    let text = r#"
[model]
kind = "pendulum"
[initial]
q = [1.001, 0.0]
off_constraint = true
[method]
geometric = "cvsgf"
alpha_g = 2e6
[integrator]
scheme = "euler"
h = 0.01
t_end = 20.0
"#;
    let (line, dir) = error_of(text);
    assert!(line.contains("diverged at step") && line.contains("t = "), "{line}");
    let csv = std::fs::read_to_string(dir.join("out/bad.csv")).unwrap();
    let rows: Vec<&str> = csv.lines().collect();
    assert!(rows.len() > 2, "rows before the failure are kept");
    assert!(rows[1..].iter().all(|r| r.split(',').all(|x| x.parse::<f64>().is_ok())), "every kept row is readable");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("out/summary.json")).unwrap()).unwrap();
    assert!(summary["cases"][0]["error"].as_str().unwrap().contains("diverged"));
}

#[test]
fn shipped_examples_run() {
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    for entry in std::fs::read_dir(&examples).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "toml") {
            let dir = tempfile::tempdir().unwrap();
            // A sweep example is for `cdyn sweep`: `run` refuses its [sweep] table.
            let is_sweep = std::fs::read_to_string(&path).unwrap().lines().any(|l| l.trim() == "[sweep]");
            let out = cdyn(&[if is_sweep { "sweep" } else { "run" }], Some(&path), dir.path());
            assert!(out.status.success(), "{}: {}", path.display(), String::from_utf8_lossy(&out.stderr));
        }
    }
}

#[test]
fn a_run_with_damping_too_stiff_for_its_step_is_refused_naming_the_element_generalized_alpha_and_a_stable_step() {
    // The flyball governor at 1 kHz: RK-4 would diverge within a few steps;
    // it does not start.
    let flyball = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/flyball_governor.toml"))
        .unwrap()
        .replace("h = 5e-5", "h = 1e-3");
    let (line, _) = error_of(&flyball);
    // h λ_d = 8.1 at 1e-3 and RK-4's limit 2.785: half of it at h ≤ 1.7e-4.
    assert!(
        line.contains("the damping of forces[1] (spring) is too stiff for the step: h λ_d = 8.137 is above rk4's stability limit 2.785"),
        "{line}"
    );
    assert!(line.contains("scheme = \"generalized_alpha\" (no such limit), or h ≤ 1.71e-4"), "{line}");
    assert!(!line.contains("step 4"), "refused before the first step: {line}");
    // And generalized-α does run there (`tests/generalized_alpha` checks its accuracy).
    let alpha =
        flyball.replace("scheme = \"rk4\"", "scheme = \"generalized_alpha\"").replace("t_end = 2.0", "t_end = 0.05");
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("alpha.toml");
    std::fs::write(&path, alpha).unwrap();
    let out = cdyn(&["run"], Some(&path), &dir.path().join("out"));
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
}

#[test]
fn a_run_stopped_by_a_stiff_spring_names_generalized_alpha_and_a_stable_step() {
    // A 2 kg point mass on a spring of 20 000 N/m: ω = 100 rad/s along it.
    let spring = |scheme: &str, h: &str| {
        format!(
            r#"
[model]
kind = "mechanism"
gravity = [0.0, 0.0]
[method]
geometric = "none"
energy = "none"
[integrator]
scheme = "{scheme}"
h = {h}
t_end = 20.0
[[bodies]]
name = "bob"
mass = 2.0
position = [0.6, 0.0]
[[forces]]
kind = "spring"
a = "ground"
point_a = [0.0, 0.0]
b = "bob"
point_b = [0.0, 0.0]
stiffness = 20000.0
rest_length = 0.5
"#
        )
    };
    // h ω = 5, past RK-4's 2√2 on the imaginary axis: it would diverge, and
    // half that limit is at h ≤ 1.41e-2.
    let (line, _) = error_of(&spring("rk4", "0.05"));
    assert!(
        line.contains(
            "the springs are too stiff for the step: h ω = 5.000 is above rk4's stability limit on oscillations 2.828"
        ),
        "{line}"
    );
    assert!(line.contains("scheme = \"generalized_alpha\" (no such limit), or h ≤ 1.41e-2"), "{line}");
    // h ω = 2: stable, but past half the limit: a note; generalized-α runs at 0.05.
    for (scheme, h, note) in [("rk4", "0.02", true), ("rk4", "0.01", false), ("generalized_alpha", "0.05", false)] {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("spring.toml");
        std::fs::write(&path, spring(scheme, h)).unwrap();
        let out = cdyn(&["run"], Some(&path), &dir.path().join("out"));
        assert!(out.status.success(), "{scheme} {h}: {}", String::from_utf8_lossy(&out.stderr));
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert_eq!(
            stdout.contains("the springs are stiff against the step (h ω = 2.000"),
            note,
            "{scheme} {h}: {stdout}"
        );
    }
}

/// A pendulum turned by the input `tau` (the torque entry leaves its key out).
const WITH_INPUT: &str = r#"
[model]
kind = "mechanism"
gravity = [0.0, -9.81]
[[inputs]]
name = "tau"
drives = "forces[0].torque"
start = 0.0
[[bodies]]
name = "link"
mass = 1.0
inertia = 0.1
position = [0.5, 0.0]
[[joints]]
kind = "revolute"
a = "ground"
b = "link"
point_b = [-0.5, 0.0]
[[forces]]
kind = "torque"
body = "link"
[integrator]
h = 1e-3
t_end = 0.01
"#;

#[test]
fn bad_inputs_and_outputs_get_one_line_naming_the_entry_and_key() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("good.toml");
    std::fs::write(&path, WITH_INPUT).unwrap();
    let out = cdyn(&["run"], Some(&path), &dir.path().join("out"));
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let cases: Vec<(String, &[&str])> = vec![
        (
            WITH_INPUT.replace("body = \"link\"\n[integrator]", "body = \"link\"\ntorque = 1.0\n[integrator]"),
            &["bad.toml: forces[0] (torque): torque is driven by the input \"tau\" (inputs[0]): leave the key out"],
        ),
        (
            WITH_INPUT.replace("forces[0].torque", "forces[0].fx"),
            &[
                "bad.toml: forces[0] (torque): input \"tau\" on fx: a torque has no key an input drives by that name (it has: torque)",
            ],
        ),
        (
            WITH_INPUT.replace("forces[0].torque", "forces[2].torque"),
            &["bad.toml: inputs[0] (tau): drives = \"forces[2].torque\": the scenario has 1 [[forces]] entries"],
        ),
        (
            WITH_INPUT.replace("forces[0].torque", "torque"),
            &["inputs[0] (tau): drives = \"torque\": expected an entry"],
        ),
        (WITH_INPUT.replace("start = 0.0\n", ""), &["bad.toml", "inputs[0]", "missing field start"]),
        (WITH_INPUT.replace("start = 0.0", "start = 0.0\ngain = 2"), &["bad.toml", "inputs[0]", "gain"]),
        (
            WITH_INPUT.replace("t_end = 0.01", "t_end = 0.01\n[output]\nselect = [\"t\", \"angle\"]"),
            &[
                "bad.toml: [output] select: no output \"angle\"; the outputs are t, link.x, link.y, link.angle, phi, psi",
            ],
        ),
        (
            GOOD.to_string() + "[[inputs]]\nname = \"f\"\ndrives = \"forces[0].fx\"\nstart = 0.0\n",
            &["bad.toml: [[inputs]] drive keys of a mechanism's entries"],
        ),
    ];
    for (text, expected) in cases {
        let (stderr, _) = error_of(&text);
        for e in expected {
            assert!(stderr.contains(e), "expected {e:?} in: {stderr}");
        }
    }
}

/// `cdyn fmu` reads a scenario as `cdyn run` does: a bad key is the same
/// one line, and no FMU (nor a partial file) is left; a good one is a ZIP
/// of the model description, the scenario and the library it was given.
#[test]
fn cdyn_fmu_refuses_what_cdyn_run_refuses_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let library = dir.path().join("libfake.so");
    std::fs::write(&library, b"not a library: packed as it is").unwrap();
    let fmu = |scenario: &Path, out: &Path| {
        Command::new(env!("CARGO_BIN_EXE_cdyn"))
            .args([
                "fmu",
                scenario.to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
                "--library",
                library.to_str().unwrap(),
            ])
            .output()
            .unwrap()
    };
    let bad = WITH_INPUT.replace("mass = 1.0", "mass = 1.0\nmas = 2.0");
    let (run_error, bad_dir) = error_of(&bad);
    let out = fmu(&bad_dir.join("bad.toml"), &dir.path().join("bad.fmu"));
    assert!(!out.status.success());
    assert_eq!(String::from_utf8_lossy(&out.stderr), run_error);
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1, "only the library: no FMU, no partial file");
    let good = dir.path().join("good.toml");
    std::fs::write(&good, WITH_INPUT).unwrap();
    let out = fmu(&good, &dir.path().join("pendulum.fmu"));
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let zip = std::fs::read(dir.path().join("pendulum.fmu")).unwrap();
    for name in ["modelDescription.xml", "resources/scenario.toml", "binaries/linux64/pendulum.so"] {
        assert!(zip.windows(name.len()).any(|w| w == name.as_bytes()), "{name} in the FMU");
    }
    let out = fmu(&good, &dir.path().join("2nd.fmu"));
    assert!(String::from_utf8_lossy(&out.stderr).contains("model identifier"));
}

#[test]
fn a_robot_whose_joint_friction_is_too_stiff_for_the_default_step_is_refused_naming_the_joint() {
    // The arm's wrist with 1 N m of friction: near rest a damper of
    // μ / s = 100 N m s on a hand of about 1e-3 kg m² about its axis.
    let arm = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/arm.urdf")).unwrap();
    let rubbed =
        arm.replace("<axis xyz=\"0.6 0 0.8\"/>", "<axis xyz=\"0.6 0 0.8\"/><dynamics damping=\"0\" friction=\"1\"/>");
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("rubbed.urdf");
    std::fs::write(&path, rubbed).unwrap();
    let out = cdyn(&["run"], Some(&path), &dir.path().join("out"));
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(!out.status.success() && stderr.trim_end().lines().count() == 1, "{stderr}");
    assert!(stderr.contains("the damping of urdf joint \"wrist\" (revolute) is too stiff for the step"), "{stderr}");
    assert!(stderr.contains("above rk4's stability limit 2.785"), "{stderr}");
    assert!(stderr.contains("scheme = \"generalized_alpha\""), "{stderr}");
}

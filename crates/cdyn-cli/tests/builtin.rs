//! Built-in models straight from scenario files: every kind builds with its
//! defaults and with every parameter set, and a key the model does not have
//! is refused by name.

use std::process::Output;

/// The pendulums' keys go in `[model]`, the others' in `[model.parameters]`.
const EVERY_PARAMETER: &[(&str, &str)] = &[
    ("pendulum", "mass = 2.0\nlength = 1.5\ngravity = 9.81\ntheta0 = 0.1\nomega0 = 0.5\n"),
    ("pendulum_theta", "mass = 2.0\nlength = 1.5\ngravity = 9.81\ntheta0 = 0.1\nomega0 = 0.5\n"),
    ("andrews", ""),
    (
        "double_pendulum",
        "[model.parameters]\nm1 = 1.5\nm2 = 0.5\nl1 = 1.2\nl2 = 0.8\ngravity = 9.0\ntheta1 = 1.0\ntheta2 = 0.5\nomega1 = 0.1\nomega2 = -0.1\n",
    ),
    (
        "double_pendulum_angles",
        "[model.parameters]\nm1 = 1.5\nm2 = 0.5\nl1 = 1.2\nl2 = 0.8\ngravity = 9.0\ntheta1 = 1.0\ntheta2 = 0.5\nomega1 = 0.1\nomega2 = -0.1\n",
    ),
    ("chain", "[model.parameters]\nn = 3\nmass = 0.5\nlength = 0.7\ngravity = 9.0\ntheta0 = 1.0\nomega0 = 0.2\n"),
    (
        "slider_crank",
        "[model.parameters]\ncrank_radius = 0.4\nrod_length = 1.2\ncrank_mass = 0.4\ncrank_inertia = 0.01\nrod_mass = 1.2\nrod_inertia = 0.15\nslider_mass = 0.8\nslider_inertia = 0.02\nomega = 3.0\ntheta0 = 0.3\ngravity = 9.0\n[model.parameters.load]\nmass = 0.3\nlength = 0.6\nangle = 0.1\nomega = 0.2\n",
    ),
    (
        "four_bar",
        "[model.parameters]\ncrank_length = 1.0\ncoupler_length = 3.0\nrocker_length = 2.5\nground_length = 3.0\ncrank_mass = 1.1\ncrank_inertia = 0.09\ncoupler_mass = 3.1\ncoupler_inertia = 2.3\nrocker_mass = 2.4\nrocker_inertia = 1.3\nomega = 1.5\ntheta0 = 0.2\ngravity = 9.0\nbranch = \"right\"\n[model.parameters.load]\nmass = 0.3\nlength = 0.6\nangle = 0.1\nomega = 0.2\n",
    ),
    (
        "four_bar_angles",
        "[model.parameters]\ncrank_length = 1.0\ncoupler_length = 3.0\nrocker_length = 2.5\nground_length = 3.0\ncrank_mass = 1.1\ncrank_inertia = 0.09\ncoupler_mass = 3.1\ncoupler_inertia = 2.3\nrocker_mass = 2.4\nrocker_inertia = 1.3\nomega = 1.5\ntheta0 = 0.2\ngravity = 9.0\nbranch = \"right\"\n[model.parameters.load]\nmass = 0.3\nlength = 0.6\nangle = 0.1\nomega = 0.2\n",
    ),
    (
        "moving_support_pendulum",
        "[model.parameters]\nsupport_mass = 1.5\nmass = 0.5\nlength = 0.9\ngravity = 9.0\nsupport_x = { sine = [[0.1, 3.0, 0.0]] }\nsupport_y = 0.0\ntheta0 = -1.0\nomega0 = 0.1\n",
    ),
    (
        "damped_pendulum",
        "[model.parameters]\nmass = 1.5\ninertia = 0.2\nlength = 0.6\ngravity = 9.0\ndamping = 0.3\ntheta0 = 0.4\nomega0 = -0.2\n",
    ),
];

/// Runs `cdyn run` on `[model] kind = "{kind}"` followed by `model`.
fn run(kind: &str, model: &str) -> Output {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("builtin.toml");
    let text = format!("[model]\nkind = \"{kind}\"\n{model}\n[integrator]\nscheme = \"rk4\"\nh = 1e-4\nt_end = 1e-3\n");
    std::fs::write(&path, text).unwrap();
    std::process::Command::new(env!("CARGO_BIN_EXE_cdyn"))
        .arg("run")
        .arg(&path)
        .arg("--out")
        .arg(dir.path().join("out"))
        .output()
        .unwrap()
}

#[test]
fn every_built_in_kind_runs_with_its_defaults_and_with_every_parameter_set() {
    for &(kind, every) in EVERY_PARAMETER {
        for model in ["", every] {
            let out = run(kind, model);
            assert!(out.status.success(), "{kind} with {model:?}: {}", String::from_utf8_lossy(&out.stderr));
        }
    }
}

#[test]
fn an_unknown_parameter_is_refused_by_name() {
    for &(kind, every) in EVERY_PARAMETER {
        let model = if every.is_empty() || every.starts_with("[model.parameters]") {
            // Insert the unknown key into [model.parameters], before any sub-table.
            let known = every.strip_prefix("[model.parameters]\n").unwrap_or("");
            format!("[model.parameters]\nno_such_key = 1.0\n{known}")
        } else {
            format!("no_such_key = 1.0\n{every}")
        };
        let out = run(kind, &model);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{kind} accepted no_such_key");
        assert!(stderr.contains("no_such_key") && stderr.trim_end().lines().count() == 1, "{kind}: {stderr}");
        assert!(!stderr.contains("panicked"), "{kind}: {stderr}");
    }
}

#[test]
fn a_bad_value_names_its_table_and_key() {
    let cases = [
        ("chain", "[model.parameters]\nmass = -1.0\n", ["[model.parameters]", "mass", "-1"]),
        ("four_bar", "[model.parameters]\nbranch = \"up\"\n", ["[model.parameters]", "branch", "up"]),
        ("slider_crank", "[model.parameters.load]\nlength = 0.0\n", ["[model.parameters]", "load length", "0"]),
        ("pendulum_theta", "theta0 = \"x\"\n", ["[model]", "theta0", "x"]),
    ];
    for (kind, model, needles) in cases {
        let out = run(kind, model);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{kind} accepted {model:?}");
        for needle in needles {
            assert!(stderr.contains(needle), "{kind} {model:?}: {stderr:?} should mention {needle:?}");
        }
    }
}

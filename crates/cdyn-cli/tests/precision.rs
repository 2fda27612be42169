//! `cdyn precision`: the diagram's table, CSV and figures from real runs,
//! each scheme at its order on Example 1 against the closed form, the
//! reference of a model without one bounded, and bad input on one line.

use crate::common::{cdyn, one_error_line, path_str, scenario};
use serde_json::Value;

const EXAMPLE1: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/suite/example1.toml");

fn run(args: &[&str]) -> (std::path::PathBuf, Value) {
    let out = tempfile::tempdir().unwrap().keep();
    let mut all = vec!["precision"];
    all.extend_from_slice(args);
    all.extend_from_slice(&["--out", path_str(&out)]);
    let done = cdyn(&all);
    assert!(done.status.success(), "{}", String::from_utf8_lossy(&done.stderr));
    let json = serde_json::from_str(&std::fs::read_to_string(out.join("precision.json")).unwrap()).unwrap();
    (out, json)
}

fn line<'a>(p: &'a Value, scheme: &str, method: &str) -> &'a Value {
    p["lines"]
        .as_array()
        .unwrap()
        .iter()
        .find(|l| l["scheme"] == scheme && l["method"] == method)
        .unwrap_or_else(|| panic!("no line {scheme} {method}"))
}

#[test]
fn each_scheme_converges_at_its_order_against_the_closed_form() {
    let (out, p) =
        run(&[EXAMPLE1, "--light", "--schemes", "ab3,rk4,rattle,generalized_alpha", "--methods", "none,robust"]);
    assert_eq!(p["reference"]["kind"], "closed form");
    assert_eq!(p["t_end"], 5.0, "a quarter of the scenario's 20 s");
    // RATTLE and generalized-α take no right-hand-side control: no robust line for them.
    assert_eq!(p["lines"].as_array().unwrap().len(), 6);
    for (scheme, method, order) in [
        ("ab3", "none", 3.0),
        ("rk4", "none", 4.0),
        ("rk4", "robust", 4.0),
        ("rattle", "none", 2.0),
        ("generalized_alpha", "none", 2.0),
    ] {
        let l = line(&p, scheme, method);
        let observed = l["observed_order"].as_f64().unwrap();
        assert!((observed - order).abs() < 0.3, "{scheme} {method}: order {observed}, expected {order}");
        let points = l["points"].as_array().unwrap();
        assert_eq!(points.len(), 3);
        for (pt, h) in points.iter().zip([0.02_f64, 0.01, 0.005]) {
            assert_eq!(pt["h"], h);
            assert_eq!(pt["steps"].as_f64().unwrap(), (5.0 / h).round());
            assert!(pt["wall_per_second"].as_f64().unwrap() > 0.0);
        }
    }
    // The cost counts what each scheme evaluates: RK-4 four times a step, AB-3 once.
    let evals = |s, k: usize| line(&p, s, "none")["points"][k]["evaluations_per_second"].as_f64().unwrap();
    assert_eq!(evals("rk4", 1), 400.0);
    // (AB-3 starts with two RK-4 steps: 506 evaluations over the 5 s.)
    assert!((evals("ab3", 1) - 101.2).abs() < 1e-9, "AB-3 {}", evals("ab3", 1));
    // robust is better than none at RK-4 here (the suite's check c).
    let error = |m, k: usize| line(&p, "rk4", m)["points"][k]["max_error"].as_f64().unwrap();
    assert!(error("robust", 1) < error("none", 1) / 10.0);
    let csv = std::fs::read_to_string(out.join("precision.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + 6 * 3);
    assert!(csv.starts_with("scheme,method,h,steps,"));
    for f in ["precision.png", "precision.svg", "precision_evaluations.png", "precision_evaluations.svg"] {
        assert!(std::fs::metadata(out.join(f)).unwrap().len() > 1000, "{f}");
    }
}

#[test]
fn without_a_closed_form_the_reference_is_a_fine_rk4_whose_error_is_bounded() {
    let (_, text) = scenario(
        "double.toml",
        "[model]\nkind = \"double_pendulum\"\n[integrator]\nscheme = \"rk4\"\nh = 0.01\nt_end = 2.0\n",
    );
    let (_, p) = run(&[path_str(&text), "--schemes", "rk4", "--methods", "none", "--h", "0.02,0.01"]);
    assert_eq!(p["reference"]["kind"], "rk4");
    assert_eq!(p["reference"]["h"], 0.01 / 8.0);
    let bound = p["reference"]["error_bound"].as_f64().unwrap();
    let finest = line(&p, "rk4", "none")["points"][1]["max_error"].as_f64().unwrap();
    assert!(bound > 0.0 && bound < finest / 100.0, "reference bound {bound:e}, finest run {finest:e}");
}

#[test]
fn bad_choices_fail_on_one_line_before_anything_runs() {
    let out = tempfile::tempdir().unwrap();
    let o = path_str(out.path());
    for (args, expect) in [
        (vec!["--schemes", "rk5"], "--schemes rk5: not a scheme"),
        (vec!["--methods", "robustt"], "--methods robustt: not a method of this model"),
        (vec!["--h", "0.01,0.003"], "--h 0.003: every step must divide the coarsest"),
        (vec!["--h", "0.01,0"], "--h 0: every step must be positive"),
        (vec!["--t-end", "0"], "--t-end 0: must be positive"),
        (vec!["--schemes", "rattle", "--methods", "robust"], "nothing to run"),
    ] {
        let mut all = vec!["precision", EXAMPLE1, "--out", o];
        all.extend(args.iter());
        let line = one_error_line(&cdyn(&all));
        assert!(line.contains(expect), "{args:?}: {line}");
    }
    assert!(!out.path().join("precision.json").exists());
}

#[test]
fn a_changed_initial_state_drops_the_models_closed_form() {
    // The closed form solves the model's own initial state; with another, the reference is RK-4.
    let (_, text) = scenario(
        "moved.toml",
        "[model]\nkind = \"pendulum\"\n[integrator]\nscheme = \"rk4\"\nh = 0.01\nt_end = 1.0\n[initial]\nv = [0.0, 1.5]\n",
    );
    let (_, p) = run(&[path_str(&text), "--schemes", "rk4", "--methods", "none", "--h", "0.02,0.01"]);
    assert_eq!(p["reference"]["kind"], "rk4");
}

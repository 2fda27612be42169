//! `cdyn bench --light`: the report has every figure, and the properties
//! that do not depend on the machine hold (no allocation per step, small
//! violations). Timings are not asserted.

use serde_json::Value;
use std::process::Command;

#[test]
fn light_bench_writes_a_complete_report() {
    let dir = tempfile::tempdir().unwrap();
    let out =
        Command::new(env!("CARGO_BIN_EXE_cdyn")).args(["bench", "--light", "--out"]).arg(dir.path()).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let r: Value = serde_json::from_str(&std::fs::read_to_string(dir.path().join("bench.json")).unwrap()).unwrap();
    assert_eq!(r["schema_version"].as_u64(), Some(3));
    assert_eq!(r["realtime"]["step_times"].as_array().unwrap().len(), 6);
    let e = &r["example1"];
    for key in ["cdyn_ns_per_step", "general_ns_per_step", "handwritten_ns_per_step", "overhead_ratio"] {
        assert!(e[key].as_f64().unwrap() > 0.0, "{key}");
    }
    assert_eq!(e["allocations_per_step"].as_f64(), Some(0.0));
    let chain = r["chain"].as_array().unwrap();
    assert_eq!(chain.iter().map(|c| c["n"].as_u64().unwrap()).collect::<Vec<_>>(), [10, 100, 1000]);
    for c in chain {
        assert!(c["max_abs_phi"].as_f64().unwrap() < 1e-8, "{c}");
        assert_eq!(c["allocations_per_step"].as_f64(), Some(0.0), "{c}");
    }
    assert!(r["chain_cost_exponent"].as_f64().is_some());
    let spatial = r["spatial_chain"].as_array().unwrap();
    assert_eq!(spatial.iter().map(|c| c["n"].as_u64().unwrap()).collect::<Vec<_>>(), [10, 100]);
    for c in spatial {
        assert!(c["max_abs_phi"].as_f64().unwrap() < 1e-8, "{c}");
        assert_eq!(c["allocations_per_step"].as_f64(), Some(0.0), "{c}");
    }
    // The other schemes on the chain: ABM-4 with the chain's control within
    // AB-3's bound; generalized-α's Newton at the positions' round-off and
    // RATTLE at its 256 ε, both × up to 1 000 m.
    for (scheme, phi) in [("abm4", 1e-8), ("rattle", 6e-11), ("generalized_alpha", 1e-9)] {
        let runs = r[format!("{scheme}_chain")].as_array().unwrap();
        assert_eq!(runs.iter().map(|c| c["n"].as_u64().unwrap()).collect::<Vec<_>>(), [10, 100, 1000], "{scheme}");
        for c in runs {
            assert!(c["max_abs_phi"].as_f64().unwrap() < phi, "{scheme}: {c}");
            assert_eq!(c["allocations_per_step"].as_f64(), Some(0.0), "{scheme}: {c}");
        }
    }
    // Every scheme's planar chain series has its cost exponent (its value
    // is a timing, not asserted; the light spatial series has one size ≥ 100).
    for key in ["", "abm4_", "rattle_", "generalized_alpha_"] {
        let exponent = r[format!("{key}chain_cost_exponent")].as_f64();
        assert!(exponent.is_some_and(f64::is_finite), "{key}chain_cost_exponent = {exponent:?}");
    }
    let flyball = r["flyball"].as_array().unwrap();
    let runs: Vec<_> = flyball.iter().map(|f| (f["scheme"].as_str().unwrap(), f["h"].as_f64().unwrap())).collect();
    assert_eq!(runs, [("rk4", 5e-5), ("rk4", 2.5e-4), ("abm4", 1e-4), ("rattle", 1e-4), ("generalized_alpha", 1e-3)]);
    for f in flyball {
        assert!(f["ms_per_simulated_second"].as_f64().unwrap() > 0.0, "{f}");
        assert_eq!(f["allocations_per_step"].as_f64(), Some(0.0), "{f}");
    }
    let against_hand = r["spatial_handwritten"].as_array().unwrap();
    assert_eq!(against_hand.iter().map(|c| c["n"].as_u64().unwrap()).collect::<Vec<_>>(), [10, 100]);
    for c in against_hand {
        for key in ["cdyn_us_per_step", "handwritten_us_per_step", "overhead_ratio"] {
            assert!(c[key].as_f64().unwrap() > 0.0, "{key}: {c}");
        }
    }
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(table.contains("overhead") && table.contains("hand µs"), "{table}");
    for title in ["CVSGF + energy, ABM-4", "RATTLE, no control", "generalized-α, no control"] {
        assert!(table.contains(&format!("N-link chain, {title}, h = 1e-3")), "{title}: {table}");
    }
}

/// The methods' comparison: every model and method, ratios to
/// `cvsgf_energy` taken within a trial (so its own is exactly 1), the
/// projection's, RATTLE's and generalized-α's iterations counted and their violations
/// within their tolerances.
#[test]
fn light_bench_compares_robust_projection_and_rattle_with_cvsgf_energy() {
    let dir = tempfile::tempdir().unwrap();
    let out =
        Command::new(env!("CARGO_BIN_EXE_cdyn")).args(["bench", "--light", "--out"]).arg(dir.path()).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let r: Value = serde_json::from_str(&std::fs::read_to_string(dir.path().join("bench.json")).unwrap()).unwrap();
    let comparisons = r["methods"].as_array().unwrap();
    let models: Vec<_> = comparisons.iter().map(|m| (m["model"].as_str().unwrap(), m["n"].as_u64().unwrap())).collect();
    assert_eq!(models, [("example1", 1), ("chain", 10), ("chain", 100), ("chain", 1000)]);
    for m in comparisons {
        let methods = m["methods"].as_array().unwrap();
        let names: Vec<_> = methods.iter().map(|c| c["method"].as_str().unwrap()).collect();
        assert_eq!(names, ["cvsgf_energy", "robust", "projection", "rattle", "generalized_alpha"], "{m}");
        assert_eq!(methods[0]["ratio_to_cvsgf_energy"].as_f64(), Some(1.0), "{m}");
        for c in methods {
            assert!(c["us_per_step"].as_f64().unwrap() > 0.0, "{c}");
            assert!(c["ratio_to_cvsgf_energy"].as_f64().unwrap() > 0.0, "{c}");
            assert_eq!(c["allocations_per_step"].as_f64(), Some(0.0), "{c}");
            let iterations = c["iterations_per_step"].as_f64();
            if c["method"] == "projection" {
                assert!(iterations.unwrap() >= 0.0, "{c}");
                // The default tolerance of the projection, met after every step.
                assert!(c["max_abs_phi"].as_f64().unwrap() <= 1e-10, "{c}");
            } else if c["method"] == "rattle" {
                // Counted; it may be below one: the light runs start at rest,
                // where the drift of the first steps already meets the tolerance.
                assert!(iterations.unwrap() >= 0.0, "{c}");
                // 256 ε × the largest coordinate (up to 1 000 on the chain).
                assert!(c["max_abs_phi"].as_f64().unwrap() <= 6e-11, "{c}");
            } else if c["method"] == "generalized_alpha" {
                // At least one Newton correction a step.
                assert!(iterations.unwrap() >= 1.0, "{c}");
                assert!(c["max_abs_phi"].as_f64().unwrap() < 1e-9, "{c}");
            } else {
                assert_eq!(iterations, None, "{c}");
            }
        }
        if m["model"] == "chain" {
            assert!(methods.iter().all(|c| c["max_abs_phi"].as_f64().unwrap() < 1e-8), "{m}");
        }
    }
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(table.contains("robust") && table.contains("projection") && table.contains("rattle"), "{table}");
    assert!(table.contains("generalized_alpha") && table.contains("flyball"), "{table}");
    assert!(table.contains("iter/step"), "{table}");
}

/// `cdyn bench --realtime --light`: every step timed on its own, by the
/// wall clock and the thread's CPU clock, for an empty step, the chain at
/// N = 10, 100, 1000, the flyball and a rod falling onto a joint limit, a
/// co-simulation step beside a bare one; no step allocates, co-simulation's
/// included (a changed input restarts the scheme without allocating), but
/// for the impact's, which builds the model holding the stop. Timings are
/// not asserted.
#[test]
fn light_realtime_bench_times_every_step_and_allocates_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_cdyn"))
        .args(["bench", "--realtime", "--light", "--out"])
        .arg(dir.path())
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let r: Value = serde_json::from_str(&std::fs::read_to_string(dir.path().join("realtime.json")).unwrap()).unwrap();
    let runs: Vec<&Value> =
        r["step_times"].as_array().unwrap().iter().chain(r["cosimulation"].as_array().unwrap()).collect();
    let cases: Vec<&str> = runs.iter().map(|t| t["case"].as_str().unwrap()).collect();
    assert!(cases[0].starts_with("empty step"), "{cases:?}");
    assert!(
        cases[1].starts_with("chain N = 10,")
            && cases[3].starts_with("chain N = 1000,")
            && cases[4].starts_with("flyball")
            && cases[5].starts_with("limited pendulum")
    );
    for (k, t) in runs.into_iter().enumerate() {
        // The limited rod's run goes on past its impact, at step 336.
        let steps = if k == 5 { 1000 } else { 200 };
        for clock in ["wall", "cpu"] {
            let p = |key: &str| t[clock][key].as_f64().unwrap();
            assert!(0.0 <= p("median_us") && p("median_us") <= p("p999_us") && p("p999_us") <= p("max_us"), "{t}");
            assert!(t[clock]["slowest_step"].as_u64().unwrap() < steps, "{t}");
        }
        let allocations = t["allocations"].as_u64().unwrap();
        assert!(if k == 5 { allocations > 0 } else { allocations == 0 }, "{t}");
        assert_eq!(t["steps"].as_u64(), Some(steps));
    }
    assert!(r["cosimulation_ratio"].as_f64().unwrap() > 0.0);
}

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
    assert!(String::from_utf8_lossy(&out.stdout).contains("overhead"));
}

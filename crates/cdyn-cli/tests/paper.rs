//! `cdyn paper`: the files it writes, and the paper's claims checked on
//! its numbers.

use serde_json::Value;
use std::path::Path;
use std::process::Command;

fn run_paper(dir: &Path) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_cdyn")).args(["paper", "--out"]).arg(dir).output().unwrap()
}

fn case<'a>(summary: &'a Value, name: &str) -> &'a Value {
    summary["cases"].as_array().unwrap().iter().find(|c| c["name"] == name).unwrap_or_else(|| panic!("no case {name}"))
}

fn num(case: &Value, key: &str) -> f64 {
    case[key].as_f64().unwrap_or_else(|| panic!("{key} missing in {case}"))
}

#[test]
fn paper_writes_every_case_and_reproduces_the_claims() {
    let dir = tempfile::tempdir().unwrap();
    let out = run_paper(dir.path());
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let table = String::from_utf8(out.stdout).unwrap();

    let names = [
        "none",
        "baumgarte",
        "cvsgf",
        "energy",
        "baumgarte_energy",
        "cvsgf_energy",
        "cvsgf_energy_backward",
        "theta",
        "theta_energy",
    ];
    let summary: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("summary.json")).unwrap()).unwrap();
    for name in names {
        assert!(table.lines().any(|l| l.starts_with(&format!("{name} "))), "table lacks {name}:\n{table}");
        let c = case(&summary, name);
        assert_eq!(c["steps"], 2000);
        assert!(c["error"].is_null());
        let csv = std::fs::read_to_string(dir.path().join(format!("{name}.csv"))).unwrap();
        let mut lines = csv.lines();
        assert_eq!(lines.next(), Some("t,X,Y,VX,VY,phi,psi,err_x"));
        let rows: Vec<Vec<f64>> = lines.map(|l| l.split(',').map(|x| x.parse().unwrap()).collect()).collect();
        assert_eq!(rows.len(), 2001, "{name}: a row at every step, t = 0 included");
        assert!((rows[2000][0] - 20.0).abs() < 1e-12);
        // The summary is the CSV's own statistics.
        let max_phi = rows.iter().fold(0.0_f64, |a, r| a.max(r[5].abs()));
        let max_err = rows.iter().fold(0.0_f64, |a, r| a.max(r[7].abs()));
        assert_eq!(max_phi, num(c, "max_abs_phi"), "{name}");
        assert_eq!(max_err, num(c, "max_abs_err_x"), "{name}");
        assert_eq!(rows[2000][7], num(c, "err_x_final"), "{name}");
    }
    for fig in ["fig3_phi", "fig4_psi", "fig5_err_x"] {
        for ext in ["png", "svg"] {
            let len = std::fs::metadata(dir.path().join(format!("{fig}.{ext}"))).unwrap().len();
            assert!(len > 10_000, "{fig}.{ext} is only {len} bytes");
        }
    }

    // Claim 1: Baumgarte's geometric control alone leaves the largest energy
    // error of the controlled cases.
    let psi = |n| num(case(&summary, n), "max_abs_psi");
    for other in ["cvsgf", "energy", "baumgarte_energy", "cvsgf_energy", "cvsgf_energy_backward"] {
        assert!(psi("baumgarte") > psi(other), "max|Ψ|: baumgarte {} vs {other} {}", psi("baumgarte"), psi(other));
    }
    // Claim 2: geometric control without energy control worsens X against no control.
    let err = |n| num(case(&summary, n), "max_abs_err_x");
    for geometric in ["baumgarte", "cvsgf"] {
        assert!(err(geometric) > err("none"), "max|err_x|: {geometric} {} vs none {}", err(geometric), err("none"));
    }
    // Claim 3: CVSGF + energy (Eq. 51, forward Euler control) has the best X
    // error of the Cartesian cases, or is within a factor 2 of it.
    let best = names[..7].iter().map(|n| err(n)).fold(f64::INFINITY, f64::min);
    assert!(err("cvsgf_energy") <= 2.0 * best, "cvsgf_energy {} vs best {best}", err("cvsgf_energy"));
    // Claim 4: energy control helps in the independent coordinate θ too.
    assert!(err("theta_energy") < err("theta"));
    // Geometric control does keep Φ small: both controls beat no control by 10×.
    let phi = |n| num(case(&summary, n), "max_abs_phi");
    assert!(phi("baumgarte") * 10.0 < phi("none") && phi("cvsgf") * 10.0 < phi("none"));
}

//! What the suite writes and prints: suite.json, the table, the summary of the checks.

use super::*;
use anyhow::Result;
use cdyn::json_float::JsonFloat;
use serde_json::json;
use std::path::Path;

impl Group {
    /// `model scheme h=…`, how the summary names the group.
    pub fn label(&self) -> String {
        format!("{} {} h={}", self.model, self.scheme, self.h)
    }

    fn json(&self) -> serde_json::Value {
        let flags = |f: fn(&Verdict) -> bool| -> serde_json::Map<String, serde_json::Value> {
            CHECKS.iter().zip(&self.verdicts).map(|((k, _), v)| (k.to_string(), f(v).into())).collect()
        };
        let numbers: serde_json::Map<_, _> =
            CHECKS.iter().zip(&self.verdicts).map(|((k, _), v)| (k.to_string(), v.numbers.clone().into())).collect();
        json!({
            "model": self.model,
            "file": self.file,
            "scheme": self.scheme,
            "h": JsonFloat(self.h),
            "t_end": JsonFloat(self.t_end),
            "sample_interval": JsonFloat(self.sample_interval),
            "reference_h": JsonFloat(self.reference_h),
            "baseline": self.baseline,
            "free_motion": self.free_motion,
            "runs": self.runs,
            "checks": flags(|v| v.pass),
            "applies": flags(|v| v.applies),
            "compared": numbers,
        })
    }
}

impl Suite {
    /// For each check: groups where it applies, and where it passed among those.
    fn counts(&self) -> Vec<(usize, usize)> {
        (0..CHECKS.len())
            .map(|i| {
                let applies = self.groups.iter().filter(|g| g.verdicts[i].applies);
                (applies.clone().count(), applies.filter(|g| g.verdicts[i].pass).count())
            })
            .collect()
    }

    /// Every failed check: `model scheme h=… (a): numbers`.
    pub fn misses(&self) -> Vec<String> {
        let mut out = Vec::new();
        for g in &self.groups {
            for ((k, _), v) in CHECKS.iter().zip(&g.verdicts) {
                if !v.pass {
                    out.push(format!("{} ({k}): {}", g.label(), v.numbers));
                }
            }
        }
        out
    }

    /// `suite.json`: every run's numbers, the checks per group, and their counts.
    pub fn json(&self) -> serde_json::Value {
        let counts: serde_json::Map<_, _> = CHECKS
            .iter()
            .zip(self.counts())
            .map(|((k, text), (applies, pass))| {
                (k.to_string(), json!({ "check": text, "applies": applies, "pass": pass }))
            })
            .collect();
        json!({
            "light": self.light,
            "error_metric": "max over t = k*sample_interval of max_i |q_i - q_ref,i| (positions); inf if the run stopped",
            "reference": "the model without control, rk4, step reference_h = sample_interval / 20",
            "violations": "max over every step after t = 0; runs[].initial = [|phi|, |phi_dot|, |psi|] at t = 0",
            "cases": self.groups.iter().map(Group::json).collect::<Vec<_>>(),
            "summary": { "groups": self.groups.len(), "checks": counts, "misses": self.misses() },
        })
    }
}

/// Writes `dir/suite.json`, whole or not at all (the figure is
/// [`crate::render::suite_plot::write`]'s, which reads this module's types).
pub fn write(suite: &Suite, dir: &Path) -> Result<()> {
    let text = serde_json::to_string_pretty(&suite.json())? + "\n";
    crate::io::output::write(&dir.join("suite.json"), text.as_bytes())
}

/// A number for the table: scientific, `inf` or `-`.
fn num(x: f64) -> String {
    if x.is_nan() { "-".into() } else { format!("{x:.2e}") }
}

/// The table: a row per model, scheme, step and method; the checks under each group.
pub fn table(suite: &Suite) -> String {
    let mut out = format!(
        "{:<24} {:<4} {:>8} {:<22} {:>9} {:>9} {:>9} {:>9} {:>9}\n",
        "model", "", "h", "method", "max err", "/none", "/proj", "max|phi|", "max|psi|"
    );
    for g in &suite.groups {
        for r in &g.runs {
            out += &format!(
                "{:<24} {:<4} {:>8} {:<22} {:>9} {:>9} {:>9} {:>9} {:>9}{}\n",
                g.model,
                g.scheme,
                g.h,
                r.method,
                num(r.max_error),
                num(r.error_vs_none),
                num(r.error_vs_projection),
                num(r.max_abs_phi),
                num(r.max_abs_psi),
                r.error.as_ref().map_or(String::new(), |e| format!("  stopped: {e}")),
            );
        }
        let marks: Vec<String> = CHECKS
            .iter()
            .zip(&g.verdicts)
            .map(|((k, _), v)| {
                format!(
                    "{k} {}",
                    if !v.applies {
                        "n/a"
                    } else if v.pass {
                        "ok"
                    } else {
                        "MISS"
                    }
                )
            })
            .collect();
        out += &format!("{:<24} checks: {}\n\n", "", marks.join(", "));
    }
    out
}

/// How many groups pass each check, and the misses.
pub fn summary(suite: &Suite) -> String {
    let mut out = format!("checks over {} (model, scheme, h):\n", suite.groups.len());
    for ((k, text), (applies, pass)) in CHECKS.iter().zip(suite.counts()) {
        out += &format!("  {k}) {text}: {pass} of {applies} pass");
        if applies < suite.groups.len() {
            out += &format!(" ({} where it does not apply)", suite.groups.len() - applies);
        }
        out += "\n";
    }
    let misses = suite.misses();
    out += &format!("misses: {}\n", misses.len());
    for m in misses {
        out += &format!("  {m}\n");
    }
    out
}

//! What a set of cases leaves behind: `summary.json`, the figures, and a
//! table on the terminal.

use crate::case::runner::{Case, CaseResult, run_case, stiffness};
use crate::io::output;
use crate::render::plot::{self, Figure, Scale};
use crate::study::paper;
use anyhow::Result;
use cdyn::json_float::JsonFloat;
use serde_json::json;
use std::path::Path;

/// Runs `cases` into `dir` in turn; an interrupted case is the last.
pub fn run_cases(cases: &[Case], dir: &Path) -> Result<Vec<CaseResult>> {
    let mut results = Vec::new();
    let bar = crate::io::progress::bar(crate::case::runner::Estimate::steps(cases), "steps");
    for case in cases {
        let result = run_case(case, dir, &bar)?;
        let interrupted = result.interrupted;
        results.push(result);
        if interrupted {
            break;
        }
    }
    bar.finish_and_clear();
    Ok(results)
}

/// The files a run of `cases` writes into its directory (those of an earlier run are removed first).
pub fn file_names(cases: &[Case], stems: Stems) -> Vec<String> {
    let csv = cases.iter().map(|c| format!("{}.csv", c.name));
    let figures = stems.iter().flat_map(|s| ["png", "svg"].map(|ext| format!("{s}.{ext}")));
    // The viewer's files too: a run without --html leaves no page of an earlier run.
    let viewer = ["summary.json", crate::render::viewer::FILE, crate::render::viewer::GIF].map(String::from);
    let view3d = ["png", "svg"].map(|ext| format!("{}.{ext}", crate::render::view3d::STEM));
    csv.chain(figures).chain(viewer).chain(view3d).collect()
}

/// Writes `dir/summary.json` with every case; `interrupted` says whether a
/// signal stopped the run, and `interrupted_at` where (case, step, time).
pub fn write_summary(dir: &Path, cases: &[CaseResult], extra: serde_json::Value) -> Result<()> {
    let mut doc = json!({ "cases": cases, "interrupted": cases.iter().any(|c| c.interrupted) });
    if let Some(c) = cases.iter().find(|c| c.interrupted) {
        doc["interrupted_at"] = json!({ "case": c.name, "step": c.record.steps, "t": JsonFloat(c.record.t_final) });
    }
    if let (Some(doc), serde_json::Value::Object(extra)) = (doc.as_object_mut(), extra) {
        doc.extend(extra);
    }
    output::write(&dir.join("summary.json"), (serde_json::to_string_pretty(&doc)? + "\n").as_bytes())
}

/// Which time history a figure shows.
#[derive(Clone, Copy)]
pub enum Quantity {
    /// The constraint violation `Φ`.
    Phi,
    /// The energy violation `Ψ`.
    Psi,
    /// The error against the reference.
    Err,
}

/// Writes one figure (PNG and SVG) of a quantity for every case that has it.
pub fn write_figure(dir: &Path, stem: &str, title: &str, quantity: Quantity, cases: &[CaseResult]) -> Result<()> {
    let series: Vec<plot::Series> = cases
        .iter()
        .filter_map(|c| {
            let s = c.series();
            let y = match quantity {
                Quantity::Phi => &s.phi,
                Quantity::Psi => &s.psi,
                Quantity::Err => &s.error,
            };
            let points: Vec<(f64, f64)> = s.t.iter().copied().zip(y.iter().copied()).collect();
            (points.iter().any(|p| p.1 != 0.0)).then(|| plot::Series { label: c.name.clone(), points })
        })
        .collect();
    let y_label = match quantity {
        Quantity::Phi => "Φ (largest constraint violation)",
        Quantity::Psi => "Ψ (energy constraint violation)",
        Quantity::Err => "error of the first observable against the reference",
    };
    plot::write_figure(&dir.join(stem), &Figure { title, x_label: "t", y_label, scale: Scale::LogAbs, series: &series })
}

/// File stems of the three figures (Φ, Ψ, error).
pub type Stems = [&'static str; 3];
/// The paper's Figs. 3–5.
pub const PAPER_FIGURES: Stems = ["fig3_phi", "fig4_psi", "fig5_err_x"];
/// Figures of `run` and `compare`.
pub const RUN_FIGURES: Stems = ["phi", "psi", "err"];

/// The violation and error figures for these cases.
pub fn write_figures(dir: &Path, title: &str, cases: &[CaseResult], stems: Stems) -> Result<()> {
    write_figure(dir, stems[0], &format!("{title}: geometric constraint violation"), Quantity::Phi, cases)?;
    write_figure(dir, stems[1], &format!("{title}: energy constraint violation"), Quantity::Psi, cases)?;
    if let Some(c) = cases.iter().find(|c| !c.series().error.is_empty()) {
        write_figure(dir, stems[2], &format!("{title}: error in {}", c.error_observable), Quantity::Err, cases)?;
    }
    Ok(())
}

/// A fixed-width table of the cases, one line each.
pub fn table(cases: &[CaseResult]) -> String {
    let opt = |x: Option<f64>| x.map_or("-".to_string(), |x| format!("{x:.3e}"));
    let mut out = format!(
        "{:<24} {:>11} {:>11} {:>11} {:>11} {:>7} {:>9}\n",
        "case", "max|phi|", "max|psi|", "max|err_x|", "err_x(end)", "steps", "rhs_evals"
    );
    for c in cases {
        out += &format!(
            "{:<24} {:>11.3e} {:>11.3e} {:>11} {:>11} {:>7} {:>9}{}\n",
            c.name,
            c.record.max_abs_phi,
            c.record.max_abs_psi,
            opt(c.record.max_abs_error),
            opt(c.record.final_error),
            c.record.steps,
            c.record.evaluations,
            c.error.as_ref().map_or(String::new(), |e| format!("  FAILED: {e}")),
        );
    }
    out += &momenta_lines(cases);
    out += &stiff_lines(cases);
    for c in cases {
        if let Some(t) = c.tuning.filter(|t| t.energy_left_out) {
            let projected = c.control.is_some_and(|c| c.projection.is_some());
            out += &format!(
                "note: {}: {} left out, the damping is stiff against the step (h λ_d = {:.3}, above {})\n",
                c.name,
                if projected { "the projection of Ψ" } else { "energy term" },
                t.dissipation_h,
                cdyn::control::gains::STIFF_DISSIPATION_H
            );
        }
    }
    out
}

/// For a case of an explicit scheme (or RATTLE) whose damping or springs
/// are stiff against its step — `h λ_d` beyond half the scheme's real
/// stability interval, or `h ω` beyond half its interval on the imaginary
/// axis — what to do: generalized-α, which has no such limit, or the
/// explicit step that would be stable. The one nearer its limit is named.
pub fn stiff_hint(c: &CaseResult) -> Option<String> {
    let s = stiffness::stiffest(cdyn::Scheme::from_name(c.scheme)?, c.h, &c.tuning?)?;
    Some(format!(
        "{} {} stiff against the step ({} = {:.3}; {}'s {} is {:.3}): scheme = \"generalized_alpha\" has no such limit, or {} needs h ≤ {:.2e}",
        s.what, s.verb, s.figure, s.value, c.scheme, s.kind, s.limit, c.scheme, s.h_max
    ))
}

/// A note for each case with a [`stiff_hint`].
fn stiff_lines(cases: &[CaseResult]) -> String {
    cases.iter().filter_map(|c| stiff_hint(c).map(|hint| format!("note: {}: {hint}\n", c.name))).collect()
}

/// What the momenta did: the ones the system keeps (from the first case
/// that has any), a note for each case that lost one which the scheme keeps
/// to round-off, and a warning for each declared one the model breaks.
fn momenta_lines(cases: &[CaseResult]) -> String {
    let mut out = String::new();
    if let Some(c) = cases.iter().find(|c| c.record.momenta.iter().any(|m| m.kept)) {
        let kept: Vec<&str> = c.record.momenta.iter().filter(|m| m.kept).map(|m| m.name.as_str()).collect();
        out += &format!("keeps: {}\n", kept.join(", "));
    }
    for c in cases {
        for m in &c.record.momenta {
            if !m.kept {
                out += &format!(
                    "warning: {}: the declared {} is not kept by the model ({} breaks it), so it is not held: it drifted by {:.3e}\n",
                    c.name,
                    m.name,
                    m.reason.as_deref().unwrap_or("something"),
                    m.max_drift
                );
            } else if m.linear && m.max_drift > cdyn::dynamics::momentum::ROUND_OFF * m.scale {
                out += &format!(
                    "note: {}: {} drifted by {:.3e}, above round-off ({:.1e} of its scale {:.3e})\n",
                    c.name,
                    m.name,
                    m.max_drift,
                    cdyn::dynamics::momentum::ROUND_OFF,
                    m.scale
                );
            }
        }
    }
    out
}

/// The assembly report as JSON (infinities and NaN as strings, as everywhere).
pub fn assembly_json(a: &cdyn::dynamics::assemble::Assembly) -> serde_json::Value {
    json!({
        "newton_iterations": a.newton_iterations,
        "max_abs_phi_before": JsonFloat(a.phi_before),
        "max_abs_phi_after": JsonFloat(a.phi_after),
        "max_abs_phi_dot_before": JsonFloat(a.phi_dot_before),
        "max_abs_phi_dot_after": JsonFloat(a.phi_dot_after),
        "max_abs_dq": JsonFloat(a.max_dq),
        "max_abs_dv": JsonFloat(a.max_dv),
    })
}

/// One line saying what the assembly did.
pub fn assembly_line(a: &cdyn::dynamics::assemble::Assembly) -> String {
    format!(
        "assembly: {} Newton iterations, max |Φ| {:.2e} → {:.2e}, max |Φ̇| {:.2e} → {:.2e}, max |Δq| = {:.2e}, max |Δv| = {:.2e}",
        a.newton_iterations, a.phi_before, a.phi_after, a.phi_dot_before, a.phi_dot_after, a.max_dq, a.max_dv
    )
}

/// `cdyn compare`: runs the cases ([`crate::study::compare::cases`]) into `dir` (until one is interrupted) with the summary, figures and gains used.
pub fn compare(cases: &[Case], path: &Path, dir: &Path) -> Result<Vec<CaseResult>> {
    let results = run_cases(cases, dir)?;
    let methods: Vec<_> =
        cases.iter().map(|c| json!({ "name": c.name, "control": format!("{:?}", c.settings.control) })).collect();
    let extra = json!({
        "scenario": path.display().to_string(),
        "methods": methods,
        "assembly": cases.first().and_then(|c| c.assembly.as_ref()).map(assembly_json),
    });
    write_summary(dir, &results, extra)?;
    let stem = path.file_stem().map_or("compare".into(), |s| s.to_string_lossy().into_owned());
    write_figures(dir, &stem, &results, RUN_FIGURES)?;
    Ok(results)
}

/// `cdyn paper`: runs `cases` (the paper's, from [`crate::study::paper::cases`]) into `dir` until one is interrupted, writes the summary and figures, and returns
/// the results (failed cases carry their error).
pub fn paper(cases: &[Case], dir: &Path) -> Result<Vec<CaseResult>> {
    let results = run_cases(cases, dir)?;
    let setup = json!({
        "problem": "Example 1: unit pendulum in Cartesian coordinates, X(0)=1, Y(0)=0, VX(0)=0, VY(0)=2, g=1",
        "scheme": "ab3 (rk4 start-up)", "h": paper::H, "t_end": paper::T_END,
        "gains": { "zeta": 20.0, "alpha_e": 40.0, "rho_q": 0.0, "baumgarte_alpha": 2.0 * 40f64.sqrt(), "baumgarte_beta": 40.0 },
    });
    write_summary(dir, &results, json!({ "setup": setup }))?;
    write_figures(dir, "Example 1 [AB-3, h = 0.01]", &results, PAPER_FIGURES)?;
    Ok(results)
}

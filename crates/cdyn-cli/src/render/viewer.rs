//! `report.html`: one self-contained page (script, style and data inline,
//! nothing fetched) showing a run — the mechanism animated from its frames
//! with play/pause, speed and a time slider (a spatial one in 3-D, with
//! orbit and zoom: `viewer3d.js`), the Φ, Ψ and error plots with
//! a cursor on the same time, the summary table and the method and gains.

use crate::case::frames::Frames;
use crate::case::runner::{Case, CaseResult};
use crate::io::output;
use crate::render::scene3d::Scene;
use anyhow::{Context, Result};
use serde_json::{Value, json};
use std::path::Path;

/// The viewer's options of `run` and `compare`.
#[derive(clap::Args, Clone, Copy)]
pub struct ViewerArgs {
    /// Also write report.html: the mechanism animated, the plots and the summary, in one self-contained page.
    #[arg(long)]
    pub html: bool,
    /// Also write animation.gif: the mechanism's motion (the first case), for slides and READMEs.
    #[arg(long)]
    pub gif: bool,
}

impl ViewerArgs {
    /// Before anything runs: refuses `--gif` for a model without a drawing
    /// (planar) or sketch (spatial),
    /// and drops the drawings when neither option is given, so that no
    /// frames are kept for nothing.
    pub fn prepare(self, cases: &mut [Case]) -> Result<()> {
        if self.gif && cases.iter().all(|c| c.example.drawing.is_none() && c.example.sketch.is_none()) {
            anyhow::bail!(
                "--gif: this model has no drawing (models in independent angles have none; their Cartesian twins do)"
            );
        }
        if !self.html && !self.gif {
            for case in cases {
                case.example.drawing = None;
            }
        }
        Ok(())
    }

    /// Writes what was asked for into `dir`, after its `summary.json`.
    pub fn write(self, dir: &Path, title: &str, cases: &[Case], results: &[CaseResult]) -> Result<()> {
        if self.html {
            write_html(dir, title, cases, results)?;
        }
        if self.gif {
            let path = dir.join(GIF);
            if let Some((case, r)) = cases.iter().zip(results).find(|(_, r)| !r.frames.is_empty()) {
                if let Some(drawing) = &case.example.drawing {
                    crate::render::gif::write(&path, drawing, &r.frames)?;
                } else if let Some(sketch) = &case.example.sketch {
                    crate::render::gif3d::write(&path, sketch, &r.frames)?;
                }
            }
        }
        Ok(())
    }
}

/// The page; `/*CDYN_DATA*/null` is replaced by the data, `/*CDYN_3D*/` by the 3-D renderer.
const TEMPLATE: &str = include_str!("viewer.html");
const DATA_SLOT: &str = "/*CDYN_DATA*/null";
const RENDERER_3D: &str = include_str!("viewer3d.js");
const RENDERER_3D_SLOT: &str = "/*CDYN_3D*/";

/// Most points per plotted line: about one per pixel of the page's plots.
const PLOT_POINTS: usize = 1000;

/// The name of the page in a run's directory.
pub const FILE: &str = "report.html";
/// The name of the animation in a run's directory.
pub const GIF: &str = "animation.gif";

/// Writes `dir/report.html` for the `results` of `cases` (in the same
/// order), after `dir/summary.json`: `title` heads the page, and what the
/// summary says besides the cases (scenario, methods, assembly) is shown too.
pub fn write_html(dir: &Path, title: &str, cases: &[Case], results: &[CaseResult]) -> Result<()> {
    let path = dir.join("summary.json");
    let text = std::fs::read_to_string(&path).with_context(|| format!("cannot read {}", path.display()))?;
    let mut info: Value = serde_json::from_str(&text).with_context(|| format!("{}: not JSON", path.display()))?;
    if let Some(doc) = info.as_object_mut() {
        doc.remove("cases");
    }
    output::write(&dir.join(FILE), page(title, cases, results, &info)?.as_bytes())
}

/// The page's text.
pub fn page(title: &str, cases: &[Case], results: &[CaseResult], info: &Value) -> Result<String> {
    let drawing = cases.iter().find_map(|c| c.example.drawing.as_ref());
    let sketch = cases.iter().find_map(|c| c.example.sketch.as_ref()).map(|sketch| {
        let frames: Vec<&Frames> = results.iter().map(|r| &r.frames).collect();
        Scene::of(sketch, &frames).json(sketch)
    });
    let runs = cases.iter().zip(results).map(|(case, result)| run(case, result)).collect::<Result<Vec<_>>>()?;
    let data = json!({
        "title": title,
        "version": env!("CARGO_PKG_VERSION"),
        "drawing": drawing,
        "sketch": sketch,
        "cases": runs,
        "info": info,
    });
    debug_assert!(TEMPLATE.contains(DATA_SLOT) && TEMPLATE.contains(RENDERER_3D_SLOT));
    Ok(TEMPLATE.replacen(RENDERER_3D_SLOT, RENDERER_3D, 1).replacen(DATA_SLOT, &inline_json(&data)?, 1))
}

/// `value` as JSON that can stand inside a `<script>` element: no `<` at
/// all (`</script>` or `<!--` in a name or path would end or change the
/// element), `\u003c` instead, which JSON reads as the same string. A `<`
/// can only be inside a string, where the escape is valid.
fn inline_json(value: &Value) -> Result<String> {
    Ok(serde_json::to_string(value)?.replace('<', "\\u003c"))
}

/// One case's data: its summary entry, frames and plotted series, and how they were sampled.
fn run(case: &Case, result: &CaseResult) -> Result<Value> {
    let f = &result.frames;
    let frames: Vec<&[f64]> = (0..f.len()).map(|i| f.q(i)).collect();
    let s = result.series();
    let group = s.t.len().div_ceil(PLOT_POINTS).max(1);
    let plot = |y: &[f64]| envelope(y, group);
    Ok(json!({
        "name": result.name,
        "summary": serde_json::to_value(result)?,
        "every": case.every,
        "frames": { "t": f.t, "q": frames, "stride": f.stride, "samples": f.samples },
        "series": {
            "t": s.t.iter().step_by(group).collect::<Vec<_>>(),
            "phi": plot(&s.phi),
            "psi": plot(&s.psi),
            "error": plot(&s.error),
            "group": group,
            "entries": s.t.len(),
        },
    }))
}

/// The largest magnitude in each group of `group` consecutive values, with
/// its sign (NaN, written `null`, where a group has none): on the page's
/// logarithmic plots a spike stays visible however many samples are merged.
fn envelope(y: &[f64], group: usize) -> Vec<f64> {
    y.chunks(group.max(1))
        .map(|c| {
            c.iter().copied().filter(|v| !v.is_nan()).fold(f64::NAN, |m, v| if m.abs() >= v.abs() { m } else { v })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inline_json_has_no_tag_and_reads_back() {
        let value = json!({ "scenario": "a</script><!--b.toml", "x": [1.5, -2e-300] });
        let text = inline_json(&value).unwrap();
        assert!(!text.contains('<'), "{text}");
        assert_eq!(serde_json::from_str::<Value>(&text).unwrap(), value);
    }

    #[test]
    fn envelope_keeps_the_largest_magnitude_of_each_group() {
        let y = [1.0, -5.0, 2.0, f64::NAN, f64::NAN, f64::NAN, 0.5];
        let e = envelope(&y, 2);
        assert_eq!(e[..2], [-5.0, 2.0]);
        assert!(e[2].is_nan());
        assert_eq!(e[3..], [0.5]);
        assert_eq!(envelope(&y, 3).len(), 3);
    }
}

//! The suite's figure, `suite.png` (and `suite.svg`): a panel per model, a
//! row per method, and in each row the method's error relative to `none`
//! (dots) and to `projection` (squares) on a log axis, one colour per
//! scheme and step. A run that stopped is a cross at the right edge.

use crate::render::plot::write_drawing;
use crate::study::suite::{Group, Suite};
use anyhow::{Result, anyhow};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

const FONT: &str = "sans-serif";
const PANEL: (u32, u32) = (640, 430);
const COLUMNS: usize = 3;
/// Room above the panels for the title and below them for the legend.
const TITLE: u32 = 50;
const LEGEND: u32 = 90;

/// Writes `dir/suite.png` and `dir/suite.svg`, each under a temporary name
/// first, so a failure leaves no half-drawn figure.
pub fn write(suite: &Suite, dir: &Path) -> Result<()> {
    let models = panels(&suite.groups);
    let rows = models.len().div_ceil(COLUMNS).max(1);
    let size = (PANEL.0 * COLUMNS.min(models.len()).max(1) as u32, TITLE + PANEL.1 * rows as u32 + LEGEND);
    write_drawing(&dir.join("suite"), size, |area| draw(area, &models), |area| draw(area, &models))
}

/// The groups of each model, models in the order they ran.
fn panels(groups: &[Group]) -> Vec<Vec<&Group>> {
    let mut out: Vec<Vec<&Group>> = Vec::new();
    for g in groups {
        match out.iter_mut().find(|p| p[0].model == g.model) {
            Some(p) => p.push(g),
            None => out.push(vec![g]),
        }
    }
    out
}

fn de<E: std::error::Error + Send + Sync>(e: DrawingAreaErrorKind<E>) -> anyhow::Error {
    anyhow!("{e}")
}

/// The colour of the `i`-th scheme and step of a model, in the suite's
/// order (AB-3, RK-4, ABM-4, RATTLE, generalized-α, each at `h` and `h/2`).
fn colour(i: usize) -> RGBAColor {
    Palette99::pick([0, 4, 3, 5, 2, 6, 1, 8, 7, 9][i % 10]).to_rgba()
}

/// A panel's point for `ratio`: its log10, or `None` where there is nothing to draw (no
/// baseline), or `Some(inf)` where the run stopped.
fn log_ratio(ratio: f64) -> Option<f64> {
    match ratio {
        r if r.is_nan() || r <= 0.0 => None,
        r => Some(r.log10()),
    }
}

fn draw<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, models: &[Vec<&Group>]) -> Result<()>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE).map_err(de)?;
    let h = root.dim_in_pixel().1;
    let title = "cdyn suite: max state error of each method relative to none (dots) and to projection (squares)";
    root.draw(&Text::new(title, (20, 14), (FONT, 24))).map_err(de)?;
    let body = root.margin(TITLE, LEGEND, 0, 0);
    let areas = body.split_evenly((models.len().div_ceil(COLUMNS).max(1), COLUMNS.min(models.len()).max(1)));
    for (area, groups) in areas.iter().zip(models) {
        panel(area, groups)?;
    }
    legend(&root.margin(h - LEGEND, 0, 0, 0), models.first().map_or(&[][..], |g| &g[..]))?;
    root.present().map_err(de)
}

/// One model: a row per method, points per scheme and step.
fn panel<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, groups: &[&Group]) -> Result<()>
where
    DB::ErrorType: 'static,
{
    // Every method of the model, in the order of its fullest group (the
    // schemes that step the model run only some of them).
    let fullest = groups.iter().max_by_key(|g| g.runs.len()).expect("a model has groups");
    let methods: Vec<&str> = fullest.runs.iter().map(|r| r.method.as_str()).collect();
    let n = methods.len();
    let ratios = || groups.iter().flat_map(|g| g.runs.iter().flat_map(|r| [r.error_vs_none, r.error_vs_projection]));
    let logs: Vec<f64> = ratios().filter_map(log_ratio).filter(|x| x.is_finite()).collect();
    let lo = logs.iter().fold(0.0f64, |a, &b| a.min(b)).floor() - 0.5;
    let hi = logs.iter().fold(0.0f64, |a, &b| a.max(b)).ceil() + 0.5;
    let stopped = ratios().any(|r| r == f64::INFINITY);
    // A run that stopped is drawn in a column of its own, past the largest ratio.
    let (edge, right) = if stopped { (hi + 0.5, hi + 1.0) } else { (hi, hi) };
    let mut ch = ChartBuilder::on(area)
        .caption(&groups[0].model, (FONT, 22))
        .margin(12)
        .x_label_area_size(44)
        .y_label_area_size(180)
        .build_cartesian_2d(lo..right, 0.0..n as f64)
        .map_err(de)?;
    let name = |y: &f64| {
        let i = y.floor() as usize;
        match (y - y.floor() - 0.5).abs() < 1e-9 && i < n {
            true => methods[n - 1 - i].to_string(),
            false => String::new(),
        }
    };
    let decade = |x: &f64| match (x - x.round()).abs() < 1e-9 && *x <= hi {
        true if x.round() == 0.0 => "1".to_string(),
        true => format!("1e{}", x.round()),
        false => String::new(),
    };
    ch.configure_mesh()
        .disable_y_mesh()
        .y_labels(2 * n + 1)
        .y_label_formatter(&name)
        .x_labels(((right - lo) as usize + 1).min(12))
        .x_label_formatter(&decade)
        .x_desc("max error ratio")
        .label_style((FONT, 14))
        .axis_desc_style((FONT, 15))
        .light_line_style(TRANSPARENT)
        .bold_line_style(BLACK.mix(0.12))
        .draw()
        .map_err(de)?;
    ch.draw_series(std::iter::once(PathElement::new([(0.0, 0.0), (0.0, n as f64)], BLACK.mix(0.6)))).map_err(de)?;
    for (c, g) in groups.iter().enumerate() {
        let colour = colour(c);
        for r in &g.runs {
            let i = methods.iter().position(|m| *m == r.method).expect("a method of the fullest group");
            let y = (n - 1 - i) as f64 + 0.2 + 0.6 * c as f64 / groups.len().max(2).saturating_sub(1) as f64;
            for (k, ratio) in [r.error_vs_none, r.error_vs_projection].into_iter().enumerate() {
                let Some(x) = log_ratio(ratio) else { continue };
                if x.is_infinite() {
                    ch.draw_series(std::iter::once(Cross::new((edge, y), 5, colour.stroke_width(2)))).map_err(de)?;
                } else if k == 0 {
                    ch.draw_series(std::iter::once(Circle::new((x, y), 4, colour.filled()))).map_err(de)?;
                } else {
                    let square = EmptyElement::at((x, y)) + Rectangle::new([(-4, -4), (4, 4)], colour.stroke_width(2));
                    ch.draw_series(std::iter::once(square)).map_err(de)?;
                }
            }
        }
    }
    Ok(())
}

/// The colours (scheme and step, as divisors of each model's h) and the markers.
fn legend<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, groups: &[&Group]) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let font = TextStyle::from((FONT, 16)).pos(plotters::style::text_anchor::Pos::new(
        plotters::style::text_anchor::HPos::Left,
        plotters::style::text_anchor::VPos::Center,
    ));
    // The schemes and steps on one line, the markers on the next.
    let (mut x, y) = (20, 24);
    let coarse = groups.iter().map(|g| g.h).fold(0.0, f64::max);
    for (c, g) in groups.iter().enumerate() {
        let step = if g.h == coarse { "h".to_string() } else { format!("h/{}", (coarse / g.h).round()) };
        area.draw(&Circle::new((x, y), 5, colour(c).filled())).map_err(de)?;
        area.draw(&Text::new(format!("{}, {step}", g.scheme), (x + 12, y), font.clone())).map_err(de)?;
        x += 185;
    }
    let (mut x, y) = (20, 60);
    let marks = ["dots: error / none", "squares: error / projection", "crosses: the run stopped", "line: ratio 1"];
    for m in marks {
        area.draw(&Text::new(m, (x, y), font.clone())).map_err(de)?;
        x += 250;
    }
    Ok(())
}

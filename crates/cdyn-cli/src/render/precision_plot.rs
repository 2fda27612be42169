//! Work-precision diagrams: `precision.png` (error against wall-clock
//! seconds per simulated second) and `precision_evaluations.png` (against
//! evaluations of the dynamics per simulated second), with their SVGs. Both
//! axes logarithmic, one line per scheme × method, a marker at every step;
//! a run that stopped leaves its point out. The reference's own error bound
//! is a grey dashed line: errors below it are not told apart.

use crate::render::plot::{FONT, de, legend_sample, style, write_drawing};
use crate::study::precision::{Point, Precision};
use anyhow::Result;
use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;

const SIZE: (u32, u32) = (1200, 800);
const LEGEND_WIDTH: u32 = 330;
/// Errors below this are drawn at it (plotters' log axis loses its ticks
/// near machine epsilon).
const SMALLEST_ERROR: f64 = 1e-15;

/// What a diagram's x axis shows of a point.
type Cost = fn(&Point) -> f64;

/// Writes both diagrams into `dir`.
pub fn write(p: &Precision, dir: &Path) -> Result<()> {
    let figures: [(&str, &str, Cost); 2] = [
        ("precision", "wall-clock seconds per simulated second", |pt| pt.wall_per_second),
        ("precision_evaluations", "evaluations of the dynamics per simulated second", |pt| pt.evaluations_per_second),
    ];
    for (stem, x_label, cost) in figures {
        write_drawing(&dir.join(stem), SIZE, |area| draw(area, p, x_label, cost), |area| draw(area, p, x_label, cost))?;
    }
    Ok(())
}

/// The drawn points of each line: `(cost, error)` of its finished runs.
fn points(p: &Precision, cost: Cost) -> Vec<Vec<(f64, f64)>> {
    p.lines
        .iter()
        .map(|l| {
            l.points
                .iter()
                .filter(|pt| pt.max_error.is_finite() && cost(pt) > 0.0 && cost(pt).is_finite())
                .map(|pt| (cost(pt), pt.max_error.max(SMALLEST_ERROR)))
                .collect()
        })
        .collect()
}

/// Whole decades around `values`.
fn decades(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
    if lo > hi {
        return (1e-3, 1.0);
    }
    let (lo, hi) = (lo.log10().floor(), hi.log10().ceil());
    (10f64.powf(lo), 10f64.powf(hi.max(lo + 1.0)))
}

fn draw<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, p: &Precision, x_label: &str, cost: Cost) -> Result<()> {
    root.fill(&WHITE).map_err(de)?;
    let title = format!("{}: error against cost, t_end = {}", p.scenario, p.t_end);
    let root = root.margin(12, 0, 0, 0).titled(&title, (FONT, 26)).map_err(de)?;
    let (plot, legend) = root.split_horizontally(root.dim_in_pixel().0 - LEGEND_WIDTH);
    let lines = points(p, cost);
    let floor = p.reference.error_bound;
    let x = decades(lines.iter().flatten().map(|pt| pt.0));
    let y = decades(lines.iter().flatten().map(|pt| pt.1).chain((floor > 0.0).then_some(floor.max(SMALLEST_ERROR))));
    let mut chart = ChartBuilder::on(&plot)
        .margin(20)
        .x_label_area_size(60)
        .y_label_area_size(90)
        .build_cartesian_2d((x.0..x.1).log_scale(), (y.0..y.1).log_scale())
        .map_err(de)?;
    let sci = |v: &f64| format!("{v:.0e}");
    chart
        .configure_mesh()
        .x_desc(x_label)
        .y_desc("largest |q − q_ref| over the samples")
        .x_label_formatter(&sci)
        .y_label_formatter(&sci)
        .label_style((FONT, 18))
        .axis_desc_style((FONT, 20))
        .bold_line_style(BLACK.mix(0.15))
        .light_line_style(BLACK.mix(0.04))
        .draw()
        .map_err(de)?;
    if floor > 0.0 {
        let grey = BLACK.mix(0.5).stroke_width(2);
        chart.draw_series(DashedLineSeries::new([(x.0, floor), (x.1, floor)], 10, 6, grey)).map_err(de)?;
    }
    for (i, line) in lines.iter().enumerate() {
        let (st, dash) = style(i);
        match dash {
            None => chart.draw_series(LineSeries::new(line.iter().copied(), st)),
            Some((a, b)) => chart.draw_series(DashedLineSeries::new(line.iter().copied(), a, b, st)),
        }
        .map_err(de)?;
        chart.draw_series(line.iter().map(|&pt| Circle::new(pt, 4, st.color.filled()))).map_err(de)?;
    }
    let font = TextStyle::from((FONT, 16)).pos(Pos::new(HPos::Left, VPos::Center));
    let row = 22;
    for (i, l) in p.lines.iter().enumerate() {
        let at = 40 + row * i as i32;
        legend_sample(&legend, i, (10, at))?;
        let stopped = l.points.iter().filter(|pt| !pt.max_error.is_finite()).count();
        let note = if stopped > 0 { format!(" ({stopped} stopped)") } else { String::new() };
        legend.draw(&Text::new(format!("{} {}{note}", l.scheme, l.method), (58, at), font.clone())).map_err(de)?;
    }
    if floor > 0.0 {
        let at = 40 + row * p.lines.len() as i32;
        legend
            .draw(&DashedPathElement::new([(10, at), (50, at)], 10, 6, BLACK.mix(0.5).stroke_width(2)))
            .map_err(de)?;
        legend.draw(&Text::new("reference's error bound", (58, at), font)).map_err(de)?;
    }
    root.present().map_err(de)
}

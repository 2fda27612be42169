//! Heat maps of a sweep: one coloured cell per grid point of two axes, a
//! colour bar for the log scale, the value printed in the cell while cells
//! are large enough to hold it (grey where the run failed).

use crate::render::plot::write_drawing;
use crate::study::sweep::{Point, Sweep};
use anyhow::Result;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// A table of values over two axes; `z[iy][ix]`, `None` where the run failed.
pub struct HeatMap<'a> {
    /// Title above the map.
    pub title: &'a str,
    /// Label of the x axis.
    pub x_label: &'a str,
    /// The x axis values, one per column.
    pub x_values: &'a [f64],
    /// Label of the y axis.
    pub y_label: &'a str,
    /// The y axis values, one per row.
    pub y_values: &'a [f64],
    /// The values, `z[iy][ix]`.
    pub z: &'a [Vec<Option<f64>>],
}

/// Writes `<stem>.png` and `<stem>.svg`.
pub fn write_heatmap(stem: &Path, map: &HeatMap) -> Result<()> {
    write_drawing(stem, (1000, 800), |area| draw(area, map), |area| draw(area, map))
}

/// Pixels kept on the right for the colour bar and its labels.
const COLOUR_BAR_WIDTH: u32 = 150;

/// Cells narrower or lower than this many pixels do not get their value
/// printed: the text would overlap its neighbours (a 100 × 100 grid); the
/// colour bar reads them instead.
const MIN_LABELLED_CELL: usize = 24;

/// At most this many values labelled along an axis, so a long axis stays readable.
const MAX_AXIS_LABELS: usize = 20;

/// The label at `at` (a cell centre, `i + 0.5`) of an axis with `values`:
/// every cell's value on a short axis, every k-th on a long one.
fn axis_label(at: f64, values: &[f64], fmt: &dyn Fn(f64) -> String) -> String {
    let i = at.floor() as usize;
    let every = values.len().div_ceil(MAX_AXIS_LABELS).max(1);
    if (at - i as f64 - 0.5).abs() < 1e-9 && i < values.len() && i.is_multiple_of(every) {
        fmt(values[i])
    } else {
        String::new()
    }
}

/// The colour scale: log10 from `lo` to `hi`, labelled with the values.
fn colour_bar<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, lo: f64, hi: f64) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let mut bar = ChartBuilder::on(area)
        .margin_top(68)
        .margin_bottom(80)
        .margin_right(10)
        .y_label_area_size(90)
        .build_cartesian_2d(0.0..1.0, lo..hi)?;
    bar.configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_labels(8)
        .y_label_formatter(&|v| format!("{:.1e}", 10f64.powf(*v)))
        .label_style(("sans-serif", 16))
        .draw()?;
    const STEPS: usize = 100;
    let step = (hi - lo) / STEPS as f64;
    bar.draw_series((0..STEPS).map(|k| {
        let y = lo + k as f64 * step;
        Rectangle::new([(0.0, y), (1.0, y + step)], colour(k as f64 / (STEPS - 1) as f64).filled())
    }))?;
    Ok(())
}

/// Blue (small) to red (large) on log10 of the value.
fn colour(t: f64) -> RGBColor {
    let t = t.clamp(0.0, 1.0);
    RGBColor((40.0 + 215.0 * t) as u8, (90.0 + 80.0 * (1.0 - (2.0 * t - 1.0).abs())) as u8, (255.0 - 215.0 * t) as u8)
}

fn draw<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, map: &HeatMap) -> Result<()>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let (nx, ny) = (map.x_values.len(), map.y_values.len());
    let logs: Vec<f64> =
        map.z.iter().flatten().flatten().filter(|v| **v > 0.0 && v.is_finite()).map(|v| v.log10()).collect();
    let (lo, hi) = logs.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(*v), b.max(*v)));
    let span = if hi > lo { hi - lo } else { 1.0 };
    let (width, _) = root.dim_in_pixel();
    let (root, bar) = root.split_horizontally(width.saturating_sub(COLOUR_BAR_WIDTH));
    if lo.is_finite() {
        colour_bar(&bar, lo, lo + span)?;
    }
    let mut chart = ChartBuilder::on(&root)
        .caption(map.title, ("sans-serif", 28))
        .margin(20)
        .x_label_area_size(60)
        .y_label_area_size(90)
        .build_cartesian_2d(0.0..nx as f64, 0.0..ny as f64)?;
    let fmt = |v: f64| if v != 0.0 && (v.abs() < 1e-2 || v.abs() >= 1e4) { format!("{v:.3e}") } else { format!("{v}") };
    let (xs, ys) = (map.x_values.to_vec(), map.y_values.to_vec());
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc(map.x_label)
        .y_desc(map.y_label)
        .x_labels(nx * 2 + 1)
        .y_labels(ny * 2 + 1)
        .x_label_formatter(&|x| axis_label(*x, &xs, &fmt))
        .y_label_formatter(&|y| axis_label(*y, &ys, &fmt))
        .label_style(("sans-serif", 18))
        .axis_desc_style(("sans-serif", 20))
        .draw()?;
    let (cell_w, cell_h) = {
        let (w, h) = chart.plotting_area().dim_in_pixel();
        (w as usize / nx.max(1), h as usize / ny.max(1))
    };
    let labelled = cell_w >= MIN_LABELLED_CELL && cell_h >= MIN_LABELLED_CELL;
    for (iy, row) in map.z.iter().enumerate() {
        for (ix, value) in row.iter().enumerate() {
            let (x, y) = (ix as f64, iy as f64);
            let (fill, text) = match value {
                Some(v) if *v > 0.0 && v.is_finite() => (colour((v.log10() - lo) / span), format!("{v:.2e}")),
                Some(v) => (RGBColor(230, 230, 230), format!("{v:.2e}")),
                None => (RGBColor(160, 160, 160), "failed".to_string()),
            };
            chart.draw_series(std::iter::once(Rectangle::new([(x, y), (x + 1.0, y + 1.0)], fill.filled())))?;
            if !labelled {
                continue;
            }
            chart.draw_series(std::iter::once(Text::new(
                text,
                (x + 0.5, y + 0.5),
                ("sans-serif", 16).into_font().color(&BLACK).pos(plotters::style::text_anchor::Pos::new(
                    plotters::style::text_anchor::HPos::Center,
                    plotters::style::text_anchor::VPos::Center,
                )),
            )))?;
        }
    }
    root.present()?;
    Ok(())
}

/// A complete sweep's heat maps over its first two axes (the first alone
/// when there is one); each cell shows the best value over the remaining
/// axes. A shard draws none (its grid has holes).
pub fn sweep_maps(sweep: &Sweep, dir: &Path) -> Result<()> {
    if sweep.shard.is_some() {
        return Ok(());
    }
    let axes = &sweep.axes;
    let (x, y) = (&axes[0], axes.get(1));
    let ny = y.map_or(1, |a| a.values.len());
    let others: usize = axes.iter().skip(2).map(|a| a.values.len()).product();
    type Metric = fn(&Point) -> Option<f64>;
    let metrics: [(&str, &str, Metric); 3] = [
        ("heat_err", "max |error| against the reference", |p| p.max_abs_err),
        ("heat_phi", "max |Φ|", |p| Some(p.max_abs_phi)),
        ("heat_psi", "max |Ψ|", |p| Some(p.max_abs_psi)),
    ];
    for (stem, what, metric) in metrics {
        if sweep.points.iter().all(|p| metric(p).is_none()) {
            continue;
        }
        let mut z = vec![vec![None::<f64>; x.values.len()]; ny];
        for p in &sweep.points {
            let i = p.index / others;
            let (ix, iy) = match y {
                Some(a) => (i / a.values.len(), i % a.values.len()),
                None => (i, 0),
            };
            let v = if p.error.is_some() { None } else { metric(p) };
            if let Some(v) = v {
                let cell = &mut z[iy][ix];
                *cell = Some(cell.map_or(v, |c| c.min(v)));
            }
        }
        let title = format!("{what}{}", if others > 1 { " (best over the other axes)" } else { "" });
        let y_values = y.map_or(vec![0.0], |a| a.values.clone());
        write_heatmap(
            &dir.join(stem),
            &HeatMap {
                title: &title,
                x_label: &x.name,
                x_values: &x.values,
                y_label: y.map_or("", |a| a.name.as_str()),
                y_values: &y_values,
                z: &z,
            },
        )?;
    }
    Ok(())
}

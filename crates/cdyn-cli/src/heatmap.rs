//! Heat maps of a sweep: one coloured cell per grid point of two axes, the
//! value printed in the cell (log colour scale; grey where the run failed).

use crate::plot::{ensure_font, with_ext};
use anyhow::{Context, Result};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// A table of values over two axes; `z[iy][ix]`, `None` where the run failed.
pub struct HeatMap<'a> {
    pub title: &'a str,
    pub x_label: &'a str,
    pub x_values: &'a [f64],
    pub y_label: &'a str,
    pub y_values: &'a [f64],
    pub z: &'a [Vec<Option<f64>>],
}

/// Writes `<stem>.png` and `<stem>.svg`.
pub fn write_heatmap(stem: &Path, map: &HeatMap) -> Result<()> {
    ensure_font()?;
    let (png, svg) = (with_ext(stem, "png"), with_ext(stem, "svg"));
    draw(BitMapBackend::new(&png, (1000, 800)).into_drawing_area(), map)
        .with_context(|| format!("writing figure {}", png.display()))?;
    draw(SVGBackend::new(&svg, (1000, 800)).into_drawing_area(), map)
        .with_context(|| format!("writing figure {}", svg.display()))
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
        .x_label_formatter(&|x| {
            let i = x.floor() as usize;
            if (x - i as f64 - 0.5).abs() < 1e-9 && i < xs.len() { fmt(xs[i]) } else { String::new() }
        })
        .y_label_formatter(&|y| {
            let i = y.floor() as usize;
            if (y - i as f64 - 0.5).abs() < 1e-9 && i < ys.len() { fmt(ys[i]) } else { String::new() }
        })
        .label_style(("sans-serif", 18))
        .axis_desc_style(("sans-serif", 20))
        .draw()?;
    for (iy, row) in map.z.iter().enumerate() {
        for (ix, value) in row.iter().enumerate() {
            let (x, y) = (ix as f64, iy as f64);
            let (fill, text) = match value {
                Some(v) if *v > 0.0 && v.is_finite() => (colour((v.log10() - lo) / span), format!("{v:.2e}")),
                Some(v) => (RGBColor(230, 230, 230), format!("{v:.2e}")),
                None => (RGBColor(160, 160, 160), "failed".to_string()),
            };
            chart.draw_series(std::iter::once(Rectangle::new([(x, y), (x + 1.0, y + 1.0)], fill.filled())))?;
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

//! The chart and its legend: title across the top, the chart on the left,
//! the legend in its own panel on the right.

use super::data::Data;
use super::labels::{log_tick, ticks};
use super::style::{MARKERS, draw_marker, legend_sample, style, widest};
use super::{FONT, Figure, SIZE, Scale, TICKS, de};

use anyhow::Result;
use plotters::coord::Shift;
use plotters::coord::ranged1d::{AsRangedCoord, Ranged, ValueFormatter};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// Title across the top, chart on the left, legend in its own panel on the right: outside
/// the plot, the legend can list many series without ever covering data.
pub(super) fn render<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, fig: &Figure, d: &Data) -> Result<()> {
    root.fill(&WHITE).map_err(de)?;
    let root = root.margin(12, 0, 0, 0).titled(fig.title, (FONT, 30)).map_err(de)?;
    let labels: Vec<String> = fig
        .series
        .iter()
        .zip(&d.runs)
        .enumerate()
        .map(|(i, (s, runs))| {
            let mut l: String = s.label.chars().take(40).collect();
            if l.len() < s.label.len() {
                l.pop();
                l.push('…');
            }
            if runs.is_empty() {
                l += " (no data)";
            }
            if let Some(over) = d.under[i] {
                let over: String = fig.series[over].label.chars().take(24).collect();
                l += &format!(" (under {over})");
            }
            l
        })
        .collect();
    let legend_w = match labels.is_empty() {
        true => 0,
        false => (widest(&root, labels.iter().cloned())? + 90).min(SIZE.0 * 2 / 5),
    };
    let (plot, legend) = root.split_horizontally(root.dim_in_pixel().0 - legend_w);
    match fig.scale {
        Scale::Linear => chart(&plot, fig, d, d.y.0..d.y.1, &ticks(d.y))?,
        Scale::LogAbs => {
            let fmt = |v: &f64| log_tick(*v, d.shift, d.y);
            chart(&plot, fig, d, (d.y.0..d.y.1).log_scale(), &fmt)?
        }
    }
    let (w, h) = legend.dim_in_pixel();
    let n = labels.len().max(1) as i32;
    let row = ((h as i32 - 100) / n).clamp(6, 28);
    let frame = [(0, 20), (w as i32 - 20, 20 + row * n + 12)];
    legend.draw(&Rectangle::new(frame, WHITE.filled())).map_err(de)?;
    legend.draw(&Rectangle::new(frame, BLACK.mix(0.4))).map_err(de)?;
    let font = TextStyle::from((FONT, (row - 6).clamp(6, 18))).pos(Pos::new(HPos::Left, VPos::Center));
    for (i, l) in labels.iter().enumerate() {
        let y = 26 + row * i as i32 + row / 2;
        legend_sample(&legend, i, (12, y))?;
        draw_marker!(i, (32, y), |e| legend.draw(&e))?;
        legend.draw(&Text::new(l.as_str(), (62, y), font.clone())).map_err(de)?;
    }
    root.present().map_err(de)
}

/// Axes, grid and lines; generic over the y coordinate so linear and log share one path.
pub(super) fn chart<DB: DrawingBackend, Y>(
    area: &DrawingArea<DB, Shift>,
    fig: &Figure,
    d: &Data,
    y: Y,
    y_fmt: &dyn Fn(&f64) -> String,
) -> Result<()>
where
    Y: AsRangedCoord<Value = f64> + Clone,
    Y::CoordDescType: ValueFormatter<f64>,
{
    // Size the y label area from the actual tick labels so long ones are never clipped.
    let keys = Ranged::key_points(&Into::<Y::CoordDescType>::into(y.clone()), TICKS);
    let y_w = widest(area, keys.iter().map(y_fmt))?;
    let y_desc = match fig.scale {
        Scale::Linear => fig.y_label.to_string(),
        Scale::LogAbs => format!("|{}|", Some(fig.y_label).filter(|l| !l.is_empty()).unwrap_or("y")),
    };
    let mut ch = ChartBuilder::on(area)
        .margin(20)
        .x_label_area_size(60)
        .y_label_area_size(y_w + 50)
        .build_cartesian_2d(d.x.0..d.x.1, y)
        .map_err(de)?;
    ch.configure_mesh()
        .x_desc(fig.x_label)
        .y_desc(y_desc)
        .x_labels(TICKS)
        .y_labels(TICKS)
        .x_label_formatter(&ticks(d.x))
        .y_label_formatter(y_fmt)
        .label_style((FONT, 18))
        .axis_desc_style((FONT, 20))
        .bold_line_style(BLACK.mix(0.15))
        .light_line_style(BLACK.mix(0.04))
        .draw()
        .map_err(de)?;
    for (i, runs) in d.runs.iter().enumerate() {
        let (st, dash) = style(i);
        for run in runs {
            let pts = run.iter().copied();
            match (run.len(), dash) {
                (1, _) => ch.draw_series(std::iter::once(Circle::new(run[0], 3, st.filled()))),
                (_, None) => ch.draw_series(LineSeries::new(pts, st)),
                (_, Some((a, b))) => ch.draw_series(DashedLineSeries::new(pts, a, b, st)),
            }
            .map_err(de)?;
        }
    }
    // Markers at staggered places along each line, so a line drawn over
    // another (the same values) leaves the lower one's markers in view.
    let n = d.runs.len().max(1);
    for (i, runs) in d.runs.iter().enumerate() {
        let points: Vec<(f64, f64)> = runs.iter().flatten().copied().collect();
        if points.len() < 2 * MARKERS {
            continue;
        }
        for k in 0..MARKERS {
            let at = ((k as f64 + (i as f64 + 0.5) / n as f64) * points.len() as f64 / MARKERS as f64) as usize;
            let at = points[at.min(points.len() - 1)];
            draw_marker!(i, at, |e| ch.draw_series(std::iter::once(e)).map(|_| ()))?;
        }
    }
    if d.runs.iter().all(Vec::is_empty) {
        let (w, h) = area.dim_in_pixel();
        let grey = BLACK.mix(0.5);
        let style = TextStyle::from((FONT, 24)).color(&grey);
        let style = style.pos(Pos::new(HPos::Center, VPos::Center));
        let text = Text::new("no finite data", (w as i32 / 2, h as i32 / 2), style);
        area.draw(&text).map_err(de)?;
    }
    Ok(())
}

//! Line figures for the command-line tool: one call writes a PNG (for quick viewing) and an
//! SVG (for papers) of the same figure.
//!
//! The target machines have no system fonts, and plotters' `ab_glyph` text backend only knows
//! fonts registered with it, so DejaVu Sans is compiled into the binary and registered as
//! "sans-serif" before anything is drawn; every text style here uses that family.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use anyhow::{Context, Result, anyhow, bail};
use image::ImageEncoder;
use plotters::coord::Shift;
use plotters::coord::ranged1d::{AsRangedCoord, Ranged, ValueFormatter};
use plotters::coord::types::RangedCoordf64;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::{FontStyle, register_font};

/// One labelled line of a figure.
pub struct Series {
    /// Its name in the legend.
    pub label: String,
    /// Its points `(x, y)`.
    pub points: Vec<(f64, f64)>,
}

/// How the y axis maps values.
pub enum Scale {
    /// y as it is.
    #[allow(dead_code)] // the figures cdyn writes are all logarithmic today
    Linear,
    /// log10 of |y|; points with y == 0 or non-finite are skipped
    LogAbs,
}

/// A line figure: its labels, y scale and series.
pub struct Figure<'a> {
    /// Title above the plot.
    pub title: &'a str,
    /// Label of the x axis.
    pub x_label: &'a str,
    /// Label of the y axis.
    pub y_label: &'a str,
    /// How y is mapped.
    pub scale: Scale,
    /// The lines drawn.
    pub series: &'a [Series],
}

const FONT_BYTES: &[u8] = include_bytes!("../../assets/DejaVuSans.ttf");
pub(crate) const FONT: &str = "sans-serif";
const SIZE: (u32, u32) = (1200, 800);
/// Upper bound on tick labels per axis; also sets how many decimals a label needs.
const TICKS: usize = 10;
/// Magnitudes at or beyond this count as non-finite: spans and logs of them overflow.
const HUGE: f64 = 1e300;
/// Tableau 10: ten hues that stay apart from each other on screen and in print.
const PALETTE: [u32; 10] =
    [0x1f77b4, 0xff7f0e, 0x2ca02c, 0xd62728, 0x9467bd, 0x8c564b, 0xe377c2, 0x7f7f7f, 0xbcbd22, 0x17becf];

/// Writes `<stem>.png` (1200x800) and `<stem>.svg`. `stem` is a path without extension.
pub fn write_figure(stem: &Path, fig: &Figure) -> Result<()> {
    let data = prepare(fig);
    write_drawing(stem, SIZE, |area| render(area, fig, &data), |area| render(area, fig, &data))
}

/// Writes `<stem>.png` and `<stem>.svg` of `size`, drawn by `png` and `svg`
/// (the same drawing on each backend). Both are drawn in memory and written
/// atomically ([`crate::io::output`]), so a failed write leaves no truncated
/// figure and its message is the I/O error, not a dump of plotters' error types.
pub fn write_drawing(
    stem: &Path,
    size: (u32, u32),
    png: impl FnOnce(DrawingArea<BitMapBackend<'_>, Shift>) -> Result<()>,
    svg: impl FnOnce(DrawingArea<SVGBackend<'_>, Shift>) -> Result<()>,
) -> Result<()> {
    ensure_font()?;
    let (png_path, svg_path) = (with_ext(stem, "png"), with_ext(stem, "svg"));
    let mut pixels = vec![0u8; (size.0 * size.1 * 3) as usize];
    png(BitMapBackend::with_buffer(&mut pixels, size).into_drawing_area())
        .with_context(|| format!("cannot draw figure {}", png_path.display()))?;
    let mut encoded = Vec::new();
    image::codecs::png::PngEncoder::new(&mut encoded)
        .write_image(&pixels, size.0, size.1, image::ColorType::Rgb8)
        .map_err(|e| anyhow!("cannot encode figure {}: {e}", png_path.display()))?;
    crate::io::output::write(&png_path, &encoded)?;
    let mut text = String::new();
    svg(SVGBackend::with_string(&mut text, size).into_drawing_area())
        .with_context(|| format!("cannot draw figure {}", svg_path.display()))?;
    crate::io::output::write(&svg_path, text.as_bytes())
}

/// Registers the shipped font once; every figure needs it (there are no system fonts).
pub fn ensure_font() -> Result<()> {
    static FONT_OK: OnceLock<bool> = OnceLock::new();
    if !*FONT_OK.get_or_init(|| register_font(FONT, FontStyle::Normal, FONT_BYTES).is_ok()) {
        bail!("the embedded DejaVuSans.ttf could not be loaded");
    }
    Ok(())
}

/// Appends the extension rather than replacing one, so a stem like `run.v2` stays intact.
pub fn with_ext(stem: &Path, ext: &str) -> PathBuf {
    let mut s = stem.as_os_str().to_owned();
    s.push(format!(".{ext}"));
    s.into()
}

/// What gets drawn, computed once for both outputs. Each series is split into runs of usable
/// points, so a skipped point leaves a gap instead of a line bridging it. For `LogAbs`, y is
/// stored as |y| / 10^shift: plotters' log axis drops ticks below f64::EPSILON, so values
/// are shifted to start at 1 and the tick labels shift them back.
struct Data {
    runs: Vec<Vec<Vec<(f64, f64)>>>,
    /// For each series, a later series drawn over it along (almost) all its length: the
    /// legend says so, since the lower one cannot be seen but for its markers.
    under: Vec<Option<usize>>,
    x: (f64, f64),
    y: (f64, f64),
    shift: i32,
}

fn prepare(fig: &Figure) -> Data {
    let log = matches!(fig.scale, Scale::LogAbs);
    let usable = |x: f64, y: f64| x.abs() < HUGE && y.abs() < HUGE && !(log && y == 0.0);
    let mut runs: Vec<Vec<Vec<(f64, f64)>>> = fig
        .series
        .iter()
        .map(|s| {
            let (mut out, mut cur) = (Vec::new(), Vec::new());
            for &(x, y) in &s.points {
                if usable(x, y) {
                    cur.push((x, if log { y.abs().log10() } else { y }));
                } else if !cur.is_empty() {
                    out.push(std::mem::take(&mut cur));
                }
            }
            out.extend((!cur.is_empty()).then_some(cur));
            out
        })
        .collect();
    let extent = |f: fn(&(f64, f64)) -> f64| {
        runs.iter()
            .flatten()
            .flatten()
            .map(f)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)))
    };
    let (x, (ylo, yhi)) = (pad(extent(|p| p.0), 0.0), extent(|p| p.1));
    let under = coincident(&runs, (yhi - ylo) * COINCIDENT);
    if !log {
        return Data { y: pad((ylo, yhi), 0.05), x, runs, under, shift: 0 };
    }
    // Whole decades, so the axis always has labelled powers of ten.
    let (lo, hi) = if ylo > yhi { (-1.0, 1.0) } else { (ylo.floor(), yhi.ceil().max(ylo.floor() + 1.0)) };
    let shift = lo.max(hi - 300.0);
    for p in runs.iter_mut().flatten().flatten() {
        p.1 = 10f64.powf((p.1 - shift).max(0.0));
    }
    Data { runs, x, y: (10f64.powf((lo - shift).max(0.0)), 10f64.powf(hi - shift)), under, shift: shift as i32 }
}

/// Two curves closer than this fraction of the y axis draw as one line.
const COINCIDENT: f64 = 0.01;

/// For each series, the first later one that covers it: same times, and
/// within `tol` (in the drawn units: log10 |y| or y) at 95 % of them.
fn coincident(runs: &[Vec<Vec<(f64, f64)>>], tol: f64) -> Vec<Option<usize>> {
    let flat: Vec<Vec<(f64, f64)>> = runs.iter().map(|r| r.iter().flatten().copied().collect()).collect();
    let covers = |a: &[(f64, f64)], b: &[(f64, f64)]| {
        let close = a.iter().zip(b).filter(|(p, q)| p.0 == q.0 && (p.1 - q.1).abs() <= tol).count();
        !a.is_empty() && a.len() == b.len() && close as f64 >= 0.95 * a.len() as f64
    };
    (0..flat.len()).map(|a| (a + 1..flat.len()).find(|&b| covers(&flat[a], &flat[b]))).collect()
}

/// Widens a range by `frac` of its span each side. A flat range (all values equal, up to
/// rounding noise) opens to ±10 % of its value (±1 around 0), an empty one becomes 0..1,
/// so plotters never gets a degenerate axis.
fn pad((lo, hi): (f64, f64), frac: f64) -> (f64, f64) {
    if lo > hi {
        return (0.0, 1.0);
    }
    if hi - lo <= lo.abs().max(hi.abs()) * 1e-9 {
        let c = (lo + hi) / 2.0;
        let h = if c == 0.0 { 1.0 } else { c.abs() * 0.1 };
        return (c - h, c + h);
    }
    let d = (hi - lo) * frac;
    (lo - d, hi + d)
}

/// Tick labeller for a linear axis over `lo..hi`: scientific outside 1e-3..1e5 (so 1e-9 is not
/// "0.000000001"), else fixed-point; either way with just the digits the tick step needs.
fn ticks((lo, hi): (f64, f64)) -> impl Fn(&f64) -> String {
    let keys = RangedCoordf64::from(lo..hi).key_points(TICKS);
    let step = match keys.as_slice() {
        [a, b, ..] => b - a,
        _ => (hi - lo) / TICKS as f64,
    };
    let k = (step.log10() + 1e-9).floor(); // decade of the step (a 1, 2 or 5 times 10^k)
    let sci_axis = !(1e-3..1e5).contains(&lo.abs().max(hi.abs()));
    move |&v| {
        let v = if v.abs() < 10f64.powf(k) / 2.0 { 0.0 } else { v };
        match (sci_axis, v == 0.0) {
            (true, true) => "0".into(),
            (true, false) => sci(v, (v.abs().log10().floor() - k).clamp(0.0, 15.0) as usize),
            (false, _) => format!("{v:.*}", (-k).clamp(0.0, 15.0) as usize),
        }
    }
}

/// Scientific notation without trailing zeros in the mantissa: "1.5e-9", "2e-10".
fn sci(v: f64, decimals: usize) -> String {
    let s = format!("{v:.decimals$e}");
    let (m, e) = s.split_once('e').unwrap_or((&s, "0"));
    match m.contains('.') {
        true => format!("{}e{e}", m.trim_end_matches('0').trim_end_matches('.')),
        false => format!("{m}e{e}"),
    }
}

/// Tick label on the log axis; `v` is in shifted units (see `Data`). Plain numbers when the
/// whole axis lies within 1e-3..1e4, scientific otherwise.
fn log_tick(v: f64, shift: i32, (lo, hi): (f64, f64)) -> String {
    let l = v.log10() + f64::from(shift);
    let (e, m) = (l.floor(), (10f64.powf(l - l.floor()) * 10.0).round() / 10.0);
    let (e, m) = if m >= 10.0 { (e + 1.0, 1.0) } else { (e, m) };
    let (alo, ahi) = (lo.log10() + f64::from(shift), hi.log10() + f64::from(shift));
    if alo >= -3.01 && ahi <= 4.01 {
        let decimals = (if m.fract() == 0.0 { -e } else { 1.0 - e }).max(0.0) as usize;
        format!("{:.*}", decimals, m * 10f64.powf(e))
    } else {
        sci(m * 10f64.powf(e), 1)
    }
}

/// Line style of series `i`: the ten hues first, then the hues again dashed, then dotted.
pub(crate) fn style(i: usize) -> (ShapeStyle, Option<(u32, u32)>) {
    let c = PALETTE[i % 10];
    let color = RGBColor((c >> 16) as u8, (c >> 8) as u8, c as u8);
    (color.stroke_width(2), [None, Some((12, 6)), Some((2, 5))][(i / 10) % 3])
}

/// Series `i`'s line style, 40 pixels of it from `(x, y)`, in a legend.
pub(crate) fn legend_sample<DB: DrawingBackend>(
    legend: &DrawingArea<DB, Shift>,
    i: usize,
    (x, y): (i32, i32),
) -> Result<()> {
    let (st, dash) = style(i);
    let sample = [(x, y), (x + 40, y)];
    match dash {
        None => legend.draw(&PathElement::new(sample, st)),
        Some((a, b)) => legend.draw(&DashedPathElement::new(sample, a, b, st)),
    }
    .map_err(de)
}

/// Markers along each line.
const MARKERS: usize = 12;

/// Draws the marker of series `$i` (its hue; a circle, triangle, square or
/// cross by turns) centred on `$at` with `$draw` (a function of the element),
/// for a chart (data coordinates) and the legend (pixels) alike.
macro_rules! draw_marker {
    ($i:expr, $at:expr, $draw:expr) => {{
        let (line, _) = style($i);
        let fill = line.color.filled();
        let at = EmptyElement::at($at);
        match $i % 4 {
            0 => $draw(at + Circle::new((0, 0), 5, fill)),
            1 => $draw(at + TriangleMarker::new((0, 0), 7, fill)),
            2 => $draw(at + Rectangle::new([(-4, -4), (4, 4)], fill)),
            _ => $draw(at + Cross::new((0, 0), 5, line.color.stroke_width(3))),
        }
        .map_err(de)
    }};
}

/// Width in pixels of the widest of `texts` in the 18 px label font.
fn widest<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, texts: impl Iterator<Item = String>) -> Result<u32> {
    let font = TextStyle::from((FONT, 18));
    let mut w = 0;
    for t in texts {
        w = w.max(area.estimate_text_size(&t, &font).map_err(de)?.0);
    }
    Ok(w)
}

pub(crate) fn de<E: std::error::Error + Send + Sync>(e: DrawingAreaErrorKind<E>) -> anyhow::Error {
    anyhow!("{e}")
}

/// Title across the top, chart on the left, legend in its own panel on the right: outside
/// the plot, the legend can list many series without ever covering data.
fn render<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, fig: &Figure, d: &Data) -> Result<()> {
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
fn chart<DB: DrawingBackend, Y>(
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A fresh directory per test, so parallel tests and earlier runs never collide.
    fn temp_dir(name: &str) -> PathBuf {
        let nanos = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).unwrap().as_nanos();
        let dir = std::env::temp_dir().join(format!("cdyn-plot-{}-{name}-{nanos}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn fig<'a>(series: &'a [Series], scale: Scale) -> Figure<'a> {
        Figure { title: "Test figure", x_label: "time t", y_label: "error", scale, series }
    }

    fn wave(label: &str, f: impl Fn(f64) -> f64) -> Series {
        Series { label: label.into(), points: (0..2000).map(|i| (i as f64 * 0.01, f(i as f64 * 0.01))).collect() }
    }

    #[test]
    fn writes_png_and_svg_with_labels() {
        let dir = temp_dir("basic");
        let series = [
            wave("energy drift", |t| 1e-9 * t.sin()),
            wave("constraint violation", |t| 2e-9 * (3.0 * t).cos()),
            wave("momentum & <error>", |t| 1e-10 * t),
        ];
        for (name, scale) in [("lin", Scale::Linear), ("log", Scale::LogAbs)] {
            write_figure(&dir.join(name), &fig(&series, scale)).unwrap();
            let png = std::fs::read(dir.join(format!("{name}.png"))).unwrap();
            let svg = std::fs::read_to_string(dir.join(format!("{name}.svg"))).unwrap();
            assert!(png.len() > 20_000 && svg.len() > 20_000, "{} {}", png.len(), svg.len());
            assert!(png.starts_with(b"\x89PNG\r\n\x1a\n"));
            for label in
                ["energy drift", "constraint violation", "momentum &amp; &lt;error&gt;", "Test figure", "time t"]
            {
                assert!(svg.contains(label), "{name}.svg lacks {label}");
            }
            assert!(svg.contains(if name == "log" { "\n|error|\n" } else { "\nerror\n" }));
        }
        std::fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn degenerate_inputs_still_make_figures() {
        let dir = temp_dir("degenerate");
        let cases: Vec<Vec<Series>> = vec![
            vec![],
            vec![Series {
                label: "bad".into(),
                points: vec![(0.0, f64::NAN), (f64::INFINITY, 1.0), (1.0, f64::NEG_INFINITY)],
            }],
            vec![wave("flat", |_| 3.0), wave("zero", |_| 0.0)],
            vec![wave("zero", |_| 0.0)],
            vec![Series { label: "one point".into(), points: vec![(1.0, 2.0)] }],
            vec![wave("gaps", |t| if (t * 10.0) as i32 % 2 == 0 { f64::NAN } else { t })],
            vec![wave("huge", |t| 1e299 * t), wave("subnormal", |t| 5e-324 * t)],
            vec![Series { label: "x".repeat(200), points: vec![(0.0, 1.0), (1.0, 1.0 + 1e-14)] }],
            (0..30).map(|k| wave(&format!("s{k}"), |t| t * k as f64)).collect(),
        ];
        for (i, series) in cases.iter().enumerate() {
            for (scale, tag) in [(Scale::Linear, "lin"), (Scale::LogAbs, "log")] {
                let stem = dir.join(format!("case{i}-{tag}"));
                write_figure(&stem, &fig(series, scale)).unwrap();
                assert!(std::fs::metadata(with_ext(&stem, "png")).unwrap().len() > 5_000);
            }
        }
        std::fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn a_curve_drawn_over_another_is_named_in_the_legend() {
        let dir = temp_dir("coincident");
        let near = |t: f64| 1e-4 * (1.0 + t.sin().abs());
        let series = [
            wave("lower", near),
            wave("apart", |t| 1e-8 * (1.0 + t)),
            // Within 0.1 % of `lower`: one line on the figure.
            wave("upper", |t| near(t) * 1.001),
        ];
        write_figure(&dir.join("fig"), &fig(&series, Scale::LogAbs)).unwrap();
        let svg = std::fs::read_to_string(dir.join("fig.svg")).unwrap();
        assert!(svg.contains("lower (under upper)"), "no note in the legend");
        assert!(!svg.contains("apart (under") && !svg.contains("upper (under"));
        // Markers: 12 along each line and one in the legend, of three shapes.
        let circles = svg.matches("<circle").count();
        assert!(circles >= 13, "{circles} circles");
        assert!(svg.matches("<polygon").count() >= 13 || svg.matches("<polyline").count() >= 13);
        let d = prepare(&fig(&series, Scale::LogAbs));
        assert_eq!(d.under, [Some(2), None, None]);
        // Curves a tenth of the axis apart are not one.
        let apart = [wave("a", near), wave("b", |t| near(t) * 2.0), wave("c", |t| 1e-8 * (1.0 + t))];
        assert_eq!(prepare(&fig(&apart, Scale::LogAbs)).under, [None, None, None]);
        std::fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn unwritable_path_names_the_file() {
        let stem = std::env::temp_dir().join("cdyn-plot-no-such-dir").join("fig");
        let err = write_figure(&stem, &fig(&[], Scale::Linear)).unwrap_err();
        assert!(format!("{err:#}").contains("fig.png"), "{err:#}");
    }

    #[test]
    fn tick_labels_are_compact() {
        let f = ticks((-1e-8, 1e-8));
        assert_eq!((f(&5e-9), f(&-1e-8), f(&1e-25)), ("5e-9".into(), "-1e-8".into(), "0".into()));
        let f = ticks((0.0, 10.0));
        assert_eq!((f(&2.0), f(&0.0)), ("2".into(), "0".into()));
        assert_eq!(ticks((0.0, 1.0))(&0.30000000000000004), "0.3");
        assert_eq!(log_tick(100.0, -20, (1.0, 1e3)), "1e-18");
        assert_eq!(log_tick(2.0, 0, (1.0, 10.0)), "2");
        assert_eq!(log_tick(0.001, 0, (1e-3, 1.0)), "0.001");
    }
}

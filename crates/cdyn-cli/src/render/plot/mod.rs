//! Line figures for the command-line tool: one call writes a PNG (for quick viewing) and an
//! SVG (for papers) of the same figure.
//!
//! The target machines have no system fonts, and plotters' `ab_glyph` text backend only knows
//! fonts registered with it, so DejaVu Sans is compiled into the binary and registered as
//! "sans-serif" before anything is drawn; every text style here uses that family.
//!
//! Here the figure and the writing of its two files; `data` the points as
//! drawn (gaps, shifted logarithms, lines drawn over others); `labels` the
//! tick labels; `style` the series' hues, dashes and markers; `draw` the
//! chart and its legend.
//!
//! May import: `io`.

mod data;
mod draw;
mod labels;
mod style;

pub(crate) use style::{legend_sample, style};

use data::prepare;
use draw::render;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use anyhow::{Context, Result, anyhow, bail};
use image::ImageEncoder;
use plotters::coord::Shift;
use plotters::prelude::*;
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

const FONT_BYTES: &[u8] = include_bytes!("../../../assets/DejaVuSans.ttf");
pub(crate) const FONT: &str = "sans-serif";
pub(super) const SIZE: (u32, u32) = (1200, 800);
/// Upper bound on tick labels per axis; also sets how many decimals a label needs.
pub(super) const TICKS: usize = 10;
/// Magnitudes at or beyond this count as non-finite: spans and logs of them overflow.
pub(super) const HUGE: f64 = 1e300;

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

pub(crate) fn de<E: std::error::Error + Send + Sync>(e: DrawingAreaErrorKind<E>) -> anyhow::Error {
    anyhow!("{e}")
}

#[cfg(test)]
mod tests {
    use super::labels::{log_tick, ticks};
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

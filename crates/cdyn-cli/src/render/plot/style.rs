//! How series look: ten hues, then dashed and dotted; a marker shape by
//! turns; the legend's line samples; the width of labels.

use super::{FONT, de};
use anyhow::Result;
use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;

/// Tableau 10: ten hues that stay apart from each other on screen and in print.
pub(super) const PALETTE: [u32; 10] =
    [0x1f77b4, 0xff7f0e, 0x2ca02c, 0xd62728, 0x9467bd, 0x8c564b, 0xe377c2, 0x7f7f7f, 0xbcbd22, 0x17becf];

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
pub(super) const MARKERS: usize = 12;

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
pub(super) use draw_marker;

/// Width in pixels of the widest of `texts` in the 18 px label font.
pub(super) fn widest<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    texts: impl Iterator<Item = String>,
) -> Result<u32> {
    let font = TextStyle::from((FONT, 18));
    let mut w = 0;
    for t in texts {
        w = w.max(area.estimate_text_size(&t, &font).map_err(de)?.0);
    }
    Ok(w)
}

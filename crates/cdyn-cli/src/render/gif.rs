//! `animation.gif`: the mechanism's motion as an animated GIF, for slides
//! and READMEs — the frames the viewer animates, at most [`MAX_FRAMES`] of
//! them, at about real time ([`encode`]); a planar mechanism drawn to scale
//! as the page draws it (bodies as bars from the centre of mass to the
//! points elements attach to, joints, springs, ground points) here, a
//! spatial one in [`crate::render::gif3d`].

use crate::case::frames::Frames;
use anyhow::{Context, Result, anyhow};
use cdyn::planar::{Anchor, Drawing};
use image::codecs::gif::{GifEncoder, Repeat};
use image::{Delay, Frame, RgbaImage};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// Most frames in a GIF.
pub const MAX_FRAMES: usize = 200;
/// Width and height in pixels.
pub const SIZE: (u32, u32) = (480, 360);
/// Shortest delay between frames: browsers show shorter ones slower.
const MIN_DELAY_MS: f64 = 20.0;
/// The viewer's body colours, in the same order.
pub const COLOURS: [RGBColor; 10] = [
    RGBColor(0x1f, 0x77, 0xb4),
    RGBColor(0xd6, 0x27, 0x28),
    RGBColor(0x2c, 0xa0, 0x2c),
    RGBColor(0x94, 0x67, 0xbd),
    RGBColor(0xff, 0x7f, 0x0e),
    RGBColor(0x8c, 0x56, 0x4b),
    RGBColor(0xe3, 0x77, 0xc2),
    RGBColor(0x17, 0xbe, 0xcf),
    RGBColor(0xbc, 0xbd, 0x22),
    RGBColor(0x7f, 0x7f, 0x7f),
];

/// Writes the animation of `frames` of the mechanism `drawing` to `path`.
pub fn write(path: &Path, drawing: &Drawing, frames: &Frames) -> Result<()> {
    let view = View::fit(drawing, frames);
    encode(path, frames, |area, q, t| draw_frame(area, drawing, &view, q, t).map_err(|e| anyhow!("{e:?}")))
}

/// The drawing of one frame: into this area, the positions and the time.
pub type Area<'a> = DrawingArea<BitMapBackend<'a>, Shift>;

/// Writes to `path` the animation of [`MAX_FRAMES`] of `frames` at most,
/// each drawn by `draw` into a [`SIZE`] image, at about real time.
pub fn encode(path: &Path, frames: &Frames, mut draw: impl FnMut(Area, &[f64], f64) -> Result<()>) -> Result<()> {
    if frames.is_empty() {
        anyhow::bail!("no frames to animate for {}", path.display());
    }
    crate::render::plot::ensure_font()?;
    let picked = pick(frames.len(), MAX_FRAMES);
    let span = frames.t[frames.len() - 1] - frames.t[0];
    let delay_ms = (1000.0 * span / picked.len().max(1) as f64).max(MIN_DELAY_MS);
    let mut bytes = Vec::new();
    {
        let mut encoder = GifEncoder::new_with_speed(&mut bytes, 20);
        encoder.set_repeat(Repeat::Infinite).map_err(|e| anyhow!("cannot encode {}: {e}", path.display()))?;
        let mut pixels = vec![0u8; (SIZE.0 * SIZE.1 * 3) as usize];
        for &k in &picked {
            draw(BitMapBackend::with_buffer(&mut pixels, SIZE).into_drawing_area(), frames.q(k), frames.t[k])
                .with_context(|| format!("cannot draw {}", path.display()))?;
            let rgba: Vec<u8> = pixels.chunks(3).flat_map(|p| [p[0], p[1], p[2], 255]).collect();
            let image = RgbaImage::from_raw(SIZE.0, SIZE.1, rgba).ok_or_else(|| anyhow!("bad frame size"))?;
            let delay = Delay::from_numer_denom_ms(delay_ms.round() as u32, 1);
            encoder
                .encode_frame(Frame::from_parts(image, 0, 0, delay))
                .map_err(|e| anyhow!("cannot encode {}: {e}", path.display()))?;
        }
    }
    crate::io::output::write(path, &bytes)
}

/// Up to `max` frame indices of `n`, evenly spread, the first and last among them.
fn pick(n: usize, max: usize) -> Vec<usize> {
    if n <= max {
        return (0..n).collect();
    }
    let mut picked: Vec<usize> = (0..max).map(|i| i * (n - 1) / (max - 1)).collect();
    picked.dedup();
    picked
}

/// World to pixels: one scale for both axes, y up, the whole motion in view.
struct View {
    lo: [f64; 2],
    scale: f64,
    offset: [f64; 2],
}

impl View {
    fn fit(d: &Drawing, frames: &Frames) -> View {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        let mut take = |p: [f64; 2]| {
            if p.iter().all(|x| x.is_finite()) {
                lo = [lo[0].min(p[0]), lo[1].min(p[1])];
                hi = [hi[0].max(p[0]), hi[1].max(p[1])];
            }
        };
        for k in 0..frames.len() {
            let q = frames.q(k);
            for (i, b) in d.bodies.iter().enumerate() {
                for &point in std::iter::once(&[0.0, 0.0]).chain(&b.points) {
                    take(d.place(Anchor { body: Some(i), point }, q));
                }
            }
        }
        for end in d.links.iter().flat_map(|l| &l.ends).filter(|e| e.body.is_none()) {
            take(end.point);
        }
        if !lo[0].is_finite() {
            (lo, hi) = ([-1.0; 2], [1.0; 2]);
        }
        let pad = 0.08 * (hi[0] - lo[0]).max(hi[1] - lo[1]).max(1e-9);
        let (lo, hi) = ([lo[0] - pad, lo[1] - pad], [hi[0] + pad, hi[1] + pad]);
        let (w, h) = (f64::from(SIZE.0), f64::from(SIZE.1));
        let scale = (w / (hi[0] - lo[0])).min(h / (hi[1] - lo[1]));
        let offset = [(w - scale * (hi[0] - lo[0])) / 2.0, h - (h - scale * (hi[1] - lo[1])) / 2.0];
        View { lo, scale, offset }
    }

    fn px(&self, p: [f64; 2]) -> (i32, i32) {
        let x = self.offset[0] + (p[0] - self.lo[0]) * self.scale;
        let y = self.offset[1] - (p[1] - self.lo[1]) * self.scale;
        (x.round() as i32, y.round() as i32)
    }
}

/// One frame, in the viewer's order: ground, rods and springs, bodies, joints, centres.
fn draw_frame<DB: DrawingBackend>(
    area: DrawingArea<DB, Shift>,
    d: &Drawing,
    view: &View,
    q: &[f64],
    t: f64,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    area.fill(&WHITE)?;
    let label = ("sans-serif", 14).into_font().color(&BLACK);
    if q.iter().any(|x| !x.is_finite()) {
        // A run that blew up: nothing sensible to draw.
        area.draw(&Text::new(format!("t = {t:.3}: positions not finite"), (8, 6), label))?;
        return area.present();
    }
    let grey = RGBColor(0x99, 0x99, 0x99);
    let at = |e: &Anchor| view.px(d.place(*e, q));
    for end in d.links.iter().flat_map(|l| &l.ends).filter(|e| e.body.is_none()) {
        let (x, y) = view.px(end.point);
        area.draw(&Polygon::new(vec![(x, y), (x - 8, y + 12), (x + 8, y + 12)], grey.filled()))?;
    }
    for l in &d.links {
        let p: Vec<(i32, i32)> = l.ends.iter().map(at).collect();
        match l.kind {
            "distance" => area.draw(&PathElement::new(p, RGBColor(0x44, 0x44, 0x44).stroke_width(3)))?,
            "spring" => area.draw(&PathElement::new(zigzag(p[0], p[1]), RGBColor(0x22, 0xaa, 0x77).stroke_width(1)))?,
            "damper" => area.draw(&PathElement::new(p, RGBColor(0xaa, 0x55, 0x22).stroke_width(4)))?,
            _ => {}
        }
    }
    for (i, b) in d.bodies.iter().enumerate() {
        let c = at(&Anchor { body: Some(i), point: [0.0, 0.0] });
        for &point in &b.points {
            let p = at(&Anchor { body: Some(i), point });
            area.draw(&PathElement::new(vec![c, p], COLOURS[i % COLOURS.len()].stroke_width(6)))?;
        }
    }
    for l in d.links.iter().filter(|l| l.kind == "revolute") {
        let p = at(&l.ends[1]);
        area.draw(&Circle::new(p, 4, WHITE.filled()))?;
        area.draw(&Circle::new(p, 4, BLACK.stroke_width(1)))?;
    }
    for i in 0..d.bodies.len() {
        let c = at(&Anchor { body: Some(i), point: [0.0, 0.0] });
        area.draw(&Circle::new(c, 6, COLOURS[i % COLOURS.len()].filled()))?;
        area.draw(&Circle::new(c, 6, BLACK.stroke_width(1)))?;
    }
    area.draw(&Text::new(format!("t = {t:.3}"), (8, 6), label))?;
    area.present()
}

/// A spring's zigzag between two pixel points.
fn zigzag(a: (i32, i32), b: (i32, i32)) -> Vec<(i32, i32)> {
    let (dx, dy) = (f64::from(b.0 - a.0), f64::from(b.1 - a.1));
    let len = dx.hypot(dy).max(1.0);
    let (nx, ny) = (-dy / len * 5.0, dx / len * 5.0);
    let turns = 20;
    let mut points = vec![a];
    for k in 1..turns {
        let f = 0.1 + 0.8 * f64::from(k) / f64::from(turns);
        let side = if k % 2 == 1 { 1.0 } else { -1.0 };
        points.push((
            (f64::from(a.0) + f * dx + side * nx).round() as i32,
            (f64::from(a.1) + f * dy + side * ny).round() as i32,
        ));
    }
    points.push(b);
    points
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn picks_evenly_with_both_ends() {
        assert_eq!(pick(5, 200), [0, 1, 2, 3, 4]);
        let p = pick(2001, 200);
        assert_eq!(p.len(), 200);
        assert_eq!((p[0], p[199]), (0, 2000));
        assert!(p.windows(2).all(|w| (10..=11).contains(&(w[1] - w[0]))));
    }
}

//! `mechanism.png` / `mechanism.svg` of a spatial run: the mechanism at
//! four instants (start, a third, two thirds, end), side by side, each an
//! orthographic view from the same oblique direction on a common scale.
//! Bodies are drawn as lines from their centre of mass to the points their
//! joints attach to; joints as rings; ground points as squares; distance
//! joints as the rod between their two ends.

use crate::case::frames::Frames;
use crate::render::plot::{FONT, write_drawing};
use anyhow::Result;
use cdyn::spatial::Sketch;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// File stem of the figure.
pub const STEM: &str = "mechanism";

const SIZE: (u32, u32) = (1600, 520);

/// The screen axes of the view: looking from `(1, −1.4, 0.8)`, z up.
fn project(p: [f64; 3]) -> (f64, f64) {
    let d: [f64; 3] = [1.0, -1.4, 0.8];
    let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    let d = d.map(|x| x / n);
    // right = up × d normalized, screen up = d × right.
    let right = [-d[1], d[0], 0.0];
    let rn = (right[0] * right[0] + right[1] * right[1]).sqrt();
    let right = right.map(|x| x / rn);
    let up = [d[1] * right[2] - d[2] * right[1], d[2] * right[0] - d[0] * right[2], d[0] * right[1] - d[1] * right[0]];
    let dot = |a: [f64; 3]| a[0] * p[0] + a[1] * p[1] + a[2] * p[2];
    (dot(right), dot(up))
}

/// A point on the screen, and a line between two.
type Point = (f64, f64);
type Segment = (Point, Point);

/// The segments and markers of one frame, projected.
struct Scene {
    /// Body lines, by body.
    limbs: Vec<Vec<Segment>>,
    rods: Vec<Segment>,
    joints: Vec<Point>,
    ground: Vec<Point>,
}

fn scene(sketch: &Sketch, q: &[f64]) -> Scene {
    let limbs = sketch
        .bodies
        .iter()
        .enumerate()
        .map(|(b, limb)| {
            let centre = project(limb.at.position(q));
            let place = |s: &[f64; 3]| project(sketch.place(q, &cdyn::spatial::Anchor { body: Some(b), point: *s }));
            limb.points.iter().map(|s| (centre, place(s))).collect()
        })
        .collect();
    let (mut rods, mut joints, mut ground) = (Vec::new(), Vec::new(), Vec::new());
    for [a, b] in &sketch.joints {
        let (pa, pb) = (project(sketch.place(q, a)), project(sketch.place(q, b)));
        if (pa.0 - pb.0).hypot(pa.1 - pb.1) > 1e-9 {
            rods.push((pa, pb));
        }
        joints.push(pa);
        for (anchor, at) in [(a, pa), (b, pb)] {
            if anchor.body.is_none() {
                ground.push(at);
            }
        }
    }
    Scene { limbs, rods, joints, ground }
}

/// Writes the figure of `frames` (none kept: nothing written) into `dir`.
pub fn write(dir: &Path, title: &str, sketch: &Sketch, frames: &Frames) -> Result<()> {
    if frames.is_empty() || sketch.bodies.is_empty() {
        return Ok(());
    }
    let last = frames.len() - 1;
    let picks = [0, last / 3, 2 * last / 3, last];
    let scenes: Vec<(f64, Scene)> = picks.iter().map(|&i| (frames.t[i], scene(sketch, frames.q(i)))).collect();
    // One scale for all four panels.
    let points = scenes.iter().flat_map(|(_, s)| {
        s.limbs
            .iter()
            .flatten()
            .flat_map(|(a, b)| [*a, *b])
            .chain(s.ground.iter().copied())
            .chain(s.joints.iter().copied())
    });
    let (mut lo, mut hi) = ((f64::INFINITY, f64::INFINITY), (f64::NEG_INFINITY, f64::NEG_INFINITY));
    for (x, y) in points {
        (lo, hi) = ((lo.0.min(x), lo.1.min(y)), (hi.0.max(x), hi.1.max(y)));
    }
    let half = 0.55 * (hi.0 - lo.0).max(hi.1 - lo.1).max(1e-6);
    let centre = (0.5 * (lo.0 + hi.0), 0.5 * (lo.1 + hi.1));
    let range = ((centre.0 - half, centre.0 + half), (centre.1 - half, centre.1 + half));
    write_drawing(&dir.join(STEM), SIZE, |a| draw(a, title, &scenes, range), |a| draw(a, title, &scenes, range))
}

/// The plotted square: x and y ranges.
type Range = ((f64, f64), (f64, f64));

fn draw<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    title: &str,
    scenes: &[(f64, Scene)],
    range: Range,
) -> Result<()> {
    let fail = |e: DrawingAreaErrorKind<DB::ErrorType>| anyhow::anyhow!("{e:?}");
    root.fill(&WHITE).map_err(fail)?;
    let root = root
        .titled(
            &format!("{title}: the mechanism at four instants (orthographic, from (1, −1.4, 0.8), z up)"),
            (FONT, 22),
        )
        .map_err(fail)?;
    for (panel, (t, s)) in root.split_evenly((1, scenes.len())).into_iter().zip(scenes) {
        let mut chart = ChartBuilder::on(&panel)
            .caption(format!("t = {t:.4} s"), (FONT, 18))
            .margin(12)
            .build_cartesian_2d(range.0.0..range.0.1, range.1.0..range.1.1)
            .map_err(fail)?;
        for (b, lines) in s.limbs.iter().enumerate() {
            let colour = Palette99::pick(b).to_rgba().stroke_width(3);
            for &(a, z) in lines {
                chart.draw_series(std::iter::once(PathElement::new(vec![a, z], colour))).map_err(fail)?;
            }
            if let Some(&(c, _)) = lines.first() {
                chart.draw_series(std::iter::once(Circle::new(c, 4, Palette99::pick(b).filled()))).map_err(fail)?;
            }
        }
        for &(a, z) in &s.rods {
            chart.draw_series(std::iter::once(PathElement::new(vec![a, z], BLACK.stroke_width(2)))).map_err(fail)?;
        }
        chart.draw_series(s.joints.iter().map(|&p| Circle::new(p, 5, BLACK.stroke_width(2)))).map_err(fail)?;
        chart
            .draw_series(s.ground.iter().map(|&(x, y)| {
                let d = 0.02 * (range.0.1 - range.0.0);
                Rectangle::new([(x - d, y - d), (x + d, y + d)], BLACK.filled())
            }))
            .map_err(fail)?;
    }
    Ok(())
}

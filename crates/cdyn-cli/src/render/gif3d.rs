//! `animation.gif` of a spatial run: each frame drawn as the page draws it
//! from the default view ([`YAW`], [`PITCH`]) — the
//! floor's edges, the bodies' and the ground's solids shaded and painted far to near, then on top
//! the skeleton: lines from each centre of mass to its joints' points,
//! joints, rods, ground points, and each body's axes (x red, y green, z
//! blue) at its centre of mass.

use crate::case::frames::Frames;
use crate::render::gif::{Area, COLOURS, SIZE, encode};
use crate::render::scene3d::{Camera, PITCH, Scene, YAW};
use anyhow::{Result, anyhow};
use cdyn::spatial::{Anchor, Sketch, rotation::rotate};
use plotters::prelude::*;
use std::path::Path;

/// Writes the animation of `frames` of `sketch` to `path`.
pub fn write(path: &Path, sketch: &Sketch, frames: &Frames) -> Result<()> {
    let scene = Scene::of(sketch, &[frames]);
    let camera = Camera::new(&scene, YAW, PITCH, 1.0, SIZE);
    encode(path, frames, |area, q, t| draw(area, sketch, &scene, &camera, q, t).map_err(|e| anyhow!("{e:?}")))
}

/// The ground's colour (a robot's base).
const GROUND: RGBColor = RGBColor(0xaa, 0xaa, 0xaa);

/// A pixel of a projected point.
fn px(p: [f64; 2]) -> (i32, i32) {
    (p[0].round() as i32, p[1].round() as i32)
}

/// `colour` lit by `light`.
fn shade(colour: RGBColor, light: f64) -> RGBColor {
    let f = |c: u8| (f64::from(c) * light).round().clamp(0.0, 255.0) as u8;
    RGBColor(f(colour.0), f(colour.1), f(colour.2))
}

/// Something painted: how far, and what.
enum Paint {
    Face(Vec<(i32, i32)>, RGBColor),
    Ball((i32, i32), i32, RGBColor),
}

fn draw(
    area: Area,
    sketch: &Sketch,
    scene: &Scene,
    cam: &Camera,
    q: &[f64],
    t: f64,
) -> Result<(), DrawingAreaErrorKind<<BitMapBackend<'static> as DrawingBackend>::ErrorType>> {
    area.fill(&WHITE)?;
    let label = ("sans-serif", 14).into_font().color(&BLACK);
    if q.iter().any(|x| !x.is_finite()) {
        area.draw(&Text::new(format!("t = {t:.3}: positions not finite"), (8, 6), label))?;
        return area.present();
    }
    let at = |p: [f64; 3]| px(cam.project(p).0);
    // Of the floor only its edges: the grid's lines would triple the file
    // (2.2 MB against 1.0 MB for the tethered arm's 200 frames).
    let grid = scene.floor_grid();
    for &[a, b] in grid.iter().take(2).chain(grid.iter().rev().take(2)) {
        area.draw(&PathElement::new(vec![at(a), at(b)], RGBColor(0xdd, 0xdd, 0xdd).stroke_width(1)))?;
    }
    // The solids, far to near.
    let mut paints: Vec<(f64, Paint)> = Vec::new();
    let bodies =
        sketch.bodies.iter().zip(&scene.solids).enumerate().map(|(b, (limb, solid))| {
            ((limb.at.position(q), limb.at.orientation(q)), solid, COLOURS[b % COLOURS.len()])
        });
    let ground = (([0.0; 3], [1.0, 0.0, 0.0, 0.0]), &scene.ground, GROUND);
    for ((r, p), solid, colour) in bodies.chain(std::iter::once(ground)) {
        let to_space = |x: [f64; 3]| -> [f64; 3] {
            let y = rotate(p, x);
            std::array::from_fn(|i| r[i] + y[i])
        };
        for face in &solid.faces {
            let corners: Vec<[f64; 3]> = face.corners.iter().map(|&x| to_space(x)).collect();
            let normal = rotate(p, face.normal);
            if !cam.sees(corners[0], normal) {
                continue;
            }
            let depth = corners.iter().map(|&x| cam.project(x).1).sum::<f64>() / corners.len() as f64;
            let pixels = corners.iter().map(|&x| at(x)).collect();
            paints.push((depth, Paint::Face(pixels, shade(colour, cam.light(normal)))));
        }
        for &(centre, radius) in &solid.spheres {
            let (c, depth) = cam.project(to_space(centre));
            let rp = cam.pixels(radius, depth).round().max(1.0) as i32;
            paints.push((depth, Paint::Ball(px(c), rp, shade(colour, 0.85))));
        }
    }
    paints.sort_by(|a, b| b.0.total_cmp(&a.0));
    for (_, paint) in paints {
        match paint {
            Paint::Face(pixels, colour) => {
                area.draw(&Polygon::new(pixels.clone(), colour.filled()))?;
                let mut outline = pixels;
                outline.push(outline[0]);
                area.draw(&PathElement::new(outline, shade(colour, 0.7).stroke_width(1)))?;
            }
            Paint::Ball(c, r, colour) => {
                area.draw(&Circle::new(c, r, colour.filled()))?;
                area.draw(&Circle::new(c, r, shade(colour, 0.7).stroke_width(1)))?;
            }
        }
    }
    // The skeleton on top.
    let dark = RGBColor(0x33, 0x33, 0x33);
    for (b, limb) in sketch.bodies.iter().enumerate() {
        let c = at(limb.at.position(q));
        for &point in &limb.points {
            area.draw(&PathElement::new(
                vec![c, at(sketch.place(q, &Anchor { body: Some(b), point }))],
                dark.stroke_width(2),
            ))?;
        }
    }
    for [a, b] in &sketch.joints {
        let (pa, pb) = (at(sketch.place(q, a)), at(sketch.place(q, b)));
        if pa != pb {
            area.draw(&PathElement::new(vec![pa, pb], BLACK.stroke_width(2)))?;
        }
        for (anchor, p) in [(a, pa), (b, pb)] {
            if anchor.body.is_none() {
                area.draw(&Rectangle::new([(p.0 - 4, p.1 - 4), (p.0 + 4, p.1 + 4)], BLACK.filled()))?;
            }
        }
        area.draw(&Circle::new(pa, 4, WHITE.filled()))?;
        area.draw(&Circle::new(pa, 4, BLACK.stroke_width(1)))?;
    }
    let axis = scene.axis_length();
    for (b, limb) in sketch.bodies.iter().enumerate() {
        let (r, p) = (limb.at.position(q), limb.at.orientation(q));
        for (k, colour) in [RED, GREEN, BLUE].into_iter().enumerate() {
            let mut unit = [0.0; 3];
            unit[k] = axis;
            let d = rotate(p, unit);
            area.draw(&PathElement::new(
                vec![at(r), at(std::array::from_fn(|i| r[i] + d[i]))],
                colour.stroke_width(2),
            ))?;
        }
        area.draw(&Circle::new(at(r), 5, COLOURS[b % COLOURS.len()].filled()))?;
        area.draw(&Circle::new(at(r), 5, BLACK.stroke_width(1)))?;
    }
    area.draw(&Text::new(format!("t = {t:.3}"), (8, 6), label))?;
    area.present()
}

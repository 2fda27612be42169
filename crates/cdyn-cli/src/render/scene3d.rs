//! The 3-D scene of a spatial run, shared by the page's animation and the
//! GIF: each body's shapes ([`cdyn::spatial::Visual`]) as flat faces with
//! outward normals and as spheres, in the body's axes, none smaller than a
//! hundredth of the scene so that a point-like body stays visible; the
//! sphere around everything the run's frames show; and the camera both
//! draw through (perspective, orbiting the scene's centre, z up).

use crate::case::frames::Frames;
use cdyn::spatial::{Anchor, Shape, Sketch, Visual, rotation::rotate};
use serde_json::{Value, json};

/// Sides of the polygon a cylinder's round faces are drawn as.
const CYLINDER_SIDES: usize = 16;
/// Squares of the floor grid along each side.
const GRID: usize = 8;
/// Body axes' length, as a fraction of the scene's radius.
const AXES: f64 = 0.12;
/// The smallest size of a drawn shape, as a fraction of the scene's radius.
const SMALLEST: f64 = 0.01;

/// A flat face of a solid: its corners, in order, and its outward normal.
#[derive(Debug, Clone, PartialEq)]
pub struct Face {
    /// Corners, body axes.
    pub corners: Vec<[f64; 3]>,
    /// Outward unit normal, body axes.
    pub normal: [f64; 3],
}

/// One body's solids, in its axes.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Solid {
    /// Faces of its boxes and cylinders.
    pub faces: Vec<Face>,
    /// Its spheres: centre and radius.
    pub spheres: Vec<([f64; 3], f64)>,
}

impl Solid {
    /// Its faces and spheres as the page's data.
    fn json(&self) -> Value {
        json!({
            "faces": self.faces.iter().map(|f| json!({ "corners": f.corners, "normal": f.normal })).collect::<Vec<_>>(),
            "spheres": self.spheres.iter().map(|(c, r)| json!({ "centre": c, "radius": r })).collect::<Vec<_>>(),
        })
    }
}

/// What the run shows: the bodies' solids, and the sphere around every frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// One per body of the sketch.
    pub solids: Vec<Solid>,
    /// The ground's, in space.
    pub ground: Solid,
    /// Centre of the sphere around the bodies and joints in every frame.
    pub centre: [f64; 3],
    /// Its radius.
    pub radius: f64,
    /// The lowest z of a body's centre or joint in any frame: where the floor is drawn.
    pub floor: f64,
}

impl Scene {
    /// The scene of `sketch` over every frame of `runs`.
    pub fn of(sketch: &Sketch, runs: &[&Frames]) -> Scene {
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        let mut take = |p: [f64; 3]| {
            if p.iter().all(|x| x.is_finite()) {
                (lo, hi) = (std::array::from_fn(|i| lo[i].min(p[i])), std::array::from_fn(|i| hi[i].max(p[i])));
            }
        };
        for (frames, k) in runs.iter().flat_map(|f| (0..f.len()).map(move |k| (f, k))) {
            let q = frames.q(k);
            for (b, limb) in sketch.bodies.iter().enumerate() {
                for &point in std::iter::once(&[0.0; 3]).chain(&limb.points) {
                    take(sketch.place(q, &Anchor { body: Some(b), point }));
                }
            }
            for anchor in sketch.joints.iter().flatten() {
                take(sketch.place(q, anchor));
            }
        }
        for v in &sketch.ground {
            take(v.position);
        }
        if !lo[0].is_finite() {
            (lo, hi) = ([-1.0; 3], [1.0; 3]);
        }
        let centre = std::array::from_fn(|i| 0.5 * (lo[i] + hi[i]));
        let half = (0..3).map(|i| (0.5 * (hi[i] - lo[i])).powi(2)).sum::<f64>().sqrt();
        // The shapes reach beyond the points: a body alone is at least its own size.
        let size = sketch.bodies.iter().flat_map(|l| &l.shapes).chain(&sketch.ground).map(extent).fold(0.0, f64::max);
        let radius = (half + 0.5 * size).max(1e-6);
        let smallest = SMALLEST * radius;
        let solid = |shapes: &[Visual]| {
            let mut solid = Solid::default();
            for v in shapes {
                add(&mut solid, v, smallest);
            }
            solid
        };
        let solids = sketch.bodies.iter().map(|limb| solid(&limb.shapes)).collect();
        Scene { solids, ground: solid(&sketch.ground), centre, radius, floor: lo[2] }
    }

    /// The scene and the sketch's bodies and joints as the page's data.
    pub fn json(&self, sketch: &Sketch) -> Value {
        let bodies: Vec<Value> = sketch
            .bodies
            .iter()
            .zip(&self.solids)
            .map(|(limb, solid)| {
                let mut body = solid.json();
                body["name"] = json!(limb.name);
                body["first"] = json!(limb.at.first);
                body["points"] = json!(limb.points);
                body["shaped"] = json!(limb.shaped);
                body
            })
            .collect();
        let joints: Vec<Value> = sketch
            .joints
            .iter()
            .map(|ends| json!(ends.iter().map(|a| json!({ "body": a.body, "point": a.point })).collect::<Vec<_>>()))
            .collect();
        json!({
            "bodies": bodies,
            "joints": joints,
            "ground": self.ground.json(),
            "centre": self.centre,
            "radius": self.radius,
            "grid": self.floor_grid(),
            "axis": self.axis_length(),
        })
    }

    /// The floor: a square grid of lines at [`Scene::floor`] under the scene.
    pub fn floor_grid(&self) -> Vec<[[f64; 3]; 2]> {
        let (c, r, z) = (self.centre, self.radius, self.floor);
        (0..=GRID)
            .flat_map(|k| {
                let s = r * (2.0 * k as f64 / GRID as f64 - 1.0);
                [[[c[0] + s, c[1] - r, z], [c[0] + s, c[1] + r, z]], [[c[0] - r, c[1] + s, z], [c[0] + r, c[1] + s, z]]]
            })
            .collect()
    }

    /// The length of the axes drawn at each body's centre of mass.
    pub fn axis_length(&self) -> f64 {
        AXES * self.radius
    }
}

/// The largest size of a shape.
fn extent(v: &Visual) -> f64 {
    match v.shape {
        Shape::Box { size } => size.iter().map(|s| s * s).sum::<f64>().sqrt(),
        Shape::Cylinder { radius, length } => (4.0 * radius * radius + length * length).sqrt(),
        Shape::Sphere { radius } => 2.0 * radius,
        _ => 0.0,
    }
}

/// Adds the faces or sphere of `v` to `solid`, no side below `smallest`.
fn add(solid: &mut Solid, v: &Visual, smallest: f64) {
    let place = |x: [f64; 3]| -> [f64; 3] {
        let r = rotate(v.orientation, x);
        std::array::from_fn(|i| v.position[i] + r[i])
    };
    let turn = |n: [f64; 3]| rotate(v.orientation, n);
    let mut face = |corners: Vec<[f64; 3]>, normal: [f64; 3]| {
        solid.faces.push(Face { corners: corners.into_iter().map(place).collect(), normal: turn(normal) });
    };
    match v.shape {
        Shape::Box { size } => {
            let h = size.map(|s| 0.5 * s.max(smallest));
            for axis in 0..3 {
                let (u, w) = ((axis + 1) % 3, (axis + 2) % 3);
                for sign in [-1.0, 1.0] {
                    let corner = |a: f64, b: f64| {
                        let mut x = [0.0; 3];
                        (x[axis], x[u], x[w]) = (sign * h[axis], a * h[u], b * h[w]);
                        x
                    };
                    let mut normal = [0.0; 3];
                    normal[axis] = sign;
                    face(vec![corner(-1.0, -1.0), corner(1.0, -1.0), corner(1.0, 1.0), corner(-1.0, 1.0)], normal);
                }
            }
        }
        Shape::Cylinder { radius, length } => {
            let (r, h) = (radius.max(0.5 * smallest), 0.5 * length.max(smallest));
            let rim: Vec<[f64; 2]> = (0..CYLINDER_SIDES)
                .map(|k| {
                    let a = std::f64::consts::TAU * k as f64 / CYLINDER_SIDES as f64;
                    [a.cos(), a.sin()]
                })
                .collect();
            for k in 0..CYLINDER_SIDES {
                let ([c0, s0], [c1, s1]) = (rim[k], rim[(k + 1) % CYLINDER_SIDES]);
                let mid = std::f64::consts::TAU * (k as f64 + 0.5) / CYLINDER_SIDES as f64;
                face(
                    vec![[r * c0, r * s0, -h], [r * c1, r * s1, -h], [r * c1, r * s1, h], [r * c0, r * s0, h]],
                    [mid.cos(), mid.sin(), 0.0],
                );
            }
            for z in [-h, h] {
                face(rim.iter().map(|&[c, s]| [r * c, r * s, z]).collect(), [0.0, 0.0, z.signum()]);
            }
        }
        Shape::Sphere { radius } => solid.spheres.push((place([0.0; 3]), radius.max(0.5 * smallest))),
        _ => {}
    }
}

/// A camera orbiting a scene's centre: `yaw` about z from the x axis and
/// `pitch` above the xy plane (radians), at `zoom` times the distance
/// that shows the whole scene; perspective with a 40° field of view.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    eye: [f64; 3],
    right: [f64; 3],
    up: [f64; 3],
    back: [f64; 3],
    /// Pixels per unit of `x / depth`.
    focal: f64,
    /// The image centre in pixels.
    middle: [f64; 2],
}

/// The default view: from `(1, −1.4, 0.8)`, as the four-instant figure.
pub const YAW: f64 = -0.950_546_84;
/// Its elevation.
pub const PITCH: f64 = 0.435_494_0;
/// How far the camera is, in scene radii, at zoom 1.
const DISTANCE: f64 = 3.0;
/// Half the field of view.
const HALF_FIELD: f64 = 20.0 * std::f64::consts::PI / 180.0;

impl Camera {
    /// The camera looking at `scene` at `(yaw, pitch, zoom)` into an image of `size` pixels.
    pub fn new(scene: &Scene, yaw: f64, pitch: f64, zoom: f64, size: (u32, u32)) -> Camera {
        let back = [pitch.cos() * yaw.cos(), pitch.cos() * yaw.sin(), pitch.sin()];
        let right = [-yaw.sin(), yaw.cos(), 0.0];
        let up = [
            back[1] * right[2] - back[2] * right[1],
            back[2] * right[0] - back[0] * right[2],
            back[0] * right[1] - back[1] * right[0],
        ];
        let distance = DISTANCE * scene.radius / zoom;
        let eye = std::array::from_fn(|i| scene.centre[i] + distance * back[i]);
        let (w, h) = (f64::from(size.0), f64::from(size.1));
        Camera { eye, right, up, back, focal: 0.5 * w.min(h) / HALF_FIELD.tan(), middle: [0.5 * w, 0.5 * h] }
    }

    /// Where `p` is drawn (pixels, y down) and its depth in front of the camera.
    pub fn project(&self, p: [f64; 3]) -> ([f64; 2], f64) {
        let d: [f64; 3] = std::array::from_fn(|i| p[i] - self.eye[i]);
        let dot = |a: [f64; 3]| a[0] * d[0] + a[1] * d[1] + a[2] * d[2];
        let depth = -dot(self.back);
        let z = depth.max(1e-9);
        ([self.middle[0] + self.focal * dot(self.right) / z, self.middle[1] - self.focal * dot(self.up) / z], depth)
    }

    /// Whether a face at `point` with outward normal `normal` (space) faces the camera.
    pub fn sees(&self, point: [f64; 3], normal: [f64; 3]) -> bool {
        (0..3).map(|i| normal[i] * (self.eye[i] - point[i])).sum::<f64>() > 0.0
    }

    /// How brightly a face with this normal is lit (0.45 … 1): by a light over the camera's shoulder.
    pub fn light(&self, normal: [f64; 3]) -> f64 {
        let l: [f64; 3] = std::array::from_fn(|i| self.back[i] + 0.6 * self.up[i] + 0.3 * self.right[i]);
        let n = (l[0] * l[0] + l[1] * l[1] + l[2] * l[2]).sqrt();
        0.45 + 0.55 * ((0..3).map(|i| normal[i] * l[i]).sum::<f64>() / n).abs()
    }

    /// A sphere's radius in pixels at `depth`.
    pub fn pixels(&self, radius: f64, depth: f64) -> f64 {
        self.focal * radius / depth.max(1e-9)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_box_has_six_outward_faces_and_a_cylinder_eighteen() {
        let mut solid = Solid::default();
        add(&mut solid, &Visual::new(Shape::Box { size: [2.0, 1.0, 0.5] }, [1.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0]), 0.0);
        assert_eq!(solid.faces.len(), 6);
        for f in &solid.faces {
            // Each corner lies on the face's plane, on the outer side of the centre (1, 0, 0).
            let c: Vec<f64> =
                f.corners.iter().map(|x| (0..3).map(|i| (x[i] - [1.0, 0.0, 0.0][i]) * f.normal[i]).sum()).collect();
            assert!(c.iter().all(|&d| (d - c[0]).abs() < 1e-15 && d > 0.0), "{f:?}");
        }
        add(
            &mut solid,
            &Visual::new(Shape::Cylinder { radius: 0.1, length: 0.0 }, [0.0; 3], [1.0, 0.0, 0.0, 0.0]),
            0.02,
        );
        assert_eq!(solid.faces.len(), 6 + CYLINDER_SIDES + 2);
        // A flat cylinder is drawn at least `smallest` long.
        let top = &solid.faces[solid.faces.len() - 1];
        assert_eq!((top.normal, top.corners[0][2]), ([0.0, 0.0, 1.0], 0.01));
    }

    #[test]
    fn the_grounds_shapes_are_in_the_scene_and_its_data() {
        let plate = Visual::new(Shape::Box { size: [0.4, 0.4, 0.1] }, [1.0, 2.0, 0.05], [1.0, 0.0, 0.0, 0.0]);
        let sketch = Sketch { ground: vec![plate], ..Sketch::default() };
        let scene = Scene::of(&sketch, &[]);
        // Alone, the plate is the scene: centred on it, as large as it.
        let size = (0.4f64 * 0.4 + 0.4 * 0.4 + 0.1 * 0.1).sqrt();
        assert_eq!((scene.centre, scene.radius), ([1.0, 2.0, 0.05], 0.5 * size));
        let json = scene.json(&sketch);
        let faces = json["ground"]["faces"].as_array().unwrap();
        assert_eq!(faces.len(), 6);
        // Its faces in space: the top at z = 0.1.
        let top = faces.iter().find(|f| f["normal"] == json!([0.0, 0.0, 1.0])).unwrap();
        assert!(top["corners"].as_array().unwrap().iter().all(|c| c[2] == json!(0.1)), "{top}");
    }

    #[test]
    fn the_camera_sees_the_centre_in_the_middle_and_the_near_face() {
        let scene =
            Scene { solids: Vec::new(), ground: Solid::default(), centre: [1.0, 2.0, 3.0], radius: 2.0, floor: 0.0 };
        let cam = Camera::new(&scene, YAW, PITCH, 1.0, (400, 300));
        let (p, depth) = cam.project(scene.centre);
        assert!((p[0] - 200.0).abs() < 1e-9 && (p[1] - 150.0).abs() < 1e-9 && (depth - 6.0).abs() < 1e-12);
        // Up in space is up on the image; the whole scene fits in it.
        let (above, _) = cam.project([1.0, 2.0, 5.0]);
        assert!(above[1] < 150.0 && above[1] > 0.0);
        let towards: [f64; 3] = [1.0, -1.4, 0.8];
        assert!(cam.sees(scene.centre, towards) && !cam.sees(scene.centre, towards.map(|x| -x)));
    }
}

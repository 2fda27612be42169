//! What a body looks like in 3-D views: boxes, cylinders and spheres placed
//! in its axes — the primitive `<visual>` geometry of a URDF link, or, for
//! a body without one, the box of uniform density that has its inertia.

use super::rotation::{compose, rotate, unrotate};

/// A primitive solid, centred on its own origin.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum Shape {
    /// A box with these side lengths along its x, y and z axes.
    Box {
        /// Side lengths.
        size: [f64; 3],
    },
    /// A cylinder about its z axis.
    Cylinder {
        /// Radius.
        radius: f64,
        /// Length along z.
        length: f64,
    },
    /// A sphere.
    Sphere {
        /// Radius.
        radius: f64,
    },
}

/// A shape placed in a body's axes (from its centre of mass).
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct Visual {
    /// The solid.
    pub shape: Shape,
    /// Its origin, in body axes.
    pub position: [f64; 3],
    /// Euler parameters of its axes relative to the body's.
    pub orientation: [f64; 4],
}

impl Visual {
    /// `shape` at `position` with axes turned by `orientation`, in body axes.
    pub fn new(shape: Shape, position: [f64; 3], orientation: [f64; 4]) -> Self {
        Self { shape, position, orientation }
    }

    /// The box of uniform density with a body's `mass` and `inertia` (about its centre, in its axes),
    /// along its principal axes: sides `a² = 6 (J₂ + J₃ − J₁) / m` and
    /// cyclically. Only the size a figure needs, so moments that are not
    /// physical give a side of 0 rather than an error.
    pub fn of_inertia(mass: f64, inertia: &[[f64; 3]; 3]) -> Self {
        let m = nalgebra::Matrix3::from_fn(|a, b| inertia[a][b]);
        let eigen = m.symmetric_eigen();
        let mut axes = eigen.eigenvectors;
        if axes.determinant() < 0.0 {
            axes.column_mut(2).neg_mut();
        }
        let j = eigen.eigenvalues;
        let side = |a: usize| (6.0 * (j[(a + 1) % 3] + j[(a + 2) % 3] - j[a]) / mass).max(0.0).sqrt();
        let q = nalgebra::UnitQuaternion::from_rotation_matrix(&nalgebra::Rotation3::from_matrix_unchecked(axes));
        let finite = |x: f64| if x.is_finite() { x } else { 0.0 };
        Self::new(Shape::Box { size: [side(0), side(1), side(2)].map(finite) }, [0.0; 3], [q.w, q.i, q.j, q.k])
    }

    /// The same visual given in the axes of a frame at `pose` (position and
    /// Euler parameters in space), moved into the axes of a body at `body`.
    pub fn into_body(self, (r, p): ([f64; 3], [f64; 4]), body: ([f64; 3], [f64; 4])) -> Self {
        let at = rotate(p, self.position);
        let space: [f64; 3] = std::array::from_fn(|i| r[i] + at[i] - body.0[i]);
        let inverse = [body.1[0], -body.1[1], -body.1[2], -body.1[3]];
        Self::new(self.shape, unrotate(body.1, space), compose(inverse, compose(p, self.orientation)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spatial::rotation::about;

    #[test]
    fn the_box_of_a_box_inertia_is_that_box() {
        // A 2 × 0.5 × 0.2 box of mass 3, turned 0.7 rad about (1, 2, 2)/3 in body axes.
        let (m, [a, b, c]) = (3.0, [2.0, 0.5, 0.2]);
        let d = [m * (b * b + c * c) / 12.0, m * (a * a + c * c) / 12.0, m * (a * a + b * b) / 12.0];
        let turn = about([1.0 / 3.0, 2.0 / 3.0, 2.0 / 3.0], 0.7);
        let r = |x: [f64; 3]| rotate(turn, x);
        let cols = [r([1.0, 0.0, 0.0]), r([0.0, 1.0, 0.0]), r([0.0, 0.0, 1.0])];
        let inertia =
            std::array::from_fn(|i| std::array::from_fn(|k| (0..3).map(|l| cols[l][i] * d[l] * cols[l][k]).sum()));
        let v = Visual::of_inertia(m, &inertia);
        let Shape::Box { size } = v.shape else { panic!("{v:?}") };
        // Each side along the axis the body's box has it.
        for (side, axis) in size.iter().zip([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]) {
            let along = rotate(v.orientation, axis);
            let k = (0..3).max_by(|&i, &k| {
                let dot = |u: [f64; 3]| (0..3).map(|j| u[j] * along[j]).sum::<f64>().abs();
                dot(cols[i]).total_cmp(&dot(cols[k]))
            });
            assert!((side - [a, b, c][k.unwrap()]).abs() < 1e-12, "{size:?}");
        }
    }

    #[test]
    fn into_body_keeps_the_visual_where_it_is_in_space() {
        let frame = ([0.1, -0.2, 0.3], about([0.0, 0.0, 1.0], 0.4));
        let body = ([1.0, 2.0, -1.0], about([0.6, 0.8, 0.0], -1.1));
        let v = Visual::new(Shape::Sphere { radius: 0.1 }, [0.5, 0.0, 0.2], about([1.0, 0.0, 0.0], 0.3));
        let moved = v.into_body(frame, body);
        let space = |r: [f64; 3], p: [f64; 4], v: &Visual, x: [f64; 3]| {
            let local = rotate(v.orientation, x);
            let at = rotate(p, std::array::from_fn(|i| v.position[i] + local[i]));
            std::array::from_fn::<f64, 3, _>(|i| r[i] + at[i])
        };
        for x in [[0.0; 3], [1.0, 0.0, 0.0], [0.0, 0.3, -0.7]] {
            let (a, b) = (space(frame.0, frame.1, &v, x), space(body.0, body.1, &moved, x));
            assert!((0..3).all(|i| (a[i] - b[i]).abs() < 1e-14), "{a:?} {b:?}");
        }
    }
}

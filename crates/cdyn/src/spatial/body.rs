//! A spatial rigid body: what the user gives, checked, where its seven
//! coordinates are in a mechanism's state, and its rotational kinetic
//! energy as a kinetic element of its Euler parameters.

use super::rotation::{body_rate, g_matrix};
use crate::ad::scalar::Scalar;
use crate::error::{Problem, Result, positive};
use crate::model::kinetic::{Kinetic, Local, VelocityMap};

/// A rigid body as the user describes it, at the initial instant; in a
/// scenario file a `[[bodies]]` entry with these keys (`orientation`,
/// `velocity` and `angular_velocity` may be omitted).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Deserialize), serde(deny_unknown_fields))]
#[non_exhaustive]
pub struct Body {
    /// Its name, for joints, error messages and output; unique, not `ground`.
    pub name: String,
    /// Mass.
    pub mass: f64,
    /// Inertia tensor about the centre of mass, in body axes (symmetric
    /// positive definite, and physical: each principal moment at most the
    /// sum of the other two). Scenario files give the principal moments
    /// `[Ixx, Iyy, Izz]` or the whole tensor `[[..], [..], [..]]`.
    #[cfg_attr(feature = "serde", serde(deserialize_with = "tensor"))]
    pub inertia: [[f64; 3]; 3],
    /// Centre of mass in space.
    pub position: [f64; 3],
    /// Euler parameters of the body axes (scalar first). A unit quaternion
    /// to round-off (within 1e-6 of unit length, then normalized); any
    /// other length is refused rather than guessed at.
    #[cfg_attr(feature = "serde", serde(default = "identity"))]
    pub orientation: [f64; 4],
    /// Velocity of the centre of mass.
    #[cfg_attr(feature = "serde", serde(default))]
    pub velocity: [f64; 3],
    /// Angular velocity, in body axes.
    #[cfg_attr(feature = "serde", serde(default))]
    pub angular_velocity: [f64; 3],
    /// What it looks like in 3-D views (a URDF link's `<visual>` boxes,
    /// cylinders and spheres); none: the box of its inertia. No dynamics.
    #[cfg_attr(feature = "serde", serde(skip))]
    pub visuals: Vec<super::visual::Visual>,
}

crate::setters!(Body {
    /// With `mass`: mass.
    with_mass => mass: f64,
    /// With `inertia`: inertia tensor about the centre of mass, in body axes (symmetric
    with_inertia => inertia: [[f64; 3]; 3],
    /// With `position`: centre of mass in space.
    with_position => position: [f64; 3],
    /// With `orientation`: euler parameters of the body axes (scalar first). A unit quaternion
    with_orientation => orientation: [f64; 4],
    /// With `velocity`: velocity of the centre of mass.
    with_velocity => velocity: [f64; 3],
    /// With `angular_velocity`: angular velocity, in body axes.
    with_angular_velocity => angular_velocity: [f64; 3],
    /// With `visuals`: what it looks like in 3-D views.
    with_visuals => visuals: Vec<super::visual::Visual>,
});

#[cfg(feature = "serde")]
fn identity() -> [f64; 4] {
    [1.0, 0.0, 0.0, 0.0]
}

/// Principal moments `[a, b, c]` or a whole tensor.
#[cfg(feature = "serde")]
fn tensor<'de, D: serde::Deserializer<'de>>(d: D) -> std::result::Result<[[f64; 3]; 3], D::Error> {
    #[derive(serde::Deserialize)]
    #[serde(untagged)]
    enum Given {
        Principal([f64; 3]),
        Full([[f64; 3]; 3]),
    }
    match serde::Deserialize::deserialize(d) {
        Ok(Given::Principal([a, b, c])) => Ok([[a, 0.0, 0.0], [0.0, b, 0.0], [0.0, 0.0, c]]),
        Ok(Given::Full(j)) => Ok(j),
        Err::<Given, D::Error>(_) => Err(serde::de::Error::custom(
            "expected the principal moments [Ixx, Iyy, Izz] or a 3 × 3 tensor [[..], [..], [..]]",
        )),
    }
}

impl Body {
    /// A body at rest at the origin, with principal moments `inertia`.
    pub fn new(name: &str, mass: f64, inertia: [f64; 3]) -> Self {
        Self {
            name: name.to_string(),
            mass,
            inertia: [[inertia[0], 0.0, 0.0], [0.0, inertia[1], 0.0], [0.0, 0.0, inertia[2]]],
            position: [0.0; 3],
            orientation: [1.0, 0.0, 0.0, 0.0],
            velocity: [0.0; 3],
            angular_velocity: [0.0; 3],
            visuals: Vec::new(),
        }
    }

    /// Checks the body; returns its unit orientation.
    pub(crate) fn check(&self) -> Result<[f64; 4]> {
        positive("mass", self.mass)?;
        let finite = |x: &[f64]| x.iter().all(|x| x.is_finite());
        let j = &self.inertia;
        if !j.iter().all(|r| finite(r))
            || (0..3).any(|a| (0..a).any(|b| (j[a][b] - j[b][a]).abs() > 1e-12 * (j[a][a] + j[b][b]).abs()))
        {
            return Err(Problem::Inertia { reason: "must be finite and symmetric" }.into());
        }
        let moments = principal_moments(j);
        if moments.iter().any(|&m| m <= 0.0) {
            return Err(Problem::Inertia { reason: "must be positive definite" }.into());
        }
        let [a, b, c] = moments;
        if c > (a + b) * (1.0 + 1e-12) {
            return Err(Problem::Inertia {
                reason: "is not physical: a principal moment exceeds the sum of the other two",
            }
            .into());
        }
        for (name, x) in [
            ("position", &self.position[..]),
            ("velocity", &self.velocity),
            ("angular_velocity", &self.angular_velocity),
        ] {
            if !finite(x) {
                return Err(Problem::Parameter { name, value: f64::NAN, reason: "must be finite" }.into());
            }
        }
        let norm = self.orientation.iter().map(|x| x * x).sum::<f64>().sqrt();
        if !norm.is_finite() || (norm - 1.0).abs() > 1e-6 {
            return Err(Problem::NotUnitQuaternion { norm }.into());
        }
        Ok(self.orientation.map(|x| x / norm))
    }
}

/// Where a body's coordinates are: `r` at `first .. first + 3`, `p` at
/// `first + 3 .. first + 7`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub struct SpatialBody {
    /// Its first coordinate.
    pub first: usize,
}

impl SpatialBody {
    /// Body `index` of a [`Mechanism`](super::Mechanism).
    pub fn of(index: usize) -> Self {
        Self { first: 7 * index }
    }
    /// Its centre of mass in `q`.
    pub fn position(&self, q: &[f64]) -> [f64; 3] {
        std::array::from_fn(|i| q[self.first + i])
    }
    /// Its Euler parameters in `q`.
    pub fn orientation(&self, q: &[f64]) -> [f64; 4] {
        std::array::from_fn(|i| q[self.first + 3 + i])
    }
    /// The coordinates of its Euler parameters.
    pub fn euler_parameters(&self) -> [usize; 4] {
        std::array::from_fn(|i| self.first + 3 + i)
    }
    /// All seven coordinates.
    pub fn coordinates(&self) -> [usize; 7] {
        std::array::from_fn(|i| self.first + i)
    }
}

/// The names of a body's coordinates: `name.x`, `name.y`, `name.z`, `name.e0` … `name.e3`.
pub fn coordinate_names(name: &str) -> [String; 7] {
    ["x", "y", "z", "e0", "e1", "e2", "e3"].map(|c| format!("{name}.{c}"))
}

/// The principal moments of a symmetric 3 × 3 tensor, ascending.
fn principal_moments(j: &[[f64; 3]; 3]) -> [f64; 3] {
    let m = nalgebra::Matrix3::from_fn(|a, b| j[a][b]);
    let mut e: Vec<f64> = m.symmetric_eigenvalues().iter().copied().collect();
    e.sort_by(f64::total_cmp);
    [e[0], e[1], e[2]]
}

/// The rotational kinetic energy of a body in its Euler parameters,
/// `½ ω′ᵀ J′ ω′ + ½ k (pᵀṗ)²` with `ω′ = 2 G(p) ṗ` (see the module head).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rotation {
    /// `J′`, in body axes.
    pub inertia: [[f64; 3]; 3],
    /// The weight of `(pᵀṗ)²`: `4 tr(J′)/3`, the mean of the block's other
    /// eigenvalues `4 J_i`, so that the block is as well conditioned as the
    /// inertia allows.
    pub k: f64,
}

impl Rotation {
    /// The element for inertia `J′`.
    pub fn new(inertia: [[f64; 3]; 3]) -> Self {
        Self { inertia, k: 4.0 * (inertia[0][0] + inertia[1][1] + inertia[2][2]) / 3.0 }
    }
}

/// The same energy as a velocity map: `w = (ω′, pᵀṗ)`, `J = diag(J′, k)`,
/// which the spatial bodies use (cheaper passes; `tests/spatial.rs`
/// checks it against the [`Kinetic`] form).
impl VelocityMap<4, 4> for Rotation {
    #[inline(always)]
    fn velocities<D: Scalar>(&self, p: [D; 4], pd: [D; 4]) -> [D; 4] {
        let w = body_rate(p, pd);
        [w[0], w[1], w[2], p[0] * pd[0] + p[1] * pd[1] + p[2] * pd[2] + p[3] * pd[3]]
    }

    fn inertia(&self) -> [[f64; 4]; 4] {
        let j = &self.inertia;
        std::array::from_fn(|r| {
            std::array::from_fn(|c| {
                if r < 3 && c < 3 {
                    j[r][c]
                } else if r == 3 && c == 3 {
                    self.k
                } else {
                    0.0
                }
            })
        })
    }

    /// In closed form, with `G = G(p)`, `ω′ = 2Gṗ`, `s = pᵀṗ` (`G(a)b =
    /// −G(b)a`, so `G(a)a = 0`):
    /// * `M = 4GᵀJ′G + k ppᵀ`;
    /// * `∂T/∂p = −2G(ṗ)ᵀJ′ω′ + k s ṗ`, since `ω′ = −2G(ṗ)p`;
    /// * `Ṁṗ = 2G(ṗ)ᵀJ′ω′ + k|ṗ|²p + k s ṗ`, the rate of `∂T/∂ṗ = 2GᵀJ′ω′ + k s p`
    ///   along `p + εṗ` (where `ω′` stays: `G(ṗ)ṗ = 0`).
    ///
    /// About a quarter of the dual passes' instructions (spatial chain: 1.1 k
    /// a body for those); `tests/spatial.rs` checks it against them.
    #[inline(always)]
    fn derivatives(&self, p: [f64; 4], pd: [f64; 4]) -> Local<4> {
        let (g, g_rate, j, k) = (g_matrix(p), g_matrix(pd), &self.inertia, self.k);
        let w = body_rate(p, pd);
        let jw: [f64; 3] = std::array::from_fn(|i| j[i][0] * w[0] + j[i][1] * w[1] + j[i][2] * w[2]);
        let (s, speed2) = ((0..4).map(|c| p[c] * pd[c]).sum::<f64>(), (0..4).map(|c| pd[c] * pd[c]).sum::<f64>());
        let turn: [f64; 4] =
            std::array::from_fn(|c| 2.0 * (g_rate[0][c] * jw[0] + g_rate[1][c] * jw[1] + g_rate[2][c] * jw[2]));
        let jg: [[f64; 4]; 3] =
            std::array::from_fn(|i| std::array::from_fn(|c| j[i][0] * g[0][c] + j[i][1] * g[1][c] + j[i][2] * g[2][c]));
        let mut mass = [[0.0; 4]; 4];
        for a in 0..4 {
            for b in a..4 {
                let m = 4.0 * (g[0][a] * jg[0][b] + g[1][a] * jg[1][b] + g[2][a] * jg[2][b]) + k * p[a] * p[b];
                (mass[a][b], mass[b][a]) = (m, m);
            }
        }
        Local {
            energy: 0.5 * (w[0] * jw[0] + w[1] * jw[1] + w[2] * jw[2] + k * s * s),
            mass,
            grad_q: std::array::from_fn(|c| -turn[c] + k * s * pd[c]),
            mdot_v: std::array::from_fn(|c| turn[c] + k * (speed2 * p[c] + s * pd[c])),
        }
    }
}

impl Kinetic<4> for Rotation {
    fn energy<D: Scalar>(&self, p: [D; 4], pd: [D; 4]) -> D {
        let w = body_rate(p, pd);
        let j = &self.inertia;
        let mut rot = D::zero();
        for a in 0..3 {
            let jw = w[0] * j[a][0] + w[1] * j[a][1] + w[2] * j[a][2];
            rot += w[a] * jw;
        }
        let along = p[0] * pd[0] + p[1] * pd[1] + p[2] * pd[2] + p[3] * pd[3];
        rot * 0.5 + along * along * (0.5 * self.k)
    }
}

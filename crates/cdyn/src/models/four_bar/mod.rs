//! The driven four-bar linkage, optionally shaking a load pendulum; its exact
//! kinematics by circle intersection. In Cartesian body coordinates
//! ([`four_bar`]) and in its three joint angles with the loop closure as
//! two constraint rows ([`four_bar_angles`], `M(q)` from the kinetic energy).
//!
//! Here the parameters; `kinematics` the exact motion of the driven
//! linkage and of its load; `cartesian` and `angles` the two models.
//!
//! May import: `error`, `ad`, `model`, `planar`, `reference` (and the
//! models' shared `parts`).

mod angles;
mod cartesian;
mod kinematics;

pub use angles::four_bar_angles;
pub use cartesian::four_bar;

use crate::error::{Problem, Result, positive};
use crate::models::parts::{LoadPendulum, validate_drive};

/// Which of the two assemblies of a four-bar linkage: joint C lies to the
/// left or to the right of the directed line from B (crank tip) to D
/// (rocker pivot). Exhaustive on purpose (not `#[non_exhaustive]`): the
/// two circles meet in at most two points.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum FourBarBranch {
    /// C to the left of B→D (with A left of D: the "open", C-above assembly).
    #[default]
    Left,
    /// C to the right of B→D: the other assembly.
    Right,
}

/// A four-bar linkage: ground pivots A = (0, 0) and D = (d, 0); crank AB
/// (length a) driven at constant angular speed by a [`Element::DriveAngle`]
/// relative to the ground; coupler BC (length b); rocker DC (length c);
/// revolute joints at A, B, C, D. The crank must turn fully without
/// reaching a toggle position: `|b − c| < d − a` and `d + a < b + c`
/// (Grashof, crank shortest and adjacent to the ground).
///
/// As for [`SliderCrankParams`](super::SliderCrankParams), the driven linkage has no free motion of
/// its own; an optional `load` pendulum hanging from joint C adds one.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
#[non_exhaustive]
pub struct FourBarParams {
    /// Crank length `a` (AB).
    pub crank_length: f64,
    /// Coupler length `b` (BC).
    pub coupler_length: f64,
    /// Rocker length `c` (DC).
    pub rocker_length: f64,
    /// Ground length `d` (AD).
    pub ground_length: f64,
    /// Mass of the crank.
    pub crank_mass: f64,
    /// Moment of inertia of the crank about its centre.
    pub crank_inertia: f64,
    /// Mass of the coupler.
    pub coupler_mass: f64,
    /// Moment of inertia of the coupler about its centre.
    pub coupler_inertia: f64,
    /// Mass of the rocker.
    pub rocker_mass: f64,
    /// Moment of inertia of the rocker about its centre.
    pub rocker_inertia: f64,
    /// Constant crank speed `ω`.
    pub omega: f64,
    /// Initial crank angle from +X.
    pub theta0: f64,
    /// Gravitational acceleration, along −Y.
    pub gravity: f64,
    /// Which of the two assemblies the linkage starts in (and keeps); in
    /// scenario files `branch = "left"` or `"right"`.
    pub branch: FourBarBranch,
    /// Pendulum hanging from joint C; none by default. In scenario files a
    /// `[model.parameters.load]` table (an empty one is the default
    /// [`LoadPendulum`]).
    pub load: Option<LoadPendulum>,
}

crate::setters!(FourBarParams {
    /// With `crank_length`: crank length `a` (AB).
    with_crank_length => crank_length: f64,
    /// With `coupler_length`: coupler length `b` (BC).
    with_coupler_length => coupler_length: f64,
    /// With `rocker_length`: rocker length `c` (DC).
    with_rocker_length => rocker_length: f64,
    /// With `ground_length`: ground length `d` (AD).
    with_ground_length => ground_length: f64,
    /// With `crank_mass`: mass of the crank.
    with_crank_mass => crank_mass: f64,
    /// With `crank_inertia`: moment of inertia of the crank about its centre.
    with_crank_inertia => crank_inertia: f64,
    /// With `coupler_mass`: mass of the coupler.
    with_coupler_mass => coupler_mass: f64,
    /// With `coupler_inertia`: moment of inertia of the coupler about its centre.
    with_coupler_inertia => coupler_inertia: f64,
    /// With `rocker_mass`: mass of the rocker.
    with_rocker_mass => rocker_mass: f64,
    /// With `rocker_inertia`: moment of inertia of the rocker about its centre.
    with_rocker_inertia => rocker_inertia: f64,
    /// With `omega`: constant crank speed `ω`.
    with_omega => omega: f64,
    /// With `theta0`: initial crank angle from +X.
    with_theta0 => theta0: f64,
    /// With `gravity`: gravitational acceleration, along −Y.
    with_gravity => gravity: f64,
    /// With `branch`: which of the two assemblies the linkage starts in (and keeps); in
    with_branch => branch: FourBarBranch,
    /// With `load`: pendulum hanging from joint C; none by default. In scenario files a
    with_load => load: Option<LoadPendulum>,
});

impl Default for FourBarParams {
    /// A Grashof crank-rocker `a = 1, b = 3, c = 2.5, d = 3` (s + l = 4 <
    /// p + q = 5.5, crank shortest), uniform bars of 1 kg/m, ω = 2, the open
    /// assembly, no load.
    fn default() -> Self {
        let bar = |len: f64| (len, len * len * len / 12.0);
        let ((ma, ia), (mb, ib), (mc, ic)) = (bar(1.0), bar(3.0), bar(2.5));
        Self {
            crank_length: 1.0,
            coupler_length: 3.0,
            rocker_length: 2.5,
            ground_length: 3.0,
            crank_mass: ma,
            crank_inertia: ia,
            coupler_mass: mb,
            coupler_inertia: ib,
            rocker_mass: mc,
            rocker_inertia: ic,
            omega: 2.0,
            theta0: 0.0,
            gravity: 9.81,
            branch: FourBarBranch::Left,
            load: None,
        }
    }
}

impl FourBarParams {
    fn validate(&self) -> Result<()> {
        let a = positive("crank_length", self.crank_length)?;
        let b = positive("coupler_length", self.coupler_length)?;
        let c = positive("rocker_length", self.rocker_length)?;
        let d = positive("ground_length", self.ground_length)?;
        if (b - c).abs() >= d - a || d + a >= b + c {
            return Err(Problem::NoFullTurn { lengths: [a, b, c, d] }.into());
        }
        positive("crank_mass", self.crank_mass)?;
        positive("crank_inertia", self.crank_inertia)?;
        positive("coupler_mass", self.coupler_mass)?;
        positive("coupler_inertia", self.coupler_inertia)?;
        positive("rocker_mass", self.rocker_mass)?;
        positive("rocker_inertia", self.rocker_inertia)?;
        validate_drive(self.omega, self.theta0, self.gravity, self.load.as_ref())
    }
}

impl FourBarBranch {
    /// +1 for the left assembly, −1 for the right one.
    fn sign(self) -> f64 {
        match self {
            FourBarBranch::Left => 1.0,
            FourBarBranch::Right => -1.0,
        }
    }
}

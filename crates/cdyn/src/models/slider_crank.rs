//! The driven slider-crank, optionally shaking a load pendulum; its exact kinematics.

use std::f64::consts::PI;

use super::parts::{LoadPendulum, example, load_state, max_acc, rigid_body, validate_drive};
use super::{Example, Reference};
use crate::error::{Error, Result, positive};
use crate::model::timefn::TimeFn;
use crate::planar::{BodyId, Element, Mechanism};

/// A slider-crank: the crank (pinned at the origin) is driven at constant
/// angular speed by a [`Element::DriveAngle`] relative to the ground; the
/// connecting rod joins the crank tip to the slider, which moves on the
/// X axis ([`Element::Prismatic`] with the ground, so it does not turn).
///
/// Without a load the driven slider-crank has no free motion (as many
/// constraints as coordinates): its motion is the kinematics, and the
/// simulation computes the forces and the drive's power. The optional
/// `load` pendulum hanging from the slider adds one free degree of freedom
/// that the drive has to shake.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
#[non_exhaustive]
pub struct SliderCrankParams {
    /// Crank radius `r`.
    pub crank_radius: f64,
    /// Connecting rod length `l > r`.
    pub rod_length: f64,
    /// Mass of the crank.
    pub crank_mass: f64,
    /// About the crank's centre (its midpoint).
    pub crank_inertia: f64,
    /// Mass of the connecting rod.
    pub rod_mass: f64,
    /// About the rod's centre (its midpoint).
    pub rod_inertia: f64,
    /// Mass of the slider.
    pub slider_mass: f64,
    /// Moment of inertia of the slider (it does not turn, but every planar body has one).
    pub slider_inertia: f64,
    /// Constant crank speed `ω`.
    pub omega: f64,
    /// Initial crank angle from +X.
    pub theta0: f64,
    /// Gravitational acceleration, along −Y.
    pub gravity: f64,
    /// Pendulum hanging from the slider's centre; none by default. In
    /// scenario files a `[model.parameters.load]` table (an empty one is the
    /// default [`LoadPendulum`]).
    pub load: Option<LoadPendulum>,
}

crate::setters!(SliderCrankParams {
    /// With `crank_radius`: crank radius `r`.
    with_crank_radius => crank_radius: f64,
    /// With `rod_length`: connecting rod length `l > r`.
    with_rod_length => rod_length: f64,
    /// With `crank_mass`: mass of the crank.
    with_crank_mass => crank_mass: f64,
    /// With `crank_inertia`: about the crank's centre (its midpoint).
    with_crank_inertia => crank_inertia: f64,
    /// With `rod_mass`: mass of the connecting rod.
    with_rod_mass => rod_mass: f64,
    /// With `rod_inertia`: about the rod's centre (its midpoint).
    with_rod_inertia => rod_inertia: f64,
    /// With `slider_mass`: mass of the slider.
    with_slider_mass => slider_mass: f64,
    /// With `slider_inertia`: moment of inertia of the slider (it does not turn, but every planar body has one).
    with_slider_inertia => slider_inertia: f64,
    /// With `omega`: constant crank speed `ω`.
    with_omega => omega: f64,
    /// With `theta0`: initial crank angle from +X.
    with_theta0 => theta0: f64,
    /// With `gravity`: gravitational acceleration, along −Y.
    with_gravity => gravity: f64,
    /// With `load`: pendulum hanging from the slider's centre; none by default. In
    with_load => load: Option<LoadPendulum>,
});

impl Default for SliderCrankParams {
    /// `r = 0.5`, `l = 1.5`, uniform bars of 1 kg/m, a 1 kg slider, one
    /// revolution every π seconds, no load.
    fn default() -> Self {
        Self {
            crank_radius: 0.5,
            rod_length: 1.5,
            crank_mass: 0.5,
            crank_inertia: 0.5 * 0.25 / 12.0,
            rod_mass: 1.5,
            rod_inertia: 1.5 * 2.25 / 12.0,
            slider_mass: 1.0,
            slider_inertia: 0.01,
            omega: 2.0,
            theta0: 0.0,
            gravity: 9.81,
            load: None,
        }
    }
}

impl SliderCrankParams {
    fn validate(&self) -> Result<()> {
        let r = positive("crank_radius", self.crank_radius)?;
        let l = positive("rod_length", self.rod_length)?;
        if l <= r {
            return Err(Error::InvalidParameter {
                name: "rod_length",
                value: l,
                reason: "must exceed the crank radius for the crank to turn",
            });
        }
        positive("crank_mass", self.crank_mass)?;
        positive("crank_inertia", self.crank_inertia)?;
        positive("rod_mass", self.rod_mass)?;
        positive("rod_inertia", self.rod_inertia)?;
        positive("slider_mass", self.slider_mass)?;
        positive("slider_inertia", self.slider_inertia)?;
        validate_drive(self.omega, self.theta0, self.gravity, self.load.as_ref())
    }
}

/// Exact kinematics of the slider-crank at crank angle `θ`, speed `ω`.
#[derive(Debug, Clone, Copy)]
struct SliderCrankState {
    crank: [f64; 6],
    rod: [f64; 6],
    /// Slider `x`, `ẋ`, `ẍ`.
    slider: [f64; 3],
}

fn slider_crank_kinematics(r: f64, l: f64, theta: f64, omega: f64) -> SliderCrankState {
    let (s, c) = theta.sin_cos();
    let root = (l * l - r * r * s * s).sqrt(); // l cos β
    let u = r * r * s * c;
    let x = r * c + root;
    let xd = -omega * (r * s + u / root);
    let xdd = -omega * omega * (r * c + r * r * (c * c - s * s) / root + u * u / root.powi(3));
    let beta = -(r * s / l).asin();
    let beta_d = -r * omega * c / root;
    let b = [r * c, r * s];
    let bd = [-r * omega * s, r * omega * c];
    SliderCrankState {
        crank: [0.5 * b[0], 0.5 * b[1], theta, 0.5 * bd[0], 0.5 * bd[1], omega],
        rod: [0.5 * (b[0] + x), 0.5 * b[1], beta, 0.5 * (bd[0] + xd), 0.5 * bd[1], beta_d],
        slider: [x, xd, xdd],
    }
}

/// Writes crank, rod and slider `(q, v)` (the first 9 coordinates).
fn slider_crank_state(k: &SliderCrankState, q: &mut [f64], v: &mut [f64]) {
    q[..3].copy_from_slice(&k.crank[..3]);
    v[..3].copy_from_slice(&k.crank[3..]);
    q[3..6].copy_from_slice(&k.rod[..3]);
    v[3..6].copy_from_slice(&k.rod[3..]);
    q[6..9].copy_from_slice(&[k.slider[0], 0.0, 0.0]);
    v[6..9].copy_from_slice(&[k.slider[1], 0.0, 0.0]);
}

/// The slider-crank in coordinates `crank.(x, y, angle)`, `rod.(x, y,
/// angle)`, `slider.(x, y, angle)` and, with a load, `load.(x, y)`.
///
/// Observables: `slider.x`, `slider.vx`, `rod.angle`, `load.angle` (with a
/// load; from the downward vertical), then the coordinates. Reference: the
/// exact kinematics, `θ = θ0 + ωt`, `x = r cos θ + √(l² − r² sin² θ)`,
/// `β = −asin(r sin θ / l)` and their rates; the load's angle by a fine RK-4
/// of its equation under the slider's exact acceleration.
pub fn slider_crank(p: SliderCrankParams) -> Result<Example> {
    p.validate()?;
    let (r, l) = (p.crank_radius, p.rod_length);
    let k = slider_crank_kinematics(r, l, p.theta0, p.omega);
    let mut m = Mechanism::new([0.0, -p.gravity]);
    let [cx, cy, ca, cvx, cvy, cw] = k.crank;
    let crank = m.push(rigid_body("crank", p.crank_mass, p.crank_inertia, [cx, cy], ca, [cvx, cvy], cw));
    let [rx, ry, ra, rvx, rvy, rw] = k.rod;
    let rod = m.push(rigid_body("rod", p.rod_mass, p.rod_inertia, [rx, ry], ra, [rvx, rvy], rw));
    let slider =
        m.push(rigid_body("slider", p.slider_mass, p.slider_inertia, [k.slider[0], 0.0], 0.0, [k.slider[1], 0.0], 0.0));
    m.add(Element::Revolute { a: BodyId::Ground, pa: [0.0, 0.0], b: crank, pb: [-0.5 * r, 0.0], limit: None });
    m.add(Element::DriveAngle { a: BodyId::Ground, b: crank, f: TimeFn::linear(p.theta0, p.omega) });
    m.add(Element::Revolute { a: crank, pa: [0.5 * r, 0.0], b: rod, pb: [-0.5 * l, 0.0], limit: None });
    m.add(Element::Revolute { a: rod, pa: [0.5 * l, 0.0], b: slider, pb: [0.0, 0.0], limit: None });
    m.add(Element::Prismatic {
        a: BodyId::Ground,
        pa: [0.0, 0.0],
        b: slider,
        pb: [0.0, 0.0],
        axis: [1.0, 0.0],
        limit: None,
    });
    if let Some(load) = &p.load {
        load.attach(&mut m, slider, [0.0, 0.0], [k.slider[0], 0.0], [k.slider[1], 0.0]);
    }
    let built = m.build()?;

    let (theta0, omega) = (p.theta0, p.omega);
    let acc = move |t: f64| [slider_crank_kinematics(r, l, theta0 + omega * t, omega).slider[2], 0.0];
    let load = p.load.map(|load| {
        let horizon = max_acc(acc, 2.0 * PI / omega.abs().max(1e-3));
        (load, load.motion(p.gravity, omega, acc, horizon))
    });
    let reference: Reference = Box::new(move |t, q, v| {
        let k = slider_crank_kinematics(r, l, theta0 + omega * t, omega);
        slider_crank_state(&k, q, v);
        if let Some((load, ode)) = &load {
            let s = [k.slider[0], 0.0];
            load_state(load, ode.at(t), s, [k.slider[1], 0.0], 9, q, v);
        }
    });
    let has_load = p.load.is_some();
    let first: &[&str] = if has_load {
        &["slider.x", "slider.vx", "rod.angle", "load.angle"]
    } else {
        &["slider.x", "slider.vx", "rod.angle"]
    };
    Ok(example(
        built,
        first,
        move |q, v, out| {
            out[0] = q[6];
            out[1] = v[6];
            out[2] = q[5];
            if has_load {
                out[3] = (q[9] - q[6]).atan2(q[7] - q[10]);
            }
        },
        Some(reference),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::parts::testing::{close, diff};
    #[test]
    fn slider_crank_kinematics_rates_are_the_derivatives() {
        let (r, l, w) = (0.5, 1.5, 2.0);
        for i in 0..40 {
            let t = 0.17 * f64::from(i);
            let k = |t: f64| slider_crank_kinematics(r, l, 0.3 + w * t, w);
            let s = k(t);
            // Rod joins the crank tip and the slider.
            let b = [2.0 * s.crank[0], 2.0 * s.crank[1]];
            close((s.slider[0] - b[0]).hypot(b[1]), l, 1e-14, "rod length");
            close(s.rod[0], 0.5 * (b[0] + s.slider[0]), 1e-14, "rod centre");
            close(s.rod[2], (-b[1]).atan2(s.slider[0] - b[0]), 1e-14, "rod angle");
            for j in 0..3 {
                close(diff(|t| k(t).crank[j], t), s.crank[3 + j], 1e-8, "crank rate");
                close(diff(|t| k(t).rod[j], t), s.rod[3 + j], 1e-8, "rod rate");
            }
            close(diff(|t| k(t).slider[0], t), s.slider[1], 1e-8, "ẋ");
            close(diff(|t| k(t).slider[1], t), s.slider[2], 1e-7, "ẍ");
        }
    }
}

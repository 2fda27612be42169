//! The pendulum on a support driven along prescribed functions of time.

use std::f64::consts::FRAC_PI_2;

use super::parts::{add, dir, example, max_acc, perp, point_body};
use super::{Example, Reference};
use crate::error::{Part, Problem, Result, finite, non_negative, positive};
use crate::model::timefn::TimeFn;
use crate::planar::{Coordinate, Element, Mechanism};
use crate::reference::PendulumExact;
use crate::reference::fine_ode::FineOde;

/// A point mass on a rod from a support point whose `x` and `y` are
/// prescribed functions of time ([`Element::DriveCoordinate`]): the drives
/// exercise `Φ_t` and `Φ_tt`. The rod angle is counter-clockwise from +X,
/// as in [`super::PendulumParams`].
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
#[non_exhaustive]
pub struct MovingSupportParams {
    /// Mass of the (driven) support point.
    pub support_mass: f64,
    /// Mass of the bob.
    pub mass: f64,
    /// Length of the rod.
    pub length: f64,
    /// Gravitational acceleration, along −Y.
    pub gravity: f64,
    /// Support `x(t)`.
    pub support_x: TimeFn,
    /// Support `y(t)`.
    pub support_y: TimeFn,
    /// Initial rod angle from +X (bob relative to the support).
    pub theta0: f64,
    /// Initial angular velocity of the rod.
    pub omega0: f64,
}

crate::setters!(MovingSupportParams {
    /// With `support_mass`: mass of the (driven) support point.
    with_support_mass => support_mass: f64,
    /// With `mass`: mass of the bob.
    with_mass => mass: f64,
    /// With `length`: length of the rod.
    with_length => length: f64,
    /// With `gravity`: gravitational acceleration, along −Y.
    with_gravity => gravity: f64,
    /// With `support_x`: support `x(t)`.
    with_support_x => support_x: TimeFn,
    /// With `support_y`: support `y(t)`.
    with_support_y => support_y: TimeFn,
    /// With `theta0`: initial rod angle from +X (bob relative to the support).
    with_theta0 => theta0: f64,
    /// With `omega0`: initial angular velocity of the rod.
    with_omega0 => omega0: f64,
});

impl Default for MovingSupportParams {
    /// A support accelerating uniformly, `x = 0.5 t + t²`, `y = 0.5 t²`
    /// (`a = (2, 1)`), under `g = 9.81`; the bob 0.5 rad from the bottom, at
    /// rest relative to the support.
    fn default() -> Self {
        Self {
            support_mass: 1.0,
            mass: 1.0,
            length: 1.0,
            gravity: 9.81,
            support_x: TimeFn::polynomial(vec![0.0, 0.5, 1.0]),
            support_y: TimeFn::polynomial(vec![0.0, 0.0, 0.5]),
            theta0: -FRAC_PI_2 + 0.5,
            omega0: 0.0,
        }
    }
}

impl MovingSupportParams {
    /// A support oscillating as `x = ax sin(w t)`, `y = ay sin(w t)`.
    pub fn sinusoidal(ax: f64, ay: f64, w: f64) -> Self {
        let sine = |amp: f64| TimeFn::sine(amp, w, 0.0);
        Self { support_x: sine(ax), support_y: sine(ay), ..Self::default() }
    }

    fn validate(&self) -> Result<()> {
        positive("support_mass", self.support_mass)?;
        positive("mass", self.mass)?;
        positive("length", self.length)?;
        non_negative("gravity", self.gravity)?;
        finite("theta0", self.theta0)?;
        finite("omega0", self.omega0)?;
        for (axis, f) in [("x", &self.support_x), ("y", &self.support_y)] {
            if !f.is_finite() {
                return Err(Problem::NonFiniteFunction.at(Part::Support(axis)));
            }
        }
        Ok(())
    }
}

/// `f(t)`, `f'(t)`, `f''(t)` of a time function, by hand.
fn time_derivatives(f: &TimeFn, t: f64) -> [f64; 3] {
    let mut out = [0.0; 3];
    for (k, &c) in f.polynomial.iter().enumerate() {
        let k = k as i32;
        out[0] += c * t.powi(k);
        if k >= 1 {
            out[1] += c * f64::from(k) * t.powi(k - 1);
        }
        if k >= 2 {
            out[2] += c * f64::from(k * (k - 1)) * t.powi(k - 2);
        }
    }
    for &[amp, w, phase] in &f.sines {
        let (s, c) = (w * t + phase).sin_cos();
        out[0] += amp * s;
        out[1] += amp * w * c;
        out[2] -= amp * w * w * s;
    }
    out
}

/// The constant acceleration of a polynomial of degree ≤ 2 without sines.
fn uniform_acceleration(f: &TimeFn) -> Option<f64> {
    let higher = f.polynomial.iter().skip(3).all(|&c| c == 0.0);
    (f.sines.iter().all(|s| s[0] == 0.0) && higher).then(|| 2.0 * f.polynomial.get(2).copied().unwrap_or(0.0))
}

/// The pendulum on a moving support, coordinates `support.(x, y)`,
/// `bob.(x, y)`.
///
/// Observables: `rel.x`, `rel.y` (bob relative to the support, the
/// pendulum proper), then the coordinates. Reference: for a uniformly
/// accelerated support (both functions polynomials of degree ≤ 2), the
/// motion relative to the support is an ordinary pendulum under the
/// effective gravity `g_eff = (0, −g) − a`: with `ρ` the angle that turns
/// −Y onto `g_eff`, `θ − ρ` obeys `θ̈' = −(|g_eff|/L) cos θ'`, which is
/// [`PendulumExact`]. Otherwise (or on the separatrix) the rod angle by a
/// fine RK-4 of `L θ̈ = g_eff(t) · (−sin θ, cos θ)`.
pub fn moving_support_pendulum(p: MovingSupportParams) -> Result<Example> {
    p.validate()?;
    let (len, th0, om0) = (p.length, p.theta0, p.omega0);
    let [sx, sxd, _] = time_derivatives(&p.support_x, 0.0);
    let [sy, syd, _] = time_derivatives(&p.support_y, 0.0);
    let mut m = Mechanism::new([0.0, -p.gravity]);
    let support = m.push(point_body("support", p.support_mass, [sx, sy], [sxd, syd]));
    let bob = m.push(point_body("bob", p.mass, add([sx, sy], len, dir(th0)), add([sxd, syd], len * om0, perp(th0))));
    for (coordinate, f) in [(Coordinate::X, &p.support_x), (Coordinate::Y, &p.support_y)] {
        m.add(Element::DriveCoordinate { body: support, coordinate, f: f.clone() });
    }
    m.add(Element::Distance { a: support, pa: [0.0, 0.0], b: bob, pb: [0.0, 0.0], length: len });
    let built = m.build()?;

    let (fx, fy) = (p.support_x.clone(), p.support_y.clone());
    let support_at = move |t: f64| (time_derivatives(&fx, t), time_derivatives(&fy, t));
    let write = move |t: f64, theta: f64, omega: f64, q: &mut [f64], v: &mut [f64]| {
        let ([x, xd, _], [y, yd, _]) = support_at(t);
        q[..2].copy_from_slice(&[x, y]);
        v[..2].copy_from_slice(&[xd, yd]);
        q[2..4].copy_from_slice(&add([x, y], len, dir(theta)));
        v[2..4].copy_from_slice(&add([xd, yd], len * omega, perp(theta)));
    };
    let g = p.gravity;
    let exact = match (uniform_acceleration(&p.support_x), uniform_acceleration(&p.support_y)) {
        (Some(ax), Some(ay)) => {
            let geff = [-ax, -g - ay];
            let mag = geff[0].hypot(geff[1]);
            if mag == 0.0 {
                // Weightless in the support frame: uniform rotation.
                Some(None)
            } else {
                let rho = geff[1].atan2(geff[0]) + FRAC_PI_2;
                PendulumExact::new(mag / len, th0 - rho, om0).ok().map(|e| Some((e, rho)))
            }
        }
        _ => None,
    };
    let reference: Reference = match exact {
        Some(Some((e, rho))) => Box::new(move |t, q, v| {
            let (th, om) = e.angle(t);
            write(t, th + rho, om, q, v);
        }),
        Some(None) => Box::new(move |t, q, v| write(t, th0 + om0 * t, om0, q, v)),
        None => {
            let (fx, fy) = (p.support_x.clone(), p.support_y.clone());
            let acc = move |t: f64| [time_derivatives(&fx, t)[2], time_derivatives(&fy, t)[2]];
            let scale = om0.abs()
                + ((g + max_acc(&acc, 10.0)) / len).sqrt()
                + [&p.support_x, &p.support_y]
                    .iter()
                    .flat_map(|f| f.sines.iter().map(|s| s[1].abs()))
                    .fold(0.0, f64::max)
                + 1e-3;
            let ode = FineOde::new(1e-3 / scale, [th0, om0], move |t, [th, w]| {
                let [ax, ay] = acc(t);
                let (s, c) = th.sin_cos();
                [w, (ax * s - (g + ay) * c) / len]
            });
            Box::new(move |t, q, v| {
                let [th, om] = ode.at(t);
                write(t, th, om, q, v);
            })
        }
    };
    Ok(example(
        built,
        &["rel.x", "rel.y"],
        |q, _v, out| {
            out[0] = q[2] - q[0];
            out[1] = q[3] - q[1];
        },
        Some(reference),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::parts::testing::{close, diff};
    #[test]
    fn time_derivatives_by_hand() {
        let f = TimeFn::polynomial(vec![1.0, -2.0, 0.5, 0.25]).with_sines(vec![[0.3, 2.0, 0.1], [-0.2, 5.0, -1.0]]);
        for i in 0..20 {
            let t = 0.3 * f64::from(i) - 2.0;
            let [v, d1, d2] = time_derivatives(&f, t);
            close(v, f.eval(t), 1e-13, "f");
            close(d1, diff(|t| f.eval(t), t), 1e-8, "f'");
            close(d2, diff(|t| time_derivatives(&f, t)[1], t), 1e-8, "f''");
        }
        assert_eq!(uniform_acceleration(&f), None);
        let quad = TimeFn::polynomial(vec![1.0, 2.0, 3.0, 0.0]);
        assert_eq!(uniform_acceleration(&quad), Some(6.0));
    }
}

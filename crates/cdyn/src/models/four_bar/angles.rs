//! The four-bar in its three joint angles, the loop closure as two
//! constraint rows and `M(q)` from the kinetic energy.

use super::FourBarParams;
use super::kinematics::{four_bar_kinematics, load_motion};

use crate::error::Result;
use crate::model::kinetic::Kinetic;
use crate::models::{Example, Reference};
use crate::{Constraint, Model, Potential, Scalar};

/// The loop closure in the joint angles `(θ, β, ψ)`: the coupler's far end
/// `a e(θ) + b e(β)` is the rocker's `(d, 0) + c e(ψ)`.
struct LoopClosure {
    lengths: [f64; 4],
}

impl Constraint<3, 2> for LoopClosure {
    fn eval<D: Scalar>(&self, [theta, beta, psi]: [D; 3], _t: D) -> [D; 2] {
        let [a, b, c, d] = self.lengths;
        [theta.cos() * a + beta.cos() * b - psi.cos() * c - d, theta.sin() * a + beta.sin() * b - psi.sin() * c]
    }
}

/// The crank driven at constant speed: `θ − (θ₀ + ω t) = 0`.
struct CrankDrive {
    theta0: f64,
    omega: f64,
}

impl Constraint<1, 1> for CrankDrive {
    fn eval<D: Scalar>(&self, [theta]: [D; 1], t: D) -> [D; 1] {
        [theta - t * self.omega - self.theta0]
    }
}

/// The coupler's kinetic energy in the crank and coupler angles: its centre
/// moves with `a θ̇ e⊥(θ) + (b/2) β̇ e⊥(β)`, and it turns at `β̇`.
struct CouplerKinetic {
    crank_length: f64,
    length: f64,
    mass: f64,
    inertia: f64,
}

impl Kinetic<2> for CouplerKinetic {
    fn energy<D: Scalar>(&self, [theta, beta]: [D; 2], [w, wb]: [D; 2]) -> D {
        let (a, hb) = (self.crank_length, 0.5 * self.length);
        let vx = -(theta.sin() * w * a) - beta.sin() * wb * hb;
        let vy = theta.cos() * w * a + beta.cos() * wb * hb;
        (vx * vx + vy * vy) * (0.5 * self.mass) + wb * wb * (0.5 * self.inertia)
    }
}

/// The load bob's kinetic energy in the rocker angle and its own angle
/// (from the downward vertical): `c ψ̇ e⊥(ψ) + L φ̇ (cos φ, sin φ)`.
struct LoadKinetic {
    rocker_length: f64,
    length: f64,
    mass: f64,
}

impl Kinetic<2> for LoadKinetic {
    fn energy<D: Scalar>(&self, [psi, phi]: [D; 2], [wp, wf]: [D; 2]) -> D {
        let (c, l) = (self.rocker_length, self.length);
        let vx = -(psi.sin() * wp * c) + phi.cos() * wf * l;
        let vy = psi.cos() * wp * c + phi.sin() * wf * l;
        (vx * vx + vy * vy) * (0.5 * self.mass)
    }
}

/// Gravity on the bars' centres and the load in the angles `(θ, β, ψ, φ)`.
struct FourBarWeight {
    lengths: [f64; 4],
    /// Crank, coupler, rocker, load masses (the load's zero without a load).
    masses: [f64; 4],
    load_length: f64,
    gravity: f64,
}

impl Potential<4> for FourBarWeight {
    fn energy<D: Scalar>(&self, [theta, beta, psi, phi]: [D; 4]) -> D {
        let [a, b, c, _] = self.lengths;
        let [ma, mb, mc, ml] = self.masses;
        let heights =
            theta.sin() * (0.5 * a * ma + a * mb) + beta.sin() * (0.5 * b * mb) + psi.sin() * (0.5 * c * mc + c * ml)
                - phi.cos() * (self.load_length * ml);
        heights * self.gravity
    }
}

/// The four-bar in its joint angles `q = (θ, β, ψ)` — crank, coupler and
/// rocker angles from +X, as in [`four_bar`](super::four_bar) — and, with a load, the load
/// pendulum's angle `φ` from the downward vertical. Constraints: the crank
/// drive and the loop closure (two rows). The crank's and rocker's inertia
/// about their pivots is constant (`m l²/4 + I` on the diagonal); the
/// coupler's and the load's kinetic energies are elements, so `M(q)` is
/// full where they couple the angles.
///
/// Observables and reference as for [`four_bar`](super::four_bar): `rocker.angle`,
/// `coupler.angle`, `rocker.rate`, `load.angle` (with a load), then the angles.
pub fn four_bar_angles(p: FourBarParams) -> Result<Example> {
    p.validate()?;
    let dims = [p.crank_length, p.coupler_length, p.rocker_length, p.ground_length];
    let [a, b, c, _] = dims;
    let sigma = p.branch.sign();
    let k = four_bar_kinematics(dims, sigma, p.theta0, p.omega);
    let pivot = |m: f64, l: f64, i: f64| m * l * l / 4.0 + i;
    let mut diagonal = vec![pivot(p.crank_mass, a, p.crank_inertia), 0.0, pivot(p.rocker_mass, c, p.rocker_inertia)];
    let (mut q0, mut v0) = (k.angle.to_vec(), k.rate.to_vec());
    if let Some(load) = &p.load {
        diagonal.push(0.0);
        q0.push(load.angle);
        v0.push(load.omega);
    }
    let coupler = CouplerKinetic { crank_length: a, length: b, mass: p.coupler_mass, inertia: p.coupler_inertia };
    let mut builder = Model::builder(diagonal)
        .constrain(CrankDrive { theta0: p.theta0, omega: p.omega }, [0])
        .constrain(LoopClosure { lengths: dims }, [0, 1, 2])
        .kinetic(coupler, [0, 1]);
    let (load_mass, load_length) = p.load.map_or((0.0, 0.0), |l| (l.mass, l.length));
    let weight = |masses, load_length| FourBarWeight { lengths: dims, masses, load_length, gravity: p.gravity };
    let masses = [p.crank_mass, p.coupler_mass, p.rocker_mass, load_mass];
    builder = match p.load {
        Some(load) => builder
            .kinetic(LoadKinetic { rocker_length: c, length: load.length, mass: load.mass }, [2, 3])
            .potential(weight(masses, load_length), [0, 1, 2, 3]),
        // Without a load the fourth angle does not exist; its term is zero.
        None => builder.potential(WithoutLoad(weight(masses, 0.0)), [0, 1, 2]),
    };
    let model = builder.build()?;
    let (theta0, omega) = (p.theta0, p.omega);
    let load = load_motion(&p, sigma);
    let reference: Reference = Box::new(move |t, q, v| {
        let k = four_bar_kinematics(dims, sigma, theta0 + omega * t, omega);
        q[..3].copy_from_slice(&k.angle);
        v[..3].copy_from_slice(&k.rate);
        if let Some((_, ode)) = &load {
            [q[3], v[3]] = ode.at(t);
        }
    });
    let has_load = p.load.is_some();
    let mut observables = vec!["rocker.angle", "coupler.angle", "rocker.rate"];
    if has_load {
        observables.push("load.angle");
    }
    observables.extend(["theta", "beta", "psi", "phi"].into_iter().take(model.n()));
    Ok(Example {
        model,
        q0,
        v0,
        observables: observables.into_iter().map(String::from).collect(),
        observe: Box::new(move |_t, q, v, out| {
            out[..3].copy_from_slice(&[q[2], q[1], v[2]]);
            let k = if has_load {
                out[3] = q[3].sin().atan2(q[3].cos());
                4
            } else {
                3
            };
            out[k..].copy_from_slice(q);
        }),
        reference: Some(reference),
        drawing: None,
        sketch: None,
    })
}

/// [`FourBarWeight`] on the three bar angles alone.
struct WithoutLoad(FourBarWeight);

impl Potential<3> for WithoutLoad {
    fn energy<D: Scalar>(&self, [theta, beta, psi]: [D; 3]) -> D {
        self.0.energy([theta, beta, psi, D::zero()])
    }
}

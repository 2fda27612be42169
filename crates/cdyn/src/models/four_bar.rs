//! The driven four-bar linkage, optionally shaking a load pendulum; its exact
//! kinematics by circle intersection. In Cartesian body coordinates
//! ([`four_bar`]) and in its three joint angles with the loop closure as
//! two constraint rows ([`four_bar_angles`], `M(q)` from the kinetic energy).

use std::f64::consts::PI;

use super::parts::{LoadPendulum, add, dir, example, load_state, max_acc, perp, rigid_body, validate_drive};
use super::{Example, Reference};
use crate::error::{Problem, Result, positive};
use crate::model::kinetic::Kinetic;
use crate::model::timefn::TimeFn;
use crate::planar::{BodyId, Element, Mechanism};
use crate::{Constraint, Model, Potential, Scalar};

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

/// Exact kinematics of the four-bar at crank angle `θ`, speed `ω`.
#[derive(Debug, Clone, Copy)]
struct FourBarState {
    /// Angles of crank, coupler, rocker.
    angle: [f64; 3],
    /// Their rates.
    rate: [f64; 3],
    /// Acceleration of joint C.
    c_acc: [f64; 2],
}

fn four_bar_kinematics([a, b, c, d]: [f64; 4], sigma: f64, theta: f64, omega: f64) -> FourBarState {
    // Circle intersection: C at distance b from B and c from D. The
    // direction B→D never reverses (D is outside the crank circle), so the
    // angles below are continuous in θ.
    let bp = [a * theta.cos(), a * theta.sin()];
    let bd = [d - bp[0], -bp[1]];
    let e2 = bd[0] * bd[0] + bd[1] * bd[1];
    let e = e2.sqrt();
    let toward_d = bd[1].atan2(bd[0]);
    let at_b = ((e2 + b * b - c * c) / (2.0 * e * b)).clamp(-1.0, 1.0).acos();
    let at_d = ((e2 + c * c - b * b) / (2.0 * e * c)).clamp(-1.0, 1.0).acos();
    let beta = toward_d + sigma * at_b;
    let psi = toward_d + PI - sigma * at_d;
    // Loop closure a e(θ) + b e(β) = d e_x + c e(ψ), differentiated:
    // a ω e⊥(θ) + b β̇ e⊥(β) = c ψ̇ e⊥(ψ); e⊥(x)·e(y) = sin(y − x).
    let s_bp = (beta - psi).sin();
    let psi_d = a * omega * (beta - theta).sin() / (c * s_bp);
    let beta_d = a * omega * (psi - theta).sin() / (b * s_bp);
    // Once more (θ̈ = 0), dotted with e(β):
    // −a ω² cos(θ − β) − b β̇² = c ψ̈ sin(β − ψ) − c ψ̇² cos(ψ − β).
    let psi_dd = (-a * omega * omega * (theta - beta).cos() - b * beta_d * beta_d
        + c * psi_d * psi_d * (psi - beta).cos())
        / (c * s_bp);
    let (ep, np) = (dir(psi), perp(psi));
    FourBarState {
        angle: [theta, beta, psi],
        rate: [omega, beta_d, psi_d],
        c_acc: [c * (psi_dd * np[0] - psi_d * psi_d * ep[0]), c * (psi_dd * np[1] - psi_d * psi_d * ep[1])],
    }
}

/// Writes crank, coupler, rocker `(q, v)` (the first 9 coordinates) and
/// returns joint C's position and velocity.
fn four_bar_state([a, b, c, d]: [f64; 4], k: &FourBarState, q: &mut [f64], v: &mut [f64]) -> ([f64; 2], [f64; 2]) {
    let [theta, beta, psi] = k.angle;
    let [w, beta_d, psi_d] = k.rate;
    let bp = add([0.0, 0.0], a, dir(theta));
    let bv = add([0.0, 0.0], a * w, perp(theta));
    let crank = (add([0.0, 0.0], 0.5 * a, dir(theta)), add([0.0, 0.0], 0.5 * a * w, perp(theta)));
    let coupler = (add(bp, 0.5 * b, dir(beta)), add(bv, 0.5 * b * beta_d, perp(beta)));
    let rocker = (add([d, 0.0], 0.5 * c, dir(psi)), add([0.0, 0.0], 0.5 * c * psi_d, perp(psi)));
    for (i, ((p, pv), angle, rate)) in
        [(crank, theta, w), (coupler, beta, beta_d), (rocker, psi, psi_d)].into_iter().enumerate()
    {
        q[3 * i..3 * i + 3].copy_from_slice(&[p[0], p[1], angle]);
        v[3 * i..3 * i + 3].copy_from_slice(&[pv[0], pv[1], rate]);
    }
    (add([d, 0.0], c, dir(psi)), add([0.0, 0.0], c * psi_d, perp(psi)))
}

/// The four-bar in coordinates `crank.(x, y, angle)`, `coupler.(x, y,
/// angle)`, `rocker.(x, y, angle)` and, with a load, `load.(x, y)`.
///
/// Observables: `rocker.angle`, `coupler.angle`, `rocker.rate`, `load.angle`
/// (with a load; from the downward vertical), then the coordinates.
/// Reference: the exact kinematics by circle intersection on the chosen
/// branch, rates and accelerations from the differentiated loop closure;
/// the load's angle by a fine RK-4 under joint C's exact acceleration.
pub fn four_bar(p: FourBarParams) -> Result<Example> {
    p.validate()?;
    let dims = [p.crank_length, p.coupler_length, p.rocker_length, p.ground_length];
    let [a, b, c, d] = dims;
    let sigma = p.branch.sign();
    let k = four_bar_kinematics(dims, sigma, p.theta0, p.omega);
    let (mut q0, mut v0) = ([0.0; 9], [0.0; 9]);
    let (cp, cv) = four_bar_state(dims, &k, &mut q0, &mut v0);
    let mut m = Mechanism::new([0.0, -p.gravity]);
    let mut body = |name: &str, mass, inertia, i: usize| {
        m.push(rigid_body(
            name,
            mass,
            inertia,
            [q0[3 * i], q0[3 * i + 1]],
            q0[3 * i + 2],
            [v0[3 * i], v0[3 * i + 1]],
            v0[3 * i + 2],
        ))
    };
    let crank = body("crank", p.crank_mass, p.crank_inertia, 0);
    let coupler = body("coupler", p.coupler_mass, p.coupler_inertia, 1);
    let rocker = body("rocker", p.rocker_mass, p.rocker_inertia, 2);
    m.add(Element::Revolute { a: BodyId::Ground, pa: [0.0, 0.0], b: crank, pb: [-0.5 * a, 0.0] });
    m.add(Element::DriveAngle { a: BodyId::Ground, b: crank, f: TimeFn::linear(p.theta0, p.omega) });
    m.add(Element::Revolute { a: crank, pa: [0.5 * a, 0.0], b: coupler, pb: [-0.5 * b, 0.0] });
    m.add(Element::Revolute { a: coupler, pa: [0.5 * b, 0.0], b: rocker, pb: [0.5 * c, 0.0] });
    m.add(Element::Revolute { a: BodyId::Ground, pa: [d, 0.0], b: rocker, pb: [-0.5 * c, 0.0] });
    if let Some(load) = &p.load {
        load.attach(&mut m, rocker, [0.5 * c, 0.0], cp, cv);
    }
    let built = m.build()?;

    let (theta0, omega) = (p.theta0, p.omega);
    let load = load_motion(&p, sigma);
    let reference: Reference = Box::new(move |t, q, v| {
        let k = four_bar_kinematics(dims, sigma, theta0 + omega * t, omega);
        let (cp, cv) = four_bar_state(dims, &k, q, v);
        if let Some((load, ode)) = &load {
            load_state(load, ode.at(t), cp, cv, 9, q, v);
        }
    });
    let has_load = p.load.is_some();
    let first: &[&str] = if has_load {
        &["rocker.angle", "coupler.angle", "rocker.rate", "load.angle"]
    } else {
        &["rocker.angle", "coupler.angle", "rocker.rate"]
    };
    Ok(example(
        built,
        first,
        move |q, v, out| {
            out[0] = q[8];
            out[1] = q[5];
            out[2] = v[8];
            if has_load {
                // C is the rocker's far end.
                let cp = add([q[6], q[7]], 0.5 * c, dir(q[8]));
                out[3] = (q[9] - cp[0]).atan2(cp[1] - q[10]);
            }
        },
        Some(reference),
    ))
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

/// The load pendulum and its fine motion under joint C's exact
/// acceleration, when there is a load.
fn load_motion(p: &FourBarParams, sigma: f64) -> Option<(LoadPendulum, crate::reference::fine_ode::FineOde<2>)> {
    let dims = [p.crank_length, p.coupler_length, p.rocker_length, p.ground_length];
    let (theta0, omega) = (p.theta0, p.omega);
    let acc = move |t: f64| four_bar_kinematics(dims, sigma, theta0 + omega * t, omega).c_acc;
    p.load.map(|load| {
        let horizon = max_acc(acc, 2.0 * PI / omega.abs().max(1e-3));
        (load, load.motion(p.gravity, omega, acc, horizon))
    })
}

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
/// rocker angles from +X, as in [`four_bar`] — and, with a load, the load
/// pendulum's angle `φ` from the downward vertical. Constraints: the crank
/// drive and the loop closure (two rows). The crank's and rocker's inertia
/// about their pivots is constant (`m l²/4 + I` on the diagonal); the
/// coupler's and the load's kinetic energies are elements, so `M(q)` is
/// full where they couple the angles.
///
/// Observables and reference as for [`four_bar`]: `rocker.angle`,
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
        observe: Box::new(move |q, v, out| {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::parts::testing::{close, diff};
    #[test]
    fn four_bar_kinematics_close_the_loop_and_rates_are_the_derivatives() {
        let dims @ [a, b, c, d] = [1.0, 3.0, 2.5, 3.0];
        for sigma in [1.0, -1.0] {
            for i in 0..60 {
                let t = 0.13 * f64::from(i);
                let k = |t: f64| four_bar_kinematics(dims, sigma, 0.4 + 2.0 * t, 2.0);
                let s = k(t);
                let [th, be, ps] = s.angle;
                let bp = add([0.0, 0.0], a, dir(th));
                let c1 = add(bp, b, dir(be));
                let c2 = add([d, 0.0], c, dir(ps));
                close(c1[0], c2[0], 1e-13, "loop x");
                close(c1[1], c2[1], 1e-13, "loop y");
                // C on the chosen side of B→D.
                let cross = (d - bp[0]) * (c1[1] - bp[1]) - (-bp[1]) * (c1[0] - bp[0]);
                assert!(cross * sigma > 0.0, "branch");
                for j in 0..3 {
                    close(diff(|t| k(t).angle[j], t), s.rate[j], 1e-8, "rate");
                }
                let cpos = |t: f64| add([d, 0.0], c, dir(k(t).angle[2]));
                let cvel = |t: f64, j: usize| diff(|t| cpos(t)[j], t);
                for j in 0..2 {
                    close(diff(|t| cvel(t, j), t), s.c_acc[j], 1e-4, "C acceleration");
                }
            }
        }
    }
}

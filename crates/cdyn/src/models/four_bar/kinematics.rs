//! The exact motion of the driven four-bar: joint C by circle intersection
//! on the chosen branch, rates and accelerations from the differentiated
//! loop closure, and the load pendulum's fine motion under C's acceleration.

use super::FourBarParams;
use std::f64::consts::PI;

use crate::models::parts::{LoadPendulum, add, dir, max_acc, perp};

/// Exact kinematics of the four-bar at crank angle `θ`, speed `ω`.
#[derive(Debug, Clone, Copy)]
pub(super) struct FourBarState {
    /// Angles of crank, coupler, rocker.
    pub(super) angle: [f64; 3],
    /// Their rates.
    pub(super) rate: [f64; 3],
    /// Acceleration of joint C.
    pub(super) c_acc: [f64; 2],
}

pub(super) fn four_bar_kinematics([a, b, c, d]: [f64; 4], sigma: f64, theta: f64, omega: f64) -> FourBarState {
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
pub(super) fn four_bar_state(
    [a, b, c, d]: [f64; 4],
    k: &FourBarState,
    q: &mut [f64],
    v: &mut [f64],
) -> ([f64; 2], [f64; 2]) {
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

/// The load pendulum and its fine motion under joint C's exact
/// acceleration, when there is a load.
pub(super) fn load_motion(
    p: &FourBarParams,
    sigma: f64,
) -> Option<(LoadPendulum, crate::reference::fine_ode::FineOde<2>)> {
    let dims = [p.crank_length, p.coupler_length, p.rocker_length, p.ground_length];
    let (theta0, omega) = (p.theta0, p.omega);
    let acc = move |t: f64| four_bar_kinematics(dims, sigma, theta0 + omega * t, omega).c_acc;
    p.load.map(|load| {
        let horizon = max_acc(acc, 2.0 * PI / omega.abs().max(1e-3));
        (load, load.motion(p.gravity, omega, acc, horizon))
    })
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

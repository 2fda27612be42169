//! Andrews' squeezing mechanism, the standard benchmark of the Test Set for
//! IVP Solvers (University of Bari, problem `andr`; Hairer & Wanner, Solving
//! ODEs II, §VII.7), described as seven rigid bodies with revolute joints,
//! a spring and a driving torque.
//!
//! The test set writes it in seven relative angles `q = (β, Θ, γ, Φ, δ, Ω, ε)`
//! with a configuration-dependent mass matrix and six loop-closure
//! constraints. Here every body has its own `(x, y, φ)` with a diagonal mass
//! matrix; the geometry below is read off the test set's constraints and
//! mass matrix (see `constants`):
//!
//! | body | angle φ | turns about | centre of mass |
//! |---|---|---|---|
//! | 1 | β | O = (0, 0) | at `ra` from O towards P |
//! | 2 | β + Θ | P, the tip of 1 (`rr` from O) | at `da` from P towards E (`d` from P) |
//! | 3 | γ | B | at √(sa² + sb²) from B |
//! | 4 | Φ + δ | F, on 5 (`zt` from A) | at `e − ea` from F towards E (`e` from F) |
//! | 5 | δ | A | at √(ta² + tb²) from A |
//! | 6 | Ω + ε | G, on 7 (`u` from A) | at `zf − fa` from G towards E (`zf` from G) |
//! | 7 | ε | A | at √(ua² + ub²) from A |
//!
//! Bodies 3, 4 and 6 meet body 2 at E: those three joints are the test
//! set's loop closures `g₁…g₆`, written here with the same sign
//! (`E on 2 − E on the other`), so their multipliers are the published `λ`.
//! Without gravity, where a body's centre of mass lies in its own frame
//! (only its distance to the pivot) does not change the motion.

use super::Example;
use crate::error::Result;
use crate::model::timefn::TimeFn;
use crate::planar::{BodyId, Element, Mechanism};

/// The test set's constants (SI units), from `andrews.f`, with every published digit.
// The names are the test set's own (see its problem description); a doc
// line each would only repeat them.
#[allow(clippy::excessive_precision, missing_docs)]
pub mod constants {
    pub const M: [f64; 7] = [0.04325, 0.00365, 0.02373, 0.00706, 0.07050, 0.00706, 0.05498];
    pub const I: [f64; 7] = [2.194e-6, 4.410e-7, 5.255e-6, 5.667e-7, 1.169e-5, 5.667e-7, 1.912e-5];
    pub const XA: f64 = -0.06934;
    pub const YA: f64 = -0.00227;
    pub const XB: f64 = -0.03635;
    pub const YB: f64 = 0.03273;
    pub const XC: f64 = 0.014;
    pub const YC: f64 = 0.072;
    pub const C0: f64 = 4530.0;
    pub const D: f64 = 28e-3;
    pub const DA: f64 = 115e-4;
    pub const E: f64 = 2e-2;
    pub const EA: f64 = 1421e-5;
    pub const RR: f64 = 7e-3;
    pub const RA: f64 = 92e-5;
    pub const L0: f64 = 7785e-5;
    pub const SS: f64 = 35e-3;
    pub const SA: f64 = 1874e-5;
    pub const SB: f64 = 1043e-5;
    pub const SC: f64 = 18e-3;
    pub const SD: f64 = 2e-2;
    pub const TA: f64 = 2308e-5;
    pub const TB: f64 = 916e-5;
    pub const U: f64 = 4e-2;
    pub const UA: f64 = 1228e-5;
    pub const UB: f64 = 449e-5;
    pub const ZF: f64 = 2e-2;
    pub const ZT: f64 = 4e-2;
    pub const FA: f64 = 1421e-5;
    pub const MOM: f64 = 33e-3;

    /// Consistent initial angles `(β, Θ, γ, Φ, δ, Ω, ε)` at t = 0; velocities are 0.
    pub const Q0: [f64; 7] = [
        -0.0617138900142764496358948458001,
        0.0,
        0.455279819163070380255912382449,
        0.222668390165885884674473185609,
        0.487364979543842550225598953530,
        -0.222668390165885884674473185609,
        1.23054744454982119249735015568,
    ];
    /// Published accelerations `q̈(0)`.
    pub const ACC0: [f64; 7] =
        [14222.4439199541138705911625887, -10666.8329399655854029433719415, 0.0, 0.0, 0.0, 0.0, 0.0];
    /// Published multipliers `λ(0)` of the six loop-closure constraints.
    pub const LAMBDA0: [f64; 6] =
        [98.5668703962410896057654982170, -6.12268834425566265503114393122, 0.0, 0.0, 0.0, 0.0];
    /// Published reference angles at t = 0.03 (PSIDE, tolerance 1e-14).
    pub const Q_REF_003: [f64; 7] = [
        0.1581077119629904e+2,
        -0.1575637105984298e+2,
        0.4082224013073101e-1,
        -0.5347301163226948e+0,
        0.5244099658805304e+0,
        0.5347301163226948e+0,
        0.1048080741042263e+1,
    ];
}

use constants::*;

/// `R(φ) p`.
fn rot(phi: f64, [x, y]: [f64; 2]) -> [f64; 2] {
    let (s, c) = phi.sin_cos();
    [c * x - s * y, s * x + c * y]
}

fn add(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] + b[0], a[1] + b[1]]
}

fn neg([x, y]: [f64; 2]) -> [f64; 2] {
    [-x, -y]
}

/// The mechanism, at the test set's initial angles `q0`.
pub fn mechanism(q0: [f64; 7]) -> Mechanism {
    let [beta, theta, gamma, phi, delta, omega, eps] = q0;
    let (a, b) = ([XA, YA], [XB, YB]);
    // Centres of mass in each body's frame, relative to its pivot.
    let c1 = [RA, 0.0];
    let c3 = [SA, SB];
    let c5 = [TA, TB];
    let c7 = [UA, UB];
    // Points in body frames relative to the centre of mass.
    let body1_o = neg(c1);
    let body1_p = [RR - RA, 0.0];
    let (body2_p, body2_e) = ([DA, 0.0], [DA - D, 0.0]);
    let (body3_b, body3_e, body3_d) = (neg(c3), add([0.0, -SS], neg(c3)), add([SD, -SC], neg(c3)));
    let (body4_f, body4_e) = ([0.0, E - EA], [0.0, -EA]);
    let (body5_a, body5_f) = (neg(c5), add([ZT, 0.0], neg(c5)));
    let (body6_g, body6_e) = ([-(ZF - FA), 0.0], [FA, 0.0]);
    let (body7_a, body7_g) = (neg(c7), add([0.0, -U], neg(c7)));

    let angles = [beta, beta + theta, gamma, phi + delta, delta, omega + eps, eps];
    let p = rot(beta, [RR, 0.0]);
    let f = add(a, rot(delta, [ZT, 0.0]));
    let g = add(a, rot(eps, [0.0, -U]));
    let centres = [
        rot(beta, c1),
        add(p, rot(angles[1], [-DA, 0.0])),
        add(b, rot(gamma, c3)),
        add(f, rot(angles[3], [0.0, -(E - EA)])),
        add(a, rot(delta, c5)),
        add(g, rot(angles[5], [ZF - FA, 0.0])),
        add(a, rot(eps, c7)),
    ];
    let mut m = Mechanism::new([0.0, 0.0]);
    let ids: Vec<BodyId> =
        (0..7).map(|i| m.rigid(&format!("body{}", i + 1), M[i], I[i], centres[i], angles[i])).collect();
    let ground = BodyId::Ground;
    let rev = |a, pa, b, pb| Element::Revolute { a, pa, b, pb, limit: None };
    m.add(rev(ground, [0.0, 0.0], ids[0], body1_o))
        .add(rev(ids[0], body1_p, ids[1], body2_p))
        // The three loop closures, as g₁…g₆: E on body 2 minus E on 3, 4, 6.
        .add(rev(ids[1], body2_e, ids[2], body3_e))
        .add(rev(ids[1], body2_e, ids[3], body4_e))
        .add(rev(ids[1], body2_e, ids[5], body6_e))
        .add(rev(ground, b, ids[2], body3_b))
        .add(rev(ids[3], body4_f, ids[4], body5_f))
        .add(rev(ground, a, ids[4], body5_a))
        .add(rev(ids[5], body6_g, ids[6], body7_g))
        .add(rev(ground, a, ids[6], body7_a))
        .add(Element::Spring { a: ids[2], pa: body3_d, b: ground, pb: [XC, YC], stiffness: C0, rest_length: L0 })
        .add(Element::AppliedTorque { body: ids[0], f: TimeFn::constant(MOM) });
    m
}

/// Rows of the loop-closure joints (`g₁…g₆`) in the model's constraint vector.
pub const CLOSURE_ROWS: std::ops::Range<usize> = 4..10;

/// The test set's angles `(β, Θ, γ, Φ, δ, Ω, ε)` from body angles `φ₁…φ₇`
/// (or their rates, or accelerations: the map is linear).
pub fn test_set_angles(phi: [f64; 7]) -> [f64; 7] {
    [phi[0], phi[1] - phi[0], phi[2], phi[3] - phi[4], phi[4], phi[5] - phi[6], phi[6]]
}

/// The body angles `φ₁…φ₇` of a state of the built model.
pub fn body_angles(q: &[f64]) -> [f64; 7] {
    std::array::from_fn(|i| q[3 * i + 2])
}

/// Andrews' mechanism at the test set's initial state. Observables are the
/// test set's seven angles.
pub fn andrews() -> Result<Example> {
    let built = mechanism(Q0).build()?;
    Ok(Example {
        model: built.model,
        q0: built.q0,
        v0: built.v0,
        observables: ["beta", "Theta", "gamma", "Phi", "delta", "Omega", "epsilon"].map(String::from).to_vec(),
        observe: Box::new(|_t, q, _v, out| out.copy_from_slice(&test_set_angles(body_angles(q)))),
        reference: None,
        drawing: Some(built.drawing),
        sketch: None,
    })
}

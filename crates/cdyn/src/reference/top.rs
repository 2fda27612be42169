//! Euler's torque-free rigid body in closed form, the reference of the
//! rigid-body tests.

use super::elliptic;

/// Euler's torque-free motion of a rigid body with principal moments
/// `J₁ < J₂ < J₃` from the body angular velocity `ω(0) = (a, 0, c)` (the
/// motion about the third axis): `ω(t) = (a cn, b sn, c dn)(s t; k)`, with
/// `s`, `b` and `k` from Euler's equations. The shared reference of the
/// rigid-body tests.
pub fn torque_free_rate([j1, j2, j3]: [f64; 3], [a, c]: [f64; 2], t: f64) -> [f64; 3] {
    let s = ((j3 - j2) * (j3 - j1) / (j1 * j2)).sqrt() * c;
    let b = j1 * a * s / ((j3 - j2) * c);
    let k = ((j2 - j1) * a * b / (j3 * c * s)).sqrt();
    let (sn, cn, dn, _) = elliptic::jacobi(s * t, k);
    [a * cn, b * sn, c * dn]
}

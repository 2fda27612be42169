//! The spatial chain of the benchmark: `N` rods hanging from a fixed point,
//! joined end to end by spherical joints.

use super::body::Body;
use super::joint::{Joint, JointKind};
use super::mechanism::Mechanism;

/// `n` uniform rods of mass 1 kg, length 1 m and radius 1 cm, the first
/// pinned at the origin by a spherical joint and each joined to the next
/// at their common end; straight, `theta0` from the downward vertical in
/// the x–z plane, at rest, under gravity `g` along −z. Each rod's body axes
/// are the space axes at the start, so its inertia tensor is full.
pub fn chain(n: usize, theta0: f64, g: f64) -> Mechanism {
    let (length, radius, mass) = (1.0, 0.01, 1.0);
    let d = [theta0.sin(), 0.0, -theta0.cos()];
    let (across, along) = (mass * (length * length / 12.0 + radius * radius / 4.0), 0.5 * mass * radius * radius);
    // J = J⊥ (I − d dᵀ) + J∥ d dᵀ
    let inertia = std::array::from_fn(|a| {
        std::array::from_fn(|b| across * ((a == b) as u8 as f64 - d[a] * d[b]) + along * d[a] * d[b])
    });
    let end = |i: usize| d.map(|x| x * length * i as f64);
    let bodies = (0..n)
        .map(|i| Body {
            inertia,
            position: d.map(|x| x * length * (i as f64 + 0.5)),
            ..Body::new(&format!("rod{i}"), mass, [1.0; 3])
        })
        .collect();
    let joints = (0..n).map(|i| Joint::new(JointKind::Spherical, i, i.checked_sub(1), end(i))).collect();
    Mechanism::new([0.0, 0.0, -g]).with_bodies(bodies).with_joints(joints)
}

//! The rod on a revolute joint of the limit tests (`limits.rs`, and the
//! allocation count of `live_allocations.rs`, which includes this file by
//! its path): mass `M`, centre of mass `L` below the pivot, inertia `JYY`
//! about its own centre.

pub const G: f64 = 9.81;
pub const M: f64 = 2.0;
pub const L: f64 = 0.5;
pub const JYY: f64 = 0.02;
pub const H: f64 = 1e-3;

/// The rod hanging from the origin on a revolute joint about Y with
/// `limit`, built at `position` and `orientation`, with `more` sections (an
/// `[initial]`) before its body; under gravity `G`, RK-4 with step `H`, 1 s.
pub fn rod_at(limit: &str, [x, y, z]: [f64; 3], [q0, q1, q2, q3]: [f64; 4], more: &str) -> String {
    format!(
        r#"
[model]
kind = "spatial"
gravity = [0.0, 0.0, -{G}]

[integrator]
scheme = "rk4"
h = {H}
t_end = 1.0
{more}
[[bodies]]
name = "rod"
mass = {M}
inertia = [0.02, {JYY}, 0.005]
position = [{x}, {y}, {z}]
orientation = [{q0}, {q1}, {q2}, {q3}]

[[joints]]
kind = "revolute"
a = "rod"
b = "ground"
point = [0.0, 0.0, 0.0]
axis = [0.0, 1.0, 0.0]
limit = {limit}
"#
    )
}

/// TIAGo's fingers' upper bound, its URDF's.
#[allow(clippy::approx_constant)] // 6.28, not 2π
pub const FINGER_UPPER: f64 = 6.28;

/// The rod of [`rod_at`] hanging, without gravity, limited to TIAGo's
/// fingers' −2.62 … 6.28 rad (more than a turn), started at the joint
/// angle `theta0` turning up at 2 rad/s, run to `t_end`.
pub fn turning_finger(theta0: f64, t_end: f64) -> String {
    let initial = format!("\n[initial]\njoints = {{ \"joints[0]\" = {theta0} }}\nrates = {{ \"joints[0]\" = 2.0 }}\n");
    let limit = format!("{{ lower = -2.62, upper = {FINGER_UPPER} }}");
    rod_at(&limit, [0.0, 0.0, -L], [1.0, 0.0, 0.0, 0.0], &initial)
        .replace(&format!("gravity = [0.0, 0.0, -{G}]"), "gravity = [0.0, 0.0, 0.0]")
        .replace("t_end = 1.0", &format!("t_end = {t_end}"))
}

//! The four-bar in Cartesian body coordinates, built as a planar mechanism.

use super::FourBarParams;
use super::kinematics::{four_bar_kinematics, four_bar_state, load_motion};

use crate::error::Result;
use crate::model::timefn::TimeFn;
use crate::models::parts::{add, dir, example, load_state, rigid_body};
use crate::models::{Example, Reference};
use crate::planar::{BodyId, Element, Mechanism};

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
    m.add(Element::Revolute { a: BodyId::Ground, pa: [0.0, 0.0], b: crank, pb: [-0.5 * a, 0.0], limit: None });
    m.add(Element::DriveAngle { a: BodyId::Ground, b: crank, f: TimeFn::linear(p.theta0, p.omega) });
    m.add(Element::Revolute { a: crank, pa: [0.5 * a, 0.0], b: coupler, pb: [-0.5 * b, 0.0], limit: None });
    m.add(Element::Revolute { a: coupler, pa: [0.5 * b, 0.0], b: rocker, pb: [0.5 * c, 0.0], limit: None });
    m.add(Element::Revolute { a: BodyId::Ground, pa: [d, 0.0], b: rocker, pb: [-0.5 * c, 0.0], limit: None });
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

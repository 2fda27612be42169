//! Built-in mechanisms in scenario files: `[model] kind = "chain"` with
//! their parameters in `[model.parameters]`; unset ones keep the defaults.

use anyhow::{Result, anyhow, bail};
use cdyn::models::{
    ChainParams, DampedPendulumParams, DoublePendulumParams, Example, FourBarParams, MovingSupportParams,
    SliderCrankParams, chain, damped_pendulum, double_pendulum, four_bar, moving_support_pendulum, slider_crank,
};
use serde::Deserialize;

/// Reads the numbers of `table` into `fields`, refusing unknown keys.
fn read(file: &str, table: &toml::Table, fields: &mut [(&str, &mut f64)]) -> Result<()> {
    for (key, value) in table {
        let Some((_, slot)) = fields.iter_mut().find(|(k, _)| k == key) else {
            let known: Vec<&str> = fields.iter().map(|(k, _)| *k).collect();
            bail!("{file}: [model.parameters] unknown key `{key}`; expected one of {}", known.join(", "));
        };
        **slot = match value {
            toml::Value::Float(x) => *x,
            toml::Value::Integer(i) => *i as f64,
            other => bail!("{file}: [model.parameters] {key} = {other}: expected a number"),
        };
        if !slot.is_finite() {
            bail!("{file}: [model.parameters] {key} = {}: must be finite", **slot);
        }
    }
    Ok(())
}

/// The built-in `kind` with the given parameters.
pub fn example(file: &str, kind: &str, table: &toml::Table) -> Result<Example> {
    let model = |e: cdyn::Error| anyhow!("{file}: [model.parameters]: {e}");
    Ok(match kind {
        "double_pendulum" => {
            let mut p = DoublePendulumParams::default();
            read(
                file,
                table,
                &mut [
                    ("m1", &mut p.m1),
                    ("m2", &mut p.m2),
                    ("l1", &mut p.l1),
                    ("l2", &mut p.l2),
                    ("gravity", &mut p.gravity),
                    ("theta1", &mut p.theta1),
                    ("theta2", &mut p.theta2),
                    ("omega1", &mut p.omega1),
                    ("omega2", &mut p.omega2),
                ],
            )?;
            double_pendulum(p).map_err(model)?
        }
        "chain" => {
            let mut p = ChainParams::default();
            let mut n = p.n as f64;
            read(
                file,
                table,
                &mut [
                    ("n", &mut n),
                    ("mass", &mut p.mass),
                    ("length", &mut p.length),
                    ("gravity", &mut p.gravity),
                    ("theta0", &mut p.theta0),
                    ("omega0", &mut p.omega0),
                ],
            )?;
            if !((1.0..=1e6).contains(&n) && n.fract() == 0.0) {
                bail!("{file}: [model.parameters] n = {n}: must be a whole number from 1 to 1000000");
            }
            p.n = n as usize;
            chain(p).map_err(model)?
        }
        "slider_crank" => {
            let mut p = SliderCrankParams::default();
            read(
                file,
                table,
                &mut [
                    ("crank_radius", &mut p.crank_radius),
                    ("rod_length", &mut p.rod_length),
                    ("crank_mass", &mut p.crank_mass),
                    ("crank_inertia", &mut p.crank_inertia),
                    ("rod_mass", &mut p.rod_mass),
                    ("rod_inertia", &mut p.rod_inertia),
                    ("slider_mass", &mut p.slider_mass),
                    ("slider_inertia", &mut p.slider_inertia),
                    ("omega", &mut p.omega),
                    ("theta0", &mut p.theta0),
                    ("gravity", &mut p.gravity),
                ],
            )?;
            slider_crank(p).map_err(model)?
        }
        "four_bar" => {
            let mut p = FourBarParams::default();
            read(
                file,
                table,
                &mut [
                    ("crank_length", &mut p.crank_length),
                    ("coupler_length", &mut p.coupler_length),
                    ("rocker_length", &mut p.rocker_length),
                    ("ground_length", &mut p.ground_length),
                    ("crank_mass", &mut p.crank_mass),
                    ("crank_inertia", &mut p.crank_inertia),
                    ("coupler_mass", &mut p.coupler_mass),
                    ("coupler_inertia", &mut p.coupler_inertia),
                    ("rocker_mass", &mut p.rocker_mass),
                    ("rocker_inertia", &mut p.rocker_inertia),
                    ("omega", &mut p.omega),
                    ("theta0", &mut p.theta0),
                    ("gravity", &mut p.gravity),
                ],
            )?;
            four_bar(p).map_err(model)?
        }
        "damped_pendulum" => {
            let mut p = DampedPendulumParams::default();
            read(
                file,
                table,
                &mut [
                    ("mass", &mut p.mass),
                    ("inertia", &mut p.inertia),
                    ("length", &mut p.length),
                    ("gravity", &mut p.gravity),
                    ("damping", &mut p.damping),
                    ("theta0", &mut p.theta0),
                    ("omega0", &mut p.omega0),
                ],
            )?;
            damped_pendulum(p).map_err(model)?
        }
        "moving_support_pendulum" => {
            let mut p = MovingSupportParams::default();
            let mut numbers = table.clone();
            for (key, slot) in [("support_x", &mut p.support_x), ("support_y", &mut p.support_y)] {
                if let Some(v) = numbers.remove(key) {
                    *slot = cdyn::timefn::TimeFn::deserialize(v)
                        .map_err(|e| anyhow!("{file}: [model.parameters] {key}: {}", e.message()))?;
                }
            }
            read(
                file,
                &numbers,
                &mut [
                    ("support_mass", &mut p.support_mass),
                    ("mass", &mut p.mass),
                    ("length", &mut p.length),
                    ("gravity", &mut p.gravity),
                    ("theta0", &mut p.theta0),
                    ("omega0", &mut p.omega0),
                ],
            )?;
            moving_support_pendulum(p).map_err(model)?
        }
        other => unreachable!("no built-in {other}"),
    })
}

//! The grid of a sweep: the axes of the scenario's `[sweep]` table, the
//! values at a point, the scenario with them set, and the scenario's hash
//! by which shards are matched.

use super::Axis;
use crate::case::scenario::Scenario;
use anyhow::{Result, anyhow, bail};

/// The axes of the scenario's `[sweep]` table, in file order.
pub fn axes(scenario: &Scenario, file: &str) -> Result<Vec<Axis>> {
    let table = scenario
        .sweep
        .as_ref()
        .ok_or_else(|| anyhow!("{file}: a sweep needs a [sweep] table, e.g. alpha_g = [10, 20, 40]"))?;
    if table.is_empty() {
        bail!("{file}: [sweep] is empty");
    }
    table
        .iter()
        .map(|(name, value)| {
            let values: Vec<f64> = value
                .as_array()
                .ok_or_else(|| anyhow!("{file}: [sweep] {name}: expected a list of numbers"))?
                .iter()
                .map(|v| v.as_float().or_else(|| v.as_integer().map(|i| i as f64)))
                .collect::<Option<_>>()
                .ok_or_else(|| anyhow!("{file}: [sweep] {name}: expected a list of numbers"))?;
            if values.is_empty() {
                bail!("{file}: [sweep] {name}: the list is empty");
            }
            set(&mut scenario.clone(), name, values[0])
                .map_err(|e| anyhow!("{file}: [sweep] {name}: not h or a [method] gain: {e}"))?;
            Ok(Axis { name: name.clone(), values })
        })
        .collect()
}

/// The grid values of point `index` (last axis fastest).
pub(super) fn values_at(axes: &[Axis], mut index: usize) -> Vec<f64> {
    let mut out = vec![0.0; axes.len()];
    for (k, a) in axes.iter().enumerate().rev() {
        out[k] = a.values[index % a.values.len()];
        index /= a.values.len();
    }
    out
}

/// The scenario with one grid point's values set.
pub(super) fn at_point(scenario: &Scenario, axes: &[Axis], values: &[f64]) -> Result<Scenario> {
    let mut s = scenario.clone();
    for (a, &v) in axes.iter().zip(values) {
        set(&mut s, &a.name, v)?;
    }
    Ok(s)
}

/// Sets one axis: `h`, or a key of the library's method table (whatever
/// [`cdyn::control::methods::MethodKeys`] accepts, so a new gain needs no change here).
pub(super) fn set(scenario: &mut Scenario, name: &str, value: f64) -> Result<()> {
    if name == "h" {
        scenario.integrator.h = value;
        return Ok(());
    }
    let mut table = toml::Table::try_from(scenario.method())?;
    table.insert(name.to_string(), toml::Value::Float(value));
    scenario.method = Some(table.try_into().map_err(|e: toml::de::Error| anyhow!("{}", e.message().trim()))?);
    Ok(())
}

/// A stable hash (128-bit FNV-1a, hex) of a canonical encoding of the parsed
/// scenario `table`: keys sorted, numbers by value (so `2` and `2.0`, which
/// the scenario reads alike, agree), comments and layout ignored. It must
/// not change between releases or platforms, so it is written out here
/// rather than taken from `std`'s randomly seeded hashers.
pub fn content_hash(table: &toml::Table) -> String {
    fn encode(value: &toml::Value, out: &mut Vec<u8>) {
        let bytes = |tag: u8, b: &[u8], out: &mut Vec<u8>| {
            out.push(tag);
            out.extend_from_slice(&(b.len() as u64).to_le_bytes());
            out.extend_from_slice(b);
        };
        match value {
            toml::Value::String(s) => bytes(b'S', s.as_bytes(), out),
            toml::Value::Integer(i) if i.unsigned_abs() < 1 << 53 => {
                bytes(b'F', &(*i as f64).to_bits().to_le_bytes(), out)
            }
            toml::Value::Integer(i) => bytes(b'I', &i.to_le_bytes(), out),
            toml::Value::Float(f) => {
                let f = if f.is_nan() {
                    f64::NAN
                } else if *f == 0.0 {
                    0.0
                } else {
                    *f
                };
                bytes(b'F', &f.to_bits().to_le_bytes(), out)
            }
            toml::Value::Boolean(b) => bytes(b'B', &[u8::from(*b)], out),
            toml::Value::Datetime(d) => bytes(b'D', d.to_string().as_bytes(), out),
            toml::Value::Array(items) => {
                bytes(b'A', &(items.len() as u64).to_le_bytes(), out);
                items.iter().for_each(|v| encode(v, out));
            }
            toml::Value::Table(t) => {
                bytes(b'T', &(t.len() as u64).to_le_bytes(), out);
                let mut keys: Vec<&String> = t.keys().collect();
                keys.sort();
                for k in keys {
                    bytes(b'K', k.as_bytes(), out);
                    encode(&t[k], out);
                }
            }
        }
    }
    let mut bytes = Vec::new();
    encode(&toml::Value::Table(table.clone()), &mut bytes);
    const OFFSET: u128 = 0x6c62272e07bb014262b821756295c58d;
    const PRIME: u128 = 0x0000000001000000000000000000013B;
    let hash = bytes.iter().fold(OFFSET, |h, &b| (h ^ u128::from(b)).wrapping_mul(PRIME));
    format!("{hash:032x}")
}

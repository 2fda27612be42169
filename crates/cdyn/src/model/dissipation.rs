//! Which force element dissipates most along a motion: what names the
//! element behind a stiff damping rate in a refused step.

use super::definition::Model;

impl Model {
    /// The force element (in the order they were added) that dissipates
    /// most power `wᵀ C_e w` along the velocity `w`, `C_e = −∂Q_e/∂v` of
    /// element `e`; `None` without damping forces. Names the element behind
    /// a stiff damping rate ([`crate::control::gains`]).
    pub fn most_dissipating(&self, q: &[f64], v: &[f64], w: &[f64], t: f64) -> Option<usize> {
        let (mut best, mut element) = ((0.0, None), 0);
        for f in &self.forces {
            let (items, k) = f.elements();
            let mut entries = Vec::with_capacity(items * k * k);
            f.jacobian_entries(&mut entries);
            let mut values = vec![0.0; entries.len()];
            f.jacobians(q, v, t, 0.0, 1.0, &mut values);
            for block in entries.chunks_exact(k * k).zip(values.chunks_exact(k * k)) {
                let power: f64 =
                    block.0.iter().zip(block.1).map(|(&(r, c), x)| w[r as usize] * x * w[c as usize]).sum();
                if power > best.0 {
                    best = (power, Some(element));
                }
                element += 1;
            }
        }
        best.1
    }
}

//! Reproducible pseudo-random numbers: the sample states of the symmetry
//! search, and the random poses of tests.
//!
//! May import: nothing.

/// A 64-bit linear congruential generator (Knuth's MMIX constants).
pub(crate) struct Lcg(pub(crate) u64);

impl Lcg {
    /// Uniform in `[−1, 1)`: the top 53 bits of the next state.
    pub(crate) fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }
}

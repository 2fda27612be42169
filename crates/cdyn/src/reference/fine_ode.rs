//! Classical RK-4 with a small fixed step, continued incrementally: the
//! state at the last whole step is cached, so calls with increasing `t`
//! only integrate the new interval; a call with an earlier `t` restarts
//! from `t = 0`. The increments are added with Kahan compensation, so that
//! the rounding of ~10⁵ small steps does not accumulate past ~1e-14.
//!
//! The built-in models size the step to about 1e-3 of the fastest time
//! scale of the equation they integrate.

use std::sync::{Mutex, PoisonError};

type Rhs<const N: usize> = Box<dyn Fn(f64, [f64; N]) -> [f64; N] + Send + Sync>;

/// More steps than this per call are refused (the result is NaN).
const MAX_STEPS: f64 = 1e9;

/// Steps taken, the state at `steps · h`, and its Kahan compensation.
type Cache<const N: usize> = (u64, [f64; N], [f64; N]);

pub(crate) struct FineOde<const N: usize> {
    rhs: Rhs<N>,
    y0: [f64; N],
    h: f64,
    cache: Mutex<Cache<N>>,
}

impl<const N: usize> FineOde<N> {
    /// `y' = rhs(t, y)`, `y(0) = y0`, step `h > 0`.
    pub(crate) fn new(h: f64, y0: [f64; N], rhs: impl Fn(f64, [f64; N]) -> [f64; N] + Send + Sync + 'static) -> Self {
        Self { rhs: Box::new(rhs), y0, h, cache: Mutex::new((0, y0, [0.0; N])) }
    }

    /// The RK-4 increment `y(t + h) − y(t)`.
    fn increment(&self, t: f64, y: [f64; N], h: f64) -> [f64; N] {
        let f = &self.rhs;
        let at = |k: [f64; N], c: f64| std::array::from_fn(|i| y[i] + c * k[i]);
        let k1 = f(t, y);
        let k2 = f(t + 0.5 * h, at(k1, 0.5 * h));
        let k3 = f(t + 0.5 * h, at(k2, 0.5 * h));
        let k4 = f(t + h, at(k3, h));
        std::array::from_fn(|i| h / 6.0 * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]))
    }

    /// `y(t)` for `t ≥ 0` (NaN for negative, non-finite or too distant `t`).
    pub(crate) fn at(&self, t: f64) -> [f64; N] {
        let whole = (t / self.h).floor();
        if !(0.0..=MAX_STEPS).contains(&whole) {
            return [f64::NAN; N];
        }
        let whole = whole as u64;
        let mut cache = self.cache.lock().unwrap_or_else(PoisonError::into_inner);
        if cache.0 > whole {
            *cache = (0, self.y0, [0.0; N]);
        }
        while cache.0 < whole {
            let (k, y, mut comp) = *cache;
            let dy = self.increment(k as f64 * self.h, y, self.h);
            let y = std::array::from_fn(|i| {
                let d = dy[i] - comp[i];
                let sum = y[i] + d;
                comp[i] = (sum - y[i]) - d;
                sum
            });
            *cache = (k + 1, y, comp);
        }
        let (k, y, comp) = *cache;
        let t0 = k as f64 * self.h;
        let dy = if t > t0 { self.increment(t0, y, t - t0) } else { [0.0; N] };
        std::array::from_fn(|i| y[i] + (dy[i] - comp[i]))
    }
}

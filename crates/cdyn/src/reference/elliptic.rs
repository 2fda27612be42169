//! Jacobi elliptic functions and elliptic integrals of real argument.
//!
//! Everything is parameterised by the **modulus** k (not the parameter
//! m = k²); only |k| matters. Public functions accept |k| ≤ 1 and return NaN
//! for |k| > 1 or non-finite input.

use std::f64::consts::{FRAC_PI_2, PI};
use std::fmt;

/// AGM(1, k') halves log(b/a) per step until quadratic convergence; even
/// k' = 5e-324 needs fewer than 20 steps, so 32 is ample.
const MAX_AGM: usize = 32;

/// Relative error target of Carlson's duplication algorithm.
const RF_TOL: f64 = 1e-16;

/// A modulus 0 ≤ k < 1 together with its AGM table.
///
/// The complement k' is supplied by the caller so that it can be formed
/// without cancellation when k is close to 1; it must satisfy
/// k² + k'² = 1 and k' > 0.
#[derive(Clone)]
pub(super) struct Modulus {
    k: f64,
    kc: f64,
    /// a_n, b_n, c_n of A&S 16.4 for n = 0..=n_max.
    a: [f64; MAX_AGM],
    b: [f64; MAX_AGM],
    c: [f64; MAX_AGM],
    n_max: usize,
    big_k: f64,
}

impl fmt::Debug for Modulus {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Modulus").field("k", &self.k).field("kc", &self.kc).field("big_k", &self.big_k).finish()
    }
}

impl Modulus {
    /// Builds the AGM table a0 = 1, b0 = k', c0 = k (A&S 16.4).
    pub(super) fn new(k: f64, kc: f64) -> Self {
        let mut a = [0.0; MAX_AGM];
        let mut b = [0.0; MAX_AGM];
        let mut c = [0.0; MAX_AGM];
        a[0] = 1.0;
        b[0] = kc;
        c[0] = k;
        let mut n = 0;
        while n + 1 < MAX_AGM && c[n] > f64::EPSILON * a[n] {
            a[n + 1] = 0.5 * (a[n] + b[n]);
            b[n + 1] = (a[n] * b[n]).sqrt();
            // c_{n+1} = (a_n − b_n)/2 = c_n²/(4 a_{n+1}); the second form
            // avoids cancellation once a_n ≈ b_n.
            c[n + 1] = c[n] * c[n] / (4.0 * a[n + 1]);
            n += 1;
        }
        Self { k, kc, a, b, c, n_max: n, big_k: FRAC_PI_2 / a[n] }
    }

    /// Modulus from k alone, for the public wrappers; None unless |k| < 1.
    fn from_k(k: f64) -> Option<Self> {
        let k = k.abs();
        (k < 1.0).then(|| Self::new(k, ((1.0 - k) * (1.0 + k)).sqrt()))
    }

    pub(super) fn k(&self) -> f64 {
        self.k
    }

    /// Complete integral K = π / (2 AGM(1, k')).
    pub(super) fn complete_k(&self) -> f64 {
        self.big_k
    }

    /// F(φ, k) for any real φ, using F(φ + nπ) = F(φ) + 2nK so that the
    /// Carlson form (valid for |φ| ≤ π/2) is only used on the reduced angle.
    pub(super) fn incomplete_f(&self, phi: f64) -> f64 {
        let n = (phi / PI).round();
        let r = phi - n * PI;
        let (s, c) = r.sin_cos();
        // 1 − k² sin²φ written as cos²φ + k'² sin²φ: no cancellation near k = 1.
        let ks = self.kc * s;
        s * carlson_rf(c * c, c * c + ks * ks, 1.0) + 2.0 * n * self.big_k
    }

    /// (sn, cn, dn, am) by the descending Landen / AGM method (A&S 16.4),
    /// after reducing u modulo 2K (am(u + 2K) = am(u) + π) so that the
    /// scaled angle 2^N a_N u stays small for large |u|.
    pub(super) fn jacobi(&self, u: f64) -> (f64, f64, f64, f64) {
        let two_k = 2.0 * self.big_k;
        let m = (u / two_k).round();
        let r = u - m * two_k;
        let n = self.n_max;
        let mut phi = r * self.a[n] * (2.0f64).powi(n as i32);
        for i in (1..=n).rev() {
            let (s, c) = phi.sin_cos();
            // asin((c_i/a_i) sin φ) as an atan2: 1 − (c/a)² sin²φ equals
            // (a² cos²φ + b² sin²φ)/a², which keeps full precision where
            // the asin argument approaches ±1 (k near 1).
            let delta = (self.c[i] * s).atan2((self.a[i] * c).hypot(self.b[i] * s));
            phi = 0.5 * (phi + delta);
        }
        let (s0, c0) = phi.sin_cos();
        // dn = √(cos²φ0 + k'² sin²φ0). A&S's cos φ0 / cos(φ1 − φ0) is 0/0 at
        // u = K (the top of a rotating pendulum) and loses digits near it.
        let ks = self.kc * s0;
        let dn = (c0 * c0 + ks * ks).sqrt();
        let sign = if m % 2.0 == 0.0 { 1.0 } else { -1.0 };
        (sign * s0, sign * c0, dn, phi + m * PI)
    }
}

/// Carlson's R_F(x, y, z) by the duplication algorithm (Carlson 1995),
/// for x, y, z ≥ 0 with at most one of them zero.
fn carlson_rf(x: f64, y: f64, z: f64) -> f64 {
    let (x0, y0, z0) = (x, y, z);
    let (mut x, mut y, mut z) = (x, y, z);
    let a0 = (x + y + z) / 3.0;
    let mut a = a0;
    let q = (3.0 * RF_TOL).powf(-1.0 / 6.0) * (a0 - x0).abs().max((a0 - y0).abs()).max((a0 - z0).abs());
    // scale = 4^{-n}
    let mut scale = 1.0;
    // The iteration count is logarithmic in the spread of x, y, z; the cap
    // only guards against degenerate input.
    for _ in 0..200 {
        if scale * q < a.abs() {
            break;
        }
        let (sx, sy, sz) = (x.sqrt(), y.sqrt(), z.sqrt());
        let lam = sx * sy + sx * sz + sy * sz;
        x = 0.25 * (x + lam);
        y = 0.25 * (y + lam);
        z = 0.25 * (z + lam);
        a = 0.25 * (a + lam);
        scale *= 0.25;
    }
    let xx = (a0 - x0) * scale / a;
    let yy = (a0 - y0) * scale / a;
    let zz = -(xx + yy);
    let e2 = xx * yy - zz * zz;
    let e3 = xx * yy * zz;
    (1.0 - e2 / 10.0 + e3 / 14.0 + e2 * e2 / 24.0 - 3.0 * e2 * e3 / 44.0) / a.sqrt()
}

/// Complete elliptic integral of the first kind K(k), modulus k.
/// Returns +∞ for |k| = 1 and NaN for |k| > 1 or non-finite k.
pub fn complete_k(k: f64) -> f64 {
    match Modulus::from_k(k) {
        Some(m) => m.complete_k(),
        None if k.abs() == 1.0 => f64::INFINITY,
        None => f64::NAN,
    }
}

/// Incomplete elliptic integral of the first kind
/// F(φ, k) = ∫₀^φ dθ / √(1 − k² sin²θ), modulus k, for any real φ
/// (extended by F(φ + nπ) = F(φ) + 2nK). For |k| = 1 it is
/// atanh(sin φ) on |φ| < π/2 and ±∞ beyond; NaN for |k| > 1.
pub fn incomplete_f(phi: f64, k: f64) -> f64 {
    if !phi.is_finite() {
        return f64::NAN;
    }
    match Modulus::from_k(k) {
        Some(m) => m.incomplete_f(phi),
        None if k.abs() == 1.0 => {
            let n = (phi / PI).round();
            if n == 0.0 { (phi - n * PI).sin().atanh() } else { f64::INFINITY.copysign(n) }
        }
        None => f64::NAN,
    }
}

/// Jacobi elliptic functions (sn, cn, dn, am) of u, modulus k.
/// am is continuous in u (am(u + 2K) = am(u) + π). For |k| = 1 these are
/// tanh u, sech u, sech u and the Gudermannian; NaN for |k| > 1 or
/// non-finite input.
pub fn jacobi(u: f64, k: f64) -> (f64, f64, f64, f64) {
    if !u.is_finite() {
        return (f64::NAN, f64::NAN, f64::NAN, f64::NAN);
    }
    match Modulus::from_k(k) {
        Some(m) => m.jacobi(u),
        None if k.abs() == 1.0 => {
            let sech = 1.0 / u.cosh();
            (u.tanh(), sech, sech, u.sinh().atan())
        }
        None => (f64::NAN, f64::NAN, f64::NAN, f64::NAN),
    }
}

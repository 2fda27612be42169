//! Euler parameters `p = (e₀, e₁, e₂, e₃)`, scalar first (Haug's
//! convention): `A(p) = E(p) G(p)ᵀ` rotates body axes to space axes, the
//! body angular velocity is `ω′ = 2 G(p) ṗ` and the spatial one
//! `ω = 2 E(p) ṗ`. Written generic over the scalar, for dual numbers.

use crate::ad::scalar::Scalar;

/// `G(p)`, with `ω′ = 2 G ṗ`.
pub fn g_matrix<D: Scalar>([e0, e1, e2, e3]: [D; 4]) -> [[D; 4]; 3] {
    [[-e1, e0, e3, -e2], [-e2, -e3, e0, e1], [-e3, e2, -e1, e0]]
}

/// `E(p)`, with `ω = 2 E ṗ`.
pub fn e_matrix<D: Scalar>([e0, e1, e2, e3]: [D; 4]) -> [[D; 4]; 3] {
    [[-e1, e0, -e3, e2], [-e2, e3, e0, -e1], [-e3, -e2, e1, e0]]
}

/// `A(p) s = (e₀² − eᵀe) s + 2 e (eᵀs) + 2 e₀ (e × s)`: `E Gᵀ s`, a
/// homogeneous quadratic in `p` (the rotation of `s` when `|p| = 1`).
#[inline(always)]
pub fn rotate<D: Scalar>(p: [D; 4], s: [D; 3]) -> [D; 3] {
    let [e0, e1, e2, e3] = p;
    let e = [e1, e2, e3];
    let scale = e0 * e0 - (e1 * e1 + e2 * e2 + e3 * e3);
    let es = e1 * s[0] + e2 * s[1] + e3 * s[2];
    let cross = [e2 * s[2] - e3 * s[1], e3 * s[0] - e1 * s[2], e1 * s[1] - e2 * s[0]];
    std::array::from_fn(|i| s[i] * scale + e[i] * es * 2.0 + e0 * cross[i] * 2.0)
}

/// `A(p) s` for a constant `s` (a body-fixed point or axis): the same
/// arithmetic as [`rotate`] with the products by `s` in plain `f64`,
/// which for dual numbers costs a third less than products of two duals.
#[inline(always)]
pub fn rotate_fixed<D: Scalar>(p: [D; 4], s: [f64; 3]) -> [D; 3] {
    let [e0, e1, e2, e3] = p;
    let e = [e1, e2, e3];
    let scale = e0 * e0 - (e1 * e1 + e2 * e2 + e3 * e3);
    let es = e1 * s[0] + e2 * s[1] + e3 * s[2];
    let cross = [e2 * s[2] - e3 * s[1], e3 * s[0] - e1 * s[2], e1 * s[1] - e2 * s[0]];
    // Written out, not by `array::from_fn`, which for jets was an outlined
    // call passing them through memory (spatial chain: 7 % of the step).
    let at = |i: usize| scale * s[i] + e[i] * es * 2.0 + e0 * cross[i] * 2.0;
    [at(0), at(1), at(2)]
}

/// `∂(A(p) s)/∂p`, a 3 × 4 matrix linear in `p`: column `e₀` is
/// `2(e₀s + e × s)`, the block of `e` is `2((eᵀs) I + e sᵀ − s eᵀ − e₀[s]×)`.
/// `A(p)s` being a quadratic form in `p`, its rate along `ṗ` is `J(p) ṗ`
/// and its second rate `2A(ṗ)s = J(ṗ) ṗ`.
#[inline(always)]
pub fn rotate_jacobian(p: [f64; 4], s: [f64; 3]) -> [[f64; 4]; 3] {
    let [e0, e1, e2, e3] = p;
    let e = [e1, e2, e3];
    let es = e1 * s[0] + e2 * s[1] + e3 * s[2];
    let cross = [e2 * s[2] - e3 * s[1], e3 * s[0] - e1 * s[2], e1 * s[1] - e2 * s[0]];
    // [s]× x = s × x: row i of [s]×.
    let skew = [[0.0, -s[2], s[1]], [s[2], 0.0, -s[0]], [-s[1], s[0], 0.0]];
    std::array::from_fn(|i| {
        let block = |j: usize| {
            let diagonal = if i == j { es } else { 0.0 };
            2.0 * (diagonal + e[i] * s[j] - s[i] * e[j] - e0 * skew[i][j])
        };
        [2.0 * (e0 * s[i] + cross[i]), block(0), block(1), block(2)]
    })
}

/// `Σᵢ cᵢ ∂²(A(p)s)ᵢ/∂p²`, 4 × 4, the same at every `p`: `A(p)s` is a
/// quadratic form in `p`, so the derivative of its Jacobian (linear in
/// `p`) along `e_l` is that Jacobian at `p = e_l`.
pub fn rotate_hessian(s: [f64; 3], c: [f64; 3]) -> [[f64; 4]; 4] {
    let mut h = [[0.0; 4]; 4];
    for l in 0..4 {
        let j = rotate_jacobian(std::array::from_fn(|k| if k == l { 1.0 } else { 0.0 }), s);
        for k in 0..4 {
            h[k][l] = c[0] * j[0][k] + c[1] * j[1][k] + c[2] * j[2][k];
        }
    }
    h
}

/// `A(p)ᵀ x`: a space vector in body axes (`|p| = 1`).
pub fn unrotate(p: [f64; 4], x: [f64; 3]) -> [f64; 3] {
    rotate([p[0], -p[1], -p[2], -p[3]], x)
}

/// `ṗ = ½ G(p)ᵀ ω′` for the body angular velocity `ω′` (`|p| = 1`).
pub fn rate_from_body(p: [f64; 4], w: [f64; 3]) -> [f64; 4] {
    let g = g_matrix(p);
    std::array::from_fn(|j| 0.5 * (0..3).map(|i| g[i][j] * w[i]).sum::<f64>())
}

/// The body angular velocity `ω′ = 2 G(p) ṗ`.
pub fn body_rate<D: Scalar>(p: [D; 4], pd: [D; 4]) -> [D; 3] {
    let g = g_matrix(p);
    std::array::from_fn(|i| (g[i][0] * pd[0] + g[i][1] * pd[1] + g[i][2] * pd[2] + g[i][3] * pd[3]) * 2.0)
}

/// The spatial angular velocity `ω = 2 E(p) ṗ`.
pub fn space_rate<D: Scalar>(p: [D; 4], pd: [D; 4]) -> [D; 3] {
    let e = e_matrix(p);
    std::array::from_fn(|i| (e[i][0] * pd[0] + e[i][1] * pd[1] + e[i][2] * pd[2] + e[i][3] * pd[3]) * 2.0)
}

/// The generalized force `2 E(p)ᵀ n` of a torque `n` (space axes) on the
/// Euler parameters: its power `(2 Eᵀ n) · ṗ = n · ω`.
pub fn torque_on_parameters<D: Scalar>(p: [D; 4], n: [D; 3]) -> [D; 4] {
    let e = e_matrix(p);
    std::array::from_fn(|j| (e[0][j] * n[0] + e[1][j] * n[1] + e[2][j] * n[2]) * 2.0)
}

/// `a × b`
pub fn cross<D: Scalar>(a: [D; 3], b: [D; 3]) -> [D; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// The unit quaternion of a rotation by `angle` about the unit `axis`.
pub fn about(axis: [f64; 3], angle: f64) -> [f64; 4] {
    let (s, c) = (0.5 * angle).sin_cos();
    [c, s * axis[0], s * axis[1], s * axis[2]]
}

/// The product `a ⊗ b` (first `b`, then `a`: `A(a ⊗ b) = A(a) A(b)`).
pub fn compose(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    let [a0, a1, a2, a3] = a;
    let [b0, b1, b2, b3] = b;
    [
        a0 * b0 - a1 * b1 - a2 * b2 - a3 * b3,
        a0 * b1 + a1 * b0 + a2 * b3 - a3 * b2,
        a0 * b2 - a1 * b3 + a2 * b0 + a3 * b1,
        a0 * b3 + a1 * b2 - a2 * b1 + a3 * b0,
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotations_compose_and_invert() {
        let p = about([0.0, 0.0, 1.0], std::f64::consts::FRAC_PI_2);
        let x = rotate(p, [1.0, 0.0, 0.0]);
        assert!((x[0]).abs() < 1e-15 && (x[1] - 1.0).abs() < 1e-15 && x[2].abs() < 1e-15, "{x:?}");
        let q = about([0.6, 0.0, 0.8], 0.7);
        let s = [0.3, -1.2, 2.0];
        let twice = rotate(p, rotate(q, s));
        let once = rotate(compose(p, q), s);
        let back = unrotate(q, rotate(q, s));
        for i in 0..3 {
            assert!((twice[i] - once[i]).abs() < 1e-14 && (back[i] - s[i]).abs() < 1e-14);
        }
        // ω′ = 2 G ṗ inverts ṗ = ½ Gᵀ ω′, and ω = A ω′.
        let w = [0.4, -2.0, 1.5];
        let pd = rate_from_body(q, w);
        let (wb, ws) = (body_rate(q, pd), space_rate(q, pd));
        let wr = rotate(q, w);
        for i in 0..3 {
            assert!((wb[i] - w[i]).abs() < 1e-14 && (ws[i] - wr[i]).abs() < 1e-14);
        }
    }

    /// `∂(A(p)s)/∂p` against central differences, off the unit sphere, and
    /// `A(p)s = ½ J(p) p` (a quadratic form).
    #[test]
    fn the_jacobian_of_a_rotated_vector_is_its_derivative() {
        let (p, s) = ([0.9, -0.3, 0.5, 0.2], [0.3, -1.2, 2.0]);
        let j = rotate_jacobian(p, s);
        let h = 1e-6;
        for k in 0..4 {
            let moved = |d: f64| rotate(std::array::from_fn(|m| p[m] + if m == k { d } else { 0.0 }), s);
            let (up, down) = (moved(h), moved(-h));
            for i in 0..3 {
                let fd = (up[i] - down[i]) / (2.0 * h);
                assert!((j[i][k] - fd).abs() < 1e-9, "∂/∂p{k} row {i}: {} against {fd}", j[i][k]);
            }
        }
        let value = rotate(p, s);
        for i in 0..3 {
            let half: f64 = 0.5 * (0..4).map(|k| j[i][k] * p[k]).sum::<f64>();
            assert!((half - value[i]).abs() < 1e-14, "{half} against {}", value[i]);
        }
    }
}

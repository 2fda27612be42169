//! The 4 × 4 algebra of one body: the rotation's Jacobian, and the
//! Cholesky factor of a block with its two triangular solves.

/// `∂(A(p) s)/∂p`, row by row: `A(p) s = (e₀² − eᵀe) s + 2e(eᵀs) + 2e₀(e × s)`
/// gives `2(e₀ s + e × s)` for `e₀` and `2((eᵀs) I + e sᵀ − s eᵀ − e₀ [s]×)` for `e`.
#[inline(always)]
pub(super) fn d_rotate([e0, e1, e2, e3]: [f64; 4], s: [f64; 3]) -> [[f64; 4]; 3] {
    let e = [e1, e2, e3];
    let es = dot(&e, &s);
    let cross = [e2 * s[2] - e3 * s[1], e3 * s[0] - e1 * s[2], e1 * s[1] - e2 * s[0]];
    // [s]× e = s × e, so row i of [s]× is ∂(s × e)_i/∂e.
    let skew = [[0.0, -s[2], s[1]], [s[2], 0.0, -s[0]], [-s[1], s[0], 0.0]];
    std::array::from_fn(|i| {
        let mut row = [2.0 * (e0 * s[i] + cross[i]), 0.0, 0.0, 0.0];
        for j in 0..3 {
            let identity = if i == j { es } else { 0.0 };
            row[j + 1] = 2.0 * (identity + e[i] * s[j] - s[i] * e[j] - e0 * skew[i][j]);
        }
        row
    })
}

#[inline(always)]
pub(super) fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(a, b)| a * b).sum()
}

pub(super) fn quaternion(x: &[f64]) -> [f64; 4] {
    [x[0], x[1], x[2], x[3]]
}

/// The Cholesky factor of the lower triangle of `s`.
#[inline(always)]
pub(super) fn cholesky(s: &[[f64; 4]; 4]) -> [[f64; 4]; 4] {
    let mut l = [[0.0; 4]; 4];
    for j in 0..4 {
        let d = (s[j][j] - (0..j).map(|k| l[j][k] * l[j][k]).sum::<f64>()).sqrt();
        l[j][j] = d;
        for i in j + 1..4 {
            l[i][j] = (s[i][j] - (0..j).map(|k| l[i][k] * l[j][k]).sum::<f64>()) / d;
        }
    }
    l
}

/// `L⁻¹ x`
#[inline(always)]
pub(super) fn forward(l: &[[f64; 4]; 4], mut x: [f64; 4]) -> [f64; 4] {
    for i in 0..4 {
        x[i] = (x[i] - (0..i).map(|k| l[i][k] * x[k]).sum::<f64>()) / l[i][i];
    }
    x
}

/// `L⁻ᵀ x`
#[inline(always)]
pub(super) fn backward(l: &[[f64; 4]; 4], mut x: [f64; 4]) -> [f64; 4] {
    for i in (0..4).rev() {
        x[i] = (x[i] - (i + 1..4).map(|k| l[k][i] * x[k]).sum::<f64>()) / l[i][i];
    }
    x
}

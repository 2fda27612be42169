//! The 4 × 4 algebra of one body: the Cholesky factor of a block with its
//! two triangular solves.

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

//! Angular momenta: the momenta of rigid rotations, quadratic in the
//! state, held by gradient feedback the way the energy is.
//!
//! A rigid rotation of the whole system about an axis moves the coordinates
//! along a field `ξ(q) = B q + b` affine in `q` (a [`Generator`]): for a
//! planar body `(x, y, θ)` turning about the point `c`,
//! `ξ = (−(y − c_y), x − c_x, 1)`; for a spatial body `(r, p)` about the
//! axis `a` through `c`, `ξ_r = a × (r − c)` and `ξ_p = ½ (0, a) ⊗ p`, so
//! that `2 E(p) ξ_p = a`. The system is symmetric under it when
//! `Φ_q ξ = 0`, `Q·ξ = 0` and the energy does not change under the
//! rotation lifted to the velocities (`v ↦ v + s B v`):
//! `Ψ_q·ξ + (M v)·(B v) = 0`. Its momentum `L = ξ(q)ᵀ M v` is then
//! conserved: `dL/dt = (B v)·M v + ξ·(∂T/∂q − ∇V + Q − Φ_qᵀλ) = 0`.
//!
//! `L` is quadratic in the state, so no explicit scheme keeps it and a
//! correction cannot keep it by staying M-orthogonal to a fixed direction,
//! as it keeps a linear momentum ([`crate::dynamics::momentum`]); `robust` and
//! `projection` hold it with the energy ([`crate::control::held`]).

/// An infinitesimal rigid rotation of the system as a field on the
/// coordinates, `ξ(q) = B q + b`.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Generator {
    /// What its momentum is called ("angular momentum z").
    pub name: String,
    /// The non-zero entries of `B`: row, column, weight.
    pub linear: Vec<(u32, u32, f64)>,
    /// The non-zero entries of `b`.
    pub offset: Vec<(u32, f64)>,
    /// Declared by the user: reported when the model does not keep it.
    pub declared: bool,
}

impl Generator {
    /// The field `ξ(q) = B q + b` with the non-zero entries `linear` of `B`
    /// (row, column, weight) and `offset` of `b`, its momentum called
    /// `name`; checked when it is declared on a model.
    pub fn new(name: &str, linear: Vec<(u32, u32, f64)>, offset: Vec<(u32, f64)>) -> Self {
        Self { name: name.to_string(), linear, offset, declared: false }
    }

    /// The rotation about the unit `axis` (normalized here) through `point`
    /// of every body of a mechanism, read from its coordinate names: a
    /// planar body's `name.x`, `name.y` and `name.angle` (the axis must be
    /// `z`), a spatial body's `name.x`, `name.y`, `name.z` and Euler
    /// parameters `name.e0` … `name.e3`. An error names a coordinate that
    /// belongs to no body, or an axis that is not allowed.
    pub fn rotation(
        name: &str,
        names: &[String],
        axis: [f64; 3],
        point: [f64; 3],
        declared: bool,
    ) -> Result<Generator, String> {
        let length = axis.iter().map(|a| a * a).sum::<f64>().sqrt();
        if !(length > 0.0 && length.is_finite()) || point.iter().any(|p| !p.is_finite()) {
            return Err(format!("axis {axis:?} through {point:?}: must be finite, the axis not zero"));
        }
        let a = axis.map(|x| x / length);
        let spatial = names.iter().any(|n| n.ends_with(".e0"));
        if !spatial && (a[0] != 0.0 || a[1] != 0.0) {
            return Err(format!("axis {axis:?}: a planar mechanism turns about z only"));
        }
        let (mut linear, mut offset) = (Vec::new(), Vec::new());
        let mut i = 0;
        while i < names.len() {
            let body = names[i].rsplit_once('.').map_or("", |(b, _)| b);
            let fields: &[&str] = if spatial {
                &["x", "y", "z", "e0", "e1", "e2", "e3"]
            } else if names.get(i + 2).is_some_and(|n| *n == format!("{body}.angle")) {
                &["x", "y", "angle"]
            } else {
                &["x", "y"]
            };
            for (k, f) in fields.iter().enumerate() {
                if names.get(i + k).is_none_or(|n| *n != format!("{body}.{f}")) {
                    return Err(format!("coordinate {}: not a body's {f}", names.get(i + k).map_or("(none)", |n| n)));
                }
            }
            let at = |k: usize| (i + k) as u32;
            if spatial {
                // ξ_r = a × r − a × c
                let cross = [[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]];
                for (r, row) in cross.iter().enumerate() {
                    for (c, &w) in row.iter().enumerate().filter(|(_, w)| **w != 0.0) {
                        linear.push((at(r), at(c), w));
                    }
                    let b = -(0..3).map(|c| row[c] * point[c]).sum::<f64>();
                    if b != 0.0 {
                        offset.push((at(r), b));
                    }
                }
                // ξ_p = ½ (0, a) ⊗ p = ½ [[0, −aᵀ], [a, [a]×]] p
                let half = [
                    [0.0, -a[0], -a[1], -a[2]],
                    [a[0], 0.0, -a[2], a[1]],
                    [a[1], a[2], 0.0, -a[0]],
                    [a[2], -a[1], a[0], 0.0],
                ];
                for (r, row) in half.iter().enumerate() {
                    for (c, &w) in row.iter().enumerate().filter(|(_, w)| **w != 0.0) {
                        linear.push((at(3 + r), at(3 + c), 0.5 * w));
                    }
                }
            } else {
                // (−(y − c_y), x − c_x, 1), turned by the sign of a_z
                let s = a[2];
                linear.extend([(at(0), at(1), -s), (at(1), at(0), s)]);
                offset.extend([(at(0), s * point[1]), (at(1), -s * point[0])].into_iter().filter(|(_, b)| *b != 0.0));
                if fields.len() == 3 {
                    offset.push((at(2), s));
                }
            }
            i += fields.len();
        }
        Ok(Generator { name: name.to_string(), linear, offset, declared })
    }

    /// `out = ξ(q) = B q + b`.
    pub fn at(&self, q: &[f64], out: &mut [f64]) {
        out.fill(0.0);
        self.offset.iter().for_each(|&(i, b)| out[i as usize] += b);
        self.linear.iter().for_each(|&(r, c, w)| out[r as usize] += w * q[c as usize]);
    }

    /// Checks the entries name coordinates of a model of `n`.
    pub(crate) fn check(&self, n: usize) -> Result<(), String> {
        let rows = self.linear.iter().flat_map(|&(r, c, _)| [r, c]).chain(self.offset.iter().map(|&(i, _)| i));
        match rows.into_iter().find(|&i| i as usize >= n) {
            Some(i) => Err(format!("{}: coordinate {i} of a model of {n}", self.name)),
            None if self.linear.iter().map(|e| e.2).chain(self.offset.iter().map(|e| e.1)).any(|w| !w.is_finite()) => {
                Err(format!("{}: its weights must be finite", self.name))
            }
            None => Ok(()),
        }
    }

    /// `out += Bᵀ x`.
    pub(crate) fn add_transposed(&self, x: &[f64], out: &mut [f64]) {
        self.linear.iter().for_each(|&(r, c, w)| out[c as usize] += w * x[r as usize]);
    }

    /// `out = B v`: how the rotation turns the velocities.
    pub fn turn(&self, v: &[f64], out: &mut [f64]) {
        out.fill(0.0);
        self.linear.iter().for_each(|&(r, c, w)| out[r as usize] += w * v[c as usize]);
    }
}

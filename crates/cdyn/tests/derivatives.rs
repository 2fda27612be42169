//! Automatic derivatives (`Φ_q`, `Φ̇`, `γ`, `∇V`) against finite differences,
//! over random states, for a time-dependent multi-row constraint element.

use cdyn::dynamics::Dynamics;
use cdyn::linalg::mass::MassMatrix;
use cdyn::{Constraint, Model, Potential, Scalar};
use proptest::prelude::*;

/// Two rheonomic rows on three coordinates, deliberately nonlinear in q and t.
struct Twisted;

impl Constraint<3, 2> for Twisted {
    fn eval<D: Scalar>(&self, [a, b, c]: [D; 3], t: D) -> [D; 2] {
        [a * b - t.sin() * c, c * c + (a * t).cos() - b.exp() * 0.3]
    }
}

/// A potential coupling two coordinates.
struct Coupled;

impl Potential<2> for Coupled {
    fn energy<D: Scalar>(&self, [x, y]: [D; 2]) -> D {
        (x * y).sin() + x * x * x * 0.25
    }
}

fn model() -> Model {
    Model::builder(vec![1.0, 2.0, 3.0, 0.5]).constrain(Twisted, [2, 0, 3]).potential(Coupled, [1, 3]).build().unwrap()
}

fn phi(model: &Model, q: &[f64], t: f64) -> Vec<f64> {
    let mut out = vec![0.0; model.m()];
    model.constraint_values(q, t, &mut out);
    out
}

fn shifted(q: &[f64], dir: &[f64], s: f64) -> Vec<f64> {
    q.iter().zip(dir).map(|(q, d)| q + s * d).collect()
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + a.abs().max(b.abs()))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    #[test]
    fn derivatives_match_finite_differences(
        q in prop::collection::vec(-1.5..1.5f64, 4),
        v in prop::collection::vec(-2.0..2.0f64, 4),
        t in 0.0..5.0f64,
    ) {
        let model = model();
        let mut d = Dynamics::new(&model);
        d.evaluate(&model, &q, &v, t).ok();
        let pattern = model.pattern();
        let h = 1e-6;
        // Φ_q column by column.
        for c in 0..4 {
            let mut e = vec![0.0; 4];
            e[c] = 1.0;
            let (p, m) = (phi(&model, &shifted(&q, &e, h), t), phi(&model, &shifted(&q, &e, -h), t));
            for r in 0..model.m() {
                let fd = (p[r] - m[r]) / (2.0 * h);
                let ad = pattern.row(r).find(|&j| pattern.cols[j] as usize == c).map_or(0.0, |j| d.jac()[j]);
                prop_assert!(close(ad, fd, 1e-7), "Φ_q[{r},{c}]: AD {ad} vs FD {fd}");
            }
        }
        // Φ̇ and γ along s ↦ Φ(q + s v, t + s).
        let along = |s: f64| phi(&model, &shifted(&q, &v, s), t + s);
        let hs = 1e-4;
        let (p1, p0, m1) = (along(hs), along(0.0), along(-hs));
        for r in 0..model.m() {
            let first = (p1[r] - m1[r]) / (2.0 * hs);
            let second = (p1[r] - 2.0 * p0[r] + m1[r]) / (hs * hs);
            prop_assert!(close(d.phi()[r], p0[r], 1e-14));
            prop_assert!(close(d.phi_dot()[r], first, 1e-6), "Φ̇[{r}]: AD {} vs FD {first}", d.phi_dot()[r]);
            prop_assert!(close(-d.gamma()[r], second, 1e-5), "γ[{r}]: AD {} vs FD {}", d.gamma()[r], -second);
        }
        // ∇V.
        for c in 0..4 {
            let mut e = vec![0.0; 4];
            e[c] = 1.0;
            let fd = (model.potential(&shifted(&q, &e, h), None) - model.potential(&shifted(&q, &e, -h), None)) / (2.0 * h);
            prop_assert!(close(d.grad_potential()[c], fd, 1e-7), "∇V[{c}]: AD {} vs FD {fd}", d.grad_potential()[c]);
        }
    }
}

#[test]
fn accelerations_satisfy_the_constraint_equations() {
    // Φ_q A = γ and M A + Φ_qᵀ λ = G, for a generic state.
    let model = model();
    let (q, v, t) = ([0.3, -0.4, 0.8, 0.2], [0.5, 1.0, -0.7, 0.3], 0.9);
    let mut d = Dynamics::new(&model);
    d.evaluate(&model, &q, &v, t).unwrap();
    let mut ja = vec![0.0; model.m()];
    d.jac_mul(&model, d.acc(), &mut ja);
    for r in 0..model.m() {
        assert!((ja[r] - d.gamma()[r]).abs() < 1e-12, "row {r}: Φ_q A = {} vs γ = {}", ja[r], d.gamma()[r]);
    }
    // M⁻¹ Φ_qᵀ λ, so that M (A + M⁻¹ Φ_qᵀ λ) = G.
    let mut jt = vec![0.0; model.n()];
    d.add_weighted_jt(&model, d.lambda(), 1.0, &mut jt);
    let total: Vec<f64> = d.acc().iter().zip(&jt).map(|(a, j)| a + j).collect();
    let mut m_total = vec![0.0; model.n()];
    d.mass(&model).mul(&total, &mut m_total);
    for i in 0..model.n() {
        let residual = m_total[i] - d.force()[i];
        assert!(residual.abs() < 1e-12, "coordinate {i}: residual {residual}");
    }
}

#[test]
fn potential_rate_is_read_off_the_right_hand_side_only_where_it_is_exact() {
    // Φ_q M⁻¹∇V from the evaluation's own right-hand side equals the product
    // formed directly, to round-off of γ's scale; it is not kept unless asked,
    // nor where a non-conservative force makes G differ from −∇V.
    let model = model();
    let (q, v, t) = ([0.3, -0.4, 0.8, 0.2], [0.5, 1.0, -0.7, 0.3], 0.9);
    let mut d = Dynamics::new(&model);
    d.evaluate(&model, &q, &v, t).unwrap();
    assert!(d.potential_rate().is_none(), "kept without being asked");
    d.keep_potential_rate(&model, true);
    d.evaluate(&model, &q, &v, t).unwrap();
    let mut w = vec![0.0; model.n()];
    d.mass(&model).solve(d.grad_potential(), &mut w);
    let mut direct = vec![0.0; model.m()];
    d.jac_mul(&model, &w, &mut direct);
    let kept = d.potential_rate().expect("kept where asked, G = −∇V");
    let scale = d.gamma().iter().chain(&direct).fold(0.0f64, |s, x| s.max(x.abs()));
    for r in 0..model.m() {
        assert!((kept[r] - direct[r]).abs() <= 8.0 * f64::EPSILON * scale, "row {r}: {} vs {}", kept[r], direct[r]);
    }
    let damped = Model::builder(vec![1.0, 2.0, 3.0, 0.5])
        .constrain(Twisted, [2, 0, 3])
        .potential(Coupled, [1, 3])
        .force(Drag, [1])
        .build()
        .unwrap();
    let mut d = Dynamics::new(&damped);
    d.keep_potential_rate(&damped, true);
    d.evaluate(&damped, &q, &v, t).unwrap();
    assert!(d.potential_rate().is_none(), "kept although G ≠ −∇V");
}

/// A linear drag: a non-conservative force.
struct Drag;

impl cdyn::Force<1> for Drag {
    fn force<D: Scalar>(&self, _: [D; 1], [v]: [D; 1], _: D) -> [D; 1] {
        [-v * 0.5]
    }
}

//! A free rigid body in Euler parameters through the configuration-dependent
//! mass path: `q = p` (a unit quaternion), `q̇ = ṗ`, the kinetic energy
//! written once as `T = ½ ωᵀ J ω` with the body angular velocity
//! `ω = 2 G(p) ṗ`, and the normalization `pᵀp = 1` as a holonomic
//! constraint held by the same controls as any other. Checked against
//! Euler's torque-free motion in Jacobi elliptic functions, with the energy
//! and the spatial angular momentum exact. This is the formulation the
//! spatial issue has to weigh; the numbers here are its first measurement.

use cdyn::model::kinetic::Kinetic;
use cdyn::reference::torque_free_rate;
use cdyn::spatial::rotation::{body_rate, e_matrix, g_matrix};
use cdyn::{Constraint, Control, Error, Model, Scalar, Scheme, Settings, Simulation, methods};

/// Principal moments of inertia, `J₁ < J₂ < J₃`.
const J: [f64; 3] = [1.0, 2.0, 3.0];
/// Initial body angular velocity `(a, 0, c)`: the motion about the third axis.
const W0: [f64; 3] = [1.0, 0.0, 1.0];

/// The body's kinetic energy, plus `½ k (pᵀṗ)²`, which vanishes with its
/// derivatives on the constraint (`pᵀṗ = 0`) and makes `M` invertible.
struct RigidBody {
    k: f64,
}

impl Kinetic<4> for RigidBody {
    fn energy<D: Scalar>(&self, p: [D; 4], pd: [D; 4]) -> D {
        let w = body_rate(p, pd);
        let rot = (0..3).fold(D::zero(), |s, i| s + w[i] * w[i] * (0.5 * J[i]));
        let along = (0..4).fold(D::zero(), |s, i| s + p[i] * pd[i]);
        rot + along * along * (0.5 * self.k)
    }
}

/// `pᵀp − 1 = 0`
struct UnitNorm;

impl Constraint<4, 1> for UnitNorm {
    fn eval<D: Scalar>(&self, p: [D; 4], _t: D) -> [D; 1] {
        [(0..4).fold(D::zero(), |s, i| s + p[i] * p[i]) - 1.0]
    }
}

/// Euler's torque-free motion from `ω(0) = (a, 0, c)` ([`torque_free_rate`]).
fn euler_exact(t: f64) -> [f64; 3] {
    torque_free_rate(J, [W0[0], W0[2]], t)
}

fn model() -> (Model, Vec<f64>, Vec<f64>) {
    let model = Model::builder(vec![0.0; 4])
        .kinetic(RigidBody { k: 4.0 * J[1] }, [0, 1, 2, 3])
        .constrain(UnitNorm, [0, 1, 2, 3])
        .build()
        .unwrap();
    // ṗ = ½ Gᵀ ω at p = (1, 0, 0, 0), where G Gᵀ = I.
    let p0 = [1.0, 0.0, 0.0, 0.0];
    let g = g_matrix(p0);
    let pd0: Vec<f64> = (0..4).map(|j| 0.5 * (0..3).map(|i| g[i][j] * W0[i]).sum::<f64>()).collect();
    (model, p0.to_vec(), pd0)
}

/// The spatial angular momentum `A J ω`.
fn momentum(p: [f64; 4], w: [f64; 3]) -> [f64; 3] {
    let (e, g) = (e_matrix(p), g_matrix(p));
    let jw: [f64; 3] = std::array::from_fn(|i| J[i] * w[i]);
    std::array::from_fn(|r| (0..3).map(|c| (0..4).map(|k| e[r][k] * g[c][k]).sum::<f64>() * jw[c]).sum())
}

/// Largest errors over `t_end` at step `h`: of `ω` against Euler's solution,
/// of `|p| − 1`, of the energy and of the spatial angular momentum.
fn run(h: f64, t_end: f64, control: Control) -> [f64; 4] {
    let (model, q0, v0) = model();
    let mut sim = Simulation::new(&model, Settings::new(Scheme::RungeKutta4, h, control), &q0, &v0).unwrap();
    let energy = |w: [f64; 3]| (0..3).map(|i| 0.5 * J[i] * w[i] * w[i]).sum::<f64>();
    let (e0, h0) = (energy(W0), momentum([1.0, 0.0, 0.0, 0.0], W0));
    let mut worst = [0.0_f64; 4];
    sim.run::<Error>(t_end, (0.01 / h).round() as u64, |s| {
        let p: [f64; 4] = s.q().try_into().unwrap();
        let w = body_rate(p, s.v().try_into().unwrap());
        let exact = euler_exact(s.t());
        let h_now = momentum(p, w);
        let errors = [
            (0..3).map(|i| (w[i] - exact[i]).abs()).fold(0.0, f64::max),
            (p.iter().map(|x| x * x).sum::<f64>().sqrt() - 1.0).abs(),
            (energy(w) - e0).abs(),
            (0..3).map(|i| (h_now[i] - h0[i]).abs()).fold(0.0, f64::max),
        ];
        worst = std::array::from_fn(|i| worst[i].max(errors[i]));
        Ok(())
    })
    .unwrap();
    worst
}

#[test]
fn the_exact_solution_satisfies_eulers_equations() {
    // Central differences of the closed form against (J₂ − J₃) ω₂ ω₃ / J₁ and its cyclic kin.
    let [j1, j2, j3] = J;
    for t in [0.0, 0.37, 1.9, 5.2] {
        let (w, d) = (euler_exact(t), 1e-5);
        let (a, b) = (euler_exact(t + d), euler_exact(t - d));
        let rate: [f64; 3] = std::array::from_fn(|i| (a[i] - b[i]) / (2.0 * d));
        let euler = [(j2 - j3) * w[1] * w[2] / j1, (j3 - j1) * w[2] * w[0] / j2, (j1 - j2) * w[0] * w[1] / j3];
        for i in 0..3 {
            assert!((rate[i] - euler[i]).abs() < 1e-8, "t = {t}: ω̇[{i}] {} vs {}", rate[i], euler[i]);
        }
    }
    assert_eq!(euler_exact(0.0), W0);
}

#[test]
fn a_rigid_body_in_euler_parameters_follows_eulers_solution_at_order_four() {
    let errors: Vec<[f64; 4]> = [0.02, 0.01, 0.005].iter().map(|&h| run(h, 10.0, Control::none())).collect();
    for (h, e) in [0.02, 0.01, 0.005].iter().zip(&errors) {
        println!(
            "RK-4, no control, h = {h}: |ω − exact| {:.2e}, ||p| − 1| {:.2e}, energy {:.2e}, momentum {:.2e}",
            e[0], e[1], e[2], e[3]
        );
    }
    for w in errors.windows(2) {
        let order = (w[0][0] / w[1][0]).log2();
        assert!((order - 4.0).abs() < 0.25, "errors {errors:?}: observed order {order:.2}");
    }
    assert!(errors[2][0] < 1e-6, "{errors:?}");
}

#[test]
fn the_normalization_is_held_by_the_controls_like_any_constraint() {
    // A coarse step where the uncontrolled drift of |p| is visible.
    let h = 0.02;
    let none = run(h, 20.0, Control::none());
    for (name, control) in [("robust", methods::robust()), ("projection", methods::projection())] {
        let e = run(h, 20.0, control);
        println!(
            "RK-4 h = {h}, 20 s, {name}: |ω − exact| {:.2e} (none {:.2e}), ||p| − 1| {:.2e} (none {:.2e}), energy {:.2e} (none {:.2e}), momentum {:.2e} (none {:.2e})",
            e[0], none[0], e[1], none[1], e[2], none[2], e[3], none[3]
        );
        assert!(e[1] < 1e-10 && e[1] < none[1] / 100.0, "{name}: ||p| − 1| {:e}, none {:e}", e[1], none[1]);
        // Projection holds |Ψ| to its tolerance 1e-10 · max(1, T + |V|), here T = 2.
        assert!(e[2] < 2.001e-10 && e[2] < none[2] / 100.0, "{name}: energy {:e}, none {:e}", e[2], none[2]);
        assert!(e[0] <= none[0] * 1.01, "{name}: ω error {:e} worse than none {:e}", e[0], none[0]);
        // The angular momentum is no control's invariant: it stays at the
        // integrator's error (3.3e-8 with either, 3.25e-8 without).
        assert!(e[3] <= none[3] * 1.1, "{name}: momentum error {:e}, none {:e}", e[3], none[3]);
    }
}

//! Constraints that lose rank: a parallelogram four-bar with a redundant
//! third crank moves exactly as the plain four-bar, and the IFToMM
//! benchmark A02 (N four-bar mechanism, which passes through the flat
//! position where N rows become dependent) against its published
//! reference and against the exact one-degree-of-freedom motion.

use cdyn::control::projection::Projection;
use cdyn::dynamics::{DependentRows, LinearSolver};
use cdyn::planar::{BodyId, Element, Mechanism};
use cdyn::{Control, Error, Geometric, Rate, Scheme, Settings, Simulation};

const G: f64 = 9.81;

/// A parallelogram four-bar of cranks 1 m (1 kg) pivoted at (0, 0) and
/// (2, 0) and a coupler 2 m (2 kg), cranks at `theta0` turning at
/// `omega0`; with `redundant`, a third, massless crank (a distance
/// constraint of 1 m) from (1, 0) to the coupler's middle.
fn parallelogram(theta0: f64, omega0: f64, redundant: bool) -> Mechanism {
    let (s, c) = theta0.sin_cos();
    let mut m = Mechanism::new([0.0, -G]);
    let left = m.rigid("left", 1.0, 1.0 / 12.0, [0.5 * c, 0.5 * s], theta0);
    let coupler = m.rigid("coupler", 2.0, 2.0 * 4.0 / 12.0, [1.0 + c, s], 0.0);
    let right = m.rigid("right", 1.0, 1.0 / 12.0, [2.0 + 0.5 * c, 0.5 * s], theta0);
    for (i, centre) in [(0, 0.5), (1, 1.0), (2, 0.5)] {
        m.bodies[i].velocity = [-centre * s * omega0, centre * c * omega0];
    }
    m.bodies[0].angular_velocity = omega0;
    m.bodies[2].angular_velocity = omega0;
    let ground = BodyId::Ground;
    m.add(Element::Revolute { a: ground, pa: [0.0, 0.0], b: left, pb: [-0.5, 0.0], limit: None });
    m.add(Element::Revolute { a: left, pa: [0.5, 0.0], b: coupler, pb: [-1.0, 0.0], limit: None });
    m.add(Element::Revolute { a: coupler, pa: [1.0, 0.0], b: right, pb: [0.5, 0.0], limit: None });
    m.add(Element::Revolute { a: ground, pa: [2.0, 0.0], b: right, pb: [-0.5, 0.0], limit: None });
    if redundant {
        m.add(Element::Distance { a: ground, pa: [1.0, 0.0], b: coupler, pb: [0.0, 0.0], length: 1.0 });
    }
    m
}

fn tolerant(settings: Settings) -> Settings {
    settings.with_dependent_rows(DependentRows::Tolerate)
}

#[test]
fn a_parallelogram_with_a_redundant_crank_moves_as_the_plain_four_bar() {
    // Released below the horizontal, it swings without reaching the flat
    // position (where the plain four-bar loses rank as well: see A02).
    let theta0 = -0.6;
    let (plain, redundant) =
        (parallelogram(theta0, 0.0, false).build().unwrap(), parallelogram(theta0, 0.0, true).build().unwrap());
    assert_eq!((plain.model.m(), redundant.model.m()), (8, 9));
    let (h, t_end) = (1e-3, 5.0);
    for control in [Control::none(), Control::none().with_geometric(Geometric::Newton(Rate::Given(50.0)))] {
        // Dense eliminates the redundant row last and drops it; the sparse
        // ordering may drop another row of the loop: the motion is the same.
        for solver in [LinearSolver::Dense, LinearSolver::Sparse] {
            let settings = Settings::new(Scheme::RungeKutta4, h, control).with_solver(solver);
            let mut a = Simulation::new(&plain.model, settings, &plain.q0, &plain.v0).unwrap();
            let mut b = Simulation::new(&redundant.model, tolerant(settings), &redundant.q0, &redundant.v0).unwrap();
            let mut worst = 0.0_f64;
            while a.t() < t_end - 0.5 * h {
                a.step().unwrap();
                b.step().unwrap();
                assert!(b.q().iter().chain(b.v()).all(|x| x.is_finite()));
                let dq = a.q().iter().zip(b.q()).fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()));
                let dv = a.v().iter().zip(b.v()).fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()));
                worst = worst.max(dq).max(dv);
            }
            // Dense drops the third crank's row and solves exactly the plain
            // four-bar's equations: the same numbers. The sparse order drops
            // a row of the loop and keeps the crank: the same equations on
            // the constraint manifold, not off it, so the two differ by how
            // the violations drift: 1.2e-9 over 5 s without control (Φ
            // drifts to 1.5e-11; the plain four-bar dense vs sparse differs
            // by 2e-14), 2.6e-10 with the Newton control holding Φ.
            let tolerance = if solver == LinearSolver::Sparse && !control.is_active() { 1e-8 } else { 1e-9 };
            assert!(worst < tolerance, "{control:?} {solver:?}: q, v differ by {worst:e}");
            if solver == LinearSolver::Dense {
                assert_eq!(worst, 0.0, "{control:?}");
            }
            // It did swing: the cranks turned.
            assert!((b.q()[2] - theta0).abs() > 0.5, "crank angle {}", b.q()[2]);
            // Every step had exactly the one dependent row; the plain four-bar none.
            assert!(a.rank_loss().is_none());
            let loss = b.rank_loss().expect("dependent rows reported");
            assert_eq!((loss.max, loss.steps, loss.first_time), (1, b.steps(), 0.0), "{loss:?}");
            assert!((loss.last_time - (t_end - h)).abs() < 1e-9, "{loss:?}");
            eprintln!("{control:?} {solver:?}: max |Δq|, |Δv| = {worst:e}, {loss:?}");
        }
    }
}

#[test]
fn strict_mode_names_the_redundant_row() {
    let built = parallelogram(-0.6, 0.0, true).build().unwrap();
    let settings = Settings::new(Scheme::RungeKutta4, 1e-3, Control::none());
    assert_eq!(settings.dependent_rows, DependentRows::Error, "strict is the default");
    let mut sim = Simulation::new(&built.model, settings, &built.q0, &built.v0).unwrap();
    let err = sim.step().unwrap_err();
    assert_eq!(err, Error::SingularConstraints { step: 0, t: 0.0, row: 8 });
    // Row 8 is the distance constraint, element 4: the third crank.
    assert_eq!(built.row_elements[err.row().unwrap()], 4);
    assert!(err.to_string().contains("dependent_rows = \"tolerate\""), "{err}");
}

/// The N four-bar mechanism of IFToMM benchmark A02: N + 1 vertical cranks
/// pivoted at (i, 0) and N couplers joining their tops, all bars 1 m and
/// 1 kg (uniform, inertia 1/12 about the centre); B0, the top of the first
/// crank, starts at (0, 1) moving at 1 m/s along +x.
fn n_four_bar(n: usize) -> Mechanism {
    let mut m = Mechanism::new([0.0, -G]);
    let inertia = 1.0 / 12.0;
    let cranks: Vec<BodyId> = (0..=n)
        .map(|i| {
            let id = m.rigid(&format!("crank{i}"), 1.0, inertia, [i as f64, 0.5], std::f64::consts::FRAC_PI_2);
            let b = m.bodies.len() - 1;
            // θ̇ = −1: the centre moves at 0.5 m/s along +x.
            (m.bodies[b].velocity, m.bodies[b].angular_velocity) = ([0.5, 0.0], -1.0);
            id
        })
        .collect();
    for i in 0..n {
        let coupler = m.rigid(&format!("coupler{i}"), 1.0, inertia, [i as f64 + 0.5, 1.0], 0.0);
        let b = m.bodies.len() - 1;
        m.bodies[b].velocity = [1.0, 0.0];
        m.add(Element::Revolute { a: cranks[i], pa: [0.5, 0.0], b: coupler, pb: [-0.5, 0.0], limit: None });
        m.add(Element::Revolute { a: coupler, pa: [0.5, 0.0], b: cranks[i + 1], pb: [0.5, 0.0], limit: None });
    }
    for (i, &crank) in cranks.iter().enumerate() {
        m.add(Element::Revolute { a: BodyId::Ground, pa: [i as f64, 0.0], b: crank, pb: [-0.5, 0.0], limit: None });
    }
    m
}

/// B0 relative to its pivot, from the first crank's coordinates.
fn b0(q: &[f64]) -> [f64; 2] {
    [q[0] + 0.5 * q[2].cos(), q[1] + 0.5 * q[2].sin()]
}

/// The exact motion on the parallelogram branch: every crank turns by the
/// same θ and every coupler translates, so with `T = ½ J θ̇²`,
/// `J = (N+1)/3 + N` and `V = g ((N+1)/2 + N) sin θ` (unit masses and
/// lengths) `θ̈ = −k g cos θ`, `k = 3(3N+1) / (2(4N+1))`. Integrated by
/// RK-4 with 1e-4 s steps (error far below 1e-9 over 10 s), B0 sampled
/// every `every` s.
fn one_degree_of_freedom(n: usize, t_end: f64, every: f64) -> Vec<(f64, [f64; 2])> {
    let k = 3.0 * (3.0 * n as f64 + 1.0) / (2.0 * (4.0 * n as f64 + 1.0));
    let f = |[th, w]: [f64; 2]| [w, -k * G * th.cos()];
    let h = 1e-4;
    let (steps, sample) = ((t_end / h).round() as usize, (every / h).round() as usize);
    let mut y = [std::f64::consts::FRAC_PI_2, -1.0];
    let mut out = Vec::new();
    for i in 0..=steps {
        if i % sample == 0 {
            out.push((i as f64 * h, [y[0].cos(), y[0].sin()]));
        }
        let k1 = f(y);
        let k2 = f([y[0] + 0.5 * h * k1[0], y[1] + 0.5 * h * k1[1]]);
        let k3 = f([y[0] + 0.5 * h * k2[0], y[1] + 0.5 * h * k2[1]]);
        let k4 = f([y[0] + h * k3[0], y[1] + h * k3[1]]);
        for j in 0..2 {
            y[j] += h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]);
        }
    }
    out
}

/// The published B0 history (N = 40), first 10 s: see the data file for its source.
fn published() -> Vec<(f64, [f64; 2])> {
    include_str!("data/a02_b0_reference.txt")
        .lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            (v[0], [v[1], v[2]])
        })
        .collect()
}

/// Runs the N four-bar for 10 s with RK-4 at step `h`, returning the
/// largest distance of B0 from `reference` at its times and the rank loss.
fn a02(n: usize, h: f64, control: Control, reference: &[(f64, [f64; 2])]) -> (f64, Option<cdyn::simulate::RankLoss>) {
    a02_with(tolerant(Settings::new(Scheme::RungeKutta4, h, control)), n, reference)
}

/// [`a02`] with any settings.
fn a02_with(settings: Settings, n: usize, reference: &[(f64, [f64; 2])]) -> (f64, Option<cdyn::simulate::RankLoss>) {
    let h = settings.h;
    let built = n_four_bar(n).build().unwrap();
    assert_eq!((built.model.n(), built.model.m()), (6 * n + 3, 6 * n + 2));
    let mut sim = Simulation::new(&built.model, settings, &built.q0, &built.v0).unwrap();
    let every = (0.05 / h).round() as u64;
    let mut worst = 0.0_f64;
    let mut at = 0;
    sim.run::<Error>(10.0, every, |s| {
        let (t, r) = reference[at];
        assert!((s.t() - t).abs() < 1e-9, "sample at {} vs reference at {t}", s.t());
        let p = b0(s.q());
        worst = worst.max((p[0] - r[0]).abs()).max((p[1] - r[1]).abs());
        at += 1;
        Ok(())
    })
    .unwrap();
    assert_eq!(at, reference.len());
    (worst, sim.rank_loss().copied())
}

#[test]
fn the_published_a02_reference_is_the_one_degree_of_freedom_motion_for_n_40() {
    // The check of the reading above: the published history (N = 40) is
    // the exact motion to its printed digits — and not the N = 2 motion.
    let (reference, exact_40, exact_2) =
        (published(), one_degree_of_freedom(40, 10.0, 0.05), one_degree_of_freedom(2, 10.0, 0.05));
    assert_eq!(reference.len(), 201);
    let diff = |a: &[(f64, [f64; 2])]| {
        reference.iter().zip(a).fold(0.0_f64, |m, ((_, p), (_, q))| m.max((p[0] - q[0]).abs()).max((p[1] - q[1]).abs()))
    };
    assert!(diff(&exact_40) < 5e-6, "N = 40: {:e}", diff(&exact_40));
    assert!(diff(&exact_2) > 0.1, "N = 2: {:e}", diff(&exact_2));
}

/// The projection method: `Φ`, `Φ̇` and the energy projected after every step.
fn projection() -> Control {
    Control::none().with_projection(Some(Projection::default()))
}

/// Baumgarte's feedback, critically damped at 10 rad/s.
fn baumgarte() -> Control {
    Control::none().with_geometric(Geometric::baumgarte_from(10.0, 1.0).unwrap())
}

#[test]
fn a02_with_40_four_bars_follows_the_published_reference() {
    let (worst, loss) = a02(40, 1e-3, projection(), &published());
    eprintln!("A02 N = 40, h = 1e-3, projection: max |B0 − published| = {worst:e}, rank loss {loss:?}");
    // The published values are printed to 6 digits (about 1e-6).
    assert!(worst < 1e-3, "{worst:e}");
    // Steps that came within 1e-4 rad of the flat position solved around
    // the N rows that become dependent there.
    assert_eq!(loss.map(|l| l.max), Some(40), "{loss:?}");
}

#[test]
fn a02_with_2_four_bars_follows_the_exact_motion() {
    // Not a published reference: the published history is for N = 40.
    let exact = one_degree_of_freedom(2, 10.0, 0.05);
    for (name, control) in [("projection", projection()), ("baumgarte", baumgarte())] {
        let (worst, loss) = a02(2, 1e-3, control, &exact);
        eprintln!("A02 N = 2, h = 1e-3, {name}: max |B0 − exact| = {worst:e}, rank loss {loss:?}");
        assert!(worst < 1e-3, "{name}: {worst:e}");
    }
    // Without control the violations drift, and at a flat passage the
    // mechanism leaves the parallelogram branch for a folded one: the
    // benchmark's point.
    let (worst, _) = a02(2, 1e-3, Control::none(), &exact);
    eprintln!("A02 N = 2, h = 1e-3, no control: max |B0 − exact| = {worst:e}");
    assert!(worst > 0.1, "{worst:e}");
}

#[test]
fn every_method_is_well_defined_with_the_redundant_crank() {
    // The control laws divide by |∇Φᵢ|² (CVSGF) or solve with the singular
    // S: with the dependent row dropped each stays finite, and the motion
    // stays the plain four-bar's up to what the law does with the extra
    // row's violation (which it keeps at round-off).
    let theta0 = -0.6;
    let (plain, redundant) =
        (parallelogram(theta0, 0.0, false).build().unwrap(), parallelogram(theta0, 0.0, true).build().unwrap());
    let mut cases = cdyn::control::methods::compare_cases(&cdyn::control::methods::MethodGains::paper(), true);
    cases.push(("newton_auto", Control::none().with_geometric(Geometric::Newton(Rate::Auto))));
    cases.push(("cvsgf_auto", Control::none().with_geometric(Geometric::Gradient(cdyn::Gain::Auto))));
    let (h, steps) = (1e-3, 3000);
    for (name, control) in cases {
        let settings = Settings::new(Scheme::RungeKutta4, h, control);
        let mut a = Simulation::new(&plain.model, settings, &plain.q0, &plain.v0).unwrap();
        let mut b = Simulation::new(&redundant.model, tolerant(settings), &redundant.q0, &redundant.v0).unwrap();
        let mut worst = 0.0_f64;
        for _ in 0..steps {
            a.step().unwrap();
            b.step().unwrap_or_else(|e| panic!("{name}: {e}"));
            worst = worst.max(a.q().iter().zip(b.q()).fold(0.0_f64, |m, (x, y)| m.max((x - y).abs())));
        }
        let (phi_a, phi) = (a.measure().phi.abs(), b.measure().phi.abs());
        eprintln!("{name}: max |Δq| {worst:e}, |Φ| {phi:e} (plain {phi_a:e}), coupling {}", b.tuning().coupling);
        assert!(b.q().iter().chain(b.v()).all(|x| x.is_finite()), "{name}");
        if name == "energy" {
            // Energy control alone lets Φ drift (the plain four-bar's to
            // {phi_a}); past about 1e-4 the redundant row is independent
            // again and enforces a second, different crank. Not a law for
            // redundant constraints: it is finite, not followed.
            assert!(phi_a > 1e-5, "{name}: {phi_a:e}");
            continue;
        }
        assert!(worst < 1e-6 && phi < 1e-6, "{name}: |Δq| {worst:e}, |Φ| {phi:e}");
        assert_eq!(b.rank_loss().map(|r| r.steps), Some(steps), "{name}");
    }
}

#[test]
fn generalized_alpha_follows_a02_through_its_flat_positions() {
    // Index 3 at a singular position: Φ_q loses N rows' rank at the flat
    // position, the multipliers along the lost rows are ill-determined and
    // Newton's corrections stall at round-off magnified by the condition
    // (it stopped at t = 0.714 before it judged the residual there); a step
    // within 1e-4 rad of flat drops the dependent rows as the explicit
    // schemes do. The benchmark's high precision is 1e-3 on B0.
    let exact = one_degree_of_freedom(2, 10.0, 0.05);
    let alpha = |h| tolerant(Settings::new(Scheme::GeneralizedAlpha, h, Control::none()));
    let errors: Vec<f64> = [1e-3, 2e-3]
        .into_iter()
        .map(|h| {
            let (worst, _) = a02_with(alpha(h), 2, &exact);
            eprintln!("A02 N = 2, generalized-α h = {h}: max |B0 − exact| = {worst:e}");
            worst
        })
        .collect();
    // Measured: 1.9e-4 at 1e-3, 7.7e-4 at 2e-3 (RK-4 with projection: 4e-11 at 1e-3, 5e-4 at 5e-2).
    assert!(errors[0] < 1e-3, "{errors:?}");
    let order = (errors[1] / errors[0]).log2();
    assert!((order - 2.0).abs() < 0.1, "observed order {order}");
    let (worst, loss) = a02_with(alpha(1e-3), 40, &published());
    eprintln!("A02 N = 40, generalized-α h = 1e-3: max |B0 − published| = {worst:e}, rank loss {loss:?}");
    // Measured 1.9e-4; the steps that came within 1e-4 rad of flat (two) dropped up to 26 rows.
    assert!(worst < 1e-3, "{worst:e}");
    assert!(loss.is_some_and(|l| l.max > 1), "{loss:?}");
}

#[test]
fn generalized_alpha_drops_the_redundant_crank_as_the_explicit_schemes_do() {
    let theta0 = -0.6;
    let (plain, redundant) =
        (parallelogram(theta0, 0.0, false).build().unwrap(), parallelogram(theta0, 0.0, true).build().unwrap());
    let settings = Settings::new(Scheme::GeneralizedAlpha, 1e-3, Control::none());
    // Strict: the dependent row is named, with the setting that tolerates it
    // (the Newton matrix was singular, and the error said "take a smaller h").
    let err = Simulation::new(&redundant.model, settings, &redundant.q0, &redundant.v0).unwrap().step().unwrap_err();
    assert_eq!(err, Error::SingularConstraints { step: 0, t: 0.0, row: 8 });
    assert!(err.to_string().contains("dependent_rows = \"tolerate\""), "{err}");
    // Tolerated: the row found dependent at each new Newton matrix has
    // Δμ = 0 and λ = 0, and the rest is the plain four-bar's system.
    for solver in [LinearSolver::Dense, LinearSolver::Sparse] {
        let settings = settings.with_solver(solver);
        let mut a = Simulation::new(&plain.model, settings, &plain.q0, &plain.v0).unwrap();
        let mut b = Simulation::new(&redundant.model, tolerant(settings), &redundant.q0, &redundant.v0).unwrap();
        let (mut worst, mut swing) = (0.0_f64, 0.0_f64);
        for _ in 0..2000 {
            a.step().unwrap();
            b.step().unwrap_or_else(|e| panic!("{solver:?}: {e}"));
            worst = worst.max(a.q().iter().zip(b.q()).fold(0.0_f64, |m, (x, y)| m.max((x - y).abs())));
            swing = swing.max((b.q()[2] - theta0).abs());
        }
        eprintln!("{solver:?}: generalized-α, redundant against plain: max |Δq| {worst:e}, swing {swing}");
        assert!(worst < 1e-9, "{solver:?}: {worst:e}");
        assert!(swing > 0.5, "{solver:?}: the cranks turned by {swing} only");
        assert_eq!(b.rank_loss().map(|l| (l.max, l.steps)), Some((1, 2000)), "{solver:?}");
    }
}

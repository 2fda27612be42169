//! Joint limits held by `cdyn run`: a rod on a revolute joint falls from
//! rest onto a stop, from a scenario's `limit` key and from a URDF
//! `<limit>`, against the stop computed by hand.
//!
//! A rod of mass `m`, centre of mass `L` from the pivot, inertia `I` about
//! the pivot, released at rest at `φ₀` from the hanging position, has
//! `φ̇² = 2k (cos φ − cos φ₀)`, `k = m g L / I`. With `sin(φ/2) = sin(φ₀/2)
//! sin ψ` the time to fall to `φ*` is the elliptic integral
//! `t* = (F(π/2 | m) − F(ψ* | m)) / √k`, `m = sin²(φ₀/2)`, `sin ψ* =
//! sin(φ*/2) / sin(φ₀/2)`, and the rate there `√(2k (cos φ* − cos φ₀))`.

use crate::common::rod::{FINGER_UPPER, G, H, JYY, L, M, rod_at, turning_finger};
use crate::common::{Table, cdyn, one_error_line, path_str, scenario, summary_case, table};

/// `t*` of the module's head ([`cdyn::reference::time_to_swing`]).
fn stop_time(k: f64, phi0: f64, phi_stop: f64) -> f64 {
    cdyn::reference::time_to_swing(k, phi0, phi_stop).unwrap()
}

/// The rate `|φ̇|` at `φ*`.
fn stop_rate(k: f64, phi0: f64, phi_stop: f64) -> f64 {
    (2.0 * k * (phi_stop.cos() - phi0.cos())).sqrt()
}

/// Runs `text` (with `files` beside it); returns stdout, the CSV and summary.json's case.
fn run(text: &str, files: &[(&str, &str)]) -> (String, Table, serde_json::Value) {
    let (dir, path) = scenario("stop.toml", text);
    for (name, body) in files {
        std::fs::write(dir.join(name), body).unwrap();
    }
    let out = dir.join("out");
    let result = cdyn(&["run", path_str(&path), "--out", path_str(&out)]);
    assert!(result.status.success(), "{}", String::from_utf8_lossy(&result.stderr));
    (String::from_utf8_lossy(&result.stdout).into_owned(), table(&out.join("stop.csv")), summary_case(&out))
}

// The rod of the library's test (crates/cdyn/tests/limits.rs), released at
// φ₀ = 1.2 rad onto a stop at φ = 0.3 rad: its joint's θ = φ − φ₀ ≥ −0.9.
const PHI0: f64 = 1.2;
const PHI_STOP: f64 = 0.3;

fn rod(limit: &str) -> String {
    let (s, c) = (PHI0.sin(), PHI0.cos());
    let orientation = [(PHI0 / 2.0).cos(), 0.0, (PHI0 / 2.0).sin(), 0.0];
    rod_at(limit, [-L * s, 0.0, -L * c], orientation, "")
}

fn column(header: &[String], name: &str) -> usize {
    header.iter().position(|h| h == name).unwrap_or_else(|| panic!("no column {name} in {header:?}"))
}

#[test]
fn a_rod_falling_onto_its_limit_is_stopped_when_the_elliptic_integral_says_and_held_there() {
    let k = M * G * L / (JYY + M * L * L);
    let (t_star, rate) = (stop_time(k, PHI0, PHI_STOP), stop_rate(k, PHI0, PHI_STOP));
    let bound = PHI_STOP - PHI0;
    let (stdout, (header, rows), case) = run(&rod(&format!("{{ lower = {bound} }}")), &[]);
    assert!(stdout.contains("limits: 1 impact, 0 releases"), "{stdout}");
    let events = case["limits"]["events"].as_array().unwrap();
    assert_eq!(events.len(), 1, "{events:?}");
    let event = &events[0];
    assert_eq!((event["joint"].as_str(), event["side"].as_str()), (Some("joints[0]"), Some("lower")));
    assert_eq!((event["event"].as_str(), event["held"].as_bool()), (Some("impact"), Some(true)));
    let t = event["t"].as_f64().unwrap();
    eprintln!("stopped at {t}, by hand {t_star}; rate {} against {rate}", event["rate"]);
    assert!((t - t_star).abs() < 1e-6, "stopped at {t}, by hand {t_star}");
    let hit = event["rate"].as_f64().unwrap();
    // Seen at the step's end, up to h after the crossing: within h |θ̈| of the rate there.
    assert!((-hit - rate).abs() < H * k, "{hit} against {rate}");
    let lost = event["kinetic_energy_lost"].as_f64().unwrap();
    assert!((lost - 0.5 * (JYY + M * L * L) * hit * hit).abs() < 1e-9 * lost, "{lost}");
    // The CSV: one table on the h grid; θ at the bound and at rest from the step after.
    let (q, v) = (column(&header, "joints[0].q"), column(&header, "joints[0].v"));
    assert_eq!(rows.len(), 1001);
    assert!(rows.iter().enumerate().all(|(i, r)| (r[0] - i as f64 * H).abs() < 1e-12));
    let after: Vec<_> = rows.iter().filter(|r| r[0] > t + H).collect();
    assert!(after.len() > 500);
    let worst = after.iter().fold(0.0_f64, |w, r| w.max((r[q] - bound).abs()).max(r[v].abs()));
    assert!(worst < 1e-9, "off the stop by {worst}");
    assert!(rows.iter().all(|r| r[q] >= bound - 1e-9), "past the stop");
}

#[test]
fn a_rod_with_restitution_rebounds_at_minus_e_times_its_rate_and_its_velocity_bound_is_reported() {
    let e = 0.5;
    let bound = PHI_STOP - PHI0;
    let text = rod(&format!("{{ lower = {bound}, restitution = {e}, velocity = 1.0 }}"));
    let (stdout, (header, rows), case) = run(&text, &[]);
    let events = case["limits"]["events"].as_array().unwrap();
    let first = &events[0];
    assert_eq!((first["event"].as_str(), first["held"].as_bool()), (Some("impact"), Some(false)));
    let (rate, t) = (first["rate"].as_f64().unwrap(), first["t"].as_f64().unwrap());
    // Hit at the crossing, at the closed form's rate: θ̇⁺ = −e θ̇⁻ there, and
    // the CSV row of the impact's step, at its end, the free pendulum since.
    let k = M * G * L / (JYY + M * L * L);
    let v = column(&header, "joints[0].v");
    let row = rows.iter().find(|r| r[0] > t).unwrap();
    let crossing = stop_rate(k, PHI0, PHI_STOP);
    assert!((rate + crossing).abs() < 1e-9 * crossing, "{rate} against {crossing}");
    let rebound = cdyn::reference::PendulumExact::new(k, PHI_STOP - std::f64::consts::FRAC_PI_2, e * crossing);
    let expected = rebound.unwrap().angle(row[0] - t).1;
    assert!((row[v] - expected).abs() < 1e-9 * crossing, "{} against {expected}", row[v]);
    // The fastest the joint went is the rate into the stop, within h |θ̈|.
    let exceeded = &case["limits"]["velocity_exceeded"][0];
    assert_eq!(exceeded["joint"].as_str(), Some("joints[0]"));
    let ratio = exceeded["ratio"].as_f64().unwrap();
    assert!((ratio - stop_rate(k, PHI0, PHI_STOP)).abs() < H * k, "{ratio}");
    assert!(stdout.contains("joints[0] exceeded its velocity bound"), "{stdout}");
}

/// A bar on a hinge about y, its centre of mass `L` along x from it, the
/// hinge limited to ±0.5 rad.
const BAR: &str = r#"<robot name="bar">
  <link name="base"/>
  <link name="bar">
    <inertial>
      <origin xyz="0.4 0 0"/>
      <mass value="1.5"/>
      <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.03" iyz="0" izz="0.03"/>
    </inertial>
  </link>
  <joint name="hinge" type="revolute">
    <parent link="base"/>
    <child link="bar"/>
    <axis xyz="0 1 0"/>
    <limit lower="-0.5" upper="0.5" effort="10" velocity="10"/>
  </joint>
</robot>
"#;

#[test]
fn a_urdf_joint_is_held_at_its_limit() {
    // Released horizontal (φ₀ = π/2 from hanging), the bar turns by θ =
    // π/2 − φ about +y, onto the upper bound θ = 0.5.
    let text = format!(
        "[model]\nkind = \"spatial\"\nurdf = \"bar.urdf\"\ngravity = [0.0, 0.0, -{G}]\n\n[integrator]\nscheme = \"rk4\"\nh = {H}\nt_end = 1.0\n"
    );
    let (stdout, (header, rows), case) = run(&text, &[("bar.urdf", BAR)]);
    assert!(stdout.contains("limits: 1 impact, 0 releases"), "{stdout}");
    assert!(!stdout.contains("not yet by cdyn run"), "{stdout}");
    let (m, l, iyy) = (1.5, 0.4, 0.03);
    let k = m * G * l / (iyy + m * l * l);
    let phi0 = std::f64::consts::FRAC_PI_2;
    let t_star = stop_time(k, phi0, phi0 - 0.5);
    let event = &case["limits"]["events"][0];
    assert_eq!((event["joint"].as_str(), event["side"].as_str()), (Some("hinge"), Some("upper")));
    let t = event["t"].as_f64().unwrap();
    assert!((t - t_star).abs() < 1e-6, "stopped at {t}, by hand {t_star}");
    let q = column(&header, "hinge.q");
    let max = rows.iter().fold(f64::MIN, |w, r| w.max(r[q]));
    assert!(max < 0.5 + 1e-9, "swung past its limit to {max}");
    let last = rows.last().unwrap();
    assert!((last[q] - 0.5).abs() < 1e-9, "{}", last[q]);
}

#[test]
fn bad_limits_get_one_line_naming_the_joint() {
    let text = format!(
        "[model]\nkind = \"spatial\"\nurdf = \"bar.urdf\"\n\n[integrator]\nscheme = \"rk4\"\nh = {H}\nt_end = 0.1\n"
    );
    let cases = [
        (BAR.replace(r#"lower="-0.5" upper="0.5""#, r#"lower="0.5" upper="-0.5""#), "lower is above upper"),
        (BAR.replace(r#"upper="0.5""#, r#"upper="nan""#), "a bound is not a number"),
    ];
    for (urdf, reason) in cases {
        let (dir, path) = scenario("bad.toml", &text);
        std::fs::write(dir.join("bar.urdf"), urdf).unwrap();
        let line = one_error_line(&cdyn(&["run", path_str(&path), "--out", path_str(&dir.join("out"))]));
        assert!(line.contains("bad.toml") && line.contains("\"hinge\"") && line.contains(reason), "{line}");
    }
}

/// A planar rod hanging from the ground `L` above its centre of mass
/// (`point_b = [0, L]`), its angle 0 hanging, released at rest at `PHI0`:
/// its revolute joint's coordinate is its angle.
fn planar_rod(limit: &str, more: &str) -> String {
    format!(
        r#"{header}
[[bodies]]
name = "rod"
mass = {M}
inertia = {JYY}
position = [{x}, {y}]
angle = {PHI0}

[[joints]]
kind = "revolute"
a = "ground"
b = "rod"
point_b = [0.0, {L}]
limit = {limit}
{more}"#,
        header = planar_header(1.0),
        x = L * PHI0.sin(),
        y = -L * PHI0.cos(),
    )
}

/// The `[model]` and `[integrator]` of the planar cases: under gravity,
/// RK-4 at `H` for `t_end`.
fn planar_header(t_end: f64) -> String {
    format!(
        "\n[model]\nkind = \"mechanism\"\ngravity = [0.0, -{G}]\n\n[integrator]\nscheme = \"rk4\"\nh = {H}\nt_end = {t_end:?}\n"
    )
}

#[test]
fn a_planar_rod_falling_onto_its_limit_is_stopped_when_the_elliptic_integral_says_and_held_there() {
    let k = M * G * L / (JYY + M * L * L);
    let t_star = stop_time(k, PHI0, PHI_STOP);
    let (stdout, (header, rows), case) = run(&planar_rod(&format!("{{ lower = {PHI_STOP} }}"), ""), &[]);
    assert!(stdout.contains("limits: 1 impact, 0 releases"), "{stdout}");
    let events = case["limits"]["events"].as_array().unwrap();
    assert_eq!(events.len(), 1, "{events:?}");
    let event = &events[0];
    assert_eq!((event["joint"].as_str(), event["side"].as_str()), (Some("joints[0]"), Some("lower")));
    assert_eq!((event["bound"].as_f64(), event["held"].as_bool()), (Some(PHI_STOP), Some(true)));
    let t = event["t"].as_f64().unwrap();
    assert!((t - t_star).abs() < 1e-6, "stopped at {t}, by hand {t_star}");
    let hit = event["rate"].as_f64().unwrap();
    assert!((-hit - stop_rate(k, PHI0, PHI_STOP)).abs() < H * k, "{hit}");
    // One table on the h grid, the angle at the bound from the step after on.
    let angle = column(&header, "rod.angle");
    assert_eq!(rows.len(), 1001);
    let after: Vec<_> = rows.iter().filter(|r| r[0] > t + H).collect();
    assert!(after.len() > 500);
    assert!(after.iter().all(|r| (r[angle] - PHI_STOP).abs() < 1e-9), "off the stop");
    assert!(rows.iter().all(|r| r[angle] >= PHI_STOP - 1e-9), "past the stop");
}

#[test]
fn a_planar_slider_is_stopped_at_its_limit_down_an_incline_and_its_velocity_bound_reported() {
    // A point mass from rest down a line at α below the horizontal: s = ½ g sin α t².
    let (alpha, d) = (0.5_f64, 0.4);
    let text = format!(
        r#"{header}
[[bodies]]
name = "block"
mass = 3.0
position = [0.0, 0.0]

[[joints]]
kind = "prismatic"
a = "ground"
b = "block"
axis = [{c}, {s}]
limit = {{ upper = {d}, velocity = 1.0 }}
"#,
        header = planar_header(0.6),
        c = alpha.cos(),
        s = -alpha.sin(),
    );
    let (stdout, (header, rows), case) = run(&text, &[]);
    let a = G * alpha.sin();
    let t_star = (2.0 * d / a).sqrt();
    let event = &case["limits"]["events"][0];
    assert_eq!((event["joint"].as_str(), event["side"].as_str()), (Some("joints[0]"), Some("upper")));
    let t = event["t"].as_f64().unwrap();
    assert!((t - t_star).abs() < 1e-9, "stopped at {t}, by hand {t_star}");
    // Past 1 m/s at t = 1 / a, first seen at the step's end after it.
    let exceeded = &case["limits"]["velocity_exceeded"][0];
    assert_eq!(exceeded["joint"].as_str(), Some("joints[0]"));
    let first = exceeded["t"].as_f64().unwrap();
    assert!(first >= 1.0 / a && first < 1.0 / a + H + 1e-12, "{first}");
    assert!(stdout.contains("joints[0] exceeded its velocity bound"), "{stdout}");
    // Held at s = d: x = d cos α from then on.
    let x = column(&header, "block.x");
    let last = rows.last().unwrap();
    assert!((last[x] - d * alpha.cos()).abs() < 1e-9, "{}", last[x]);
}

#[test]
fn bad_planar_limits_get_one_line_naming_the_file_and_the_joint() {
    for (limit, says) in [
        ("{ lower = 1.0, upper = -1.0 }", "joints[0] (revolute): limit lower = 1, upper = -1: lower is above upper"),
        ("{ lower = nan }", "joints[0] (revolute): limit lower = NaN, upper = inf: a bound is not a number"),
        ("{ lower = 0.1, restitution = -0.5 }", "joints[0] (revolute): restitution = -0.5 must be in [0, 1]"),
        ("{ lower = 0.1, velocity = -2.0 }", "joints[0] (revolute): velocity limit = -2"),
        ("{ lower = 0.1, effort = 3.0 }", "limit effort = 3: a planar joint has no actuator to clamp"),
        ("{ lower = 0.1, uper = 1.0 }", "uper"),
    ] {
        let (dir, path) = scenario("bad.toml", &planar_rod(limit, ""));
        let line = one_error_line(&cdyn(&["run", path_str(&path), "--out", path_str(&dir.join("out"))]));
        assert!(line.contains("bad.toml") && line.contains("joints[0]") && line.contains(says), "{limit}: {line}");
    }
    // Started past its bound; a limit on a joint without a coordinate.
    let (dir, path) = scenario("bad.toml", &planar_rod("{ upper = 1.0 }", ""));
    let line = one_error_line(&cdyn(&["run", path_str(&path), "--out", path_str(&dir.join("out"))]));
    assert!(line.contains("bad.toml: joint joints[0]: starts 2.000e-1 past its upper limit 1"), "{line}");
    let distance =
        "[[joints]]\nkind = \"distance\"\na = \"ground\"\nb = \"rod\"\nlength = 1.0\nlimit = { lower = 0.0 }\n";
    let (dir, path) = scenario("bad.toml", &planar_rod("{ lower = 0.3 }", distance));
    let line = one_error_line(&cdyn(&["run", path_str(&path), "--out", path_str(&dir.join("out"))]));
    assert!(line.contains("bad.toml") && line.contains("joints[1]") && line.contains("limit"), "{line}");
}

/// A rod on a revolute joint about y whose built pose points straight up
/// (its joint's `θ = φ − π`, `φ` from hanging), limited to `[2, 4.5]`: a
/// range shorter than a turn that straddles π. Released at rest at
/// `θ = 2.5`, it swings down through `θ = π` (hanging) to `2π − 2.5` and
/// back, inside its range, meeting no stop.
#[test]
fn a_rods_angle_in_a_range_across_pi_is_reported_in_that_range_without_a_jump() {
    let initial = "\n[initial]\njoints = { \"joints[0]\" = 2.5 }\n";
    let text = rod_at("{ lower = 2.0, upper = 4.5 }", [0.0, 0.0, L], [0.0, 0.0, 1.0, 0.0], initial);
    let (stdout, (header, rows), case) = run(&text, &[]);
    assert!(stdout.contains("limits: 0 impacts, 0 releases"), "{stdout}");
    let q = column(&header, "joints[0].q");
    let (low, high) = rows.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), r| (l.min(r[q]), h.max(r[q])));
    // Energy kept: it turns back at 2π − 2.5, sampled within ½ θ̈ (h/2)² of it.
    assert!((low - 2.5).abs() < 1e-5 && (high - (std::f64::consts::TAU - 2.5)).abs() < 1e-5, "{low} … {high}");
    // Through π at most |θ̇| h = 2.74e-3 a step (√(2k (1 − cos(π − 2.5))), k = m g L / I).
    let jump = rows.windows(2).map(|w| (w[1][q] - w[0][q]).abs()).fold(0.0, f64::max);
    assert!(jump < 2.8e-3, "the angle jumps by {jump}");
    let reported = case["joint_space"]["joints"].as_array().unwrap();
    let stats = reported.iter().find(|c| c["column"] == "joints[0].q").unwrap();
    assert_eq!((stats["min"].as_f64(), stats["max"].as_f64()), (Some(low), Some(high)), "{stats}");
}

#[test]
fn multi_turn_limits_a_finger_turning_past_pi_meets_its_upper_stop_at_the_turn_it_started_in() {
    // θ = θ₀ + 2t: from 0 it passes π and 3.66 (read −2.62 in (−π, π],
    // its lower bound: a spurious stop before) to 6.28 at 3.14 s; from
    // 5.0 (read −1.28 from the state alone) to 6.28 at 0.64 s.
    for (theta0, t_end) in [(0.0, 3.5), (5.0, 1.0)] {
        let t_star = (FINGER_UPPER - theta0) / 2.0;
        let (_, _, case) = run(&turning_finger(theta0, t_end), &[]);
        let events = case["limits"]["events"].as_array().unwrap();
        let impacts: Vec<_> = events.iter().filter(|e| e["event"] == "impact").collect();
        let [impact] = impacts[..] else { panic!("from {theta0}: {events:?}") };
        assert_eq!((impact["side"].as_str(), impact["held"].as_bool()), (Some("upper"), Some(true)), "{impact}");
        let t = impact["t"].as_f64().unwrap();
        assert!((t - t_star).abs() < 1e-9, "from {theta0}: stopped at {t}, by hand {t_star}");
    }
}

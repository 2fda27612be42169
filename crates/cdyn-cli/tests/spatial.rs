//! Spatial mechanisms in scenario files (`kind = "spatial"`): the shipped
//! examples run and reproduce their references, and bad entries get one
//! line naming the entry.

use crate::common::{cdyn, one_error_line, path_str, scenario, summary_case, table};
use std::path::{Path, PathBuf};

fn example(name: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples").join(name);
    std::fs::read_to_string(path).unwrap()
}

/// Runs `cdyn run` on `text`; returns the output directory.
fn run(name: &str, text: &str) -> PathBuf {
    let (dir, path) = scenario(&format!("{name}.toml"), text);
    let out = dir.join("out");
    let result = cdyn(&["run", path_str(&path), "--out", path_str(&out)]);
    assert!(result.status.success(), "{}", String::from_utf8_lossy(&result.stderr));
    out
}

#[test]
fn the_heavy_top_example_ends_on_the_published_euler_parameters() {
    let out = run("heavy_top", &example("heavy_top.toml"));
    // The 3-D view at four instants, besides the figures of every run.
    for file in ["mechanism.png", "mechanism.svg", "phi.png", "psi.svg"] {
        assert!(out.join(file).metadata().is_ok_and(|m| m.len() > 1000), "{file}");
    }
    let svg = std::fs::read_to_string(out.join("mechanism.svg")).unwrap();
    assert!(svg.contains("t = 0.0000 s") && svg.contains("t = 0.2000 s"), "the first and last instants");
    let (header, rows) = table(&out.join("heavy_top.csv"));
    let last = rows.last().unwrap();
    assert_eq!(last[0], 0.2);
    // Published at t = 0.2 s (Exudyn's heavy-top test): to every digit given.
    for (key, published, half_unit) in
        [("top.e0", -0.70828, 5e-6), ("top.e1", 0.43878, 5e-6), ("top.e2", 0.54573, 5e-6), ("top.e3", 0.0894, 5e-5)]
    {
        let column = header.iter().position(|h| h == key).unwrap();
        assert!((last[column] - published).abs() <= half_unit, "{key} = {} vs {published}", last[column]);
    }
}

/// The page's inline data in `dir`.
fn page_data(dir: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(dir.join("report.html")).unwrap();
    let open = r#"<script id="data" type="application/json">"#;
    let start = text.find(open).unwrap() + open.len();
    serde_json::from_str(&text[start..start + text[start..].find("</script>").unwrap()]).unwrap()
}

#[test]
fn a_spatial_runs_page_and_gif_animate_it_in_3d() {
    // The heavy top: no URDF, so drawn as the box of its inertia — a thin
    // square plate (Iy = Ix + Iz), 0.433 m wide and the smallest drawn thickness.
    let (dir, path) = scenario("top.toml", &example("heavy_top.toml"));
    let out = dir.join("out");
    let r = cdyn(&["run", path_str(&path), "--out", path_str(&out), "--html", "--gif"]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let data = page_data(&out);
    let sketch = &data["sketch"];
    let top = &sketch["bodies"][0];
    assert_eq!(
        (top["name"].as_str(), top["shaped"].as_bool(), top["first"].as_u64()),
        (Some("top"), Some(false), Some(0))
    );
    let faces = top["faces"].as_array().unwrap();
    assert_eq!(faces.len(), 6);
    let radius = sketch["radius"].as_f64().unwrap();
    let corner = |f: &serde_json::Value| -> Vec<f64> {
        f["corners"][0].as_array().unwrap().iter().map(|x| x.as_f64().unwrap().abs()).collect()
    };
    let mut half: Vec<f64> = faces.iter().flat_map(corner).collect();
    half.sort_by(f64::total_cmp);
    let (thin, wide) = (half[0], half[half.len() - 1]);
    assert!((wide - 0.5 * 0.1875f64.sqrt()).abs() < 1e-12 && (thin - 0.005 * radius).abs() < 1e-12, "{half:?}");
    // The top turns about its fixed point at the origin, 1 m away: the scene holds both.
    assert!(radius > 0.5 && radius < 2.0, "{radius}");
    let frames = data["cases"][0]["frames"]["q"].as_array().unwrap();
    assert_eq!((frames.len(), frames[0].as_array().unwrap().len()), (21, 7));
    assert!(!std::fs::read_to_string(out.join("report.html")).unwrap().contains("CDYN_3D"));
    gif_moves(&out.join("animation.gif"), 21);

    // The URDF arm: its links' own primitives, the massless tool's sphere on the hand, the base's on the ground.
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let out = dir.join("arm");
    let r = cdyn(&["run", path_str(&examples.join("arm.urdf")), "--out", path_str(&out), "--html"]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let data = page_data(&out);
    let bodies = data["sketch"]["bodies"].as_array().unwrap();
    let counts: Vec<(usize, usize, bool)> = bodies
        .iter()
        .map(|b| (b["faces"].as_array().unwrap().len(), b["spheres"].as_array().unwrap().len(), b["shaped"] == true))
        .collect();
    assert_eq!(counts, [(18, 0, true), (6, 0, true), (0, 1, true)], "cylinder, box, sphere");
    assert_eq!(bodies[2]["spheres"][0]["radius"].as_f64(), Some(0.05));
    // The base's cylinder on the ground, in space: its top at z = 0.1.
    let ground = &data["sketch"]["ground"]["faces"];
    assert_eq!(ground.as_array().unwrap().len(), 18, "{ground}");
    let top = ground.as_array().unwrap().iter().find(|f| f["normal"][2].as_f64() == Some(1.0)).unwrap();
    assert!(top["corners"].as_array().unwrap().iter().all(|c| (c[2].as_f64().unwrap() - 0.1).abs() < 1e-15), "{top}");
}

/// The GIF at `path` has `n` frames of 480 × 360 pixels, and many pixels change between the first and the middle one.
fn gif_moves(path: &Path, n: usize) {
    use image::AnimationDecoder;
    let file = std::fs::File::open(path).unwrap();
    let frames = image::codecs::gif::GifDecoder::new(file).unwrap().into_frames().collect_frames().unwrap();
    assert_eq!(frames.len(), n);
    assert_eq!(frames[0].buffer().dimensions(), (480, 360));
    let (first, middle) = (frames[0].buffer(), frames[n / 2].buffer());
    let changed = first.pixels().zip(middle.pixels()).filter(|(a, b)| a != b).count();
    assert!(changed > 500, "the mechanism did not move: {changed} pixels differ");
}

#[test]
fn bricards_redundant_mechanism_moves_and_keeps_its_energy_without_control() {
    // The example as shipped (projection), and without any control.
    let text = example("bricard.toml");
    let none = text.replace("[method]\npreset = \"projection\"\n", "");
    assert_ne!(none, text);
    for (name, text, psi_bound) in [("projected", &text, 1e-11), ("uncontrolled", &none, 1e-9)] {
        let out = run(name, text);
        let summary: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
        let case = &summary["cases"][0];
        // RK-4 at h = 1e-3 over 10 s: |Ψ| (the energy balance) 1.3e-12 with
        // projection and 1.2e-10 without control; |Φ| 5e-13 and 2e-11.
        assert!(case["max_abs_psi"].as_f64().unwrap() < psi_bound, "{name}: {case}");
        assert!(case["max_abs_phi"].as_f64().unwrap() < 1e-9, "{name}: {case}");
        // One row is redundant at every step, and it was dropped, not failed on.
        assert_eq!(case["dependent_rows"]["max"].as_u64(), Some(1), "{name}: {case}");
        assert_eq!(case["steps"].as_u64(), Some(10_000));
        // It moves: the first rod swings about the y axis through half a turn.
        let (header, rows) = table(&out.join(format!("{name}.csv")));
        let x = header.iter().position(|h| h == "rod1.x").unwrap();
        let lowest = rows.iter().map(|r| r[x]).fold(f64::INFINITY, f64::min);
        assert!(lowest < -0.4, "{name}: rod1.x stays above {lowest}");
    }
}

#[test]
fn bricards_projection_holds_the_energy_though_it_has_as_many_rows_as_coordinates() {
    // 35 rows on 35 coordinates, one of them dependent: one degree of
    // freedom, so the projection holds Ψ, to its tolerance 1e-10 of
    // T + |V| (some tens of J). At h = 2e-2: 3.8e-9; 1.8e-7 when rows
    // were counted with the dependent one (as a fully driven mechanism).
    let text = example("bricard.toml").replace("h = 1e-3", "h = 2e-2").replace("t_end = 10.0", "t_end = 5.0");
    let out = run("coarse", &text);
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let case = &summary["cases"][0];
    assert_eq!(case["dependent_rows"]["max"].as_u64(), Some(1), "{case}");
    assert!(case["max_abs_psi"].as_f64().unwrap() < 1e-8, "{case}");
}

#[test]
fn bricard_with_generalized_alpha_drops_its_redundant_row_and_converges_at_order_2() {
    // RK-4 at h = 1e-3 with projection is the reference (4e-12 from RK-4 at
    // 1e-4); the benchmark's high precision is 1e-3 on positions.
    let text = example("bricard.toml");
    let reference = table(&run("reference", &text).join("reference.csv"));
    let errors: Vec<f64> = [(1e-2, 1), (5e-3, 2)]
        .into_iter()
        .map(|(h, every)| {
            let alpha = text
                .replace("scheme = \"rk4\"", "scheme = \"generalized_alpha\"")
                .replace("h = 1e-3", &format!("h = {h}"))
                .replace("every = 10", &format!("every = {every}"))
                .replace("[method]\npreset = \"projection\"\n", "");
            let out = run("alpha", &alpha);
            let summary: serde_json::Value =
                serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
            assert_eq!(summary["cases"][0]["dependent_rows"]["max"].as_u64(), Some(1), "{summary}");
            largest_difference(&reference, &table(&out.join("alpha.csv")), "rod")
        })
        .collect();
    // Measured: 8.0e-4 at 1e-2, 2.0e-4 at 5e-3 (RK-4 without control: 3e-7 at 1e-2).
    assert!(errors[0] < 1e-3, "{errors:?}");
    let order = (errors[0] / errors[1]).log2();
    assert!((order - 2.0).abs() < 0.1, "{errors:?}: observed order {order}");
}

/// The largest difference of the columns starting with `prefix` between two
/// runs' tables, at the times both have.
fn largest_difference(a: &(Vec<String>, Vec<Vec<f64>>), b: &(Vec<String>, Vec<Vec<f64>>), prefix: &str) -> f64 {
    let columns: Vec<(usize, usize)> =
        a.0.iter()
            .enumerate()
            .filter(|(_, h)| h.starts_with(prefix) && !h.contains(".e"))
            .map(|(i, h)| (i, b.0.iter().position(|g| g == h).unwrap()))
            .collect();
    let mut worst = 0.0_f64;
    for row in &a.1 {
        if let Some(other) = b.1.iter().find(|r| (r[0] - row[0]).abs() < 1e-9) {
            worst = columns.iter().fold(worst, |w, &(i, j)| w.max((row[i] - other[j]).abs()));
        }
    }
    worst
}

#[test]
fn bad_spatial_entries_get_one_line_naming_the_entry() {
    let good = example("heavy_top.toml");
    let cases: Vec<(String, &[&str])> = vec![
        (
            good.replace("orientation = [1.0, 0.0, 0.0, 0.0]", "orientation = [0.0, 0.0, 0.0, 0.0]"),
            &["bodies[0] (top): orientation has length 0"],
        ),
        (
            good.replace("orientation = [1.0, 0.0, 0.0, 0.0]", "orientation = [1.0, 0.5, 0.0, 0.0]"),
            &["bodies[0] (top)", "unit quaternion"],
        ),
        (
            good.replace("inertia = [0.234375, 0.46875, 0.234375]", "inertia = [0.1, 0.1, 0.5]"),
            &["bodies[0] (top): inertia is not physical"],
        ),
        (
            good.replace("inertia = [0.234375, 0.46875, 0.234375]", "inertia = [0.1, -0.1, 0.1]"),
            &["bodies[0] (top): inertia must be positive definite"],
        ),
        (
            good.replace("inertia = [0.234375, 0.46875, 0.234375]", "inertia = [0.1, 0.1]"),
            &["bodies[0]", "inertia", "principal moments"],
        ),
        (good.replace("mass = 15.0", "mass = 15.0\nangle = 1.0"), &["bodies[0]", "angle"]),
        (good.replace("kind = \"spherical\"", "kind = \"hinge\""), &["joints[0]", "hinge"]),
        (
            good.replace("kind = \"spherical\"", "kind = \"revolute\""),
            &["joints[0] (revolute): a revolute joint needs axis"],
        ),
        (
            good.replace("point = [0.0, 0.0, 0.0]", "point = [0.0, 0.0, 0.0]\naxis = [0.0, 0.0, 0.0]"),
            &["joints[0] (spherical): a spherical joint takes no axis"],
        ),
        (good.replace("a = \"top\"", "a = \"tip\""), &["joints[0] (spherical): a = \"tip\": no body of that name"]),
        (good.replace("gravity = [0.0, 0.0, -9.81]", "gravity = [0.0, -9.81]"), &["gravity", "[gx, gy, gz]"]),
        (good.replace("[[bodies]]", "[[drives]]\nkind = \"angle\"\n\n[[bodies]]"), &["spatial", "[[drives]]"]),
        (
            good.replace("point = [0.0, 0.0, 0.0]", "point = [0.0, 0.0, 0.0]\nlimit = { lower = -1.0, upper = 1.0 }"),
            &["joints[0] (spherical): joint 0 is spherical: only revolute and prismatic joints have a coordinate"],
        ),
        (
            good.replace("kind = \"spherical\"", "kind = \"revolute\"\naxis = [0.0, 1.0, 0.0]")
                .replace("point = [0.0, 0.0, 0.0]", "point = [0.0, 0.0, 0.0]\nlimit = { lower = 1.0, upper = -1.0 }"),
            &["joints[0] (revolute): limit lower = 1, upper = -1: lower is above upper"],
        ),
        (
            good.replace("kind = \"spherical\"", "kind = \"revolute\"\naxis = [0.0, 1.0, 0.0]")
                .replace("point = [0.0, 0.0, 0.0]", "point = [0.0, 0.0, 0.0]\nlimit = { lower = -1.0, upper = nan }"),
            &["joints[0] (revolute): limit lower = -1, upper = NaN: a bound is not a number"],
        ),
        (
            good.replace("kind = \"spherical\"", "kind = \"revolute\"\naxis = [0.0, 1.0, 0.0]")
                .replace("point = [0.0, 0.0, 0.0]", "point = [0.0, 0.0, 0.0]\nlimit = { lower = -1.0, stiff = 2.0 }"),
            &["joints[0]", "stiff"],
        ),
    ];
    for (text, expected) in cases {
        let (dir, path) = scenario("bad.toml", &text);
        let line = one_error_line(&cdyn(&["run", path_str(&path), "--out", path_str(&dir.join("out"))]));
        for e in expected {
            assert!(line.contains(e), "{line:?} should contain {e:?}");
        }
        assert!(!dir.join("out").join("bad.csv").exists(), "output written for a refused scenario");
    }
}

#[test]
fn a_urdf_robot_runs_alone_and_with_a_loop_closure_from_the_scenario() {
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("alone");
    let result = cdyn(&["run", path_str(&examples.join("arm.urdf")), "--out", path_str(&out)]);
    assert!(result.status.success(), "{}", String::from_utf8_lossy(&result.stderr));
    let (header, rows) = table(&out.join("arm.csv"));
    assert_eq!(&header[1..4], ["upper.x", "upper.y", "upper.z"]);
    assert_eq!(rows.last().unwrap()[0], 1.0);
    // The tethered arm: the scenario's distance rod holds the hand's point at 1 m from its anchor.
    let out = dir.path().join("tethered");
    let result = cdyn(&["run", path_str(&examples.join("arm_tethered.toml")), "--out", path_str(&out)]);
    assert!(result.status.success(), "{}", String::from_utf8_lossy(&result.stderr));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert!(summary["cases"][0]["max_abs_phi"].as_f64().unwrap() < 1e-10, "{summary}");
    let (_, tethered) = table(&out.join("arm_tethered.csv"));
    let (_, alone) = table(&dir.path().join("alone/arm.csv"));
    // Held up, the hand falls less far in the first second than alone.
    let z = 17; // hand.z: t, then 7 coordinates per body, the hand third
    let drop = |rows: &[Vec<f64>]| {
        rows[0][z] - rows.iter().filter(|r| r[0] <= 1.0).map(|r| r[z]).fold(f64::INFINITY, f64::min)
    };
    assert!(drop(&tethered) < drop(&alone) && drop(&alone) > 0.05, "{} vs {}", drop(&tethered), drop(&alone));
}

#[test]
fn a_robots_csv_has_each_joints_angle_and_rate_under_its_urdf_name() {
    // arm.urdf for 0.2 s, every step written (h = 1e-3).
    let text = example("arm_tethered.toml").replace("t_end = 2.0", "t_end = 0.2").replace("every = 10", "every = 1");
    let text = &text[..text.find("[[joints]]").unwrap()]; // the arm alone
    let (dir, path) = scenario("arm.toml", text);
    std::fs::write(dir.join("arm.urdf"), example("arm.urdf")).unwrap();
    let out = dir.join("out");
    let result = cdyn(&["run", path_str(&path), "--out", path_str(&out)]);
    assert!(result.status.success(), "{}", String::from_utf8_lossy(&result.stderr));
    let (header, rows) = table(&out.join("arm.csv"));
    // After the three bodies' coordinates, the revolute and continuous
    // joints (not the fixed tool_mount), in the URDF's order.
    let joints = ["shoulder_yaw", "shoulder_pitch", "wrist"];
    let expected: Vec<String> = joints.iter().flat_map(|j| [format!("{j}.q"), format!("{j}.v")]).collect();
    assert_eq!(header[22..28], expected[..]);
    assert_eq!(header[28..], ["phi", "psi"]);
    // The yaw joint turns `upper` about the vertical from the ground:
    // its angle is 2 atan2(e3, e0) of the body's Euler parameters.
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    let (e0, e3, yaw) = (col("upper.e0"), col("upper.e3"), col("shoulder_yaw.q"));
    let wrap = |x: f64| (x + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
    let yaw_error = rows.iter().map(|r| wrap(r[yaw] - 2.0 * r[e3].atan2(r[e0])).abs()).fold(0.0, f64::max);
    let turned = rows.iter().map(|r| r[yaw].abs()).fold(0.0, f64::max);
    assert!(yaw_error < 1e-12 && turned > 0.1, "yaw off by {yaw_error:e}, turned {turned}");
    // Each rate is the derivative of its angle: a central difference over
    // ±k rows agrees to O((k h)²), four times closer at k = 1 than at k = 2.
    for j in joints {
        let (q, v) = (col(&format!("{j}.q")), col(&format!("{j}.v")));
        let difference = |k: usize| {
            let at = |i: usize| (rows[i + k][q] - rows[i - k][q]) / (rows[i + k][0] - rows[i - k][0]) - rows[i][v];
            (2..rows.len() - 2).map(|i| at(i).abs()).fold(0.0, f64::max)
        };
        let (fine, coarse) = (difference(1), difference(2));
        let fastest = rows.iter().map(|r| r[v].abs()).fold(0.0, f64::max);
        assert!(fine < 1e-4 * fastest && (3.5..4.5).contains(&(coarse / fine)), "{j}: {fine:e}, {coarse:e}, {fastest}");
    }
}

#[test]
fn bad_urdf_references_get_one_line_naming_the_file_and_element() {
    let arm = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/arm.urdf")).unwrap();
    let scenario_text = example("arm_tethered.toml");
    let cases: Vec<(&str, String, String, &[&str])> = vec![
        (
            "missing",
            arm.clone(),
            scenario_text.replace("urdf = \"arm.urdf\"", "urdf = \"nowhere.urdf\""),
            &["[model] urdf = \"nowhere.urdf\"", "cannot read"],
        ),
        (
            "malformed",
            "<robot name=\"x\"><link".into(),
            scenario_text.clone(),
            &["[model] urdf = \"arm.urdf\"", "not a valid URDF"],
        ),
        (
            "planar",
            arm.replace("type=\"continuous\"", "type=\"planar\""),
            scenario_text.clone(),
            &["joint \"wrist\": type planar is not supported"],
        ),
        (
            "link",
            arm.clone(),
            scenario_text.replace("a = \"hand\"", "a = \"palm\""),
            &["joints[0] (distance): a = \"palm\": no body of that name"],
        ),
        (
            "still",
            // Every joint welded: the links with a mass join the fixed base.
            arm.replace("type=\"revolute\"", "type=\"fixed\"").replace("type=\"continuous\"", "type=\"fixed\""),
            scenario_text.clone(),
            &["nothing moves: every link with a mass is the root or welded to it"],
        ),
        (
            "key",
            arm.clone(),
            scenario_text.replace("urdf = \"arm.urdf\"", "urdf = \"arm.urdf\"\nscale = 2.0"),
            &["[model] scale"],
        ),
    ];
    for (name, urdf, text, expected) in cases {
        let (dir, path) = scenario("bad.toml", &text);
        std::fs::write(dir.join("arm.urdf"), urdf).unwrap();
        let line = one_error_line(&cdyn(&["run", path_str(&path), "--out", path_str(&dir.join("out"))]));
        for e in expected {
            assert!(line.contains(e), "{name}: {line:?} should contain {e:?}");
        }
    }
}

/// A crank driven in angle about a revolute joint, a rod on a spherical
/// joint at its end pulled back by a damped spring, and a torque on the rod.
const DRIVEN: &str = r#"
[model]
kind = "spatial"
gravity = [0.0, 0.0, -9.81]

[integrator]
scheme = "rk4"
h = 1e-3
t_end = 1.0

[[bodies]]
name = "crank"
mass = 1.0
inertia = [0.01, 0.1, 0.1]
position = [0.25, 0.0, 0.0]

[[bodies]]
name = "rod"
mass = 0.5
inertia = [0.002, 0.04, 0.04]
position = [0.75, 0.0, 0.0]

[[joints]]
kind = "revolute"
a = "crank"
point = [0.0, 0.0, 0.0]
axis = [0.0, 1.0, 0.0]
angle = { polynomial = [0.0, 3.0] }

[[joints]]
kind = "spherical"
a = "crank"
b = "rod"
point = [0.5, 0.0, 0.0]

[[forces]]
kind = "spring"
a = "rod"
b = "ground"
point = [1.0, 0.0, 0.0]
point_b = [1.0, 0.0, 1.0]
stiffness = 20.0
damping = 0.5

[[forces]]
kind = "torque"
body = "rod"
torque = [0.0, 0.0, 0.1]
"#;

#[test]
fn driven_joints_springs_and_torques_run_from_a_scenario() {
    let out = run("driven", DRIVEN);
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let case = &summary["cases"][0];
    assert!(case["max_abs_phi"].as_f64().unwrap() < 1e-10, "{case}");
    // The assembly set the crank turning at the drive's 3 rad/s; the
    // crank's angle at 1 s is the drive's 3 rad: its x axis points (cos 3, 0, −sin 3).
    let (header, rows) = table(&out.join("driven.csv"));
    let last = rows.last().unwrap();
    let at = |k: &str| last[header.iter().position(|h| h == k).unwrap()];
    let (e0, e2) = (at("crank.e0"), at("crank.e2"));
    let angle = 2.0 * e2.atan2(e0);
    assert!((angle - 3.0).abs() < 1e-9, "crank angle {angle}");
    let cases: Vec<(String, &[&str])> = vec![
        (DRIVEN.replace("stiffness = 20.0", "stiffness = -20.0"), &["forces[0] (spring): stiffness = -20"]),
        (
            DRIVEN.replace("body = \"rod\"", "body = \"bar\""),
            &["forces[1] (torque): body = \"bar\": no body of that name"],
        ),
        (DRIVEN.replace("kind = \"torque\"", "kind = \"twist\""), &["forces[1]", "twist"]),
        (
            DRIVEN.replace("torque = [0.0, 0.0, 0.1]", "torque = [0.0, 0.0, 0.1]\npoint = [0.0, 0.0, 0.0]"),
            &["forces[1]", "point"],
        ),
        (
            DRIVEN.replace("point = [0.5, 0.0, 0.0]", "point = [0.5, 0.0, 0.0]\nangle = 1.0"),
            &["joints[1] (spherical): a spherical joint takes no angle"],
        ),
        (DRIVEN.to_string() + "\n[[drives]]\nkind = \"angle\"\n", &["no [[drives]]", "angle or displacement"]),
    ];
    for (text, expected) in cases {
        let (dir, path) = scenario("bad.toml", &text);
        let line = one_error_line(&cdyn(&["run", path_str(&path), "--out", path_str(&dir.join("out"))]));
        for e in expected {
            assert!(line.contains(e), "{line:?} should contain {e:?}");
        }
    }
}

/// arm.urdf started at given joint angles and rates, with a PD servo
/// (clamped at the URDF's effort), a torque ramp and a servo whose target
/// is an input.
const ACTUATED_ARM: &str = r#"
[model]
kind = "spatial"
urdf = "arm.urdf"
gravity = [0.0, 0.0, -9.81]

[integrator]
scheme = "rk4"
h = 1e-3
t_end = 0.1

[output]
every = 10

[initial]
joints = { shoulder_pitch = 0.4, wrist = -0.3 }
rates = { shoulder_yaw = 0.2 }

[[actuators]]
joint = "shoulder_pitch"
target = 0.9
kp = 200.0
kd = 5.0

[[actuators]]
joint = "wrist"
torque = { polynomial = [0.5, 1.0] }

[[actuators]]
joint = "shoulder_yaw"
kd = 2.0

[[inputs]]
name = "yaw_target"
drives = "actuators[2].target"
start = 0.0
"#;

/// A run's CSV header and rows, and summary.json's case.
#[test]
fn a_scenario_may_name_a_urdf_link_merged_into_another_links_body() {
    // arm.urdf's massless tool is part of the hand's body: the tethered
    // arm's rod on "tool" is the same run, to the bit, as on "hand".
    let tethered = example("arm_tethered.toml");
    let (on_hand, on_tool) =
        (run_arm(&tethered).unwrap(), run_arm(&tethered.replace("a = \"hand\"", "a = \"tool\"")).unwrap());
    assert!(tethered.contains("a = \"hand\""));
    assert_eq!((on_hand.0, on_hand.1), (on_tool.0, on_tool.1));
}

type ArmRun = (Vec<String>, Vec<Vec<f64>>, serde_json::Value);

/// Runs `text` beside arm.urdf, or gives the error line.
fn run_arm(text: &str) -> Result<ArmRun, String> {
    let (dir, path) = scenario("arm.toml", text);
    std::fs::write(dir.join("arm.urdf"), example("arm.urdf")).unwrap();
    let out = dir.join("out");
    let result = cdyn(&["run", path_str(&path), "--out", path_str(&out)]);
    if !result.status.success() {
        return Err(one_error_line(&result));
    }
    let (header, rows) = table(&out.join("arm.csv"));
    Ok((header, rows, summary_case(&out)))
}

#[test]
fn an_arm_starts_at_its_initial_joint_angles_and_writes_each_actuators_torque() {
    let (header, rows, summary) = run_arm(ACTUATED_ARM).unwrap();
    let col = |name: &str| header.iter().position(|h| h == name).unwrap_or_else(|| panic!("{name} in {header:?}"));
    let first = &rows[0];
    // The t = 0 row reads the given joint values back (the assembly's
    // projection of an exact pose moves it by round-off only).
    for (name, value) in [
        ("shoulder_pitch.q", 0.4),
        ("wrist.q", -0.3),
        ("shoulder_yaw.q", 0.0),
        ("shoulder_yaw.v", 0.2),
        ("shoulder_pitch.v", 0.0),
        ("wrist.v", 0.0),
    ] {
        assert!((first[col(name)] - value).abs() < 1e-12, "{name} = {} at t = 0", first[col(name)]);
    }
    // After the joint columns, one torque column per actuator: the servo
    // asks 200 · 0.5 = 100 N m and gets the URDF's effort, 30; the wrist's
    // ramp 0.5 + t; the yaw servo to the input's 0 is a damper, 2 · (0 − 0.2).
    assert_eq!(header[28..31], ["shoulder_pitch.tau", "wrist.tau", "shoulder_yaw.tau"]);
    assert_eq!(first[col("shoulder_pitch.tau")], 30.0);
    assert_eq!(first[col("wrist.tau")], 0.5);
    assert!((first[col("shoulder_yaw.tau")] + 0.4).abs() < 1e-12, "{}", first[col("shoulder_yaw.tau")]);
    let last = rows.last().unwrap();
    assert!((last[0] - 0.1).abs() < 1e-12 && (last[col("wrist.tau")] - 0.6).abs() < 1e-12, "{last:?}");
    // The clamped servo drives the pitch up towards its target.
    assert!(last[col("shoulder_pitch.q")] > 0.45, "{}", last[col("shoulder_pitch.q")]);
    // summary.json's joint space: each joint column's range and last value
    // as the CSV holds them, and each actuator against its effort.
    let joint_space = &summary["joint_space"];
    let columns = joint_space["joints"].as_array().unwrap();
    let joint_columns = header.iter().filter(|h| [".q", ".v", ".tau"].iter().any(|s| h.ends_with(s))).count();
    assert_eq!(columns.len(), joint_columns, "{joint_space}");
    for c in columns {
        let name = c["column"].as_str().unwrap();
        let values: Vec<f64> = rows.iter().map(|r| r[col(name)]).collect();
        let (min, max) = values.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| (a.min(x), b.max(x)));
        assert_eq!(
            [c["min"].as_f64(), c["max"].as_f64(), c["final"].as_f64()],
            [Some(min), Some(max), values.last().copied()],
            "{name}"
        );
    }
    let actuators = joint_space["actuators"].as_array().unwrap();
    let pitch = &actuators[0];
    assert_eq!(
        (pitch["column"].as_str(), pitch["max_abs"].as_f64(), pitch["effort"].as_f64()),
        (Some("shoulder_pitch.tau"), Some(30.0), Some(30.0))
    );
    let samples = pitch["samples"].as_u64().unwrap();
    assert_eq!(samples, rows.len() as u64);
    let at_bound = rows.iter().filter(|r| r[col("shoulder_pitch.tau")].abs() == 30.0).count() as u64;
    assert!(at_bound >= 1 && pitch["saturated_samples"].as_u64() == Some(at_bound), "{pitch} against {at_bound}");
    // The wrist has no <limit> in arm.urdf, so no effort bound to reach.
    assert!(actuators[1]["effort"].is_null(), "{}", actuators[1]);
    assert_eq!(actuators[1]["saturated_samples"].as_u64(), Some(0), "{}", actuators[1]);
    assert!((actuators[1]["max_abs"].as_f64().unwrap() - 0.6).abs() < 1e-12, "{}", actuators[1]);
}

#[test]
fn bad_actuators_and_initial_joints_get_one_line_naming_the_entry() {
    let cases: [(String, &[&str]); 9] = [
        (ACTUATED_ARM.replace("kd = 5.0", "kd = 5.0\ngain = 1.0"), &["arm.toml", "actuators[0]", "gain"]),
        (
            ACTUATED_ARM.replace("joint = \"wrist\"", "joint = \"elbow\""),
            &["arm.toml: actuators[1]: joint = \"elbow\": no joint of that name; the joints are shoulder_yaw"],
        ),
        (
            ACTUATED_ARM.replace("target = 0.9", "target = 0.9\ntorque = 1.0"),
            &["arm.toml: actuators[0]: torque and target: give one"],
        ),
        (
            ACTUATED_ARM.replace("kp = 200.0", "kp = -200.0"),
            &["arm.toml: actuators[0]: kp = -200 must be finite and not negative"],
        ),
        (
            ACTUATED_ARM.replace("joint = \"wrist\"", "joint = \"shoulder_pitch\""),
            &["arm.toml: actuators[1]: joint = \"shoulder_pitch\": actuators[0] drives it already"],
        ),
        (
            ACTUATED_ARM.replace("kd = 2.0\n", "kd = 2.0\ntarget = 0.1\n"),
            &["arm.toml: actuators[2]: target is driven by the input \"yaw_target\" (inputs[0]): leave the key out"],
        ),
        (
            ACTUATED_ARM.replace("actuators[2].target", "actuators[5].target"),
            &["inputs[0] (yaw_target): drives = \"actuators[5].target\": the scenario has 3 [[actuators]] entries"],
        ),
        (
            ACTUATED_ARM.replace("wrist = -0.3", "elbow = -0.3"),
            &[
                "arm.toml: [initial] joints: no revolute or prismatic joint \"elbow\"; the joints are shoulder_yaw, shoulder_pitch, wrist",
            ],
        ),
        (
            ACTUATED_ARM.replace("[initial]\n", "[initial]\nq = [0.0]\n"),
            &["arm.toml: [initial] joints and q exclude each other"],
        ),
    ];
    for (text, expected) in cases {
        let line = run_arm(&text).unwrap_err();
        for e in expected {
            assert!(line.contains(e), "expected {e:?} in: {line}");
        }
    }
}

#[test]
fn a_robot_in_joint_coordinates_writes_the_same_columns_and_motion_as_in_body_coordinates() {
    // arm_pd.toml (three servos, one clamped at its effort) for 0.5 s, in
    // both coordinates: the same columns, the bodies' poses and the joints
    // to the integrators' error; an unknown choice is one line.
    let text = example("arm_pd.toml").replace("t_end = 2.0", "t_end = 0.5");
    let runs: Vec<(Vec<String>, Vec<Vec<f64>>)> = ["bodies", "joints"]
        .iter()
        .map(|c| {
            let text = text.replace("urdf = \"arm.urdf\"", &format!("urdf = \"arm.urdf\"\ncoordinates = \"{c}\""));
            let (dir, path) = scenario("arm_pd.toml", &text);
            std::fs::write(dir.join("arm.urdf"), example("arm.urdf")).unwrap();
            let out = dir.join("out");
            let result = cdyn(&["run", path_str(&path), "--out", path_str(&out)]);
            assert!(result.status.success(), "{c}: {}", String::from_utf8_lossy(&result.stderr));
            assert!(out.join("mechanism.svg").metadata().is_ok_and(|m| m.len() > 1000), "{c}: the 3-D view");
            table(&out.join("arm_pd.csv"))
        })
        .collect();
    let [(bodies_header, bodies), (joints_header, joints)] = &runs[..] else { unreachable!() };
    assert_eq!(bodies_header, joints_header);
    assert_eq!(bodies.len(), joints.len());
    let mut worst: f64 = 0.0;
    for (b, j) in bodies.iter().zip(joints) {
        for (k, name) in bodies_header.iter().enumerate().filter(|(_, h)| !matches!(h.as_str(), "phi" | "psi")) {
            // Euler parameters are the same rotation up to sign.
            let sign = if name.contains(".e") && b[k] * j[k] < 0.0 && (b[k] + j[k]).abs() < 1e-6 { -1.0 } else { 1.0 };
            worst = worst.max((b[k] - sign * j[k]).abs());
        }
    }
    assert!(worst < 1e-6, "the two runs differ by {worst:e}");
    let turned = joints.iter().map(|r| r[bodies_header.iter().position(|h| h == "shoulder_yaw.q").unwrap()].abs());
    assert!(turned.fold(0.0, f64::max) > 0.2, "the yaw servo swings the arm");
    let (dir, path) =
        scenario("bad.toml", &text.replace("urdf = \"arm.urdf\"", "urdf = \"arm.urdf\"\ncoordinates = \"angles\""));
    std::fs::write(dir.join("arm.urdf"), example("arm.urdf")).unwrap();
    let line = one_error_line(&cdyn(&["run", path_str(&path), "--out", path_str(&dir.join("out"))]));
    assert!(line.contains("[model] coordinates = \"angles\"") && line.contains("\"joints\""), "{line}");
}

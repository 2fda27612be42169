//! `--html` and `--gif`: the page's inline data (drawing, frames, sampling,
//! cases), that it needs nothing from the network, and the GIF's frames.
//! The page in a real browser is tested by `.ci/browser-test.sh`.

use crate::common::{cdyn, one_error_line, path_str, scenario};
use image::AnimationDecoder;
use serde_json::Value;
use std::path::{Path, PathBuf};

fn examples() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples")
}

/// The page's text and its inline data.
fn page(dir: &Path) -> (String, Value) {
    let text = std::fs::read_to_string(dir.join("report.html")).unwrap();
    let open = r#"<script id="data" type="application/json">"#;
    let start = text.find(open).unwrap() + open.len();
    let end = start + text[start..].find("</script>").unwrap();
    (text.clone(), serde_json::from_str(&text[start..end]).unwrap())
}

/// Runs `cdyn command scenario --out out extra…`, which must succeed, and
/// returns the page it wrote.
fn viewed(command: &str, scenario: &Path, out: &Path, extra: &[&str]) -> (String, Value) {
    let r = cdyn(&[&[command, path_str(scenario), "--out", path_str(out)], extra].concat());
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    page(out)
}

#[test]
fn run_html_and_gif_of_a_mechanism() {
    let out = tempfile::tempdir().unwrap();
    let four_bar = examples().join("four_bar.toml");
    let (text, data) = viewed("run", &four_bar, out.path(), &["--html", "--gif"]);
    // Self-contained: a policy that forbids fetching anything, and no address to fetch.
    assert!(text.contains("default-src 'none'"));
    assert!(!text.contains("http:") && !text.contains("https:") && !text.contains("src="), "the page names an address");
    let bodies: Vec<&str> =
        data["drawing"]["bodies"].as_array().unwrap().iter().map(|b| b["name"].as_str().unwrap()).collect();
    assert_eq!(bodies, ["crank", "coupler", "rocker"]);
    let case = &data["cases"][0];
    // t_end = 6, h = 2e-3, every = 5: 601 samples, all kept.
    let (t, q) = (case["frames"]["t"].as_array().unwrap(), case["frames"]["q"].as_array().unwrap());
    assert_eq!((t.len(), q.len(), case["frames"]["stride"].as_u64()), (601, 601, Some(1)));
    assert_eq!((t[0].as_f64(), t[600].as_f64()), (Some(0.0), Some(6.0)));
    assert!(q.iter().all(|row| row.as_array().unwrap().len() == 9));
    // The last frame is the end state of summary.json.
    let summary: Value =
        serde_json::from_str(&std::fs::read_to_string(out.path().join("summary.json")).unwrap()).unwrap();
    assert_eq!(q[600], summary["cases"][0]["q_end"]);
    assert_eq!(case["summary"]["max_abs_phi"], summary["cases"][0]["max_abs_phi"]);
    assert_eq!(data["info"]["scenario"], summary["scenario"]);

    let file = std::fs::File::open(out.path().join("animation.gif")).unwrap();
    let frames = image::codecs::gif::GifDecoder::new(file).unwrap().into_frames().collect_frames().unwrap();
    assert!(frames.len() > 100 && frames.len() <= 200, "{} frames", frames.len());
    assert_eq!(frames[0].buffer().dimensions(), (480, 360));
    let (first, middle) = (frames[0].buffer(), frames[frames.len() / 2].buffer());
    let changed = first.pixels().zip(middle.pixels()).filter(|(a, b)| a != b).count();
    assert!(changed > 1000, "the mechanism did not move: {changed} pixels differ");

    // A run without the options into the same directory leaves no page or GIF of the earlier one.
    let r = cdyn(&["run", path_str(&four_bar), "--out", path_str(out.path())]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    assert!(!out.path().join("report.html").exists() && !out.path().join("animation.gif").exists());
}

#[test]
fn long_runs_are_decimated_and_say_so() {
    let text = std::fs::read_to_string(examples().join("four_bar.toml")).unwrap();
    assert!(text.contains("every = 5"));
    let (dir, path) = scenario("four_bar_every_step.toml", &text.replace("every = 5", "every = 1"));
    let out = dir.join("out");
    let (_, data) = viewed("run", &path, &out, &["--html"]);
    let frames = &data["cases"][0]["frames"];
    let (n, stride) = (frames["t"].as_array().unwrap().len(), frames["stride"].as_u64().unwrap());
    // 3001 samples: every other one, plus the end state.
    assert_eq!((frames["samples"].as_u64(), stride), (Some(3001), 2));
    assert_eq!(n, 1501);
    assert_eq!(frames["t"][1].as_f64(), Some(4e-3));
    assert_eq!(frames["t"][n - 1].as_f64(), Some(6.0));
}

#[test]
fn compare_html_has_every_case_and_draws_a_built_in() {
    let out = tempfile::tempdir().unwrap();
    let dp = examples().join("double_pendulum.toml");
    let (_, data) = viewed("compare", &dp, out.path(), &["--html"]);
    let summary: Value =
        serde_json::from_str(&std::fs::read_to_string(out.path().join("summary.json")).unwrap()).unwrap();
    let names = |cases: &Value| -> Vec<String> {
        cases.as_array().unwrap().iter().map(|c| c["name"].as_str().unwrap().to_string()).collect()
    };
    assert_eq!(names(&data["cases"]), names(&summary["cases"]));
    assert!(data["cases"].as_array().unwrap().len() > 3);
    assert_eq!(data["info"]["methods"], summary["methods"]);
    // The built-in is a mechanism: two bobs on two rods, the first from the ground.
    assert_eq!(names(&data["drawing"]["bodies"]), ["bob1", "bob2"]);
    let links = data["drawing"]["links"].as_array().unwrap();
    assert_eq!(links.iter().map(|l| l["kind"].as_str().unwrap()).collect::<Vec<_>>(), ["distance", "distance"]);
    assert!(links[0]["ends"][0]["body"].is_null() && links[1]["ends"][0]["body"] == 0);
    let frames = &data["cases"][0]["frames"];
    assert_eq!(frames["t"].as_array().unwrap().len(), 501, "5 s sampled every 10 steps of 1e-3");
    assert!(!data["cases"][0]["series"]["phi"].as_array().unwrap().is_empty());
}

#[test]
fn the_cartesian_pendulum_is_drawn_as_a_bob_on_a_rod() {
    let out = tempfile::tempdir().unwrap();
    let pendulum = examples().join("cvsgf_energy.toml");
    let (_, data) = viewed("run", &pendulum, out.path(), &["--html", "--gif"]);
    let drawing = &data["drawing"];
    assert_eq!(drawing["bodies"][0]["name"], "bob");
    assert_eq!((drawing["bodies"][0]["x"].as_u64(), drawing["bodies"].as_array().unwrap().len()), (Some(0), 1));
    assert_eq!(drawing["links"][0]["kind"], "distance");
    assert!(drawing["links"][0]["ends"][0]["body"].is_null() && drawing["links"][0]["ends"][1]["body"] == 0);
    // The rod's length is the distance of the bob's coordinates from the pivot in every frame.
    let q = data["cases"][0]["frames"]["q"].as_array().unwrap();
    assert!(q.len() > 100);
    for frame in q {
        let (x, y) = (frame[0].as_f64().unwrap(), frame[1].as_f64().unwrap());
        assert!(((x * x + y * y).sqrt() - 1.0).abs() < 1e-3, "{x} {y}");
    }
    assert!(out.path().join("animation.gif").exists());
}

#[test]
fn a_model_in_angles_plots_only_and_refuses_a_gif() {
    let out = tempfile::tempdir().unwrap();
    let angles = examples().join("double_pendulum_angles.toml");
    let (text, data) = viewed("run", &angles, out.path(), &["--html"]);
    assert!(data["drawing"].is_null() && text.contains("has no drawing"));
    assert!(data["cases"][0]["frames"]["t"].as_array().unwrap().is_empty());
    assert!(!data["cases"][0]["series"]["phi"].as_array().unwrap().is_empty());

    // No GIF without a drawing: refused before anything runs.
    let out = tempfile::tempdir().unwrap();
    let e = one_error_line(&cdyn(&["run", path_str(&angles), "--out", path_str(out.path()), "--gif"]));
    assert!(e.contains("--gif: this model has no drawing"), "{e}");
    assert!(!out.path().join("summary.json").exists());
}

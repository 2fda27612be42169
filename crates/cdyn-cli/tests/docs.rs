//! The README and the book stay true: every scenario they show runs, the
//! README's commands do what it says, `cdyn paper` prints the README's
//! table to the last digit, and every link between the pages resolves.

use crate::common::{cdyn, path_str, scenario};
use std::path::{Path, PathBuf};

/// The repository's root.
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// README.md and every page of the book, with their paths from the root.
fn pages() -> Vec<(String, String)> {
    let mut pages = vec![("README.md".to_string(), std::fs::read_to_string(root().join("README.md")).unwrap())];
    let mut book: Vec<_> = std::fs::read_dir(root().join("docs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    book.sort();
    for p in book {
        let name = format!("docs/{}", p.file_name().unwrap().to_string_lossy());
        pages.push((name, std::fs::read_to_string(&p).unwrap()));
    }
    pages
}

/// The fenced blocks of `lang` in `text`, in order.
fn blocks<'a>(text: &'a str, lang: &str) -> Vec<&'a str> {
    let open = format!("```{lang}\n");
    let mut out = Vec::new();
    let mut rest = text;
    while let Some(start) = rest.find(&open) {
        let body = &rest[start + open.len()..];
        let end = body.find("```").expect("a closed block");
        out.push(&body[..end]);
        rest = &body[end + 3..];
    }
    out
}

/// `block` with its commented-out keys and tables (`# zeta = 20.0`,
/// `# [[invariants]]`) written in, or `None` when it has none: the book's
/// alternatives, which must be real keys of the tables they sit in.
fn uncommented(block: &str) -> Option<String> {
    let mut changed = false;
    let lines: Vec<String> = block
        .lines()
        .map(|line| {
            let Some(rest) = line.strip_prefix("# ") else { return line.to_string() };
            let key: String = rest.chars().take_while(|c| c.is_ascii_lowercase() || *c == '_').collect();
            let table = rest.split(" #").next().unwrap_or_default().trim_end();
            let header = table.trim_start_matches('[').trim_end_matches(']');
            let is_header = table.starts_with('[')
                && table.ends_with(']')
                && header.chars().all(|c| c.is_ascii_lowercase() || c == '_' || c == '.');
            if is_header || (!key.is_empty() && rest[key.len()..].starts_with(" = ")) {
                changed = true;
                rest.to_string()
            } else {
                line.to_string()
            }
        })
        .collect();
    changed.then(|| lines.join("\n"))
}

#[test]
fn every_scenario_in_the_readme_and_the_book_runs() {
    let mut count = 0;
    let mut alternatives = 0;
    for (page, text) in pages() {
        for (i, block) in blocks(&text, "toml").into_iter().enumerate() {
            if let Some(all) = uncommented(block) {
                // Read, not run: the alternatives exclude each other.
                let read = cdyn_cli::case::scenario::parse(&all, "<book>");
                assert!(read.is_ok(), "{page}, TOML block {} with its commented keys: {:?}", i + 1, read.err());
                alternatives += 1;
            }
            // A snippet that shows only the model's keys runs for ten steps.
            let mut text = block.to_string();
            if !text.contains("[integrator]") {
                text.push_str("\n[integrator]\nscheme = \"rk4\"\nh = 0.01\nt_end = 0.1\n");
            }
            let (dir, file) = scenario("snippet.toml", &text);
            let out = cdyn(&["run", path_str(&file), "--out", path_str(&dir.join("out"))]);
            let stderr = String::from_utf8_lossy(&out.stderr);
            assert!(out.status.success(), "{page}, TOML block {}: {stderr}", i + 1);
            count += 1;
        }
    }
    assert!(count >= 4, "only {count} scenario blocks found");
    assert!(alternatives >= 1, "no block with commented keys found");
}

/// The names a serde type expected where it refused `zzz_not_a_key`
/// (`unknown field …, expected one of \`a\`, \`b\``): its keys, or
/// its variants for an unknown variant.
fn expected(error: impl std::fmt::Display) -> Vec<String> {
    let error = error.to_string();
    if error.contains("there are no fields") {
        return Vec::new();
    }
    let list = error.split("expected").nth(1).unwrap_or_else(|| panic!("not a list of expected names: {error}"));
    let names: Vec<String> = list.split('`').skip(1).step_by(2).map(str::to_string).collect();
    assert!(!names.is_empty(), "no names in: {error}");
    names
}

/// The keys (and names of kinds) `T` accepts from `text`, which holds an
/// unknown key or value that `T` refuses with the list it expected.
fn probe<T: serde::de::DeserializeOwned + std::fmt::Debug>(text: &str) -> Vec<String> {
    expected(toml::from_str::<T>(text).expect_err(text))
}

/// The identifiers a page shows as code: in inline code and in TOML
/// blocks, comments included.
fn code_words(text: &str) -> std::collections::BTreeSet<String> {
    let mut code = blocks(text, "toml").concat();
    let prose: String = text.split("```").step_by(2).collect::<Vec<_>>().concat();
    code.extend(prose.split('`').skip(1).step_by(2).flat_map(|span| [span, " "]));
    code.split(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
        .filter(|w| !w.is_empty())
        .map(str::to_string)
        .collect()
}

#[test]
fn every_key_the_scenario_accepts_is_in_the_reference() {
    use cdyn::models::Kind;
    use cdyn_cli::case::scenario::{InitialSpec, IntegratorSpec, InvariantSpec, OutputSpec, Scenario};
    const UNKNOWN: &str = "zzz_not_a_key = 0";
    let tagged = |kind: &str| format!("kind = \"{kind}\"\n{UNKNOWN}");
    let value = |key: &str| format!("{key} = \"zzz_not_a_value\"");
    #[derive(Debug, serde::Deserialize)]
    struct Value<T> {
        #[allow(dead_code)]
        v: T,
    }

    // (what, the names it accepts), read from the types themselves.
    let mut planar: Vec<(String, Vec<String>)> = vec![
        ("the scenario's tables".into(), probe::<Scenario>(UNKNOWN)),
        // `[model]` takes every other key (the pendulum's parameters), so it
        // cannot be probed: its own keys are these.
        ("[model]".into(), ["kind", "gravity", "parameters"].map(String::from).to_vec()),
        ("[initial]".into(), probe::<InitialSpec>(UNKNOWN)),
        ("[integrator]".into(), probe::<IntegratorSpec>(UNKNOWN)),
        ("[output]".into(), probe::<OutputSpec>(UNKNOWN)),
        ("[method]".into(), probe::<cdyn::control::methods::MethodKeys>(UNKNOWN)),
        ("model kinds".into(), probe::<Value<Kind>>("v = \"zzz\"")),
        ("schemes".into(), cdyn::Scheme::ALL.iter().map(|s| s.info().name.to_string()).collect()),
        ("a function of time".into(), probe::<Value<cdyn::model::timefn::TimeFn>>(&format!("v = {{ {UNKNOWN} }}"))),
        ("[[bodies]]".into(), probe::<cdyn::planar::Body>(UNKNOWN)),
        ("element kinds".into(), probe::<cdyn::planar::Element<String>>(&tagged("zzz"))),
        ("[[invariants]] kinds".into(), probe::<InvariantSpec>(&tagged("zzz"))),
    ];
    for kind in planar.iter().find(|(what, _)| what == "element kinds").unwrap().1.clone() {
        planar.push((format!("{kind} elements"), probe::<cdyn::planar::Element<String>>(&tagged(&kind))));
    }
    for kind in planar.iter().find(|(what, _)| what == "[[invariants]] kinds").unwrap().1.clone() {
        planar.push((format!("{kind} invariants"), probe::<InvariantSpec>(&tagged(&kind))));
    }
    for (what, key) in [
        ("geometric", "geometric"),
        ("velocity", "velocity"),
        ("energy", "energy"),
        ("preset", "preset"),
        ("apply", "apply"),
        ("on_failure", "on_failure"),
        ("invariants", "invariants"),
    ] {
        let names = probe::<cdyn::control::methods::MethodKeys>(&value(key));
        planar.push((format!("{what} values"), names));
    }
    planar.push((
        "dependent_rows values".into(),
        probe::<IntegratorSpec>(&format!("h = 0.1\nt_end = 1.0\n{}", value("dependent_rows"))),
    ));
    for kind in Kind::ALL.into_iter().filter(|k| !k.is_described()) {
        let table: toml::Table = toml::from_str(UNKNOWN).unwrap();
        if let Err(e) = kind.example(toml::Value::Table(table)) {
            planar.push((format!("{kind:?}'s parameters"), expected(e)));
        }
    }
    for kind in [Kind::SliderCrank, Kind::FourBar] {
        let table: toml::Table = toml::from_str(&format!("load = {{ {UNKNOWN} }}")).unwrap();
        let error = kind.example(toml::Value::Table(table)).err().expect("a load with an unknown key");
        planar.push((format!("{kind:?}'s load"), expected(error)));
    }
    let table: toml::Table = toml::from_str(&value("branch")).unwrap();
    planar
        .push(("four-bar branches".into(), expected(Kind::FourBar.example(toml::Value::Table(table)).err().unwrap())));
    planar.push((
        "drive coordinates".into(),
        probe::<cdyn::planar::Element<String>>(
            "kind = \"coordinate\"\nbody = \"b\"\nfunction = 1.0\ncoordinate = \"zzz\"",
        ),
    ));

    let mut spatial: Vec<(String, Vec<String>)> = vec![
        ("[model] of a spatial mechanism".into(), vec!["urdf".to_string()]),
        ("spatial [[bodies]]".into(), probe::<cdyn::spatial::Body>(UNKNOWN)),
        ("spatial [[joints]]".into(), probe::<cdyn::spatial::Joint<String>>(UNKNOWN)),
        ("spatial [[actuators]]".into(), probe::<cdyn::spatial::Actuator<String>>(UNKNOWN)),
        ("spatial joint kinds".into(), probe::<Value<cdyn::spatial::JointKind>>("v = \"zzz\"")),
        ("spatial load kinds".into(), probe::<cdyn::spatial::Load<String>>(&tagged("zzz"))),
    ];
    for kind in spatial[4].1.clone() {
        spatial.push((format!("spatial {kind} loads"), probe::<cdyn::spatial::Load<String>>(&tagged(&kind))));
    }

    let (mut checked, mut missing) = (0, Vec::new());
    for (page, groups) in [("docs/scenarios.md", planar), ("docs/spatial.md", spatial)] {
        let words = code_words(&std::fs::read_to_string(root().join(page)).unwrap());
        for (what, names) in groups {
            let absent: Vec<_> = names.iter().filter(|n| !words.contains(*n)).collect();
            if !absent.is_empty() {
                missing.push(format!("{page} does not show {what}: {absent:?}"));
            }
            checked += names.len();
        }
    }
    assert!(missing.is_empty(), "{}", missing.join("\n"));
    assert!(checked > 200, "only {checked} names checked");
}

#[test]
fn the_readme_first_scenario_runs_as_its_command_says() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let section = &readme[readme.find("## A first scenario").unwrap()..];
    let toml = blocks(section, "toml")[0];
    let command = blocks(section, "sh")[0].trim();
    let args: Vec<&str> = command.split_whitespace().collect();
    assert_eq!(args[..2], ["cdyn", "run"], "{command}");
    let (dir, _) = scenario(args[2], toml);
    let out =
        std::process::Command::new(env!("CARGO_BIN_EXE_cdyn")).args(&args[1..]).current_dir(&dir).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let out_dir = dir.join(args[args.iter().position(|&a| a == "--out").unwrap() + 1]);
    let stem = Path::new(args[2]).file_stem().unwrap().to_string_lossy();
    for file in [format!("{stem}.csv"), "summary.json".into(), "report.html".into(), "phi.png".into(), "psi.png".into()]
    {
        assert!(out_dir.join(&file).is_file(), "{file} not written");
    }
    // What the README says it printed.
    let printed = String::from_utf8_lossy(&out.stdout);
    let row = printed.lines().find(|l| l.starts_with(&*stem)).unwrap();
    let values: Vec<f64> = row.split_whitespace().skip(1).take(2).map(|x| x.parse().unwrap()).collect();
    assert!(values[0] < 1e-15 && values[1] < 1e-13, "{row}");
}

#[test]
fn a_scenario_without_scheme_runs_the_default_the_book_names() {
    // The book names the default in the scenario reference and in the
    // work-precision page's advice; a scenario without the key runs it.
    let reference = std::fs::read_to_string(root().join("docs/scenarios.md")).unwrap();
    let named = reference
        .split("; default ")
        .nth(1)
        .and_then(|r| r.split_whitespace().next())
        .expect("docs/scenarios.md names a default scheme");
    let precision = std::fs::read_to_string(root().join("docs/precision.md")).unwrap();
    let precision = precision.split_whitespace().collect::<Vec<_>>().join(" ");
    assert!(
        precision.contains(&format!("`{named}` with `robust` (the default scheme of a scenario that names none)")),
        "docs/precision.md's advice names another default than {named}"
    );
    let body = "[model]\nkind = \"pendulum\"\n[integrator]\nSCHEMEh = 0.01\nt_end = 0.5\n";
    let run = |scheme: &str| {
        let (dir, file) = scenario("default.toml", &body.replace("SCHEME", scheme));
        let out = dir.join("out");
        let result = cdyn(&["run", path_str(&file), "--out", path_str(&out)]);
        assert!(result.status.success(), "{}", String::from_utf8_lossy(&result.stderr));
        let summary: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
        (summary["cases"][0]["scheme"].as_str().unwrap().to_string(), std::fs::read(out.join("default.csv")).unwrap())
    };
    let (default, rows) = run("");
    assert_eq!(default, named);
    let (explicit, explicit_rows) = run(&format!("scheme = \"{named}\"\n"));
    assert_eq!((explicit, &explicit_rows), (default, &rows), "the same run, to the bit");
    let (other, other_rows) = run("scheme = \"ab3\"\n");
    assert!(other == "ab3" && other_rows != rows);
}

#[test]
fn cdyn_paper_prints_the_readme_table_to_the_last_digit() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let table = blocks(&readme, "text")[0];
    let dir = tempfile::tempdir().unwrap();
    let out = cdyn(&["paper", "--out", path_str(dir.path())]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let printed = String::from_utf8_lossy(&out.stdout);
    for line in table.lines() {
        assert!(printed.lines().any(|p| p == line), "not printed by cdyn paper: {line}\n{printed}");
    }
}

/// GitHub's anchor of a heading: lower case, punctuation dropped, spaces as `-`.
fn anchor(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || *c == ' ' || *c == '-' || *c == '_')
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

/// The anchors of the headings of a Markdown page (outside code blocks).
fn anchors(text: &str) -> Vec<String> {
    let mut fenced = false;
    let mut out = Vec::new();
    for line in text.lines() {
        if line.starts_with("```") {
            fenced = !fenced;
        } else if !fenced && line.starts_with('#') {
            out.push(anchor(line.trim_start_matches('#')));
        }
    }
    out
}

#[test]
fn every_link_between_the_pages_resolves() {
    let mut checked = 0;
    for (page, text) in pages() {
        let base = root().join(&page).parent().unwrap().to_path_buf();
        let mut rest = text.as_str();
        while let Some(at) = rest.find("](") {
            let tail = &rest[at + 2..];
            let end = tail.find(')').unwrap();
            let target = &tail[..end];
            rest = &tail[end..];
            if target.starts_with("http") || target.contains(' ') {
                continue;
            }
            let (file, fragment) = target.split_once('#').unwrap_or((target, ""));
            let path = if file.is_empty() { root().join(&page) } else { base.join(file) };
            assert!(path.exists(), "{page}: link to {target}: no such file");
            if !fragment.is_empty() {
                let linked = std::fs::read_to_string(&path).unwrap();
                assert!(anchors(&linked).iter().any(|a| a == fragment), "{page}: link to {target}: no such heading");
            }
            checked += 1;
        }
    }
    assert!(checked >= 20, "only {checked} links found");
}

#[test]
fn the_book_lists_every_page_and_the_readme_stays_short() {
    let summary = std::fs::read_to_string(root().join("docs/SUMMARY.md")).unwrap();
    for (page, _) in pages().iter().filter(|(p, _)| p.starts_with("docs/") && *p != "docs/SUMMARY.md") {
        let name = page.trim_start_matches("docs/");
        assert!(summary.contains(&format!("]({name})")), "docs/SUMMARY.md does not list {name}");
    }
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    assert!(readme.lines().count() <= 250, "README.md has {} lines", readme.lines().count());
}

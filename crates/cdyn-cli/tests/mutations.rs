//! Property tests: random mutations of the shipped examples (renamed, added
//! and deleted keys, changed values and types, truncated files) fed to
//! `cdyn run`, the path every scenario takes. Each must end in a clean
//! one-line error or a successful run: never a panic, a crash or a hang, and
//! never exit 0 when a key was misspelt (an ignored key is silently wrong
//! physics).
//!
//! Every example's `t_end` is first cut to 20 steps (and `every` to 1), so a
//! case takes milliseconds.

use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

/// The shipped examples, shortened, as parsed tables.
fn examples() -> Vec<(String, toml::Table)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let mut files: Vec<PathBuf> = Vec::new();
    for dir in [root.clone(), root.join("suite")] {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "toml") {
                files.push(path);
            }
        }
    }
    files.sort();
    files
        .into_iter()
        .filter_map(|path| {
            let mut table: toml::Table = toml::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
            // `cdyn run` refuses a [sweep] table: nothing else of such a file would be tested.
            if table.contains_key("sweep") {
                return None;
            }
            let integrator = table.get_mut("integrator").unwrap().as_table_mut().unwrap();
            let h = integrator["h"].as_float().unwrap();
            integrator.insert("t_end".into(), toml::Value::Float(20.0 * h));
            if let Some(output) = table.get_mut("output").and_then(|o| o.as_table_mut()) {
                output.insert("every".into(), toml::Value::Integer(1));
            }
            Some((path.file_name().unwrap().to_string_lossy().into_owned(), table))
        })
        .collect()
}

/// One step of a path into a table.
#[derive(Debug, Clone)]
enum Step {
    Key(String),
    Index(usize),
}

/// Every value's path in `value`, depth first.
fn paths(value: &toml::Value, at: &mut Vec<Step>, out: &mut Vec<Vec<Step>>) {
    match value {
        toml::Value::Table(t) => {
            for (k, v) in t {
                at.push(Step::Key(k.clone()));
                out.push(at.clone());
                paths(v, at, out);
                at.pop();
            }
        }
        toml::Value::Array(items) => {
            for (i, v) in items.iter().enumerate() {
                at.push(Step::Index(i));
                out.push(at.clone());
                paths(v, at, out);
                at.pop();
            }
        }
        _ => {}
    }
}

/// The container holding the last step of `path`.
fn parent<'a>(root: &'a mut toml::Value, path: &[Step]) -> &'a mut toml::Value {
    path[..path.len() - 1].iter().fold(root, |v, step| match step {
        Step::Key(k) => v.get_mut(k.as_str()).unwrap(),
        Step::Index(i) => v.get_mut(*i).unwrap(),
    })
}

/// Paths ending in a table key (not an array element).
fn key_paths(table: &toml::Table) -> Vec<Vec<Step>> {
    let mut out = Vec::new();
    paths(&toml::Value::Table(table.clone()), &mut Vec::new(), &mut out);
    out.retain(|p| matches!(p.last(), Some(Step::Key(_))));
    out
}

/// All paths (keys and array elements).
fn all_paths(table: &toml::Table) -> Vec<Vec<Step>> {
    let mut out = Vec::new();
    paths(&toml::Value::Table(table.clone()), &mut Vec::new(), &mut out);
    out
}

/// What `cdyn run` made of a scenario.
struct Ran {
    out: Output,
    text: String,
}

/// Runs `cdyn run` on `text`; a run over 60 s is a hang and fails the test.
fn run(text: &str) -> Ran {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("mutated.toml");
    std::fs::write(&file, text).unwrap();
    // The robots the examples name (`urdf = "arm.urdf"`), next to the scenario as there.
    let examples = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    for entry in std::fs::read_dir(&examples).unwrap().flatten() {
        if entry.path().extension().is_some_and(|e| e == "urdf") {
            std::fs::copy(entry.path(), dir.path().join(entry.file_name())).unwrap();
        }
    }
    let mut child = Command::new(env!("CARGO_BIN_EXE_cdyn"))
        .args(["run", file.to_str().unwrap(), "--out", dir.path().join("out").to_str().unwrap()])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > Duration::from_secs(60) {
            child.kill().unwrap();
            panic!("cdyn run hangs on:\n{text}");
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    Ran { out: child.wait_with_output().unwrap(), text: text.to_string() }
}

/// A clean outcome: success, or exit 1 with one line `error: …`; never a
/// panic, a signal or another code. Returns the error line on failure.
fn clean(ran: &Ran) -> Result<Option<String>, TestCaseError> {
    let err = String::from_utf8_lossy(&ran.out.stderr).into_owned();
    let text = &ran.text;
    prop_assert!(!err.contains("panicked"), "panic: {err}\non:\n{text}");
    match ran.out.status.code() {
        Some(0) => Ok(None),
        Some(1) => {
            prop_assert_eq!(err.trim_end().lines().count(), 1, "not one line: {}\non:\n{}", err, text);
            prop_assert!(err.starts_with("error: "), "{err}\non:\n{text}");
            Ok(Some(err))
        }
        other => Err(TestCaseError::fail(format!("exit {other:?} (a crash?): {err}\non:\n{text}"))),
    }
}

/// `cases` cases, or `PROPTEST_CASES` for a longer search.
fn config(cases: u32) -> Config {
    let cases = std::env::var("PROPTEST_CASES").ok().and_then(|n| n.parse().ok()).unwrap_or(cases);
    Config { cases, failure_persistence: None, ..Config::default() }
}

#[test]
fn every_shortened_example_runs() {
    for (name, table) in examples() {
        let ran = run(&toml::to_string(&table).unwrap());
        assert!(ran.out.status.success(), "{name}: {}", String::from_utf8_lossy(&ran.out.stderr));
    }
}

#[test]
fn a_misspelt_or_unknown_key_is_an_error_naming_it() {
    let examples = examples();
    let mut runner = TestRunner::new(config(64));
    let strategy = (0..examples.len(), any::<prop::sample::Index>(), any::<bool>(), "[a-z]{1,3}");
    runner
        .run(&strategy, |(which, at, add, suffix)| {
            let (name, table) = &examples[which];
            let keys = key_paths(table);
            let path = &keys[at.index(keys.len())];
            let mut root = toml::Value::Table(table.clone());
            let Some(Step::Key(key)) = path.last() else { unreachable!() };
            let container = parent(&mut root, path);
            let new_key = format!("{key}_{suffix}");
            let holder = container.as_table_mut().unwrap();
            if add {
                // A new key beside an existing one.
                holder.insert(new_key.clone(), toml::Value::Integer(1));
            } else {
                // The key misspelt: the same value under another name.
                let value = holder.remove(key).unwrap();
                holder.insert(new_key.clone(), value);
            }
            let ran = run(&toml::to_string(&root).unwrap());
            let err = clean(&ran)?;
            let Some(err) = err else {
                return Err(TestCaseError::fail(format!(
                    "{name}: exit 0 with the unknown key {new_key} (ignored?):\n{}",
                    ran.text
                )));
            };
            // A required key misspelt may be reported as missing instead.
            let named = err.contains(&new_key) || (!add && err.contains(&format!("missing field {key}")));
            prop_assert!(named, "{name}: the error names neither {new_key} nor a missing {key}: {err}");
            Ok(())
        })
        .unwrap();
}

/// A value in place of another: other numbers, other types.
fn replacement() -> impl Strategy<Value = toml::Value> {
    prop_oneof![
        Just(toml::Value::Float(0.0)),
        Just(toml::Value::Float(-1.0)),
        Just(toml::Value::Float(f64::NAN)),
        Just(toml::Value::Float(f64::INFINITY)),
        Just(toml::Value::Float(1e300)),
        Just(toml::Value::Float(1e-300)),
        Just(toml::Value::Integer(0)),
        Just(toml::Value::Integer(-3)),
        Just(toml::Value::Integer(i64::MAX)),
        (-1e3..1e3f64).prop_map(toml::Value::Float),
        "[a-z_]{0,8}".prop_map(toml::Value::String),
        any::<bool>().prop_map(toml::Value::Boolean),
        Just(toml::Value::Array(vec![])),
        Just(toml::Value::Array(vec![toml::Value::Float(1.0), toml::Value::String("x".into())])),
        Just(toml::Value::Table(toml::Table::new())),
    ]
}

#[test]
fn changed_values_and_types_give_a_clean_error_or_a_run() {
    let examples = examples();
    let mut runner = TestRunner::new(config(96));
    let strategy = (0..examples.len(), any::<prop::sample::Index>(), replacement(), any::<bool>());
    let (ran_ok, refused) = (AtomicUsize::new(0), AtomicUsize::new(0));
    runner
        .run(&strategy, |(which, at, value, delete)| {
            let (_, table) = &examples[which];
            let all = all_paths(table);
            let path = &all[at.index(all.len())];
            let mut root = toml::Value::Table(table.clone());
            let container = parent(&mut root, path);
            match (path.last().unwrap(), container) {
                (Step::Key(k), toml::Value::Table(t)) if delete => drop(t.remove(k)),
                (Step::Key(k), toml::Value::Table(t)) => drop(t.insert(k.clone(), value)),
                (Step::Index(i), toml::Value::Array(a)) if delete => drop(a.remove(*i)),
                (Step::Index(i), toml::Value::Array(a)) => a[*i] = value,
                _ => unreachable!(),
            }
            // A mixed array cannot be written as TOML by every writer; a
            // value the writer refuses is no scenario to test.
            let Ok(text) = toml::to_string(&root) else { return Ok(()) };
            let outcome = clean(&run(&text))?;
            [&ran_ok, &refused][usize::from(outcome.is_some())].fetch_add(1, Ordering::Relaxed);
            Ok(())
        })
        .unwrap();
    // Both outcomes occur, so the test exercises the runs and the refusals.
    let (ran_ok, refused) = (ran_ok.into_inner(), refused.into_inner());
    assert!(ran_ok > 0 && refused > 0, "{ran_ok} runs, {refused} refusals");
}

#[test]
fn truncated_files_give_a_clean_error_or_a_run() {
    let examples = examples();
    let mut runner = TestRunner::new(config(64));
    let strategy = (0..examples.len(), any::<prop::sample::Index>());
    runner
        .run(&strategy, |(which, at)| {
            let text = toml::to_string(&examples[which].1).unwrap();
            let mut cut = at.index(text.len());
            while !text.is_char_boundary(cut) {
                cut -= 1;
            }
            clean(&run(&text[..cut])).map(drop)
        })
        .unwrap();
}

//! What `docs/library.md` ("What is stable") promises, checked on the
//! source: every public enum is `#[non_exhaustive]` unless it is a closed
//! set named below, and every configuration type — one that scenario files
//! deserialize, or that has `with_*` setters — is `#[non_exhaustive]`, so
//! that a new variant or field does not break a user's program.

use std::path::{Path, PathBuf};

/// Enums whose variants are a closed set: a `match` on them needs no
/// wildcard arm, and a new variant would be a breaking change on purpose.
const CLOSED: &[&str] = &[
    "BodyId",        // planar: the ground or a body
    "Coordinate",    // planar: a body's x, y, angle
    "FourBarBranch", // the two assemblies of a four-bar
];

/// Not yet `#[non_exhaustive]` (file, name): none now; a type listed here
/// makes the test say so until it is marked.
const PENDING: &[(&str, &str)] = &[];

fn pending(item: &Item) -> bool {
    PENDING.iter().any(|(file, name)| item.file.ends_with(file) && item.name == *name)
}

fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            sources(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// A public item at the top level of a file: its kind, name, and the
/// attribute and doc lines right above it.
struct Item {
    file: String,
    kind: &'static str,
    name: String,
    attributes: String,
}

impl Item {
    fn marked(&self) -> bool {
        self.attributes.lines().any(|l| l.trim() == "#[non_exhaustive]")
    }
}

fn items() -> Vec<Item> {
    let mut files = Vec::new();
    sources(&Path::new(env!("CARGO_MANIFEST_DIR")).join("src"), &mut files);
    let mut items = Vec::new();
    for path in files {
        let text = std::fs::read_to_string(&path).unwrap();
        // Leave out the unit tests: a `#[cfg(test)]` module with a body.
        let lines: Vec<&str> = text.lines().collect();
        let end = (0..lines.len())
            .find(|&i| lines[i] == "#[cfg(test)]" && lines.get(i + 1).is_some_and(|l| l.ends_with('{')))
            .unwrap_or(lines.len());
        for (i, line) in lines[..end].iter().enumerate() {
            let Some((kind, rest)) = line
                .strip_prefix("pub enum ")
                .map(|r| ("enum", r))
                .or(line.strip_prefix("pub struct ").map(|r| ("struct", r)))
            else {
                continue;
            };
            let name: String = rest.chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
            let above = lines[..i].iter().rev().take_while(|l| {
                l.starts_with('#') || l.starts_with("///") || l.starts_with("    ") || l.starts_with(')')
            });
            let attributes = above.copied().collect::<Vec<_>>().join("\n");
            let file = path.display().to_string();
            items.push(Item { file, kind, name, attributes });
        }
    }
    items
}

fn setters_of(name: &str) -> bool {
    let mut files = Vec::new();
    sources(&Path::new(env!("CARGO_MANIFEST_DIR")).join("src"), &mut files);
    files.iter().any(|p| {
        let text = std::fs::read_to_string(p).unwrap();
        text.contains(&format!("setters!({name} {{")) || text.contains(&format!("setters!(impl<B> {name}<B> {{"))
    })
}

#[test]
fn public_enums_and_configuration_types_are_non_exhaustive() {
    let items = items();
    assert!(items.len() > 50, "only {} public types found", items.len());
    let mut missing = Vec::new();
    let mut configuration = 0;
    for item in &items {
        let marked = item.marked();
        let wanted = match item.kind {
            "enum" => !CLOSED.contains(&item.name.as_str()),
            _ => {
                let config = item.attributes.contains("Deserialize") || setters_of(&item.name);
                configuration += usize::from(config);
                config
            }
        };
        if wanted && !marked && !pending(item) {
            missing.push(format!("{} {} ({})", item.kind, item.name, item.file));
        }
        if marked && CLOSED.contains(&item.name.as_str()) {
            missing.push(format!("{} is listed as closed but marked #[non_exhaustive]", item.name));
        }
    }
    assert!(configuration >= 20, "only {configuration} configuration types found");
    assert!(missing.is_empty(), "not #[non_exhaustive]:\n{}", missing.join("\n"));
}

#[test]
fn pending_names_are_still_pending() {
    // A type left in PENDING after it is marked says something false.
    let items = items();
    for (file, name) in PENDING {
        let found: Vec<_> = items.iter().filter(|i| i.name == *name && i.file.ends_with(file)).collect();
        assert_eq!(found.len(), 1, "{file}: no public type {name}");
        assert!(!found[0].marked(), "{name} is marked now: remove it from PENDING");
    }
}

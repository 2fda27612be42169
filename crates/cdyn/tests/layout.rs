//! The library and the command line are laid out by concept, with imports
//! pointing one way:
//! - among the top-level modules (folders and files), no chain of
//!   `crate::…` references leads back to where it started;
//! - nor among the files inside one folder;
//! - each folder's `mod.rs` says which top-level modules it may import
//!   (`May import: …`), and its code imports no other;
//! - code inside a crate names modules by their paths, not by the flat
//!   aliases kept at the crate root for users' old programs.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

type Graph = BTreeMap<String, BTreeSet<String>>;

/// A source file's code: test modules and comment lines left out.
fn code(path: &Path) -> String {
    let text = std::fs::read_to_string(path).unwrap();
    let code = text.split("#[cfg(test)]").next().unwrap();
    code.lines().filter(|l| !l.trim_start().starts_with("//")).collect::<Vec<_>>().join("\n")
}

fn ident(s: &str) -> String {
    s.chars().take_while(|c| c.is_ascii_alphanumeric() || *c == '_').collect()
}

/// The paths named after `prefix` (`crate::`, `super::`), each as its
/// segments; `a::{b, c::d}` yields `a::b` and `a::c::d`.
fn paths(code: &str, prefix: &str) -> Vec<Vec<String>> {
    fn expand(s: &str, stem: Vec<String>, out: &mut Vec<Vec<String>>) {
        // `s` starts right after a `::`.
        if let Some(rest) = s.strip_prefix('{') {
            let mut depth = 0;
            let mut start = 0;
            for (i, c) in rest.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 0 => {
                        expand_item(&rest[start..i], stem.clone(), out);
                        return;
                    }
                    '}' => depth -= 1,
                    ',' if depth == 0 => {
                        expand_item(&rest[start..i], stem.clone(), out);
                        start = i + 1;
                    }
                    _ => {}
                }
            }
            return;
        }
        expand_item(s, stem, out);
    }
    fn expand_item(s: &str, mut stem: Vec<String>, out: &mut Vec<Vec<String>>) {
        let s = s.trim_start();
        let name = ident(s);
        if name.is_empty() {
            if !stem.is_empty() {
                out.push(stem);
            }
            return;
        }
        stem.push(name.clone());
        let rest = &s[name.len()..];
        match rest.strip_prefix("::") {
            Some(rest) => expand(rest.trim_start(), stem, out),
            None => out.push(stem),
        }
    }
    let mut out = Vec::new();
    for (at, _) in code.match_indices(prefix) {
        let before = code[..at].chars().next_back();
        if before.is_some_and(|c| c.is_ascii_alphanumeric() || c == '_' || c == ':') {
            continue;
        }
        expand(&code[at + prefix.len()..], Vec::new(), &mut out);
    }
    out
}

/// The modules a `mod.rs` or `lib.rs` declares.
fn declared_modules(code: &str) -> BTreeSet<String> {
    code.lines()
        .filter_map(|l| {
            let l = l.trim_start();
            let l = l.strip_prefix("pub(crate) ").or_else(|| l.strip_prefix("pub ")).unwrap_or(l);
            l.strip_prefix("mod ").map(ident)
        })
        .collect()
}

/// The names a file declares at its top level (items and public re-exports).
fn declared_items(code: &str) -> BTreeSet<String> {
    let mut names = BTreeSet::new();
    for line in code.lines().filter(|l| !l.starts_with(' ') && !l.starts_with('}')) {
        let public = line.starts_with("pub");
        let l = line.strip_prefix("pub(crate) ").or_else(|| line.strip_prefix("pub ")).unwrap_or(line);
        for kind in ["struct ", "enum ", "trait ", "fn ", "const ", "type ", "static ", "mod "] {
            if let Some(rest) = l.strip_prefix(kind) {
                names.insert(ident(rest));
            }
        }
        if public && l.starts_with("use ") {
            for p in paths(l, "super::").into_iter().chain(paths(l, "crate::")) {
                names.insert(p.last().unwrap().clone());
            }
        }
    }
    names
}

struct Crate {
    src: PathBuf,
    /// Top-level module → its files (name within the folder → code).
    modules: BTreeMap<String, BTreeMap<String, String>>,
    /// Item re-exported at the root → the top-level module it comes from.
    root_items: BTreeMap<String, String>,
    /// The flat aliases kept at the root for users.
    aliases: BTreeSet<String>,
    /// Macros defined in `lib.rs`.
    macros: BTreeSet<String>,
}

fn read(krate: &str) -> Crate {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(krate).join("src");
    let root = ["lib.rs", "main.rs"].iter().map(|f| src.join(f)).find(|p| p.exists()).unwrap();
    let lib = std::fs::read_to_string(&root).unwrap();
    let mut modules = BTreeMap::new();
    for name in declared_modules(&lib) {
        let file = src.join(format!("{name}.rs"));
        let mut files = BTreeMap::new();
        if file.exists() {
            files.insert(String::new(), code(&file));
        } else {
            for entry in std::fs::read_dir(src.join(&name)).unwrap() {
                let path = entry.unwrap().path();
                let stem = path.file_stem().unwrap().to_string_lossy().to_string();
                if path.extension().is_some_and(|e| e == "rs") {
                    files.insert(if stem == "mod" { String::new() } else { stem }, code(&path));
                } else if path.join("mod.rs").exists() {
                    // A module split into a folder of its own counts as one file of its folder.
                    let mut nested: Vec<_> = std::fs::read_dir(&path).unwrap().map(|e| e.unwrap().path()).collect();
                    nested.sort();
                    files.insert(stem, nested.iter().map(|p| code(p)).collect::<Vec<_>>().join("\n"));
                }
            }
        }
        modules.insert(name, files);
    }
    let mut root_items = BTreeMap::new();
    let mut aliases = BTreeSet::new();
    let lib_code = code(&root);
    let mut rest = lib_code.as_str();
    while let Some(at) = rest.find("pub use ") {
        let hidden = rest[..at].trim_end().ends_with("#[doc(hidden)]");
        let end = at + rest[at..].find(';').unwrap();
        let text = format!("crate::{}", rest[at + 8..end].trim().trim_start_matches("crate::"));
        for p in paths(&text, "crate::") {
            if hidden {
                aliases.insert(p.last().unwrap().clone());
            } else {
                root_items.insert(p.last().unwrap().clone(), p[0].clone());
            }
        }
        rest = &rest[end..];
    }
    let macros = lib_code.lines().filter_map(|l| l.strip_prefix("macro_rules! ").map(ident)).collect();
    Crate { src, modules, root_items, aliases, macros }
}

impl Crate {
    /// Top-level module → the top-level modules its code names.
    fn top_graph(&self) -> Graph {
        let mut graph = Graph::new();
        for (name, files) in &self.modules {
            let names = graph.entry(name.clone()).or_default();
            for (file, code) in files {
                for path in paths(code, "crate::") {
                    let first = &path[0];
                    let target = if self.modules.contains_key(first) {
                        first.clone()
                    } else if let Some(module) = self.root_items.get(first) {
                        module.clone()
                    } else if self.macros.contains(first) {
                        continue;
                    } else if self.aliases.contains(first) {
                        panic!(
                            "{}/{name}/{file}: names `crate::{}`, a flat alias kept for users; use its path",
                            self.src.display(),
                            path.join("::")
                        );
                    } else {
                        panic!("{}/{name}/{file}: `crate::{}` names no module", self.src.display(), path.join("::"));
                    };
                    if &target != name {
                        names.insert(target);
                    }
                }
            }
        }
        graph
    }

    /// Within folder `name`: file → the files of the same folder it names.
    fn folder_graph(&self, name: &str) -> Graph {
        let files = &self.modules[name];
        let owner: BTreeMap<String, String> = files
            .iter()
            .filter(|(f, _)| !f.is_empty())
            .flat_map(|(f, code)| declared_items(code).into_iter().map(move |item| (item, f.clone())))
            .chain(files.keys().filter(|f| !f.is_empty()).map(|f| (f.clone(), f.clone())))
            .collect();
        let mut graph = Graph::new();
        for (file, code) in files.iter().filter(|(f, _)| !f.is_empty()) {
            let names = graph.entry(file.clone()).or_default();
            let inside = paths(code, "crate::").into_iter().filter(|p| p[0] == name).map(|p| p[1..].to_vec());
            for path in inside.chain(paths(code, "super::")) {
                if let Some(target) = path.first().and_then(|first| owner.get(first))
                    && target != file
                {
                    names.insert(target.clone());
                }
            }
        }
        graph
    }
}

/// A cycle through `start`, if any.
fn cycle(graph: &Graph, start: &str) -> Option<Vec<String>> {
    fn walk(graph: &Graph, start: &str, path: &mut Vec<String>, seen: &mut BTreeSet<String>) -> bool {
        let here = path.last().unwrap().clone();
        for next in graph.get(&here).into_iter().flatten() {
            if next == start {
                path.push(next.clone());
                return true;
            }
            if graph.contains_key(next) && seen.insert(next.clone()) {
                path.push(next.clone());
                if walk(graph, start, path, seen) {
                    return true;
                }
                path.pop();
            }
        }
        false
    }
    let mut path = vec![start.to_string()];
    walk(graph, start, &mut path, &mut BTreeSet::new()).then_some(path)
}

fn no_cycle(graph: &Graph, what: &str) {
    for module in graph.keys() {
        if let Some(path) = cycle(graph, module) {
            panic!("{what}: an import circle: {}", path.join(" → "));
        }
    }
}

#[test]
fn no_module_imports_its_way_back_to_itself() {
    for krate in ["cdyn", "cdyn-cli"] {
        let c = read(krate);
        let graph = c.top_graph();
        let files: usize = c.modules.values().map(BTreeMap::len).sum();
        assert!(graph.len() >= 4 && files > 20, "{krate}: only {} modules, {files} files found", graph.len());
        no_cycle(&graph, krate);
        for (name, files) in &c.modules {
            if files.len() > 1 {
                no_cycle(&c.folder_graph(name), &format!("{krate}/{name}"));
            }
        }
    }
}

#[test]
fn each_folder_imports_only_what_its_head_allows() {
    for krate in ["cdyn", "cdyn-cli"] {
        let c = read(krate);
        let graph = c.top_graph();
        let folders: Vec<_> = c.modules.iter().filter(|(_, files)| files.len() > 1).collect();
        assert!(folders.len() >= 4, "{krate}: only {} folders", folders.len());
        for (name, _) in folders {
            let head = std::fs::read_to_string(c.src.join(name).join("mod.rs")).unwrap();
            let line = head
                .split("//! May import:")
                .nth(1)
                .unwrap_or_else(|| panic!("{krate}/{name}/mod.rs does not say what it may import"));
            let mut lines = line.lines();
            let first = lines.next().unwrap().to_string();
            let more = lines.map_while(|l| l.strip_prefix("//! ")).map(str::to_string);
            let allowed: BTreeSet<String> = std::iter::once(first)
                .chain(more)
                .collect::<Vec<_>>()
                .join(" ")
                .split([',', '`', '.', ' '])
                .filter(|w| c.modules.contains_key(*w))
                .map(str::to_string)
                .collect();
            let extra: Vec<_> = graph[name].difference(&allowed).collect();
            assert!(extra.is_empty(), "{krate}/{name} imports {extra:?}, which its mod.rs does not allow");
        }
    }
}

#[test]
fn the_path_reader_sees_groups_and_nesting() {
    let code = "use crate::{a::{b, c::D}, e};\nfn f() { crate::g::h(); super::i::J; }";
    let found: Vec<String> = paths(code, "crate::").into_iter().map(|p| p.join("::")).collect();
    assert_eq!(found, ["a::b", "a::c::D", "e", "g::h"]);
    assert_eq!(paths(code, "super::"), [vec!["i".to_string(), "J".to_string()]]);
}

//! The module structure ARCHITECTURE.md promises, checked on the source tree:
//! - the top-level modules of `src/` import each other without a cycle (data flows one way:
//!   `cli` → `build` → `family` → the generic stages → `fit`, `integrate`);
//! - outside `src/family/`, no source file names a family or one of its quantities: the
//!   generic stages reach them only through the registry.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

fn src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

/// The top-level module a file of `src/` belongs to (`None` for the crate roots).
fn top_module(path: &Path) -> Option<String> {
    let rel = path.strip_prefix(src()).unwrap();
    let first = rel.components().next()?.as_os_str().to_str()?.to_string();
    let name = first.strip_suffix(".rs").unwrap_or(&first).to_string();
    (name != "lib" && name != "main").then_some(name)
}

/// Identifiers following `crate::` in the file (including inside `use crate::{a, b}` groups).
fn crate_refs(text: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for (i, _) in text.match_indices("crate::") {
        // `$crate::` and `other::crate::` are not paths of this crate.
        if text[..i].ends_with('$') || text[..i].ends_with("::") {
            continue;
        }
        let rest = &text[i + "crate::".len()..];
        if let Some(group) = rest.strip_prefix('{') {
            let end = group.find('}').unwrap_or(group.len());
            for part in group[..end].split(',') {
                let id: String = part.trim().chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
                if !id.is_empty() {
                    out.insert(id);
                }
            }
        } else {
            let id: String = rest.chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
            if !id.is_empty() {
                out.insert(id);
            }
        }
    }
    out
}

fn module_graph() -> BTreeMap<String, BTreeSet<String>> {
    let mut files = Vec::new();
    rust_files(&src(), &mut files);
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for f in &files {
        let Some(m) = top_module(f) else { continue };
        let text = std::fs::read_to_string(f).unwrap();
        let deps = graph.entry(m.clone()).or_default();
        deps.extend(crate_refs(&text).into_iter().filter(|d| *d != m));
    }
    let modules: BTreeSet<String> = graph.keys().cloned().collect();
    for deps in graph.values_mut() {
        deps.retain(|d| modules.contains(d));
    }
    graph
}

/// A cycle of the graph, if there is one (depth-first search, deterministic order).
fn find_cycle(graph: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn visit(
        n: &str,
        graph: &BTreeMap<String, BTreeSet<String>>,
        state: &mut BTreeMap<String, u8>,
        stack: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        state.insert(n.to_string(), 1);
        stack.push(n.to_string());
        for d in &graph[n] {
            match state.get(d.as_str()).copied().unwrap_or(0) {
                1 => {
                    let at = stack.iter().position(|s| s == d).unwrap();
                    let mut cycle = stack[at..].to_vec();
                    cycle.push(d.clone());
                    return Some(cycle);
                }
                0 => {
                    if let Some(c) = visit(d, graph, state, stack) {
                        return Some(c);
                    }
                }
                _ => {}
            }
        }
        stack.pop();
        state.insert(n.to_string(), 2);
        None
    }
    let mut state = BTreeMap::new();
    for n in graph.keys() {
        if state.get(n.as_str()).copied().unwrap_or(0) == 0
            && let Some(c) = visit(n, graph, &mut state, &mut Vec::new())
        {
            return Some(c);
        }
    }
    None
}

#[test]
fn cycle_finder_finds_a_planted_cycle() {
    // The checker itself can fail: a three-module cycle and a diamond (no cycle).
    let g = |edges: &[(&str, &str)]| {
        let mut m: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
        for (a, b) in edges {
            m.entry(a.to_string()).or_default().insert(b.to_string());
            m.entry(b.to_string()).or_default();
        }
        m
    };
    assert_eq!(find_cycle(&g(&[("a", "b"), ("b", "c"), ("c", "a")])).map(|c| c.len()), Some(4));
    assert_eq!(find_cycle(&g(&[("a", "b"), ("a", "c"), ("b", "d"), ("c", "d")])), None);
    assert_eq!(
        crate_refs("use crate::fit::{a, b};\nuse crate::{spec, emit::x};\n$crate::no\nshadefit::crate::no"),
        ["emit", "fit", "spec"].iter().map(|s| s.to_string()).collect()
    );
}

#[test]
fn top_level_modules_import_each_other_without_a_cycle() {
    let graph = module_graph();
    for (m, deps) in &graph {
        println!("{m:<10} → {}", deps.iter().cloned().collect::<Vec<_>>().join(", "));
    }
    assert!(graph.contains_key("family") && graph.contains_key("fit"), "modules not found: {graph:?}");
    if let Some(c) = find_cycle(&graph) {
        panic!("import cycle between top-level modules: {}", c.join(" → "));
    }
}

/// Whole-word occurrences of `word` in `text` (a word: letters, digits and `_`).
fn has_word(text: &str, word: &str) -> bool {
    let is_word = |c: char| c.is_alphanumeric() || c == '_';
    text.match_indices(word).any(|(i, _)| {
        let before = text[..i].chars().next_back();
        let after = text[i + word.len()..].chars().next();
        !before.is_some_and(is_word) && !after.is_some_and(is_word)
    })
}

#[test]
fn only_the_family_folders_name_a_family() {
    let mut names: Vec<String> = Vec::new();
    for f in shadefit::family::families() {
        names.push(f.name.to_string());
        names.extend(f.quantities.iter().map(|q| q.name.to_string()));
        names.extend(f.spec_kinds.iter().map(|k| k.spec.name.to_string()));
    }
    let mut files = Vec::new();
    rust_files(&src(), &mut files);
    let family_dir = src().join("family");
    let mut found = Vec::new();
    for f in files.iter().filter(|f| !f.starts_with(&family_dir)) {
        let text = std::fs::read_to_string(f).unwrap();
        for n in &names {
            if has_word(&text, n) {
                found.push(format!("{} names '{n}'", f.strip_prefix(src()).unwrap().display()));
            }
        }
    }
    assert!(found.is_empty(), "generic modules name families:\n{}", found.join("\n"));
    // The check can fail: a planted mention is found.
    assert!(has_word("see the gloss-length fit", "gloss") && !has_word("glossary", "gloss"));
}

/// The module path of a file of `src/` (`family/ggx/lut/spec.rs` → family, ggx, lut, spec;
/// `mod.rs` names its folder).
fn module_path(path: &Path) -> Vec<String> {
    let rel = path.strip_prefix(src()).unwrap();
    let mut out: Vec<String> = rel.components().map(|c| c.as_os_str().to_str().unwrap().to_string()).collect();
    let last = out.pop().unwrap();
    let stem = last.strip_suffix(".rs").unwrap_or(&last).to_string();
    if stem != "mod" && stem != "lib" && stem != "main" {
        out.push(stem);
    }
    out
}

/// The families a file names by path: `crate::family::NAME` and `super::…::NAME` chains that
/// climb out of its own family folder into `family`.
fn families_named(path: &Path, text: &str, families: &[String]) -> BTreeSet<String> {
    let module = module_path(path);
    let mut out = BTreeSet::new();
    let ident = |s: &str| s.chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect::<String>();
    for (i, _) in text.match_indices("crate::family::") {
        if text[..i].ends_with('$') || text[..i].ends_with("::") {
            continue;
        }
        let rest = &text[i + "crate::family::".len()..];
        if let Some(group) = rest.strip_prefix('{') {
            let end = group.find('}').unwrap_or(group.len());
            out.extend(group[..end].split(',').map(|p| ident(p.trim())));
        } else {
            out.insert(ident(rest));
        }
    }
    for (i, _) in text.match_indices("super::") {
        if text[..i].ends_with("::") {
            continue;
        }
        let mut rest = &text[i..];
        let mut up = 0;
        while let Some(r) = rest.strip_prefix("super::") {
            up += 1;
            rest = r;
        }
        if up <= module.len() && module[..module.len() - up] == ["family".to_string()] {
            out.insert(ident(rest));
        }
    }
    out.retain(|n| families.contains(n));
    out
}

#[test]
fn no_family_imports_another_family() {
    let families: Vec<String> = shadefit::family::families().iter().map(|f| f.name.to_string()).collect();
    let mut files = Vec::new();
    rust_files(&src().join("family"), &mut files);
    let mut found = Vec::new();
    for f in &files {
        let module = module_path(f);
        let Some(own) = module.get(1) else { continue };
        let text = std::fs::read_to_string(f).unwrap();
        for other in families_named(f, &text, &families) {
            if &other != own {
                found.push(format!("{} names family '{other}'", f.strip_prefix(src()).unwrap().display()));
            }
        }
    }
    assert!(found.is_empty(), "families import each other (shared terms belong in the shading layer or a stage):\n{}", found.join("\n"));
    // The check can fail: planted paths of another family are found, one's own and a stage are not.
    let fams = ["ggx".to_string(), "gloss".to_string()];
    let at = src().join("family/ggx/lut/spec.rs");
    let named = |t: &str| families_named(&at, t, &fams).into_iter().collect::<Vec<_>>();
    assert_eq!(named("use crate::family::gloss::integrals::x;"), ["gloss"]);
    assert_eq!(named("use crate::family::{gloss, Family};"), ["gloss"]);
    assert_eq!(named("super::super::super::gloss::integrals::x"), ["gloss"]);
    assert!(named("super::super::integrals::env; crate::family::ggx::lut; crate::shading::roughness").iter().all(|n| n == "ggx"));
}

/// Lines of a file before its first `#[cfg(test)]` item at the top level (all of it when it
/// has none).
fn lines_before_tests(text: &str) -> usize {
    text.lines().take_while(|l| !l.starts_with("#[cfg(test)]")).count()
}

#[test]
fn no_source_file_is_longer_than_1200_lines_before_its_tests() {
    let mut files = Vec::new();
    rust_files(&src(), &mut files);
    let mut long: Vec<String> = files
        .iter()
        .filter_map(|f| {
            let n = lines_before_tests(&std::fs::read_to_string(f).unwrap());
            (n > 1200).then(|| format!("{}: {n} lines", f.strip_prefix(src()).unwrap().display()))
        })
        .collect();
    long.sort();
    assert!(long.is_empty(), "files to split along their concerns:\n{}", long.join("\n"));
    assert_eq!(lines_before_tests("a\nb\n#[cfg(test)]\nmod tests {}\n"), 2);
    assert_eq!(lines_before_tests("a\n    #[cfg(test)]\nb\n"), 3);
}

//! House rule: imports run downward, never back up. This test parses every `crate::`, `super::`
//! and `self::` path in the library crates' module files (the core `photomontage/src` without its
//! binaries, and the studio's `app/src` library) and fails when modules import each other in a
//! circle, directly or through others.
//!
//! A path resolves to the deepest module file it names (`crate::fit::pick::Pick` → `fit::pick`).
//! Imports between a module and its own ancestors are not edges: a parent declares and
//! re-exports its children, and a child reaches its parent's shared types, which is the tree, not
//! a circle. Test-only code (`*tests.rs` files and inline `#[cfg(test)] mod … { … }`) is skipped.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// A crate's module files: module path (`["fit", "pick"]`) → source text.
fn module_files(src: &Path) -> BTreeMap<Vec<String>, String> {
    let mut out = BTreeMap::new();
    let mut stack = vec![src.to_path_buf()];
    while let Some(dir) = stack.pop() {
        let entries = std::fs::read_dir(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
        for entry in entries {
            let path = entry.expect("directory entry").path();
            if path.is_dir() {
                if path.file_name().is_some_and(|n| n == "bin") && dir == src {
                    continue; // binaries are their own crates
                }
                stack.push(path);
                continue;
            }
            let Some(name) = path.file_name().and_then(|n| n.to_str()) else {
                continue;
            };
            if !name.ends_with(".rs") || name.ends_with("tests.rs") || name == "main.rs" {
                continue;
            }
            let text = std::fs::read_to_string(&path).expect("module source");
            out.insert(module_path(src, &path), text);
        }
    }
    out
}

fn module_path(src: &Path, file: &Path) -> Vec<String> {
    let rel = file.strip_prefix(src).expect("file under src");
    let mut parts: Vec<String> = rel
        .iter()
        .map(|p| p.to_string_lossy().into_owned())
        .collect();
    let last = parts.pop().expect("file name");
    let stem = last.trim_end_matches(".rs");
    if stem != "mod" && stem != "lib" {
        parts.push(stem.to_owned());
    }
    parts
}

/// Drops comments and string literals so that paths in docs and messages are not read as imports.
fn strip_comments_and_strings(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let bytes: Vec<char> = text.chars().collect();
    let mut i = 0;
    while i < bytes.len() {
        let c = bytes[i];
        let next = bytes.get(i + 1).copied();
        if c == '/' && next == Some('/') {
            while i < bytes.len() && bytes[i] != '\n' {
                i += 1;
            }
        } else if c == '/' && next == Some('*') {
            i += 2;
            while i + 1 < bytes.len() && !(bytes[i] == '*' && bytes[i + 1] == '/') {
                i += 1;
            }
            i += 2;
        } else if c == '"' {
            i += 1;
            while i < bytes.len() && bytes[i] != '"' {
                if bytes[i] == '\\' {
                    i += 1;
                }
                i += 1;
            }
            i += 1;
            out.push_str("\"\"");
        } else if c == '\'' && next.is_some_and(|n| n != '\\') && bytes.get(i + 2) == Some(&'\'') {
            i += 3; // a char literal such as '{'
        } else if c == '\'' && next == Some('\\') {
            i += 2;
            while i < bytes.len() && bytes[i] != '\'' {
                i += 1;
            }
            i += 1;
        } else {
            out.push(c);
            i += 1;
        }
    }
    out
}

/// Removes inline `#[cfg(test)] mod name { … }` blocks (comments and strings already stripped,
/// so the braces balance).
fn strip_test_modules(text: &str) -> String {
    let mut out = text.to_owned();
    while let Some(start) = out.find("#[cfg(test)]") {
        let after = &out[start + "#[cfg(test)]".len()..];
        let trimmed = after.trim_start();
        let is_inline_mod = trimmed.starts_with("mod ")
            && trimmed
                .find(['{', ';'])
                .is_some_and(|i| trimmed.as_bytes()[i] == b'{');
        let end = if is_inline_mod {
            let open = start + out[start..].find('{').expect("brace found above");
            let mut depth = 0usize;
            let mut end = out.len();
            for (i, c) in out[open..].char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' => {
                        depth -= 1;
                        if depth == 0 {
                            end = open + i + 1;
                            break;
                        }
                    }
                    _ => {}
                }
            }
            end
        } else {
            start + "#[cfg(test)]".len()
        };
        out.replace_range(start..end, "");
    }
    out
}

/// Every path the text names, as segment lists starting with `crate`, `super` or `self`;
/// `use` groups (`use crate::{a::b, c::{d, e}}`) are expanded.
fn paths_in(text: &str) -> Vec<Vec<String>> {
    let chars: Vec<char> = text.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let starts_word = i == 0 || !(chars[i - 1].is_alphanumeric() || chars[i - 1] == '_');
        let rest: String = chars[i..chars.len().min(i + 7)].iter().collect();
        let root = ["crate::", "super::", "self::"]
            .into_iter()
            .find(|r| rest.starts_with(r));
        let preceded_by_colons = i >= 2 && chars[i - 1] == ':' && chars[i - 2] == ':';
        if let (true, Some(_), false) = (starts_word, root, preceded_by_colons) {
            let (paths, end) = parse_tree(&chars, i, Vec::new());
            out.extend(paths);
            i = end.max(i + 1);
        } else {
            i += 1;
        }
    }
    out
}

/// Parses a path tree at `i` (segments separated by `::`, possibly ending in a `{…}` group).
fn parse_tree(chars: &[char], mut i: usize, prefix: Vec<String>) -> (Vec<Vec<String>>, usize) {
    let mut segments = prefix;
    loop {
        while i < chars.len() && chars[i].is_whitespace() {
            i += 1;
        }
        if i < chars.len() && chars[i] == '{' {
            let mut out = Vec::new();
            i += 1;
            loop {
                while i < chars.len() && (chars[i].is_whitespace() || chars[i] == ',') {
                    i += 1;
                }
                if i >= chars.len() || chars[i] == '}' {
                    return (out, i + 1);
                }
                let (paths, end) = parse_tree(chars, i, segments.clone());
                out.extend(paths);
                if end <= i {
                    return (out, i + 1);
                }
                i = end;
            }
        }
        let start = i;
        while i < chars.len() && (chars[i].is_alphanumeric() || chars[i] == '_') {
            i += 1;
        }
        if i == start {
            // `*`, `self` handled as a segment below, or the end of the path
            if i < chars.len() && chars[i] == '*' {
                i += 1;
            }
            return (vec![segments], i);
        }
        segments.push(chars[start..i].iter().collect());
        if chars.get(i) == Some(&':') && chars.get(i + 1) == Some(&':') {
            i += 2;
        } else {
            // skip a trailing `as name`
            return (vec![segments], i);
        }
    }
}

/// Resolves a path seen in `from` to the deepest existing module it names.
fn resolve(
    from: &[String],
    path: &[String],
    modules: &BTreeSet<Vec<String>>,
) -> Option<Vec<String>> {
    let mut base: Vec<String> = from.to_vec();
    let mut rest = path;
    match rest.first().map(String::as_str) {
        Some("crate") => {
            base.clear();
            rest = &rest[1..];
        }
        Some("self") => rest = &rest[1..],
        Some("super") => {
            while rest.first().map(String::as_str) == Some("super") {
                base.pop()?;
                rest = &rest[1..];
            }
        }
        _ => return None,
    }
    let mut deepest = None;
    let mut current = base;
    if modules.contains(&current) {
        deepest = Some(current.clone());
    }
    for segment in rest {
        current.push(segment.clone());
        if modules.contains(&current) {
            deepest = Some(current.clone());
        } else {
            break;
        }
    }
    deepest
}

fn is_prefix(a: &[String], b: &[String]) -> bool {
    a.len() <= b.len() && a == &b[..a.len()]
}

/// Import edges between modules that are not ancestors of one another.
fn import_graph(src: &Path) -> BTreeMap<Vec<String>, BTreeSet<Vec<String>>> {
    let files = module_files(src);
    let modules: BTreeSet<Vec<String>> = files.keys().cloned().collect();
    let mut graph: BTreeMap<Vec<String>, BTreeSet<Vec<String>>> = BTreeMap::new();
    for (module, text) in &files {
        let text = strip_test_modules(&strip_comments_and_strings(text));
        let edges = graph.entry(module.clone()).or_default();
        for path in paths_in(&text) {
            let Some(target) = resolve(module, &path, &modules) else {
                continue;
            };
            if is_prefix(&target, module) || is_prefix(module, &target) {
                continue;
            }
            edges.insert(target);
        }
    }
    graph
}

/// Strongly connected components with more than one module (Tarjan).
fn cycles(graph: &BTreeMap<Vec<String>, BTreeSet<Vec<String>>>) -> Vec<Vec<Vec<String>>> {
    struct State<'a> {
        graph: &'a BTreeMap<Vec<String>, BTreeSet<Vec<String>>>,
        index: BTreeMap<&'a Vec<String>, usize>,
        low: BTreeMap<&'a Vec<String>, usize>,
        stack: Vec<&'a Vec<String>>,
        on_stack: BTreeSet<&'a Vec<String>>,
        next: usize,
        out: Vec<Vec<Vec<String>>>,
    }
    fn visit<'a>(s: &mut State<'a>, v: &'a Vec<String>) {
        s.index.insert(v, s.next);
        s.low.insert(v, s.next);
        s.next += 1;
        s.stack.push(v);
        s.on_stack.insert(v);
        if let Some(targets) = s.graph.get(v) {
            for w in targets {
                let Some((w, _)) = s.graph.get_key_value(w) else {
                    continue;
                };
                if !s.index.contains_key(w) {
                    visit(s, w);
                    let low = s.low[v].min(s.low[w]);
                    s.low.insert(v, low);
                } else if s.on_stack.contains(w) {
                    let low = s.low[v].min(s.index[w]);
                    s.low.insert(v, low);
                }
            }
        }
        if s.low[v] == s.index[v] {
            let mut component = Vec::new();
            while let Some(w) = s.stack.pop() {
                s.on_stack.remove(w);
                component.push(w.clone());
                if w == v {
                    break;
                }
            }
            if component.len() > 1 {
                component.sort();
                s.out.push(component);
            }
        }
    }
    let mut s = State {
        graph,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on_stack: BTreeSet::new(),
        next: 0,
        out: Vec::new(),
    };
    for v in graph.keys() {
        if !s.index.contains_key(v) {
            visit(&mut s, v);
        }
    }
    s.out
}

fn describe(
    graph: &BTreeMap<Vec<String>, BTreeSet<Vec<String>>>,
    component: &[Vec<String>],
) -> String {
    let members: BTreeSet<&Vec<String>> = component.iter().collect();
    let mut lines = Vec::new();
    for m in component {
        for t in graph.get(m).into_iter().flatten() {
            if members.contains(t) {
                lines.push(format!("  {} → {}", m.join("::"), t.join("::")));
            }
        }
    }
    lines.join("\n")
}

fn assert_no_cycles(crate_src: PathBuf) {
    let graph = import_graph(&crate_src);
    assert!(
        graph.len() > 5,
        "{}: too few modules found",
        crate_src.display()
    );
    let found = cycles(&graph);
    let report: Vec<String> = found.iter().map(|c| describe(&graph, c)).collect();
    assert!(
        found.is_empty(),
        "{}: modules import each other in a circle:\n{}",
        crate_src.display(),
        report.join("\n\n")
    );
}

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("workspace root")
        .to_path_buf()
}

#[test]
fn core_library_has_no_import_cycles() {
    assert_no_cycles(workspace().join("photomontage/src"));
}

#[test]
fn studio_has_no_import_cycles() {
    assert_no_cycles(workspace().join("app/src"));
}

/// The checker itself finds a circle through a third module, `super::` paths and `use` groups,
/// and ignores parent–child imports and paths in comments and strings.
#[test]
fn checker_finds_a_known_cycle() {
    let dir = tempfile::tempdir().expect("temp dir");
    let src = dir.path();
    std::fs::create_dir_all(src.join("a")).expect("mkdir");
    std::fs::create_dir_all(src.join("b")).expect("mkdir");
    let write = |p: &str, t: &str| std::fs::write(src.join(p), t).expect("write");
    write("lib.rs", "pub mod a; pub mod b; pub mod c; pub mod d;");
    write("a/mod.rs", "pub mod x; pub use x::X;");
    write("a/x.rs", "use crate::{b::y::{Y, Z}, d};\nuse super::X;");
    write("b/mod.rs", "pub mod y;");
    write("b/y.rs", "fn f() { super::super::c::g(); }");
    write(
        "c.rs",
        "// crate::d::h\nfn g() { let s = \"crate::d\"; crate::a::x::k(); }",
    );
    write(
        "d.rs",
        "pub fn h() {}\n#[cfg(test)]\nmod tests { use crate::a::x::k; fn t() { {} } }",
    );
    write("e.rs", "");
    let graph = import_graph(src);
    let found = cycles(&graph);
    let names: Vec<Vec<String>> = found
        .iter()
        .map(|c| c.iter().map(|m| m.join("::")).collect())
        .collect();
    assert_eq!(
        names,
        vec![vec!["a::x".to_owned(), "b::y".into(), "c".into()]]
    );
    // d is imported but imports nothing back; a (the parent) is not an edge target of a::x
    assert!(graph[&vec!["a".to_owned(), "x".into()]].contains(&vec!["d".to_owned()]));
    assert!(!graph[&vec!["c".to_owned()]].contains(&vec!["d".to_owned()]));
    // the test module of d imports a::x, which is not an edge
    assert!(graph[&vec!["d".to_owned()]].is_empty());
}

//! Tidy: the docs and the tree say the same thing (in the spirit of rust-analyzer's
//! `xtask/src/tidy.rs`). Every source file starts with a `//!` doc saying what it owns;
//! ARCHITECTURE.md names every crate of the workspace and no other, and its count of bad
//! inputs is the count in tests/bad; a test that can return early says `SKIPPED:` and why.

use pvtc_tests::root;
use std::path::{Path, PathBuf};

/// Every `.rs` file below `dir`, sorted.
fn rust_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                out.push(path);
            }
        }
    }
    out.sort();
    out
}

/// The workspace's member crates under `crates/`, from Cargo.toml.
fn member_crates() -> Vec<String> {
    let manifest = std::fs::read_to_string(root().join("Cargo.toml")).unwrap();
    let members = manifest
        .lines()
        .find(|l| l.trim_start().starts_with("members"))
        .expect("a members line");
    members
        .split('"')
        .filter_map(|m| m.strip_prefix("crates/"))
        .map(str::to_string)
        .collect()
}

#[test]
fn every_source_file_starts_with_a_module_doc() {
    let mut missing = Vec::new();
    let mut dirs: Vec<PathBuf> = member_crates()
        .iter()
        .map(|c| root().join("crates").join(c).join("src"))
        .collect();
    dirs.push(root().join("tests"));
    for dir in dirs {
        for file in rust_files(&dir) {
            let text = std::fs::read_to_string(&file).unwrap();
            let first = text.lines().find(|l| !l.trim().is_empty()).unwrap_or("");
            if !first.starts_with("//!") {
                missing.push(file.strip_prefix(root()).unwrap().display().to_string());
            }
        }
    }
    assert!(missing.is_empty(), "files without a //! doc: {missing:?}");
}

#[test]
fn architecture_names_every_crate_and_no_other() {
    let text = std::fs::read_to_string(root().join("ARCHITECTURE.md")).unwrap();
    let named: Vec<String> = text
        .lines()
        .filter_map(|l| l.strip_prefix("### `crates/"))
        .filter_map(|l| l.strip_suffix('`'))
        .map(str::to_string)
        .collect();
    let mut members = member_crates();
    members.sort();
    let mut sorted = named.clone();
    sorted.sort();
    assert_eq!(
        sorted, members,
        "ARCHITECTURE.md's crate sections against Cargo.toml"
    );
}

#[test]
fn architecture_counts_the_bad_inputs() {
    let text = std::fs::read_to_string(root().join("ARCHITECTURE.md")).unwrap();
    let claim: usize = text
        .split("`tests/bad.rs`: ")
        .nth(1)
        .and_then(|rest| rest.split(' ').next())
        .and_then(|n| n.parse().ok())
        .expect("ARCHITECTURE.md says how many bad inputs there are");
    let files = std::fs::read_dir(root().join("tests/bad"))
        .unwrap()
        .filter(|e| e.as_ref().unwrap().file_name() != "EXPECTED")
        .count();
    assert_eq!(claim, files, "ARCHITECTURE.md's count of tests/bad");
}

/// The body of every `#[test]` function of `text`: from its `fn` to the matching brace.
fn test_bodies(text: &str) -> Vec<&str> {
    let mut out = Vec::new();
    let mut rest = text;
    while let Some(at) = rest.find("#[test]") {
        let after = &rest[at..];
        let Some(open) = after.find('{') else { break };
        let mut depth = 0;
        let mut end = after.len();
        for (i, c) in after[open..].char_indices() {
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
        out.push(&after[..end]);
        rest = &after[end..];
    }
    out
}

#[test]
fn a_test_that_returns_early_says_it_skipped() {
    let mut dirs: Vec<PathBuf> = member_crates()
        .iter()
        .map(|c| root().join("crates").join(c).join("tests"))
        .filter(|d| d.is_dir())
        .collect();
    dirs.push(root().join("tests"));
    let mut silent = Vec::new();
    for dir in dirs {
        for file in rust_files(&dir) {
            let text = std::fs::read_to_string(&file).unwrap();
            for body in test_bodies(&text) {
                let returns = body.contains("return;") || body.contains("return }");
                if returns && !body.contains("#[ignore") && !text.contains("SKIPPED:") {
                    let name = body.split("fn ").nth(1).unwrap_or("").split('(').next();
                    silent.push(format!("{}: {}", file.display(), name.unwrap_or("")));
                }
            }
        }
    }
    assert!(
        silent.is_empty(),
        "tests that return early without saying SKIPPED: {silent:?}"
    );
}

/// Every `.rs` file under each member crate's `src/`, with its path from the root.
fn crate_sources() -> Vec<(String, String)> {
    member_crates()
        .iter()
        .flat_map(|c| rust_files(&root().join("crates").join(c).join("src")))
        .map(|f| {
            let name = f.strip_prefix(root()).unwrap().display().to_string();
            (name, std::fs::read_to_string(&f).unwrap())
        })
        .collect()
}

#[test]
fn line_and_column_are_computed_in_one_place() {
    // What a function turning offsets into lines (or lines into offsets) is called or does.
    const SIGNS: [&str; 6] = [
        "fn line_col(",
        "fn line_of(",
        "fn line_range(",
        "fn line_column(",
        "b'\\n').count()",
        "matches('\\n').count()",
    ];
    let mut found = Vec::new();
    for (name, text) in crate_sources() {
        if name == "crates/pvt-core/src/text.rs" {
            continue;
        }
        for sign in SIGNS {
            if text.contains(sign) {
                found.push(format!("{name}: {sign}"));
            }
        }
    }
    assert!(
        found.is_empty(),
        "line/column arithmetic outside pvt-core's text.rs (call pvt_core::text): {found:?}"
    );
}

/// The part of a source file that is not test code: nothing from its `#[cfg(test)]` on,
/// and nothing of a file that is a test module (`tests.rs`, `*_tests.rs`).
fn non_test_code<'a>(name: &str, text: &'a str) -> &'a str {
    if name.ends_with("/tests.rs") || name.ends_with("_tests.rs") {
        return "";
    }
    text.split("#[cfg(test)]").next().unwrap_or("")
}

#[test]
fn every_default_is_defined_once_in_pvt_core() {
    const HOME: &str = "crates/pvt-core/src/defaults.rs";
    let mut rapid = Vec::new();
    let mut elsewhere = Vec::new();
    for (name, text) in crate_sources() {
        let code = non_test_code(&name, &text);
        for (i, line) in code.lines().enumerate() {
            if line.contains("5000.0") || line.contains("5_000.0") {
                rapid.push(format!("{name}:{}", i + 1));
            }
            // A default given its own number (not a name from pvt_core::defaults).
            let t = line.trim_start();
            let defines = (t.starts_with("pub const DEFAULT") || t.starts_with("const DEFAULT"))
                && t.split('=').nth(1).is_some_and(|v| {
                    v.trim_start()
                        .starts_with(|c: char| c.is_ascii_digit() || c == '-')
                });
            if defines && name != HOME {
                elsewhere.push(format!("{name}:{}", i + 1));
            }
        }
    }
    assert!(
        rapid.len() == 1 && rapid[0].starts_with(HOME),
        "the 5000 mm/min rapid default is written once, in {HOME}: {rapid:?}"
    );
    assert!(
        elsewhere.is_empty(),
        "defaults defined outside {HOME}: {elsewhere:?}"
    );
}

/// The pvtc modules each pvtc module names: `use crate::a::…`, `use crate::{a, b…}` and
/// `crate::a::` paths in code (comments and test modules left out); the crate root is
/// not a module here.
fn pvtc_module_graph() -> std::collections::BTreeMap<String, Vec<String>> {
    pvtc_imports().0
}

/// pvtc's module graph (each module and the modules it names), and every place where a
/// module names something of the crate root (`crate::x` with `x` no module).
fn pvtc_imports() -> (std::collections::BTreeMap<String, Vec<String>>, Vec<String>) {
    let src = root().join("crates/pvtc/src");
    let modules: Vec<String> = rust_files(&src)
        .iter()
        .filter(|f| f.parent() == Some(src.as_path()))
        .filter_map(|f| f.file_stem().map(|s| s.to_string_lossy().into_owned()))
        .filter(|m| m != "lib" && m != "main")
        .collect();
    let mut graph = std::collections::BTreeMap::new();
    let mut from_root = Vec::new();
    for m in &modules {
        let text = std::fs::read_to_string(src.join(format!("{m}.rs"))).unwrap();
        let code: String = non_test_code(m, &text)
            .lines()
            .map(|l| l.split("//").next().unwrap_or(""))
            .collect::<Vec<_>>()
            .join("\n");
        let mut named = Vec::new();
        for (i, _) in code.match_indices("crate::") {
            let rest = &code[i + "crate::".len()..];
            let names: Vec<&str> = if let Some(group) = rest.strip_prefix('{') {
                // `use crate::{a, b::c}`: the first word of each item.
                let group = group.split('}').next().unwrap_or("");
                group.split(',').map(|item| item.trim()).collect()
            } else {
                vec![rest]
            };
            for name in names {
                let word: String = name
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                if !word.is_empty() && !modules.contains(&word) {
                    from_root.push(format!("{m}.rs: crate::{word}"));
                } else if word != *m && !named.contains(&word) {
                    named.push(word);
                }
            }
        }
        graph.insert(m.clone(), named);
    }
    (graph, from_root)
}

/// A cycle of `graph` as the modules along it, if there is one.
fn find_cycle(graph: &std::collections::BTreeMap<String, Vec<String>>) -> Option<Vec<String>> {
    fn visit(
        m: &str,
        graph: &std::collections::BTreeMap<String, Vec<String>>,
        path: &mut Vec<String>,
        done: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        if let Some(at) = path.iter().position(|p| p == m) {
            let mut cycle = path[at..].to_vec();
            cycle.push(m.to_string());
            return Some(cycle);
        }
        if done.iter().any(|d| d == m) {
            return None;
        }
        path.push(m.to_string());
        for next in graph.get(m).into_iter().flatten() {
            if let Some(c) = visit(next, graph, path, done) {
                return Some(c);
            }
        }
        path.pop();
        done.push(m.to_string());
        None
    }
    let mut done = Vec::new();
    graph
        .keys()
        .find_map(|m| visit(m, graph, &mut Vec::new(), &mut done))
}

#[test]
fn the_cycle_finder_finds_cycles() {
    let graph = |edges: &[(&str, &str)]| {
        let mut g = std::collections::BTreeMap::<String, Vec<String>>::new();
        for (a, b) in edges {
            g.entry(a.to_string()).or_default().push(b.to_string());
            g.entry(b.to_string()).or_default();
        }
        g
    };
    assert_eq!(
        find_cycle(&graph(&[("a", "b"), ("b", "c"), ("a", "c")])),
        None
    );
    assert_eq!(
        find_cycle(&graph(&[("a", "b"), ("b", "c"), ("c", "a")])),
        Some(vec!["a".into(), "b".into(), "c".into(), "a".into()])
    );
}

#[test]
fn pvtc_modules_import_each_other_without_a_cycle() {
    let graph = pvtc_module_graph();
    // The graph is read: the modules that carry the compile name their inputs.
    assert!(
        graph["pipeline"].contains(&"front".to_string()),
        "{graph:?}"
    );
    assert!(graph["front"].contains(&"options".to_string()), "{graph:?}");
    assert_eq!(find_cycle(&graph), None, "pvtc's module imports: {graph:?}");
}

#[test]
fn the_command_line_writes_standard_error_only_through_its_reporter() {
    const HOME: &str = "crates/pvtc/src/report.rs";
    let found: Vec<String> = crate_sources()
        .into_iter()
        .filter(|(name, _)| name.starts_with("crates/pvtc/src/") && name != HOME)
        .flat_map(|(name, text)| {
            non_test_code(&name, &text)
                .lines()
                .enumerate()
                .filter(|(_, line)| line.contains("eprintln!") || line.contains("eprint!"))
                .map(|(i, _)| format!("{name}:{}", i + 1))
                .collect::<Vec<_>>()
        })
        .collect();
    assert!(
        found.is_empty(),
        "standard error is written by {HOME} alone (one voice, one JSON mode): {found:?}"
    );
}

#[test]
fn no_pvtc_module_imports_from_the_crate_root() {
    let (graph, from_root) = pvtc_imports();
    assert!(
        graph.contains_key("input") && graph.contains_key("report"),
        "{graph:?}"
    );
    assert!(
        from_root.is_empty(),
        "lib.rs is the dispatcher alone; name the module that owns it instead: {from_root:?}"
    );
}

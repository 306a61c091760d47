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

/// The places in `code` that number lines by hand: enumerating a text's lines, a counter
/// named for lines (`line`, `number`, `lines`, …) stepped by one, or a loop counting
/// lines from 1. `pvt_core::text` does this once (`lines`, `numbered_lines`,
/// `LineCursor`), so every reader names the same line.
fn line_counting(code: &str) -> Vec<String> {
    const ENUMERATED: [&str; 3] = [
        ".lines().enumerate()",
        ".split('\\n').enumerate()",
        ".split(b'\\n').enumerate()",
    ];
    let mut found: Vec<String> = ENUMERATED
        .iter()
        .filter(|sign| code.contains(*sign))
        .map(|sign| sign.to_string())
        .collect();
    let named_for_lines = |name: &str| {
        let last = name.rsplit(['.', ' ', '(']).next().unwrap_or(name);
        last.contains("line") || last.contains("number")
    };
    for step in [" += 1", ".saturating_add(1)", ".wrapping_add(1)"] {
        let mut rest = code;
        while let Some(at) = rest.find(step) {
            let before = &rest[..at];
            let start = before
                .rfind(|c: char| !(c.is_alphanumeric() || c == '_' || c == '.'))
                .map_or(0, |i| i + 1);
            let name = &before[start..];
            if named_for_lines(name) {
                found.push(format!("{name}{step}"));
            }
            rest = &rest[at + step.len()..];
        }
    }
    for counter in ["line", "number", "line_number"] {
        if code.contains(&format!("for {counter} in 1..")) {
            found.push(format!("for {counter} in 1.."));
        }
    }
    found
}

#[test]
fn the_line_counting_finder_finds_line_counting() {
    // What excerpt.rs, pvt-csv and the G-code syntax check did before they used
    // pvt_core::text, and what pvt-gcode's line readers do.
    let counted = [
        "for (n, raw) in source.split('\\n').enumerate() {",
        "for (i, raw) in text.lines().enumerate() {",
        "let start = offset;\n            number += 1;",
        "for number in 1.. {",
        "        lines += 1;",
        "number: self.number.saturating_add(1),",
    ];
    for code in counted {
        assert!(!line_counting(code).is_empty(), "not found in {code:?}");
    }
    let not_counted = [
        "offset += read;",
        "for (k, a) in axes.iter().enumerate() {",
        "retries += 1;",
        "for line in pvt_core::text::lines(bytes) {",
        "let at = cursor.pass(read);",
    ];
    for code in not_counted {
        assert_eq!(line_counting(code), Vec::<String>::new(), "in {code:?}");
    }
}

#[test]
fn lines_are_numbered_in_one_place() {
    // The G-code front end's own line readers, the hot loop of every compile: its
    // streaming `Reader` (fed a line at a time) and `SourceLines` (a text held whole)
    // number each line as they take it.
    const READERS: [(&str, &str); 2] = [
        (
            "crates/pvt-gcode/src/lib.rs",
            "self.number.saturating_add(1)",
        ),
        (
            "crates/pvt-gcode/src/parser.rs",
            "self.number.saturating_add(1)",
        ),
    ];
    let mut found = Vec::new();
    for (name, text) in crate_sources() {
        if name == "crates/pvt-core/src/text.rs" {
            continue;
        }
        let code: String = non_test_code(&name, &text)
            .lines()
            .map(|l| l.split("//").next().unwrap_or(""))
            .collect::<Vec<_>>()
            .join("\n");
        for sign in line_counting(&code) {
            if !READERS.contains(&(name.as_str(), sign.as_str())) {
                found.push(format!("{name}: {sign}"));
            }
        }
    }
    assert!(
        found.is_empty(),
        "lines numbered outside pvt-core's text.rs (use pvt_core::text::lines, \
         numbered_lines or LineCursor): {found:?}"
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

type Graph = std::collections::BTreeMap<String, Vec<String>>;

/// A crate's modules by path (`crate` for the root, `plan::path::curve`), each with its
/// non-test code, comments left out. Test modules (`tests.rs`, `*_tests.rs`) and
/// `main.rs` are not modules of the library.
fn crate_modules(krate: &str) -> std::collections::BTreeMap<String, String> {
    let src = root().join("crates").join(krate).join("src");
    let mut modules = std::collections::BTreeMap::new();
    for file in rust_files(&src) {
        let relative = file.strip_prefix(&src).unwrap().display().to_string();
        let name = relative.trim_end_matches(".rs");
        let name = name.strip_suffix("/mod").unwrap_or(name);
        if name == "main" || name.ends_with("tests") {
            continue;
        }
        let path = match name {
            "lib" => "crate".to_string(),
            _ => name.replace('/', "::"),
        };
        let text = std::fs::read_to_string(&file).unwrap();
        let code: Vec<&str> = non_test_code(&relative, &text)
            .lines()
            .map(|l| l.split("//").next().unwrap_or(""))
            .collect();
        modules.insert(path, code.join("\n"));
    }
    modules
}

/// The parent of module `m` (`crate` for a top-level module).
fn parent_of(m: &str) -> String {
    match m.rsplit_once("::") {
        Some((parent, _)) => parent.to_string(),
        None if m == "crate" => "crate".to_string(),
        None => "crate".to_string(),
    }
}

/// `child` of module `m` as a module path.
fn child_of(m: &str, child: &str) -> String {
    match m {
        "crate" => child.to_string(),
        _ => format!("{m}::{child}"),
    }
}

/// The `use` statements of `code` (each from `use` to its `;`), with whether each is a
/// re-export (`pub use`, `pub(crate) use`).
fn use_statements(code: &str) -> Vec<(bool, String)> {
    let mut out = Vec::new();
    for (at, _) in code.match_indices("use ") {
        let before = &code[..at];
        let line_start = before.rfind('\n').map_or(0, |n| n + 1);
        let lead = before[line_start..].trim();
        if !(lead.is_empty() || lead.starts_with("pub")) {
            continue;
        }
        let Some(end) = code[at..].find(';') else {
            continue;
        };
        let body: String = code[at + 4..at + end].split_whitespace().collect();
        out.push((lead.starts_with("pub"), body));
    }
    out
}

/// The items of a use tree (`a::{b, c::{d, e as f}}`): each full path and the name it
/// is known by.
fn use_items(tree: &str) -> Vec<(String, String)> {
    fn expand(prefix: &str, tree: &str, out: &mut Vec<(String, String)>) {
        if let Some(open) = tree.find('{') {
            let head = &tree[..open];
            let inner = &tree[open + 1..tree.rfind('}').unwrap_or(tree.len())];
            let mut depth = 0;
            let mut start = 0;
            let mut parts = Vec::new();
            for (i, c) in inner.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' => depth -= 1,
                    ',' if depth == 0 => {
                        parts.push(&inner[start..i]);
                        start = i + 1;
                    }
                    _ => {}
                }
            }
            parts.push(&inner[start..]);
            for part in parts.into_iter().filter(|p| !p.is_empty()) {
                expand(&format!("{prefix}{head}"), part, out);
            }
            return;
        }
        let (path, alias) = match tree.split_once("as") {
            Some((p, a)) if tree.contains("::") || !a.is_empty() => (p, Some(a)),
            _ => (tree, None),
        };
        let full = format!("{prefix}{path}");
        let full = full.trim_end_matches("::self").to_string();
        let name = alias
            .map(str::to_string)
            .unwrap_or_else(|| full.rsplit("::").next().unwrap_or("").to_string());
        out.push((full, name));
    }
    let mut out = Vec::new();
    expand("", tree, &mut out);
    out
}

/// The module a path written in module `m` names: the longest run of its segments that
/// is a module, then a name that module re-exports followed to where it is defined
/// (`reexports`). `None` for another crate's path.
fn resolve(
    m: &str,
    path: &str,
    modules: &std::collections::BTreeMap<String, String>,
    reexports: &std::collections::BTreeMap<(String, String), String>,
    depth: usize,
) -> Option<String> {
    let mut segments = path.split("::").filter(|s| !s.is_empty()).peekable();
    let mut at = match *segments.peek()? {
        "crate" => {
            segments.next();
            "crate".to_string()
        }
        "super" => {
            let mut at = m.to_string();
            while segments.peek() == Some(&"super") {
                segments.next();
                at = parent_of(&at);
            }
            at
        }
        "self" => {
            segments.next();
            m.to_string()
        }
        first if modules.contains_key(&child_of(m, first)) => m.to_string(),
        _ => return None,
    };
    for segment in segments {
        let child = child_of(&at, segment);
        if modules.contains_key(&child) {
            at = child;
            continue;
        }
        if let Some(target) = reexports.get(&(at.clone(), segment.to_string())) {
            if depth < 8 {
                if let Some(found) = resolve(&at, target, modules, reexports, depth + 1) {
                    return Some(found);
                }
            }
        }
        break;
    }
    Some(at)
}

/// The module graph of a member crate: each module (the root `crate` included) and the
/// modules its code and imports name, with names re-exported (by the root or a façade)
/// followed to the module that defines them. A module naming its own descendants (the
/// modules it declares, a façade re-exporting them) is no edge.
fn module_graph(krate: &str) -> Graph {
    let modules = crate_modules(krate);
    let mut reexports = std::collections::BTreeMap::new();
    for (m, code) in &modules {
        for (public, tree) in use_statements(code) {
            if public {
                for (full, name) in use_items(&tree) {
                    reexports.insert((m.clone(), name), full);
                }
            }
        }
    }
    let mut graph = Graph::new();
    for (m, code) in &modules {
        let mut paths: Vec<String> = Vec::new();
        for (_, tree) in use_statements(code) {
            paths.extend(use_items(&tree).into_iter().map(|(full, _)| full));
        }
        let statements: Vec<String> = use_statements(code).into_iter().map(|u| u.1).collect();
        for prefix in ["crate::", "super::"] {
            for (at, _) in code.match_indices(prefix) {
                let path: String = code[at..]
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_' || *c == ':')
                    .collect();
                if !statements.iter().any(|s| s.contains(&path)) {
                    paths.push(path);
                }
            }
        }
        let mut named: Vec<String> = Vec::new();
        for path in paths {
            let Some(target) = resolve(m, &path, &modules, &reexports, 0) else {
                continue;
            };
            let descendant = m == "crate" || target.starts_with(&format!("{m}::"));
            if target != *m && !descendant && !named.contains(&target) {
                named.push(target);
            }
        }
        graph.insert(m.clone(), named);
    }
    graph
}

/// pvtc's module graph and every place where a module names the crate root itself.
fn pvtc_imports() -> (Graph, Vec<String>) {
    let graph = module_graph("pvtc");
    let from_root = graph
        .iter()
        .filter(|(_, named)| named.iter().any(|n| n == "crate"))
        .map(|(m, _)| format!("{m}: names something defined in lib.rs"))
        .collect();
    (graph, from_root)
}

/// A cycle of `graph` as the modules along it, if there is one.
fn find_cycle(graph: &Graph) -> Option<Vec<String>> {
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
    let graph = module_graph("pvtc");
    // The graph is read: the route names the front ends and the settings, the settings
    // the options, and a command's module in `commands/` the route.
    assert!(graph["route"].contains(&"front".to_string()), "{graph:?}");
    assert!(
        graph["route"].contains(&"settings".to_string()),
        "{graph:?}"
    );
    assert!(
        graph["settings"].contains(&"options".to_string()),
        "{graph:?}"
    );
    assert!(
        graph["commands::batch"].contains(&"route".to_string()),
        "{graph:?}"
    );
    assert_eq!(find_cycle(&graph), None, "pvtc's module imports: {graph:?}");
}

#[test]
fn the_module_graph_follows_re_exports() {
    // plan/driver.rs imports `super::{plan_contour, …}`: plan/mod.rs re-exports it from
    // plan/contour.rs, where the edge goes. The stage (stream.rs) sits above the
    // planners' dispatch, with no arrow back.
    let graph = module_graph("pvt-core");
    let driver = &graph["plan::driver"];
    assert!(driver.contains(&"plan::contour".to_string()), "{driver:?}");
    assert!(!driver.contains(&"stream".to_string()), "{driver:?}");
    assert!(graph["stream"].contains(&"plan::driver".to_string()));
    // pvtc's root re-exports its option types; the root's own uses are no edges back.
    let pvtc = module_graph("pvtc");
    assert!(pvtc["crate"].is_empty(), "{:?}", pvtc["crate"]);
}

/// No import edge of pvt-core or pvt-gcode closes a cycle, crate roots and re-exports
/// counted.
#[test]
fn pvt_core_and_pvt_gcode_modules_import_each_other_without_a_cycle() {
    // The graph sees the path planner's edges, which point one way: pieces.rs builds
    // pieces at the knots, knots.rs only reads them, and both take `Piece` from piece.rs.
    let core = module_graph("pvt-core");
    let pieces = &core["plan::path::pieces"];
    assert!(
        pieces.contains(&"plan::path::knots".to_string()),
        "{pieces:?}"
    );
    assert!(
        pieces.contains(&"plan::path::piece".to_string()),
        "{pieces:?}"
    );
    let knots = &core["plan::path::knots"];
    assert!(
        knots.contains(&"plan::path::piece".to_string()),
        "{knots:?}"
    );
    let mut cycles = Vec::new();
    for krate in ["pvt-core", "pvt-gcode"] {
        let mut graph = module_graph(krate);
        // Every cycle, each found one cut at its last edge to find the next.
        while let Some(cycle) = find_cycle(&graph) {
            let (from, to) = (&cycle[cycle.len() - 2], &cycle[cycle.len() - 1]);
            graph.get_mut(from).unwrap().retain(|n| n != to);
            cycles.push(format!("{krate}: {}", cycle.join(" -> ")));
        }
    }
    assert!(cycles.is_empty(), "import cycles: {cycles:#?}");
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

#[test]
fn pvtc_applies_defaults_in_settings_alone() {
    // A default named by pvtc: pvt-core's `defaults` or a front end's `DEFAULT_…`.
    const HOME: &str = "crates/pvtc/src/settings.rs";
    let found: Vec<String> = crate_sources()
        .into_iter()
        .filter(|(name, _)| name.starts_with("crates/pvtc/src/") && name != HOME)
        .flat_map(|(name, text)| {
            non_test_code(&name, &text)
                .lines()
                .enumerate()
                .filter(|(_, l)| {
                    let code = l.split("//").next().unwrap_or("");
                    code.contains("defaults::") || code.contains("DEFAULT_")
                })
                .map(|(i, _)| format!("{name}:{}", i + 1))
                .collect::<Vec<_>>()
        })
        .collect();
    assert!(
        found.is_empty(),
        "pvtc applies a default in {HOME} alone (its one builder of CompileOptions): {found:?}"
    );
}

/// The layer of a workspace crate: pvt-core at the bottom, the front and back ends on
/// it, the command line on them, the Python package on top.
fn crate_layer(name: &str) -> Option<usize> {
    match name {
        "pvt-core" => Some(0),
        "pvt-gcode" | "pvt-dxf" | "pvt-csv" | "pvt-emit" => Some(1),
        "pvtc" => Some(2),
        // The Python package, on the command line's library.
        "pvtc-py" => Some(3),
        _ => None,
    }
}

#[test]
fn crates_depend_only_on_lower_layers() {
    let mut wrong = Vec::new();
    for krate in member_crates() {
        let manifest =
            std::fs::read_to_string(root().join("crates").join(&krate).join("Cargo.toml")).unwrap();
        let layer = crate_layer(&krate).unwrap_or_else(|| panic!("{krate} has no layer"));
        let mut section = "";
        for line in manifest.lines().map(str::trim) {
            if line.starts_with('[') {
                section = line;
                continue;
            }
            let dependency = line.split(['.', '=', ' ']).next().unwrap_or("");
            let Some(below) = crate_layer(dependency) else {
                continue;
            };
            // Tests and benches may use any crate below the top; libraries only lower ones.
            let normal = section == "[dependencies]";
            if (normal && below >= layer) || (!normal && below > layer) {
                wrong.push(format!("{krate} {section} -> {dependency}"));
            }
        }
    }
    assert!(
        wrong.is_empty(),
        "a crate depends on its own layer or one above it: {wrong:?}"
    );
}

#[test]
fn pvtc_compiles_by_one_route() {
    // What runs the phases: the planning stage, the planners' whole-program entries, a
    // back end's writer, the whole-program emit and the long-piece cut.
    const PHASES: [&str; 9] = [
        "PlanStage",
        "plan_toolpath_report",
        "plan_timed",
        "emit_to_vec",
        "pvt_emit::emit(",
        "Checked::new",
        ".writer(",
        "PieceSplitter",
        "split_long_pieces",
    ];
    const HOME: &str = "crates/pvtc/src/route.rs";
    let mut found = Vec::new();
    for (name, text) in crate_sources() {
        if !name.starts_with("crates/pvtc/src/") || name == HOME {
            continue;
        }
        for (i, line) in non_test_code(&name, &text).lines().enumerate() {
            let code = line.split("//").next().unwrap_or("");
            if let Some(phase) = PHASES.iter().find(|p| code.contains(*p)) {
                found.push(format!("{name}:{}: {phase}", i + 1));
            }
        }
    }
    assert!(
        found.is_empty(),
        "pvtc runs the phases in {HOME} alone (one compile route): {found:?}"
    );
}

#[test]
fn pvt_core_plan_module_is_a_facade() {
    // plan/mod.rs holds `mod` lines and re-exports, nothing that computes or defines.
    let text = std::fs::read_to_string(root().join("crates/pvt-core/src/plan/mod.rs")).unwrap();
    let code = non_test_code("plan/mod.rs", &text);
    let mut statement = String::new();
    let mut other = Vec::new();
    for line in code.lines().map(str::trim) {
        if line.is_empty() || line.starts_with("//") || line.starts_with("#[") {
            continue;
        }
        statement.push_str(line);
        if !line.ends_with(';') {
            continue;
        }
        let allowed = ["mod ", "pub mod ", "pub use ", "pub(crate) use ", "use "];
        if !allowed.iter().any(|a| statement.starts_with(a)) {
            other.push(statement.clone());
        }
        statement.clear();
    }
    assert!(
        other.is_empty() && statement.is_empty(),
        "plan/mod.rs is a façade: {other:?} {statement:?}"
    );
}

/// Places outside pvtc's settings.rs that resolve a default of their own crate's option
/// type, each with why (file, the default named).
const OWN_DEFAULTS: [(&str, &str); 4] = [
    // PlanOptions::path_options: a plan without a servo period (no machine file).
    ("crates/pvt-core/src/plan/options.rs", "SERVO_PERIOD_S"),
    // check_program: a CheckOptions with a servo period that is no period.
    ("crates/pvt-core/src/check/mod.rs", "SERVO_PERIOD_S"),
    // read_drawing: the join tolerance in the drawing's units, known once it is read.
    ("crates/pvt-dxf/src/lib.rs", "DEFAULT_JOIN_MM"),
    // DxfOptions::with_feed, the type's defaults (no Default: a drawing needs a feed).
    ("crates/pvt-dxf/src/lib.rs", "DEFAULT_MAX_POINTS"),
];

#[test]
fn libraries_apply_defaults_in_their_own_default_or_one_resolution() {
    // Outside pvt-core's defaults.rs (and pvtc, held to settings.rs above), a default is
    // named only by a type's own `impl Default`, a re-export or alias of the constant,
    // a call of a shared resolution (`defaults::rapid_per_minute`, `defaults::tolerance`,
    // the arc tolerances of a program's units)
    // or one of OWN_DEFAULTS.
    let mut found = Vec::new();
    for (name, text) in crate_sources() {
        if name.starts_with("crates/pvtc/") || name == "crates/pvt-core/src/defaults.rs" {
            continue;
        }
        let mut in_default_impl = false;
        for (i, line) in non_test_code(&name, &text).lines().enumerate() {
            let code = line.split("//").next().unwrap_or("");
            if code.starts_with("impl") {
                in_default_impl = code.starts_with("impl Default for");
            } else if code.starts_with('}') {
                in_default_impl = false;
            }
            let names_default = code.contains("defaults::") || code.contains("DEFAULT_");
            let t = code.trim_start();
            let allowed = in_default_impl
                || t.starts_with("pub use ")
                || t.starts_with("pub const ")
                || code.contains("defaults::rapid_per_minute(")
                || code.contains("defaults::tolerance(")
                || code.contains("defaults::arc_abs_tolerance(")
                || code.contains("defaults::arc_radius_tolerance(")
                || OWN_DEFAULTS
                    .iter()
                    .any(|(file, constant)| name == *file && code.contains(constant));
            if names_default && !allowed {
                found.push(format!("{name}:{}: {}", i + 1, code.trim()));
            }
        }
    }
    assert!(
        found.is_empty(),
        "a default applied outside a Default, a shared resolution or OWN_DEFAULTS: {found:#?}"
    );
}

#[test]
fn the_stage_and_the_check_each_have_one_module_name() {
    // pvt-core's planning stage is the one `stream` module and its check the one `check`:
    // pvt-emit's piece writer is `writer.rs`, pvtc's compile path `route.rs`.
    for name in ["stream", "check"] {
        let homes: Vec<String> = crate_sources()
            .into_iter()
            .map(|(path, _)| path)
            .filter(|path| {
                let path = Path::new(path);
                let stem = path.file_stem().and_then(|s| s.to_str());
                let dir = path.parent().and_then(|d| d.file_name()?.to_str());
                stem == Some(name) || (stem == Some("mod") && dir == Some(name))
            })
            .collect();
        assert_eq!(homes.len(), 1, "modules named `{name}`: {homes:?}");
    }
}

//! The README against the program: its commands run, its shown output is the real output,
//! its usage synopsis and option table agree with `--help`, its samples table lists every
//! sample, and its minimum Rust version is the workspace's.
//!
//! Conventions (stated in the README's "Development" section): every line of a `sh` code
//! block that starts with `pvtc` is run with the built binary in a scratch folder that
//! sees `samples/`; when the next code block (only blank lines between) is `text`, `c` or
//! `json`, it is the last command's standard output, where a line `...` stands for lines
//! left out.

mod common;

use common::root;

use std::path::{Path, PathBuf};
use std::process::Command;

fn readme() -> String {
    std::fs::read_to_string(root().join("README.md")).unwrap()
}

/// A fenced code block: its language, its lines, and the README lines it spans (1-based,
/// fences included).
struct Block {
    lang: String,
    lines: Vec<String>,
    first: usize,
    last: usize,
}

fn blocks(text: &str) -> Vec<Block> {
    let mut out = Vec::new();
    let mut open: Option<Block> = None;
    for (i, line) in text.lines().enumerate() {
        match (&mut open, line.strip_prefix("```")) {
            (None, Some(lang)) => {
                open = Some(Block {
                    lang: lang.trim().to_string(),
                    lines: Vec::new(),
                    first: i + 1,
                    last: i + 1,
                })
            }
            (Some(block), Some(_)) => {
                block.last = i + 1;
                out.push(open.take().unwrap());
            }
            (Some(block), None) => block.lines.push(line.to_string()),
            (None, None) => {}
        }
    }
    assert!(open.is_none(), "README.md: a code block is not closed");
    out
}

/// Whether `shown` (with `...` lines for lines left out) is `actual`.
fn shown_matches(shown: &[String], actual: &str) -> Result<(), String> {
    let actual: Vec<&str> = actual.lines().collect();
    let open_start = shown.first().is_some_and(|l| l == "...");
    let open_end = shown.last().is_some_and(|l| l == "...");
    let chunks: Vec<&[String]> = shown
        .split(|l| l == "...")
        .filter(|c| !c.is_empty())
        .collect();
    let mut pos = 0;
    for (n, chunk) in chunks.iter().enumerate() {
        let fits = |at: usize| {
            at + chunk.len() <= actual.len() && chunk.iter().zip(&actual[at..]).all(|(s, a)| s == a)
        };
        let at = if n == 0 && !open_start {
            fits(0).then_some(0)
        } else {
            (pos..=actual.len()).find(|&at| fits(at))
        };
        let Some(at) = at else {
            return Err(format!(
                "the shown lines starting {:?} are not in the output:\n{}",
                chunk[0],
                actual.join("\n")
            ));
        };
        pos = at + chunk.len();
    }
    if !open_end && pos != actual.len() {
        return Err(format!(
            "the output goes on after the shown lines: {:?}",
            &actual[pos..]
        ));
    }
    Ok(())
}

/// A scratch folder holding a link to `samples/`, removed when dropped.
struct Scratch(PathBuf);

impl Scratch {
    fn new() -> Scratch {
        let dir = std::env::temp_dir().join(format!("pvtc-readme-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        #[cfg(unix)]
        std::os::unix::fs::symlink(root().join("samples"), dir.join("samples")).unwrap();
        Scratch(dir)
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

#[cfg(unix)]
#[test]
fn every_readme_command_runs_and_shows_its_real_output() {
    let text = readme();
    let blocks = blocks(&text);
    let lines: Vec<&str> = text.lines().collect();
    let scratch = Scratch::new();
    let bin = Path::new(env!("CARGO_BIN_EXE_pvtc")).parent().unwrap();
    let path = format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let mut ran = 0;
    let mut compared = 0;
    for (n, block) in blocks.iter().enumerate() {
        if block.lang != "sh" {
            continue;
        }
        let mut last_stdout = None;
        for command in block.lines.iter().filter(|l| l.starts_with("pvtc ")) {
            let o = Command::new("sh")
                .arg("-c")
                .arg(command)
                .current_dir(&scratch.0)
                .env("PATH", &path)
                .env("NO_COLOR", "1")
                .stdin(std::process::Stdio::null())
                .output()
                .unwrap();
            assert!(
                o.status.success(),
                "README.md:{}: `{command}` failed: {}",
                block.first,
                String::from_utf8_lossy(&o.stderr)
            );
            ran += 1;
            last_stdout = Some(String::from_utf8(o.stdout).unwrap());
        }
        let Some(next) = blocks.get(n + 1) else {
            continue;
        };
        let adjacent = lines[block.last..next.first - 1]
            .iter()
            .all(|l| l.trim().is_empty());
        if adjacent && ["text", "c", "json"].contains(&next.lang.as_str()) {
            let stdout = last_stdout.expect("a shown output follows a pvtc command");
            if let Err(e) = shown_matches(&next.lines, &stdout) {
                panic!("README.md:{}: {e}", next.first);
            }
            compared += 1;
        }
    }
    assert!(ran >= 8 && compared >= 4, "ran {ran}, compared {compared}");
    // The plots the README shows are what its plot commands draw now.
    let mut plots = 0;
    for entry in std::fs::read_dir(root().join("docs/plots")).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_str().unwrap().to_string();
        let drawn = std::fs::read(scratch.0.join(&name))
            .unwrap_or_else(|_| panic!("no README command draws docs/plots/{name}"));
        assert!(
            drawn == std::fs::read(&path).unwrap(),
            "docs/plots/{name} is not what its README command draws now: redraw it"
        );
        plots += 1;
    }
    assert!(plots >= 4);
}

#[test]
fn the_shown_output_rule_catches_differences() {
    let lines = |s: &str| s.lines().map(str::to_string).collect::<Vec<_>>();
    assert!(shown_matches(&lines("a\nb"), "a\nb\n").is_ok());
    assert!(shown_matches(&lines("a\n..."), "a\nb\n").is_ok());
    assert!(shown_matches(&lines("...\nb\n...\nd"), "a\nb\nc\nd\n").is_ok());
    assert!(shown_matches(&lines("a"), "a\nb\n").is_err());
    assert!(shown_matches(&lines("b\n..."), "a\nb\n").is_err());
    assert!(shown_matches(&lines("...\nc\n...\nb\n..."), "a\nb\nc\n").is_err());
    assert!(shown_matches(&lines("a\nx"), "a\nb\n").is_err());
}

#[test]
fn the_usage_synopsis_and_the_help_agree() {
    let text = readme();
    let usage = text.split("## Usage").nth(1).expect("a Usage section");
    let synopsis = &blocks(usage)[0];
    assert_eq!(synopsis.lang, "text");
    let all = common::long_options();
    let mut current: Option<&(String, Vec<String>)> = None;
    let mut named = std::collections::BTreeSet::new();
    for line in &synopsis.lines {
        if let Some(rest) = line.strip_prefix("pvtc ") {
            let name = rest.split_whitespace().next().unwrap();
            current = Some(
                all.iter()
                    .find(|(n, _)| n == name)
                    .unwrap_or_else(|| panic!("README synopsis: no subcommand {name}")),
            );
            named.insert(name.to_string());
        }
        let (name, longs) = current.expect("the synopsis starts with `pvtc SUBCOMMAND`");
        for word in line.split(|c: char| !(c.is_ascii_alphanumeric() || c == '-')) {
            if word.starts_with("--") {
                assert!(
                    longs.iter().any(|l| l == word),
                    "README synopsis: `pvtc {name}` has no option {word}"
                );
            }
        }
    }
    for (name, longs) in &all {
        assert!(named.contains(name), "README synopsis lacks `pvtc {name}`");
        for long in longs {
            assert!(
                text.contains(&format!("`{long}")) || text.contains(&format!("{long} ")),
                "README.md does not mention `pvtc {name} {long}`"
            );
        }
    }
}

#[test]
fn the_samples_table_lists_every_sample() {
    let text = readme();
    let section = text
        .split("\n## Samples\n")
        .nth(1)
        .expect("a Samples section");
    let section = section.split("\n## ").next().unwrap();
    let lines: Vec<&str> = section.lines().collect();
    let start = lines.iter().position(|l| l.starts_with('|')).unwrap();
    let len = lines[start..]
        .iter()
        .take_while(|l| l.starts_with('|'))
        .count();
    let table = &lines[start..start + len];
    // A blank line inside the table would end it: no row may follow it.
    assert!(
        !lines[start + len..].iter().any(|l| l.starts_with('|')),
        "the Samples table is broken by a line that is not a row"
    );
    let rows: Vec<&str> = table
        .iter()
        .filter_map(|l| l.strip_prefix("| `")?.split('`').next())
        .collect();
    let mut files = Vec::new();
    let mut stack = vec![root().join("samples")];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else {
                let rel = path.strip_prefix(root()).unwrap();
                files.push(rel.to_string_lossy().replace('\\', "/"));
            }
        }
    }
    files.sort();
    assert!(files.len() >= 28, "{files:?}");
    for file in &files {
        assert!(
            rows.contains(&file.as_str()),
            "no row for {file} in Samples"
        );
    }
    for row in &rows {
        assert!(
            files.iter().any(|f| f == row),
            "Samples row {row} names no file"
        );
    }
}

#[test]
fn the_stated_minimum_rust_version_is_the_workspaces() {
    let manifest = std::fs::read_to_string(root().join("Cargo.toml")).unwrap();
    let version = manifest
        .lines()
        .find_map(|l| l.strip_prefix("rust-version = \""))
        .and_then(|v| v.strip_suffix('"'))
        .expect("workspace rust-version");
    assert!(
        readme().contains(&format!("**Minimum Rust version: {version}**")),
        "README must state the minimum Rust version {version}"
    );
}

//! Every bad input of tests/bad/ run through the command line as users run it: as a file
//! and on standard input, with `--diagnostics json`. Both routes must exit 1, write no
//! output, and report the code and line tests/bad/EXPECTED gives, the same way.

mod common;
use common::{pvtc_bytes, root};

/// (exit code, stdout length, every (code, line) on stderr) of one run.
fn run(args: &[&str], stdin: &[u8]) -> (Option<i32>, usize, Vec<(String, u64)>) {
    let out = pvtc_bytes(args, stdin);
    let diagnostics = String::from_utf8_lossy(&out.stderr)
        .lines()
        .filter_map(|l| serde_json::from_str::<serde_json::Value>(l).ok())
        .filter(|v| v["severity"] == "error")
        .map(|v| {
            let code = v["code"].as_str().unwrap_or_default().to_string();
            (code, v["line"].as_u64().unwrap_or(0))
        })
        .collect();
    (out.status.code(), out.stdout.len(), diagnostics)
}

#[test]
fn every_bad_input_fails_alike_from_a_file_and_from_standard_input() {
    let expected = std::fs::read_to_string(root().join("tests/bad/EXPECTED")).unwrap();
    let mut checked = 0;
    for entry in expected.lines() {
        let entry = entry.split('#').next().unwrap().trim();
        let fields: Vec<&str> = entry.split_whitespace().collect();
        let [name, code, line] = fields[..] else {
            continue;
        };
        let line: u64 = line.parse().unwrap();
        let path = format!("tests/bad/{name}");
        let kind = match name.rsplit_once('.').map(|p| p.1) {
            Some("dxf") => "dxf",
            Some("csv") => "csv",
            _ => "gcode",
        };
        let mut common = vec!["--diagnostics", "json", "--input-format", kind];
        if kind == "dxf" {
            common.extend(["--feed", "1200"]);
        }
        let bytes = std::fs::read(root().join(&path)).unwrap();
        let from_file = run(&[&["compile", path.as_str()][..], &common].concat(), b"");
        let from_stdin = run(&[&["compile", "-"][..], &common].concat(), &bytes);
        for (route, (status, written, found)) in [("file", &from_file), ("stdin", &from_stdin)] {
            assert_eq!(*status, Some(1), "{name} ({route}): {found:?}");
            assert_eq!(*written, 0, "{name} ({route}) wrote output");
            assert!(
                found
                    .iter()
                    .any(|(c, l)| c == code && (line == 0 || *l == line)),
                "{name} ({route}): expected {code} at line {line}, got {found:?}"
            );
        }
        assert_eq!(from_file.2, from_stdin.2, "{name}: the routes disagree");
        checked += 1;
    }
    assert!(checked >= 40, "only {checked} bad inputs");
}

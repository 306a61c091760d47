//! The catalogue of bad inputs in tests/bad/: every file there must fail with the error
//! code and line that tests/bad/EXPECTED gives it, through its front end and through the
//! whole pipeline (which must then produce no output), and none may panic.
//!
//! EXPECTED has one line per file: `FILE CODE LINE` (line 0: the front end cannot know
//! the line, e.g. an empty drawing); `#` starts a comment.

use pvt_core::Units;
use pvtc::{compile, CompileOptions, Failure, Source};
use pvtc_tests::root;
use std::collections::BTreeMap;

fn manifest() -> BTreeMap<String, (String, u32)> {
    let text = std::fs::read_to_string(root().join("tests/bad/EXPECTED")).unwrap();
    let mut out = BTreeMap::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap().trim();
        if line.is_empty() {
            continue;
        }
        let fields: Vec<&str> = line.split_whitespace().collect();
        let [file, code, at] = fields[..] else {
            panic!("EXPECTED:{}: need FILE CODE LINE", i + 1)
        };
        let previous = out.insert(file.to_string(), (code.to_string(), at.parse().unwrap()));
        assert!(previous.is_none(), "{file} listed twice");
    }
    out
}

/// Every (code, line) the file's own front end reports.
fn front_end_errors(name: &str, bytes: &[u8]) -> Vec<(String, u32)> {
    let text = String::from_utf8_lossy(bytes);
    if name.ends_with(".dxf") {
        let errors =
            pvt_dxf::read_drawing(bytes, &pvt_dxf::DxfOptions::with_feed(1200.0)).expect_err(name);
        errors
            .errors
            .iter()
            .map(|e| (e.code_str(), e.span().line))
            .collect()
    } else if name.ends_with(".csv") {
        let errors = pvt_csv::read_points(&text, Units::Millimetre).expect_err(name);
        errors
            .diagnostics
            .iter()
            .map(|d| (d.code().to_string(), d.line))
            .collect()
    } else {
        let errors = pvt_gcode::compile(&text, &Default::default()).expect_err(name);
        errors
            .diagnostics
            .iter()
            .map(|d| {
                (
                    d.code().to_string(),
                    pvt_gcode::line_col(&text, d.span().start).0 as u32,
                )
            })
            .collect()
    }
}

#[test]
fn every_bad_input_fails_with_its_code_and_line() {
    let expected = manifest();
    let mut files: Vec<String> = std::fs::read_dir(root().join("tests/bad"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n != "EXPECTED")
        .collect();
    files.sort();
    assert!(
        files.len() >= 40,
        "the catalogue holds at least 40 bad inputs, has {}",
        files.len()
    );
    for name in &files {
        let (code, line) = expected
            .get(name)
            .unwrap_or_else(|| panic!("{name} is not in tests/bad/EXPECTED"));
        let bytes = std::fs::read(root().join("tests/bad").join(name)).unwrap();
        let found = front_end_errors(name, &bytes);
        assert!(
            found.iter().any(|(c, l)| c == code && l == line),
            "{name}: expected {code} at line {line}, got {found:?}"
        );
        let mut options = CompileOptions::new(pvt_emit::Format::Json);
        options.input = pvtc::InputKind::from_name(name);
        options.feed = name.ends_with(".dxf").then_some(1200.0);
        match compile(
            &Source {
                name: name.clone(),
                bytes,
            },
            &options,
        ) {
            Err(Failure::Input(reports)) => {
                let codes: Vec<String> = reports
                    .iter()
                    .filter_map(|r| r.code().map(|c| c.to_string()))
                    .collect();
                assert!(codes.contains(code), "{name}: pipeline reported {codes:?}");
            }
            other => panic!("{name}: the pipeline must fail with input errors, got {other:?}"),
        }
    }
    for name in expected.keys() {
        assert!(
            files.contains(name),
            "EXPECTED lists {name}, which is not in tests/bad"
        );
    }
}

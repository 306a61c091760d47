//! `pvtc diff` through the command line: the same program in two formats is equal, every
//! format's reader reads the motion its writer wrote, and each kind of difference
//! (position, a time stretch, a dropped piece, an event out of order) is found where it
//! is, with the exit statuses 0, 1 and 2. The programs B are made from A here by editing
//! its JSON, so the differences are known by construction.

mod common;

use common::{command, root};
use serde_json::Value;
use std::path::{Path, PathBuf};

/// Runs `pvtc ARGS` and returns its exit status, standard output and standard error.
fn run(args: &[&str]) -> (i32, String, String) {
    let out = command(args).output().unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Compiles `sample` with `args` into `dir/NAME`, which is returned.
fn compile(dir: &Path, sample: &str, name: &str, args: &[&str]) -> PathBuf {
    let out = dir.join(name);
    let mut all = vec!["compile", sample, "-o", out.to_str().unwrap()];
    all.extend_from_slice(args);
    let (code, _, err) = run(&all);
    assert_eq!(code, 0, "{all:?}: {err}");
    out
}

/// `pvtc diff A B ARGS --json`: the exit status and the report.
fn diff(a: &Path, b: &Path, args: &[&str]) -> (i32, Value, String) {
    let mut all = vec!["diff", a.to_str().unwrap(), b.to_str().unwrap(), "--json"];
    all.extend_from_slice(args);
    let (code, out, err) = run(&all);
    let report = serde_json::from_str(&out).unwrap_or_else(|e| panic!("{e}: {out}\n{err}"));
    (code, report, err)
}

fn codes(report: &Value) -> Vec<String> {
    report["differences"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| d["code"].as_str().unwrap().to_string())
        .collect()
}

/// A JSON program edited by `edit`, written beside it as `name`.
fn edited(json: &Path, name: &str, edit: impl FnOnce(&mut Value)) -> PathBuf {
    let mut doc: Value = serde_json::from_str(&std::fs::read_to_string(json).unwrap()).unwrap();
    edit(&mut doc);
    let out = json.with_file_name(name);
    std::fs::write(&out, serde_json::to_string_pretty(&doc).unwrap()).unwrap();
    out
}

const POCKET: &str = "samples/gcode/linuxcnc_params_pocket.ngc";

#[test]
fn the_same_program_in_two_formats_is_equal() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let grid = ["--quantize", "1ms"];
    for (x, y) in [("pmac", "json"), ("xps", "csv"), ("powerpmac", "movepvt")] {
        let a = compile(
            d,
            POCKET,
            &format!("a.{}", ext(x)),
            &[&["--format", x][..], &grid].concat(),
        );
        let b = compile(
            d,
            POCKET,
            &format!("b.{}", ext(y)),
            &[&["--format", y][..], &grid].concat(),
        );
        let (code, report, err) = diff(&a, &b, &[]);
        assert_eq!(code, 0, "{x} and {y}: {report}\n{err}");
        assert_eq!(report["equal"], true);
        assert!(
            report["aligned"]["value"].as_f64().unwrap() < 1e-6,
            "{report}"
        );
    }
}

/// The extension of a format's output, by which `diff` reads it.
fn ext(format: &str) -> &str {
    match format {
        "movepvt" => "c",
        "xps" => "trj",
        "galil" => "dmc",
        "powerpmac" => "pmc",
        other => other,
    }
}

#[test]
fn every_formats_reader_reads_the_motion_its_writer_wrote() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scale = [
        "--counts-per-unit",
        "X=1000",
        "--counts-per-unit",
        "Y=1000",
        "--counts-per-unit",
        "Z=1000",
    ];
    // Each format on its own grid, against JSON (read by serde) planned on the same.
    for (format, quantum) in [
        ("pmac", "1ms"),
        ("powerpmac", "1ms"),
        ("movepvt", "off"),
        ("xps", "100us"),
        ("galil", "1953.125us"),
        ("zaber", "100us"),
        ("csv", "off"),
    ] {
        let name = format!("p.{}", ext(format));
        let written = compile(
            d,
            POCKET,
            &name,
            &[&["--format", format, "--quantize", quantum][..], &scale].concat(),
        );
        let json = compile(
            d,
            POCKET,
            &format!("{format}.json"),
            &["--format", "json", "--quantize", quantum],
        );
        let (code, report, err) = diff(&json, &written, &scale);
        assert_eq!(code, 0, "{format}: {report}\n{err}");
        assert_eq!(report["b"]["format"], format);
        // Whole counts (Galil, Zaber at 1000 per mm) are within half a count per axis.
        let largest = report["aligned"]["value"].as_f64().unwrap();
        assert!(largest <= 0.0009, "{format}: {largest}");
    }
}

#[test]
fn a_shift_of_a_micrometre_is_within_two_and_beyond_half_with_its_instant_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let a = compile(dir.path(), POCKET, "a.json", &["--format", "json"]);
    let b = edited(&a, "b.json", |doc| {
        let shift = |p: &mut Value| {
            let x = p[0].as_f64().unwrap();
            p[0] = serde_json::json!(x + 0.001);
        };
        for c in doc["contours"].as_array_mut().unwrap() {
            shift(&mut c["start"]);
            for s in c["segments"].as_array_mut().unwrap() {
                shift(&mut s["p"]);
            }
        }
    });
    let (code, report, _) = diff(&a, &b, &["--tolerance", "2um"]);
    assert_eq!((code, codes(&report)), (0, vec![]), "{report}");
    let largest = report["aligned"]["value"].as_f64().unwrap();
    assert!((largest - 0.001).abs() < 1e-9, "{largest}");
    let (code, report, err) = diff(&a, &b, &["--tolerance", "0.5um"]);
    assert_eq!(code, 1);
    assert_eq!(codes(&report), ["pvtc::diff::position"], "{report}");
    let first = &report["first_divergence"];
    assert_eq!(first["time"].as_f64(), Some(0.0));
    // A's first segment is on its line 13; B, rewritten by serde_json not one segment a
    // line, names the source line its segment keeps (7).
    assert_eq!(first["lines"], serde_json::json!([13, 7]), "{report}");
    assert!(err.contains("pvtc::diff::position"), "{err}");
    let message = report["differences"][0]["message"].as_str().unwrap();
    assert!(
        message.contains("first diverge at t=0.0000 s") && message.contains("a.json line 13"),
        "{message}"
    );
}

#[test]
fn a_time_stretch_is_reported_as_time() {
    let dir = tempfile::tempdir().unwrap();
    let a = compile(dir.path(), POCKET, "a.json", &["--format", "json"]);
    let b = edited(&a, "b.json", |doc| {
        for c in doc["contours"].as_array_mut().unwrap() {
            for s in c["segments"].as_array_mut().unwrap() {
                let t = s["t"].as_f64().unwrap();
                s["t"] = serde_json::json!(t * 1.01);
                let v: Vec<f64> = s["v"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|v| v.as_f64().unwrap() / 1.01)
                    .collect();
                s["v"] = serde_json::json!(v);
            }
        }
    });
    let (code, report, _) = diff(&a, &b, &[]);
    assert_eq!(code, 1);
    let found = codes(&report);
    assert!(
        found.contains(&"pvtc::diff::time_shift".to_string())
            && found.contains(&"pvtc::diff::total_time".to_string())
            && !found.contains(&"pvtc::diff::position".to_string()),
        "{report}"
    );
    let shift = report["time_shift"]["value"].as_f64().unwrap();
    let total = report["a"]["total_time"].as_f64().unwrap();
    assert!(shift > 0.0 && shift <= 0.01 * total, "{shift} of {total}");
}

#[test]
fn a_dropped_piece_is_found_at_its_line() {
    let dir = tempfile::tempdir().unwrap();
    let a = compile(dir.path(), POCKET, "a.json", &["--format", "json"]);
    let text = std::fs::read_to_string(&a).unwrap();
    // A side of the pocket's square (contour 3, a feed): the text holds a segment a line.
    let doc: Value = serde_json::from_str(&text).unwrap();
    let (c, s) = (2, 2);
    let before: usize = (0..c)
        .map(|k| doc["contours"][k]["segments"].as_array().unwrap().len())
        .sum();
    let line = pvt_core::text::numbered_lines(&text)
        .filter(|(_, l)| l.trim_start().starts_with("{\"p\": "))
        .nth(before + s)
        .map(|(n, _)| n)
        .unwrap();
    let b = edited(&a, "b.json", |doc| {
        doc["contours"][c]["segments"]
            .as_array_mut()
            .unwrap()
            .remove(s);
    });
    let (code, report, err) = diff(&a, &b, &[]);
    assert_eq!(code, 1, "{err}");
    assert!(
        codes(&report).contains(&"pvtc::diff::position".to_string()),
        "{report}"
    );
    let first = &report["first_divergence"];
    assert_eq!(first["lines"][0].as_u64(), Some(line as u64), "{report}");
    assert!(report["path"]["value"].as_f64().unwrap() > 1.0, "{report}");
}

#[test]
fn an_event_out_of_order_is_found() {
    let dir = tempfile::tempdir().unwrap();
    let source = dir.path().join("events.ngc");
    std::fs::write(
        &source,
        "G21 G90\nS1000 M3\nG1 X10 F600\nM8\nG1 Y10\nM9\nG1 X0\nM5\nM2\n",
    )
    .unwrap();
    let a = compile(
        dir.path(),
        source.to_str().unwrap(),
        "a.json",
        &["--format", "json"],
    );
    let pmac = compile(
        dir.path(),
        source.to_str().unwrap(),
        "a.pmac",
        &["--quantize", "off"],
    );
    let (code, report, err) = diff(&a, &pmac, &[]);
    assert_eq!(
        (code, &report["events"]["counts"]),
        (0, &serde_json::json!([5, 5])),
        "{err}"
    );
    let b = edited(&a, "b.json", |doc| {
        let events = doc["events"].as_array_mut().unwrap();
        let names: Vec<&str> = events
            .iter()
            .map(|e| e["event"].as_str().unwrap())
            .collect();
        let (m8, m9) = (
            names.iter().position(|n| *n == "coolant_flood").unwrap(),
            names.iter().position(|n| *n == "coolant_off").unwrap(),
        );
        let (x, y) = (events[m8]["event"].clone(), events[m9]["event"].clone());
        events[m8]["event"] = y;
        events[m9]["event"] = x;
    });
    let (code, report, err) = diff(&a, &b, &[]);
    assert_eq!(code, 1);
    assert_eq!(codes(&report), ["pvtc::diff::events"], "{report}");
    let message = report["differences"][0]["message"].as_str().unwrap();
    assert!(
        message.contains("has coolant_flood at line 4")
            && message.contains("has coolant_off at line 4"),
        "{message}\n{err}"
    );
}

#[test]
fn a_source_compiles_to_the_other_sides_format_and_names_its_lines() {
    let dir = tempfile::tempdir().unwrap();
    let golden = root().join("tests/golden/gcode/linuxcnc_params_pocket.pmac");
    let (code, report, err) = diff(&root().join(POCKET), &golden, &[]);
    assert_eq!(code, 0, "{report}\n{err}");
    assert_eq!(report["a"]["format"], "pmac");
    assert_eq!(report["a"]["compiled"], true);
    // In inches the same motion is the same.
    let inch = compile(
        dir.path(),
        POCKET,
        "inch.json",
        &["--format", "json", "--units", "in", "--quantize", "1ms"],
    );
    let (code, report, err) = diff(&golden, &inch, &[]);
    assert_eq!(code, 0, "{report}\n{err}");
    assert_eq!(report["units"], "mm");
}

#[test]
fn usage_errors_exit_2() {
    let golden = "tests/golden/gcode/square.json";
    for args in [
        vec!["diff", golden],
        vec!["diff", golden, golden, "--tolerance", "1"],
        vec!["diff", golden, golden, "--peak-tolerance", "-1%"],
        vec!["diff", golden, golden, "-o", "out.svg"],
        vec!["diff", golden, golden, "--tolerance", "2counts"],
    ] {
        let (code, _, err) = run(&args);
        assert_eq!(code, 2, "{args:?}: {err}");
    }
    let (code, out, _) = run(&["diff", golden, golden]);
    assert_eq!(code, 0);
    assert!(
        out.ends_with("equal within 0.001 mm, 1 ms and 1 %\n"),
        "{out}"
    );
}

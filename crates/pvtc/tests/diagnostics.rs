//! How diagnostics reach people and tools: repeats of one code grouped with a count and
//! their places, notes that `--deny-warnings` lets through, and each file's diagnostics
//! in a batch with a summary.

mod common;

use common::{root, run as pvtc};

use std::process::Output;

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Every line of standard error as a JSON object: under `--diagnostics json` a line that
/// is not one fails the test.
fn json_lines(o: &Output) -> Vec<serde_json::Value> {
    let err = stderr(o);
    err.lines()
        .map(|l| match serde_json::from_str::<serde_json::Value>(l) {
            Ok(value) if value.is_object() => value,
            _ => panic!("a line of standard error is not a JSON object: {l:?}\n{err}"),
        })
        .collect()
}

/// The lines of the step sample holding a zero-length feed move, found here from the
/// file: every `X…` block whose target equals the position before it.
fn zero_length_lines() -> Vec<usize> {
    let text = std::fs::read_to_string(root().join("samples/gcode/an208_step.ngc")).unwrap();
    let mut x = 0.0;
    let mut lines = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let Some(at) = line.find('X').filter(|_| !line.starts_with('(')) else {
            continue;
        };
        let word: String = line[at + 1..]
            .chars()
            .take_while(|c| c.is_ascii_digit() || *c == '.')
            .collect();
        let target: f64 = word.parse().unwrap();
        if target == x {
            lines.push(i + 1);
        }
        x = target;
    }
    lines
}

#[test]
fn repeated_warnings_are_one_diagnostic_with_a_count_and_their_places() {
    let expected = zero_length_lines();
    assert_eq!(expected.len(), 7);
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("step.pmac");
    let o = pvtc(&[
        "compile",
        "samples/gcode/an208_step.ngc",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stderr(&o);
    assert_eq!(
        text.matches("pvtc::gcode::zero_length_move").count(),
        1,
        "{text}"
    );
    assert!(text.contains("(7 times; the first 3 shown)"), "{text}");
    assert_eq!(text.matches("╰── zero-length move").count(), 3, "{text}");
    let listed: Vec<String> = expected.iter().map(|l| l.to_string()).collect();
    assert!(
        text.contains(&format!("at lines {}", listed.join(", "))),
        "{text}"
    );
    assert!(text.lines().count() < 30, "{text}");

    let o = pvtc(&[
        "compile",
        "samples/gcode/an208_step.ngc",
        "-o",
        out.to_str().unwrap(),
        "--diagnostics",
        "json",
    ]);
    let zero: Vec<serde_json::Value> = json_lines(&o)
        .into_iter()
        .filter(|v| v["code"] == "pvtc::gcode::zero_length_move")
        .collect();
    assert_eq!(zero.len(), 1);
    assert_eq!(zero[0]["count"], 7);
    assert_eq!(zero[0]["line"], expected[0]);
    let lines: Vec<usize> = zero[0]["places"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["line"].as_u64().unwrap() as usize)
        .collect();
    assert_eq!(lines, expected);
}

#[test]
fn repeated_errors_are_grouped_too_and_a_single_one_is_not() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("bad.ngc");
    std::fs::write(
        &input,
        "G21\nG1 X1 E1 F100\nG1 X2 E2\nG1 X3 E3\nG1 X4 Y4 Y5\n",
    )
    .unwrap();
    let o = pvtc(&["compile", input.to_str().unwrap(), "--diagnostics", "json"]);
    assert_eq!(o.status.code(), Some(1));
    let found = json_lines(&o);
    let unknown = found
        .iter()
        .find(|v| v["code"] == "pvtc::gcode::unknown_word")
        .unwrap_or_else(|| panic!("{}", stderr(&o)));
    assert_eq!(unknown["count"], 3);
    let single = found
        .iter()
        .find(|v| v["code"] == "pvtc::gcode::repeated_axis")
        .unwrap_or_else(|| panic!("{}", stderr(&o)));
    assert!(single.get("count").is_none() && single["line"] == 5);
}

#[test]
fn ordinary_cam_output_passes_deny_warnings_with_notes() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("cam.ngc");
    // A post-processor's frame: % lines, a rapid to where the machine already is.
    std::fs::write(
        &input,
        "%\n(POST: generic)\nG21 G90 G94\nG0 X0 Y0\nG0 Z5\nG1 Z-1 F300\nG1 X10 Y10\nG0 Z5\nM30\n%\n",
    )
    .unwrap();
    // JSON output: PMAC text adds its own warning when piece times are not whole ms.
    let out = dir.path().join("cam.json");
    let o = pvtc(&[
        "compile",
        input.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--format",
        "json",
        "--deny-warnings",
        "--diagnostics",
        "json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(out.exists());
    let note = json_lines(&o)
        .into_iter()
        .find(|v| v["code"] == "pvtc::gcode::rapid_to_current_point")
        .unwrap_or_else(|| panic!("{}", stderr(&o)));
    assert_eq!(
        (note["severity"].as_str(), note["line"].as_u64()),
        (Some("advice"), Some(4))
    );
    // A feed move to the current point is still a warning, and still denied.
    std::fs::write(&input, "G21 G90\nG1 X0 F100\nG1 X10\n").unwrap();
    let o = pvtc(&[
        "compile",
        input.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--format",
        "json",
        "--deny-warnings",
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("pvtc::gcode::zero_length_move"));
}

#[test]
fn a_batch_prints_each_files_diagnostics_under_its_name_and_a_summary() {
    let dir = tempfile::tempdir().unwrap();
    let inputs = dir.path().join("in");
    std::fs::create_dir(&inputs).unwrap();
    std::fs::copy(
        root().join("samples/gcode/an208_step.ngc"),
        inputs.join("a_step.ngc"),
    )
    .unwrap();
    std::fs::write(inputs.join("b_good.ngc"), "G21 G90\nG1 X1 F100\nM2\n").unwrap();
    std::fs::write(
        inputs.join("c_bad.ngc"),
        "G21 G90\nG1 X1 Y1 F100\nG1 X2 E7 Y2\nG1 X3 Y3 E3\n",
    )
    .unwrap();
    let out = dir.path().join("out");
    let args = [
        "compile",
        inputs.to_str().unwrap(),
        "--out-dir",
        out.to_str().unwrap(),
        "--format",
        "json",
    ];
    let o = pvtc(&args);
    assert_eq!(o.status.code(), Some(1));
    let err = stderr(&o);
    let step = err.find("a_step.ngc: 7 warnings").expect(&err);
    let bad = err.find("c_bad.ngc: 2 errors").expect(&err);
    assert!(step < bad, "{err}");
    // The warnings are rendered in full (source, labels), not one line.
    let warnings = &err[step..bad];
    assert!(warnings.contains("(7 times; the first 3 shown)"), "{err}");
    assert!(warnings.contains("│ G1 X0 F1200000"), "{err}");
    // So are the errors, with the lines of both places.
    let errors = &err[bad..];
    assert!(
        errors.contains("│ G1 X2 E7 Y2") && errors.contains("at lines 3, 4"),
        "{err}"
    );
    // E7 and E3 read differently: the first message, and how many more like it.
    assert!(errors.contains("(and 1 more like it)"), "{err}");
    assert!(
        err.trim_end()
            .ends_with("2 files compiled, 1 failed, 7 warnings"),
        "{err}"
    );

    let mut json_args = args.to_vec();
    json_args.extend(["--diagnostics", "json"]);
    let o = pvtc(&json_args);
    let values = json_lines(&o);
    let zero = values
        .iter()
        .find(|v| v["code"] == "pvtc::gcode::zero_length_move")
        .unwrap();
    assert!(zero["input"].as_str().unwrap().ends_with("a_step.ngc"));
    assert_eq!(zero["count"], 7);
    let unknown = values
        .iter()
        .find(|v| v["code"] == "pvtc::gcode::unknown_word")
        .unwrap();
    assert!(unknown["input"].as_str().unwrap().ends_with("c_bad.ngc"));
    let summary = values.last().unwrap();
    assert_eq!(summary["code"], "pvtc::batch::summary");
    assert_eq!(
        (
            &summary["compiled"],
            &summary["failed"],
            &summary["warnings"]
        ),
        (
            &serde_json::json!(2),
            &serde_json::json!(1),
            &serde_json::json!(7)
        )
    );
}

#[test]
fn under_json_diagnostics_a_batch_and_its_usage_errors_print_only_json_objects() {
    let dir = tempfile::tempdir().unwrap();
    let inputs = dir.path().join("in");
    std::fs::create_dir_all(inputs.join("dxf")).unwrap();
    std::fs::write(inputs.join("good.ngc"), "G21 G90\nG1 X1 F100\nM2\n").unwrap();
    std::fs::write(
        inputs.join("dxf/broken.dxf"),
        "0\nSECTION\n2\nENTITIES\n0\nLINE\n",
    )
    .unwrap();
    let out = dir.path().join("out");
    let o = pvtc(&[
        "compile",
        inputs.to_str().unwrap(),
        "--out-dir",
        out.to_str().unwrap(),
        "--diagnostics",
        "json",
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let values = json_lines(&o);
    let failed = values
        .iter()
        .find(|v| v["code"] == "pvtc::batch::failed")
        .expect("one object per failed file");
    assert!(failed["input"].as_str().unwrap().ends_with("broken.dxf"));
    assert_eq!(failed["severity"], "error");
    assert_eq!(values.last().unwrap()["code"], "pvtc::batch::summary");
    // The folder of the file that failed is not left behind empty.
    assert!(out.join("good.pmac").is_file());
    assert!(!out.join("dxf").exists(), "an empty out/dxf/ is left");

    // Two inputs without --out-dir: a usage error, as one JSON object.
    let o = pvtc(&[
        "compile",
        inputs.join("good.ngc").to_str().unwrap(),
        inputs.join("good.ngc").to_str().unwrap(),
        "--diagnostics",
        "json",
    ]);
    assert_eq!(o.status.code(), Some(2));
    let values = json_lines(&o);
    assert_eq!(values.len(), 1, "{}", stderr(&o));
    assert_eq!(values[0]["code"], "pvtc::usage");
    assert!(values[0]["message"].as_str().unwrap().contains("--out-dir"));

    // Two inputs that would write one output: a usage error naming both.
    let other = dir.path().join("other");
    std::fs::create_dir(&other).unwrap();
    std::fs::write(other.join("good.ngc"), "G1 X2 F100\nM2\n").unwrap();
    let o = pvtc(&[
        "compile",
        inputs.join("good.ngc").to_str().unwrap(),
        other.join("good.ngc").to_str().unwrap(),
        "--out-dir",
        out.to_str().unwrap(),
        "--diagnostics",
        "json",
    ]);
    assert_eq!(o.status.code(), Some(2));
    let values = json_lines(&o);
    assert_eq!(values.len(), 1, "{}", stderr(&o));
    assert_eq!(values[0]["code"], "pvtc::usage");
    assert!(values[0]["message"]
        .as_str()
        .unwrap()
        .contains("would both write"));
}

#[test]
fn a_batch_whose_every_file_fails_leaves_no_output_folder() {
    let dir = tempfile::tempdir().unwrap();
    let inputs = dir.path().join("in");
    std::fs::create_dir_all(inputs.join("sub")).unwrap();
    std::fs::write(inputs.join("sub/bad.ngc"), "G1 X1 Q#\n").unwrap();
    let out = dir.path().join("out");
    let o = pvtc(&[
        "compile",
        inputs.to_str().unwrap(),
        "--out-dir",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("0 files compiled, 1 failed"),
        "{}",
        stderr(&o)
    );
    assert!(!out.exists(), "the failed batch created {}", out.display());
}

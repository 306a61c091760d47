//! Issue 24 through the command line: what real CAM output and LinuxCNC's programs need
//! beyond the motion `tests/dialect/` compares with `rs274` (line numbers of files with
//! odd line ends, `%` lines, a missing program end, HAL pins, I/O events, probing,
//! grouped diagnostics, arc turns).

mod common;

use common::{pvtc_bytes, text};

/// Every diagnostic of a run as (code, line), from `--diagnostics json` (each place of
/// a repeated one).
fn diagnostics(args: &[&str], program: &[u8]) -> (bool, Vec<(String, u64)>) {
    let mut all = vec![
        "compile",
        "-",
        "--format",
        "toolpath",
        "--diagnostics",
        "json",
    ];
    all.extend_from_slice(&["-o", "/dev/null"]);
    all.extend_from_slice(args);
    let out = pvtc_bytes(&all, program);
    let found = text(&out.stderr)
        .lines()
        .filter(|l| l.starts_with('{'))
        .map(|l| serde_json::from_str::<serde_json::Value>(l).expect("JSON"))
        .flat_map(|d| {
            let code = d["code"].as_str().unwrap_or_default().to_owned();
            let places = match d["places"].as_array() {
                Some(places) => places.iter().map(|p| p["line"].as_u64()).collect(),
                None => vec![d["line"].as_u64()],
            };
            let lines = places.into_iter().map(|line| line.unwrap_or(0));
            lines.map(move |line| (code.clone(), line))
        })
        .collect();
    (out.status.success(), found)
}

/// CR CR LF line ends (PyCAM 0.5) are one line end: no `\r` word, and a diagnostic names
/// the line it is on, in the JSON and in the rendered excerpt.
#[test]
fn cr_cr_lf_lines_are_read_and_counted_as_lines() {
    let program = b"G21 G90\r\r\nG1 X1 F100\r\r\nG1 X2 Q\r\r\nM2\r\r\n";
    let (ok, found) = diagnostics(&[], program);
    assert!(!ok);
    assert_eq!(found, [("pvtc::gcode::syntax".to_owned(), 3)]);
    let out = pvtc_bytes(&["compile", "-", "-o", "/dev/null"], program);
    assert!(
        text(&out.stderr).contains("<stdin>:3:7"),
        "{}",
        text(&out.stderr)
    );
    let (ok, found) = diagnostics(&[], b"G21 G90\r\r\nG1 X1 F100\r\r\nM2\r\r\n");
    assert!(
        ok && found.iter().all(|(c, _)| !c.contains("unknown_word")),
        "{found:?}"
    );
}

/// A file that ends without M2, M30 or `%` warns (`no_program_end`, at its last line),
/// so `--deny-warnings` refuses it; with M2 it compiles silently.
#[test]
fn a_missing_program_end_is_a_warning_that_deny_warnings_refuses() {
    let program = b"G21 G90 F300\nG1 X5 Y2\nG1 X10\n";
    let (ok, found) = diagnostics(&[], program);
    assert!(ok);
    assert!(
        found.contains(&("pvtc::gcode::no_program_end".to_owned(), 3)),
        "{found:?}"
    );
    let (ok, _) = diagnostics(&["--deny-warnings"], program);
    assert!(!ok, "--deny-warnings refuses a program without its end");
    let (ok, found) = diagnostics(&["--deny-warnings"], b"G21 G90 F300\nG1 X5 Y2\nM2\n");
    assert!(ok, "{found:?}");
}

/// A `%` line that neither opens nor closes the program is an error at that line, as
/// rs274 stops there; a program opened with `%` ends at its closing `%`.
#[test]
fn a_percent_line_mid_program_is_an_error_at_its_line() {
    let program = b"G21 G90 F300\nG1 X5 Y2\n% vfd enable\nG1 X10\nM2\n";
    let (ok, found) = diagnostics(&[], program);
    assert!(!ok);
    assert_eq!(found, [("pvtc::gcode::percent_line".to_owned(), 3)]);
    let (ok, found) = diagnostics(&["--deny-warnings"], b"\n%\nG21 G1 X5 F300\n%\n");
    assert!(ok, "{found:?}");
    let (_, found) = diagnostics(&[], b"%\nG21 G1 X5 F300\n");
    assert!(
        found.contains(&("pvtc::gcode::no_program_end".to_owned(), 2)),
        "{found:?}"
    );
}

/// Each unsupported feature is its own diagnostic with its own message and count, not
/// merged under the first feature's message; E on M67 is read.
#[test]
fn unsupported_features_are_reported_one_per_feature() {
    let program = b"G21 G1 X1 F100\nM61 Q1\nM61 Q2\nG17.1\nG1 X#<_hal[motion.x]>\nM67 E0 Q2\nM2\n";
    let out = pvtc_bytes(&["compile", "-", "--format", "toolpath"], program);
    let err = text(&out.stderr);
    let heads: Vec<&str> = err.lines().filter(|l| l.contains("× ")).collect();
    assert_eq!(heads.len(), 3, "{err}");
    assert!(heads[0].contains("M61 (setting the current tool)"), "{err}");
    assert!(heads[1].contains("G17.1 (UVW planes)"), "{err}");
    assert!(heads[2].contains("HAL pins"), "{err}");
    assert!(err.contains("(2 places;"), "{err}");
    assert!(
        !err.contains("more like it") && !err.contains("unknown word"),
        "{err}"
    );
}

/// `--hal NAME=VALUE` gives a pin its value; a malformed one, or one for a drawing, is a
/// usage error.
#[test]
fn hal_values_come_from_the_command_line() {
    let program = b"G21 F100\nG1 X#<_hal[motion.analog-in-00]>\nM2\n";
    let (ok, found) = diagnostics(&[], program);
    assert!(!ok && found[0].0 == "pvtc::gcode::unsupported", "{found:?}");
    let args = [
        "compile",
        "-",
        "--format",
        "toolpath",
        "--hal",
        "motion.analog-in-00=2.5",
    ];
    let out = pvtc_bytes(&args, program);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(
        text(&out.stdout).contains("\"end\":[2.5,"),
        "{}",
        text(&out.stdout)
    );
    for bad in ["motion.x", "=1", "x=inf", "x=one"] {
        let out = pvtc_bytes(&["compile", "-", "--hal", bad], program);
        assert_eq!(
            out.status.code(),
            Some(2),
            "--hal {bad}: {}",
            text(&out.stderr)
        );
    }
    let drawing = ["compile", "-", "--input-format", "dxf", "--hal", "x=1"];
    let out = pvtc_bytes(&drawing, b"0\nEOF\n");
    assert!(
        text(&out.stderr).contains("--hal does nothing here"),
        "{}",
        text(&out.stderr)
    );
}

/// `--probe-result X,Y,Z` lets a probing program compile; without it each probing block
/// is its own `probe` error; a malformed one is a usage error.
#[test]
fn probe_results_come_from_the_command_line() {
    let program = b"G21 G90 F100\nG1 X1\nG38.2 Z-10 F50\nG0 Z5\nG38.3 Z-10\nM2\n";
    let (ok, found) = diagnostics(&[], program);
    assert!(!ok);
    let probe = "pvtc::gcode::probe".to_owned();
    assert_eq!(found, [(probe.clone(), 3), (probe, 5)]);
    let given = ["--probe-result", "1,0,-3.5", "--probe-result", "1,0,-2"];
    let (ok, found) = diagnostics(&given, program);
    assert!(ok, "{found:?}");
    for bad in ["1,2", "1,2,x", "1,2,3,4", "1,nan,2"] {
        let out = pvtc_bytes(&["compile", "-", "--probe-result", bad], program);
        assert_eq!(out.status.code(), Some(2), "--probe-result {bad}");
    }
}

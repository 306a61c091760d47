//! The `pvtc` binary end to end: exit codes, diagnostics, stdin/stdout, no partial output.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn pvtc(args: &[&str], stdin: Option<&str>) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_pvtc"))
        .args(args)
        .current_dir(root())
        .env("NO_COLOR", "1")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("pvtc runs");
    let mut pipe = child.stdin.take().unwrap();
    pipe.write_all(stdin.unwrap_or("").as_bytes()).unwrap();
    drop(pipe);
    child.wait_with_output().unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

const BAD_LINE_3: &str = "G21 G90\nG1 X1 Y1 F100\nG1 X2 Q7 Y2\nG1 X3 Y3\n";

#[test]
fn compiles_a_sample_to_json_on_stdout() {
    let o = pvtc(
        &[
            "compile",
            "samples/gcode/an208_octagon.ngc",
            "--format",
            "json",
        ],
        None,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["axes"], serde_json::json!(["X", "Y"]));
    assert_eq!(v["contours"][0]["segments"].as_array().unwrap().len(), 8);
}

#[test]
fn bad_word_on_line_3_exits_1_names_line_3_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("bad.ngc");
    std::fs::write(&input, BAD_LINE_3).unwrap();
    let out = dir.path().join("out.pmac");
    let o = pvtc(
        &[
            "compile",
            input.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ],
        None,
    );
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(err.contains("bad.ngc:3:"), "diagnostic names line 3: {err}");
    assert!(err.contains("pvtc::gcode::unknown_word"), "{err}");
    assert!(!out.exists(), "no output file on failure");
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        1,
        "no temporary file left behind"
    );
}

#[test]
fn failed_compile_leaves_an_existing_output_untouched() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.json");
    std::fs::write(&out, "previous good output").unwrap();
    let o = pvtc(
        &["compile", "-", "-o", out.to_str().unwrap()],
        Some(BAD_LINE_3),
    );
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("<stdin>:3:"), "{}", stderr(&o));
    assert_eq!(
        std::fs::read_to_string(&out).unwrap(),
        "previous good output"
    );
}

#[test]
fn output_file_is_written_whole_and_matches_stdout() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("zigzag.pmac");
    let o = pvtc(
        &[
            "compile",
            "samples/gcode/an208_zigzag.ngc",
            "-o",
            out.to_str().unwrap(),
        ],
        None,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(o.stdout.is_empty());
    let stdout = pvtc(&["compile", "samples/gcode/an208_zigzag.ngc"], None).stdout;
    assert_eq!(std::fs::read(&out).unwrap(), stdout);
    assert!(String::from_utf8(stdout)
        .unwrap()
        .contains("OPEN PROG 1 CLEAR"));
}

#[test]
fn stdin_to_stdout() {
    let o = pvtc(
        &["compile", "-", "--format", "json", "--feed", "600"],
        Some("G1 X10\nY10\n"),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["source"], "<stdin>");
    assert_eq!(v["contours"][0]["segments"][1]["line"], 2);
}

#[test]
fn usage_errors_exit_2() {
    assert_eq!(pvtc(&["compile"], None).status.code(), Some(2));
    assert_eq!(
        pvtc(&["compile", "x.ngc", "--tolerance", "-1"], None)
            .status
            .code(),
        Some(2)
    );
    assert_eq!(
        pvtc(&["compile", "x.ngc", "--format", "svg"], None)
            .status
            .code(),
        Some(2)
    );
    assert_eq!(pvtc(&["frobnicate"], None).status.code(), Some(2));
}

#[test]
fn missing_input_exits_1() {
    let o = pvtc(&["compile", "no/such/file.ngc"], None);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("pvtc::io"), "{}", stderr(&o));
}

#[test]
fn empty_input_is_an_error_not_an_empty_program() {
    let o = pvtc(&["compile", "-"], Some(""));
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("pvtc::gcode::no_motion"),
        "{}",
        stderr(&o)
    );
    assert!(o.stdout.is_empty());
}

#[test]
fn movepvt_output_compiles_as_c() {
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    if Command::new(&cc).arg("--version").output().is_err() {
        eprintln!("SKIPPED: no C compiler `{cc}` on this machine");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    for sample in ["an208_octagon", "quad_circle_arc", "an208_step"] {
        let c_file = dir.path().join(format!("{sample}.c"));
        let input = format!("samples/gcode/{sample}.ngc");
        let o = pvtc(
            &[
                "compile",
                &input,
                "--format",
                "movepvt",
                "-o",
                c_file.to_str().unwrap(),
            ],
            None,
        );
        assert!(o.status.success(), "{}", stderr(&o));
        let status = Command::new(&cc)
            .args([
                "-std=c99",
                "-Wall",
                "-Werror",
                "-Wno-unused-variable",
                "-c",
                "-o",
            ])
            .arg(dir.path().join(format!("{sample}.o")))
            .arg(&c_file)
            .status()
            .unwrap();
        assert!(status.success(), "{sample}.c does not compile");
    }
}

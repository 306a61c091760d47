//! O-words through the `pvtc` binary: `--subroutine-path`, and the coded errors of a
//! missing subroutine file, runaway recursion and an endless loop (exit 1, no output).

use std::path::Path;
use std::process::{Command, Output, Stdio};

fn pvtc(args: &[&str], cwd: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pvtc"))
        .args(args)
        .current_dir(cwd)
        .env("NO_COLOR", "1")
        .stdin(Stdio::null())
        .output()
        .expect("pvtc runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The first JSON diagnostic's code, line and column.
fn first_diagnostic(o: &Output) -> (String, u64, u64) {
    let first = stderr(o).lines().next().unwrap_or("").to_string();
    let v: serde_json::Value = serde_json::from_str(&first).expect("a JSON diagnostic");
    (
        v["code"].as_str().unwrap_or("").to_owned(),
        v["line"].as_u64().unwrap_or(0),
        v["column"].as_u64().unwrap_or(0),
    )
}

const SQUARE: &str = "o<square> sub\nG91 G1 X#1 F100\nY#1\nX-#1\nY-#1\nG90\no<square> endsub\n";

#[test]
fn subroutine_path_finds_files_in_each_folder_given() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    std::fs::create_dir_all(&a).unwrap();
    std::fs::create_dir_all(&b).unwrap();
    std::fs::write(b.join("square.ngc"), SQUARE).unwrap();
    std::fs::write(
        dir.path().join("main.ngc"),
        "G21 G0 X1 Y1\no<square> call [2]\nM2\n",
    )
    .unwrap();
    let out = dir.path().join("out.jsonl");
    let list = format!("{}:{}", a.display(), b.display());
    for path in [
        vec!["--subroutine-path", &list],
        vec!["--subroutine-path", "a", "--subroutine-path", "b"],
    ] {
        let mut args = vec![
            "compile",
            "main.ngc",
            "--format",
            "toolpath",
            "-o",
            out.to_str().unwrap(),
        ];
        args.extend(path);
        let o = pvtc(&args, dir.path());
        assert!(o.status.success(), "{}", stderr(&o));
        let text = std::fs::read_to_string(&out).unwrap();
        let lines = text
            .lines()
            .filter(|l| l.contains("\"kind\":\"line\""))
            .count();
        assert_eq!(lines, 5, "{text}");
    }
    // Without the path the call is a coded error, and nothing is written.
    std::fs::remove_file(&out).unwrap();
    let o = pvtc(
        &[
            "compile",
            "main.ngc",
            "--diagnostics",
            "json",
            "-o",
            out.to_str().unwrap(),
        ],
        dir.path(),
    );
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(
        first_diagnostic(&o),
        ("pvtc::gcode::unknown_subroutine".to_owned(), 2, 1)
    );
    assert!(stderr(&o).contains("square.ngc"), "{}", stderr(&o));
    assert!(!out.exists());
    // The path is for G-code only.
    std::fs::write(dir.path().join("p.csv"), "t,x\n0,0\n1,1\n").unwrap();
    let o = pvtc(&["compile", "p.csv", "--subroutine-path", "a"], dir.path());
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
}

#[test]
fn an_error_in_a_subroutine_file_names_the_file_its_line_and_the_call() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("bad.ngc"),
        "o<bad> sub\nG1 X1 F100\nG1 X[1/0]\no<bad> endsub\n",
    )
    .unwrap();
    std::fs::write(dir.path().join("main.ngc"), "G0 X1\n\no<bad> call\n").unwrap();
    let o = pvtc(
        &[
            "compile",
            "main.ngc",
            "--subroutine-path",
            ".",
            "--diagnostics",
            "json",
        ],
        dir.path(),
    );
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(
        first_diagnostic(&o),
        ("pvtc::gcode::in_subroutine_file".to_owned(), 3, 1)
    );
    let text = stderr(&o);
    assert!(text.contains("bad.ngc line 3 column 7"), "{text}");
    assert!(text.contains("pvtc::gcode::math_error"), "{text}");
}

#[test]
fn runaway_recursion_and_endless_loops_are_coded_errors() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("deep.ngc"),
        "G1 X1 F100\no<d> sub\no<d> call\no<d> endsub\no<d> call\n",
    )
    .unwrap();
    std::fs::write(
        dir.path().join("endless.ngc"),
        "G1 X1 F100\n#1 = 0\no1 while [#1 GE 0]\n#1 = [#1 + 1]\no1 endwhile\n",
    )
    .unwrap();
    for (file, code, line) in [
        ("deep.ngc", "pvtc::gcode::recursion_limit", 3),
        ("endless.ngc", "pvtc::gcode::loop_limit", 3),
    ] {
        let o = pvtc(&["compile", file, "--diagnostics", "json"], dir.path());
        assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
        assert_eq!(first_diagnostic(&o), (code.to_owned(), line, 1));
        assert!(o.stdout.is_empty());
    }
}

//! The `pvtc` binary end to end: exit codes, diagnostics, stdin/stdout, no partial output.

use std::path::Path;
use std::process::{Command, Output};

mod common;
use common::{pvtc, pvtc_into, root};

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

const BAD_LINE_3: &str = "G21 G90\nG1 X1 Y1 F100\nG1 X2 E7 Y2\nG1 X3 Y3\n";

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

/// Standard output redirected to a file is written in one pass, starting over when the
/// prescan's guess is wrong; appending keeps what was there; a failure adds nothing.
#[test]
fn stdout_redirected_to_a_file_streams_and_starts_over_like_an_output_file() {
    let dir = tempfile::tempdir().unwrap();
    // Y is named but never moves: the prescan guesses X Y, the compile finds X.
    let program = dir.path().join("still_y.ngc");
    std::fs::write(&program, "G0 X0 Y0\nG1 X5 F300\nG1 X5 Y0\nG1 X9\nM2\n").unwrap();
    let program = program.to_str().unwrap();
    let piped = pvtc(&["compile", program], None);
    assert!(piped.status.success(), "{}", stderr(&piped));
    assert!(String::from_utf8_lossy(&piped.stdout).contains("; axes: X;"));

    let out = dir.path().join("out.pmac");
    let o = pvtc_into(&["compile", program], std::fs::File::create(&out).unwrap());
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(std::fs::read(&out).unwrap(), piped.stdout);

    std::fs::write(&out, "; kept\n").unwrap();
    let append = std::fs::OpenOptions::new().append(true).open(&out).unwrap();
    let o = pvtc_into(&["compile", program], append);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        std::fs::read(&out).unwrap(),
        [b"; kept\n".as_slice(), &piped.stdout].concat()
    );

    // An error after enough moves that output has been written by then.
    let bad = dir.path().join("bad.ngc");
    let moves: String = (1..=5000).map(|i| format!("G1 X{i} F600\n")).collect();
    std::fs::write(&bad, moves + "G1 X2 E7 Y2\n").unwrap();
    let append = std::fs::OpenOptions::new().append(true).open(&out).unwrap();
    let o = pvtc_into(&["compile", bad.to_str().unwrap()], append);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("bad.ngc:5001:"), "{}", stderr(&o));
    assert_eq!(
        std::fs::read(&out).unwrap(),
        [b"; kept\n".as_slice(), &piped.stdout].concat()
    );
}

/// Into a pipe, the whole program is checked before the first byte: an error on its
/// last line leaves the pipe empty and is reported once; a warning is reported once
/// and the program is written whole, the bytes a file gets.
#[test]
fn a_pipe_gets_nothing_from_a_program_with_an_error_and_each_warning_once() {
    let dir = tempfile::tempdir().unwrap();
    let moves: String = (1..=5000).map(|i| format!("G1 X{i} F600\n")).collect();
    let bad = dir.path().join("bad.ngc");
    std::fs::write(&bad, moves.clone() + "G1 X2 E7 Y2\n").unwrap();
    let o = pvtc(&["compile", bad.to_str().unwrap()], None);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(o.stdout.is_empty(), "nothing on the pipe");
    assert_eq!(
        stderr(&o).matches("bad.ngc:5001:").count(),
        1,
        "{}",
        stderr(&o)
    );

    let warned = dir.path().join("warned.ngc");
    std::fs::write(&warned, moves + "G1 X5000\nM2\n").unwrap();
    let o = pvtc(&["compile", warned.to_str().unwrap()], None);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        stderr(&o).matches("warned.ngc:5001:").count(),
        1,
        "{}",
        stderr(&o)
    );
    let out = dir.path().join("warned.pmac");
    let to_file = pvtc(
        &[
            "compile",
            warned.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ],
        None,
    );
    assert!(to_file.status.success(), "{}", stderr(&to_file));
    assert_eq!(std::fs::read(&out).unwrap(), o.stdout);
}

/// `pvtc compile p.ngc >> p.ngc` would read its own output for ever: it is refused.
#[test]
fn standard_output_into_the_input_file_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let program = dir.path().join("p.ngc");
    let text = "G1 X1 F100\nG1 X2\n";
    std::fs::write(&program, text).unwrap();
    let append = std::fs::OpenOptions::new()
        .append(true)
        .open(&program)
        .unwrap();
    let o = pvtc_into(&["compile", program.to_str().unwrap()], append);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("pvtc::usage"), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("standard output is the input file"),
        "{}",
        stderr(&o)
    );
    assert_eq!(std::fs::read_to_string(&program).unwrap(), text);
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
    let compiles = |c_file: &Path, object: &str| {
        let o = Command::new(&cc)
            .args(["-std=c99", "-Wall", "-Wextra", "-Werror", "-c", "-o"])
            .arg(dir.path().join(object))
            .arg(c_file)
            .output()
            .unwrap();
        assert!(
            o.status.success(),
            "{} does not compile cleanly: {}",
            c_file.display(),
            String::from_utf8_lossy(&o.stderr)
        );
    };
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
        // Alone, and included by a program using only the arrays the header comment
        // names, or only the table.
        compiles(&c_file, &format!("{sample}.o"));
        let arrays = dir.path().join(format!("{sample}_arrays.c"));
        std::fs::write(
            &arrays,
            format!(
                "#include \"{sample}.c\"\n\
                 double first_time(void);\n\
                 double first_time(void) {{ return pvtc_c1_start[0] + pvtc_c1_position[0] \
                 + pvtc_c1_velocity[0] + pvtc_c1_time[0] + (double)PVTC_C1_POINTS; }}\n"
            ),
        )
        .unwrap();
        compiles(&arrays, &format!("{sample}_arrays.o"));
        let table = dir.path().join(format!("{sample}_table.c"));
        std::fs::write(
            &table,
            format!(
                "#include \"{sample}.c\"\n\
                 long points(void);\n\
                 long points(void) {{ return pvtc_contours[0].count; }}\n"
            ),
        )
        .unwrap();
        compiles(&table, &format!("{sample}_table.o"));
    }
}

#[test]
fn diagnostics_json_gives_code_line_and_column() {
    let o = pvtc(&["compile", "-", "--diagnostics", "json"], Some(BAD_LINE_3));
    assert_eq!(o.status.code(), Some(1));
    let first = stderr(&o).lines().next().unwrap().to_string();
    let v: serde_json::Value = serde_json::from_str(&first).unwrap();
    assert_eq!(v["code"], "pvtc::gcode::unknown_word");
    assert_eq!(v["severity"], "error");
    assert_eq!(
        (v["line"].as_u64(), v["column"].as_u64()),
        (Some(3), Some(7))
    );
    assert_eq!(v["file"], "<stdin>");
}

#[test]
fn deny_warnings_turns_a_warning_into_a_failure() {
    let program = "G1 X0 F100\nX10\n";
    let ok = pvtc(&["compile", "-"], Some(program));
    assert!(ok.status.success());
    assert!(stderr(&ok).contains("pvtc::gcode::zero_length_move"));
    let denied = pvtc(&["compile", "-", "--deny-warnings"], Some(program));
    assert_eq!(denied.status.code(), Some(1));
    assert!(denied.stdout.is_empty());
}

#[test]
fn pmac_times_whole_milliseconds_unless_quantize_is_off() {
    let o = pvtc(
        &[
            "compile",
            "samples/gcode/an208_zigzag.ngc",
            "--quantize",
            "off",
        ],
        None,
    );
    assert!(
        stderr(&o).contains("pvtc::emit::fractional_ms"),
        "{}",
        stderr(&o)
    );
    // By default PMAC output is on the 1 ms grid: no --quantize needed.
    let q = pvtc(&["compile", "samples/gcode/an208_zigzag.ngc"], None);
    assert!(q.status.success(), "{}", stderr(&q));
    assert!(!stderr(&q).contains("fractional_ms"));
    assert!(stderr(&q).contains("pvtc::plan::quantized"));
    let text = String::from_utf8(q.stdout).unwrap();
    for line in text.lines().filter(|l| l.starts_with("TA")) {
        let ms = &line[2..line.find(' ').unwrap()];
        assert!(ms.ends_with(".0000"), "{line}");
    }
    // Every printed time is whole, so the program says none is not (820 ms was stored as
    // 0.8200000000000001 s and counted as fractional).
    assert!(!text.contains("not whole"), "{text}");
}

/// The piece times of a compile, ms as printed, and its header line about quantization.
fn quantized(extra: &[&str]) -> (Vec<String>, String) {
    let mut args = vec![
        "compile",
        "samples/gcode/an208_zigzag.ngc",
        "--planner",
        "contour",
        "--quantize",
        "1ms",
    ];
    args.extend_from_slice(extra);
    let o = pvtc(&args, None);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8(o.stdout).unwrap();
    let times = text
        .lines()
        .filter_map(|l| l.strip_prefix("TA"))
        .map(|l| l.split(' ').next().unwrap().to_string())
        .collect();
    let header = text
        .lines()
        .find(|l| l.contains("quantized"))
        .unwrap_or_default()
        .to_string();
    (times, header)
}

#[test]
fn quantized_times_round_up_or_to_nearest_as_asked_and_say_which() {
    // Planned: 642.1749, 819.3295 and 1761.0297 ms.
    let (up, header) = quantized(&[]);
    assert_eq!(up, ["643.0000", "820.0000", "1762.0000"]);
    assert!(header.contains("rounded up"), "{header}");
    let (same, _) = quantized(&["--quantize-rounding", "up"]);
    assert_eq!(same, up);
    let (nearest, header) = quantized(&["--quantize-rounding", "nearest"]);
    assert_eq!(nearest, ["642.0000", "819.0000", "1761.0000"]);
    assert!(header.contains("rounded to nearest"), "{header}");
    let o = pvtc(
        &[
            "compile",
            "samples/gcode/an208_zigzag.ngc",
            "--quantize-rounding",
            "down",
        ],
        None,
    );
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    // JSON carries each time as the f64 nearest to its decimal value.
    let o = pvtc(
        &[
            "compile",
            "samples/gcode/an208_zigzag.ngc",
            "--planner",
            "contour",
            "--quantize",
            "1ms",
            "--format",
            "json",
        ],
        None,
    );
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let t: Vec<f64> = v["contours"][0]["segments"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["t"].as_f64().unwrap())
        .collect();
    assert_eq!(t, [0.643, 0.82, 1.762]);
}

/// The pieces of a PMAC program of one axis: (time s, end position, end velocity).
fn pmac_pieces(text: &str) -> Vec<(f64, f64, f64)> {
    text.lines()
        .filter_map(|l| l.strip_prefix("TA"))
        .map(|l| {
            let (ms, word) = l.split_once(" X").unwrap();
            let (p, v) = word.split_once(':').unwrap();
            (
                ms.parse::<f64>().unwrap() / 1000.0,
                p.parse().unwrap(),
                v.parse().unwrap(),
            )
        })
        .collect()
}

/// Position at time `t` of the cubics through `pieces` from rest at 0.
fn position_at(pieces: &[(f64, f64, f64)], t: f64) -> f64 {
    let (mut begin, mut p0, mut v0) = (0.0, 0.0, 0.0);
    for (i, &(d, p1, v1)) in pieces.iter().enumerate() {
        if t <= begin + d || i + 1 == pieces.len() {
            let s = pvt_core::HermiteSegment::new(p0, v0, p1, v1, d);
            return s.at(t - begin).position;
        }
        (begin, p0, v0) = (begin + d, p1, v1);
    }
    0.0
}

#[test]
fn pmac_pieces_longer_than_4095_ms_are_split_without_changing_the_motion() {
    let program = "G1 X100 F10\n";
    let json = pvtc(&["compile", "-", "--format", "json"], Some(program));
    assert!(json.status.success(), "{}", stderr(&json));
    let v: serde_json::Value = serde_json::from_slice(&json.stdout).unwrap();
    let seg = &v["contours"][0]["segments"][0];
    let whole = [(
        seg["t"].as_f64().unwrap(),
        seg["p"][0].as_f64().unwrap(),
        seg["v"][0].as_f64().unwrap(),
    )];
    assert_eq!(whole[0].0, 900.0, "one piece of 900 s");
    // In memory (standard input) and streamed (a file into -o): the same pieces.
    let dir = tempfile::tempdir().unwrap();
    let (ngc, pmac) = (dir.path().join("long.ngc"), dir.path().join("long.pmac"));
    std::fs::write(&ngc, program).unwrap();
    let o = pvtc(
        &[
            "compile",
            ngc.to_str().unwrap(),
            "-o",
            pmac.to_str().unwrap(),
        ],
        None,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let streamed = std::fs::read_to_string(&pmac).unwrap();
    let o = pvtc(&["compile", "-"], Some(program));
    assert!(o.status.success(), "{}", stderr(&o));
    let in_memory = String::from_utf8(o.stdout).unwrap();
    assert_eq!(
        streamed.lines().skip(1).collect::<Vec<_>>(),
        in_memory.lines().skip(1).collect::<Vec<_>>()
    );
    for text in [&streamed, &in_memory] {
        let tas: Vec<&str> = text
            .lines()
            .filter_map(|l| l.strip_prefix("TA"))
            .map(|l| l.split(' ').next().unwrap())
            .collect();
        // 900,000 ms in whole ms: 200 pieces of 4091 ms, 20 of 4090.
        assert_eq!(tas.len(), 220, "{text}");
        assert_eq!(tas.iter().filter(|&&ms| ms == "4091.0000").count(), 200);
        assert_eq!(tas.iter().filter(|&&ms| ms == "4090.0000").count(), 20);
        assert!(!text.contains("not whole ms"), "{text}");
        let pieces = pmac_pieces(text);
        for s in 0..=90_000 {
            let t = 900.0 * f64::from(s) / 90_000.0;
            let (a, b) = (position_at(&whole, t), position_at(&pieces, t));
            // PMAC text carries 6 decimals of position and velocity, 4 of ms.
            assert!((a - b).abs() < 1e-5, "t={t}: {a} vs {b}");
        }
    }
    // Quantized, every piece stays on the 1 ms grid.
    let o = pvtc(&["compile", "-", "--quantize", "1ms"], Some(program));
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8(o.stdout).unwrap();
    let pieces = pmac_pieces(&text);
    assert_eq!(pieces.len(), 220);
    for (t, _, _) in &pieces {
        let ms = t * 1000.0;
        assert!(ms <= 4095.0 && (ms - ms.round()).abs() < 1e-9, "{ms}");
    }
}

#[test]
fn pt_planner_is_refused_by_pmac_and_written_as_json() {
    let o = pvtc(
        &["compile", "samples/csv/an208_step.csv", "--planner", "pt"],
        None,
    );
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("pvtc::emit::unsupported_interpolation"),
        "{}",
        stderr(&o)
    );
    let j = pvtc(
        &[
            "compile",
            "samples/csv/an208_step.csv",
            "--planner",
            "pt",
            "--format",
            "json",
        ],
        None,
    );
    assert!(j.status.success(), "{}", stderr(&j));
    let v: serde_json::Value = serde_json::from_slice(&j.stdout).unwrap();
    assert_eq!(v["interpolation"], "pt");
}

#[test]
fn lspb_needs_an_acceleration() {
    let o = pvtc(
        &[
            "compile",
            "samples/gcode/an208_zigzag.ngc",
            "--planner",
            "lspb",
        ],
        None,
    );
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("pvtc::plan::missing_accel"),
        "{}",
        stderr(&o)
    );
    let ok = pvtc(
        &[
            "compile",
            "samples/gcode/an208_zigzag.ngc",
            "--planner",
            "lspb",
            "--accel",
            "400000",
        ],
        None,
    );
    assert!(ok.status.success(), "{}", stderr(&ok));
}

/// Asserts that `args` is refused as a usage error whose message contains `says`.
fn assert_usage(args: &[&str], says: &str) {
    let o = pvtc(args, None);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
    assert!(err.contains("pvtc::usage"), "{args:?}: {err}");
    assert!(err.contains(says), "{args:?}: {err}");
    assert!(o.stdout.is_empty(), "{args:?}");
}

#[test]
fn options_that_would_do_nothing_are_usage_errors() {
    let ngc = "samples/gcode/an208_zigzag.ngc";
    let csv = "samples/csv/an208_step.csv";
    let dxf = "samples/dxf/lines_arcs.dxf";
    // --time-slice: path (G-code default), contour, any CSV series.
    assert_usage(
        &["compile", ngc, "--time-slice", "5ms"],
        "--time-slice does nothing",
    );
    let contour = [
        "compile",
        ngc,
        "--planner",
        "contour",
        "--time-slice",
        "5ms",
    ];
    assert_usage(&contour, "with the contour planner");
    assert_usage(&["compile", csv, "--time-slice", "5ms"], "CSV series");
    let csv_pt = ["compile", csv, "--planner", "pt", "--time-slice", "5ms"];
    assert_usage(&csv_pt, "CSV series");
    // --accel: any planner but lspb.
    assert_usage(&["compile", ngc, "--accel", "1000"], "--accel does nothing");
    assert_usage(
        &["compile", csv, "--accel", "1000"],
        "with the spline planner",
    );
    let pt = ["compile", ngc, "--planner", "pt", "--accel", "1000"];
    assert_usage(&pt, "with the pt planner");
    // --layer: DXF only.
    assert_usage(&["compile", ngc, "--layer", "CUT"], "--layer does nothing");
    assert_usage(&["compile", csv, "--layer", "CUT"], "--layer does nothing");
    // -j: only with --out-dir.
    assert_usage(
        &["compile", ngc, "-j", "2"],
        "-j does nothing without --out-dir",
    );
    // The same options where they do something are accepted.
    let used = [
        vec![
            "compile",
            ngc,
            "--planner",
            "pt",
            "--time-slice",
            "5ms",
            "--format",
            "json",
        ],
        vec!["compile", ngc, "--planner", "lspb", "--accel", "400000"],
        vec!["compile", dxf, "--feed", "1200", "--layer", "CUT"],
    ];
    for args in used {
        let o = pvtc(&args, None);
        assert!(o.status.success(), "{args:?}: {}", stderr(&o));
    }
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let out = out.to_str().unwrap();
    let o = pvtc(&["compile", ngc, "--out-dir", out, "-j", "2"], None);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn a_duration_without_a_unit_is_a_usage_error_with_a_hint() {
    let ngc = "samples/gcode/an208_zigzag.ngc";
    for (option, value) in [("--quantize", "1"), ("--time-slice", "5")] {
        let o = pvtc(&["compile", ngc, "--planner", "pt", option, value], None);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{option}: {err}");
        assert!(err.contains("pvtc::usage"), "{option}: {err}");
        assert!(
            err.contains(&format!("write {value}ms or {value}s")),
            "{err}"
        );
    }
    let o = pvtc(&["check", ngc, "--servo-period", "0.5"], None);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("write 0.5ms or 0.5s"), "{}", stderr(&o));
    let o = pvtc(&["compile", ngc, "--quantize", "1ms"], None);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn inch_defaults_print_rounded_in_the_header() {
    let o = pvtc(&["compile", "-"], Some("G20 G90\nG1 X1 F10\nM2\n"));
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8(o.stdout).unwrap();
    assert!(
        text.contains("196.85 in/min (default 5000 mm/min)"),
        "{text}"
    );
    assert!(text.contains("0.0000393701 in"), "{text}");
    assert!(!text.contains("196.8503937"), "{text}");
}

#[test]
fn check_reports_seed_001_step_acceleration_as_json() {
    let o = pvtc(
        &[
            "check",
            "samples/csv/an208_step.csv",
            "--planner",
            "pt",
            "--servo-period",
            "500us",
            "--json",
        ],
        None,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let a = v["peaks"]["X"]["sampled_acceleration"].as_f64().unwrap();
    assert!(
        (a - 4.0e7).abs() <= 4.0e7 * 1e-6,
        "seed 001: 40 million counts/s², got {a}"
    );
    assert!((v["total_time"].as_f64().unwrap() - 1.75).abs() < 1e-9);
    assert!(v["max_path_error"].as_f64().is_some());
}

/// The servo period prints as a person would write it.
#[test]
fn check_prints_the_servo_period_in_plain_milliseconds() {
    for (given, shown) in [("50us", "0.05"), ("500us", "0.5"), ("1ms", "1")] {
        let o = pvtc(
            &["check", "samples/gcode/square.ngc", "--servo-period", given],
            None,
        );
        assert!(o.status.success(), "{}", stderr(&o));
        let text = String::from_utf8_lossy(&o.stdout);
        assert!(
            text.contains(&format!("(servo period {shown} ms)")),
            "{text}"
        );
    }
}

#[test]
fn check_names_a_dxf_line_for_every_peak_or_says_it_is_unknown() {
    // Rapids and entities inside blocks carry the line of an entity record.
    let o = pvtc(
        &["check", "samples/dxf/cad_part.dxf", "--feed", "1200"],
        None,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(!text.contains("line 0"), "{text}");
    assert!(!text.contains("unknown line"), "{text}");
    // A binary drawing has no lines to give.
    let o = pvtc(
        &["check", "samples/dxf/cad_part_binary.dxf", "--feed", "1200"],
        None,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(!text.contains("line 0"), "{text}");
    assert!(text.contains("unknown line"), "{text}");
}

#[test]
fn check_exits_1_when_a_limit_is_exceeded() {
    let o = pvtc(
        &[
            "check",
            "samples/gcode/an208_octagon.ngc",
            "--max-vel",
            "X=1000",
        ],
        None,
    );
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stdout).contains("LIMIT EXCEEDED: X velocity"));
    let ok = pvtc(
        &[
            "check",
            "samples/gcode/an208_octagon.ngc",
            "--max-vel",
            "X=1e9",
        ],
        None,
    );
    assert!(ok.status.success());
    assert!(String::from_utf8_lossy(&ok.stdout).contains("limits: none exceeded"));
}

#[test]
fn check_reads_a_pvtc_json_program() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("octagon.json");
    let c = pvtc(
        &[
            "compile",
            "samples/gcode/an208_octagon.ngc",
            "--format",
            "json",
            "-o",
            json.to_str().unwrap(),
        ],
        None,
    );
    assert!(c.status.success());
    let o = pvtc(&["check", json.to_str().unwrap(), "--json"], None);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let direct = pvtc(
        &["check", "samples/gcode/an208_octagon.ngc", "--json"],
        None,
    );
    let d: serde_json::Value = serde_json::from_slice(&direct.stdout).unwrap();
    assert_eq!(v["total_time"], d["total_time"]);
    for axis in ["X", "Y"] {
        for q in [
            "velocity",
            "acceleration",
            "jerk",
            "sampled_velocity",
            "sampled_acceleration",
        ] {
            let (a, b) = (
                v["peaks"][axis][q].as_f64().unwrap(),
                d["peaks"][axis][q].as_f64().unwrap(),
            );
            assert!(
                (a - b).abs() <= 1e-9 * a.abs().max(b.abs()),
                "{axis} {q}: {a} vs {b}"
            );
        }
    }
    assert!(
        v["max_path_error"].is_null(),
        "no geometry in a JSON program"
    );
}

#[test]
fn batch_compiles_a_folder_and_matches_single_runs() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let o = pvtc(
        &[
            "compile",
            "samples/gcode",
            "--out-dir",
            out.to_str().unwrap(),
            "--format",
            "json",
        ],
        None,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("files compiled, 0 failed"),
        "{}",
        stderr(&o)
    );
    for name in ["an208_octagon", "quad_circle_arc"] {
        let single = pvtc(
            &[
                "compile",
                &format!("samples/gcode/{name}.ngc"),
                "--format",
                "json",
            ],
            None,
        )
        .stdout;
        assert_eq!(
            std::fs::read(out.join(format!("{name}.json"))).unwrap(),
            single,
            "{name}"
        );
    }
}

#[test]
fn batch_mirrors_subfolders_under_the_out_dir() {
    let dir = tempfile::tempdir().unwrap();
    let inputs = dir.path().join("in");
    std::fs::create_dir_all(inputs.join("sub")).unwrap();
    std::fs::write(inputs.join("a.ngc"), "G1 X1 F100\n").unwrap();
    std::fs::write(inputs.join("sub/b.ngc"), "G1 X2 F100\n").unwrap();
    let out = dir.path().join("out");
    let o = pvtc(
        &[
            "compile",
            inputs.to_str().unwrap(),
            "--out-dir",
            out.to_str().unwrap(),
        ],
        None,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("2 files compiled, 0 failed"),
        "{}",
        stderr(&o)
    );
    assert!(out.join("a.pmac").is_file());
    assert!(out.join("sub/b.pmac").is_file());
}

#[test]
fn batch_keeps_going_past_a_bad_file_and_exits_1() {
    let dir = tempfile::tempdir().unwrap();
    let inputs = dir.path().join("in");
    std::fs::create_dir(&inputs).unwrap();
    std::fs::write(inputs.join("good.ngc"), "G1 X1 F100\n").unwrap();
    std::fs::write(inputs.join("bad.ngc"), BAD_LINE_3).unwrap();
    let out = dir.path().join("out");
    let o = pvtc(
        &[
            "compile",
            inputs.to_str().unwrap(),
            "--out-dir",
            out.to_str().unwrap(),
        ],
        None,
    );
    assert_eq!(o.status.code(), Some(1));
    let err = stderr(&o);
    assert!(
        err.contains("bad.ngc: pvtc::gcode::unknown_word (line 3)"),
        "{err}"
    );
    assert!(err.contains("1 files compiled, 1 failed"), "{err}");
    assert!(out.join("good.pmac").exists());
    assert!(!out.join("bad.pmac").exists());
    assert_eq!(
        std::fs::read_dir(&out).unwrap().count(),
        1,
        "no partial or temporary file"
    );
}

#[test]
fn plot_writes_an_svg() {
    let dir = tempfile::tempdir().unwrap();
    let svg = dir.path().join("octagon.svg");
    let o = pvtc(
        &[
            "plot",
            "samples/gcode/an208_octagon.ngc",
            "-o",
            svg.to_str().unwrap(),
        ],
        None,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.starts_with("<svg") && text.trim_end().ends_with("</svg>"));
}

#[test]
fn plot_refuses_an_output_named_for_another_format() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["part.jpg", "part"] {
        let png = dir.path().join(name);
        let o = pvtc(
            &[
                "plot",
                "samples/gcode/an208_octagon.ngc",
                "-o",
                png.to_str().unwrap(),
            ],
            None,
        );
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert!(err.contains("pvtc::usage"), "{err}");
        assert!(err.contains("FILE.svg"), "{err}");
        assert!(!png.exists(), "nothing written to {name}");
    }
    let upper = dir.path().join("PART.SVG");
    let o = pvtc(
        &[
            "plot",
            "samples/gcode/an208_octagon.ngc",
            "-o",
            upper.to_str().unwrap(),
        ],
        None,
    );
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn offsets_file_and_units_conversion_apply_to_gcode() {
    let dir = tempfile::tempdir().unwrap();
    let offsets = dir.path().join("offsets.txt");
    std::fs::write(&offsets, "# work offsets\nG55 X100 Y50\n").unwrap();
    let program = "G21 G90 G55\nG1 X10 Y0 F600\n";
    let o = pvtc(
        &[
            "compile",
            "-",
            "--format",
            "json",
            "--offsets",
            offsets.to_str().unwrap(),
        ],
        Some(program),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let last = v["contours"].as_array().unwrap().last().unwrap().clone();
    assert_eq!(last["segments"][0]["p"], serde_json::json!([110.0, 50.0]));
    let inch = pvtc(
        &["compile", "-", "--format", "json", "--units", "in"],
        Some("G21 G1 X25.4 F600\n"),
    );
    let v: serde_json::Value = serde_json::from_slice(&inch.stdout).unwrap();
    assert_eq!(v["units"], "in");
    assert_eq!(
        v["contours"][0]["segments"][0]["p"],
        serde_json::json!([1.0])
    );
    std::fs::write(&offsets, "G54 X1\nG60 X2\n").unwrap();
    let bad = pvtc(
        &["compile", "-", "--offsets", offsets.to_str().unwrap()],
        Some(program),
    );
    assert_eq!(bad.status.code(), Some(1));
    assert!(
        stderr(&bad).contains("pvtc::offsets::syntax"),
        "{}",
        stderr(&bad)
    );
}

/// A batch reads the offsets table once for the run: a bad one is one diagnostic with
/// its line, not one per job, and no output is written.
#[test]
fn a_batch_reads_the_offsets_file_once() {
    let dir = tempfile::tempdir().unwrap();
    let offsets = dir.path().join("offsets.txt");
    std::fs::write(&offsets, "G54 X1\nG60 X2\n").unwrap();
    let out = dir.path().join("out");
    let mut args = vec!["compile"];
    let inputs: Vec<String> = (0..3)
        .map(|i| {
            let p = dir.path().join(format!("p{i}.ngc"));
            std::fs::write(&p, "G21 G90 G55\nG1 X10 Y0 F600\n").unwrap();
            p.display().to_string()
        })
        .collect();
    args.extend(inputs.iter().map(String::as_str));
    args.extend(["--out-dir", out.to_str().unwrap()]);
    args.extend([
        "--offsets",
        offsets.to_str().unwrap(),
        "--diagnostics",
        "json",
    ]);
    let o = pvtc(&args, None);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let errors: Vec<serde_json::Value> = stderr(&o)
        .lines()
        .filter_map(|l| serde_json::from_str(l).ok())
        .collect();
    assert_eq!(errors.len(), 1, "{}", stderr(&o));
    assert_eq!(errors[0]["code"], "pvtc::offsets::syntax");
    assert_eq!(errors[0]["line"], 2);
    assert!(!out.exists() || std::fs::read_dir(&out).unwrap().next().is_none());
}

#[test]
fn a_dxf_the_dxf_crate_panics_on_is_a_clean_read_error() {
    let o = pvtc(
        &[
            "compile",
            "tests/fuzz-regressions/dxf_chrono_panic.dxf",
            "--feed",
            "1200",
        ],
        None,
    );
    assert_eq!(o.status.code(), Some(1));
    let err = stderr(&o);
    assert!(err.contains("pvtc::dxf::read"), "{err}");
    assert!(
        !err.contains("panicked"),
        "no panic trace for a caught panic: {err}"
    );
}

#[test]
fn a_drawing_over_the_point_limit_is_refused_before_it_is_parsed() {
    let text = std::fs::read_to_string(root().join("samples/dxf/polylines.dxf")).unwrap();
    let points = pvt_dxf::source::SourceMap::scan(text.as_bytes()).points;
    assert!(points > 3, "{points}");
    let limit = (points - 1).to_string();
    let args = [
        "compile",
        "samples/dxf/polylines.dxf",
        "--feed",
        "1000",
        "--max-points",
        &limit,
        "--diagnostics",
        "json",
    ];
    let o = pvtc(&args, None);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("pvtc::dxf::too_many_points"),
        "{}",
        stderr(&o)
    );
    assert!(stderr(&o).contains(&format!("holds {points} points")));
    let enough = points.to_string();
    let o = pvtc(&[&args[..5], &[enough.as_str()]].concat(), None);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn check_refuses_a_program_too_long_to_sample_instead_of_running_for_hours() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("long.json");
    let golden =
        std::fs::read_to_string(root().join("tests/golden/gcode/an208_octagon.json")).unwrap();
    // The first piece time becomes 1e300 s.
    let at = golden.find("\"t\": ").unwrap() + 5;
    let end = at + golden[at..].find([',', '}']).unwrap();
    let text = format!("{}1e300{}", &golden[..at], &golden[end..]);
    std::fs::write(&json, text).unwrap();
    let o = pvtc(
        &["check", json.to_str().unwrap(), "--diagnostics", "json"],
        None,
    );
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("pvtc::check::too_many_samples"),
        "{}",
        stderr(&o)
    );
    let o = pvtc(
        &[
            "check",
            "samples/gcode/an208_octagon.ngc",
            "--max-samples",
            "10",
            "--diagnostics",
            "json",
        ],
        None,
    );
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("over the limit of 10"),
        "{}",
        stderr(&o)
    );
}

/// A pvtc JSON program on X from rest at 0 through `(end, velocity, time, line)` pieces.
fn x_program(pieces: &[(f64, f64, f64, u32)]) -> String {
    let segments: Vec<String> = pieces
        .iter()
        .map(|(p, v, t, line)| {
            format!(r#"{{"p": [{p:?}], "v": [{v:?}], "t": {t:?}, "line": {line}}}"#)
        })
        .collect();
    format!(
        r#"{{"format": "pvtc-program", "version": 1, "units": "mm", "interpolation": "pvt", "axes": ["X"], "contours": [{{"kind": "feed", "start": [0.0], "segments": [{}]}}], "events": []}}"#,
        segments.join(", ")
    )
}

#[test]
fn check_into_a_closed_pipe_does_not_panic_and_still_reports_the_limits() {
    for (extra, code) in [(None, 0), (Some("X=1"), 1)] {
        let mut args = vec!["check", "samples/gcode/an208_octagon.ngc", "--json"];
        if let Some(limit) = extra {
            args.extend(["--max-vel", limit]);
        }
        let mut child = Command::new(env!("CARGO_BIN_EXE_pvtc"))
            .args(&args)
            .current_dir(root())
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        // The reader is gone before pvtc writes: its write fails with a broken pipe.
        drop(child.stdout.take());
        let o = child.wait_with_output().unwrap();
        assert_eq!(o.status.code(), Some(code), "{}", stderr(&o));
        assert!(!stderr(&o).contains("panicked"), "{}", stderr(&o));
    }
}

#[test]
fn check_default_samples_a_program_over_20_million_periods_and_still_refuses_1e300_s() {
    // 15000 s at 0.5 ms: 3·10^7 samples, refused by the old default of 2·10^7.
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("long.json");
    std::fs::write(&json, x_program(&[(100.0, 0.0, 15000.0, 3)])).unwrap();
    let o = pvtc(&["check", json.to_str().unwrap()], None);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let table = String::from_utf8_lossy(&o.stdout);
    assert!(table.contains("total time: 15000.000000 s"), "{table}");
    std::fs::write(&json, x_program(&[(100.0, 0.0, 1e300, 3)])).unwrap();
    let o = pvtc(
        &["check", json.to_str().unwrap(), "--diagnostics", "json"],
        None,
    );
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("over the limit of 1000000000"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn check_fails_an_acceleration_step_over_the_jerk_limit_naming_line_and_time() {
    // Piece 1, (0, 0) → (1, 1) in 1 s: a from 4 to −2; piece 2, (1, 1) → (1.5, 0) in
    // 0.5 s: a from 4 to −8 (a(0) = (6Δp − 4v₀T − 2v₁T)/T², a(T) = (−6Δp + 2v₀T + 4v₁T)/T²).
    // Steps over 1 ms: 4000 from rest at 0 s, 6000 at 1 s, 8000 back to rest at 1.5 s.
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("steps.json");
    std::fs::write(&json, x_program(&[(1.0, 1.0, 1.0, 1), (1.5, 0.0, 0.5, 2)])).unwrap();
    let json = json.to_str().unwrap();
    let args = ["check", json, "--servo-period", "1ms"];
    let o = pvtc(&[&args[..], &["--max-jerk", "X=7000"]].concat(), None);
    let table = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(1), "{table}");
    assert!(
        table.contains(
            "LIMIT EXCEEDED: X acceleration_step 8000.000000 > 7000.000000 at t=1.5000 s (line 2)"
        ),
        "{table}"
    );
    assert_eq!(table.matches("LIMIT EXCEEDED").count(), 1, "{table}");
    let o = pvtc(
        &[&args[..], &["--max-jerk", "X=3000", "--json"]].concat(),
        None,
    );
    assert_eq!(o.status.code(), Some(1));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let found: Vec<(String, u64, f64, f64)> = v["violations"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| {
            (
                v["quantity"].as_str().unwrap().to_string(),
                v["line"].as_u64().unwrap(),
                v["value"].as_f64().unwrap(),
                v["time"].as_f64().unwrap(),
            )
        })
        .collect();
    assert_eq!(found.len(), 2, "{found:?}");
    for ((q, line, value, time), want) in found.iter().zip([(1, 4000.0, 0.0), (2, 8000.0, 1.5)]) {
        assert_eq!((q.as_str(), *line), ("acceleration_step", want.0));
        assert!((value - want.1).abs() < 1e-6 && (time - want.2).abs() < 1e-9);
    }
    let step = &v["peaks"]["X"]["at"]["acceleration_step"];
    assert!((v["peaks"]["X"]["acceleration_step"].as_f64().unwrap() - 8000.0).abs() < 1e-6);
    assert_eq!(
        (step["line"].as_u64(), step["time"].as_f64()),
        (Some(2), Some(1.5))
    );
    let o = pvtc(&[&args[..], &["--max-jerk", "X=8000"]].concat(), None);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stdout)
    );
    // A machine file's servo period spreads the step: over 2 ms the largest is 4000.
    let machine = dir.path().join("m.toml");
    let file = |jerk: f64| {
        format!("units = \"mm\"\nservo_period = 0.002\n[axes.X]\nmax_velocity = 100\nmax_acceleration = 1000\nmax_jerk = {jerk:?}\n")
    };
    let check = ["check", json, "--machine", machine.to_str().unwrap()];
    std::fs::write(&machine, file(3500.0)).unwrap();
    let o = pvtc(&check, None);
    let table = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(1), "{table}{}", stderr(&o));
    assert!(
        table.contains("X acceleration_step 4000.000000 > 3500.000000"),
        "{table}"
    );
    std::fs::write(&machine, file(4000.0)).unwrap();
    assert_eq!(pvtc(&check, None).status.code(), Some(0));
}

const SQUARE: &str = "G21 G90\nG1 X100 F6000\nG1 Y100\nG1 X0\nG1 Y0\nM2\n";

#[test]
fn check_max_path_error_fails_seed_000_on_a_square_and_passes_the_path_planner() {
    let dir = tempfile::tempdir().unwrap();
    let square = dir.path().join("square.ngc");
    std::fs::write(&square, SQUARE).unwrap();
    let square = square.to_str().unwrap();
    let args = ["check", square, "--max-path-error", "0.001"];
    let o = pvtc(&[&args[..], &["--planner", "contour"]].concat(), None);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("pvtc::check::path_error"),
        "{}",
        stderr(&o)
    );
    // The table says so too: it does not end on "none exceeded" alone.
    let table = String::from_utf8_lossy(&o.stdout);
    assert!(table.contains("PATH ERROR EXCEEDED: "), "{table}");
    assert!(table.contains("> --max-path-error 0.001"), "{table}");
    let json = ["--planner", "contour", "--diagnostics", "json"];
    let o = pvtc(&[&args[..], &json].concat(), None);
    let err = stderr(&o);
    let values: Vec<serde_json::Value> = err
        .lines()
        .map(|l| serde_json::from_str(l).expect("a JSON object per line"))
        .collect();
    assert_eq!(values.len(), 1, "{err}");
    assert_eq!(values[0]["code"], "pvtc::check::path_error");
    let o = pvtc(&args, None);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let table = String::from_utf8_lossy(&o.stdout);
    assert!(!table.contains("PATH ERROR EXCEEDED"), "{table}");
}

#[test]
fn check_with_a_machine_file_passes_the_path_planner_and_fails_seed_000() {
    let args = [
        "check",
        "samples/dxf/cad_part.dxf",
        "--feed",
        "1200",
        "--machine",
        "samples/machines/mill.toml",
    ];
    let o = pvtc(&args, None);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let o = pvtc(&[&args[..], &["--planner", "contour"]].concat(), None);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let table = String::from_utf8_lossy(&o.stdout);
    assert!(table.contains("LIMIT EXCEEDED: X acceleration"), "{table}");
}

#[test]
fn check_with_a_jerk_limit_passes_the_path_planner_on_a_1ms_grid() {
    // mill.toml limits X and Y jerk; on the grid, pieces re-timed without re-planning
    // reached 4975 in/s³ of 1968.5 on cad_part.
    let args = [
        "check",
        "samples/dxf/cad_part.dxf",
        "--feed",
        "1200",
        "--machine",
        "samples/machines/mill.toml",
        "--quantize",
        "1ms",
    ];
    let o = pvtc(&args, None);
    let table = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{table}{}", stderr(&o));
    assert!(table.contains("limits: none exceeded"), "{table}");
}

#[test]
fn a_machine_file_without_a_moved_axis_is_refused_with_its_code() {
    let dir = tempfile::tempdir().unwrap();
    let machine = dir.path().join("m.toml");
    std::fs::write(
        &machine,
        "units = \"mm\"\n[axes.X]\nmax_velocity = 100\nmax_acceleration = 1000\n",
    )
    .unwrap();
    let o = pvtc(
        &[
            "compile",
            "-",
            "--machine",
            machine.to_str().unwrap(),
            "--diagnostics",
            "json",
        ],
        Some(SQUARE),
    );
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("pvtc::machine::missing_axis"),
        "{}",
        stderr(&o)
    );
    assert!(o.stdout.is_empty());
}

#[test]
fn quantized_path_motion_passes_check_with_the_machine_file_and_the_tolerance() {
    let dir = tempfile::tempdir().unwrap();
    let machine = dir.path().join("m.toml");
    let mut axes = String::from("units = \"mm\"\nservo_period = 0.0005\n");
    for axis in ["X", "Y", "Z"] {
        axes += &format!("[axes.{axis}]\nmax_velocity = 100\nmax_acceleration = 1000\n");
    }
    std::fs::write(&machine, axes).unwrap();
    let square = dir.path().join("square.ngc");
    std::fs::write(&square, format!("G64 P0.5\n{SQUARE}")).unwrap();
    let (machine, square) = (machine.to_str().unwrap(), square.to_str().unwrap());
    let o = pvtc(
        &[
            "compile",
            square,
            "--machine",
            machine,
            "--quantize",
            "1ms",
            "--diagnostics",
            "json",
        ],
        None,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!stderr(&o).contains("quantized_path"), "{}", stderr(&o));
    let args = [
        "check",
        square,
        "--machine",
        machine,
        "--quantize",
        "1ms",
        "--max-path-error",
        "0.5",
    ];
    let o = pvtc(&args, None);
    let table = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{table}{}", stderr(&o));
}

#[test]
fn deny_warnings_on_standard_input_writes_nothing() {
    // PMAC output of times that are not whole ms warns.
    let odd = "G21 G90\nG1 X10.123 F777\nM2\n";
    let o = pvtc(
        &[
            "compile",
            "-",
            "--deny-warnings",
            "--diagnostics",
            "json",
            "--quantize",
            "off",
        ],
        Some(odd),
    );
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("pvtc::deny_warnings"), "{}", stderr(&o));
    assert!(o.stdout.is_empty());
    let o = pvtc(
        &["compile", "-", "--deny-warnings", "--format", "json"],
        Some(odd),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!o.stdout.is_empty());
}

#[test]
fn plot_with_a_machine_file_draws_the_limits() {
    let dir = tempfile::tempdir().unwrap();
    let svg = dir.path().join("p.svg");
    let svg_name = svg.to_str().unwrap();
    let args = ["plot", "samples/gcode/square.ngc", "-o", svg_name];
    let o = pvtc(&args, None);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!std::fs::read_to_string(&svg).unwrap().contains("X limit"));
    let machine = ["--machine", "samples/machines/mill.toml"];
    let o = pvtc(&[&args[..], &machine].concat(), None);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(
        text.contains("X limit") && text.contains("Y limit"),
        "no limit lines"
    );
}

/// `-o` naming a FIFO (as `-o /dev/null` names a device) writes into it and leaves it a
/// FIFO: renaming a temporary file onto it would replace it with a regular file.
#[cfg(unix)]
#[test]
fn output_to_a_fifo_writes_through_it_and_keeps_it() {
    use std::os::unix::fs::FileTypeExt;
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("out.fifo");
    if !Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .is_ok_and(|s| s.success())
    {
        eprintln!("SKIPPED: no mkfifo on this machine");
        return;
    }
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || std::fs::read(fifo).unwrap())
    };
    let o = pvtc(
        &[
            "compile",
            "samples/gcode/square.ngc",
            "-o",
            fifo.to_str().unwrap(),
        ],
        None,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    // Checked before joining: had the FIFO been replaced, its reader would wait for ever.
    assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
    let written = reader.join().unwrap();
    assert!(String::from_utf8_lossy(&written).contains("CLOSE"));
}

#[test]
fn tool_table_offsets_apply_and_its_errors_name_the_line() {
    let dir = tempfile::tempdir().unwrap();
    let table = dir.path().join("tools.tbl");
    std::fs::write(&table, "T1 P1 Z12.7 D6 ;6 mm drill\nT2 P2 Z-5\n").unwrap();
    let program = "G21 G90\nG0 X1 Y0 Z0\nT1 M6 G43 H1\nG0 Z10\n";
    let run = |extra: &[&str]| {
        let mut args = vec!["compile", "-", "--format", "json"];
        args.extend_from_slice(extra);
        pvtc(&args, Some(program))
    };
    let o = run(&["--tool-table", table.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let last = v["contours"].as_array().unwrap().last().unwrap().clone();
    // Z10 with tool 1's 12.7 mm length: the machine Z is 22.7.
    assert_eq!(last["segments"][0]["p"], serde_json::json!([1.0, 22.7]));
    // The same table read in inches: 12.7 in is 322.58 mm.
    let o = run(&[
        "--tool-table",
        table.to_str().unwrap(),
        "--tool-table-units",
        "in",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let last = v["contours"].as_array().unwrap().last().unwrap().clone();
    let z = last["segments"][0]["p"][1].as_f64().unwrap();
    assert!((z - (10.0 + 12.7 * 25.4)).abs() < 1e-9, "{z}");
    let o = run(&["--tool-table-units", "in"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    // Without the table, H1 is an unknown tool.
    let o = run(&[]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("pvtc::gcode::unknown_tool"),
        "{}",
        stderr(&o)
    );
    // A bad word names its line and is labelled.
    std::fs::write(&table, "T1 Z1\nT2 Z1.x\n").unwrap();
    let o = run(&["--tool-table", table.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1));
    let err = stderr(&o);
    assert!(err.contains("pvtc::tool_table::syntax"), "{err}");
    assert!(err.contains("line 2: `Z1.x`"), "{err}");
    assert!(o.stdout.is_empty());
    let missing = dir.path().join("missing.tbl");
    let o = run(&["--tool-table", missing.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1));
}

/// `--format toolpath --deny-warnings` on a warning writes nothing, into a file or into
/// a pipe, and says so with `pvtc::deny_warnings` (it used to write the file first).
#[test]
fn toolpath_under_deny_warnings_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let program = dir.path().join("w.ngc");
    std::fs::write(&program, "G1 X5 F100\nG1 X5\nM2\n").unwrap();
    let out = dir.path().join("w.jsonl");
    let (program, out) = (program.to_str().unwrap(), out.to_str().unwrap());
    let args = [
        "compile",
        program,
        "--format",
        "toolpath",
        "--deny-warnings",
    ];
    let to_file = pvtc(&[&args[..], &["-o", out]].concat(), None);
    assert_eq!(to_file.status.code(), Some(1), "{}", stderr(&to_file));
    assert!(stderr(&to_file).contains("pvtc::deny_warnings"));
    assert!(!std::path::Path::new(out).exists(), "nothing written");
    let to_pipe = pvtc(&args, None);
    assert_eq!(to_pipe.status.code(), Some(1), "{}", stderr(&to_pipe));
    assert!(to_pipe.stdout.is_empty(), "nothing on the pipe");
    let allowed = pvtc(&args[..4], None);
    assert!(allowed.status.success() && !allowed.stdout.is_empty());
}

#[test]
fn negative_values_of_start_point_and_safe_z_read_as_separate_arguments() {
    let joined = pvtc(
        &[
            "compile",
            "samples/dxf/lines_arcs.dxf",
            "--feed",
            "1200",
            "--start-point=-10,-10",
            "--safe-z=-2",
            "--format",
            "json",
        ],
        None,
    );
    assert!(joined.status.success(), "{}", stderr(&joined));
    let separate = pvtc(
        &[
            "compile",
            "samples/dxf/lines_arcs.dxf",
            "--feed",
            "1200",
            "--start-point",
            "-10,-10",
            "--safe-z",
            "-2",
            "--format",
            "json",
        ],
        None,
    );
    assert!(separate.status.success(), "{}", stderr(&separate));
    assert_eq!(joined.stdout, separate.stdout);
    // The values reached the drawing: another start point and safe Z give another motion.
    let plain = pvtc(
        &[
            "compile",
            "samples/dxf/lines_arcs.dxf",
            "--feed",
            "1200",
            "--format",
            "json",
        ],
        None,
    );
    assert_ne!(plain.stdout, separate.stdout);
}

#[test]
fn a_machine_file_with_a_planner_that_cannot_keep_it_is_a_usage_error() {
    let machine = ["--machine", "samples/machines/mill.toml"];
    for planner in ["contour", "pt", "chord-forward", "spline", "lspb"] {
        let mut args = vec!["compile", "samples/gcode/square.ngc", "--planner", planner];
        if planner == "lspb" {
            args.extend(["--accel", "1000"]);
        }
        args.extend(machine);
        let o = pvtc(&args, None);
        assert_eq!(o.status.code(), Some(2), "{planner}: {}", stderr(&o));
        assert!(stderr(&o).contains("pvtc::usage"), "{}", stderr(&o));
        assert!(
            stderr(&o).contains("only by the path planner"),
            "{}",
            stderr(&o)
        );
        assert!(o.stdout.is_empty());
    }
    // The path planner keeps it; `check` still takes it with any planner, to verify.
    let o = pvtc(
        &[&["compile", "samples/gcode/square.ngc"][..], &machine].concat(),
        None,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let check = [
        "check",
        "samples/gcode/square.ngc",
        "--planner",
        "contour",
        "--machine",
        "samples/machines/mill.toml",
    ];
    assert_eq!(pvtc(&check, None).status.code(), Some(1));
}

/// Every planner, with `--machine`: either its output passes `pvtc check --machine`
/// against the same file, or the compile is a usage error naming the planner that keeps
/// limits; none compiles and ignores the file.
#[test]
fn a_machine_file_is_kept_or_refused_by_every_planner() {
    let dir = tempfile::tempdir().unwrap();
    let machine = "samples/machines/mill.toml";
    let mut kept = Vec::new();
    for planner in pvt_core::Planner::ALL {
        let out = dir.path().join(format!("{}.json", planner.name()));
        let mut args = vec![
            "compile",
            "samples/gcode/square.ngc",
            "--planner",
            planner.name(),
            "--machine",
            machine,
            "--format",
            "json",
            "-o",
            out.to_str().unwrap(),
        ];
        if planner == pvt_core::Planner::Lspb {
            args.extend(["--accel", "1000"]);
        }
        let o = pvtc(&args, None);
        if o.status.code() == Some(2) {
            assert!(stderr(&o).contains("pvtc::usage"), "{}", stderr(&o));
            assert!(
                stderr(&o).contains("only by the path planner"),
                "{}",
                stderr(&o)
            );
            assert!(!out.exists(), "{}: output written", planner.name());
            continue;
        }
        assert!(o.status.success(), "{}: {}", planner.name(), stderr(&o));
        let check = pvtc(
            &["check", out.to_str().unwrap(), "--machine", machine],
            None,
        );
        let table = String::from_utf8_lossy(&check.stdout);
        assert_eq!(check.status.code(), Some(0), "{}: {table}", planner.name());
        assert!(table.contains("limits: none exceeded"), "{table}");
        kept.push(planner.name());
    }
    assert_eq!(kept, ["path"]);
}

#[test]
fn drawing_options_on_a_program_are_usage_errors() {
    for option in [
        &["--safe-z", "5"][..],
        &["--start-point", "1,1"],
        &["--join-tolerance", "0.1"],
        &["--max-points", "10"],
        &["--layer", "CUT"],
    ] {
        let o = pvtc(
            &[&["compile", "samples/gcode/square.ngc"][..], option].concat(),
            None,
        );
        assert_eq!(o.status.code(), Some(2), "{option:?}: {}", stderr(&o));
        let expected = format!("{} does nothing here", option[0]);
        assert!(stderr(&o).contains(&expected), "{}", stderr(&o));
    }
}

/// The passes a compile takes over its G-code input, counted on this thread: one into a
/// file, the null device (`-o /dev/null` is no slower than a file) or a pipe (through a
/// temporary file), two into a stream written directly (a checking pass first), and
/// the same bytes every way.
#[cfg(unix)]
#[test]
fn files_null_device_and_pipes_take_one_pass_and_a_direct_stream_two() {
    use clap::Parser;
    let dir = tempfile::tempdir().unwrap();
    let program = common::root().join("samples/gcode/an208_zigzag.ngc");
    let program = program.to_str().unwrap();
    let passes = |output: &str| {
        let before = pvtc::route::front_end_passes();
        let cli = pvtc::Cli::parse_from(["pvtc", "compile", program, "-o", output]);
        assert_eq!(pvtc::run(cli), std::process::ExitCode::SUCCESS);
        pvtc::route::front_end_passes() - before
    };
    let file = dir.path().join("out.pmac");
    assert_eq!(passes("/dev/null"), 1);
    assert_eq!(passes(file.to_str().unwrap()), 1);
    let fifo = dir.path().join("fifo");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    assert!(made.unwrap().success(), "mkfifo");
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || std::fs::read(fifo).unwrap())
    };
    assert_eq!(passes(fifo.to_str().unwrap()), 1);
    assert_eq!(reader.join().unwrap(), std::fs::read(&file).unwrap());

    let args = pvtc::Cli::parse_from(["pvtc", "compile", program]);
    let pvtc::Command::Compile(args) = args.command else {
        unreachable!("a compile command")
    };
    let options = args.compile_options(program).unwrap();
    let mut piped = Vec::new();
    let before = pvtc::route::front_end_passes();
    let mut stream = pvtc::output::Target::Stream(&mut piped);
    let warnings = pvtc::route::compile_to(program.as_ref(), &options, false, &mut stream);
    assert!(warnings.is_ok());
    assert_eq!(pvtc::route::front_end_passes() - before, 2);
    assert_eq!(piped, std::fs::read(&file).unwrap());
}

/// The piece times a PMAC program's `TA` words give, in ms, summed.
fn pmac_total_ms(text: &str) -> f64 {
    text.lines()
        .filter_map(|l| l.strip_prefix("TA"))
        .map(|l| l.split(' ').next().unwrap().parse::<f64>().unwrap())
        .sum()
}

/// PMAC text carries positions to 10⁻⁹, so the planner keeps no room for its rounding
/// worth speaking of: under mill.toml's jerk limit on a 1 ms grid an inch program's PMAC
/// text takes the time of its JSON (with 6 decimals it took 16.6 times as long), and of
/// its millimetre twin's PMAC text within 1 % (the twins differ by 0.77 % in JSON too: the
/// plan's own arithmetic in other units, not the text).
#[test]
fn an_inch_program_and_its_mm_twin_take_the_same_time_as_pmac_text() {
    let inch = "G20 G90 G17\nG1 X1 Y0 F40\nG3 X1.5 Y0.5 I0 J0.5\nG1 X1.5 Y1.2\nG1 X0.2 Y1.3\n";
    let mm = "G21 G90 G17\nG1 X25.4 Y0 F1016\nG3 X38.1 Y12.7 I0 J12.7\nG1 X38.1 Y30.48\n\
              G1 X5.08 Y33.02\n";
    let grid = [
        "--machine",
        "samples/machines/mill.toml",
        "--quantize",
        "1ms",
    ];
    let compile = |program: &str, format: &str| {
        let args = [&["compile", "-", "--format", format][..], &grid].concat();
        let o = pvtc(&args, Some(program));
        assert!(o.status.success(), "{}", stderr(&o));
        String::from_utf8(o.stdout).unwrap()
    };
    let json_ms = |program: &str| {
        let json: serde_json::Value = serde_json::from_str(&compile(program, "json")).unwrap();
        json["contours"]
            .as_array()
            .unwrap()
            .iter()
            .flat_map(|c| c["segments"].as_array().unwrap())
            .map(|s| s["t"].as_f64().unwrap() * 1000.0)
            .sum::<f64>()
    };
    let inch_ms = pmac_total_ms(&compile(inch, "pmac"));
    let mm_ms = pmac_total_ms(&compile(mm, "pmac"));
    for (pmac, json) in [(inch_ms, json_ms(inch)), (mm_ms, json_ms(mm))] {
        assert!(pmac > 0.0);
        assert!(
            (pmac - json).abs() < 1e-6 * json,
            "PMAC {pmac} ms, JSON {json} ms"
        );
    }
    assert!(
        (inch_ms - mm_ms).abs() < 0.01 * mm_ms,
        "inch {inch_ms} ms, mm {mm_ms} ms"
    );
}

#[test]
fn a_tolerance_finer_than_the_smallest_is_a_usage_error() {
    let ngc = "samples/gcode/an208_octagon.ngc";
    for option in ["--tolerance", "--corner-tolerance"] {
        let o = pvtc(&["compile", ngc, option, "1e-200", "-o", "-"], None);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{option}: {err}");
        assert!(err.contains("must be at least 0.000001"), "{option}: {err}");
        assert!(o.stdout.is_empty(), "{option}");
        let o = pvtc(&["compile", ngc, option, "0.000001", "-o", "-"], None);
        assert!(o.status.success(), "{option}: {}", stderr(&o));
    }
}

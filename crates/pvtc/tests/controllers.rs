//! The controller formats from the command line: their rules as coded errors naming the
//! source line, counts per unit, travel limits from the machine file, `--quantize off`.

use std::process::Output;

mod common;
use common::pvtc;

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn machine(dir: &std::path::Path, extra: &str) -> String {
    let path = dir.join("m.toml");
    let text = format!(
        "units = \"mm\"\n[axes.X]\nmax_velocity = 100.0\nmax_acceleration = 1000.0\n{extra}\n\
         [axes.Y]\nmax_velocity = 100.0\nmax_acceleration = 1000.0\n"
    );
    std::fs::write(&path, text).unwrap();
    path.display().to_string()
}

const PROGRAM: &str = "G21 G90\nG1 X5 Y0 F600\nG1 X10 Y2\nM2\n";

#[test]
fn counts_formats_without_counts_per_unit_fail_with_nothing_written() {
    for format in ["galil", "zaber"] {
        let o = pvtc(&["compile", "-", "--format", format], Some(PROGRAM));
        assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
        assert!(
            stderr(&o).contains("pvtc::emit::no_scale"),
            "{}",
            stderr(&o)
        );
        assert!(o.stdout.is_empty());
        let o = pvtc(
            &[
                "compile",
                "-",
                "--format",
                format,
                "--counts-per-unit",
                "X=1000",
                "--counts-per-unit",
                "Y=1000",
            ],
            Some(PROGRAM),
        );
        assert!(o.status.success(), "{}", stderr(&o));
    }
}

#[test]
fn a_move_past_the_travel_limit_is_refused_at_its_line_in_every_format() {
    let dir = tempfile::tempdir().unwrap();
    let m = machine(dir.path(), "max_position = 8\ncounts_per_unit = 1000");
    let input = dir.path().join("p.ngc");
    std::fs::write(&input, PROGRAM).unwrap();
    let input = input.display().to_string();
    for format in ["pmac", "xps", "galil", "csv", "powerpmac", "json"] {
        let mut args = vec![
            "compile",
            input.as_str(),
            "--machine",
            &m,
            "--format",
            format,
        ];
        if format == "galil" {
            args.extend(["--counts-per-unit", "Y=1000"]);
        }
        let o = pvtc(&args, None);
        assert_eq!(o.status.code(), Some(1), "{format}: {}", stderr(&o));
        let e = stderr(&o);
        assert!(e.contains("pvtc::emit::travel_limit"), "{format}: {e}");
        assert!(e.contains("source line 3"), "{format}: {e}");
        assert!(o.stdout.is_empty());
    }
    // Within the travel it compiles.
    let roomy = machine(dir.path(), "max_position = 10.5");
    let o = pvtc(
        &["compile", &input, "--machine", &roomy, "--format", "xps"],
        None,
    );
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn lspb_pieces_under_the_xps_shortest_are_merged_by_its_grid_or_refused_without() {
    let sample = "samples/gcode/grbl_r_arcs.ngc";
    let base = ["compile", sample, "--planner", "lspb", "--accel", "1e5"];
    let mut args = base.to_vec();
    args.extend(["--format", "xps", "--quantize", "off"]);
    let o = pvtc(&args, None);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("pvtc::emit::piece_too_short"),
        "{}",
        stderr(&o)
    );
    // By default the XPS output is on a grid of its shortest element, 100 µs.
    let mut args = base.to_vec();
    args.extend(["--format", "xps"]);
    let o = pvtc(&args, None);
    assert!(o.status.success(), "{}", stderr(&o));
    for line in String::from_utf8(o.stdout).unwrap().lines() {
        let t: f64 = line.split(',').next().unwrap().trim().parse().unwrap();
        assert!(t >= 1e-4 * (1.0 - 1e-9), "{line}");
    }
}

#[test]
fn a_grid_the_galil_cannot_take_is_refused_and_off_is_no_grid() {
    let counts = ["--counts-per-unit", "X=1000", "--counts-per-unit", "Y=1000"];
    let mut args = vec!["compile", "-", "--format", "galil", "--quantize", "1ms"];
    args.extend(counts);
    let o = pvtc(&args, Some(PROGRAM));
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("pvtc::emit::piece_time_off_grid"),
        "{}",
        stderr(&o)
    );
    // PMAC with --quantize off plans freely, and warns that PMAC rounds TA.
    let o = pvtc(&["compile", "-", "--quantize", "off"], Some(PROGRAM));
    assert!(o.status.success());
    assert!(
        stderr(&o).contains("pvtc::emit::fractional_ms"),
        "{}",
        stderr(&o)
    );
    let o = pvtc(&["compile", "-", "--quantize", "2"], Some(PROGRAM));
    assert_eq!(o.status.code(), Some(2), "a bare number is a usage error");
}

#[test]
fn check_reads_the_emitted_pmac_text_and_names_a_line_it_cannot_read() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("zigzag.pmac");
    let out = out.display().to_string();
    let o = pvtc(
        &["compile", "samples/gcode/an208_zigzag.ngc", "-o", &out],
        None,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    // The time the controller runs: the sum of the TA times in the text.
    let text = std::fs::read_to_string(&out).unwrap();
    let written: f64 = text
        .lines()
        .filter_map(|l| l.strip_prefix("TA"))
        .map(|l| l.split(' ').next().unwrap().parse::<f64>().unwrap() / 1000.0)
        .sum();
    let o = pvtc(&["check", &out, "--json"], None);
    assert!(o.status.success(), "{}", stderr(&o));
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let total = report["total_time"].as_f64().unwrap();
    assert!((total - written).abs() < 1e-9, "{total} for {written}");
    // A broken move line is refused with its line.
    let line = text.lines().position(|l| l.starts_with("TA")).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_owned).collect();
    lines[line] = lines[line].replacen(':', ":1x", 1);
    std::fs::write(&out, lines.join("\n")).unwrap();
    let o = pvtc(&["check", &out], None);
    assert_eq!(o.status.code(), Some(1));
    let e = stderr(&o);
    assert!(e.contains("pvtc::check::read_back"), "{e}");
    assert!(e.contains(&format!("line {}:", line + 1)), "{e}");
}

#[test]
fn check_takes_a_csv_table_as_the_pieces_it_holds() {
    let dir = tempfile::tempdir().unwrap();
    let table = dir.path().join("zigzag.csv").display().to_string();
    let o = pvtc(
        &[
            "compile",
            "samples/gcode/an208_zigzag.ngc",
            "--format",
            "csv",
            "-o",
            &table,
        ],
        None,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    // From the table itself: the last row's time, and the largest |vX| of any row.
    let text = std::fs::read_to_string(&table).unwrap();
    let rows: Vec<Vec<f64>> = text
        .lines()
        .skip(1)
        .map(|r| r.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    let end = rows.last().unwrap()[0];
    let vx = rows.iter().map(|r| r[2].abs()).fold(0.0, f64::max);
    let args = [
        "check",
        &table,
        "--planner",
        "chord-forward",
        "--velocities",
        "file",
        "--json",
    ];
    let o = pvtc(&args, None);
    assert!(o.status.success(), "{}", stderr(&o));
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let total = report["total_time"].as_f64().unwrap();
    assert!((total - end).abs() < 1e-9, "{total} for {end}");
    let peak = report["peaks"]["X"]["velocity"].as_f64().unwrap();
    assert!(peak >= vx * (1.0 - 1e-12), "{peak} below a knot's {vx}");
}

#[test]
fn trigger_intervals_need_a_unit_and_a_format_that_takes_them() {
    let o = pvtc(&["compile", "-", "--trigger-every", "5"], Some(PROGRAM));
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("5mm"), "{}", stderr(&o));
    let o = pvtc(
        &["compile", "-", "--trigger-every", "2mm", "--format", "xps"],
        Some(PROGRAM),
    );
    assert_eq!(o.status.code(), Some(1));
    let e = stderr(&o);
    assert!(e.contains("pvtc::emit::no_triggers"), "{e}");
    assert!(e.contains("MultipleAxesPVTPulseOutputSet"), "{e}");
    assert!(o.stdout.is_empty());
    // PMAC: 0.2 in is 5.08 mm; the 10.4 mm path has two triggers, each an M1 edge.
    let o = pvtc(&["compile", "-", "--trigger-every", "0.2in"], Some(PROGRAM));
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8(o.stdout).unwrap();
    let edges: Vec<&str> = text.lines().filter(|l| l.starts_with("M1==")).collect();
    assert_eq!(edges, ["M1==1", "M1==0"], "{text}");
}

#[test]
fn check_reads_a_csv_table_with_its_trigger_column() {
    let dir = tempfile::tempdir().unwrap();
    let table = dir.path().join("zigzag.csv").display().to_string();
    let args = [
        "compile",
        "samples/gcode/an208_zigzag.ngc",
        "--format",
        "csv",
        "--trigger-every",
        "0.5s",
        "-o",
        &table,
    ];
    let o = pvtc(&args, None);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(&table).unwrap();
    assert!(text.lines().next().unwrap().ends_with(",trigger"), "{text}");
    let fired = text.lines().skip(1).filter(|r| r.ends_with(",1")).count();
    assert!(fired > 0, "{text}");
    let end: f64 = text
        .lines()
        .last()
        .unwrap()
        .split(',')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    let args = [
        "check",
        &table,
        "--planner",
        "chord-forward",
        "--velocities",
        "file",
        "--json",
    ];
    let o = pvtc(&args, None);
    assert!(o.status.success(), "{}", stderr(&o));
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let total = report["total_time"].as_f64().unwrap();
    assert!((total - end).abs() < 1e-9, "{total} for {end}");
    // A trigger field other than 0 or 1 is an error at its row and column.
    let bad = text.replacen(",1\n", ",2\n", 1);
    std::fs::write(&table, bad).unwrap();
    let o = pvtc(&["check", &table], None);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("pvtc::csv::bad_trigger"),
        "{}",
        stderr(&o)
    );
}

/// Runs `pvtc ARGS` into a pipe with no temporary directory to write in: the pipe is
/// written directly, after a first pass that checks the program.
fn piped_without_temporary_files(args: &[&str], dir: &std::path::Path) -> Output {
    common::command(args)
        .env("TMPDIR", dir.join("no such directory"))
        .stdin(std::process::Stdio::null())
        .output()
        .expect("pvtc runs")
}

/// Into a pipe, the output is written to a temporary file and piped once whole; where no
/// temporary file can be made, a first pass checks the program as the back end would
/// without making its text. Either way every format's refusals (travel, counts,
/// triggers, piece times) and warnings are those of the same compile into a file, a
/// refused program sends the pipe nothing, and a program it keeps is piped whole, byte
/// for byte the file's.
#[test]
fn a_pipe_is_refused_and_warned_as_a_file_is_in_every_format() {
    let dir = tempfile::tempdir().unwrap();
    let travel = machine(dir.path(), "max_position = 8\ncounts_per_unit = 1000");
    let roomy_dir = dir.path().join("roomy");
    std::fs::create_dir(&roomy_dir).unwrap();
    let roomy = machine(&roomy_dir, "max_position = 50\ncounts_per_unit = 1000");
    // Long enough that the text written before the move past the travel fills the
    // output's buffers many times over.
    let mut program = String::from("G21 G90 F600\n");
    for i in 0..1500 {
        program += &format!("G1 X{} Y{:.3}\n", 5 * (i % 2), 0.001 * f64::from(i));
    }
    program += "G1 X10 Y2\nM2\n";
    let input = dir.path().join("p.ngc");
    std::fs::write(&input, program).unwrap();
    let input = input.display().to_string();
    let out = dir.path().join("out").display().to_string();
    let counts = ["--counts-per-unit", "X=1000", "--counts-per-unit", "Y=1000"];
    let formats = pvt_emit::Format::ALL.map(pvt_emit::Format::name);
    let mut refused = 0;
    for format in formats {
        for extra in [
            vec!["--machine", travel.as_str()],
            vec!["--machine", roomy.as_str(), "--trigger-every", "5ms"],
            vec!["--quantize", "off"],
        ] {
            let mut args = vec!["compile", input.as_str(), "--format", format];
            args.extend(&extra);
            if matches!(format, "galil" | "zaber") {
                args.extend(counts);
            }
            let piped = [
                pvtc(&args, None),
                piped_without_temporary_files(&args, dir.path()),
            ];
            args.extend(["-o", out.as_str()]);
            let _ = std::fs::remove_file(&out);
            let filed = pvtc(&args, None);
            for (piped, how) in piped.iter().zip(["spooled", "checked first"]) {
                let what = format!("{format} {extra:?} {how}");
                assert_eq!(piped.status.code(), filed.status.code(), "{what}");
                assert_eq!(stderr(piped), stderr(&filed), "{what}");
                if filed.status.success() {
                    assert_eq!(piped.stdout, std::fs::read(&out).unwrap(), "{what}");
                } else {
                    assert!(piped.stdout.is_empty(), "{what}");
                    assert!(std::fs::metadata(&out).is_err(), "{what}");
                }
            }
            if !filed.status.success() {
                refused += 1;
            }
        }
    }
    // Travel in every format, triggers where the controller has none, piece times.
    assert!(refused >= 8 + 3, "{refused} refused");
}

/// MovePVT holds a contour's velocity and time arrays until the contour ends, past 64 KiB
/// in a temporary file: where none can be made (a pipe without a temporary directory),
/// it holds them in memory, and the pipe gets the whole program, byte for byte the file's.
#[test]
fn movepvt_without_temporary_files_holds_its_arrays_in_memory() {
    let dir = tempfile::tempdir().unwrap();
    let mut program = String::from("G21 G90 F600\n");
    for i in 1..=6000 {
        program += &format!("G1 X{} Y{:.3}\n", 5 * (i % 2), 0.001 * f64::from(i));
    }
    program += "M2\n";
    let input = dir.path().join("long.ngc");
    std::fs::write(&input, program).unwrap();
    let input = input.display().to_string();
    let out = dir.path().join("long.c").display().to_string();
    let args = [
        "compile",
        input.as_str(),
        "--format",
        "movepvt",
        "--quantize",
        "off",
    ];
    let piped = piped_without_temporary_files(&args, dir.path());
    assert!(
        piped.status.success(),
        "{}",
        String::from_utf8_lossy(&piped.stderr)
    );
    let filed = pvtc(&[&args[..], &["-o", out.as_str()]].concat(), None);
    assert!(filed.status.success());
    let written = std::fs::read(&out).unwrap();
    assert!(
        written.len() > 3 * 64 * 1024,
        "{} bytes: past the bound",
        written.len()
    );
    assert_eq!(piped.stdout, written);
}

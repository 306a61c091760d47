//! The planners' names and what they say about themselves: headers and `--help` name the
//! methods in words, each chord method by its own name, PT into MovePT arrays, and which
//! velocities a CSV series is planned with.

mod common;

use common::{run as pvtc, text};

use std::process::{Command, Output};

const PLANNERS: [&str; 8] = [
    "path",
    "contour",
    "pt",
    "chord-forward",
    "chord-back",
    "const-accel",
    "spline",
    "lspb",
];

#[test]
fn headers_and_help_name_the_methods_in_words_not_seed_numbers() {
    let help = text(&pvtc(&["compile", "--help"]).stdout);
    assert!(!help.to_lowercase().contains("seed"), "{help}");
    for name in PLANNERS {
        assert!(help.contains(name), "--help does not name {name}");
    }
    assert!(help.contains("incoming chord") && help.contains("outgoing chord"));
    for planner in PLANNERS {
        for format in ["pmac", "movepvt", "json"] {
            let mut args = vec![
                "compile",
                "samples/csv/an208_zigzag.csv",
                "--planner",
                planner,
                "--format",
                format,
            ];
            if planner == "lspb" {
                args.extend(["--accel", "1e6"]);
            }
            let o = pvtc(&args);
            let out = text(&o.stdout);
            if (planner, format) == ("pt", "pmac") {
                // PMAC's PVT mode needs velocities: refused, with a hint.
                assert_eq!(o.status.code(), Some(1));
                continue;
            }
            assert!(
                o.status.success(),
                "{planner} {format}: {}",
                text(&o.stderr)
            );
            let planner_line = out
                .lines()
                .find(|l| l.contains("planner"))
                .unwrap_or_else(|| panic!("{planner} {format}: no planner line\n{out}"));
            assert!(
                !planner_line.to_lowercase().contains("seed"),
                "{planner} {format}: {planner_line}"
            );
            assert!(
                planner_line.contains(&format!("{planner} (")),
                "{planner} {format}: {planner_line}"
            );
        }
    }
}

#[test]
fn chord_is_an_alias_of_chord_forward_and_chord_back_differs() {
    let run = |planner: &str| {
        let o = pvtc(&[
            "compile",
            "samples/csv/an208_step.csv",
            "--planner",
            planner,
            "--velocities",
            "plan",
            "--format",
            "json",
        ]);
        assert!(o.status.success(), "{planner}: {}", text(&o.stderr));
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        v["contours"][0]["segments"]
            .as_array()
            .unwrap()
            .iter()
            .map(|s| s["v"][0].as_f64().unwrap())
            .collect::<Vec<f64>>()
    };
    let forward = run("chord-forward");
    assert_eq!(run("chord"), forward);
    // AN208 table 1, 5000 counts in 0.25 s: the forward difference puts 20000 counts/s
    // on the point before the step, the backward difference on the point after it.
    assert_eq!(forward, vec![0.0, 0.0, 20000.0, 0.0, 0.0, 0.0, 0.0]);
    assert_eq!(
        run("chord-back"),
        vec![0.0, 0.0, 0.0, 20000.0, 0.0, 0.0, 0.0]
    );
}

fn codes(o: &Output) -> Vec<String> {
    text(&o.stderr)
        .lines()
        .filter(|l| l.starts_with('{'))
        .map(|l| {
            let v: serde_json::Value = serde_json::from_str(l).unwrap();
            format!(
                "{} {}",
                v["severity"].as_str().unwrap(),
                v["code"].as_str().unwrap()
            )
        })
        .collect()
}

fn compile_csv(sample: &str, extra: &[&str]) -> Output {
    let mut args = vec![
        "compile",
        sample,
        "--format",
        "json",
        "--diagnostics",
        "json",
    ];
    args.extend(extra);
    pvtc(&args)
}

#[test]
fn velocity_columns_are_used_or_ignored_as_asked_and_never_silently() {
    let zigzag = "samples/csv/an208_zigzag.csv";
    // Default: the columns are used by every velocity method, and a note says so.
    let by_file: Vec<Vec<u8>> = ["chord-forward", "chord-back", "const-accel", "spline"]
        .iter()
        .map(|planner| {
            let o = compile_csv(zigzag, &["--planner", planner, "--deny-warnings"]);
            assert!(o.status.success(), "{planner}: {}", text(&o.stderr));
            assert_eq!(codes(&o)[0], "advice pvtc::plan::file_velocities");
            let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
            serde_json::to_vec(&v["contours"]).unwrap()
        })
        .collect();
    assert!(by_file.windows(2).all(|w| w[0] == w[1]));
    // --velocities plan: each method's own velocities, all different.
    let planned: Vec<Vec<u8>> = ["chord-forward", "chord-back", "const-accel", "spline"]
        .iter()
        .map(|planner| {
            let o = compile_csv(zigzag, &["--planner", planner, "--velocities", "plan"]);
            assert!(o.status.success(), "{planner}: {}", text(&o.stderr));
            assert_eq!(codes(&o)[0], "advice pvtc::plan::velocity_columns_ignored");
            let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
            serde_json::to_vec(&v["contours"]).unwrap()
        })
        .collect();
    for i in 0..planned.len() {
        for j in i + 1..planned.len() {
            assert_ne!(planned[i], planned[j], "methods {i} and {j} agree");
        }
    }
    // A planner that takes no velocities ignores the columns with a warning.
    let o = compile_csv(zigzag, &["--planner", "pt"]);
    assert!(codes(&o).contains(&"warning pvtc::plan::velocities_ignored".to_string()));
    // --velocities file where it cannot apply is a usage error.
    for extra in [
        &["--planner", "pt", "--velocities", "file"][..],
        &["--planner", "chord-back", "--velocities", "file"][..],
    ] {
        let sample = if extra[1] == "pt" {
            zigzag
        } else {
            "samples/csv/an208_octagon.csv"
        };
        let o = compile_csv(sample, extra);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {}", text(&o.stderr));
        assert!(o.stdout.is_empty());
    }
    let o = pvtc(&[
        "compile",
        "samples/gcode/an208_zigzag.ngc",
        "--velocities",
        "plan",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o.stderr));
}

#[test]
fn the_contour_planner_on_a_series_says_it_replaces_the_times() {
    let o = compile_csv(
        "samples/csv/an208_octagon.csv",
        &["--planner", "contour", "--deny-warnings"],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(codes(&o).contains(&"advice pvtc::plan::times_replaced".to_string()));
    let o = compile_csv(
        "samples/csv/an208_octagon.csv",
        &["--planner", "chord-back"],
    );
    assert!(!codes(&o).iter().any(|c| c.ends_with("times_replaced")));
}

#[test]
fn pt_into_movepvt_is_movept_arrays_that_compile_and_pmac_points_there() {
    let pmac = pvtc(&[
        "compile",
        "samples/gcode/an208_zigzag.ngc",
        "--planner",
        "pt",
        "--diagnostics",
        "json",
    ]);
    assert_eq!(pmac.status.code(), Some(1));
    let hint: serde_json::Value =
        serde_json::from_str(text(&pmac.stderr).lines().next().unwrap()).unwrap();
    assert_eq!(hint["code"], "pvtc::emit::unsupported_interpolation");
    assert!(hint["help"]
        .as_str()
        .unwrap()
        .contains("--format movepvt (MovePT arrays)"));
    let dir = tempfile::tempdir().unwrap();
    let c_file = dir.path().join("zigzag_pt.c");
    let o = pvtc(&[
        "compile",
        "samples/gcode/an208_zigzag.ngc",
        "--planner",
        "pt",
        "--format",
        "movepvt",
        "-o",
        c_file.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let c = std::fs::read_to_string(&c_file).unwrap();
    assert!(c.contains("MovePT(pvtc_cN_position, pvtc_cN_time") && !c.contains("_velocity[]"));
    // The positions are the program's points: the zigzag's corners.
    assert!(
        c.contains("    5000.0, 0.0,\n    0.0, 10000.0,\n    5000.0, 1000.0,\n"),
        "{c}"
    );
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    if Command::new(&cc).arg("--version").output().is_err() {
        eprintln!("SKIPPED: compiling, no C compiler `{cc}` on this machine");
        return;
    }
    let user = dir.path().join("user.c");
    std::fs::write(
        &user,
        "#include \"zigzag_pt.c\"\n\
         double first(void);\n\
         double first(void) { return pvtc_c1_position[0] + pvtc_c1_time[0] \
         + (double)PVTC_C1_POINTS + (double)pvtc_contours[0].count; }\n",
    )
    .unwrap();
    for file in [&c_file, &user] {
        let o = Command::new(&cc)
            .args(["-std=c99", "-Wall", "-Wextra", "-Werror", "-c", "-o"])
            .arg(dir.path().join("out.o"))
            .arg(file)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", text(&o.stderr));
    }
}

/// The summary compares the time with length / feed only where there is a feed: a point
/// series has none, so it gives no ratio (it used to print `inf x length / feed`).
#[test]
fn the_summary_of_a_series_has_no_feed_ratio() {
    let series = pvtc(&["compile", "samples/csv/an208_step.csv", "--planner", "path"]);
    let said = text(&series.stderr);
    assert!(series.status.success(), "{said}");
    assert!(said.contains("pvtc::plan::summary"), "{said}");
    assert!(
        !said.contains("inf") && !said.contains("length / feed"),
        "{said}"
    );
    let program = pvtc(&["compile", "samples/gcode/square.ngc"]);
    let words = text(&program.stderr).replace('│', " ");
    let words: Vec<&str> = words.split_whitespace().collect();
    assert!(words.join(" ").contains("x length / feed"), "{words:?}");
}

/// The rows of a CSV series with a `t` column, read here: (t, positions, velocities).
fn series_rows(sample: &str) -> Vec<Vec<f64>> {
    let text = std::fs::read_to_string(common::root().join(sample)).unwrap();
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with('t'))
        .map(|l| l.split(',').map(|v| v.trim().parse().unwrap()).collect())
        .collect()
}

#[test]
fn a_series_keeps_its_times_and_velocities_by_default() {
    // AN208's step: 8 points 0.25 s apart, at rest for 0.75 s, a step, at rest again.
    let sample = "samples/csv/an208_step.csv";
    let rows = series_rows(sample);
    let o = compile_csv(sample, &[]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let program = pvt_emit::json::read(&text(&o.stdout)).unwrap();
    let pieces: Vec<_> = program
        .contours
        .iter()
        .flat_map(|c| (0..c.len()).map(move |i| c.segment(i)))
        .collect();
    assert_eq!(pieces.len(), rows.len() - 1);
    for (piece, (before, row)) in pieces.iter().zip(rows.iter().zip(&rows[1..])) {
        assert!((piece.duration - (row[0] - before[0])).abs() < 1e-12);
        assert_eq!(piece.end[0], row[1]);
        assert_eq!(piece.velocity[0], row[2], "the vx column, as given");
    }
    let total: f64 = pieces.iter().map(|p| p.duration).sum();
    assert!((total - 1.75).abs() < 1e-12, "{total}");
    // The header names the planner, and leaves out rapid and feed, which a series has not.
    let header = text(&pvtc(&["compile", sample]).stdout);
    assert!(header.contains("spline ("), "{header}");
    assert!(!header.contains("rapid") && !header.contains("default feed"));
    // contour stays one option away, and replaces the times.
    let o = compile_csv(sample, &["--planner", "contour"]);
    assert!(o.status.success() && codes(&o).iter().any(|c| c.ends_with("times_replaced")));
}

#[test]
fn options_that_do_nothing_for_a_series_are_usage_errors() {
    let sample = "samples/csv/an208_zigzag.csv";
    let dir = tempfile::tempdir().unwrap();
    let offsets = dir.path().join("offsets.txt");
    std::fs::write(&offsets, "G54 X100 Y50 Z-20\n").unwrap();
    for extra in [
        &["--feed", "100"][..],
        &["--rapid", "1000"],
        &["--tolerance", "0.01"],
        &["--tolerance", "0.01", "--planner", "chord-back"],
        &["--corner-tolerance", "0.01"],
        &["--safe-z", "5"],
        &["--start-point", "1,2"],
        &["--join-tolerance", "0.1"],
        &["--max-points", "10"],
        &["--arc-abs-tolerance", "0.1"],
        &["--offsets", offsets.to_str().unwrap()],
    ] {
        let o = compile_csv(sample, extra);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {}", text(&o.stderr));
        assert!(o.stdout.is_empty());
        assert!(
            codes(&o).contains(&"error pvtc::usage".to_string()),
            "{:?}",
            codes(&o)
        );
        assert!(
            text(&o.stderr).contains(extra[0]),
            "{extra:?}: {}",
            text(&o.stderr)
        );
    }
    // The path planner reads a tolerance and a corner tolerance on a series too.
    let o = compile_csv(
        sample,
        &[
            "--planner",
            "path",
            "--tolerance",
            "0.01",
            "--corner-tolerance",
            "0.01",
        ],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
}

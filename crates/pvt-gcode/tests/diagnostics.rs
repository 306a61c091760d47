//! Each diagnostic code, asserted with its exact line and column.

mod common;

use common::errors;
use pvt_gcode::{compile, line_col, GcodeOptions};

const HEAD: &str = "G21 G90 F100\nG0 X0 Y0\n";

/// The errors of `HEAD` followed by `body` (so `body` starts on line 3).
fn after_head(body: &str) -> Vec<(&'static str, usize, usize)> {
    errors(&format!("{HEAD}{body}"))
}

#[test]
fn syntax_errors_name_line_and_column() {
    assert_eq!(after_head("G1 X--1\n"), [("syntax", 3, 4)]);
    assert_eq!(after_head("G1 X1 (open\n"), [("syntax", 3, 7)]);
    assert_eq!(after_head("G1 Y3e2\n"), [("syntax", 3, 6)]);
}

#[test]
fn a_bad_word_on_line_3_names_line_3() {
    let source = "G21\nG0 X1\nG1 X2 Y%3 F100\nG1 X3\n";
    let errors = compile(source, &GcodeOptions::default()).unwrap_err();
    assert_eq!(errors.diagnostics.len(), 1);
    let d = &errors.diagnostics[0];
    assert_eq!(line_col(source, d.span().start), (3, 7));
    assert_eq!(&source[d.span()], "Y%3");
}

#[test]
fn every_bad_line_is_reported() {
    let got = after_head("G1 X--1\nG1 X2\nG1 Y.\nE5\nG1 X(\n");
    assert_eq!(
        got,
        [
            ("syntax", 3, 4),
            ("syntax", 5, 4),
            ("unknown_word", 6, 1),
            ("syntax", 7, 4)
        ]
    );
}

#[test]
fn unknown_words() {
    assert_eq!(after_head("G1 X1 E5\n"), [("unknown_word", 3, 7)]);
    assert_eq!(after_head("G1 X1 ~\n"), [("unknown_word", 3, 7)]);
    assert_eq!(after_head("G1.5 X1\n"), [("unknown_word", 3, 1)]);
    assert_eq!(after_head("M1000\n"), [("unknown_word", 3, 1)]);
}

#[test]
fn unsupported_features_are_named() {
    let source = format!("{HEAD}G76 X1 Z-1\n");
    let errors = compile(&source, &GcodeOptions::default()).unwrap_err();
    let messages: Vec<_> = errors.diagnostics.iter().map(ToString::to_string).collect();
    assert_eq!(
        messages,
        ["G76 is spindle-synchronised: a time-based PVT program cannot follow a spindle encoder"]
    );
    assert_eq!(after_head("G95 X1\n"), [("spindle_sync", 3, 1)]);
    assert_eq!(after_head("G1 X1 M60\n"), [("unsupported", 3, 7)]);
    assert_eq!(
        after_head("G1 X#<_hal[motion.probe-input]>\n"),
        [("unsupported", 3, 5)]
    );
    assert_eq!(after_head("G1 X#5063\n"), [("unsupported", 3, 5)]);
    assert_eq!(after_head("G38.2 Z-5\n"), [("probe", 3, 1)]);
}

#[test]
fn conflicts_and_repeats() {
    assert_eq!(after_head("G0 G1 X1\n"), [("conflicting_motion", 3, 4)]);
    assert_eq!(after_head("G1 G2 X1 I1\n"), [("conflicting_motion", 3, 4)]);
    assert_eq!(after_head("G20 G21\n"), [("conflicting_modes", 3, 5)]);
    assert_eq!(after_head("G1 X1 X2\n"), [("repeated_axis", 3, 7)]);
    assert_eq!(after_head("G1 X1 F1 F2\n"), [("repeated_word", 3, 10)]);
}

#[test]
fn arc_errors() {
    assert_eq!(
        after_head("G2 X10 Y0 I4.9 J0\n"),
        [("arc_radius_mismatch", 3, 1)]
    );
    assert_eq!(
        after_head("G2 X10 Y0 R4\n"),
        [("arc_radius_too_small", 3, 11)]
    );
    assert_eq!(after_head("G2 X10 Y0\n"), [("arc_missing_center", 3, 1)]);
    assert_eq!(
        after_head("G1 X1\nG2 X10 Y0\n"),
        [("arc_missing_center", 4, 1)]
    );
    assert_eq!(
        after_head("G2 X10 Y0 I5 R5\n"),
        [("arc_r_with_center", 3, 14)]
    );
    assert_eq!(after_head("G2 X0 Y0 R5\n"), [("arc_full_circle_r", 3, 10)]);
    assert_eq!(after_head("G3 R5\n"), [("arc_full_circle_r", 3, 4)]);
    assert_eq!(after_head("G2 X10 I0 J0\n"), [("arc_zero_radius", 3, 8)]);
    assert_eq!(after_head("G2 X10 K5\n"), [("arc_offset_off_plane", 3, 8)]);
    assert_eq!(
        after_head("G18 G2 X10 J5\n"),
        [("arc_offset_off_plane", 3, 12)]
    );
    assert_eq!(
        after_head("G19 G2 Y10 I5\n"),
        [("arc_offset_off_plane", 3, 12)]
    );
}

#[test]
fn arc_radius_mismatch_names_both_radii() {
    let source = format!("{HEAD}G2 X10 Y0 I4.9 J0\n");
    let errors = compile(&source, &GcodeOptions::default()).unwrap_err();
    let message = errors.diagnostics[0].to_string();
    assert_eq!(
        message,
        "arc start radius 4.9 mm and end radius 5.1 mm differ by 0.2 mm"
    );
}

#[test]
fn feed_errors() {
    assert_eq!(errors("G21\nG1 X1\nX2\n"), [("no_feed", 2, 1)]);
    assert_eq!(errors("G1 X1 F0\n"), [("zero_feed", 1, 7)]);
    assert_eq!(errors("F0\nG0 X1\nG1 X2\nX3\n"), [("zero_feed", 3, 1)]);
    assert_eq!(errors("G1 X1 F-5\n"), [("zero_feed", 1, 7)]);
    // F0 is harmless for rapids.
    assert!(compile("F0\nG0 X1\n", &GcodeOptions::default()).is_ok());
    // A default feed replaces the missing F.
    let options = GcodeOptions {
        default_feed: Some(120.0),
        ..GcodeOptions::default()
    };
    let compiled = compile("G1 X1\n", &options).unwrap();
    assert_eq!(compiled.toolpath.contours[0].elements[0].feed, 2.0);
}

#[test]
fn motion_mode_errors() {
    assert_eq!(errors("X1 Y1\nG0 X2\n"), [("no_motion_mode", 1, 1)]);
    assert_eq!(after_head("G80 X1\n"), [("no_motion_mode", 3, 5)]);
    assert_eq!(after_head("G1 X1 I1\n"), [("arc_word_without_arc", 3, 7)]);
}

#[test]
fn no_motion() {
    for source in [
        "",
        "\n\n",
        "(only a comment)\n; another\n",
        "%\nG21 G90\n%\n",
        "\u{feff}",
    ] {
        assert_eq!(errors(source), [("no_motion", 1, 1)], "{source:?}");
    }
}

#[test]
fn out_of_range() {
    let huge = format!("G91 G0 X{big}\nX{big}\n", big = "9".repeat(308));
    assert_eq!(errors(&huge), [("out_of_range", 2, 1)]);
}

#[test]
fn warnings_do_not_fail() {
    let compiled = common::ok("G0 X1\nG0 X1\nM2\nG0 X5\n");
    let codes: Vec<_> = compiled
        .warnings
        .iter()
        .map(|w| (w.code(), w.is_warning()))
        .collect();
    assert_eq!(
        codes,
        [
            ("pvtc::gcode::rapid_to_current_point", true),
            ("pvtc::gcode::after_program_end", true)
        ]
    );
}

#[test]
fn a_rapid_to_the_current_point_is_a_note_and_a_feed_move_a_warning() {
    use miette::{Diagnostic, Severity};
    let compiled = common::ok("G0 X0 Y0\nG1 X1 F100\nG1 X1\nG0 X1\nM2\n");
    let found: Vec<_> = compiled
        .warnings
        .iter()
        .map(|w| (w.code(), w.severity()))
        .collect();
    assert_eq!(
        found,
        [
            (
                "pvtc::gcode::rapid_to_current_point",
                Some(Severity::Advice)
            ),
            ("pvtc::gcode::zero_length_move", Some(Severity::Warning)),
            (
                "pvtc::gcode::rapid_to_current_point",
                Some(Severity::Advice)
            ),
        ]
    );
}

#[test]
fn errors_render_with_miette() {
    let source = format!("{HEAD}G1 X--1\nG2 X10 Y0 I4.9 J0\n");
    let errors = compile(&source, &GcodeOptions::default()).unwrap_err();
    let report =
        miette::Report::new(errors).with_source_code(miette::NamedSource::new("part.ngc", source));
    let mut rendered = String::new();
    miette::NarratableReportHandler::new()
        .render_report(&mut rendered, report.as_ref())
        .unwrap();
    println!("{rendered}");
    assert!(
        rendered.contains("the G-code program has 2 errors"),
        "{rendered}"
    );
    assert!(rendered.contains("pvtc::gcode::syntax"), "{rendered}");
    assert!(
        rendered.contains("pvtc::gcode::arc_radius_mismatch"),
        "{rendered}"
    );
    assert!(rendered.contains("part.ngc"), "{rendered}");
    assert!(rendered.contains("line 3, columns 4 to 7"), "{rendered}");
}

#[test]
fn issue_4_codes_name_line_and_column() {
    assert_eq!(after_head("G1 X[1/0]\n"), [("math_error", 3, 7)]);
    assert_eq!(
        after_head("G1 X#<depth>\n"),
        [("undefined_parameter", 3, 5)]
    );
    assert_eq!(after_head("G1 X1 *3\n"), [("checksum_mismatch", 3, 7)]);
    assert_eq!(after_head("G4\n"), [("missing_word", 3, 1)]);
    assert_eq!(after_head("G92\n"), [("missing_word", 3, 1)]);
    assert_eq!(after_head("G93 G1 X5\n"), [("inverse_time_feed", 3, 5)]);
    assert_eq!(after_head("T-1\n"), [("bad_value", 3, 1)]);
    assert_eq!(after_head("G4 P-1\n"), [("bad_value", 3, 4)]);
    assert_eq!(after_head("G2 X0 Y0 I5 P0\n"), [("bad_value", 3, 13)]);
    assert_eq!(after_head("G1 X#0\n"), [("out_of_range", 3, 5)]);
    assert_eq!(after_head("G10 L20 P1 R45\n"), [("bad_value", 3, 12)]);
    assert_eq!(after_head("G10 L1 P1 Z1\n"), [("unknown_tool", 3, 8)]);
    assert_eq!(after_head("G10 P1 X1\n"), [("missing_word", 3, 1)]);
    assert_eq!(after_head("o100 sub\n"), [("oword", 3, 1)]);
    assert_eq!(after_head("o100 jump\n"), [("oword", 3, 1)]);
    assert_eq!(after_head("o100 call\n"), [("unknown_subroutine", 3, 1)]);
    assert_eq!(after_head("G43 H1\n"), [("unknown_tool", 3, 5)]);
    assert_eq!(after_head("G81 X1 Z-1\n"), [("cycle", 3, 1)]);
}

#[test]
fn unsupported_features_are_reported_once_with_their_count() {
    let source = format!("{HEAD}M60\nM60\nG17.1\nM60\n");
    let errors = compile(&source, &GcodeOptions::default()).unwrap_err();
    let messages: Vec<_> = errors
        .diagnostics
        .iter()
        .filter(|d| d.code() == "pvtc::gcode::unsupported")
        .map(ToString::to_string)
        .collect();
    assert_eq!(
        messages,
        [
            "M60 (pallet change) is not supported by pvtc (3 places; the first is shown)",
            "G17.1 (UVW planes) is not supported by pvtc"
        ]
    );
}

#[test]
fn ignored_words_are_warnings() {
    // A program number is a name, not a warning.
    let source = "O10\nG21 G1 X1 F100 P2 $1\nM2\n";
    let compiled = compile(source, &GcodeOptions::default()).unwrap();
    let warnings: Vec<_> = compiled
        .warnings
        .iter()
        .map(|w| (w.code(), line_col(source, w.span().start)))
        .collect();
    assert_eq!(
        warnings,
        [
            ("pvtc::gcode::ignored_word", (2, 16)),
            ("pvtc::gcode::ignored_word", (2, 19))
        ]
    );
    assert!(compiled.warnings.iter().all(|w| w.is_warning()));
}

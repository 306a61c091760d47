//! What decides how long a part takes, as LinuxCNC runs it: the order of a block's steps
//! (F before G20/G21), feeds kept in the units they were set in, G94/G95 resetting the
//! feed, M70–M73's saved modal state, spindle-synchronised motion at the programmed S,
//! and arcs within LinuxCNC's radius rule run as spirals. Each expected number is
//! worked out here from the program's words.

mod common;

use common::{elements, errors, ok};
use pvt_core::{Element, ElementKind, EventKind};
use pvt_gcode::{compile, GcodeOptions, SpindleSync};

/// The feed of each element, per minute.
fn feeds(source: &str) -> Vec<f64> {
    elements(&ok(source))
        .iter()
        .map(|e| e.feed * 60.0)
        .collect()
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-9 * b.abs().max(1.0)
}

#[test]
fn f_is_read_before_the_units_of_its_block() {
    // The V-carve's start: F6 then G20 in one block is 6 mm/min, 6 / 25.4 in/min.
    let c = ok("G20 F6\nG1 X1\nM2\n");
    assert!(close(elements(&c)[0].feed * 60.0, 6.0 / 25.4));
    let warning = &c.warnings[0];
    assert_eq!(warning.code(), "pvtc::gcode::feed_before_units");
    let text = warning.to_string();
    assert!(
        text.contains("6 mm/min") && text.contains("not 6 in/min"),
        "{text}"
    );
    // On a line before the units, F6 is in inches.
    let c = ok("G20\nF6\nG1 X1\nM2\n");
    assert!(close(elements(&c)[0].feed * 60.0, 6.0));
    assert!(c.warnings.is_empty(), "{:?}", c.warnings);
    // A units word that changes nothing reads F as it always would: no warning.
    let c = ok("G21\nG21 F6 G1 X1\nM2\n");
    assert!(close(elements(&c)[0].feed * 60.0, 6.0));
    assert!(c.warnings.is_empty(), "{:?}", c.warnings);
}

#[test]
fn a_feed_keeps_the_units_it_was_set_in() {
    // LinuxCNC converts F when it is set: 254 mm/min stays 254 mm/min (10 in/min) after
    // G20, and 10 in/min stays 254 mm/min after G21.
    let f = feeds("G21 F254\nG1 X10\nG20\nG1 X1\nM2\n");
    assert!(close(f[0], 254.0) && close(f[1], 254.0), "{f:?}");
    let f = feeds("G20\nF10\nG1 X1\nG21\nG1 X50\nM2\n");
    assert!(
        close(f[0], 10.0) && close(f[1], 10.0),
        "{f:?} (output in inches)"
    );
}

#[test]
fn g94_and_g95_set_the_feed_to_zero() {
    // LinuxCNC: `F100` then `G94` leaves F0, and a feed move needs a new F.
    assert_eq!(
        errors("G21 F100\nG1 X1\nG94\nG1 X2\nM2\n"),
        [("zero_feed", 4, 1)]
    );
    let text = compile("G21 F100\nG94\nG1 X2\nM2\n", &GcodeOptions::default())
        .unwrap_err()
        .diagnostics[0]
        .to_string();
    assert!(text.contains("G94 sets the feed to 0"), "{text}");
    // In its own block, G94 comes before F: `G94 F100` feeds at 100.
    assert!(close(feeds("G21 F50\nG94 F100 G1 X1\nM2\n")[0], 100.0));
    // G93 does not: back in G94 after it the feed is 0 too (the G94 resets it).
    assert_eq!(
        errors("G21 F100\nG93 G1 X1 F2\nG94\nG1 X2\nM2\n"),
        [("zero_feed", 4, 1)]
    );
}

/// The spindle events of a compile, in order.
fn spindle(c: &pvt_gcode::Compiled) -> Vec<String> {
    c.toolpath
        .events
        .iter()
        .filter_map(|e| match &e.kind {
            EventKind::Spindle { state } => Some(format!("{state:?}")),
            EventKind::SpindleSpeed { rpm } => Some(format!("S{rpm}")),
            _ => None,
        })
        .collect()
}

#[test]
fn m6_stops_the_spindle_and_s_comes_before_m3() {
    let c = ok("G21 F100\nM3 S1000 T1\nG1 X1\nM6\nG1 X2\nM2\n");
    assert_eq!(spindle(&c), ["S1000", "Clockwise", "Off"]);
}

#[test]
fn m70_m72_restore_feed_speed_units_and_distance() {
    // LinuxCNC's toplevel.ngc: F200 S1200 G90 saved, F50 S120 G91 after, M72 back.
    let c = ok("G21 F200 S1200 G90\nM70\nF50 S120 G91\nG1 X5\nM72\nG1 X6\nM71\nM2\n");
    let e = elements(&c);
    assert!(close(e[0].feed * 60.0, 50.0) && close(e[0].end[0], 5.0));
    // G90 again: X6 is absolute; F200 again.
    assert!(close(e[1].feed * 60.0, 200.0) && close(e[1].end[0], 6.0));
    assert_eq!(spindle(&c), ["S1200", "S120", "S1200"]);
    // Units come back first, so the restored F is read in them.
    let e = elements(&ok("G21 F100\nM70\nG20\nF2\nG1 X1\nM72\nG1 X50\nM2\n"));
    assert!(close(e[1].feed * 60.0, 100.0), "{:?}", e[1]);
    // M72 after M71 (or without M70) restores nothing.
    assert_eq!(
        errors("G21 F100\nM70\nM71\nM72\nG1 X1\nM2\n"),
        [("no_saved_state", 4, 1)]
    );
    // F is restored with one decimal, as rs274 writes it.
    let e = elements(&ok("G21 F100.26\nM70\nF5\nM72\nG1 X1\nM2\n"));
    assert!(close(e[0].feed * 60.0, 100.3), "{}", e[0].feed * 60.0);
}

#[test]
fn m73_restores_when_the_subroutine_returns() {
    let program = "o<inch> sub\nM73\nG20 G91\nF5\nG1 X1\no<inch> endsub\n\
                   G21 G90 F200\no<inch> call\nG1 X10\nM2\n";
    let e = elements(&ok(program));
    // In the subroutine: 1 in at 5 in/min (the output is in millimetres).
    assert!(close(e[0].end[0], 25.4) && close(e[0].feed * 60.0, 127.0));
    // Back: G21 G90 F200.
    assert!(close(e[1].end[0], 10.0) && close(e[1].feed * 60.0, 200.0));
    // At the top level M73 saves without restoring on return (as rs274 does).
    let e = elements(&ok("G21 F200\nM73\nF5\nG1 X1\nM72\nG1 X2\nM2\n"));
    assert!(close(e[1].feed * 60.0, 200.0));
}

fn exact() -> GcodeOptions {
    GcodeOptions {
        spindle_sync: SpindleSync::ProgrammedSpeed,
        ..GcodeOptions::default()
    }
}

#[test]
fn spindle_synchronised_motion_is_refused_by_default() {
    for program in [
        "G21 S500 M3\nG95 F0.1\nG1 X1\nM2\n",
        "G21 S500 M3\nG33 Z-10 K1.5\nM2\n",
        "G21 S500 M3\nG33.1 Z-10 K1.25\nM2\n",
        "G21 S500 M3 G18\nG76 P1.5 Z-10 I-1 J0.1 K0.9\nM2\n",
    ] {
        let e = compile(program, &GcodeOptions::default()).unwrap_err();
        let codes: Vec<_> = e.diagnostics.iter().map(|d| d.code()).collect();
        assert_eq!(codes, ["pvtc::gcode::spindle_sync"], "{program}");
    }
}

#[test]
fn spindle_synchronised_motion_runs_at_the_programmed_speed() {
    let run = |program: &str| compile(program, &exact()).expect("compiles");
    // G95: 0.1 mm/rev at 500 rpm is 50 mm/min.
    let c = run("G21 S500 M3\nG95 F0.1\nG1 X1\nM2\n");
    assert!(close(elements(&c)[0].feed * 60.0, 50.0));
    assert_eq!(c.warnings[0].code(), "pvtc::gcode::spindle_rpm_exact");
    // G33: 1.5 mm/rev at 500 rpm is 750 mm/min, a contour of its own.
    let c = run("G21 S500 M3 F100\nG1 X1\nG33 Z-10 K1.5\nG1 X2\nM2\n");
    assert_eq!(c.toolpath.contours.len(), 3);
    assert!(close(elements(&c)[1].feed * 60.0, 750.0));
    // G33.1: in at 1.25 × 400 and out at twice that (I2), back where it started.
    let c = run("G21 S400 M3\nG0 Z5\nG33.1 Z-10 K1.25 I2\nM2\n");
    let e = elements(&c);
    assert!(close(e[1].feed * 60.0, 500.0) && close(e[1].end[2], -10.0));
    assert!(close(e[2].feed * 60.0, 1000.0) && close(e[2].end[2], 5.0));
}

#[test]
fn g76_makes_linuxcnc_passes() {
    // External thread from X10 Z1 to Z-10: crest 1 below the start, first cut 0.2,
    // depth 0.6 (degression 1): passes at 1.2, 1.4 and 1.6 (the full depth), each at
    // pitch × S = 1.5 × 200 = 300 mm/min over Z1 → Z-10.
    let program = "G21 G18 S200 M3\nG0 X10 Z1\nG76 P1.5 Z-10 I-1 J0.2 K0.6\nM2\n";
    let c = compile(program, &exact()).expect("compiles");
    let e = elements(&c);
    let cuts: Vec<&Element> = e.iter().filter(|e| e.feed * 60.0 < 1000.0).collect();
    let depths: Vec<f64> = cuts.iter().map(|e| 10.0 - e.end[0]).collect();
    assert_eq!(cuts.len(), 3, "{depths:?}");
    for (depth, want) in depths.iter().zip([1.2, 1.4, 1.6]) {
        assert!((depth - want).abs() < 1e-9, "{depths:?}");
    }
    for cut in &cuts {
        assert!(
            close(cut.feed * 60.0, 300.0) && close(cut.start[2], 1.0) && close(cut.end[2], -10.0)
        );
    }
    // It ends at the block's end point.
    let last = e.last().expect("moves");
    assert!(close(last.end[0], 10.0) && close(last.end[2], -10.0));
}

#[test]
fn an_arc_within_linuxcnc_rule_is_a_spiral() {
    // Radius 100 to 100.05 (beyond 0.0283 mm, within 0.1 %): LinuxCNC runs it, the
    // radius changing along the arc; the element keeps both radii.
    let c = ok("G21 F100\nG0 X100\nG3 X0 Y100.05 I-100\nM2\n");
    let e = elements(&c);
    let ElementKind::Arc(arc) = e[1].kind else {
        panic!("an arc: {:?}", e[1]);
    };
    let radius = |p: &[f64; 6]| libm::hypot(p[0] - arc.center[0], p[1] - arc.center[1]);
    assert!(close(radius(&e[1].start), 100.0) && close(radius(&e[1].end), 100.05));
    assert_eq!(arc.direction, pvt_core::ArcDirection::CounterClockwise);
}

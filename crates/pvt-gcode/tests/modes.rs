//! Issue 4 modes and the streaming API: offsets, units, G53, G61, G93, events, sinks, and
//! a round trip of random lines and arcs.

mod common;

use common::{elements, errors, ok};
use proptest::prelude::*;
use pvt_core::{Element, ElementKind, EventKind, Motion, Units};
use pvt_gcode::{compile, compile_into, GcodeOptions, ToolpathSink};

#[test]
fn work_offsets_g92_and_g53() {
    let mut options = GcodeOptions::default();
    options.work_offsets[1] = [100.0, 50.0, 0.0, 0.0, 0.0, 0.0];
    let c = compile(
        "G21 G55 G0 X1 Y1\nG92 X0\nG0 X2\nG53 G0 X0\nG92.1 G54 G0 X3\n",
        &options,
    )
    .unwrap();
    let e = elements(&c);
    assert_eq!(e[0].end[..2], [101.0, 51.0]);
    assert_eq!(e[1].end[0], 103.0, "G92 made 101 read 0");
    assert_eq!(e[2].end[0], 0.0, "G53 is machine coordinates");
    assert_eq!(e[3].end[0], 3.0);
}

#[test]
fn units_option_converts_the_output() {
    let options = GcodeOptions {
        units: Some(Units::Millimetre),
        ..GcodeOptions::default()
    };
    let c = compile("G20\nG1 X1 F10\n", &options).unwrap();
    assert_eq!(c.toolpath.units, Units::Millimetre);
    assert!((elements(&c)[0].end[0] - 25.4).abs() < 1e-12);
    assert!((elements(&c)[0].feed - 254.0 / 60.0).abs() < 1e-12);
}

#[test]
fn exact_stop_ends_each_move_and_g64_records_p() {
    let c = ok("G21 F100 G61 G1 X1\nX2\nG64 P0.05 X3\nX4\n");
    let lens: Vec<_> = c
        .toolpath
        .contours
        .iter()
        .map(|c| c.elements.len())
        .collect();
    assert_eq!(lens, [1, 1, 2]);
    assert_eq!(c.path_tolerance, Some(0.05));
}

#[test]
fn inverse_time_feed_is_length_over_time() {
    let c = ok("G21 G93 G1 X30 F2\n");
    // 30 mm in half a minute.
    assert!((elements(&c)[0].feed - 1.0).abs() < 1e-12);
}

#[test]
fn events_end_contours_and_keep_their_place() {
    let c = ok("G21 F100 G1 X1\nS500 M3\nG1 X2\nG4 P2\n(MSG, done)\nM0\nG1 X3\nM2\n");
    let got: Vec<_> = c
        .toolpath
        .events
        .iter()
        .map(|e| (e.before_contour, e.kind.name(), e.line))
        .collect();
    assert_eq!(
        got,
        [
            (1, "spindle_speed", 2),
            (1, "spindle_cw", 2),
            (2, "dwell", 4),
            (2, "message", 5),
            (2, "pause", 6)
        ]
    );
    assert_eq!(c.toolpath.contours.len(), 3);
    assert_eq!(c.toolpath.events[2].kind, EventKind::Dwell { seconds: 2.0 });
}

#[test]
fn diameter_mode_halves_x() {
    let c = ok("G18 G7 G0 X20 Z1\nG8 G0 X20\n");
    assert_eq!(elements(&c)[0].end[0], 10.0);
    assert_eq!(elements(&c)[1].end[0], 20.0);
}

#[test]
fn absolute_arc_centres() {
    let c = ok("G21 F100 G0 X10 Y0\nG90.1 G3 X0 Y10 I0 J0\n");
    let ElementKind::Arc(arc) = elements(&c)[1].kind else {
        panic!("an arc")
    };
    assert_eq!(arc.center, [0.0, 0.0]);
}

/// Records the call sequence of the streaming API.
#[derive(Default)]
struct Recorder(Vec<String>);

impl ToolpathSink for Recorder {
    fn element(&mut self, motion: Motion, element: &Element) {
        self.0
            .push(format!("{} {}", motion.name(), element.span.line));
    }
    fn end_contour(&mut self) {
        self.0.push("end".to_owned());
    }
    fn event(&mut self, event: &EventKind, line: u32) {
        self.0.push(format!("{} {line}", event.name()));
    }
}

#[test]
fn streaming_sends_elements_ends_and_events_in_order() {
    let mut sink = Recorder::default();
    let source = "G21 F100 G0 X1\nG1 X2\nX3\nM8\nG1 X4\nM2\n";
    let summary = compile_into(source, &GcodeOptions::default(), &mut sink).unwrap();
    assert_eq!(summary.units, Units::Millimetre);
    assert_eq!(
        sink.0,
        [
            "rapid 1",
            "end",
            "feed 2",
            "feed 3",
            "end",
            "coolant_flood 4",
            "feed 5",
            "end"
        ]
    );
}

/// One move of a random program.
#[derive(Debug, Clone)]
enum Move {
    Line([f64; 3]),
    /// End point in XY, centre offset from the start, clockwise, Z rise.
    Arc {
        angle: f64,
        radius: f64,
        cw: bool,
        rise: f64,
    },
}

fn moves() -> impl Strategy<Value = Vec<Move>> {
    let line = prop::array::uniform3(-50i32..50).prop_map(|p| Move::Line(p.map(f64::from)));
    let arc = (0.0f64..360.0, 1.0f64..20.0, any::<bool>(), -5.0f64..5.0).prop_map(
        |(angle, radius, cw, rise)| {
            let radius = (radius * 1e4).round() / 1e4;
            Move::Arc {
                angle,
                radius,
                cw,
                rise,
            }
        },
    );
    prop::collection::vec(prop_oneof![line, arc], 1..20)
}

proptest! {
    #[test]
    fn random_lines_and_arcs_round_trip(moves in moves()) {
        let mut source = String::from("G21 G90 G17 F600\n");
        let mut at = [0.0f64; 3];
        let mut expected = Vec::new();
        for m in &moves {
            match *m {
                Move::Line(p) => {
                    source.push_str(&format!("G1 X{:.4} Y{:.4} Z{:.4}\n", p[0], p[1], p[2]));
                    if p != at { expected.push((None, p)); }
                    at = p;
                }
                Move::Arc { angle, radius, cw, rise } => {
                    // Centre `radius` to the -X side of the start; the end on that circle.
                    let center = [at[0] - radius, at[1]];
                    let a = angle.to_radians();
                    let end = [
                        center[0] + radius * libm::cos(a),
                        center[1] + radius * libm::sin(a),
                        at[2] + rise,
                    ];
                    let end = end.map(|v| (v * 1e4).round() / 1e4);
                    source.push_str(&format!(
                        "G{} X{:.4} Y{:.4} Z{:.4} I{:.4} J0\n",
                        if cw { 2 } else { 3 }, end[0], end[1], end[2], -radius
                    ));
                    expected.push((Some((center, radius)), end));
                    at = end;
                }
            }
        }
        let compiled = compile(&source, &GcodeOptions::default())
            .map_err(|e| TestCaseError::fail(format!("{source}\n{e:?}")))?;
        let got = elements(&compiled);
        prop_assert_eq!(got.len(), expected.len());
        for (e, (arc, end)) in got.iter().zip(&expected) {
            for (got, want) in e.end.iter().zip(end) {
                prop_assert!((got - want).abs() < 1e-9);
            }
            if let (ElementKind::Arc(a), Some((center, radius))) = (e.kind, arc) {
                prop_assert!((a.center[0] - center[0]).abs() < 1e-9);
                prop_assert!((a.center[1] - center[1]).abs() < 1e-9);
                // Points along the arc lie on its circle (within the rounding of the end).
                let sweep = a.sweep(&e.start, &e.end);
                for k in 0..=8 {
                    let t = f64::from(k) / 8.0;
                    let r = sweep.start_radius + t * (sweep.end_radius - sweep.start_radius);
                    let th = sweep.start_angle + t * sweep.sweep;
                    let p = [a.center[0] + r * libm::cos(th), a.center[1] + r * libm::sin(th)];
                    let d = libm::hypot(p[0] - center[0], p[1] - center[1]);
                    prop_assert!((d - radius).abs() < 1e-3, "point off the arc by {}", d - radius);
                }
            }
        }
    }
}

#[test]
fn a_path_tolerance_finer_than_the_smallest_is_refused_at_its_word() {
    // 1e-201 would make the planner cut an arc into pieces without bound.
    let tiny = format!("G21 F100 G64 P0.{}1 G1 X1\n", "0".repeat(200));
    assert_eq!(errors(&tiny), [("bad_value", 1, 14)]);
    assert_eq!(
        errors("G20 F100\nG1 X1\nG64 P0.0000009\n"),
        [("bad_value", 3, 5)]
    );
    // The smallest is accepted, in either unit; P0 is plain G64.
    assert_eq!(
        ok("G21 F100 G64 P0.000001 G1 X1\n").path_tolerance,
        Some(1e-6)
    );
    assert_eq!(
        ok("G20 F100 G64 P0.000001 G1 X1\n").path_tolerance,
        Some(1e-6)
    );
    assert_eq!(ok("G21 F100 G64 P0 G1 X1\n").path_tolerance, None);
}

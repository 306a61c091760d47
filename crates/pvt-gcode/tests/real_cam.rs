//! Issue 24: real CAM output read as LinuxCNC's `rs274` reads it, through the library.
//!
//! The differential programs (`tests/dialect/`, compared with `rs274` by
//! `crates/pvtc/tests/dialect.rs`) pin the motion; these tests pin what the comparison
//! cannot see: diagnostics and their codes, options, events and memory bounds.

mod common;

use common::{errors, ok};
use pvt_core::{plan_toolpath_report, PlanOptions, Planner};
use pvt_gcode::{compile, GcodeOptions};

/// The code and message of every diagnostic of a refused program.
fn messages(refused: &pvt_gcode::GcodeErrors) -> Vec<(&'static str, String)> {
    let diagnostics = refused.diagnostics.iter();
    diagnostics.map(|d| (d.code(), d.to_string())).collect()
}

#[test]
fn g64_p0_is_plain_g64() {
    let c = ok("G21 G64 P0 F100\nG1 X1\nG3 X0 Y1 I-1 J0\nG64 P0.02\nM2\n");
    assert_eq!(c.path_tolerance, Some(0.02));
    let c = ok("G21 G64 P0 F100\nG1 X1\nG3 X0 Y1 I-1 J0\nM2\n");
    assert_eq!(c.path_tolerance, None, "G64 P0 sets no tolerance");
}

/// A zero path tolerance from a source (a front end that reads G64 P0 literally) is
/// no tolerance of its own: the arc is planned within the one in force (it overflowed a
/// capacity computing the arc's knots).
#[test]
fn a_zero_path_tolerance_plans_an_arc_within_the_tolerance_in_force() {
    let mut c = ok("G21 F600\nG1 X10\nG3 X0 Y10 I-10 J0\nM2\n");
    c.toolpath.path_tolerances = vec![(0, 0.0)];
    let options = PlanOptions {
        planner: Planner::Path,
        ..PlanOptions::default()
    };
    let planned = plan_toolpath_report(&c.toolpath, &options).expect("planned");
    let bound = planned.report.path_error.expect("a path error bound");
    assert!(
        bound > 0.0 && bound <= pvt_core::defaults::TOLERANCE_MM,
        "{bound}"
    );
}

/// M62–M68 and M100–M199 are events with their words, in LinuxCNC's order within a
/// block (I/O after T, before M6; user codes after coolant).
#[test]
fn io_and_user_m_codes_are_events_with_their_words() {
    let c = ok(
        "G21 F100\nG1 X1\nM62 P1\nM65 P2\nM66 E1 L0 Q2\nM67 E0 Q2.5\n\
                M68 E1 Q-1\nT2 M6 M64 P3\nM8 M101 P4 Q5\nG1 X2\nM2\n",
    );
    let got: Vec<(String, Option<String>, u32)> = c
        .toolpath
        .events
        .iter()
        .map(|e| (e.kind.name().to_owned(), e.kind.code_written(), e.line))
        .collect();
    let want = [
        ("digital_output_on_synced", Some("M62 P1"), 3),
        ("digital_output_off", Some("M65 P2"), 4),
        ("wait_input", Some("M66 E1 L0 Q2"), 5),
        ("analog_output_synced", Some("M67 E0 Q2.5"), 6),
        ("analog_output", Some("M68 E1 Q-1"), 7),
        ("tool_select", None, 8),
        ("digital_output_on", Some("M64 P3"), 8),
        ("spindle_off", None, 8),
        ("tool_change", None, 8),
        ("coolant_flood", None, 9),
        ("user_m_code", Some("M101 P4 Q5"), 9),
    ];
    let want: Vec<(String, Option<String>, u32)> = want
        .iter()
        .map(|(n, w, l)| (n.to_string(), w.map(str::to_owned), *l))
        .collect();
    assert_eq!(got, want);
    assert!(
        c.warnings.is_empty(),
        "their words are used: {:?}",
        c.warnings
    );
}

/// E is a word of M66–M68 only; two I/O codes in one block conflict, as in rs274.
#[test]
fn e_words_and_io_conflicts() {
    assert_eq!(errors("G21 F100\nG1 X1 E3\nM2\n"), [("unknown_word", 2, 7)]);
    assert_eq!(
        errors("G21 F100\nG1 X1\nM64 P1 E2\nM2\n"),
        [("unknown_word", 3, 8)]
    );
    assert_eq!(
        errors("G21 F100\nG1 X1\nM62 M64 P2\nM2\n"),
        [("conflicting_modes", 3, 5)]
    );
}

/// G33 is spindle-synchronised, refused without `--spindle-rpm-exact`; G71.1/G71.2
/// without the Q of their profile miss a word (they run: `tests/dialect/` holds them to
/// rs274).
#[test]
fn g33_is_refused_and_g71_1_needs_its_profile() {
    let c = compile(
        "G21 F100\nG1 X1\nG33 X2 K1\nG18\nG71.1 X3 Z-1\nG71.2 X1\nM2\n",
        &Default::default(),
    );
    let found = messages(&c.expect_err("refused"));
    assert_eq!(found.len(), 3, "{found:?}");
    assert_eq!(found[0].0, "pvtc::gcode::spindle_sync", "{found:?}");
    assert!(
        found[0].1.contains("G33 is spindle-synchronised"),
        "{found:?}"
    );
    for (code, message) in &found[1..] {
        assert_eq!(*code, "pvtc::gcode::missing_word", "{found:?}");
        assert!(message.contains("Q word"), "{found:?}");
    }
}

/// Counts what a front end hands on, keeping nothing.
#[derive(Default)]
struct Count {
    elements: u64,
    turns: f64,
}

impl pvt_gcode::ToolpathSink for Count {
    fn element(&mut self, _: pvt_core::Motion, element: &pvt_core::Element) {
        self.elements += 1;
        if let pvt_core::ElementKind::Arc(arc) = element.kind {
            let sweep = arc.sweep(&element.start, &element.end).sweep;
            self.turns += sweep.abs() / std::f64::consts::TAU;
        }
    }
    fn end_contour(&mut self) {}
    fn event(&mut self, _: &pvt_core::EventKind, _: u32) {}
}

/// An arc of many turns is handed on a turn at a time (so the planner's window bounds
/// the memory), each turn a full circle from the start's ray, the last one ending at the
/// programmed end; the turns add up to P.
#[test]
fn an_arc_of_many_turns_is_handed_on_a_turn_at_a_time() {
    let mut count = Count::default();
    let source = "G21 F600\nG1 X5\nG2 X0 Y5 I-5 J0 Z-7 P1000\nM2\n";
    pvt_gcode::compile_into(source, &Default::default(), &mut count).expect("compiles");
    assert_eq!(count.elements, 1 + 1000);
    // 999 full turns and three quarters (clockwise from 0° to 90°).
    assert!((count.turns - 999.75).abs() < 1e-6, "{}", count.turns);
    let c = ok("G21 F600\nG1 X5\nG2 X0 Y5 I-5 J0 Z-7 P1000\nM2\n");
    let arcs = &c.toolpath.contours[0].elements[1..];
    assert_eq!(arcs[0].start, [5.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
    assert_eq!(arcs[999].end, [0.0, 5.0, -7.0, 0.0, 0.0, 0.0]);
    for pair in arcs.windows(2) {
        assert_eq!(pair[0].end, pair[1].start, "the turns join");
    }
    // The height rises linearly with angle: 7 mm over 999.75 turns.
    let per_turn = 7.0 / 999.75;
    assert!(
        (arcs[0].end[2] + per_turn).abs() < 1e-12,
        "{:?}",
        arcs[0].end
    );
}

/// More turns than a block (P) or a run may make is `turn_limit`, never hours of work.
#[test]
fn arc_turns_are_bounded_per_block_and_per_run() {
    assert_eq!(
        errors("G21 F600\nG1 X5\nG2 X5 Y0 I-5 J0 P1000001\nM2\n"),
        [("turn_limit", 3, 17)]
    );
    let looped = "G21 F600\nG1 X5\no1 repeat [11]\nG2 X5 Y0 I-5 J0 P1000000\no1 endrepeat\nM2\n";
    let mut count = Count::default();
    let refused = pvt_gcode::compile_into(looped, &Default::default(), &mut count);
    let codes = messages(&refused.expect_err("refused"));
    assert_eq!(codes.len(), 1, "{codes:?}");
    assert_eq!(codes[0].0, "pvtc::gcode::turn_limit");
    assert!(codes[0].1.contains("10000000 turns in all"), "{codes:?}");
    assert_eq!(count.elements, 1 + pvt_gcode::MAX_TOTAL_ARC_TURNS);
}

/// `#<_hal[NAME]>` reads the value given for its pin (names as rs274 reads them: lower
/// case, blanks left out); a pin without one is one `unsupported` at its first place,
/// with the count of places; a program may not assign a pin.
#[test]
fn hal_pins_read_their_given_values() {
    let options = GcodeOptions {
        hal_pins: vec![("Motion.Analog-In-00".to_owned(), 3.5)],
        ..GcodeOptions::default()
    };
    let source =
        "G21 F100\nG1 X[#<_hal[motion.analog-in-00]> * 2] Y#<_HAL[ motion.analog-in-00 ]>\nM2\n";
    let c = compile(source, &options).expect("compiles");
    assert_eq!(c.toolpath.contours[0].elements[0].end[..2], [7.0, 3.5]);
    let source = "G21 F100\nG1 X#<_hal[a.b]>\nG1 Y#<_hal[c.d]>\nM2\n";
    let refused = compile(source, &options).expect_err("no value for a.b or c.d");
    let found = messages(&refused);
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!(found[0].0, "pvtc::gcode::unsupported");
    assert!(
        found[0].1.contains("#<_hal[a.b]>") && found[0].1.contains("2 places"),
        "{found:?}"
    );
    assert_eq!(
        errors("G21 F100\n#<_hal[x]> = 2\nG1 X1\nM2\n")
            .first()
            .map(|e| e.0),
        Some("bad_value")
    );
}

/// G38.2–G38.5 are refused one by one (`probe`), unless results are given: then each
/// probing move, in order, is a feed move to where it trips, which #5061–#5063 then read
/// (#5070 reads 1: tripped).
#[test]
fn probing_moves_need_a_result_and_then_end_where_it_trips() {
    let source = "G21 G90 F100\nG1 X1\nG38.2 Z-10 F50\nG0 Z5\nG38.5 Z-10\nM2\n";
    assert_eq!(errors(source), [("probe", 3, 1), ("probe", 5, 1)]);
    let options = GcodeOptions {
        probe_results: vec![[1.0, 0.0, -3.5], [1.0, 0.0, -1.0]],
        ..GcodeOptions::default()
    };
    let source = "G21 G90 F100\nG1 X1\nG38.2 Z-10 F50\nG92 Z0\nG1 X[#5061 + 1] Y#5070 F100\n\
                  G0 Z5\nG38.3 Z-10\nG1 X[#5063]\nM2\n";
    let c = compile(source, &options).expect("compiles");
    let ends: Vec<[f64; 3]> = c
        .toolpath
        .contours
        .iter()
        .flat_map(|c| c.elements.iter().map(|e| [e.end[0], e.end[1], e.end[2]]))
        .collect();
    assert_eq!(
        ends,
        [
            [1.0, 0.0, 0.0],
            [1.0, 0.0, -3.5],
            [2.0, 1.0, -3.5],
            [2.0, 1.0, 1.5],
            [1.0, 0.0, -4.5],
            [-1.0, 0.0, -4.5],
        ]
    );
    let one = GcodeOptions {
        probe_results: vec![[1.0, 0.0, -3.5]],
        ..GcodeOptions::default()
    };
    let refused = compile("G21 F50\nG38.2 Z-10\nG38.4 Z5\nM2\n", &one).expect_err("one short");
    assert_eq!(refused.diagnostics.len(), 1);
    assert_eq!(refused.diagnostics[0].code(), "pvtc::gcode::probe");
}

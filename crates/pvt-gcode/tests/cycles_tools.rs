//! Issue 16 part 2: canned cycles, tools and homes, the modes accepted as state, and an
//! unknown G code that must not cascade. Expected moves are worked out here from
//! LinuxCNC's rules (checked against `rs274`), not read back from pvtc.

mod common;

use common::{errors, ok};
use pvt_core::{EventKind, Motion, SpindleState};
use pvt_gcode::{compile, GcodeOptions, ToolTable};

/// Every move as (rapid?, X, Y, Z), in order.
fn moves(source: &str, options: &GcodeOptions) -> Vec<(bool, [f64; 3])> {
    let compiled = compile(source, options).unwrap_or_else(|e| panic!("{e:?}"));
    compiled
        .toolpath
        .contours
        .iter()
        .flat_map(|c| {
            c.elements
                .iter()
                .map(move |e| (c.motion == Motion::Rapid, [e.end[0], e.end[1], e.end[2]]))
        })
        .collect()
}

fn assert_moves(got: &[(bool, [f64; 3])], want: &[(bool, [f64; 3])]) {
    assert_eq!(got.len(), want.len(), "{got:?}");
    for (g, w) in got.iter().zip(want) {
        assert_eq!(g.0, w.0, "{got:?}");
        for k in 0..3 {
            assert!((g.1[k] - w.1[k]).abs() < 1e-9, "{g:?} != {w:?}");
        }
    }
}

const RAPID: bool = true;
const FEED: bool = false;

#[test]
fn g81_returns_to_the_start_level_under_g98_and_to_r_under_g99() {
    let d = GcodeOptions::default();
    let g98 = moves("G21 F100\nG0 Z10\nG98 G81 X1 Y2 Z-3 R2\nX5\n", &d);
    let g99 = moves("G21 F100\nG0 Z10\nG99 G81 X1 Y2 Z-3 R2\nX5\n", &d);
    let hole = |x: f64, clear: f64, from: f64| {
        let mut v = vec![(RAPID, [x, 2.0, from])];
        if from != 2.0 {
            v.push((RAPID, [x, 2.0, 2.0]));
        }
        v.extend([(FEED, [x, 2.0, -3.0]), (RAPID, [x, 2.0, clear])]);
        v
    };
    let mut want = vec![(RAPID, [0.0, 0.0, 10.0])];
    want.extend(hole(1.0, 10.0, 10.0));
    want.extend(hole(5.0, 10.0, 10.0));
    assert_moves(&g98, &want);
    let mut want = vec![(RAPID, [0.0, 0.0, 10.0])];
    want.extend(hole(1.0, 2.0, 10.0));
    want.extend(hole(5.0, 2.0, 2.0));
    assert_moves(&g99, &want);
}

#[test]
fn g83_pecks_step_by_q_and_re_enter_0_254_mm_above_the_last_depth() {
    let got = moves(
        "G21 F100\nG0 Z10\nG83 X1 Y1 Z-5 R1 Q2\n",
        &GcodeOptions::default(),
    );
    // Independent: depths 1-2=-1, -3, then the bottom -5; each re-entry 0.254 above.
    let mut want = vec![
        (RAPID, [0.0, 0.0, 10.0]),
        (RAPID, [1.0, 1.0, 10.0]),
        (RAPID, [1.0, 1.0, 1.0]),
    ];
    for depth in [-1.0, -3.0] {
        want.push((FEED, [1.0, 1.0, depth]));
        want.push((RAPID, [1.0, 1.0, 1.0]));
        want.push((RAPID, [1.0, 1.0, depth + 0.254]));
    }
    want.push((FEED, [1.0, 1.0, -5.0]));
    want.push((RAPID, [1.0, 1.0, 1.0]));
    assert_moves(&got, &want);
    // G73 breaks the chip without going back to R; inches back off 0.01.
    let got = moves(
        "G20 F10\nG0 Z1\nG73 X1 Z-0.5 R0.1 Q0.3\n",
        &GcodeOptions::default(),
    );
    let z: Vec<f64> = got.iter().map(|m| m.1[2]).collect();
    let want = [1.0, 1.0, 0.1, 0.1 - 0.3, 0.1 - 0.3 + 0.01, -0.5, 0.1];
    assert_eq!(z.len(), want.len(), "{z:?}");
    for (a, b) in z.iter().zip(want) {
        assert!((a - b).abs() < 1e-12, "{z:?}");
    }
}

#[test]
fn l_repeats_step_under_g91_from_the_initial_level() {
    let got = moves(
        "G21 F100\nG0 Z10\nG91 G99 G81 X2 Z-3 R-1 L2\nX1\n",
        &GcodeOptions::default(),
    );
    // R = 10 - 1 = 9, bottom 9 - 3 = 6; holes at X2, X4 and then X5.
    let want = [
        (RAPID, [0.0, 0.0, 10.0]),
        (RAPID, [2.0, 0.0, 10.0]),
        (RAPID, [2.0, 0.0, 9.0]),
        (FEED, [2.0, 0.0, 6.0]),
        (RAPID, [2.0, 0.0, 9.0]),
        (RAPID, [4.0, 0.0, 9.0]),
        (FEED, [4.0, 0.0, 6.0]),
        (RAPID, [4.0, 0.0, 9.0]),
        (RAPID, [5.0, 0.0, 9.0]),
        (FEED, [5.0, 0.0, 6.0]),
        (RAPID, [5.0, 0.0, 9.0]),
    ];
    assert_moves(&got, &want);
}

#[test]
fn tapping_and_boring_cycles_turn_the_spindle_as_linuxcnc_does() {
    let c = ok("G21 F100 S500 M3\nG0 Z10\nG84 X3 Z-5 R1\nG86 X5 Z-5 R1 P1\n");
    let spindle: Vec<SpindleState> = c
        .toolpath
        .events
        .iter()
        .filter_map(|e| match e.kind {
            EventKind::Spindle { state } => Some(state),
            _ => None,
        })
        .collect();
    use SpindleState::*;
    assert_eq!(
        spindle,
        [
            Clockwise,
            Off,
            CounterClockwise,
            Off,
            Clockwise,
            Off,
            Clockwise
        ]
    );
    assert!(c
        .toolpath
        .events
        .iter()
        .any(|e| e.kind == EventKind::Dwell { seconds: 1.0 }));
    // G84 feeds out of the hole; G86 rapids out.
    let m = moves(
        "G21 F100 S500 M3\nG0 Z10\nG84 X3 Z-5 R1\nG86 X5 Z-5 R1 P1\n",
        &GcodeOptions::default(),
    );
    assert_eq!(m[4], (FEED, [3.0, 0.0, 1.0]));
    assert_eq!(m[7], (RAPID, [5.0, 0.0, 1.0]));
}

#[test]
fn cycle_errors_are_coded() {
    let head = "G21 G90 F100\nG0 X0 Y0 Z5\n";
    let e = |body: &str| errors(&format!("{head}{body}"));
    assert_eq!(e("G81 X1 Z-1\n"), [("cycle", 3, 1)], "no R");
    assert_eq!(e("G81 X1 R1\n"), [("cycle", 3, 1)], "no Z");
    assert_eq!(e("G81 X1 Z2 R1\n"), [("cycle", 3, 1)], "R below Z");
    assert_eq!(e("G83 X1 Z-2 R1\n"), [("cycle", 3, 1)], "no Q");
    assert_eq!(e("G81 X1 Z-2 R1 L0\n"), [("cycle", 3, 1)], "L0");
    assert_eq!(e("G84 X1 Z-2 R1\n"), [("cycle", 3, 1)], "no spindle");
    assert_eq!(e("M4\nG84 X1 Z-2 R1\n"), [("cycle", 4, 1)], "M4 tapping");
    assert_eq!(e("G86 X1 Z-2 R1 P1\n"), [("cycle", 3, 1)], "G86 no spindle");
    assert_eq!(e("G53 G81 X1 Z-2 R1\n"), [("cycle", 3, 5)], "G53");
    assert_eq!(e("G81 X1 Z-2 R1 A1\n"), [("cycle", 3, 1)], "A word");
    assert_eq!(e("G93 G81 X1 Z-2 R1 F1\n"), [("cycle", 3, 5)], "G93");
}

fn table() -> GcodeOptions {
    GcodeOptions {
        tool_table: ToolTable::parse("T1 P1 Z12.7\nT2 P2 X2.54 Z-38.1\n").unwrap(),
        ..GcodeOptions::default()
    }
}

#[test]
fn tool_length_offsets_shift_the_machine_position() {
    let got = moves(
        "G21 G90\nG0 X1 Y1 Z1\nT1 M6\nG43 H1\nG0 X2\nG43 Z15. H2 T2 M6\nG43.1 Z3\nG0 X3\nG49\nG0 X4\n",
        &table(),
    );
    // The machine is at program + tool offset: H1 lifts nothing until Z is programmed.
    let want = [
        (RAPID, [1.0, 1.0, 1.0]),
        (RAPID, [2.0, 1.0, 1.0]),
        (RAPID, [2.0, 1.0, 15.0 - 38.1]),
        (RAPID, [3.0 + 2.54, 1.0, 15.0 - 38.1]),
        (RAPID, [4.0, 1.0, 15.0 - 38.1]),
    ];
    assert_moves(&got, &want);
    assert_eq!(errors("G21 F1\nG0 X1\nG43 H3\n"), [("unknown_tool", 3, 5)]);
}

#[test]
fn g28_goes_through_the_intermediate_point_to_the_stored_home() {
    let d = GcodeOptions::default();
    let got = moves("G21\nG0 X4 Y1 Z-3\nG91 G28 Z2\n", &d);
    let want = [
        (RAPID, [4.0, 1.0, -3.0]),
        (RAPID, [4.0, 1.0, -1.0]),
        (RAPID, [4.0, 1.0, 0.0]),
    ];
    assert_moves(&got, &want);
    let got = moves("G21\nG0 X1 Y2 Z3\nG28.1\nG0 X5 Y5 Z5\nG28\nG30\n", &d);
    let want = [
        (RAPID, [1.0, 2.0, 3.0]),
        (RAPID, [5.0, 5.0, 5.0]),
        (RAPID, [1.0, 2.0, 3.0]),
        (RAPID, [0.0, 0.0, 0.0]),
    ];
    assert_moves(&got, &want);
}

/// LinuxCNC keeps the G28 and G30 homes in #5161… and #5181…: a program that writes
/// them moves where G28 and G30 go (millimetres, as the parameters read; in an inch
/// program 25.4 is one inch).
#[test]
fn homes_written_as_parameters_move_g28_and_g30() {
    let d = GcodeOptions::default();
    let got = moves(
        "G21\n#5161 = 7\n#5163 = 9\n#5182 = -4\nG0 X1 Y1 Z1\nG28\nG30\n",
        &d,
    );
    let want = [
        (RAPID, [1.0, 1.0, 1.0]),
        (RAPID, [7.0, 0.0, 9.0]),
        (RAPID, [0.0, -4.0, 0.0]),
    ];
    assert_moves(&got, &want);
    let inch = moves("G20\n#5161 = 25.4\nG0 X2\nG28\n", &d);
    assert_moves(&inch, &[(RAPID, [2.0, 0.0, 0.0]), (RAPID, [1.0, 0.0, 0.0])]);
    // Reading the parameter back gives what was written.
    let read = moves("G21\n#5161 = 3\nG0 X#5161\n", &d);
    assert_moves(&read, &[(RAPID, [3.0, 0.0, 0.0])]);
}

#[test]
fn fanuc_post_lines_compile() {
    let c = compile(
        "G21 G90\nG91 G28 Z0.\nG90\nT1 M6\nG0 G54 X0 Y0\nG43 Z15. H1 T1 M6\nS1000 M3\nG81 X10 Y10 Z-2 R2 F200\nG80\nM30\n",
        &table(),
    )
    .unwrap_or_else(|e| panic!("{e:?}"));
    let last = c.toolpath.contours.last().unwrap().elements.last().unwrap();
    assert!((last.end[2] - (2.0 + 12.7)).abs() < 1e-9, "{last:?}");
}

#[test]
fn modes_accepted_as_state() {
    let c = ok("G21 G96 D2000 S200 M3\nG97 S1000\nM48\nM50 P0\nM51 P1\nM52 P1\nM53 P1\nG64 P0.254 Q0.025\nG1 X1 F100\nM2\n");
    assert!(c.warnings.is_empty(), "{:?}", c.warnings);
    let rpm: Vec<_> = c
        .toolpath
        .events
        .iter()
        .filter(|e| matches!(e.kind, EventKind::SpindleSpeed { .. }))
        .collect();
    assert_eq!(rpm.len(), 1, "G96's S is a surface speed, not rpm");
    let mut sink = EndX::default();
    let source = "G20 G64 P0.01 Q0.001\nG1 X1 F10\n";
    let summary = pvt_gcode::compile_into(source, &GcodeOptions::default(), &mut sink).unwrap();
    assert_eq!(summary.naive_cam_tolerance, Some(0.001));
    assert_eq!(summary.path_tolerance, Some(0.01));
    let c = ok("G21 G1 X1 F100 Q2 H1 L3 D1\n");
    let ignored = c
        .warnings
        .iter()
        .filter(|w| w.code() == "pvtc::gcode::ignored_word");
    assert_eq!(ignored.count(), 4);
}

#[test]
fn an_unknown_g_code_is_one_error_and_drifts_nothing() {
    let mut source = String::from("G21 G90 F100\nG1 X1\nG12.3 P3 K0 X0 Y0 R1 G91\n");
    for k in 0..200 {
        source.push_str(&format!("K{k} X{k} Y1 R1\n"));
    }
    source.push_str("G1 X2\n");
    assert_eq!(errors(&source), [("unknown_word", 3, 1)]);
}

/// Collects the end X of each element, whatever the outcome.
#[derive(Default)]
struct EndX(Vec<f64>);

impl pvt_gcode::ToolpathSink for EndX {
    fn element(&mut self, _motion: Motion, element: &pvt_core::Element) {
        self.0.push(element.end[0]);
    }
    fn end_contour(&mut self) {}
    fn event(&mut self, _kind: &EventKind, _line: u32) {}
}

#[test]
fn the_unknown_block_sets_no_mode() {
    // G91 on the skipped line must not make the later X2 incremental (it would end at 3).
    let mut sink = EndX::default();
    let source = "G21 G90 F100\nG1 X1\nG12.3 G91\nG1 X2\n";
    let result = pvt_gcode::compile_into(source, &GcodeOptions::default(), &mut sink);
    assert_eq!(result.unwrap_err().diagnostics.len(), 1);
    assert_eq!(sink.0, [1.0, 2.0]);
}

#[test]
fn g10_writes_coordinate_systems_and_g52_shares_g92() {
    let got = moves(
        "G21 G90\nG0 X1 Y1\nG10 L2 P2 X10 Y20\nG55 G0 X1 Y1\nG10 L2 P0 X5\nG0 X2\nG10 L20 P1 X0 Y0\nG54 G0 X1 Y1\nG52 X3\nG0 X2\nG92.1\nG0 X2\n",
        &GcodeOptions::default(),
    );
    // G10 L20 P1 at machine (7, 21) makes that point G54's (0, 0).
    let want = [
        (RAPID, [1.0, 1.0, 0.0]),
        (RAPID, [11.0, 21.0, 0.0]),
        (RAPID, [7.0, 21.0, 0.0]),
        (RAPID, [8.0, 22.0, 0.0]),
        (RAPID, [7.0 + 3.0 + 2.0, 22.0, 0.0]),
        (RAPID, [7.0 + 2.0, 22.0, 0.0]),
    ];
    assert_moves(&got, &want);
}

#[test]
fn g10_l1_and_l10_write_the_tool_table() {
    let options = GcodeOptions {
        tool_table: ToolTable::parse("T1 P1 Z0\n").unwrap(),
        ..GcodeOptions::default()
    };
    let got = moves(
        "G21 G90\nG0 Z10\nG10 L1 P1 Z3\nG43 H1\nG0 Z0\nG10 L10 P1 Z4\nG43 H1\nG0 Z0\n",
        &options,
    );
    // L1: length 3. L10 at machine Z 3 reading Z4: length 3 - 4 = -1.
    let want = [
        (RAPID, [0.0, 0.0, 10.0]),
        (RAPID, [0.0, 0.0, 3.0]),
        (RAPID, [0.0, 0.0, -1.0]),
    ];
    assert_moves(&got, &want);
}

#[test]
fn polar_words_give_radius_and_angle_from_the_origin() {
    let got = moves(
        "G21 G90 F100\nG0 @5 ^90\nG1 ^30\nG91 G1 @1 ^15\n",
        &GcodeOptions::default(),
    );
    let (half_root3, root_half) = (3.0_f64.sqrt() / 2.0, 0.5_f64.sqrt());
    let want = [
        (RAPID, [0.0, 5.0, 0.0]),
        (FEED, [5.0 * half_root3, 5.0 * 0.5, 0.0]),
        (FEED, [6.0 * root_half, 6.0 * root_half, 0.0]),
    ];
    assert_moves(&got, &want);
    assert_eq!(errors("G21 F1\nG1 X1 @2\n"), [("bad_value", 2, 7)]);
}

#[test]
fn debug_and_print_comments_are_messages_with_parameters() {
    let c =
        ok("G21\n#1=2.5\n#<a>=3\n(DEBUG, a=#<a> f=%.2f#1)\n(PRINT,p #1)\n(LOGOPEN,x.log)\nG0 X1\n");
    let texts: Vec<_> = c
        .toolpath
        .events
        .iter()
        .filter_map(|e| match &e.kind {
            EventKind::Message { text } => Some(text.as_str()),
            _ => None,
        })
        .collect();
    assert_eq!(texts, ["a=3.000000 f=2.50", "p 2.500000"]);
}

#[test]
fn g28_and_g53_reach_machine_positions_whatever_the_tool_offset() {
    let got = moves(
        "G21 G90\nG0 X1 Z5\nT1 M6\nG43 H1\nG53 G0 Z0\nG0 Z2\nG91 G28 Z0\n",
        &table(),
    );
    // Tool 1 is 12.7 long: G53 Z0 and the G28 home are machine 0, Z2 is 2 + 12.7.
    let want = [
        (RAPID, [1.0, 0.0, 5.0]),
        (RAPID, [1.0, 0.0, 0.0]),
        (RAPID, [1.0, 0.0, 14.7]),
        (RAPID, [1.0, 0.0, 0.0]),
    ];
    assert_moves(&got, &want);
}

#[test]
fn g43_without_h_takes_the_tool_m6_loads_in_the_same_block() {
    let got = moves("G21 G90\nG0 X1\nT1 M6 G43\nG0 Z0\n", &table());
    assert_moves(&got, &[(RAPID, [1.0, 0.0, 0.0]), (RAPID, [1.0, 0.0, 12.7])]);
}

#[test]
fn a_tiny_peck_or_a_huge_level_is_refused_not_run() {
    let head = "G21 G90 F100\nG0 X0 Y0 Z5\n";
    let e = |body: &str| errors(&format!("{head}{body}"));
    assert_eq!(e("G83 X1 Z-1000 R1 Q0.000001\n"), [("cycle", 3, 1)]);
    let huge = format!("1{}", "0".repeat(300));
    assert_eq!(e(&format!("G81 X1 Z-1 R{huge}\n")), [("cycle", 3, 1)]);
    assert_eq!(
        e(&format!("G91 G81 X{huge} Z-1 R1 L3\n")),
        [("cycle", 3, 5)]
    );
}

#[test]
fn pecks_times_repeats_are_bounded() {
    // 1000 pecks a hole is fine; 1000 pecks times L200 is refused.
    let ok = "G21 G90 F100\nG0 X0 Y0 Z5\nG91 G83 X1 Z-101 R-4 Q0.1 L2\n";
    assert!(compile(ok, &GcodeOptions::default()).is_ok());
    let head = "G21 G90 F100\nG0 X0 Y0 Z5\n";
    let e = |body: &str| errors(&format!("{head}{body}"));
    assert_eq!(e("G91 G83 X1 Z-101 R-4 Q0.1 L200\n"), [("cycle", 3, 5)]);
}

#[test]
fn an_unknown_motion_mode_with_p_and_l_words_is_one_error() {
    let mut source = String::from("G21 G90 F100\nG1 X1\nG74 P3 L3 X0 Y0\n");
    for k in 0..50 {
        source.push_str(&format!("X{k} Y1 P1 L2\n"));
    }
    source.push_str("G1 X2\n");
    let e = compile(&source, &GcodeOptions::default()).unwrap_err();
    let codes: Vec<_> = e.diagnostics.iter().map(|d| d.code()).collect();
    assert_eq!(codes, ["pvtc::gcode::unknown_word"], "{e:?}");
}

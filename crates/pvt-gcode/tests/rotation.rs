//! Coordinate system rotation (G10 L2 R, LinuxCNC's #5230…): program coordinates plus
//! the G92 offset, turned about the work origin, plus the work offset. Expected machine
//! positions are worked out here by hand with quarter and half turns (checked against
//! `rs274`; `crates/pvtc/tests/dialect.rs` compares general angles with it).

mod common;

use common::errors;
use pvt_core::{ElementKind, Motion};
use pvt_gcode::{compile, line_col, GcodeOptions, ToolTable};

/// Every move as (rapid?, X, Y, Z, arc centre in the plane if an arc).
fn moves(source: &str) -> Vec<(bool, [f64; 3], Option<[f64; 2]>)> {
    let compiled = compile(source, &GcodeOptions::default()).unwrap_or_else(|e| panic!("{e:?}"));
    compiled
        .toolpath
        .contours
        .iter()
        .flat_map(|c| {
            c.elements.iter().map(move |e| {
                let centre = match &e.kind {
                    ElementKind::Arc(arc) => Some(arc.center),
                    _ => None,
                };
                (
                    c.motion == Motion::Rapid,
                    [e.end[0], e.end[1], e.end[2]],
                    centre,
                )
            })
        })
        .collect()
}

fn ends(source: &str) -> Vec<[f64; 3]> {
    moves(source).into_iter().map(|m| m.1).collect()
}

fn assert_close(got: &[[f64; 3]], want: &[[f64; 3]]) {
    assert_eq!(got.len(), want.len(), "{got:?}");
    for (g, w) in got.iter().zip(want) {
        for k in 0..3 {
            assert!((g[k] - w[k]).abs() < 1e-9, "{got:?} != {want:?}");
        }
    }
}

#[test]
fn absolute_incremental_and_arc_centres_turn_about_the_work_origin() {
    // G54 at (10, 5) turned 90°: program (x, y) is machine (10 - y, 5 + x).
    let source = "G21 G90 F100\nG10 L2 P1 X10 Y5 R90\nG0 X1 Y0\nG91 G0 X1\nG90\n\
                  G3 X2 Y2 I0 J1\nG90.1 G2 X2 Y4 I2 J3\n";
    let got = moves(source);
    assert_close(
        &got.iter().map(|m| m.1).collect::<Vec<_>>(),
        &[
            [10.0, 6.0, 0.0],
            [10.0, 7.0, 0.0],
            [8.0, 7.0, 0.0],
            [6.0, 7.0, 0.0],
        ],
    );
    // I0 J1 from program (2, 0): centre (2, 1), machine (9, 7); G90.1 (2, 3): (7, 7).
    for (m, want) in got[2..].iter().zip([[9.0, 7.0], [7.0, 7.0]]) {
        let centre = m.2.expect("an arc");
        assert!((centre[0] - want[0]).abs() < 1e-9 && (centre[1] - want[1]).abs() < 1e-9);
    }
}

#[test]
fn g92_polar_words_and_parameters_live_in_the_turned_frame() {
    // Turned 90° about (0, 0): program (x, y) is machine (-y, x) plus the G92 shift.
    let source = "G21 G90 F100\nG10 L2 P1 R90\nG0 X1 Y0\nG92 X0 Y0\nG0 X0 Y1\nG92.1\n\
                  G1 @2 ^0\nG0 X#5421 Y#5420\nG0 X[#5230 / 45] Y0\n";
    assert_close(
        &ends(source),
        &[
            // (1, 0) turned.
            [0.0, 1.0, 0.0],
            // G92 shifts by (1, 0): (0, 1) + (1, 0) = (1, 1), turned (-1, 1).
            [-1.0, 1.0, 0.0],
            // @2 ^0 is program (2, 0).
            [0.0, 2.0, 0.0],
            // #5420, #5421 read program (2, 0): the move is to program (0, 2).
            [-2.0, 0.0, 0.0],
            // #5230 is 90: program (2, 0).
            [0.0, 2.0, 0.0],
        ],
    );
}

#[test]
fn g10_l20_sets_x_and_y_together_in_the_turned_frame() {
    // At program (10, 3) of G54 (10, 5) R90, machine (7, 15). L20 X0 makes the current
    // point program (0, 3): the work origin moves to (7, 15) - turned (0, 3) = (10, 15).
    let source = "G21 G90\nG10 L2 P1 X10 Y5 R90\nG0 X10 Y3\nG10 L20 P1 X0\nG0 X0 Y0\n\
                  G10 L2 P0 R0\nG0 X1 Y1\n";
    assert_close(
        &ends(source),
        &[[7.0, 15.0, 0.0], [10.0, 15.0, 0.0], [11.0, 16.0, 0.0]],
    );
}

#[test]
fn g28_reads_the_home_in_the_turned_frame_for_the_axes_with_words() {
    // G54 at (10, 0) turned 90°: program (x, y) is machine (10 - y, x). The home, machine
    // (0, 0), is program (0, 10). From program (1, 1): the intermediate point (3, 1), then
    // X takes the home's 0 and Y keeps 1: program (0, 1), machine (9, 0).
    let source = "G21 G90\nG10 L2 P1 X10 R90\nG0 X1 Y1\nG28 X3\n";
    assert_close(
        &ends(source),
        &[[9.0, 1.0, 0.0], [9.0, 3.0, 0.0], [9.0, 0.0, 0.0]],
    );
}

#[test]
fn a_cycle_drills_its_holes_in_the_turned_frame() {
    let source = "G21 G90 F100\nG10 L2 P1 X1 R180\nG0 Z5\nG99 G81 X2 Y1 Z-1 R1\nG80\n";
    let got = ends(source);
    // (2, 1) turned half round is (-2, -1), plus X1.
    assert_close(
        &got,
        &[
            // Z alone leaves X and Y where they are.
            [0.0, 0.0, 5.0],
            [-1.0, -1.0, 5.0],
            [-1.0, -1.0, 1.0],
            [-1.0, -1.0, -1.0],
            [-1.0, -1.0, 1.0],
        ],
    );
}

#[test]
fn what_a_turned_system_cannot_run_is_refused() {
    let head = "G21 G90 F100\nG10 L2 P1 R30\n";
    assert_eq!(
        errors(&format!("{head}G18 G2 X1 Z1 R2\n")),
        [("unsupported", 3, 5)]
    );
    assert_eq!(
        errors(&format!("{head}G10 L20 P1 R5\n")),
        [("bad_value", 3, 12)]
    );
    // Tool offsets in X or Y from a turned position (L10; L11 when G59.3 is turned).
    let options = GcodeOptions {
        tool_table: ToolTable::parse("T1 P1 Z0\n").unwrap(),
        ..GcodeOptions::default()
    };
    for (source, column) in [
        (format!("{head}G10 L10 P1 X1\n"), 12),
        (format!("{head}G10 L2 P9 R5\nG10 L11 P1 Y1\n"), 12),
    ] {
        let failed = compile(&source, &options).expect_err("refused");
        let d = &failed.diagnostics[0];
        assert_eq!(d.code(), "pvtc::gcode::unsupported");
        let line = source.lines().count();
        assert_eq!(
            line_col(&source, d.span().start),
            (line, column),
            "{source}"
        );
    }
    // Z offsets stay free.
    assert!(compile(&format!("{head}G10 L10 P1 Z1\nG0 X1\n"), &options).is_ok());
}

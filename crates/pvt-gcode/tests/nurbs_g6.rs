//! G6.2 NURBS blocks (LinuxCNC 2.10): the Béziers a block makes, against the NURBS
//! LinuxCNC 2.10 defines, evaluated here by the Cox–de Boor recursion
//! ([`common::TrueNurbs`]); the planned motion against the same curve; the refusals at
//! their lines. Debian's rs274 (LinuxCNC 2.9) refuses G6.2, so the reference is 2.10's
//! own: the programs of its `nc_files/nurbs/G6` folder (`G6.2 X- Y- R- K- P- Q-` opening
//! line, `X- Y- R- K-` control points, P closing `G6.2 K-` lines; the plane's words in
//! G18 and G19) and its canon's `NURBS_G6_FEED` (the knot vector is the K of every line
//! in order, the control points every line but the last P). The programs here are
//! written in that style, not copied.

mod common;

use common::{bezier_elements, bezier_point};

use common::TrueNurbs;
use pvt_core::{Axis, ElementKind};
use pvt_gcode::{compile, GcodeOptions, NURBS_FIT_SHARE};

/// A leaf-like outline: seven control points with uneven knots and a double one.
const POINTS: [[f64; 2]; 7] = [
    [10.0, 5.0],
    [14.0, 12.0],
    [22.0, 18.0],
    [30.0, 9.0],
    [24.0, -4.0],
    [15.0, -6.0],
    [11.0, 1.0],
];
const KNOTS: [f64; 10] = [0.0, 0.0, 0.0, 1.0, 2.0, 2.0, 3.5, 5.0, 5.0, 5.0];

/// A G6.2 block in `plane` (17, 18 or 19) through `points` with weights and knots, order
/// `order`, the tool at the first point first; the block's lines are 3 onward.
fn program(
    plane: u32,
    points: &[[f64; 2]],
    weights: &[f64],
    knots: &[f64],
    order: usize,
) -> String {
    let words = match plane {
        17 => ["X", "Y"],
        18 => ["Z", "X"],
        _ => ["Y", "Z"],
    };
    let at = |p: [f64; 2]| format!("{}{} {}{}", words[0], p[0], words[1], p[1]);
    let mut s = format!("G21 G90 G{plane} F1200\nG0 {}\n", at(points[0]));
    for (i, p) in points.iter().enumerate() {
        let head = if i == 0 { "G6.2 " } else { "    " };
        let tail = if i == 0 {
            format!(" P{order} Q1")
        } else {
            String::new()
        };
        s += &format!("{head}{} R{} K{}{tail}\n", at(*p), weights[i], knots[i]);
    }
    for k in &knots[points.len()..] {
        s += &format!("G6.2 K{k}\n");
    }
    s + "G1 X0 Y0 Z0\nM2\n"
}

fn plane_axes(plane: u32) -> [Axis; 2] {
    match plane {
        17 => [Axis::X, Axis::Y],
        18 => [Axis::Z, Axis::X],
        _ => [Axis::Y, Axis::Z],
    }
}

/// Equal weights, order 3 and 4: one exact cubic per non-empty knot span, element `k`'s
/// `u` the span's parameter `t_k + u·(t_{k+1} − t_k)`, in G17, G18 and G19; the other
/// axis stays where it was and the tool ends at the last control point.
#[test]
fn a_block_is_its_nurbs_in_every_plane() {
    let cases: [(&[f64], usize); 2] = [
        (&KNOTS, 3),
        (&[0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 2.5, 4.0, 4.0, 4.0, 4.0], 4),
    ];
    for plane in [17, 18, 19] {
        for (knots, order) in cases {
            let weights = [1.5; 7];
            let source = program(plane, &POINTS, &weights, knots, order);
            let curve = TrueNurbs::new(&POINTS, &weights, knots, order, 8);
            let spans: Vec<[f64; 2]> = (knots.windows(2))
                .filter(|w| w[1] > w[0])
                .map(|w| [w[0], w[1]])
                .collect();
            let e = bezier_elements(&source);
            assert_eq!(e.len(), spans.len(), "{source}");
            let axes = plane_axes(plane);
            for (element, span) in e.iter().zip(&spans) {
                let ElementKind::Bezier(b) = element.kind else {
                    unreachable!()
                };
                assert_eq!(b.fit, 0.0, "{source}");
                assert_eq!([b.plane.axes().0, b.plane.axes().1], axes, "{source}");
                let normal = b.plane.axes().2.index();
                assert_eq!((element.start[normal], element.end[normal]), (0.0, 0.0));
                for j in 0..=32 {
                    let u = f64::from(j) / 32.0;
                    let want = curve.at(span[0] + u * (span[1] - span[0]));
                    let got = bezier_point(element, u);
                    let d = (got[0] - want[0]).abs().max((got[1] - want[1]).abs());
                    assert!(d < 1e-9, "{source}: {span:?} u {u}: {got:?} vs {want:?}");
                }
            }
            let end = e.last().unwrap().end;
            assert_eq!([end[axes[0].index()], end[axes[1].index()]], POINTS[6]);
        }
    }
}

/// Unequal weights (R) and order 5: cubics within `NURBS_FIT_SHARE` of the default
/// tolerance of the rational curve, ends exact, joined end to start, each carrying its
/// share as `fit`.
#[test]
fn rational_and_high_order_blocks_are_fitted_within_their_share() {
    let bound = NURBS_FIT_SHARE * pvt_core::defaults::TOLERANCE_MM;
    let weights = [1.0, 2.5, 0.4, 3.0, 1.0, 0.7, 1.0];
    let cases: [(&[f64], &[f64], usize); 2] = [
        (&weights, &KNOTS, 3),
        (
            &[1.0; 7],
            &[0.0, 0.0, 0.0, 0.0, 0.0, 1.5, 2.2, 3.0, 3.0, 3.0, 3.0, 3.0],
            5,
        ),
    ];
    for plane in [17, 18] {
        for (weights, knots, order) in cases {
            let source = program(plane, &POINTS, weights, knots, order);
            let curve = TrueNurbs::new(&POINTS, weights, knots, order, 2000);
            let e = bezier_elements(&source);
            assert!(e.len() > 3, "{source}");
            for pair in e.windows(2) {
                assert_eq!(pair[0].end, pair[1].start, "{source}");
            }
            let (mut at, mut worst) = (0, 0.0_f64);
            for element in &e {
                let ElementKind::Bezier(b) = element.kind else {
                    unreachable!()
                };
                assert_eq!(b.fit, bound, "{source}");
                for j in 0..=64 {
                    let p = bezier_point(element, f64::from(j) / 64.0);
                    worst = worst.max(curve.distance(p, &mut at));
                }
            }
            assert!(worst <= bound && worst > 0.0, "{source}: {worst} > {bound}");
            assert_eq!(bezier_point(&e[0], 0.0), POINTS[0]);
            assert_eq!(bezier_point(e.last().unwrap(), 1.0), POINTS[6]);
        }
    }
}

/// The planned motion (the path planner at the default tolerance) of exact, rational
/// and order-5 blocks is within the tolerance of the true NURBS, in G17 and G19.
#[test]
fn the_planned_motion_follows_the_nurbs() {
    let tolerance = pvt_core::defaults::TOLERANCE_MM;
    let cases: [(&[f64], &[f64], usize); 3] = [
        (&[1.0; 7], &KNOTS, 3),
        (&[1.0, 8.0, 0.2, 3.0, 1.0, 0.1, 1.0], &KNOTS, 3),
        (
            &[1.0; 7],
            &[0.0, 0.0, 0.0, 0.0, 0.0, 1.5, 2.2, 3.0, 3.0, 3.0, 3.0, 3.0],
            5,
        ),
    ];
    for plane in [17, 19] {
        for (weights, knots, order) in cases {
            let source = program(plane, &POINTS, weights, knots, order);
            let curve = TrueNurbs::new(&POINTS, weights, knots, order, 2000);
            // The curve's elements are the last closing knot's line.
            let line = 3 + knots.len() as u32 - 1;
            let worst = common::planned_distance(&source, &curve, plane_axes(plane), &[line]);
            assert!(worst <= tolerance && worst > 0.0, "{source}: {worst}");
        }
    }
}

/// Where the tool is not at the first control point, a straight feed goes there first.
#[test]
fn a_block_away_from_the_tool_starts_with_a_feed_to_it() {
    let source = program(17, &POINTS, &[1.0; 7], &KNOTS, 3);
    let compiled = compile(&source, &GcodeOptions::default()).expect("compiles");
    let feed = &compiled.toolpath.contours[1].elements;
    assert!(matches!(feed[0].kind, ElementKind::Bezier(_)));
    let source = source.replace("G0 X10 Y5", "G0 X3 Y4");
    let compiled = compile(&source, &GcodeOptions::default()).expect("compiles");
    let feed = &compiled.toolpath.contours[1].elements;
    assert!(matches!(feed[0].kind, ElementKind::Line));
    assert_eq!((feed[0].start[0], feed[0].start[1]), (3.0, 4.0));
    assert_eq!((feed[0].end[0], feed[0].end[1]), (10.0, 5.0));
    assert!(matches!(feed[1].kind, ElementKind::Bezier(_)));
}

/// P, Q, R and K words of a block are its own: no warning.
#[test]
fn the_words_of_a_block_are_not_ignored() {
    let source = program(17, &POINTS, &[1.0; 7], &KNOTS, 3);
    let compiled = compile(&source, &GcodeOptions::default()).expect("compiles");
    assert!(compiled.warnings.is_empty(), "{:?}", compiled.warnings);
}

#[test]
fn refusals_are_at_their_lines() {
    let head = "G21 G17 F600\n";
    let close = "G6.2 K2\nG6.2 K2\nG6.2 K2\n";
    for (body, line, code) in [
        // No order P on the opening line, or a bad one.
        (
            format!("G6.2 X0 Y0 R1 K0\nX1 Y1 R1 K0\nX2 Y0 R1 K0\n{close}"),
            2,
            "missing_word",
        ),
        (
            format!("G6.2 X0 Y0 R1 K0 P1\nX1 Y1 R1 K0\nX2 Y0 R1 K0\n{close}"),
            2,
            "bad_value",
        ),
        // P after the opening line.
        (
            format!("G6.2 X0 Y0 R1 K0 P3\nX1 Y1 R1 K0 P3\nX2 Y0 R1 K0\n{close}"),
            3,
            "bad_value",
        ),
        // A control point without R, without K, with a non-positive R.
        (
            format!("G6.2 X0 Y0 R1 K0 P3\nX1 Y1 K0\nX2 Y0 R1 K0\n{close}"),
            3,
            "missing_word",
        ),
        (
            format!("G6.2 X0 Y0 R1 K0 P3\nX1 Y1 R1\nX2 Y0 R1 K0\n{close}"),
            3,
            "missing_word",
        ),
        (
            format!("G6.2 X0 Y0 R1 K0 P3\nX1 Y1 R0 K0\nX2 Y0 R1 K0\n{close}"),
            3,
            "bad_value",
        ),
        // A knot below the one before.
        (
            format!("G6.2 X0 Y0 R1 K0 P3\nX1 Y1 R1 K1\nX2 Y0 R1 K0\n{close}"),
            4,
            "bad_value",
        ),
        // A control point after a closing knot.
        (
            "G6.2 X0 Y0 R1 K0 P3\nX1 Y1 R1 K0\nG6.2 K1\nX2 Y0 R1 K0\n".to_string(),
            5,
            "missing_word",
        ),
        // Fewer control points than P.
        (
            "G6.2 X0 Y0 R1 K0 P3\nX1 Y1 R1 K0\nG6.2 K1\nG6.2 K1\nG6.2 K1\n".to_string(),
            2,
            "missing_word",
        ),
        // Unclamped knots.
        (
            "G6.2 X0 Y0 R1 K0 P3\nX1 Y1 R1 K0\nX2 Y0 R1 K1\nG6.2 K2\nG6.2 K2\nG6.2 K2\n"
                .to_string(),
            7,
            "unsupported",
        ),
        // Z in G17, inverse time.
        (
            format!("G6.2 X0 Y0 R1 K0 P3\nX1 Y1 Z1 R1 K0\nX2 Y0 R1 K0\n{close}"),
            3,
            "unsupported",
        ),
        (
            format!("G93\nG6.2 X0 Y0 R1 K0 P3\nX1 Y1 R1 K0\nX2 Y0 R1 K0\n{close}"),
            3,
            "unsupported",
        ),
        // Other motion before the closing knots.
        (
            "G6.2 X0 Y0 R1 K0 P3\nX1 Y1 R1 K0\nX2 Y0 R1 K0\nG6.2 K2\nG1 X5\n".to_string(),
            2,
            "missing_word",
        ),
        // A control point line in G6.2 mode after the block ended, without G6.2.
        (
            format!("G6.2 X0 Y0 R1 K0 P3\nX1 Y1 R1 K0\nX2 Y0 R1 K0\n{close}X3 Y3 R1 K0\n"),
            8,
            "missing_word",
        ),
    ] {
        let source = format!("{head}{body}M2\n");
        let (said, at, _) = common::errors(&source)[0];
        assert_eq!((said, at), (code, line), "{source}");
    }
}

//! G5.2/G5.3 NURBS blocks: the Béziers a block makes, against the NURBS LinuxCNC
//! defines (the start as first control point, weights P, order L (3 when absent), the
//! uniform clamped knot vector `0…0 1 2 … m…m`) evaluated here by the Cox–de Boor
//! recursion in homogeneous coordinates, random control points included; the refusals
//! at their lines; and, against LinuxCNC's `rs274`, which blocks it accepts and the
//! point count of each curve (`NURBS_FEED(n, …)`). Without rs274 the differential tests
//! say SKIPPED; with `PVTC_REQUIRE_RS274=1` they fail instead.

mod common;

use common::{bezier_elements, bezier_point};

use proptest::prelude::*;
use pvt_core::ElementKind;
use pvt_gcode::{compile, GcodeOptions};

/// The B-spline basis function `N(i, order)` at `t` (Cox–de Boor, half-open spans, the
/// domain's end closing the last one).
fn basis(i: usize, order: usize, t: f64, knots: &[f64]) -> f64 {
    if order == 1 {
        let end = *knots.last().unwrap();
        let inside = knots[i] <= t && t < knots[i + 1];
        let last = t == end && knots[i] < knots[i + 1] && knots[i + 1] == end;
        return f64::from(u8::from(inside || last));
    }
    let mut value = 0.0;
    let left = knots[i + order - 1] - knots[i];
    if left > 0.0 {
        value += (t - knots[i]) / left * basis(i, order - 1, t, knots);
    }
    let right = knots[i + order] - knots[i + 1];
    if right > 0.0 {
        value += (knots[i + order] - t) / right * basis(i + 1, order - 1, t, knots);
    }
    value
}

/// The NURBS point at `t` ∈ [0, points − order + 1].
fn nurbs(points: &[[f64; 2]], weights: &[f64], order: usize, t: f64) -> [f64; 2] {
    let n = points.len();
    let m = (n - order + 1) as f64;
    let knots: Vec<f64> = (0..n + order)
        .map(|i| (i as f64 - order as f64 + 1.0).clamp(0.0, m))
        .collect();
    let (mut x, mut y, mut w) = (0.0, 0.0, 0.0);
    for i in 0..n {
        let b = basis(i, order, t, &knots) * weights[i];
        x += b * points[i][0];
        y += b * points[i][1];
        w += b;
    }
    [x / w, y / w]
}

/// Checks the elements trace the NURBS: span `k` of the curve is element `k`, the
/// element's `u` the parameter `k + u`.
fn assert_traces(source: &str, points: &[[f64; 2]], order: usize) {
    let e = bezier_elements(source);
    let weights = vec![1.0; points.len()];
    assert_eq!(e.len(), points.len() + 1 - order, "{source}");
    for (k, element) in e.iter().enumerate() {
        for j in 0..=32 {
            let u = f64::from(j) / 32.0;
            let want = nurbs(points, &weights, order, k as f64 + u);
            let got = bezier_point(element, u);
            let d = (got[0] - want[0]).abs().max((got[1] - want[1]).abs());
            assert!(d < 1e-9, "{source}: span {k} u {u}: {got:?} vs {want:?}");
        }
    }
}

/// A block from `start` through `rest`, every weight `weight` (the start's set by an
/// opening `G5.2 P- L-` line when `order` is given).
fn program(start: [f64; 2], rest: &[[f64; 2]], weight: f64, order: Option<usize>) -> String {
    let mut s = format!("G21 G17 G90 F600\nG0 X{} Y{}\n", start[0], start[1]);
    let opened = order.is_some();
    if let Some(l) = order {
        s += &format!("G5.2 P{weight} L{l}\n");
    }
    for (i, p) in rest.iter().enumerate() {
        let head = if i == 0 && !opened { "G5.2 " } else { "" };
        s += &format!("{head}X{} Y{} P{weight}\n", p[0], p[1]);
    }
    s + "G5.3\nM2\n"
}

#[test]
fn a_block_is_its_uniform_clamped_nurbs() {
    let points = [
        [0.0, 0.0],
        [0.0, 10.0],
        [20.0, 20.0],
        [20.0, 0.0],
        [40.0, 5.0],
    ];
    // L1 to L3 are order 3, as rs274 reads them.
    for (l, order) in [(1, 3), (2, 3), (3, 3), (4, 4)] {
        let source = program(points[0], &points[1..], 2.0, Some(l));
        assert_traces(&source, &points, order);
    }
    // L left out: order 3.
    let source = program(points[0], &points[1..], 1.0, None);
    assert_traces(&source, &points, 3);
    // G5.2 P- L- alone sets the start's weight; the block goes on at the next line.
    let source = "G21 G17 F600\nG5.2 P1 L3\nX0 Y10 P1\nX20 Y20 P1\nG5.3\nM2\n";
    assert_traces(source, &[[0.0, 0.0], [0.0, 10.0], [20.0, 20.0]], 3);
}

/// The largest distance from the elements' cubics (64 samples each) to the NURBS
/// ([`common::TrueNurbs`]), with the ends and joins checked.
fn fit_error(source: &str, points: &[[f64; 2]], weights: &[f64], order: usize) -> f64 {
    let e = bezier_elements(source);
    let curve = common::TrueNurbs::uniform(points, weights, order, 2000);
    let first = [e[0].start[0], e[0].start[1]];
    assert_eq!(first, points[0], "{source}");
    let last = e.last().unwrap().end;
    assert!(
        close(points[points.len() - 1], [last[0], last[1]]),
        "{source}"
    );
    for pair in e.windows(2) {
        assert_eq!(pair[0].end, pair[1].start, "{source}");
    }
    let mut at: usize = 0;
    let mut worst: f64 = 0.0;
    for element in &e {
        for j in 0..=64 {
            let p = bezier_point(element, f64::from(j) / 64.0);
            worst = worst.max(curve.distance(p, &mut at));
        }
    }
    worst
}

fn close(a: [f64; 2], b: [f64; 2]) -> bool {
    (a[0] - b[0]).abs() < 1e-9 && (a[1] - b[1]).abs() < 1e-9
}

/// The control polygon of the fitted-block tests: six points, a loop and a hook.
const POLYGON: [[f64; 2]; 6] = [
    [0.0, 0.0],
    [0.0, 10.0],
    [20.0, 20.0],
    [20.0, 0.0],
    [40.0, 5.0],
    [45.0, 30.0],
];

/// Rational and order-5 blocks: cubics within `NURBS_FIT_SHARE` of the default
/// tolerance (0.001 mm) of the NURBS, ends exact, joined end to start.
#[test]
fn rational_and_high_order_blocks_are_fitted_within_their_share() {
    let bound = pvt_gcode::NURBS_FIT_SHARE * pvt_core::defaults::TOLERANCE_MM;
    let points = POLYGON;
    let cases: [(&[f64], usize); 3] = [
        (&[1.0, 3.0, 0.5, 2.0, 1.0, 1.0], 3),
        (&[1.0, 1.0, 1.0, 1.0, 1.0, 1.0], 5),
        (&[2.0, 1.0, 4.0, 1.0, 0.7, 1.0], 6),
    ];
    for (weights, order) in cases {
        let mut source = format!("G21 G17 G90 F600\nG5.2 P{} L{order}\n", weights[0]);
        for (p, w) in points[1..].iter().zip(&weights[1..]) {
            source += &format!("X{} Y{} P{w}\n", p[0], p[1]);
        }
        source += "G5.3\nM2\n";
        let worst = fit_error(&source, &points, weights, order);
        assert!(worst <= bound, "{source}: {worst} > {bound}");
        assert!(
            bezier_elements(&source).len() > points.len() - order + 1,
            "{source}"
        );
    }
}

#[test]
fn refusals_are_at_their_lines() {
    let head = "G21 G17 F600\n";
    for (body, line, code) in [
        ("G5.2 X1 L3 P1\nX2 Y0 P1\nG5.3\n", 2, "missing_word"),
        ("G5.2 X1 Y1 L3 P1\nX2 Y0\nG5.3\n", 3, "missing_word"),
        ("G5.2 X1 Y1 L4 P1\nX2 Y0 P1\nG5.3\n", 4, "missing_word"),
        ("G5.3\n", 2, "missing_word"),
        ("G5.2 X1 Y1 L3 P1\nX2 Y0 P1\nG1 X3\n", 2, "missing_word"),
        ("G5.2 X1 Y1 L3 P1\nX2 Y0 P1\n", 4, "missing_word"),
        (
            "G5.2 X1 Y1 L3 P1\nX2 Y0 P1\nG5.3\nX5 Y5\n",
            5,
            "no_motion_mode",
        ),
        (
            "G5.2 X1 Y1 L3 P1\nX2 Y0 P2\nX3 Y1 Z1 P1\nG5.3\n",
            4,
            "unsupported",
        ),
        (
            "G93\nG5.2 X1 Y1 L3 P1\nX2 Y0 P1\nX3 Y1 P1\nG5.3\n",
            3,
            "unsupported",
        ),
    ] {
        let source = format!("{head}{body}M2\n");
        let (said, at, _) = common::errors(&source)[0];
        assert_eq!((said, at), (code, line), "{source}");
    }
}

fn coordinate() -> impl Strategy<Value = [f64; 2]> {
    [-500i32..500, -500i32..500].prop_map(|v| v.map(|c| f64::from(c) / 10.0))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// rs274 accepts every random block pvtc accepts, with one curve of as many points
    /// as the block has (the start included); pvtc's Béziers trace the NURBS of order
    /// `max(L, 3)` (order 5 and 6: within `NURBS_FIT_SHARE` of the default tolerance).
    #[test]
    fn rs274_reads_the_same_blocks(
        points in prop::collection::vec(coordinate(), 6..12),
        l in 2usize..=6,
        weight in 1u8..=3,
    ) {
        let source = program(points[0], &points[1..], f64::from(weight), Some(l));
        let order = l.max(3);
        if order <= 4 {
            assert_traces(&source, &points, order);
        } else {
            let bound = pvt_gcode::NURBS_FIT_SHARE * pvt_core::defaults::TOLERANCE_MM;
            let weights = vec![1.0; points.len()];
            prop_assert!(fit_error(&source, &points, &weights, order) <= bound, "{}", source);
        }
        let Some(reading) = common::rs274_nurbs_counts(&source, "nurbs-random") else {
            eprintln!("SKIPPED: rs274 is not installed");
            return Ok(());
        };
        let counts = reading.map_err(|e| TestCaseError::fail(format!("{source}\n{e}")))?;
        prop_assert_eq!(counts, vec![points.len()], "{}", source);
    }
}

/// The programs pvtc refuses where LinuxCNC does, rs274 refuses too.
#[test]
fn rs274_refuses_what_pvtc_refuses() {
    for body in [
        "G5.2 X1 L3 P1\nX2 Y0 P1\nG5.3\n",
        "G5.2 X1 Y1 L3 P1\nX2 Y0\nG5.3\n",
        "G5.2 X1 Y1 L4 P1\nX2 Y0 P1\nG5.3\n",
        "G5.3\n",
        "G5.2 X1 Y1 L3 P1\nX2 Y0 P1\nG1 X3\nG5.3\n",
        "G5.2 X1 Y1 L3 P1\nX2 Y0 P1\nG5.3\nX5 Y5\n",
    ] {
        let source = format!("G21 G17 F600\n{body}M2\n");
        let Some(reading) = common::rs274_nurbs_counts(&source, "nurbs-refused") else {
            eprintln!("SKIPPED: rs274 is not installed");
            return;
        };
        assert!(reading.is_err(), "rs274 accepts {body}");
        assert!(compile(&source, &GcodeOptions::default()).is_err());
    }
}

/// G5.2 in G18 and G19, under G91 and with L on a later line, as rs274 (LinuxCNC 2.9)
/// runs them: the curve is in XY whatever the plane (X Y words, Z stays), under G91 every
/// control point is an offset from the block's start, an L above 3 on any line sets the
/// order; rs274's point count is pvtc's and its next feed starts where pvtc's tool is.
#[test]
fn rs274_places_blocks_in_every_plane_and_distance_mode() {
    let start = [1.0, 0.5];
    let words = [[3.0, 5.0], [6.0, 4.0], [8.0, 9.0], [10.0, 2.0]];
    for (modes, later_l, order) in [
        ("G18 G90", "", 3),
        ("G19 G90", "", 3),
        ("G17 G91", "", 3),
        ("G19 G91", "", 3),
        ("G18 G90", " L4", 4),
    ] {
        let mut source = format!("G21 {modes} F600\nG0 X1 Y0.5 Z2\nG5.2 P1 L2\n");
        for (i, w) in words.iter().enumerate() {
            let l = if i == 2 { later_l } else { "" };
            source += &format!("X{} Y{} P1{l}\n", w[0], w[1]);
        }
        source += "G5.3\nG1 A1\nM2\n";
        let offset = if modes.contains("G91") {
            start
        } else {
            [0.0, 0.0]
        };
        let mut points = vec![start];
        points.extend(words.iter().map(|w| [w[0] + offset[0], w[1] + offset[1]]));
        assert_traces(&source, &points, order);
        let compiled = compile(&source, &GcodeOptions::default()).expect("compiles");
        let last = compiled
            .toolpath
            .contours
            .last()
            .unwrap()
            .elements
            .last()
            .unwrap();
        assert!(matches!(last.kind, ElementKind::Line), "{source}");
        let Some(counts) = common::rs274_nurbs_counts(&source, "nurbs-planes") else {
            eprintln!("SKIPPED: rs274 is not installed");
            return;
        };
        assert_eq!(counts.expect("rs274 accepts it"), vec![5], "{source}");
        let ends = common::rs274_feed_ends(&source, "nurbs-planes")
            .unwrap()
            .unwrap();
        let rs274 = ends[0];
        for (k, want) in rs274.iter().enumerate() {
            assert!(
                (last.start[k] - want).abs() < 1e-4,
                "{source}: {rs274:?} vs {:?}",
                last.start
            );
        }
    }
}

/// The planned motion (the path planner at the default tolerance), every PVT segment's
/// cubic evaluated here at 64 times, is within the tolerance of the true NURBS (its
/// distance refined on the curve itself), exact and fitted blocks alike: a fitted
/// cubic's `fit` is taken from what the planner may deviate from it.
#[test]
fn the_planned_motion_follows_the_nurbs() {
    let points = POLYGON;
    let tolerance = pvt_core::defaults::TOLERANCE_MM;
    let cases: [(&[f64], usize); 4] = [
        (&[1.0; 6], 4),
        (&[1.0, 3.0, 0.5, 2.0, 1.0, 1.0], 3),
        (&[1.0, 20.0, 0.05, 9.0, 0.3, 1.0], 4),
        (&[1.0; 6], 6),
    ];
    for (weights, order) in cases {
        let mut source = format!("G21 G17 G90 F3000\nG5.2 P{} L{order}\n", weights[0]);
        for (p, w) in points[1..].iter().zip(&weights[1..]) {
            source += &format!("X{} Y{} P{w}\n", p[0], p[1]);
        }
        source += "G5.3\nM2\n";
        let curve = common::TrueNurbs::uniform(&points, weights, order, 2000);
        let axes = [pvt_core::Axis::X, pvt_core::Axis::Y];
        let worst = common::planned_distance(&source, &curve, axes, &[8]);
        assert!(worst <= tolerance, "{source}: {worst} > {tolerance}");
        assert!(worst > 0.0, "{source}");
    }
}

/// A NURBS block's P and L words are its own: no `ignored_word` warning.
#[test]
fn p_and_l_words_of_a_block_are_not_ignored() {
    let source = "G21 G17 F100\nG5.2 P1 L3\nX0 Y1 P1\nX2 Y2 P1\nX2 Y0 P1\nX0 Y0 P2\nG5.3\nM2\n";
    let compiled = compile(source, &GcodeOptions::default()).expect("compiles");
    assert!(compiled.warnings.is_empty(), "{:?}", compiled.warnings);
}

#[test]
fn lines_without_axis_words_inside_a_block_add_no_point() {
    // LinuxCNC's nc_files/nurbs/G5/Curva_Delfino #1=1_G5.ngc has `;K29` lines in its block.
    let plain = "G21 G17 G90 F100\nG0 X0 Y0\nG5.2 P1 L3\nX0 Y1 P1\nX2 Y2 P1\nX2 Y0 P1\nX0 Y0 P2\nG5.3\nM2\n";
    let noisy = "G21 G17 G90 F100\nG0 X0 Y0\nG5.2 P1 L3\nX0 Y1 P1\n\n(a comment)\nX2 Y2 P1\n;K3\nF100\nX2 Y0 P1\nX0 Y0 P2\n;K3\nG5.3\nM2\n";
    let (a, b) = (bezier_elements(plain), bezier_elements(noisy));
    assert!(!a.is_empty());
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(&b) {
        assert_eq!((x.start, x.end, x.kind), (y.start, y.end, y.kind));
    }
}

#[test]
fn a_block_in_the_planes_own_words_is_the_same_curve_in_that_plane() {
    // LinuxCNC 2.10's nc_files/nurbs/G5 (nurbs-yz.ngc, nurbs-zx.ngc) write G5.2 in G18/G19
    // with the plane's words; rs274 2.9 reads only X Y. The same control points in each
    // plane's words must give the G17 curve on that plane's axes.
    let block = |plane: &str, a: char, b: char| {
        let p = |x: i32, y: i32| format!("{a}{x} {b}{y}");
        format!(
            "G21 {plane} G90 F100\nG0 X0 Y0 Z0\nG5.2 P1 L3\n{} P1\n{} P1\n{} P1\n{} P2\nG5.3\nM2\n",
            p(0, 1),
            p(2, 2),
            p(2, 0),
            p(0, 0)
        )
    };
    let xy = bezier_elements(&block("G17", 'X', 'Y'));
    assert!(!xy.is_empty());
    for (plane, a, b, ia, ib) in [("G18", 'Z', 'X', 2, 0), ("G19", 'Y', 'Z', 1, 2)] {
        let other = bezier_elements(&block(plane, a, b));
        assert_eq!(other.len(), xy.len(), "{plane}");
        for (e, f) in xy.iter().zip(&other) {
            for (p, q) in [(e.start, f.start), (e.end, f.end)] {
                assert_eq!((p[0], p[1]), (q[ia], q[ib]), "{plane}");
            }
            for k in 1..8 {
                let u = f64::from(k) / 8.0;
                let (c, d) = (bezier_point(e, u), bezier_point(f, u));
                assert!(
                    (c[0] - d[0]).abs().max((c[1] - d[1]).abs()) < 1e-12,
                    "{plane} at {u}"
                );
            }
        }
    }
    // Words of two planes in one block, or X Y Z in G18, are refused.
    for source in [
        "G21 G18 F100\nG5.2 P1 L3\nZ0 X1 P1\nX2 Y2 P1\nZ2 X0 P1\nG5.3\nM2\n",
        "G21 G18 F100\nG5.2 P1 L3\nX0 Y1 Z1 P1\nX2 Y2 P1\nX2 Y0 P1\nG5.3\nM2\n",
    ] {
        assert!(
            compile(source, &GcodeOptions::default()).is_err(),
            "{source}"
        );
    }
}

//! G5.2/G5.3 NURBS blocks: the Béziers a block makes, against the NURBS LinuxCNC
//! defines (the start as first control point, weights P, order L (3 when absent), the
//! uniform clamped knot vector `0…0 1 2 … m…m`) evaluated here by the Cox–de Boor
//! recursion in homogeneous coordinates, random control points included; the refusals
//! at their lines; and, against LinuxCNC's `rs274`, which blocks it accepts and the
//! point count of each curve (`NURBS_FEED(n, …)`). Without rs274 the differential tests
//! say SKIPPED; with `PVTC_REQUIRE_RS274=1` they fail instead.

mod common;

use proptest::prelude::*;
use pvt_core::{Element, ElementKind};
use pvt_gcode::{compile, GcodeOptions};

fn elements(source: &str) -> Vec<Element> {
    compile(source, &GcodeOptions::default())
        .unwrap_or_else(|e| panic!("{source}: {:?}", e.diagnostics))
        .toolpath
        .contours
        .into_iter()
        .flat_map(|c| c.elements)
        .filter(|e| matches!(e.kind, ElementKind::Bezier(_)))
        .collect()
}

fn cubic(e: &Element, u: f64) -> [f64; 2] {
    let ElementKind::Bezier(b) = e.kind else {
        panic!("not a Bézier: {e:?}");
    };
    let p = [
        [e.start[0], e.start[1]],
        b.controls[0],
        b.controls[1],
        [e.end[0], e.end[1]],
    ];
    let s = 1.0 - u;
    let w = [s * s * s, 3.0 * s * s * u, 3.0 * s * u * u, u * u * u];
    [0, 1].map(|k| (0..4).map(|i| w[i] * p[i][k]).sum())
}

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
    let e = elements(source);
    let weights = vec![1.0; points.len()];
    assert_eq!(e.len(), points.len() + 1 - order, "{source}");
    for (k, element) in e.iter().enumerate() {
        for j in 0..=32 {
            let u = f64::from(j) / 32.0;
            let want = nurbs(points, &weights, order, k as f64 + u);
            let got = cubic(element, u);
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
    for order in [2, 3, 4] {
        let source = program(points[0], &points[1..], 2.0, Some(order));
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
/// (a polyline of `per_span` samples per knot span, searched near the last match).
fn fit_error(source: &str, points: &[[f64; 2]], weights: &[f64], order: usize) -> f64 {
    let e = elements(source);
    let spans = points.len() + 1 - order;
    let n = spans * 4000;
    let curve: Vec<[f64; 2]> = (0..=n)
        .map(|i| nurbs(points, weights, order, spans as f64 * i as f64 / n as f64))
        .collect();
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
            let p = cubic(element, f64::from(j) / 64.0);
            let window = at.saturating_sub(400)..(at + 4000).min(n);
            let (best, d) = window
                .map(|i| (i, segment_distance(p, curve[i], curve[i + 1])))
                .fold((at, f64::INFINITY), |a, b| if b.1 < a.1 { b } else { a });
            at = best;
            worst = worst.max(d);
        }
    }
    worst
}

fn close(a: [f64; 2], b: [f64; 2]) -> bool {
    (a[0] - b[0]).abs() < 1e-9 && (a[1] - b[1]).abs() < 1e-9
}

fn segment_distance(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (ab, ap) = ([b[0] - a[0], b[1] - a[1]], [p[0] - a[0], p[1] - a[1]]);
    let len2 = ab[0] * ab[0] + ab[1] * ab[1];
    let t = if len2 > 0.0 {
        ((ap[0] * ab[0] + ap[1] * ab[1]) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let d = [ap[0] - t * ab[0], ap[1] - t * ab[1]];
    (d[0] * d[0] + d[1] * d[1]).sqrt()
}

/// Rational and order-5 blocks: cubics within `NURBS_FIT_SHARE` of the default
/// tolerance (0.001 mm) of the NURBS, ends exact, joined end to start.
#[test]
fn rational_and_high_order_blocks_are_fitted_within_their_share() {
    let bound = pvt_gcode::NURBS_FIT_SHARE * pvt_core::defaults::TOLERANCE_MM;
    let points = [
        [0.0, 0.0],
        [0.0, 10.0],
        [20.0, 20.0],
        [20.0, 0.0],
        [40.0, 5.0],
        [45.0, 30.0],
    ];
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
            elements(&source).len() > points.len() - order + 1,
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
        ("G18\nG5.2 X1 Y1 L3 P1\nX2 Y0 P1\nG5.3\n", 3, "unsupported"),
    ] {
        let source = format!("{head}{body}M2\n");
        let Err(e) = compile(&source, &GcodeOptions::default()) else {
            panic!("accepted: {source}");
        };
        let first = &e.diagnostics[0];
        let at = miette::Diagnostic::labels(first)
            .and_then(|mut l| l.next())
            .map(|l| source[..l.offset()].matches('\n').count() + 1);
        let code = format!("pvtc::gcode::{code}");
        let said = miette::Diagnostic::code(first).map(|c| c.to_string());
        assert_eq!(said.as_deref(), Some(code.as_str()), "{source}");
        assert_eq!(at, Some(line), "{source}");
    }
}

fn coordinate() -> impl Strategy<Value = [f64; 2]> {
    [-500i32..500, -500i32..500].prop_map(|v| v.map(|c| f64::from(c) / 10.0))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// rs274 accepts every random block pvtc accepts, with one curve of as many points
    /// as the block has (the start included); pvtc's Béziers trace the NURBS (order 5
    /// and 6: within `NURBS_FIT_SHARE` of the default tolerance).
    #[test]
    fn rs274_reads_the_same_blocks(
        points in prop::collection::vec(coordinate(), 6..12),
        order in 2usize..=6,
        weight in 1u8..=3,
    ) {
        let source = program(points[0], &points[1..], f64::from(weight), Some(order));
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

/// The planned motion (the path planner at the default tolerance), every PVT segment's
/// cubic evaluated here at 32 times, is within the tolerance of the true NURBS (exact
/// blocks), and within `1 + NURBS_FIT_SHARE` times it (fitted ones).
#[test]
fn the_planned_motion_follows_the_nurbs() {
    let points = [
        [0.0, 0.0],
        [0.0, 10.0],
        [20.0, 20.0],
        [20.0, 0.0],
        [40.0, 5.0],
        [45.0, 30.0],
    ];
    let tolerance = pvt_core::defaults::TOLERANCE_MM;
    let cases: [(&[f64], usize, f64); 3] = [
        (&[1.0; 6], 4, tolerance),
        (
            &[1.0, 3.0, 0.5, 2.0, 1.0, 1.0],
            3,
            tolerance * (1.0 + pvt_gcode::NURBS_FIT_SHARE),
        ),
        (&[1.0; 6], 6, tolerance * (1.0 + pvt_gcode::NURBS_FIT_SHARE)),
    ];
    for (weights, order, bound) in cases {
        let mut source = format!("G21 G17 G90 F3000\nG5.2 P{} L{order}\n", weights[0]);
        for (p, w) in points[1..].iter().zip(&weights[1..]) {
            source += &format!("X{} Y{} P{w}\n", p[0], p[1]);
        }
        source += "G5.3\nM2\n";
        let compiled = compile(&source, &GcodeOptions::default()).expect("compiles");
        let options = pvt_core::PlanOptions {
            planner: pvt_core::Planner::Path,
            ..pvt_core::PlanOptions::default()
        };
        let program = pvt_core::plan_toolpath(&compiled.toolpath, &options).expect("planned");
        assert_eq!(program.axes.len(), 2, "{source}");
        let spans = points.len() + 1 - order;
        let n = spans * 4000;
        let curve: Vec<[f64; 2]> = (0..=n)
            .map(|i| nurbs(&points, weights, order, spans as f64 * i as f64 / n as f64))
            .collect();
        let mut worst: f64 = 0.0;
        let mut at: usize = 0;
        for contour in &program.contours {
            let mut from = [contour.start[0], contour.start[1], 0.0, 0.0];
            for i in 0..contour.durations.len() {
                let (t, e, v) = (
                    contour.durations[i],
                    &contour.ends[2 * i..],
                    &contour.velocities[2 * i..],
                );
                for j in 0..=32 {
                    let s = f64::from(j) / 32.0;
                    let h = [
                        2.0 * s * s * s - 3.0 * s * s + 1.0,
                        s * s * s - 2.0 * s * s + s,
                        -2.0 * s * s * s + 3.0 * s * s,
                        s * s * s - s * s,
                    ];
                    let p = [0, 1].map(|k| {
                        h[0] * from[k] + h[1] * t * from[k + 2] + h[2] * e[k] + h[3] * t * v[k]
                    });
                    let window = at.saturating_sub(400)..(at + 4000).min(n);
                    let (best, d) = window
                        .map(|i| (i, segment_distance(p, curve[i], curve[i + 1])))
                        .fold((at, f64::INFINITY), |a, b| if b.1 < a.1 { b } else { a });
                    at = best;
                    worst = worst.max(d);
                }
                from = [e[0], e[1], v[0], v[1]];
            }
        }
        assert!(worst <= bound, "{source}: {worst} > {bound}");
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

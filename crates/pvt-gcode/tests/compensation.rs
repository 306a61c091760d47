//! Cutter-radius compensation keeps the tool radius from the programmed path: every
//! compensated element of a random closed profile (lines and arcs, convex and concave
//! corners, tool left or right), sampled densely, lies exactly one tool radius from the
//! nearest point of the programmed profile (within r·(1 − cos 0.05) after a corner that
//! turns less than LinuxCNC's 0.05 rad, which it takes as tangent), measured here from
//! the profile's own geometry. (Which path LinuxCNC makes is `crates/pvtc/tests/dialect.rs`'s question.)
//! Also the refusals, each with its code at its line.

use proptest::prelude::*;
use pvt_core::{ArcDirection, Element, ElementKind};
use pvt_gcode::{compile, GcodeOptions};

/// One edge of a programmed profile, in the XY plane.
#[derive(Debug, Clone, Copy)]
enum Edge {
    Line([f64; 2], [f64; 2]),
    /// From, to, centre, counter-clockwise.
    Arc([f64; 2], [f64; 2], [f64; 2], bool),
}

fn distance(a: [f64; 2], b: [f64; 2]) -> f64 {
    libm::hypot(b[0] - a[0], b[1] - a[1])
}

/// The angle from `a` to `b` counter-clockwise, in [0, 2π).
fn ccw_angle(a: f64, b: f64) -> f64 {
    (b - a).rem_euclid(std::f64::consts::TAU)
}

impl Edge {
    /// The distance from `p` to the edge.
    fn distance(&self, p: [f64; 2]) -> f64 {
        match *self {
            Edge::Line(a, b) => {
                let d = [b[0] - a[0], b[1] - a[1]];
                let t = ((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / (d[0] * d[0] + d[1] * d[1]);
                let t = t.clamp(0.0, 1.0);
                distance(p, [a[0] + t * d[0], a[1] + t * d[1]])
            }
            Edge::Arc(a, b, c, ccw) => {
                let angle = |q: [f64; 2]| libm::atan2(q[1] - c[1], q[0] - c[0]);
                let (from, to) = if ccw { (a, b) } else { (b, a) };
                let span = ccw_angle(angle(from), angle(to));
                let within = ccw_angle(angle(from), angle(p)) <= span;
                match within {
                    true => (distance(p, c) - distance(a, c)).abs(),
                    false => distance(p, a).min(distance(p, b)),
                }
            }
        }
    }
}

/// Points along an element of the compiled toolpath, computed from its start, end and
/// centre alone.
fn samples(element: &Element, count: usize) -> Vec<[f64; 2]> {
    let s = [element.start[0], element.start[1]];
    let e = [element.end[0], element.end[1]];
    (0..=count)
        .map(|i| {
            let t = i as f64 / count as f64;
            match element.kind {
                ElementKind::Line => [s[0] + t * (e[0] - s[0]), s[1] + t * (e[1] - s[1])],
                ElementKind::Arc(arc) => {
                    let c = arc.center;
                    let a0 = libm::atan2(s[1] - c[1], s[0] - c[0]);
                    let a1 = libm::atan2(e[1] - c[1], e[0] - c[0]);
                    let sweep = match arc.direction {
                        ArcDirection::CounterClockwise => ccw_angle(a0, a1),
                        ArcDirection::Clockwise => -ccw_angle(a1, a0),
                    };
                    let r = distance(s, c) + t * (distance(e, c) - distance(s, c));
                    let (sin, cos) = libm::sincos(a0 + t * sweep);
                    [c[0] + r * cos, c[1] + r * sin]
                }
                ElementKind::Bezier(_) => panic!("compensation never makes a spline"),
            }
        })
        .collect()
}

/// A star profile: corners at increasing angles (degrees) and distances from the origin,
/// each edge a line or an arc (bulge: radius over half chord, sign the side).
#[derive(Debug, Clone)]
struct Profile {
    corners: Vec<(f64, f64)>,
    bulges: Vec<Option<(bool, f64)>>,
    left: bool,
    reverse: bool,
    radius: f64,
}

fn profile() -> impl Strategy<Value = Profile> {
    (4usize..8).prop_flat_map(|n| {
        let arc = prop::option::weighted(0.4, (any::<bool>(), 130u32..400))
            .prop_map(|a| a.map(|(ccw, k)| (ccw, f64::from(k) / 100.0)));
        // Corner i within 30° after i·360°/n: the centre is inside the profile.
        let corner = |i: usize| {
            let at = (i * 360 / n) as u32;
            (at..at + 30, 120u32..250)
        };
        (
            (0..n).map(corner).collect::<Vec<_>>(),
            prop::collection::vec(arc, n),
            any::<bool>(),
            any::<bool>(),
            1u32..10,
        )
            .prop_map(|(corners, bulges, left, reverse, r)| Profile {
                corners: corners
                    .into_iter()
                    .map(|(a, r)| (f64::from(a), f64::from(r) / 10.0))
                    .collect(),
                bulges,
                left,
                reverse,
                radius: f64::from(r) / 10.0,
            })
    })
}

/// The cosine of the turn from `first`'s end to `second`'s start.
fn tangent_dot(first: Edge, second: Edge) -> f64 {
    let unit = |v: [f64; 2]| {
        let l = libm::hypot(v[0], v[1]);
        [v[0] / l, v[1] / l]
    };
    let tangent = |edge: Edge, at_end: bool| match edge {
        Edge::Line(a, b) => unit([b[0] - a[0], b[1] - a[1]]),
        Edge::Arc(a, b, c, ccw) => {
            let q = if at_end { b } else { a };
            let r = [q[0] - c[0], q[1] - c[1]];
            unit(if ccw { [-r[1], r[0]] } else { [r[1], -r[0]] })
        }
    };
    let (t1, t2) = (tangent(first, true), tangent(second, false));
    t1[0] * t2[0] + t1[1] * t2[1]
}

/// The least distance between edges of a closed profile that do not meet (sampled).
fn clearance(edges: &[Edge]) -> f64 {
    let n = edges.len();
    let mut least = f64::INFINITY;
    for (i, edge) in edges.iter().enumerate() {
        let points = match *edge {
            Edge::Line(a, b) => (0..=200)
                .map(|k| {
                    let t = f64::from(k) / 200.0;
                    [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]
                })
                .collect::<Vec<_>>(),
            Edge::Arc(a, b, c, ccw) => {
                let r = distance(a, c);
                let a0 = libm::atan2(a[1] - c[1], a[0] - c[0]);
                let a1 = libm::atan2(b[1] - c[1], b[0] - c[0]);
                let sweep = if ccw {
                    ccw_angle(a0, a1)
                } else {
                    -ccw_angle(a1, a0)
                };
                (0..=200)
                    .map(|k| {
                        let (sin, cos) = libm::sincos(a0 + f64::from(k) / 200.0 * sweep);
                        [c[0] + r * cos, c[1] + r * sin]
                    })
                    .collect()
            }
        };
        for (j, other) in edges.iter().enumerate() {
            let apart = (i + n - j) % n;
            if apart > 1 && apart < n - 1 {
                for &p in &points {
                    least = least.min(other.distance(p));
                }
            }
        }
    }
    least
}

/// The profile's edges (the first one twice) and its program (entry from outside, once
/// round and over the first edge again, G40, exit).
fn program(profile: &Profile) -> (Vec<Edge>, String) {
    let mut corners = profile.corners.clone();
    corners.sort_by(|a, b| a.0.total_cmp(&b.0));
    if profile.reverse {
        corners.reverse();
    }
    let points: Vec<[f64; 2]> = corners
        .iter()
        .map(|(a, r)| {
            let (sin, cos) = libm::sincos(a.to_radians());
            [r * cos, r * sin].map(|v| (v * 1e4).round() / 1e4)
        })
        .collect();
    let code = if profile.left { "G41.1" } else { "G42.1" };
    let start = points[0].map(|v| v * 1.8);
    let mut text = format!(
        "G21 G90 G17 F500\nG0 X{:.4} Y{:.4}\n{code} D{}\nG1 X{:.4} Y{:.4}\n",
        start[0],
        start[1],
        2.0 * profile.radius,
        points[0][0],
        points[0][1]
    );
    let mut edges = Vec::new();
    // Round once and over the first edge again, so that every corner is compensated.
    let n = points.len();
    for (i, bulge) in profile.bulges[..n]
        .iter()
        .chain(&profile.bulges[..1])
        .enumerate()
    {
        let i = i % n;
        let (a, b) = (points[i], points[(i + 1) % n]);
        match bulge {
            None => {
                edges.push(Edge::Line(a, b));
                text.push_str(&format!("G1 X{:.4} Y{:.4}\n", b[0], b[1]));
            }
            Some((ccw, k)) => {
                // The centre on the chord's bisector, a short arc of radius k·chord/2.
                let half = distance(a, b) / 2.0;
                let r = k * half;
                let offset = (r * r - half * half).sqrt();
                let side = if *ccw { 1.0 } else { -1.0 };
                let m = [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0];
                let n = [-(b[1] - a[1]) / (2.0 * half), (b[0] - a[0]) / (2.0 * half)];
                let c = [m[0] + side * offset * n[0], m[1] + side * offset * n[1]];
                edges.push(Edge::Arc(a, b, c, *ccw));
                let g = if *ccw { "G3" } else { "G2" };
                text.push_str(&format!(
                    "{g} X{:.4} Y{:.4} I{:.10} J{:.10}\n",
                    b[0],
                    b[1],
                    c[0] - a[0],
                    c[1] - a[1]
                ));
            }
        }
    }
    text.push_str(&format!("G40\nG0 X{:.4} Y{:.4}\nM2\n", start[0], start[1]));
    (edges, text)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn every_compensated_element_keeps_the_tool_radius_from_the_path(profile in profile()) {
        let (edges, text) = program(&profile);
        // Where edges that do not meet come within two radii, the offsets of the one
        // reach the other: a gouge no one-move look-ahead sees (LinuxCNC's neither).
        prop_assume!(clearance(&edges[..edges.len() - 1]) > 2.0 * profile.radius + 1e-3);
        // Nor does it see an edge that turns back along the one before (a spike).
        prop_assume!(edges.windows(2).all(|w| tangent_dot(w[0], w[1]) > -0.8));
        let compiled = compile(&text, &GcodeOptions::default());
        // A profile LinuxCNC would refuse (an inside corner too tight) has no path.
        prop_assume!(compiled.is_ok());
        let compiled = compiled.unwrap();
        // The first pass over the first edge starts from the entry move's corner, the
        // second ends where G40 finds the tool, before the corner after it.
        let profile_lines = 6..4 + edges.len() as u32;
        // A corner turning less than 0.05 rad is taken as tangent (LinuxCNC's rule): the
        // next move starts where the last ended, up to r·(1 − cos 0.05) off its offset.
        // The program's coordinates are the edges' written to 4 decimals: up to
        // 0.5·10⁻⁴·√2 from the edges measured here.
        let slack = profile.radius * (1.0 - libm::cos(0.05)) + 0.5e-4 * 2f64.sqrt() + 1e-9;
        let mut measured = 0;
        for element in compiled.toolpath.contours.iter().flat_map(|c| &c.elements) {
            // The entry move (line 4) and the exit after G40 approach the path.
            if !profile_lines.contains(&element.span.line) {
                continue;
            }
            for p in samples(element, 64) {
                let nearest = edges.iter().map(|e| e.distance(p)).fold(f64::INFINITY, f64::min);
                prop_assert!(
                    (nearest - profile.radius).abs() <= slack,
                    "{text}\nline {}: {p:?} is {nearest} from the path, the radius is {}",
                    element.span.line,
                    profile.radius
                );
                measured += 1;
            }
        }
        prop_assert!(measured > 0);
    }
}

#[test]
fn the_generator_makes_profiles_that_compile() {
    use proptest::strategy::ValueTree;
    let mut runner = proptest::test_runner::TestRunner::deterministic();
    let compiled = (0..40)
        .filter(|_| {
            let profile = profile()
                .new_tree(&mut runner)
                .expect("a profile")
                .current();
            compile(&program(&profile).1, &GcodeOptions::default()).is_ok()
        })
        .count();
    assert!(compiled >= 30, "only {compiled} of 40 profiles compile");
}

/// The measure itself fails a path one hundredth of the radius off.
#[test]
fn the_measure_sees_a_path_off_the_radius() {
    let edge = Edge::Line([0.0, 0.0], [10.0, 0.0]);
    assert!((edge.distance([5.0, 1.0]) - 1.0).abs() < 1e-12);
    assert!((edge.distance([5.0, 1.01]) - 1.0).abs() > 1e-7);
    let arc = Edge::Arc([1.0, 0.0], [0.0, 1.0], [0.0, 0.0], true);
    assert!((arc.distance([2.0, 0.0]) - 1.0).abs() < 1e-12);
    assert!((arc.distance([-2.0, 0.0]) - 5f64.sqrt()).abs() < 1e-12);
}

/// The (code, line) of every error of a program that must fail.
fn errors_with(source: &str, options: &GcodeOptions) -> Vec<(&'static str, usize)> {
    let errors = compile(source, options).expect_err("the program must fail");
    errors
        .diagnostics
        .iter()
        .map(|d| {
            let line = source[..d.span().start].matches('\n').count() + 1;
            (d.code().trim_start_matches("pvtc::gcode::"), line)
        })
        .collect()
}

#[test]
fn refusals_have_their_codes_at_their_lines() {
    let head = "G21 G90 G17 F100\nG0 X-10 Y-10\n";
    let options = GcodeOptions {
        tool_table: pvt_gcode::ToolTable::parse("T5 D0.4 Q2\n").expect("a table"),
        ..GcodeOptions::default()
    };
    let cases = [
        ("G41.1 D4\nG1 X-9 Y-10\n", ("compensation_entry", 4)),
        (
            "G41.1 D4\nG1 X0 Y0\nG1 X10 Y0\nG3 X10 Y2 R1\n",
            ("tool_radius_over_arc", 6),
        ),
        (
            "G41.1 D4\nG1 X0 Y0\nG1 X20 Y0\nG1 X20 Y1\nG1 X21 Y1\n",
            ("concave_corner", 7),
        ),
        (
            "G41.1 D4\nG1 X0 Y0\nG41.1 D2\n",
            ("compensation_conflict", 5),
        ),
        (
            "G41.1 D4\nG1 X0 Y0\nG40\nG2 X5 Y0 R5\n",
            ("compensation_conflict", 6),
        ),
        ("G41.1 D4\nG1 X0 Y0\nG19\n", ("compensation_conflict", 5)),
        ("G41.1 D4\nG1 X0 Y0\nG55\n", ("compensation_conflict", 5)),
        ("G41.1 D4\nG1 X0 Y0\nT5 M6\n", ("compensation_conflict", 5)),
        ("G41.1 D4\nG1 X0 Y0\nG43 H5\n", ("compensation_conflict", 5)),
        (
            "G41.1 D4\nG1 X0 Y0\nG53 G0 X0\n",
            ("compensation_conflict", 5),
        ),
        ("G41.1 D4\nG1 X0 Y0\nG28\n", ("compensation_conflict", 5)),
        (
            "G41.1 D4\nG1 X0 Y0\nG81 X1 Y1 Z-1 R1\n",
            ("compensation_conflict", 5),
        ),
        ("G19 G41.1 D4\n", ("compensation_conflict", 3)),
        ("G41.1\n", ("missing_word", 3)),
        ("G41 D7\n", ("unknown_tool", 3)),
        ("G41 D5\n", ("compensation_conflict", 3)),
        ("G41.1 D4 L3\n", ("compensation_conflict", 3)),
        ("G18 G41.1 D4 L12\n", ("bad_value", 3)),
    ];
    for (body, (code, line)) in cases {
        let source = format!("{head}{body}M2\n");
        let found = errors_with(&source, &options);
        assert!(
            found.iter().any(|&(c, l)| c == code && l == line),
            "{source}: {found:?}, expected {code} at line {line}"
        );
    }
}

//! The path planner's promises, checked independently of its own bounds: every cubic is
//! evaluated densely (as Bézier curves from its end states) and measured against the true
//! lines, arcs and helices; every programmed element is covered; per-axis peaks are
//! computed from the Bézier control points; piece counts and times are as documented.
//!
//! Long run: `PROPTEST_CASES=2000 cargo test -p pvt-core --test path --release`.
//!
//! The reference geometry uses std's trigonometry on purpose: it is independent of the
//! planner's libm, and these numbers are never written to an output.
#![allow(clippy::disallowed_methods)]

use proptest::prelude::*;
use pvt_core::{
    plan_path, Arc, ArcDirection, Axis, AxisLimits, Contour, Element, ElementKind, Motion,
    PathOptions, Plane, Position, PvtContour, Span,
};
use std::collections::BTreeMap;
use std::f64::consts::{FRAC_PI_2, PI};

const SAMPLES: usize = 48;

fn pos(x: f64, y: f64, z: f64) -> Position {
    [x, y, z, 0.0, 0.0, 0.0]
}

fn line(start: Position, end: Position, feed: f64) -> Element {
    Element {
        kind: ElementKind::Line,
        start,
        end,
        feed,
        span: Span::default(),
    }
}

fn arc(start: Position, end: Position, center: [f64; 2], ccw: bool, feed: f64) -> Element {
    Element {
        kind: ElementKind::Arc(Arc {
            plane: Plane::XY,
            center,
            direction: if ccw {
                ArcDirection::CounterClockwise
            } else {
                ArcDirection::Clockwise
            },
            extra_turns: 0,
        }),
        start,
        end,
        feed,
        span: Span::default(),
    }
}

fn contour(elements: Vec<Element>) -> Contour {
    Contour {
        motion: Motion::Feed,
        elements,
    }
}

const XYZ: [Axis; 3] = [Axis::X, Axis::Y, Axis::Z];

fn plan(c: &Contour, tolerance: f64, limits: &BTreeMap<Axis, AxisLimits>) -> PvtContour {
    let options = PathOptions {
        tolerance,
        limits: limits.clone(),
    };
    plan_path(c, &XYZ, &options).expect("plans").0
}

/// Bézier control points of piece `i` (3 axes): p0, p0 + v0·T/3, p1 − v1·T/3, p1.
fn control_points(c: &PvtContour, i: usize) -> [[f64; 3]; 4] {
    let seg = c.segment(i);
    let (p0, v0): (Vec<f64>, Vec<f64>) = if i == 0 {
        (c.start.clone(), vec![0.0; 3])
    } else {
        let prev = c.segment(i - 1);
        (prev.end.to_vec(), prev.velocity.to_vec())
    };
    let t = seg.duration;
    let mut out = [[0.0; 3]; 4];
    for k in 0..3 {
        out[0][k] = p0[k];
        out[1][k] = p0[k] + v0[k] * t / 3.0;
        out[2][k] = seg.end[k] - seg.velocity[k] * t / 3.0;
        out[3][k] = seg.end[k];
    }
    out
}

fn bezier(cp: &[[f64; 3]; 4], u: f64) -> [f64; 3] {
    let w = [
        (1.0 - u).powi(3),
        3.0 * u * (1.0 - u).powi(2),
        3.0 * u * u * (1.0 - u),
        u.powi(3),
    ];
    let mut p = [0.0; 3];
    for k in 0..3 {
        p[k] = (0..4).map(|j| w[j] * cp[j][k]).sum();
    }
    p
}

/// Every sampled point of the motion, ends included.
fn motion_samples(c: &PvtContour) -> Vec<[f64; 3]> {
    let mut out = Vec::new();
    for i in 0..c.len() {
        let cp = control_points(c, i);
        for s in 0..=SAMPLES {
            out.push(bezier(&cp, s as f64 / SAMPLES as f64));
        }
    }
    out
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

fn to3(p: &Position) -> [f64; 3] {
    [p[0], p[1], p[2]]
}

/// Distance from `p` to the segment a–b.
fn to_segment(p: [f64; 3], a: [f64; 3], b: [f64; 3]) -> f64 {
    let d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    let t = if dd == 0.0 {
        0.0
    } else {
        (((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1] + (p[2] - a[2]) * d[2]) / dd).clamp(0.0, 1.0)
    };
    dist(p, [a[0] + t * d[0], a[1] + t * d[1], a[2] + t * d[2]])
}

/// Points along an XY arc or helix (true geometry), `n` + 1 of them.
fn arc_points(e: &Element, n: usize) -> Vec<[f64; 3]> {
    let ElementKind::Arc(a) = e.kind else {
        unreachable!()
    };
    let (cx, cy) = (a.center[0], a.center[1]);
    let a0 = (e.start[1] - cy).atan2(e.start[0] - cx);
    let a1 = (e.end[1] - cy).atan2(e.end[0] - cx);
    let r = (e.start[0] - cx).hypot(e.start[1] - cy);
    let mut sweep = a1 - a0;
    if a.direction == ArcDirection::CounterClockwise {
        if sweep <= 1e-12 {
            sweep += 2.0 * PI;
        }
    } else if sweep >= -1e-12 {
        sweep -= 2.0 * PI;
    }
    (0..=n)
        .map(|i| {
            let f = i as f64 / n as f64;
            let ang = a0 + sweep * f;
            [
                cx + r * ang.cos(),
                cy + r * ang.sin(),
                e.start[2] + (e.end[2] - e.start[2]) * f,
            ]
        })
        .collect()
}

/// Distance from `p` to element `e`: exact for lines and planar arcs, to a polyline of
/// 20 000 true points (sagitta far below the tolerances used) for helices.
fn to_element(p: [f64; 3], e: &Element) -> f64 {
    match e.kind {
        ElementKind::Line => to_segment(p, to3(&e.start), to3(&e.end)),
        ElementKind::Arc(a) if e.start[2] == e.end[2] => {
            let (cx, cy) = (a.center[0], a.center[1]);
            let r = (e.start[0] - cx).hypot(e.start[1] - cy);
            let ang = (p[1] - cy).atan2(p[0] - cx);
            let pts = arc_points(e, 4);
            let inside = angle_within(e, ang);
            let ends = dist(p, pts[0]).min(dist(p, pts[4]));
            if inside {
                let radial = (p[0] - cx).hypot(p[1] - cy) - r;
                (radial * radial + (p[2] - e.start[2]).powi(2))
                    .sqrt()
                    .min(ends)
            } else {
                ends
            }
        }
        ElementKind::Arc(_) => {
            let pts = arc_points(e, 20_000);
            pts.windows(2)
                .map(|w| to_segment(p, w[0], w[1]))
                .fold(f64::INFINITY, f64::min)
        }
    }
}

/// Whether angle `ang` lies within the sweep of arc `e`.
fn angle_within(e: &Element, ang: f64) -> bool {
    let ElementKind::Arc(a) = e.kind else {
        return false;
    };
    let (cx, cy) = (a.center[0], a.center[1]);
    let a0 = (e.start[1] - cy).atan2(e.start[0] - cx);
    let a1 = (e.end[1] - cy).atan2(e.end[0] - cx);
    let tau = 2.0 * PI;
    let (from, span) = if a.direction == ArcDirection::CounterClockwise {
        (a0, (a1 - a0).rem_euclid(tau))
    } else {
        (a1, (a0 - a1).rem_euclid(tau))
    };
    let span = if span <= 1e-12 { tau } else { span };
    (ang - from).rem_euclid(tau) <= span
}

/// Largest distance from the motion to the programmed elements.
fn path_error(c: &PvtContour, elements: &[Element]) -> f64 {
    motion_samples(c)
        .into_iter()
        .map(|p| {
            elements
                .iter()
                .map(|e| to_element(p, e))
                .fold(f64::INFINITY, f64::min)
        })
        .fold(0.0, f64::max)
}

/// How far the polyline through the motion samples may be from the motion itself: a
/// curve leaves its chord over a time step Δt by at most |acceleration|·Δt²/8.
fn sample_sag(c: &PvtContour) -> f64 {
    let mut worst: f64 = 0.0;
    for i in 0..c.len() {
        let cp = control_points(c, i);
        let t = c.durations[i];
        let accel = |j: usize| {
            (0..3)
                .map(|k| (6.0 * (cp[j][k] - 2.0 * cp[j + 1][k] + cp[j + 2][k]) / (t * t)).powi(2))
                .sum::<f64>()
                .sqrt()
        };
        let dt = t / SAMPLES as f64;
        worst = worst.max(accel(0).max(accel(1)) * dt * dt / 8.0);
    }
    worst
}

/// Largest distance from a programmed point to the motion (coverage), less the sampling
/// allowance of [`sample_sag`].
fn coverage_gap(c: &PvtContour, elements: &[Element]) -> f64 {
    let motion = motion_samples(c);
    let mut worst: f64 = 0.0;
    for e in elements {
        let pts = match e.kind {
            ElementKind::Line => (0..=200)
                .map(|i| {
                    let f = i as f64 / 200.0;
                    let (a, b) = (to3(&e.start), to3(&e.end));
                    [
                        a[0] + (b[0] - a[0]) * f,
                        a[1] + (b[1] - a[1]) * f,
                        a[2] + (b[2] - a[2]) * f,
                    ]
                })
                .collect(),
            ElementKind::Arc(_) => arc_points(e, 200),
        };
        for p in pts {
            let d = motion
                .windows(2)
                .map(|w| to_segment(p, w[0], w[1]))
                .fold(f64::INFINITY, f64::min);
            worst = worst.max(d);
        }
    }
    worst - sample_sag(c)
}

/// Per-axis peaks from Bézier control points: the velocity is a quadratic Bézier with
/// control points 3(P[j+1] − P[j])/T (its extreme at an end or its vertex), the
/// acceleration is linear, 6(P[j] − 2P[j+1] + P[j+2])/T² at the ends.
fn peaks(c: &PvtContour) -> Vec<(f64, f64)> {
    let mut out = vec![(0.0f64, 0.0f64); 3];
    for i in 0..c.len() {
        let cp = control_points(c, i);
        let t = c.durations[i];
        for k in 0..3 {
            let q: Vec<f64> = (0..3)
                .map(|j| 3.0 * (cp[j + 1][k] - cp[j][k]) / t)
                .collect();
            let mut v = q[0].abs().max(q[2].abs());
            let den = q[0] - 2.0 * q[1] + q[2];
            if den != 0.0 {
                let u = (q[0] - q[1]) / den;
                if (0.0..=1.0).contains(&u) {
                    let val = (1.0 - u).powi(2) * q[0] + 2.0 * u * (1.0 - u) * q[1] + u * u * q[2];
                    v = v.max(val.abs());
                }
            }
            let a0 = 6.0 * (cp[0][k] - 2.0 * cp[1][k] + cp[2][k]) / (t * t);
            let a1 = 6.0 * (cp[1][k] - 2.0 * cp[2][k] + cp[3][k]) / (t * t);
            out[k].0 = out[k].0.max(v);
            out[k].1 = out[k].1.max(a0.abs().max(a1.abs()));
        }
    }
    out
}

fn limits(v: f64, a: f64) -> BTreeMap<Axis, AxisLimits> {
    XYZ.iter()
        .map(|&axis| {
            (
                axis,
                AxisLimits {
                    velocity: Some(v),
                    acceleration: Some(a),
                    jerk: None,
                },
            )
        })
        .collect()
}

fn square(side: f64, feed: f64) -> Vec<Element> {
    let p = [
        pos(0.0, 0.0, 0.0),
        pos(side, 0.0, 0.0),
        pos(side, side, 0.0),
        pos(0.0, side, 0.0),
        pos(0.0, 0.0, 0.0),
    ];
    p.windows(2).map(|w| line(w[0], w[1], feed)).collect()
}

/// Quarter circle R=1000 between two tangent 100 mm lines (issue: 21 µm with contour).
fn quarter_with_tangent_lines(feed: f64) -> Vec<Element> {
    vec![
        line(pos(900.0, -100.0, 0.0), pos(1000.0, 0.0, 0.0), feed)
            .clone_with_end(pos(1000.0, -100.0, 0.0), pos(1000.0, 0.0, 0.0)),
        arc(
            pos(1000.0, 0.0, 0.0),
            pos(0.0, 1000.0, 0.0),
            [0.0, 0.0],
            true,
            feed,
        ),
        line(pos(0.0, 1000.0, 0.0), pos(-100.0, 1000.0, 0.0), feed),
    ]
}

trait WithEnds {
    fn clone_with_end(&self, start: Position, end: Position) -> Element;
}

impl WithEnds for Element {
    fn clone_with_end(&self, start: Position, end: Position) -> Element {
        Element {
            start,
            end,
            ..*self
        }
    }
}

#[test]
fn square_stays_on_its_sides() {
    let elements = square(100.0, 100.0);
    let c = plan(&contour(elements.clone()), 0.001, &BTreeMap::new());
    let err = path_error(&c, &elements);
    assert!(err <= 0.001, "square off by {err}");
    assert!(coverage_gap(&c, &elements) <= 0.001);
}

#[test]
fn quarter_circle_between_tangent_lines_is_few_pieces_near_the_feed() {
    let elements = quarter_with_tangent_lines(100.0);
    let c = plan(&contour(elements.clone()), 0.001, &BTreeMap::new());
    let err = path_error(&c, &elements);
    assert!(err <= 0.001, "off by {err}");
    let on_arc = (0..c.len())
        .filter(|&i| {
            let e = c.segment(i).end;
            e[1] > 0.0 && e[0] > 0.0 && (e[0] < 1000.0 - 1e-9)
        })
        .count()
        + 1;
    assert!(on_arc <= 16, "{on_arc} pieces on the arc");
    let length = 200.0 + 1000.0 * FRAC_PI_2;
    let ratio = c.total_time() / (length / 100.0);
    assert!(ratio <= 1.25, "time ratio {ratio}");
}

#[test]
fn plunge_into_a_cut_does_not_gouge() {
    let elements = vec![
        line(pos(0.0, 0.0, 0.0), pos(0.0, 0.0, -1.0), 10.0),
        line(pos(0.0, 0.0, -1.0), pos(50.0, 0.0, -1.0), 50.0),
        line(pos(50.0, 0.0, -1.0), pos(50.0, 20.0, -1.0), 50.0),
    ];
    let c = plan(&contour(elements.clone()), 0.001, &BTreeMap::new());
    let lowest = motion_samples(&c)
        .iter()
        .map(|p| p[2])
        .fold(f64::INFINITY, f64::min);
    assert!(lowest >= -1.0 - 0.001, "dives to {lowest}");
    assert!(path_error(&c, &elements) <= 0.001);
}

#[test]
fn limits_hold_on_a_square_and_exact_stop_time_is_near_four_trapezoids() {
    let elements = square(100.0, 100.0);
    let lim = limits(100.0, 1000.0);
    let c = plan(&contour(elements.clone()), 0.001, &lim);
    for (v, a) in peaks(&c) {
        assert!(
            v <= 100.0 * (1.0 + 1e-6) && a <= 1000.0 * (1.0 + 1e-6),
            "v {v} a {a}"
        );
    }
    assert!(path_error(&c, &elements) <= 0.001);
    // One side: accelerate to 100 in 0.1 s over 5 mm, cruise 90 mm, decelerate.
    let trapezoid = 0.1 + 0.9 + 0.1;
    let ratio = c.total_time() / (4.0 * trapezoid);
    assert!(ratio <= 1.05, "ratio {ratio}");
}

#[test]
fn a_wider_tolerance_rounds_corners_faster_than_exact_stop() {
    let elements = square(100.0, 100.0);
    let lim = limits(100.0, 1000.0);
    let tight = plan(&contour(elements.clone()), 0.001, &lim);
    let loose = plan(&contour(elements.clone()), 0.5, &lim);
    assert!(
        loose.total_time() < tight.total_time() * 0.98,
        "{} vs {}",
        loose.total_time(),
        tight.total_time()
    );
    assert!(path_error(&loose, &elements) <= 0.5);
    for (v, a) in peaks(&loose) {
        assert!(
            v <= 100.0 * (1.0 + 1e-6) && a <= 1000.0 * (1.0 + 1e-6),
            "v {v} a {a}"
        );
    }
}

#[test]
fn full_circle_within_limits() {
    let e = arc(
        pos(50.0, 0.0, 0.0),
        pos(50.0, 0.0, 0.0),
        [0.0, 0.0],
        true,
        1000.0,
    );
    let lim = limits(100.0, 1000.0);
    let c = plan(&contour(vec![e]), 0.001, &lim);
    for (v, a) in peaks(&c) {
        assert!(
            v <= 100.0 * (1.0 + 1e-6) && a <= 1000.0 * (1.0 + 1e-6),
            "v {v} a {a}"
        );
    }
    assert!(path_error(&c, &[e]) <= 0.001);
}

/// A random program step.
#[derive(Debug, Clone, Copy)]
enum Step {
    Line(f64, f64, f64),
    TangentArc(f64, f64, bool),
    Helix(f64, f64, f64, bool),
    Plunge(f64),
}

fn step() -> impl Strategy<Value = Step> {
    prop_oneof![
        3 => (-20.0..20.0f64, -20.0..20.0f64, -2.0..2.0f64).prop_map(|(x, y, z)| Step::Line(x, y, z)),
        2 => (0.5..30.0f64, 0.1..3.0f64, any::<bool>()).prop_map(|(r, s, c)| Step::TangentArc(r, s, c)),
        1 => (0.5..20.0f64, 0.1..6.0f64, -3.0..3.0f64, any::<bool>()).prop_map(|(r, s, z, c)| Step::Helix(r, s, z, c)),
        1 => (-3.0..-0.1f64).prop_map(Step::Plunge),
    ]
}

/// Elements from steps; arcs leave tangent to the last XY direction.
fn program(steps: &[Step], feed: f64) -> Vec<Element> {
    let mut at = pos(0.0, 0.0, 0.0);
    let mut heading = 0.0f64;
    let mut out = Vec::new();
    for s in steps {
        let e = match *s {
            Step::Line(x, y, z) => {
                let end = pos(at[0] + x, at[1] + y, at[2] + z);
                if x != 0.0 || y != 0.0 {
                    heading = y.atan2(x);
                }
                line(at, end, feed)
            }
            Step::Plunge(z) => line(at, pos(at[0], at[1], at[2] + z), feed),
            Step::TangentArc(r, sweep, ccw) | Step::Helix(r, sweep, _, ccw) => {
                let side = if ccw { FRAC_PI_2 } else { -FRAC_PI_2 };
                let c = [
                    at[0] + r * (heading + side).cos(),
                    at[1] + r * (heading + side).sin(),
                ];
                let a0 = (at[1] - c[1]).atan2(at[0] - c[0]);
                let a1 = if ccw { a0 + sweep } else { a0 - sweep };
                let dz = if let Step::Helix(_, _, z, _) = *s {
                    z
                } else {
                    0.0
                };
                let end = pos(c[0] + r * a1.cos(), c[1] + r * a1.sin(), at[2] + dz);
                heading += if ccw { sweep } else { -sweep };
                arc(at, end, c, ccw, feed)
            }
        };
        at = e.end;
        out.push(e);
    }
    out
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn random_programs_stay_within_tolerance_and_cover_the_path(
        steps in prop::collection::vec(step(), 1..6),
        tol_exp in -3.0..-1.0f64,
        feed in 5.0..200.0f64,
        limited in any::<bool>(),
    ) {
        let elements = program(&steps, feed);
        let tol = 10f64.powf(tol_exp);
        let lim = if limited { limits(80.0, 800.0) } else { BTreeMap::new() };
        let c = plan(&contour(elements.clone()), tol, &lim);
        let err = path_error(&c, &elements);
        prop_assert!(err <= tol * (1.0 + 1e-9) + 1e-9, "off by {} > {}", err, tol);
        let gap = coverage_gap(&c, &elements);
        prop_assert!(gap <= tol * (1.0 + 1e-9) + 1e-9, "gap {} > {}", gap, tol);
        if limited {
            for (v, a) in peaks(&c) {
                prop_assert!(v <= 80.0 * (1.0 + 1e-6), "v {}", v);
                prop_assert!(a <= 800.0 * (1.0 + 1e-6), "a {}", a);
            }
        }
    }
}

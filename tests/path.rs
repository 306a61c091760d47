//! The path planner's promises, checked independently of its own bounds: every cubic is
//! evaluated densely (as Bézier curves from its end states) and measured against the true
//! lines, arcs, helices and Béziers; every programmed element is covered; per-axis peaks are
//! computed from the Bézier control points; piece counts and times are as documented.
//!
//! Long run: `PROPTEST_CASES=2000 cargo test -p pvtc-tests --test path --release`.
//!
//! The reference geometry uses std's trigonometry on purpose: it is independent of the
//! planner's libm, and these numbers are never written to an output.
#![allow(clippy::disallowed_methods)]

use proptest::prelude::*;
use pvt_core::{
    plan_path, Arc, ArcDirection, Axis, AxisLimits, Bezier, Contour, Element, ElementKind,
    Interpolation, Motion, PathOptions, PathStream, Plane, Position, PvtContour, PvtProgram,
    Quantum, Rounding, Span, Toolpath, Units,
};
use pvtc_tests::reference::{self, Deviation};
use std::collections::BTreeMap;
use std::f64::consts::FRAC_PI_2;

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

/// Elements numbered as if each were on its own source line.
fn contour(mut elements: Vec<Element>) -> Contour {
    for (i, e) in elements.iter_mut().enumerate() {
        e.span.line = i as u32 + 1;
    }
    Contour {
        motion: Motion::Feed,
        elements,
    }
}

const XYZ: [Axis; 3] = [Axis::X, Axis::Y, Axis::Z];

fn plan(c: &Contour, tolerance: f64, limits: &BTreeMap<Axis, AxisLimits>) -> PvtContour {
    plan_on(c, tolerance, limits, None)
}

/// As [`plan`], with piece times on `quantum`'s grid when given.
fn plan_on(
    c: &Contour,
    tolerance: f64,
    limits: &BTreeMap<Axis, AxisLimits>,
    quantum: Option<Quantum>,
) -> PvtContour {
    let options = path_options(tolerance, limits, quantum);
    plan_path(c, &XYZ, &options).expect("plans").0
}

/// The servo period the planner bounds acceleration steps over (the default's 0.5 ms).
const SERVO: f64 = 0.0005;

const MS: Quantum = Quantum {
    seconds: 0.001,
    rounding: Rounding::Up,
};

/// Asserts every piece time is a whole number (at least one) of `q` seconds.
fn assert_on_grid(planned: &PvtContour, q: f64) {
    for &t in &planned.durations {
        let whole = (t / q).round();
        assert!(
            whole >= 1.0 && (t / q - whole).abs() < 1e-9,
            "piece time {t} is not whole quanta of {q}"
        );
    }
}

/// The independent deviation of a planned contour from its elements.
/// The random programs' checks, by the reference: within `tol` of the contour and
/// covering it, and, when `limited`, within 80 units/s and 800 units/s² per axis.
fn within(c: &Contour, planned: &PvtContour, tol: f64, limited: bool) -> Result<(), TestCaseError> {
    let d = deviation(c, planned);
    prop_assert!(d.error <= tol, "off by {} > {}", d.error, tol);
    prop_assert!(d.gap <= tol, "gap {} > {}", d.gap, tol);
    if limited {
        for (v, a) in reference::peaks(planned) {
            prop_assert!(v <= 80.0 * (1.0 + 1e-6), "v {}", v);
            prop_assert!(a <= 800.0 * (1.0 + 1e-6), "a {}", a);
        }
    }
    Ok(())
}

fn deviation(c: &Contour, planned: &PvtContour) -> Deviation {
    let program = PvtProgram {
        axes: XYZ.to_vec(),
        units: Units::Millimetre,
        interpolation: Interpolation::Pvt,
        contours: vec![planned.clone()],
        events: Vec::new(),
    };
    let toolpath = Toolpath {
        contours: vec![c.clone()],
        ..Toolpath::default()
    };
    reference::deviation(&program, &toolpath, 1.0)
}

fn samples_of(c: &PvtContour) -> Vec<Vec<f64>> {
    (0..c.len())
        .flat_map(|i| reference::piece_samples(c, i))
        .collect()
}

fn limits(v: f64, a: f64) -> BTreeMap<Axis, AxisLimits> {
    limits_with_jerk(v, a, None)
}

fn limits_with_jerk(v: f64, a: f64, j: Option<f64>) -> BTreeMap<Axis, AxisLimits> {
    XYZ.iter()
        .map(|&axis| {
            (
                axis,
                AxisLimits {
                    velocity: Some(v),
                    acceleration: Some(a),
                    jerk: j,
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
        line(pos(1000.0, -100.0, 0.0), pos(1000.0, 0.0, 0.0), feed),
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

/// Asserts the motion is within `tol` of `c` and covers it, independently measured.
fn assert_follows(c: &Contour, planned: &PvtContour, tol: f64) {
    let d = deviation(c, planned);
    assert!(
        d.error <= tol,
        "motion {} from the path (tolerance {tol})",
        d.error
    );
    assert!(
        d.gap <= tol,
        "path point {} from the motion (tolerance {tol})",
        d.gap
    );
}

fn assert_within(planned: &PvtContour, v: f64, a: f64) {
    for (pv, pa) in reference::peaks(planned) {
        assert!(pv <= v * (1.0 + 1e-6), "velocity {pv} > {v}");
        assert!(pa <= a * (1.0 + 1e-6), "acceleration {pa} > {a}");
    }
}

#[test]
fn square_stays_on_its_sides() {
    let c = contour(square(100.0, 100.0));
    let planned = plan(&c, 0.001, &BTreeMap::new());
    assert_follows(&c, &planned, 0.001);
}

#[test]
fn quarter_circle_between_tangent_lines_is_few_pieces_near_the_feed() {
    let c = contour(quarter_with_tangent_lines(100.0));
    let planned = plan(&c, 0.001, &BTreeMap::new());
    assert_follows(&c, &planned, 0.001);
    let on_arc = planned.lines.iter().filter(|&&l| l == 2).count();
    assert!(on_arc <= 16, "{on_arc} pieces on the arc");
    let length = 200.0 + 1000.0 * FRAC_PI_2;
    let ratio = planned.total_time() / (length / 100.0);
    assert!(ratio <= 1.25, "time ratio {ratio}");
}

#[test]
fn plunge_into_a_cut_does_not_gouge() {
    let c = contour(vec![
        line(pos(0.0, 0.0, 0.0), pos(0.0, 0.0, -1.0), 10.0),
        line(pos(0.0, 0.0, -1.0), pos(50.0, 0.0, -1.0), 50.0),
        line(pos(50.0, 0.0, -1.0), pos(50.0, 20.0, -1.0), 50.0),
    ]);
    for lim in [BTreeMap::new(), limits(100.0, 1000.0)] {
        let planned = plan(&c, 0.001, &lim);
        let lowest = samples_of(&planned)
            .iter()
            .map(|p| p[2])
            .fold(f64::INFINITY, f64::min);
        assert!(lowest >= -1.0 - 0.001, "dives to {lowest}");
        assert_follows(&c, &planned, 0.001);
    }
}

#[test]
fn limits_hold_on_a_square_and_exact_stop_time_is_near_four_trapezoids() {
    let c = contour(square(100.0, 100.0));
    let planned = plan(&c, 0.001, &limits(100.0, 1000.0));
    assert_within(&planned, 100.0, 1000.0);
    assert_follows(&c, &planned, 0.001);
    // One side: accelerate to 100 in 0.1 s over 5 mm, cruise 90 mm, decelerate.
    let trapezoid = 0.1 + 0.9 + 0.1;
    let ratio = planned.total_time() / (4.0 * trapezoid);
    assert!(ratio <= 1.05, "ratio {ratio}");
}

#[test]
fn a_wider_tolerance_rounds_corners_faster_than_exact_stop() {
    let c = contour(square(100.0, 100.0));
    let lim = limits(100.0, 1000.0);
    let tight = plan(&c, 0.001, &lim);
    let loose = plan(&c, 0.5, &lim);
    assert!(
        loose.total_time() < tight.total_time() * 0.98,
        "{} vs {}",
        loose.total_time(),
        tight.total_time()
    );
    assert!(loose.total_time() < 4.0 * 1.1);
    assert_follows(&c, &loose, 0.5);
    assert_within(&loose, 100.0, 1000.0);
}

/// A blend at equal end speeds passes L·sin(α/2)/2 from the corner, so it is sized to
/// that: the corner is the full tolerance from the motion (it was half), and the square
/// is faster than with blends sized by the triangle bound L·sin(α/2) (4.2872 s).
#[test]
fn corner_blends_use_the_whole_tolerance() {
    let c = contour(square(100.0, 100.0));
    let lim = limits(100.0, 1000.0);
    let planned = plan(&c, 0.5, &lim);
    let d = deviation(&c, &planned);
    assert!(d.gap <= 0.5 && d.error <= 0.5, "{d:?}");
    assert!(
        d.gap >= 0.49,
        "the corner is only {} from the motion",
        d.gap
    );
    assert_within(&planned, 100.0, 1000.0);
    assert!(planned.total_time() < 4.25, "{}", planned.total_time());
}

/// Blends between a fast and a slow line have unequal end speeds, which would take the
/// blend farther than at equal speeds: their speeds are evened out where needed.
#[test]
fn blends_between_fast_and_slow_lines_keep_the_tolerance() {
    let mut elements = Vec::new();
    let mut at = pos(0.0, 0.0, 0.0);
    for i in 0..12 {
        let next = pos(at[0] + 10.0, if i % 2 == 0 { 6.0 } else { 0.0 }, 0.0);
        elements.push(line(at, next, if i % 3 == 0 { 100.0 } else { 8.0 }));
        at = next;
    }
    let c = contour(elements);
    let lim = limits(100.0, 1000.0);
    for tol in [0.5, 0.05, 0.001] {
        let planned = plan(&c, tol, &lim);
        assert_follows(&c, &planned, tol);
        assert_within(&planned, 100.0, 1000.0);
    }
}

/// The bench's ellipse (60 × 30 mm, 720 chords) at 1000 mm/s: its blends must turn and
/// change speed at once. TOPP-RA's time-optimal motion on it takes 2.7833 s
/// (`bench/toppra/RESULTS.md`); blends that let the passes use their lines' whole
/// tangential acceleration took 3.3522 s (1.204×), repaired in small steps.
#[test]
fn a_dense_polyline_keeps_speed_through_its_blends() {
    let points: Vec<Position> = (0..=720)
        .map(|i| {
            let a = if i == 720 {
                0.0
            } else {
                std::f64::consts::TAU * i as f64 / 720.0
            };
            pos(60.0 * a.cos(), 30.0 * a.sin(), 0.0)
        })
        .collect();
    let c = contour(
        points
            .windows(2)
            .map(|w| line(w[0], w[1], 1000.0))
            .collect(),
    );
    let lim = limits(100.0, 1000.0);
    let planned = plan(&c, 0.001, &lim);
    assert_within(&planned, 100.0, 1000.0);
    assert_follows(&c, &planned, 0.001);
    let ratio = planned.total_time() / 2.7833;
    assert!(ratio <= 1.05, "ratio to TOPP-RA {ratio}");
}

#[test]
fn a_corner_tolerance_blends_corners_without_a_machine_file() {
    let c = contour(square(100.0, 100.0));
    let options = PathOptions {
        tolerance: 0.001,
        corner_tolerance: Some(0.05),
        limits: BTreeMap::new(),
        quantum: None,
        servo_period: SERVO,
        position_resolution: 0.0,
    };
    let blended = plan_path(&c, &XYZ, &options).unwrap().0;
    let d = deviation(&c, &blended);
    assert!(d.error <= 0.05 && d.gap <= 0.05, "{d:?}");
    // No stop inside the contour: every interior knot moves.
    for i in 0..blended.len() - 1 {
        let v = blended.segment(i).velocity;
        assert!(v.iter().any(|x| *x != 0.0), "stop at piece {i}");
    }
}

#[test]
fn full_circle_within_limits() {
    let c = contour(vec![arc(
        pos(50.0, 0.0, 0.0),
        pos(50.0, 0.0, 0.0),
        [0.0, 0.0],
        true,
        1000.0,
    )]);
    let planned = plan(&c, 0.001, &limits(100.0, 1000.0));
    assert_within(&planned, 100.0, 1000.0);
    assert_follows(&c, &planned, 0.001);
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
        let c = contour(program(&steps, feed));
        let tol = 10f64.powf(tol_exp);
        let lim = if limited { limits(80.0, 800.0) } else { BTreeMap::new() };
        let planned = plan(&c, tol, &lim);
        within(&c, &planned, tol, limited)?;
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    /// `--quantize`: on the grid, every piece stays within the limits and the tolerance,
    /// as measured by the reference (re-timing after planning broke both).
    #[test]
    fn random_programs_on_a_time_grid_stay_within_limits_and_tolerance(
        steps in prop::collection::vec(step(), 1..6),
        tol_exp in -3.0..-1.0f64,
        feed in 5.0..200.0f64,
        quantum_ms in prop_oneof![Just(1.0f64), Just(2.0), Just(0.442)],
        nearest in any::<bool>(),
    ) {
        let c = contour(program(&steps, feed));
        let tol = 10f64.powf(tol_exp);
        let lim = limits(80.0, 800.0);
        let q = Quantum {
            seconds: quantum_ms / 1000.0,
            rounding: if nearest { Rounding::Nearest } else { Rounding::Up },
        };
        let planned = plan_on(&c, tol, &lim, Some(q));
        assert_on_grid(&planned, q.seconds);
        within(&c, &planned, tol, true)?;
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    /// With a jerk limit every piece's jerk (independently: the third difference of its
    /// control points) stays within it, and so does every knot's acceleration step
    /// within the jerk limit times the servo period (independently: each cubic's end
    /// accelerations from its end states), on a time grid (1, 2 or 0.442 ms, either
    /// rounding) or not, and so do the other limits and the tolerance.
    #[test]
    fn random_programs_with_a_jerk_limit_keep_it(
        steps in prop::collection::vec(step(), 1..6),
        tol_exp in -3.0..-1.0f64,
        feed in 5.0..200.0f64,
        quantum_ms in prop_oneof![Just(0.0f64), Just(1.0), Just(2.0), Just(0.442)],
        nearest in any::<bool>(),
    ) {
        let c = contour(program(&steps, feed));
        let tol = 10f64.powf(tol_exp);
        let lim = limits_with_jerk(80.0, 800.0, Some(20000.0));
        let q = (quantum_ms > 0.0).then(|| Quantum {
            seconds: quantum_ms / 1000.0,
            rounding: if nearest { Rounding::Nearest } else { Rounding::Up },
        });
        let planned = plan_on(&c, tol, &lim, q);
        if let Some(q) = q {
            assert_on_grid(&planned, q.seconds);
        }
        within(&c, &planned, tol, true)?;
        for j in reference::jerks(&planned) {
            prop_assert!(j <= 20000.0 * (1.0 + 1e-6), "jerk {}", j);
        }
        for step in reference::knot_steps(&planned) {
            prop_assert!(step <= 20000.0 * SERVO * (1.0 + 1e-6), "acceleration step {}", step);
        }
    }
}

/// A full circle R=50 at 100 mm/s and 1000 mm/s² has pieces with jerk near v³/R²
/// (8000 mm/s³ at 100 mm/s); a 2000 mm/s³ limit slows it and holds.
#[test]
fn a_jerk_limit_slows_a_circle_and_holds() {
    let c = contour(vec![arc(
        pos(50.0, 0.0, 0.0),
        pos(50.0, 0.0, 0.0),
        [0.0, 0.0],
        true,
        6000.0,
    )]);
    let free = plan(&c, 0.001, &limits(100.0, 1000.0));
    let worst = reference::jerks(&free).into_iter().fold(0.0, f64::max);
    assert!(worst > 2000.0, "jerk {worst} without a limit");
    let held = plan(&c, 0.001, &limits_with_jerk(100.0, 1000.0, Some(2000.0)));
    for j in reference::jerks(&held) {
        assert!(j <= 2000.0 * (1.0 + 1e-6), "jerk {j}");
    }
    for step in reference::knot_steps(&held) {
        assert!(
            step <= 2000.0 * SERVO * (1.0 + 1e-6),
            "acceleration step {step}"
        );
    }
    assert_within(&held, 100.0, 1000.0);
    assert_follows(&c, &held, 0.001);
    assert!(held.total_time() > free.total_time());
}

/// A slot (two lines joined by two semicircles of radius `r`, all tangent) and a line, a
/// quarter circle and a line, turned by `turn` radians, mirrored (the arcs clockwise)
/// when `mirror`: line→arc and arc→line junctions of both turning senses.
fn tangent_arcs(r: f64, long: f64, turn: f64, mirror: bool) -> Vec<Contour> {
    let (sin, cos) = turn.sin_cos();
    let sign = if mirror { -1.0 } else { 1.0 };
    let at = |x: f64, y: f64| pos(x * cos - sign * y * sin, x * sin + sign * y * cos, 0.0);
    let center = |x: f64, y: f64| {
        let p = at(x, y);
        [p[0], p[1]]
    };
    let slot = vec![
        line(at(0.0, 0.0), at(long, 0.0), 100.0),
        arc(
            at(long, 0.0),
            at(long, 2.0 * r),
            center(long, r),
            !mirror,
            100.0,
        ),
        line(at(long, 2.0 * r), at(0.0, 2.0 * r), 100.0),
        arc(
            at(0.0, 2.0 * r),
            at(0.0, 0.0),
            center(0.0, r),
            !mirror,
            100.0,
        ),
    ];
    let quarter = vec![
        line(at(0.0, 0.0), at(long, 0.0), 100.0),
        arc(
            at(long, 0.0),
            at(long + r, r),
            center(long, r),
            !mirror,
            100.0,
        ),
        line(at(long + r, r), at(long + r, r + long), 100.0),
    ];
    vec![contour(slot), contour(quarter)]
}

/// Distance from `p` to the elements of `c` (lines and plane arcs in XY), measured
/// here: to each line segment, and to each arc's circle where `p` lies within its swept
/// angle (else to its nearer end).
fn to_lines_and_arcs(c: &Contour, p: [f64; 2]) -> f64 {
    let tau = std::f64::consts::TAU;
    let near = |e: &Element| -> f64 {
        let (a, b) = ([e.start[0], e.start[1]], [e.end[0], e.end[1]]);
        let ends = (p[0] - a[0])
            .hypot(p[1] - a[1])
            .min((p[0] - b[0]).hypot(p[1] - b[1]));
        match e.kind {
            ElementKind::Arc(arc) => {
                let c = arc.center;
                let angle = |q: [f64; 2]| (q[1] - c[1]).atan2(q[0] - c[0]);
                let ccw = matches!(arc.direction, ArcDirection::CounterClockwise);
                let swept = |from: f64, to: f64| {
                    let d = if ccw { to - from } else { from - to };
                    d.rem_euclid(tau)
                };
                let mut sweep = swept(angle(a), angle(b));
                if sweep < 1e-12 {
                    sweep = tau;
                }
                if swept(angle(a), angle(p)) <= sweep {
                    let r = (a[0] - c[0]).hypot(a[1] - c[1]);
                    ((p[0] - c[0]).hypot(p[1] - c[1]) - r).abs()
                } else {
                    ends
                }
            }
            _ => {
                let d = [b[0] - a[0], b[1] - a[1]];
                let l2 = d[0] * d[0] + d[1] * d[1];
                let u = (((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / l2).clamp(0.0, 1.0);
                (p[0] - a[0] - u * d[0]).hypot(p[1] - a[1] - u * d[1])
            }
        }
    };
    c.elements.iter().map(near).fold(f64::INFINITY, f64::min)
}

/// Each written cubic evaluated from its end states at 200 points: the largest distance
/// from the elements, and the largest speed within `reach` of `point`.
fn cubic_samples(c: &Contour, planned: &PvtContour, point: [f64; 2], reach: f64) -> (f64, f64) {
    let (mut far, mut speed) = (0.0f64, 0.0f64);
    for i in 0..planned.len() {
        let seg = planned.segment(i);
        let (p0, v0) = if i == 0 {
            (planned.start.clone(), vec![0.0; planned.dim])
        } else {
            let prev = planned.segment(i - 1);
            (prev.end.to_vec(), prev.velocity.to_vec())
        };
        let t = seg.duration;
        for k in 0..=200 {
            let u = k as f64 / 200.0;
            let (h00, h10) = (
                2.0 * u.powi(3) - 3.0 * u * u + 1.0,
                u.powi(3) - 2.0 * u * u + u,
            );
            let (h01, h11) = (-2.0 * u.powi(3) + 3.0 * u * u, u.powi(3) - u * u);
            let (d00, d10) = (6.0 * u * u - 6.0 * u, 3.0 * u * u - 4.0 * u + 1.0);
            let (d01, d11) = (-6.0 * u * u + 6.0 * u, 3.0 * u * u - 2.0 * u);
            let at = |a: usize| {
                h00 * p0[a] + h10 * t * v0[a] + h01 * seg.end[a] + h11 * t * seg.velocity[a]
            };
            let rate = |a: usize| {
                (d00 * p0[a] + d01 * seg.end[a]) / t + d10 * v0[a] + d11 * seg.velocity[a]
            };
            let p = [at(0), at(1)];
            far = far.max(to_lines_and_arcs(c, p));
            if (p[0] - point[0]).hypot(p[1] - point[1]) <= reach {
                speed = speed.max(rate(0).hypot(rate(1)));
            }
        }
    }
    (far, speed)
}

/// Lines into tangent arcs and out again under a jerk limit, plain, on a 1 ms grid and
/// streamed in short windows: measured here from the written cubics alone, the motion
/// stays within the tolerance of the true lines and arcs, every piece's jerk and every
/// knot's acceleration step (from the end states) within the limits; and the junction
/// is taken at more than twice `√(J·Tₛ·R)`, the fastest the exact geometry allows there
/// (its acceleration steps by `v²/R`), so the curvature transition is what holds them.
#[test]
fn curvature_transitions_keep_the_tolerance_jerk_and_steps_at_speed() {
    let jerk = 50000.0;
    let lim = limits_with_jerk(100.0, 1000.0, Some(jerk));
    for (r, tol) in [(5.0, 0.001), (5.0, 0.0005), (1.0, 0.001), (20.0, 0.002)] {
        for (turn, mirror) in [(0.0, false), (0.7, true), (2.5, false), (-1.9, true)] {
            for c in tangent_arcs(r, 12.0, turn, mirror) {
                let options = path_options(tol, &lim, None);
                let gridded = PathOptions {
                    quantum: Some(MS),
                    ..options.clone()
                };
                let junction = [c.elements[1].start[0], c.elements[1].start[1]];
                let exact = (jerk * SERVO * r).sqrt();
                for route in ["plain", "1 ms", "windows", "1 ms windows"] {
                    let case = format!("R {r} tol {tol} turn {turn} mirror {mirror} {route}");
                    let planned = match route {
                        "plain" => plan_on(&c, tol, &lim, None),
                        "1 ms" => plan_on(&c, tol, &lim, Some(MS)),
                        "windows" => plan_stream(&c, &options, 2),
                        _ => plan_stream(&c, &gridded, 2),
                    };
                    let (far, speed) = cubic_samples(&c, &planned, junction, 0.01 * r);
                    assert!(far <= tol * (1.0 + 1e-9), "{case}: {far} from the path");
                    for j in reference::jerks(&planned) {
                        assert!(j <= jerk * (1.0 + 1e-6), "{case}: jerk {j}");
                    }
                    for step in reference::knot_steps(&planned) {
                        let bound = jerk * SERVO;
                        assert!(step <= bound * (1.0 + 1e-6), "{case}: step {step}");
                    }
                    assert_within(&planned, 100.0, 1000.0);
                    assert!(
                        speed > 2.0 * exact,
                        "{case}: {speed} at the junction against {exact}"
                    );
                }
            }
        }
    }
}

/// The time grid's plain re-timing (each piece stretched, each knot's velocity divided by
/// the larger stretch beside it) breaks the acceleration limit on the square's short
/// trapezoid and blend pieces; planning on the grid does not, and costs little time.
#[test]
fn a_square_on_a_1ms_grid_keeps_its_limits_and_tolerance() {
    let c = contour(square(100.0, 100.0));
    let lim = limits(100.0, 1000.0);
    for tol in [0.001, 0.5] {
        let free = plan(&c, tol, &lim);
        let retimed = pvt_core::plan::quantize::retime(&free, 0.001, Rounding::Up);
        let broken = reference::peaks(&retimed)
            .iter()
            .any(|(v, a)| *v > 100.0 * (1.0 + 1e-6) || *a > 1000.0 * (1.0 + 1e-6));
        let planned = plan_on(&c, tol, &lim, Some(MS));
        assert_on_grid(&planned, 0.001);
        assert_within(&planned, 100.0, 1000.0);
        assert_follows(&c, &planned, tol);
        let ratio = planned.total_time() / free.total_time();
        assert!(
            (1.0..1.02).contains(&ratio),
            "tol {tol}: grid / free time {ratio}"
        );
        assert!(
            broken,
            "tol {tol}: re-timing after planning kept the limits"
        );
    }
}

/// On a quantum grid a long contour streams too: windows of 16 and 64 elements emit
/// most pieces before the contour ends, every piece on the grid, within the limits and
/// the tolerance by the reference, and within 1 % of the time of the contour planned
/// whole (which takes the shortest of several plans; a window takes the first that
/// converges, see "Streaming on a grid" in the planner).
#[test]
fn a_long_contour_streams_on_a_grid_within_its_limits_and_tolerance() {
    let c = lines_then_polygon();
    let lim = limits(100.0, 1000.0);
    let options = path_options(0.001, &lim, Some(MS));
    let (whole, held) = plan_stream_counting(&c, &options, usize::MAX);
    assert_eq!(held, 0, "the whole contour is planned at its end");
    for window in [16, 64, usize::MAX] {
        let (planned, early) = plan_stream_counting(&c, &options, window);
        assert_on_grid(&planned, 0.001);
        assert_follows(&c, &planned, 0.001);
        assert_within(&planned, 100.0, 1000.0);
        let ratio = planned.total_time() / whole.total_time();
        assert!((0.99..1.01).contains(&ratio), "window {window}: {ratio}");
        if window < usize::MAX {
            let all = planned.durations.len();
            // The lines stream; the polygon's sides are shorter than a stopping distance.
            assert!(early >= 100, "window {window}: {early} of {all} early");
        }
    }
}

/// The `generate arcs` program (the speed benchmark's): 0.2 mm lines along X, every tenth
/// an arc whose centre is 1 mm off its chord's middle, so that it meets the lines beside
/// it at corners.
#[path = "../crates/pvtc/examples/generate/programs.rs"]
mod programs;

/// Under a jerk limit on the 1 ms grid, the window of `generate arcs`' first 1028 lines
/// was cut 1.9 ms before the corner at a kinked arc's end (line 821), which left the next
/// window a piece too short to turn the velocity onto the corner's direction within the
/// jerk limit: every round of that window failed (`path_not_met`). The cut now leaves
/// the turn its time (the planner's `Knots::turn_time`), and the program compiles on
/// the grid within the tolerance and every axis' limits, by the reference.
#[test]
fn a_window_cut_before_a_corner_leaves_the_next_one_time_to_turn() {
    let mut text = Vec::new();
    programs::write("arcs", 100_000, &mut text).unwrap();
    let text: String = String::from_utf8(text)
        .unwrap()
        .lines()
        .take(1028)
        .map(|l| format!("{l}\n"))
        .collect();
    let mill = pvtc_tests::root().join("samples/machines/mill.toml");
    let mut options = pvtc::CompileOptions::new(pvt_emit::Format::Json);
    options.machine = Some(pvtc::machine::Machine::read(&mill).unwrap());
    options.quantize = Some(0.001);
    let source = pvtc::Source::from_text("arcs.ngc", &text);
    let (planned, toolpath, _) =
        pvtc::plan(&source, &options).unwrap_or_else(|f| panic!("{:?}", f.codes()));
    let program = planned.program;
    // X, Y and Z of the mill: velocity, acceleration and (X and Y only) jerk.
    let limits = [
        (100.0, 1000.0, 50000.0),
        (100.0, 1000.0, 50000.0),
        (50.0, 500.0, f64::INFINITY),
    ];
    for c in &program.contours {
        assert_on_grid(c, 0.001);
        for (k, (v, a)) in reference::peaks(c).into_iter().enumerate() {
            assert!(v <= limits[k].0 * (1.0 + 1e-6), "axis {k}: velocity {v}");
            assert!(
                a <= limits[k].1 * (1.0 + 1e-6),
                "axis {k}: acceleration {a}"
            );
        }
        for (k, j) in reference::jerks(c).into_iter().enumerate() {
            assert!(j <= limits[k].2 * (1.0 + 1e-6), "axis {k}: jerk {j}");
        }
    }
    // Pieces and elements within 0.01 mm of each other: a deviation over the tolerance
    // shows as one of at least that.
    let d = reference::deviation(&program, &toolpath, 0.01);
    assert!(d.error <= 0.001 * (1.0 + 1e-9), "{} from the path", d.error);
    assert!(
        d.gap <= 0.001 * (1.0 + 1e-9),
        "path point {} from the motion",
        d.gap
    );
}

/// 40 lines of 20 mm, zigzag with corners, then [`long_contour`]'s polygon: a window
/// on a grid streams where a line leaves room to stop after a cut (see "Streaming on a
/// grid" in the planner): on the lines here, not on the polygon's 1.7 mm sides.
fn lines_then_polygon() -> Contour {
    let polygon = long_contour();
    let start = polygon.elements[0].start;
    let mut at = pos(start[0] - 20.0, start[1] - 80.0, 0.0);
    let mut elements = Vec::new();
    for i in 0..40 {
        let x = if i % 2 == 0 {
            start[0]
        } else {
            start[0] - 20.0
        };
        let next = if i == 39 {
            start
        } else {
            pos(x, at[1] + 2.0, 0.0)
        };
        elements.push(line(at, next, 80.0));
        at = next;
    }
    elements.extend(polygon.elements);
    contour(elements)
}

/// As [`plan_stream`], with the number of pieces emitted before the contour ended.
fn plan_stream_counting(c: &Contour, options: &PathOptions, window: usize) -> (PvtContour, usize) {
    let start = XYZ.iter().map(|a| c.elements[0].start[a.index()]).collect();
    let out = std::cell::RefCell::new(PvtContour::new(c.motion, start));
    let mut emit =
        |s: &pvt_core::SegmentRef<'_>| out.borrow_mut().push(s.end, s.velocity, s.duration, s.line);
    let mut stream = PathStream::with_window(&XYZ, options, window);
    for e in &c.elements {
        stream.push(e, &mut emit).unwrap();
    }
    let early = out.borrow().durations.len();
    stream.finish(&mut emit).unwrap();
    (out.into_inner(), early)
}

/// The planner's options at `tolerance` (no corner tolerance) under `limits`, on the
/// grid of `quantum` when given, with the test servo period and no position rounding.
fn path_options(
    tolerance: f64,
    limits: &BTreeMap<Axis, AxisLimits>,
    quantum: Option<Quantum>,
) -> PathOptions {
    PathOptions {
        tolerance,
        corner_tolerance: None,
        limits: limits.clone(),
        quantum,
        servo_period: SERVO,
        position_resolution: 0.0,
    }
}

/// Plans `c` through a [`PathStream`] holding at most `window` elements.
fn plan_windowed(
    c: &Contour,
    tol: f64,
    lim: &BTreeMap<Axis, AxisLimits>,
    window: usize,
) -> PvtContour {
    let options = path_options(tol, lim, None);
    plan_stream(c, &options, window)
}

/// Plans `c` with `options` through a [`PathStream`] holding at most `window` elements.
fn plan_stream(c: &Contour, options: &PathOptions, window: usize) -> PvtContour {
    let start = XYZ.iter().map(|a| c.elements[0].start[a.index()]).collect();
    let mut out = PvtContour::new(c.motion, start);
    let mut emit = |s: &pvt_core::SegmentRef<'_>| out.push(s.end, s.velocity, s.duration, s.line);
    let mut stream = PathStream::with_window(&XYZ, options, window);
    for e in &c.elements {
        stream.push(e, &mut emit).unwrap();
    }
    stream.finish(&mut emit).unwrap();
    out
}

/// A 720-gon of radius 200 (1.7 mm sides) with a helical arc and a plunge in the middle.
fn long_contour() -> Contour {
    let mut elements = Vec::new();
    let mut at = pos(200.0, 0.0, 0.0);
    for i in 1..=720 {
        let a = (i as f64).to_radians() * 0.5;
        let next = pos(200.0 * a.cos(), 200.0 * a.sin(), 0.0);
        elements.push(line(at, next, 50.0));
        at = next;
        if i == 360 {
            let end = pos(at[0], at[1], -2.0);
            elements.push(line(at, end, 20.0));
            at = end;
        }
    }
    contour(elements)
}

#[test]
fn a_short_window_gives_the_same_motion_as_the_whole_contour() {
    let c = long_contour();
    let lim = limits(100.0, 1000.0);
    let whole = plan_windowed(&c, 0.001, &lim, usize::MAX);
    let windowed = plan_windowed(&c, 0.001, &lim, 16);
    for planned in [&whole, &windowed] {
        assert_follows(&c, planned, 0.001);
        assert_within(planned, 100.0, 1000.0);
    }
    let ratio = windowed.total_time() / whole.total_time();
    assert!((ratio - 1.0).abs() < 1e-6, "windowed / whole time {ratio}");
}

#[test]
fn a_window_shorter_than_the_stopping_distance_is_slower_but_within_limits() {
    let c = long_contour();
    let lim = limits(100.0, 20.0);
    let whole = plan_windowed(&c, 0.001, &lim, usize::MAX);
    let windowed = plan_windowed(&c, 0.001, &lim, 4);
    for planned in [&whole, &windowed] {
        assert_follows(&c, planned, 0.001);
        assert_within(planned, 100.0, 20.0);
    }
    assert!(windowed.total_time() >= whole.total_time() * (1.0 - 1e-9));
}

#[test]
fn a_tolerance_no_piece_can_meet_is_an_error_naming_the_line() {
    // A 1° bend passed at the feed: its pieces halve each round, 400 rounds fall short.
    let bend = (1.0f64).to_radians();
    let c = contour(vec![
        line(pos(0.0, 0.0, 0.0), pos(10.0, 0.0, 0.0), 50.0),
        line(
            pos(10.0, 0.0, 0.0),
            pos(10.0 + 10.0 * bend.cos(), 10.0 * bend.sin(), 0.0),
            50.0,
        ),
    ]);
    let options = path_options(1e-200, &BTreeMap::new(), None);
    let e = plan_path(&c, &XYZ, &options).unwrap_err();
    assert_eq!(e.code(), "pvtc::plan::path_not_met");
    assert_eq!(e.line(), 1);
}

/// A 100 mm line from rest to rest under `samples/machines/mill.toml`'s X limits
/// (100 mm/s, 1000 mm/s², 50000 mm/s³), worked by hand. The planner plans to
/// (1 − 10⁻⁵) of each limit, and a line's S-curves take 0.99 of the jerk: V = 100·s,
/// A = 1000·s, J = 49500·s with s = 1 − 10⁻⁵ (Ruckig's optimum at the whole limits:
/// 1.12 s). V ≥ A²/J, so each speed change reaches A:
/// a ramp of A/J, a constant-acceleration middle of V/A − A/J and a ramp down, over
/// (V/2)·(V/A + A/J) mm each; the cruise covers the rest at V.
#[test]
fn a_line_from_rest_to_rest_is_two_s_curves_and_a_cruise() {
    let c = contour(vec![line(pos(0.0, 0.0, 0.0), pos(100.0, 0.0, 0.0), 6000.0)]);
    let share: f64 = 1.0 - 1e-5;
    let lim = limits_with_jerk(100.0, 1000.0, Some(50000.0));
    let planned = plan(&c, 0.001, &lim);
    let (v, a, j) = (100.0 * share, 1000.0 * share, 0.99 * 50000.0 * share);
    let (ramp, middle) = (a / j, v / a - a / j);
    let change = v / 2.0 * (v / a + a / j);
    let cruise = (100.0 - 2.0 * change) / v;
    let expected = [ramp, middle, ramp, cruise, ramp, middle, ramp];
    assert_eq!(
        planned.durations.len(),
        expected.len(),
        "{:?}",
        planned.durations
    );
    for (t, e) in planned.durations.iter().zip(expected) {
        assert!(
            (t - e).abs() <= 1e-9 * e,
            "durations {:?}, expected {expected:?}",
            planned.durations
        );
    }
    let total = 2.0 * (v / a + a / j) + cruise;
    assert!((planned.total_time() - total).abs() <= 1e-9 * total);
    let (peak_v, peak_a) = reference::peaks(&planned)[0];
    assert!((peak_v - v).abs() <= 1e-9 * v, "velocity {peak_v}");
    assert!((peak_a - a).abs() <= 1e-9 * a, "acceleration {peak_a}");
    let jerk = reference::jerks(&planned)[0];
    assert!((jerk - j).abs() <= 1e-6 * j, "jerk {jerk}");
    // Continuous acceleration: no step at any knot (rounding only).
    assert!(
        reference::knot_steps(&planned)[0] < 1e-6,
        "{:?}",
        reference::knot_steps(&planned)
    );
}

/// A 0.2 mm line from rest to rest under the same limits never reaches A: each speed
/// change is two ramps of jerk J meeting at the peak speed p, over p·√(p/J) = 0.1 mm, so
/// p = (0.1·√J)^⅔ and each of the four pieces takes √(p/J); the peak acceleration is √(p·J).
#[test]
fn a_short_line_is_two_triangular_s_curves() {
    let c = contour(vec![line(pos(0.0, 0.0, 0.0), pos(0.2, 0.0, 0.0), 6000.0)]);
    let share: f64 = 1.0 - 1e-5;
    let lim = limits_with_jerk(100.0, 1000.0, Some(50000.0));
    let planned = plan(&c, 0.001, &lim);
    let (a, j) = (1000.0 * share, 0.99 * 50000.0 * share);
    let peak = (0.1 * j.sqrt()).powf(2.0 / 3.0);
    assert!(peak < a * a / j, "the case is triangular: {peak}");
    let ramp = (peak / j).sqrt();
    assert_eq!(planned.durations.len(), 4, "{:?}", planned.durations);
    for t in &planned.durations {
        assert!(
            (t - ramp).abs() <= 1e-9 * ramp,
            "{:?} != {ramp}",
            planned.durations
        );
    }
    let (peak_v, peak_a) = reference::peaks(&planned)[0];
    assert!(
        (peak_v - peak).abs() <= 1e-9 * peak,
        "velocity {peak_v} != {peak}"
    );
    let expected = (peak * j).sqrt();
    assert!(
        (peak_a - expected).abs() <= 1e-9 * expected,
        "acceleration {peak_a}"
    );
    assert!(
        reference::knot_steps(&planned)[0] < 1e-6,
        "{:?}",
        reference::knot_steps(&planned)
    );
}

/// Under a jerk limit a contour streams in windows too (see "Jerk" in the planner):
/// windows of 16 and 64 elements cut [`lines_then_polygon`] inside its lines, emit
/// pieces before the contour ends, and keep every limit, every piece's jerk, every
/// knot's acceleration step (where windows meet too) and the tolerance, all recomputed
/// from the written end states; the windows' caps cost at most 2 % of the time of the
/// contour planned whole.
#[test]
fn a_jerk_limit_streams_in_windows_within_every_limit() {
    let c = lines_then_polygon();
    let lim = limits_with_jerk(100.0, 1000.0, Some(50000.0));
    let options = path_options(0.001, &lim, None);
    let (whole, held) = plan_stream_counting(&c, &options, usize::MAX);
    assert_eq!(held, 0, "the whole contour is planned at its end");
    for window in [16, 64] {
        let (planned, early) = plan_stream_counting(&c, &options, window);
        assert_follows(&c, &planned, 0.001);
        assert_within(&planned, 100.0, 1000.0);
        assert_jerk_within(&planned, 50000.0);
        assert!(early >= 100, "window {window}: {early} pieces early");
        let ratio = planned.total_time() / whole.total_time();
        assert!((0.999..1.02).contains(&ratio), "window {window}: {ratio}");
    }
    assert_follows(&c, &whole, 0.001);
    assert_jerk_within(&whole, 50000.0);
}

/// Under a jerk limit a contour streams on grids of 1, 2 and 0.442 ms too (see
/// "Streaming on a grid" in the planner): windows of 16 and 64 elements emit pieces
/// before the contour ends, every piece on the grid and within every limit, every
/// piece's jerk, every grid knot's acceleration step (where windows meet too) and the
/// tolerance, all recomputed from the written end states, and the time stays near that
/// of the contour planned whole on the same grid.
#[test]
fn a_jerk_limit_streams_on_grids_within_every_limit() {
    let c = lines_then_polygon();
    let lim = limits_with_jerk(100.0, 1000.0, Some(50000.0));
    for ms in [1.0, 2.0, 0.442] {
        let q = Quantum {
            seconds: ms / 1000.0,
            rounding: Rounding::Up,
        };
        let options = path_options(0.001, &lim, Some(q));
        let (whole, _) = plan_stream_counting(&c, &options, usize::MAX);
        for window in [16, 64] {
            let (planned, early) = plan_stream_counting(&c, &options, window);
            assert_on_grid(&planned, q.seconds);
            assert_follows(&c, &planned, 0.001);
            assert_within(&planned, 100.0, 1000.0);
            assert_jerk_within(&planned, 50000.0);
            assert!(
                early >= 100,
                "{ms} ms, window {window}: {early} pieces early"
            );
            let ratio = planned.total_time() / whole.total_time();
            assert!(
                (0.95..1.05).contains(&ratio),
                "{ms} ms, window {window}: {ratio}"
            );
        }
    }
}

/// Asserts every piece's jerk within `j` and every knot's acceleration step within
/// `j · SERVO`, both recomputed from the written end states by the reference.
fn assert_jerk_within(planned: &PvtContour, j: f64) {
    for jerk in reference::jerks(planned) {
        assert!(jerk <= j * (1.0 + 1e-6), "jerk {jerk} > {j}");
    }
    for step in reference::knot_steps(planned) {
        let bound = j * SERVO;
        assert!(
            step <= bound * (1.0 + 1e-6),
            "acceleration step {step} > {bound}"
        );
    }
}

/// Single lines of 0.2 to 100 mm under mill.toml's X limits on a 1 ms grid: the
/// jerk-limited plan resampled onto the grid takes at most two quanta more than the plan
/// itself (stretching each S-curve part to whole quanta, at least three, took 0.142 s
/// for the 2 mm line against 0.112 s), within every limit.
#[test]
fn single_lines_on_a_1ms_grid_under_a_jerk_limit_lose_at_most_two_quanta() {
    let lim = limits_with_jerk(100.0, 1000.0, Some(50000.0));
    for length in [0.2, 0.5, 2.0, 10.0, 100.0] {
        let c = contour(vec![line(
            pos(0.0, 0.0, 0.0),
            pos(length, 0.0, 0.0),
            6000.0,
        )]);
        let free = plan(&c, 0.001, &lim);
        let grid = plan_on(&c, 0.001, &lim, Some(MS));
        assert_on_grid(&grid, MS.seconds);
        assert_follows(&c, &grid, 0.001);
        assert_within(&grid, 100.0, 1000.0);
        assert_jerk_within(&grid, 50000.0);
        let (t0, t1) = (free.total_time(), grid.total_time());
        assert!(
            t1 <= t0 + 2.0 * MS.seconds + 1e-9,
            "{length} mm: {t1} s on the grid against {t0} s planned"
        );
    }
}

/// A circle of R 30 as 360 chords at F6000 under mill.toml's X and Y limits, on grids
/// of 1, 2 and 0.442 ms: the jerk-limited plan is resampled, not stretched piece by
/// piece (which took 5.3, 5.2 and 5.5 times as long), so the grid's time stays near the
/// un-gridded plan's. On 2 ms, four servo periods, a jerk change inside a quantum can
/// step the acceleration more than one period allows, and on 0.442 ms an acceleration
/// step inside a quantum asks more jerk than the limit: those grids take the lower
/// jerks and steps of the later plans. Every limit, step and the tolerance hold,
/// recomputed independently.
#[test]
fn dense_chords_on_grids_under_a_jerk_limit_keep_the_planned_time() {
    let points: Vec<Position> = (0..=360)
        .map(|i| {
            let a = std::f64::consts::TAU * f64::from(i % 360) / 360.0;
            pos(30.0 * a.cos(), 30.0 * a.sin(), 0.0)
        })
        .collect();
    let c = contour(
        points
            .windows(2)
            .map(|w| line(w[0], w[1], 6000.0))
            .collect(),
    );
    let lim = limits_with_jerk(100.0, 1000.0, Some(50000.0));
    let free = plan(&c, 0.001, &lim);
    for (ms, most) in [(1.0, 1.05), (2.0, 1.25), (0.442, 1.5)] {
        let q = Quantum {
            seconds: ms / 1000.0,
            rounding: Rounding::Up,
        };
        let grid = plan_on(&c, 0.001, &lim, Some(q));
        assert_on_grid(&grid, q.seconds);
        assert_follows(&c, &grid, 0.001);
        assert_within(&grid, 100.0, 1000.0);
        assert_jerk_within(&grid, 50000.0);
        let ratio = grid.total_time() / free.total_time();
        assert!(ratio <= most, "{ms} ms: {ratio} of the un-gridded time");
    }
}

/// A cubic Bézier from `at` by offsets: inner control points `c1`, `c2` and end `e` in XY,
/// `dz` of Z travel.
fn bezier_step(at: Position, c: [f64; 6], dz: f64, feed: f64) -> Element {
    Element {
        kind: ElementKind::Bezier(Bezier {
            plane: Plane::XY,
            controls: [[at[0] + c[0], at[1] + c[1]], [at[0] + c[2], at[1] + c[3]]],
            fit: 0.0,
        }),
        start: at,
        end: pos(at[0] + c[4], at[1] + c[5], at[2] + dz),
        feed,
        span: Span::default(),
    }
}

fn bezier_steps() -> impl Strategy<Value = Vec<([f64; 6], f64)>> {
    prop::collection::vec(
        (
            prop::array::uniform6(-30.0..30.0f64),
            prop_oneof![3 => Just(0.0), 1 => -3.0..3.0f64],
        ),
        1..4,
    )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// Random cubic Béziers (loops, cusps and near-cusps included), chained, with and
    /// without limits: every cubic, evaluated densely, is within the tolerance of the
    /// true curve (its Bernstein form, evaluated by the reference), and covers it.
    #[test]
    fn random_beziers_stay_within_tolerance_and_cover_the_curve(
        steps in bezier_steps(),
        tol_exp in -3.0..-1.0f64,
        feed in 5.0..200.0f64,
        limited in any::<bool>(),
    ) {
        let mut at = pos(0.0, 0.0, 0.0);
        let mut elements = Vec::new();
        for (c, dz) in &steps {
            let e = bezier_step(at, *c, *dz, feed);
            at = e.end;
            elements.push(e);
        }
        let c = contour(elements);
        let tol = 10f64.powf(tol_exp);
        let lim = if limited { limits(80.0, 800.0) } else { BTreeMap::new() };
        let planned = plan(&c, tol, &lim);
        within(&c, &planned, tol, limited)?;
    }
}

/// A smooth S-shaped Bézier takes few pieces from rest to rest: its pieces are placed by
/// the cubic's own error bound, not by chords.
#[test]
fn a_smooth_bezier_is_few_pieces() {
    let c = contour(vec![bezier_step(
        pos(0.0, 0.0, 0.0),
        [10.0, 20.0, 20.0, -20.0, 30.0, 0.0],
        0.0,
        100.0,
    )]);
    let planned = plan(&c, 1e-3, &BTreeMap::new());
    assert_follows(&c, &planned, 1e-3);
    // Chords within 1e-3 would be √(max|B''|/(8·1e-3)) = √(360/0.008) = 213.
    assert!(planned.len() <= 32, "{} pieces", planned.len());
}

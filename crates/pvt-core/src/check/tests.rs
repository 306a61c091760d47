//! Seed 001's numbers and hand-computed closed forms.

use super::*;
use crate::axis::Units;
use crate::plan::{plan_timed, PlanOptions, Planner, TimedPoints};
use crate::program::{Interpolation, PvtContour};
use crate::toolpath::{Arc, ArcDirection, Contour, Element, ElementKind, Motion, Plane, Span};

fn series(dim: usize, points: &[f64], dt: f64) -> TimedPoints {
    let mut r = TimedPoints::start_at(&points[..dim]);
    for (i, p) in points.chunks(dim).skip(1).enumerate() {
        r.push(p, dt, i as u32 + 3);
    }
    r
}

fn planned(points: &TimedPoints, axes: &[Axis], planner: Planner) -> PvtProgram {
    let options = PlanOptions {
        planner,
        ..PlanOptions::default()
    };
    plan_timed(points, axes.to_vec(), Units::Millimetre, &options)
        .unwrap()
        .program
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs())
}

const STEP: [f64; 8] = [0.0, 0.0, 0.0, 0.0, 5000.0, 5000.0, 5000.0, 5000.0];

#[test]
fn pt_step_has_seed_001_peak_acceleration() {
    let program = planned(&series(1, &STEP, 0.25), &[Axis::X], Planner::Pt);
    let report = check_program(&program, None, &CheckOptions::default());
    let x = report.axis(Axis::X).unwrap();
    // A 20000 counts/s step seen over one 500 µs sample: 20000 / 0.0005 = 4e7.
    assert!(
        close(x.sampled_acceleration.value, 4.0e7, 1e-6),
        "{:?}",
        x.sampled_acceleration
    );
    assert!(close(x.acceleration.value, 4.0e7, 1e-12));
    assert!(close(x.sampled_velocity.value, 20000.0, 1e-6));
    assert_eq!(x.velocity.value, 20000.0);
    assert!(close(x.acceleration.time, 0.75, 1e-12) && x.acceleration.line == 6);
    assert!(close(report.total_time, 1.75, 1e-12));
    assert!(report.path_error.is_none() && report.speed.is_none());
}

/// Seed 001's octagon: 9 points 45° apart on r = 5000 about (0, 5000), from 6 o'clock.
fn octagon() -> (TimedPoints, Toolpath) {
    let mut pts = Vec::new();
    for i in 0..=8 {
        let a = -std::f64::consts::FRAC_PI_2 + i as f64 * std::f64::consts::FRAC_PI_4;
        pts.extend_from_slice(&[5000.0 * libm::cos(a), 5000.0 + 5000.0 * libm::sin(a)]);
    }
    pts[0] = 0.0;
    pts[16] = 0.0;
    pts[1] = 0.0;
    pts[17] = 0.0;
    let circle = Arc {
        plane: Plane::XY,
        center: [0.0, 5000.0],
        direction: ArcDirection::CounterClockwise,
        extra_turns: 0,
    };
    let origin = [0.0; 6];
    let element = Element {
        kind: ElementKind::Arc(circle),
        start: origin,
        end: origin,
        feed: 10000.0,
        span: Span::default(),
    };
    let toolpath = Toolpath {
        contours: vec![Contour {
            motion: Motion::Feed,
            elements: vec![element],
        }],
        ..Toolpath::default()
    };
    (series(2, &pts, 0.25), toolpath)
}

#[test]
fn pt_octagon_radial_error_is_the_sagitta() {
    let (points, circle) = octagon();
    let program = planned(&points, &[Axis::X, Axis::Y], Planner::Pt);
    let report = check_program(&program, Some(&circle), &CheckOptions::default());
    let expected = 5000.0 * (1.0 - libm::cos(22.5f64.to_radians()));
    let error = report.path_error.unwrap();
    assert!(
        close(error.value, expected, 1e-9),
        "{} vs {expected}",
        error.value
    );
    // Midway between two points.
    let phase = (error.time / 0.25).fract();
    assert!((phase - 0.5).abs() < 1e-6, "{phase}");
}

/// Largest distance from the circle over one piece, by dense sampling.
fn radial_error(program: &PvtProgram, i: usize) -> f64 {
    let c = &program.contours[0];
    (0..=1000)
        .map(|s| {
            let t = c.durations[i] * s as f64 / 1000.0;
            let (x, y) = (
                c.hermite(i, 0).at(t).position,
                c.hermite(i, 1).at(t).position,
            );
            (libm::hypot(x, y - 5000.0) - 5000.0).abs()
        })
        .fold(0.0, f64::max)
}

#[test]
fn pvt_octagon_errs_most_in_first_and_last_segments() {
    let (points, circle) = octagon();
    for planner in [Planner::Contour, Planner::Chord, Planner::Spline] {
        let program = planned(&points, &[Axis::X, Axis::Y], planner);
        let errors: Vec<f64> = (0..8).map(|i| radial_error(&program, i)).collect();
        // Chord's forward difference is not symmetric: its first segment already ends
        // with the next chord's velocity, so only its last segment stands out.
        let ends = if planner == Planner::Chord {
            errors[7]
        } else {
            errors[0].min(errors[7])
        };
        assert!(
            errors[1..7].iter().all(|&e| e < ends),
            "{planner}: {errors:?}"
        );
        let report = check_program(&program, Some(&circle), &CheckOptions::default());
        let worst = report.path_error.unwrap();
        assert!(
            close(worst.value, errors[0].max(errors[7]), 1e-6),
            "{planner}: {worst:?} {errors:?}"
        );
        let c = &program.contours[0];
        let in_ends = worst.time <= c.durations[0] || worst.time >= c.total_time() - c.durations[7];
        assert!(in_ends, "{planner}: {worst:?}");
    }
}

fn one_piece(p0: f64, v0: f64, p1: f64, v1: f64, t: f64) -> PvtProgram {
    let mut c = PvtContour::new(Motion::Feed, vec![p0]);
    c.push(&[p0], &[v0], 1.0, 1);
    c.push(&[p1], &[v1], t, 2);
    c.push(&[p1], &[0.0], 1.0, 3);
    PvtProgram {
        axes: vec![Axis::X],
        units: Units::Millimetre,
        interpolation: Interpolation::Pvt,
        contours: vec![c],
        events: Vec::new(),
    }
}

#[test]
fn closed_form_peaks_match_hand_values() {
    // Rest to rest over 10 in 2 s: peak speed 1.5·10/2 at mid-time, |a| = 6·10/4, |j| = 12·10/8.
    let mut c = PvtContour::new(Motion::Feed, vec![0.0]);
    c.push(&[10.0], &[0.0], 2.0, 7);
    let program = PvtProgram {
        axes: vec![Axis::X],
        units: Units::Millimetre,
        interpolation: Interpolation::Pvt,
        contours: vec![c],
        events: Vec::new(),
    };
    let x = *check_program(&program, None, &CheckOptions::default())
        .axis(Axis::X)
        .unwrap();
    assert!(
        close(x.velocity.value, 7.5, 1e-12)
            && close(x.velocity.time, 1.0, 1e-12)
            && x.velocity.line == 7
    );
    assert!(close(x.acceleration.value, 15.0, 1e-12) && x.acceleration.time == 0.0);
    assert!(close(x.jerk.value, 15.0, 1e-12));
    // Sampled: the servo sees nearly the same peaks.
    assert!(close(x.sampled_velocity.value, 7.5, 1e-4));
    assert!(close(x.sampled_acceleration.value, 15.0, 1e-3));
    // A piece that turns back inside: v(t) = 3 − 12t + 6t² from 0 (v 3) to 0 (v 3) in 1 s,
    // not larger than its ends; one that peaks inside: from 0 at 1 to 0 at −1 ... v(½) = 1.5.
    let x = *check_program(
        &one_piece(0.0, 0.0, 1.0, 0.0, 1.0),
        None,
        &CheckOptions::default(),
    )
    .axis(Axis::X)
    .unwrap();
    assert!(
        close(x.velocity.value, 1.5, 1e-12)
            && close(x.velocity.time, 1.5, 1e-12)
            && x.velocity.line == 2
    );
    let x = *check_program(
        &one_piece(0.0, 0.0, 2.0, 4.0, 1.0),
        None,
        &CheckOptions::default(),
    )
    .axis(Axis::X)
    .unwrap();
    // Rest to (2, 4) in 1 s: a0 = 12 − 8 = 4, j = 24 − 24 = 0; then back to rest in 1 s
    // from v 4 with no displacement: a0 = −16, j = 24; |v| peaks at the end of piece 2.
    assert!(close(x.velocity.value, 4.0, 1e-12) && close(x.acceleration.value, 16.0, 1e-12));
    assert!(close(x.jerk.value, 24.0, 1e-12) && x.jerk.line == 3);
}

#[test]
fn limits_are_reported_per_line() {
    let program = planned(&series(1, &STEP, 0.25), &[Axis::X], Planner::Spline);
    let mut options = CheckOptions::default();
    options.limits.insert(
        Axis::X,
        AxisLimits {
            velocity: Some(1000.0),
            acceleration: Some(1e9),
            jerk: None,
        },
    );
    let report = check_program(&program, None, &options);
    assert!(report.exceeded());
    assert!(report
        .violations
        .iter()
        .all(|v| v.quantity == Quantity::Velocity && v.value > 1000.0));
    let lines: Vec<u32> = report.violations.iter().map(|v| v.line).collect();
    let mut unique = lines.clone();
    unique.dedup();
    assert_eq!(lines, unique);
    let peak = report.axis(Axis::X).unwrap().velocity;
    assert!(report
        .violations
        .iter()
        .any(|v| v.value == peak.value && v.line == peak.line));
}

#[test]
fn straight_line_follows_its_source_at_the_feed() {
    let element = Element {
        kind: ElementKind::Line,
        start: [0.0; 6],
        end: [30.0, 40.0, 0.0, 0.0, 0.0, 0.0],
        feed: 10.0,
        span: Span {
            start: 0,
            end: 0,
            line: 4,
        },
    };
    let toolpath = Toolpath {
        contours: vec![Contour {
            motion: Motion::Feed,
            elements: vec![element],
        }],
        ..Toolpath::default()
    };
    let program = crate::plan::plan_toolpath(&toolpath, &PlanOptions::default()).unwrap();
    let report = check_program(&program, Some(&toolpath), &CheckOptions::default());
    assert!(report.max_path_error().unwrap() < 1e-9);
    let speed = report.speed.unwrap();
    // Seed 000 rest to rest: peak speed at mid-time equals the feed.
    assert!(close(speed.max.value, 10.0, 1e-6) && speed.min.value < 1e-3);
    assert!(speed.rms_error > 0.0 && speed.samples > 0);
    assert!(close(report.total_time, 7.5, 1e-12));
}

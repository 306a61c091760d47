//! Seed 001's numbers and hand-computed closed forms.

use super::*;
use crate::axis::Units;
use crate::plan::{PlanOptions, Planner, TimedPoints};
use crate::program::{Interpolation, PvtContour};
use crate::stream::plan_timed;
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
    pvt_x_from(p0, &[(p0, v0, 1.0, 1), (p1, v1, t, 2), (p1, 0.0, 1.0, 3)])
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
    let program = crate::stream::plan_toolpath(&toolpath, &PlanOptions::default()).unwrap();
    let report = check_program(&program, Some(&toolpath), &CheckOptions::default());
    assert!(report.max_path_error().unwrap() < 1e-9);
    let speed = report.speed.unwrap();
    // Seed 000 rest to rest: peak speed at mid-time equals the feed.
    assert!(close(speed.max.value, 10.0, 1e-6) && speed.min.value < 1e-3);
    assert!(speed.rms_error > 0.0 && speed.samples > 0);
    assert!(close(report.total_time, 7.5, 1e-12));
}

/// One feed contour on X through `(end, velocity, time, line)` pieces from rest at 0.
fn pvt_x(pieces: &[(f64, f64, f64, u32)]) -> PvtProgram {
    pvt_x_from(0.0, pieces)
}

/// One feed contour on X through `(end, velocity, time, line)` pieces from rest at `start`.
fn pvt_x_from(start: f64, pieces: &[(f64, f64, f64, u32)]) -> PvtProgram {
    let mut c = PvtContour::new(Motion::Feed, vec![start]);
    for &(p, v, t, line) in pieces {
        c.push(&[p], &[v], t, line);
    }
    PvtProgram {
        axes: vec![Axis::X],
        units: Units::Millimetre,
        interpolation: Interpolation::Pvt,
        contours: vec![c],
        events: Vec::new(),
    }
}

fn with_jerk(period: f64, jerk: f64) -> CheckOptions {
    let mut options = CheckOptions {
        servo_period: period,
        ..CheckOptions::default()
    };
    options.limits.insert(
        Axis::X,
        AxisLimits {
            jerk: Some(jerk),
            ..AxisLimits::default()
        },
    );
    options
}

/// The acceleration-step violations of `program` under a jerk limit `jerk` over `period`,
/// as (line, step in units/s², time); every violation must be a step.
fn step_violations(program: &PvtProgram, period: f64, jerk: f64) -> Vec<(u32, f64, f64)> {
    check_program(program, None, &with_jerk(period, jerk))
        .violations
        .iter()
        .map(|v| {
            assert_eq!(v.quantity, Quantity::AccelerationStep);
            (v.line, v.value * period, v.time)
        })
        .collect()
}

#[test]
fn acceleration_steps_at_knots_are_the_hand_values() {
    // By hand, a(0) = (6Δp − 4v₀T − 2v₁T)/T² and a(T) = (−6Δp + 2v₀T + 4v₁T)/T²:
    // piece 1, (0, 0) → (1, 1) in 1 s: a from 4 to −2;
    // piece 2, (1, 1) → (3, 3) in 1 s: a from 2 to 2;
    // piece 3, (3, 3) → (3, 0) in 1 s: a from −12 to 6.
    // Steps: 4 from rest, 2 − (−2) = 4, −12 − 2 = −14, and 6 back to rest at the end.
    let program = pvt_x(&[(1.0, 1.0, 1.0, 1), (3.0, 3.0, 1.0, 2), (3.0, 0.0, 1.0, 3)]);
    let period = 0.001;
    let tl = Timeline::new(&program);
    let into: Vec<Peak> = (0..3)
        .map(|i| {
            let [.., (q, peak)] = peaks::piece_peaks(&tl, i, 0, period);
            assert_eq!(q, Quantity::AccelerationStep);
            peak
        })
        .collect();
    for (peak, (step, time, line)) in
        into.iter()
            .zip([(4.0, 0.0, 1), (4.0, 1.0, 2), (14.0, 2.0, 3)])
    {
        assert!(close(peak.value, step / period, 1e-12), "{peak:?}");
        assert!(
            close(peak.time, time, 1e-12) && peak.line == line,
            "{peak:?}"
        );
    }
    assert!(peaks::stop(&tl, &tl.pieces[1], 0, period).next().is_none());
    let end: Vec<(Quantity, Peak)> = peaks::stop(&tl, &tl.pieces[2], 0, period).collect();
    assert_eq!(end.len(), 1);
    assert_eq!(end[0].0, Quantity::AccelerationStep);
    assert!(close(end[0].1.value, 6.0 / period, 1e-12) && close(end[0].1.time, 3.0, 1e-12));
    // The report: the largest step, at the second knot; the pieces' jerk is apart from it
    // (6·(v₀ + v₁)/T² − 12Δp/T³: −6, 0, 18).
    let report = check_program(&program, None, &with_jerk(period, 14.0 / period));
    let x = report.axis(Axis::X).unwrap();
    assert!(close(x.acceleration_step.value, 14000.0, 1e-12));
    assert!(close(x.acceleration_step.time, 2.0, 1e-12) && x.acceleration_step.line == 3);
    assert!(close(x.jerk.value, 18.0, 1e-9));
    assert!(!report.exceeded(), "{:?}", report.violations);
    let report = check_program(&program, None, &with_jerk(period, 10.0 / period));
    let v = report.violations;
    assert_eq!(v.len(), 1, "{v:?}");
    assert_eq!((v[0].quantity, v[0].line), (Quantity::AccelerationStep, 3));
    assert!(close(v[0].value, 14000.0, 1e-12) && close(v[0].time, 2.0, 1e-12));
    assert_eq!(v[0].limit, 10000.0);
}

#[test]
fn a_contour_starts_and_ends_against_rest() {
    // Piece 1, (0, 0) → (1, 1) in 1 s: a from 4 to −2; piece 2, (1, 1) → (1.5, 0) in
    // 0.5 s: a from 4 to −8. Steps: 4 from rest at 0 s, 6 at 1 s, 8 to rest at 1.5 s.
    let program = pvt_x(&[(1.0, 1.0, 1.0, 1), (1.5, 0.0, 0.5, 2)]);
    let period = 0.001;
    let steps = |jerk: f64| step_violations(&program, period, jerk);
    let near = |got: &[(u32, f64, f64)], want: &[(u32, f64, f64)]| {
        got.len() == want.len()
            && got
                .iter()
                .zip(want)
                .all(|(a, b)| a.0 == b.0 && close(a.1, b.1, 1e-12) && close(a.2, b.2, 1e-12))
    };
    // Only the stop at the end is over 7 / P; line 2's worst is its end, not its knot.
    let got = steps(7.0 / period);
    assert!(near(&got, &[(2, 8.0, 1.5)]), "{got:?}");
    // Over 3 / P: the start from rest as well.
    let got = steps(3.0 / period);
    assert!(near(&got, &[(1, 4.0, 0.0), (2, 8.0, 1.5)]), "{got:?}");
    assert!(steps(8.0 / period).is_empty());
    // The step scales with the servo period: over 2 ms it is half as steep.
    let report = check_program(&program, None, &with_jerk(0.002, 1e9));
    let x = report.axis(Axis::X).unwrap();
    assert!(close(x.acceleration_step.value, 4000.0, 1e-12));
}

/// Two contours one after the other: the step between them is one step, from the first
/// contour's end acceleration to the second's start, unless the machine rests between.
#[test]
fn contours_straight_on_step_once_and_rest_only_where_the_machine_rests() {
    use crate::toolpath::{EventKind, ProgramEvent, SpindleState};
    // Contour 1, (0, 0) → (1, 0) in 1 s: a from 6 to −6. Contour 2, (1, 0) → (1.5, 0) in
    // 1 s: a from 3 to −3. Straight on, the step between them at 1 s is 3 − (−6) = 9;
    // against rest it is 6 on one side and 3 on the other.
    let mut program = pvt_x(&[(1.0, 0.0, 1.0, 1)]);
    let mut second = PvtContour::new(Motion::Feed, vec![1.0]);
    second.push(&[1.5], &[0.0], 1.0, 2);
    program.contours.push(second);
    let period = 0.001;
    let steps = |program: &PvtProgram| step_violations(program, period, 7.0 / period);
    let straight_on = |got: &[(u32, f64, f64)]| {
        got.len() == 1
            && got[0].0 == 2
            && close(got[0].1, 9.0, 1e-12)
            && close(got[0].2, 1.0, 1e-12)
    };
    let got = steps(&program);
    assert!(straight_on(&got), "{got:?}");
    // A spindle event between does not stop the motion.
    let event = |kind: EventKind| ProgramEvent {
        before_contour: 1,
        kind,
        line: 2,
    };
    program.events.push(event(EventKind::Spindle {
        state: SpindleState::Off,
    }));
    let got = steps(&program);
    assert!(straight_on(&got), "{got:?}");
    // A dwell does: each side steps against rest, 6 and 3, both within 7.
    program
        .events
        .push(event(EventKind::Dwell { seconds: 0.5 }));
    let got = steps(&program);
    assert!(got.is_empty(), "{got:?}");
}

#[test]
fn pt_acceleration_step_is_the_velocity_step_over_a_period_squared() {
    let program = planned(&series(1, &STEP, 0.25), &[Axis::X], Planner::Pt);
    let report = check_program(&program, None, &CheckOptions::default());
    let x = report.axis(Axis::X).unwrap();
    // 20000 counts/s in one 500 µs period: acceleration 4e7 for one period, stepping up and
    // down by 4e7 within it: 4e7 / 0.0005 = 8e10, as the jerk.
    assert!(close(x.acceleration_step.value, 8.0e10, 1e-12));
    assert_eq!(x.acceleration_step, x.jerk);
    let mut options = CheckOptions::default();
    options.limits.insert(
        Axis::X,
        AxisLimits {
            jerk: Some(1e10),
            ..AxisLimits::default()
        },
    );
    let report = check_program(&program, None, &options);
    for q in [Quantity::Jerk, Quantity::AccelerationStep] {
        assert!(report.violations.iter().any(|v| v.quantity == q));
    }
}

/// A program of PVT and PT contours, rapids and feeds, with pieces shorter and longer than
/// a servo period.
fn mixed(interpolation: Interpolation) -> PvtProgram {
    let mut a = PvtContour::new(Motion::Rapid, vec![0.0, 1.0]);
    a.push(&[2.0, 1.5], &[3.0, 0.5], 0.0013, 4);
    a.push(&[2.1, 1.7], &[0.0, 0.0], 0.25, 5);
    let mut b = PvtContour::new(Motion::Feed, vec![2.1, 1.7]);
    for i in 0..40 {
        let x = 2.1 + 0.01 * f64::from(i + 1);
        b.push(
            &[x, 1.7 - x * 0.1],
            &[0.4, -0.04],
            0.00037 * f64::from(i % 5 + 1),
            6 + i,
        );
    }
    b.push(&[2.6, 1.4], &[0.0, 0.0], 0.01, 50);
    PvtProgram {
        axes: vec![Axis::X, Axis::Y],
        units: Units::Millimetre,
        interpolation,
        contours: vec![a, b],
        events: Vec::new(),
    }
}

#[test]
fn a_walk_reads_what_a_search_finds() {
    for interpolation in [Interpolation::Pvt, Interpolation::Pt] {
        let program = mixed(interpolation);
        let tl = Timeline::new(&program);
        let mut walk = timeline::Walk::new(&tl);
        let (mut got, mut v) = ([0.0; 2], [0.0; 2]);
        let period = 0.0005;
        for k in -3..=((tl.total / period) as i64 + 3) {
            let t = k as f64 * period;
            let i = tl.piece_at(t).unwrap();
            assert_eq!(walk.seek(t), Some(i), "t = {t}");
            let p = &tl.pieces[i];
            walk.positions_at(t, &mut got);
            for (k, x) in got.iter().enumerate() {
                assert_eq!(
                    x.to_bits(),
                    tl.position(p, k, t - p.start).to_bits(),
                    "t = {t}"
                );
            }
            let into = (t - p.start).min(p.duration);
            walk.velocities(i, into, &mut v);
            for (k, x) in v.iter().enumerate() {
                assert_eq!(x.to_bits(), tl.cubic(p, k).at(into).velocity.to_bits());
            }
        }
    }
}

#[test]
fn sampled_peaks_are_second_differences_of_positions_found_by_search() {
    let program = mixed(Interpolation::Pvt);
    let tl = Timeline::new(&program);
    let period = 0.0005;
    let (vel, acc) = servo::sampled_peaks(&tl, period);
    // Independently: every sample's position by binary search, held before and after.
    let x = |t: f64, k: usize| {
        let i = tl.piece_at(t).unwrap();
        tl.position(&tl.pieces[i], k, t - tl.pieces[i].start)
    };
    for k in 0..2 {
        let (mut v, mut a) = (0.0f64, 0.0f64);
        for s in 0..=((tl.total / period).ceil() as i64 + 1) {
            let t = s as f64 * period;
            v = v.max(((x(t, k) - x(t - period, k)) / period).abs());
            let second = (x(t + period, k) - 2.0 * x(t, k) + x(t - period, k)) / (period * period);
            a = a.max(second.abs());
        }
        assert!(close(vel[k].value, v, 1e-12), "{} vs {v}", vel[k].value);
        assert!(close(acc[k].value, a, 1e-12), "{} vs {a}", acc[k].value);
    }
}

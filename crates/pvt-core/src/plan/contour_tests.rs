//! Unit tests of the contour planner (seed 000): degenerate cases and exactness.

use super::*;
use crate::hermite::HermiteSegment;

const F: f64 = 100.0;

/// A polyline through `points` (each of `dim` axes) at feed `F` everywhere.
fn poly(dim: usize, points: &[f64]) -> Polyline {
    let mut p = Polyline::start_at(&points[..dim]);
    for (i, chunk) in points.chunks(dim).enumerate().skip(1) {
        p.push(chunk, F, i as u32 + 1);
    }
    p
}

fn plan(dim: usize, points: &[f64]) -> PvtContour {
    plan_contour(&poly(dim, points), Motion::Feed).unwrap()
}

fn speed(v: &[f64]) -> f64 {
    norm(v)
}

/// Speed of segment `i` at mid-time, from the cubics of all axes.
fn mid_speed(c: &PvtContour, i: usize) -> f64 {
    let t = c.durations[i] / 2.0;
    let v: Vec<f64> = (0..c.dim).map(|k| c.hermite(i, k).at(t).velocity).collect();
    norm(&v)
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()).max(1e-300)
}

#[test]
fn square_corner_velocity_is_along_the_bisector() {
    let c = plan(2, &[0.0, 0.0, 10.0, 0.0, 10.0, 10.0]);
    assert_eq!(c.len(), 2);
    let v = c.segment(0).velocity;
    let h = F / 2f64.sqrt();
    assert!(close(v[0], h, 1e-12) && close(v[1], h, 1e-12), "{v:?}");
    assert_eq!(c.segment(1).velocity, &[0.0, 0.0]);
}

#[test]
fn mid_segment_speed_is_the_mean_of_end_speeds() {
    let pts = [0.0, 0.0, 3.0, 1.0, 5.0, -2.0, 9.0, 0.5, 12.0, 7.0, 4.0, 8.0];
    let c = plan(2, &pts);
    let mut prev = 0.0;
    for i in 0..c.len() {
        let end = speed(c.segment(i).velocity);
        assert!(
            close(mid_speed(&c, i), 0.5 * (prev + end), 1e-9),
            "segment {i}"
        );
        prev = end;
    }
}

#[test]
fn every_segment_ends_at_its_point_with_its_velocity() {
    let pts = [
        0.0, 0.0, 1.0, 3.0, 1.0, 2.0, 5.0, 1.0, 0.0, 0.0, 6.0, 6.0, 6.0, 6.0, 6.0,
    ];
    let c = plan(3, &pts);
    for i in 0..c.len() {
        let seg = c.segment(i);
        for k in 0..3 {
            let e = c.hermite(i, k).end();
            assert!(close(e.position, seg.end[k], 1e-9) || (e.position - seg.end[k]).abs() < 1e-12);
            assert!((e.velocity - seg.velocity[k]).abs() <= 1e-9 * F);
        }
    }
}

#[test]
fn directions_straddling_180_degrees_point_backwards() {
    // Travelling in −X with a slight bend: the chord angles are about +179.4° and −179.4°.
    let c = plan(2, &[0.0, 0.0, -10.0, 0.1, -20.0, 0.0]);
    let v = c.segment(0).velocity;
    assert!(v[0] < -0.99 * F && v[1].abs() < 1e-9 * F, "{v:?}");
}

#[test]
fn repeated_points_are_dropped() {
    let with = plan(2, &[0.0, 0.0, 5.0, 0.0, 5.0, 0.0, 5.0, 5.0, 5.0, 5.0]);
    let without = plan(2, &[0.0, 0.0, 5.0, 0.0, 5.0, 5.0]);
    assert_eq!(with.ends, without.ends);
    assert_eq!(with.velocities, without.velocities);
    assert_eq!(with.durations, without.durations);
}

#[test]
fn full_reversal_comes_to_rest_and_continues() {
    let c = plan(2, &[0.0, 0.0, 10.0, 0.0, 4.0, 0.0]);
    assert_eq!(c.len(), 2);
    assert_eq!(c.segment(0).velocity, &[0.0, 0.0]);
    // Both segments rest to rest: T = 1.5·d / feed, so the peak speed is the feed.
    assert!(close(c.durations[0], 1.5 * 10.0 / F, 1e-12));
    assert!(close(c.durations[1], 1.5 * 6.0 / F, 1e-12));
    assert!(close(mid_speed(&c, 0), F, 1e-12));
}

#[test]
fn near_reversal_keeps_seed_000_behaviour() {
    // Short of 180° by 1e-6 rad: not a reversal, so the corner keeps its speed.
    let a = 1e-6;
    let c = plan(
        2,
        &[
            0.0,
            0.0,
            10.0,
            0.0,
            10.0 - libm::cos(a) * 5.0,
            libm::sin(a) * 5.0,
        ],
    );
    assert!(close(speed(c.segment(0).velocity), F, 1e-12));
}

#[test]
fn collinear_run_moves_at_constant_velocity() {
    let c = plan(2, &[0.0, 0.0, 1.0, 1.0, 2.0, 2.0, 4.0, 4.0, 5.0, 5.0]);
    let h = F / 2f64.sqrt();
    for i in 0..3 {
        let v = c.segment(i).velocity;
        assert!(close(v[0], h, 1e-12) && close(v[1], h, 1e-12));
    }
    // Interior segments: constant speed F, so T = d / F and no acceleration.
    let d = 2.0 * 2f64.sqrt();
    assert!(close(c.durations[2], d / F, 1e-12));
    let h2: HermiteSegment = c.hermite(2, 0);
    assert!(h2.a0.abs() < 1e-9 && h2.jerk.abs() < 1e-6);
    // First segment: from rest to F, mid speed F/2.
    assert!(close(mid_speed(&c, 0), F / 2.0, 1e-12));
}

#[test]
fn two_point_contour_is_rest_to_rest_at_the_feed() {
    let c = plan(1, &[0.0, 5000.0]);
    assert_eq!(c.len(), 1);
    assert!(close(c.durations[0], 1.5 * 5000.0 / F, 1e-15));
    assert_eq!(c.segment(0).velocity, &[0.0]);
}

#[test]
fn single_point_has_no_segment() {
    assert!(plan(2, &[1.0, 2.0]).is_empty());
    assert!(plan(2, &[1.0, 2.0, 1.0, 2.0]).is_empty());
}

#[test]
fn lower_feed_wins_at_a_junction() {
    let mut p = Polyline::start_at(&[0.0, 0.0]);
    p.push(&[10.0, 0.0], 100.0, 1);
    p.push(&[20.0, 0.0], 40.0, 2);
    p.push(&[30.0, 0.0], 40.0, 3);
    let c = plan_contour(&p, Motion::Feed).unwrap();
    assert!(close(c.segment(0).velocity[0], 40.0, 1e-15));
}

#[test]
fn rest_point_stops_the_motion() {
    let mut p = Polyline::start_at(&[0.0, 0.0]);
    p.push(&[10.0, 0.0], F, 1);
    p.rest_at_last();
    p.push(&[20.0, 0.0], F, 2);
    let c = plan_contour(&p, Motion::Feed).unwrap();
    assert_eq!(c.segment(0).velocity, &[0.0, 0.0]);
}

#[test]
fn bad_feed_and_nan_are_errors_naming_the_line() {
    let mut p = Polyline::start_at(&[0.0]);
    p.push(&[1.0], 0.0, 7);
    assert_eq!(
        plan_contour(&p, Motion::Feed).unwrap_err(),
        PlanError::BadFeed { line: 7, feed: 0.0 }
    );
    let mut p = Polyline::start_at(&[0.0]);
    p.push(&[f64::NAN], 1.0, 9);
    let e = plan_contour(&p, Motion::Feed).unwrap_err();
    assert_eq!((e.code(), e.line()), ("pvtc::plan::non_finite_point", 9));
}

#[test]
fn segment_time_solves_the_quadratic() {
    // Constant velocity along the chord: T = |d| / v.
    let t = segment_time(&[3.0, 4.0], &[6.0, 8.0], &[6.0, 8.0], 10.0);
    assert!(close(t, 0.5, 1e-15));
    // From rest to v: seed 000's first segment.
    let t = segment_time(&[5.0], &[0.0], &[10.0], 5.0);
    let c = HermiteSegment::new(0.0, 0.0, 5.0, 10.0, t);
    assert!(close(c.at(t / 2.0).velocity, 5.0, 1e-12));
}

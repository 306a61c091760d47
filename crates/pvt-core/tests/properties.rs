//! Properties of the contour planner over random point sets, hard cases included:
//! repeated points, exact reversals, near-reversals (179.999°), collinear runs,
//! coordinates from 1e-6 to 1e6, feeds from 1e-3 to 1e5 units/min, one- and two-point
//! contours.
//!
//! The default run uses proptest's default case count; the documented long run is
//! `PROPTEST_CASES=10000 cargo test -p pvt-core --test properties --release`.

use proptest::prelude::*;
use pvt_core::{plan_contour, Motion, Polyline, PvtContour};

/// How the next point is made from the previous two.
#[derive(Debug, Clone, Copy)]
enum Step {
    Random(f64, f64),
    Repeat,
    Reverse(f64),
    NearReverse(f64),
    Collinear(f64),
}

fn step() -> impl Strategy<Value = Step> {
    prop_oneof![
        4 => (-1.0..1.0f64, -1.0..1.0f64).prop_map(|(x, y)| Step::Random(x, y)),
        1 => Just(Step::Repeat),
        1 => (0.1..2.0f64).prop_map(Step::Reverse),
        1 => (0.1..2.0f64).prop_map(Step::NearReverse),
        1 => (0.1..2.0f64).prop_map(Step::Collinear),
    ]
}

/// Points at `scale` around `origin` following `steps`.
fn points(origin: (f64, f64), scale: f64, steps: &[Step]) -> Vec<[f64; 2]> {
    let mut pts = vec![[origin.0, origin.1]];
    for s in steps {
        let p = *pts.last().unwrap();
        let d = match pts.len() {
            1 => [scale, 0.0],
            n => [p[0] - pts[n - 2][0], p[1] - pts[n - 2][1]],
        };
        let next = match *s {
            Step::Random(x, y) => [p[0] + x * scale, p[1] + y * scale],
            Step::Repeat => p,
            Step::Reverse(k) => [p[0] - k * d[0], p[1] - k * d[1]],
            Step::NearReverse(k) => {
                let a = (180.0f64 - 0.001).to_radians();
                let (s, c) = libm::sincos(a);
                [
                    p[0] + k * (c * d[0] - s * d[1]),
                    p[1] + k * (s * d[0] + c * d[1]),
                ]
            }
            Step::Collinear(k) => [p[0] + k * d[0], p[1] + k * d[1]],
        };
        pts.push(next);
    }
    pts
}

fn plan(pts: &[[f64; 2]], feed_per_min: f64) -> PvtContour {
    let feed = feed_per_min / 60.0;
    let mut poly = Polyline::start_at(&pts[0]);
    for (i, p) in pts.iter().enumerate().skip(1) {
        poly.push(p, feed, i as u32);
    }
    plan_contour(&poly, Motion::Feed).expect("finite points and a positive feed always plan")
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

fn scenario() -> impl Strategy<Value = (Vec<[f64; 2]>, f64)> {
    (
        -6.0..6.0f64,
        (-1.0..1.0f64, -1.0..1.0f64),
        prop::collection::vec(step(), 0..24),
        -3.0..5.0f64,
    )
        .prop_map(|(log_scale, (ox, oy), steps, log_feed)| {
            let scale = libm::pow(10.0, log_scale);
            let origin = (ox * scale * 10.0, oy * scale * 10.0);
            (points(origin, scale, &steps), libm::pow(10.0, log_feed))
        })
}

proptest! {
    /// Every piece is finite, takes a positive time, and its cubic ends exactly at its
    /// point with its velocity (1e-9 relative).
    #[test]
    fn pieces_end_exactly_where_they_are_told((pts, feed) in scenario()) {
        let c = plan(&pts, feed);
        let size = pts.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
        for i in 0..c.len() {
            let seg = c.segment(i);
            prop_assert!(seg.duration.is_finite() && seg.duration > 0.0, "segment {} time {}", i, seg.duration);
            prop_assert!(seg.end.iter().chain(seg.velocity).all(|x| x.is_finite()));
            let speed = norm(seg.velocity).max(feed / 60.0);
            for k in 0..2 {
                let end = c.hermite(i, k).end();
                prop_assert!((end.position - seg.end[k]).abs() <= 1e-9 * size.max(f64::MIN_POSITIVE));
                prop_assert!((end.velocity - seg.velocity[k]).abs() <= 1e-9 * speed);
            }
        }
    }

    /// Seed 000's defining property: the speed at mid-time is the mean of the end speeds
    /// (or the feed, for a piece at rest at both ends).
    #[test]
    fn mid_segment_speed_is_the_mean_of_end_speeds((pts, feed) in scenario()) {
        let c = plan(&pts, feed);
        let mut prev = 0.0;
        for i in 0..c.len() {
            let end = norm(c.segment(i).velocity);
            let t = c.durations[i] / 2.0;
            let mid: Vec<f64> = (0..2).map(|k| c.hermite(i, k).at(t).velocity).collect();
            let want = if prev == 0.0 && end == 0.0 { feed / 60.0 } else { 0.5 * (prev + end) };
            prop_assert!((norm(&mid) - want).abs() <= 1e-9 * want, "segment {}: {} vs {}", i, norm(&mid), want);
            prev = end;
        }
    }

    /// Faster feed, never more time: times scale exactly as 1/feed.
    #[test]
    fn total_time_is_monotone_in_feed((pts, feed) in scenario(), factor in 1.0..100.0f64) {
        let slow = plan(&pts, feed).total_time();
        let fast = plan(&pts, feed * factor).total_time();
        prop_assert!(fast <= slow * (1.0 + 1e-12), "{} at x{} vs {}", fast, factor, slow);
        if slow > 0.0 {
            prop_assert!((fast * factor - slow).abs() <= 1e-9 * slow);
        }
    }

    /// One point, or two equal points: no piece at all; two distinct points: one piece
    /// from rest to rest whose peak speed is the feed.
    #[test]
    fn one_and_two_point_contours(x in -1e6..1e6f64, y in -1e6..1e6f64, dx in -1e3..1e3f64, feed in 1e-3..1e5f64) {
        prop_assert!(plan(&[[x, y]], feed).is_empty());
        prop_assert!(plan(&[[x, y], [x, y]], feed).is_empty());
        let b = [x + dx, y];
        prop_assume!(b[0] != x);
        let c = plan(&[[x, y], b], feed);
        prop_assert_eq!(c.len(), 1);
        let d = (b[0] - x).abs();
        prop_assert!((c.durations[0] - 1.5 * d / (feed / 60.0)).abs() <= 1e-9 * c.durations[0]);
    }
}

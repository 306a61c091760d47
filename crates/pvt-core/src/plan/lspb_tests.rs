//! Unit tests of the LSPB planner (seed 004): blends, grids and the acceleration bound.

use super::*;

fn run(dim: usize, points: &[f64], times: &[f64]) -> TimedPoints {
    let mut r = TimedPoints::start_at(&points[..dim]);
    for (i, (p, &t)) in points.chunks(dim).skip(1).zip(times).enumerate() {
        r.push(p, t, i as u32 + 1);
    }
    r
}

/// The unquantized plan and its count of lengthened segments.
fn lspb(run: &TimedPoints, accel: f64) -> (PvtContour, usize) {
    let plan = plan_lspb(run, accel, None, Motion::Feed);
    (plan.contour, plan.raised)
}

/// Every piece is a constant-acceleration piece within the limit on every axis.
fn assert_zero_jerk_within(c: &PvtContour, accel: f64) {
    for i in 0..c.len() {
        for k in 0..c.dim {
            let h = c.hermite(i, k);
            let scale = h.a0.abs().max(accel);
            assert!(
                h.jerk.abs() * c.durations[i] <= 1e-7 * scale,
                "piece {i} axis {k}: jerk {}",
                h.jerk
            );
            assert!(
                h.a0.abs() <= accel * (1.0 + 1e-9),
                "piece {i} axis {k}: accel {}",
                h.a0
            );
        }
    }
}

#[test]
fn single_segment_is_a_trapezoid() {
    let (c, raised) = lspb(&run(1, &[0.0, 10.0], &[2.0]), 20.0);
    assert_eq!((c.len(), raised), (3, 0));
    let tb = (2.0 - 2f64.sqrt()) / 2.0;
    assert!((c.durations[0] - tb).abs() < 1e-12 && (c.durations[2] - tb).abs() < 1e-12);
    assert!((c.total_time() - 2.0).abs() < 1e-12);
    assert!((c.velocities[0] - 20.0 * tb).abs() < 1e-9);
    assert_eq!((c.ends[2], c.velocities[2]), (10.0, 0.0));
    assert_zero_jerk_within(&c, 20.0);
}

#[test]
fn corner_deviation_is_dv_tb_over_8() {
    let pts = [0.0, 0.0, 10.0, 0.0, 10.0, 10.0, 10.0, 20.0];
    let accel = 50.0;
    let (c, raised) = lspb(&run(2, &pts, &[1.0, 1.0, 1.0]), accel);
    assert_eq!(raised, 0);
    assert_zero_jerk_within(&c, accel);
    // Pieces: start blend, cruise 0, corner blend, cruise 1, blend, cruise 2, end blend.
    assert_eq!(c.len(), 7);
    let (v_in, v_out) = (
        c.segment(1).velocity.to_vec(),
        c.segment(2).velocity.to_vec(),
    );
    let tb = c.durations[2];
    let dv = [v_out[0] - v_in[0], v_out[1] - v_in[1]];
    assert!((tb - dv[0].abs().max(dv[1].abs()) / accel).abs() < 1e-12);
    let mid = [
        c.hermite(2, 0).at(tb / 2.0).position,
        c.hermite(2, 1).at(tb / 2.0).position,
    ];
    let gap = libm::hypot(mid[0] - 10.0, mid[1]);
    let expected = blend_corner_deviation(&v_in, &v_out, accel);
    assert!((gap - expected).abs() < 1e-9, "{gap} vs {expected}");
    assert!((expected - libm::hypot(dv[0], dv[1]) * tb / 8.0).abs() < 1e-12);
    assert!((c.total_time() - 3.0).abs() < 1e-12);
}

#[test]
fn cruises_follow_the_chords_in_every_axis() {
    let pts = [0.0, 0.0, 0.0, 4.0, 2.0, 1.0, 9.0, -3.0, 2.0, 12.0, 0.0, 0.0];
    let (c, _) = lspb(&run(3, &pts, &[1.0, 1.5, 1.0]), 40.0);
    // The middle segment's cruise velocity is its chord over its time.
    let cruise = c.segment(3).velocity;
    for k in 0..3 {
        assert!((cruise[k] - (pts[6 + k] - pts[3 + k]) / 1.5).abs() < 1e-12);
    }
    assert_eq!(c.segment(c.len() - 1).end, &pts[9..]);
}

#[test]
fn overlapping_blends_lengthen_the_segment() {
    // Reversals at 100 units/s with only 100 units/s²: far too short for the blends.
    let pts = [0.0, 10.0, 0.0, 10.0];
    let accel = 100.0;
    let (c, raised) = lspb(&run(1, &pts, &[0.1, 0.1, 0.1]), accel);
    assert!(raised > 0);
    assert!(c.total_time() > 0.3);
    assert!(c.durations.iter().all(|&t| t > 0.0));
    assert_zero_jerk_within(&c, accel);
    assert_eq!(
        (c.ends[c.len() - 1], c.velocities[c.len() - 1]),
        (10.0, 0.0)
    );
    // Lengthened segments keep every feasible plan feasible: planning again raises nothing.
    let single = lspb(&run(1, &[0.0, 10.0], &[0.1]), accel).0;
    assert!((single.total_time() - 2.0 * (10.0f64 / accel).sqrt()).abs() < 1e-9);
}

#[test]
fn dwell_is_a_stop() {
    let (c, raised) = lspb(&run(1, &[0.0, 0.0, 5.0, 5.0], &[0.5, 1.0, 0.5]), 100.0);
    assert_eq!(raised, 0);
    assert!((c.total_time() - 2.0).abs() < 1e-12);
    assert_zero_jerk_within(&c, 100.0);
    assert_eq!(c.ends[c.len() - 1], 5.0);
}

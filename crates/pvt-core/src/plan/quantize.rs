//! Time quantization for controllers that take whole multiples of a time unit.
//!
//! Seed 003: PMAC takes PVT piece times in whole milliseconds and silently rounds any other
//! value. Owns the rounding of piece times up to a multiple of a quantum `q` and the
//! velocities that go with the new times, and measures what that did to the speed. It
//! must not move a point: positions stay exact.
//!
//! Method:
//! - every piece time `T` becomes `T' = q·⌈T/q⌉` (up, so speeds stay at or below plan; a
//!   time already on the grid within 1e-9 of a quantum stays; never less than one `q`);
//! - PT and the velocity methods (chord, const-accel, spline) are planned again from the
//!   new times with the same method, so the result is what that method gives for them;
//! - LSPB quantizes its own blend and cruise times (see its module): stretching its
//!   constant-acceleration pieces one by one would take them above the limit;
//! - contour, path and given velocities are re-timed with [`retime`]: each piece is
//!   stretched by `k = T'/T ≥ 1` and the velocity at each point is divided by the larger
//!   stretch of the two pieces meeting there. A run of equal stretches is an exact time
//!   scaling (the same path, speed divided by `k`); velocities stay continuous because each
//!   point keeps one velocity, and lowering end velocities never makes a piece back up.
//!
//! The report is the largest relative change of the vector speed at any piece's mid-time.

use crate::program::{Interpolation, PvtContour};
use crate::vector::norm;

/// The piece time `t` rounded up to a whole, positive multiple of `quantum`.
pub fn quantize_time(t: f64, quantum: f64) -> f64 {
    let k = (t / quantum - 1e-9).ceil().max(1.0);
    k * quantum
}

/// Re-times a PVT contour onto the quantum grid as the module documentation describes.
pub fn retime(contour: &PvtContour, quantum: f64) -> PvtContour {
    let n = contour.len();
    let dim = contour.dim;
    let stretch: Vec<f64> = contour
        .durations
        .iter()
        .map(|&t| quantize_time(t, quantum) / t)
        .collect();
    let mut out = PvtContour::new(contour.motion, contour.start.clone());
    let mut v = vec![0.0; dim];
    for i in 0..n {
        let seg = contour.segment(i);
        let k = if i + 1 < n {
            stretch[i].max(stretch[i + 1])
        } else {
            stretch[i]
        };
        for (o, x) in v.iter_mut().zip(seg.velocity) {
            *o = x / k;
        }
        out.push(seg.end, &v, quantize_time(seg.duration, quantum), seg.line);
    }
    out
}

/// Vector speed at the middle of piece `i`, under the given interpolation.
pub fn mid_speed(contour: &PvtContour, i: usize, interpolation: Interpolation) -> f64 {
    match interpolation {
        Interpolation::Pt => norm(contour.segment(i).velocity),
        Interpolation::Pvt => {
            let t = contour.durations[i] / 2.0;
            let v: Vec<f64> = (0..contour.dim)
                .map(|k| contour.hermite(i, k).at(t).velocity)
                .collect();
            norm(&v)
        }
    }
}

/// Largest relative change in mid-piece speed from `before` to `after` (same pieces).
///
/// Pieces that stand still before (mid speed below 1e-12 of the contour's fastest) are left
/// out: a relative change of nothing is not defined.
pub fn mid_speed_change(
    before: &PvtContour,
    after: &PvtContour,
    interpolation: Interpolation,
) -> f64 {
    let speeds: Vec<f64> = (0..before.len())
        .map(|i| mid_speed(before, i, interpolation))
        .collect();
    let fastest = speeds.iter().fold(0.0_f64, |m, &s| m.max(s));
    let mut worst = 0.0_f64;
    for (i, &s) in speeds.iter().enumerate() {
        if s > 1e-12 * fastest && i < after.len() {
            worst = worst.max((mid_speed(after, i, interpolation) - s).abs() / s);
        }
    }
    worst
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::toolpath::Motion;

    #[test]
    fn times_round_up_to_the_grid() {
        assert_eq!(quantize_time(0.0101, 0.001), 0.011);
        assert!((quantize_time(0.003, 0.001) - 0.003).abs() < 1e-15);
        assert_eq!(quantize_time(1e-6, 0.001), 0.001);
    }

    #[test]
    fn equal_stretch_is_a_time_scaling() {
        let mut c = PvtContour::new(Motion::Feed, vec![0.0]);
        c.push(&[1.0], &[2.0], 0.75, 1);
        c.push(&[2.0], &[0.0], 0.75, 2);
        let r = retime(&c, 1.0);
        assert_eq!(r.durations, vec![1.0, 1.0]);
        assert_eq!(r.velocities, vec![1.5, 0.0]);
        let change = mid_speed_change(&c, &r, Interpolation::Pvt);
        assert!((change - 0.25).abs() < 1e-12, "{change}");
    }
}

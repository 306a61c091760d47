//! The PT planner of seed 001: constant velocity between points.
//!
//! Owns the piece velocity of position-time motion: `(X(n+1) − X(n)) / T(n)` for each
//! segment, stored as that segment's velocity (see [`crate::program::Interpolation::Pt`]).
//! It must not smooth anything: the velocity steps at every point are what PT is.

use super::timed::TimedPoints;
use crate::program::PvtContour;
use crate::toolpath::Motion;

/// The PT contour of a run: each segment carries its own constant velocity.
///
/// Passes exactly through every point at its time. Given velocities are not used: a PT
/// controller takes none.
pub fn plan_pt(run: &TimedPoints, motion: Motion) -> PvtContour {
    let dim = run.dim;
    let mut out = PvtContour::new(motion, run.point(0).to_vec());
    let mut velocity = vec![0.0; dim];
    for i in 1..run.len() {
        let t = run.durations[i - 1];
        let (from, to) = (run.point(i - 1), run.point(i));
        for k in 0..dim {
            velocity[k] = (to[k] - from[k]) / t;
        }
        out.push(to, &velocity, t, run.lines[i - 1]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn piece_velocity_is_the_chord_over_the_time() {
        let mut run = TimedPoints::start_at(&[0.0, 0.0]);
        run.push(&[5000.0, 0.0], 0.25, 1);
        run.push(&[0.0, 10000.0], 0.25, 2);
        let c = plan_pt(&run, Motion::Feed);
        assert_eq!(c.velocities, vec![20000.0, 0.0, -20000.0, 40000.0]);
        assert_eq!(c.ends, vec![5000.0, 0.0, 0.0, 10000.0]);
    }
}

//! The constant-acceleration velocity method of seed 001 (method 2).
//!
//! Owns the recurrence `V(n+1) = (2/T(n))·(X(n+1) − X(n) − V(n)·T(n)) + V(n)` from
//! `V(0) = 0`: each segment is a zero-jerk (constant acceleration) piece given the velocity
//! the previous one ended with. The recurrence does not end at rest in general; pvtc sets
//! the last point's velocity to 0, so the last segment is the one piece that is not a
//! constant-acceleration piece (a cubic from `V(N−1)` to rest), rather than adding seed
//! 001's extra final point (which would overshoot the last point and come back). It is
//! known to oscillate (velocities alternate about the chord velocity); it must not damp that.

use super::timed::TimedPoints;

/// Seed 001's constant-acceleration fit at every point of a run, last velocity 0.
pub fn const_accel_velocities(run: &TimedPoints) -> Vec<f64> {
    let (dim, n) = (run.dim, run.len());
    let mut v = vec![0.0; n * dim];
    for j in 0..n.saturating_sub(2) {
        let (here, next, t) = (run.point(j), run.point(j + 1), run.durations[j]);
        for k in 0..dim {
            let vn = v[j * dim + k];
            v[(j + 1) * dim + k] = (2.0 / t) * (next[k] - here[k] - vn * t) + vn;
        }
    }
    v
}

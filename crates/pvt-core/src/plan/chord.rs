//! The chord velocity methods: forward and backward differences.
//!
//! Owns the two rules "the velocity at a point is a chord's difference quotient", with
//! points `X(0)..X(N)` and segment times `T(0)..T(N−1)`, rest at both ends
//! (`V(0) = V(N) = 0`):
//!
//! - forward (`chord-forward`, alias `chord`): `V(j) = (X(j+1) − X(j)) / T(j)` for
//!   `0 < j < N`, the outgoing chord. This is exactly the quad-circle MovePVT example
//!   (seed 002: `vel[i] = (position[i+1] − position[i]) / TIME_SLICE`, last velocity set
//!   to 0), whose arrays start at the first point after the start position.
//! - backward (`chord-back`): `V(j) = (X(j) − X(j−1)) / T(j−1)` for `0 < j < N`, the
//!   incoming chord: application note AN208's method 1 (seed 001),
//!   `V(n+1) = (X(n+1) − X(n)) / T(n)`. AN208 adds "an extra final point, setting the last
//!   velocity to zero"; pvtc sets the last point's velocity to zero, which is that extra
//!   point when the series repeats its last point (as AN208's test tables do), and stops at
//!   the last point without overshoot otherwise.
//!
//! It must not change positions or times.

use super::timed::TimedPoints;

/// AN208's backward-difference velocity at every point of a run, flat like its coords.
pub fn chord_back_velocities(run: &TimedPoints) -> Vec<f64> {
    let (dim, n) = (run.dim, run.len());
    let mut v = vec![0.0; n * dim];
    for j in 1..n.saturating_sub(1) {
        let (before, here) = (run.point(j - 1), run.point(j));
        for k in 0..dim {
            v[j * dim + k] = (here[k] - before[k]) / run.durations[j - 1];
        }
    }
    v
}

/// Seed 002's forward-difference velocity at every point of a run, flat like its coords.
pub fn chord_velocities(run: &TimedPoints) -> Vec<f64> {
    let (dim, n) = (run.dim, run.len());
    let mut v = vec![0.0; n * dim];
    for j in 1..n.saturating_sub(1) {
        let (here, next) = (run.point(j), run.point(j + 1));
        for k in 0..dim {
            v[j * dim + k] = (next[k] - here[k]) / run.durations[j];
        }
    }
    v
}

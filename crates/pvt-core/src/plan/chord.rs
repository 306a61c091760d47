//! The chord velocity method: seed 002's forward difference.
//!
//! Owns the rule "the velocity at a point is its outgoing chord's difference quotient":
//! with points `X(0)..X(N)` and segment times `T(0)..T(N−1)`,
//! `V(j) = (X(j+1) − X(j)) / T(j)` for `0 < j < N`, and `V(0) = V(N) = 0` (rest at both ends).
//!
//! This is exactly the quad-circle code of seed 002 (`vel[i] = (position[i+1] −
//! position[i]) / TIME_SLICE`, last velocity set to 0), whose arrays start at the first
//! point after the start position. Seed 001 prints the same formula as
//! `V(n+1) = (X(n+1) − X(n)) / T(n)`, i.e. the *incoming* chord's quotient, and then needs an
//! extra final point to come to rest; pvtc implements seed 002's indexing, which ends at
//! the last point at rest without an extra point and without overshoot. It must not change
//! positions or times.

use super::timed::TimedPoints;

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

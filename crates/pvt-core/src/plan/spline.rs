//! The spline velocity method: velocities of the C2 cubic spline through the points.
//!
//! Owns the clamped cubic spline with the given knot times: it passes exactly through
//! every point, starts and ends at rest, and its acceleration is continuous at every
//! interior point. Equal accelerations on both sides of interior point `i` give, with
//! segment times `h` and chords `d`,
//!
//! ```text
//! V(i−1)/h(i−1) + 2·V(i)·(1/h(i−1) + 1/h(i)) + V(i+1)/h(i) = 3·(d(i−1)/h(i−1)² + d(i)/h(i)²)
//! ```
//!
//! a strictly diagonally dominant tridiagonal system solved exactly by the Thomas
//! algorithm (one factorization, one sweep per axis). It is the shape PMAC's SPLINE modes
//! aim at (seed 003) but through the points, not inside them. It must not change times.

use super::timed::TimedPoints;

/// Velocities of the clamped C2 cubic spline through a run's points, flat like its coords.
pub fn spline_velocities(run: &TimedPoints) -> Vec<f64> {
    let (dim, n) = (run.dim, run.len());
    let mut v = vec![0.0; n * dim];
    if n < 3 {
        return v;
    }
    let h = &run.durations;
    // Forward elimination of the matrix, shared by every axis: c'(i) and the pivots.
    let m = n - 2;
    let mut upper = vec![0.0; m];
    let mut pivot = vec![0.0; m];
    for r in 0..m {
        let i = r + 1;
        let diag = 2.0 * (1.0 / h[i - 1] + 1.0 / h[i]);
        let below = if r == 0 { 0.0 } else { 1.0 / h[i - 1] };
        let prev_upper = if r == 0 { 0.0 } else { upper[r - 1] };
        pivot[r] = diag - below * prev_upper;
        upper[r] = if i + 1 < n - 1 {
            (1.0 / h[i]) / pivot[r]
        } else {
            0.0
        };
    }
    let mut rhs = vec![0.0; m];
    for k in 0..dim {
        for r in 0..m {
            let i = r + 1;
            let d0 = run.point(i)[k] - run.point(i - 1)[k];
            let d1 = run.point(i + 1)[k] - run.point(i)[k];
            let b = 3.0 * (d0 / (h[i - 1] * h[i - 1]) + d1 / (h[i] * h[i]));
            let below = if r == 0 { 0.0 } else { 1.0 / h[i - 1] };
            let prev = if r == 0 { 0.0 } else { rhs[r - 1] };
            rhs[r] = (b - below * prev) / pivot[r];
        }
        let mut next = 0.0;
        for r in (0..m).rev() {
            let vi = rhs[r] - upper[r] * next;
            v[(r + 1) * dim + k] = vi;
            next = vi;
        }
    }
    v
}

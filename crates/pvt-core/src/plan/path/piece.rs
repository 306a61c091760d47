//! One piece of a planned contour: its end states, time, error bound and cubics.
//!
//! Owns the [`Piece`] value (start and end points and velocities, time, error bound, the
//! knot it starts from, its S-curve part) and what follows from it alone: each axis'
//! cubic, its end accelerations and the closed-form per-axis peaks that limits are
//! checked against. It must not build pieces from knots or move knots: that is
//! [`super::pieces`] and [`super::knots`], which both read this one.

use super::{AxisBounds, Vector};
use crate::hermite::HermiteSegment;

/// One piece, ready to emit.
#[derive(Debug, Clone)]
pub(super) struct Piece {
    pub start: Vector,
    pub end: Vector,
    pub start_velocity: Vector,
    pub end_velocity: Vector,
    /// Seconds.
    pub duration: f64,
    /// Bound on the distance between the cubic and the programmed point, program units.
    pub error: f64,
    /// The knot the piece starts from (the piece of an S-curve's part).
    pub knot: usize,
    /// Where on its knot's piece an S-curve part runs (jerk mode); `None` for a whole piece.
    pub part: Option<Part>,
}

/// One part of a piece's S-curve (jerk mode): its parameters and parameter rates at both
/// ends, and which end is a knot (the other is inside the S-curve).
#[derive(Debug, Clone, Copy)]
pub(super) struct Part {
    pub params: [f64; 2],
    pub rates: [f64; 2],
    pub at_knot: [bool; 2],
}

impl Piece {
    /// The piece after knot `k` in `dim` axes with every state, time and error zero: the
    /// start its builders fill in.
    pub fn zeroed(dim: usize, knot: usize) -> Piece {
        Piece {
            start: Vector::zeros(dim),
            end: Vector::zeros(dim),
            start_velocity: Vector::zeros(dim),
            end_velocity: Vector::zeros(dim),
            duration: 0.0,
            error: 0.0,
            knot,
            part: None,
        }
    }

    /// Each axis' acceleration at the start and at the end of the cubic.
    pub fn end_accelerations(&self) -> [Vector; 2] {
        let n = self.start.len();
        let (mut start, mut end) = (Vector::zeros(n), Vector::zeros(n));
        for (i, (a0, a1)) in start.iter_mut().zip(end.iter_mut()).enumerate() {
            let h = self.cubic(i);
            (*a0, *a1) = (h.a0, h.end().acceleration);
        }
        [start, end]
    }

    /// The cubic of axis `i`: from its start to its end state over the piece's time.
    #[inline]
    pub fn cubic(&self, i: usize) -> HermiteSegment {
        HermiteSegment::new(
            self.start[i],
            self.start_velocity[i],
            self.end[i],
            self.end_velocity[i],
            self.duration,
        )
    }

    /// True when the piece starts and ends at rest.
    pub fn at_rest(&self) -> bool {
        self.start_velocity
            .iter()
            .chain(&self.end_velocity)
            .all(|v| *v == 0.0)
    }

    /// 1 when every axis' closed-form velocity and acceleration peaks and its jerk are
    /// within its limits; otherwise the factor by which the piece's speeds should shrink.
    pub fn limit_factor(&self, bounds: &AxisBounds) -> f64 {
        let mut factor: f64 = 1.0;
        for i in 0..self.start.len() {
            let (vmax, amax, jmax) = (bounds.velocity[i], bounds.acceleration[i], bounds.jerk[i]);
            if vmax == f64::INFINITY && amax == f64::INFINITY && jmax == f64::INFINITY {
                // No limit on the axis: no peak of its cubic can be over one.
                continue;
            }
            let h = self.cubic(i);
            let (velocity, acceleration) = peaks(&h);
            if velocity > vmax * (1.0 + 1e-9) {
                factor = factor.min(vmax / velocity);
            }
            if acceleration > amax * (1.0 + 1e-9) {
                factor = factor.min((amax / acceleration).sqrt());
            }
            let jerk = h.jerk.abs();
            if jerk > jmax * (1.0 + 1e-9) {
                factor = factor.min(libm::cbrt(jmax / jerk));
            }
        }
        factor
    }
}

/// Largest |velocity| and |acceleration| of a cubic: the velocity at an end or where the
/// acceleration vanishes inside, the acceleration at an end.
fn peaks(h: &HermiteSegment) -> (f64, f64) {
    let end = h.end();
    let mut velocity = h.v0.abs().max(end.velocity.abs());
    if h.jerk != 0.0 {
        let t = -h.a0 / h.jerk;
        if t > 0.0 && t < h.duration {
            velocity = velocity.max(h.at(t).velocity.abs());
        }
    }
    (velocity, h.a0.abs().max(end.acceleration.abs()))
}

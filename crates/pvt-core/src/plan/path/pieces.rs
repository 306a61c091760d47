//! The pieces between knots: their cubic's end conditions, time and error bound.
//!
//! Owns the piece time from the reference motion (constant parameter acceleration), the
//! per-piece error bound of the module documentation, and the closed-form per-axis peaks
//! that limits are checked against. It must not move knots or change speeds.

use super::curve::Curve;
use super::knots::Knots;
use super::AxisBounds;
use crate::hermite::HermiteSegment;

/// One piece, ready to emit.
#[derive(Debug, Clone)]
pub(super) struct Piece {
    pub start: Vec<f64>,
    pub end: Vec<f64>,
    pub start_velocity: Vec<f64>,
    pub end_velocity: Vec<f64>,
    /// Seconds.
    pub duration: f64,
    /// Bound on the distance between the cubic and the programmed point, program units.
    pub error: f64,
}

impl Knots {
    /// The piece between every two consecutive knots.
    pub fn pieces(&self, curves: &[Curve], bounds: &AxisBounds) -> Vec<Piece> {
        (0..self.knots.len() - 1)
            .map(|k| self.piece(curves, bounds, k))
            .collect()
    }

    fn piece(&self, curves: &[Curve], bounds: &AxisBounds, k: usize) -> Piece {
        if let Some(j) = self.knots[k].blend {
            return self.blend_piece(curves, k, j);
        }
        let (curve, from, to) = self.piece_span(curves, k);
        let dim = curve.start.len();
        let (a, b) = (&self.knots[k], &self.knots[k + 1]);
        let mut piece = Piece {
            start: vec![0.0; dim],
            end: vec![0.0; dim],
            start_velocity: vec![0.0; dim],
            end_velocity: vec![0.0; dim],
            duration: 0.0,
            error: 0.0,
        };
        curve.position(from, &mut piece.start);
        curve.position(to, &mut piece.end);
        self.velocity(k, curve, from, &mut piece.start_velocity);
        self.velocity(k + 1, curve, to, &mut piece.end_velocity);
        let (wa, wb) = (a.speed / curve.rate(from), b.speed / curve.rate(to));
        let span = to - from;
        if wa + wb > 0.0 {
            piece.duration = 2.0 * span / (wa + wb);
            let [d2, d3, d4] = curve.derivative_bounds();
            let (t, w) = (piece.duration, wa.max(wb));
            let dw = (wb - wa).abs() / t;
            let bend =
                t.powi(4) / 384.0 * (d4 * w.powi(4) + 6.0 * d3 * w * w * dw + 3.0 * d2 * dw * dw);
            let mismatch = |speed: f64, junction: Option<usize>| {
                junction.map_or(0.0, |j| speed * self.junctions[j].deviation)
            };
            let turn =
                4.0 / 27.0 * t * (mismatch(a.speed, a.junction) + mismatch(b.speed, b.junction));
            piece.error = bend + turn;
        } else {
            // At rest at both ends: the smoothstep along the chord, peaking at the cap.
            let cap = super::knots::speed_cap(curve, from, to, bounds);
            piece.duration = 1.5 * curve.length(from, to) / cap;
            piece.error = if curve.is_line() { 0.0 } else { f64::INFINITY };
        }
        piece
    }
}

impl Knots {
    /// The corner blend after knot `k`: from the first line at L before the corner to
    /// the second at L after it, velocities along each line, time from
    /// [`blend_time`], so both inner control points lie on the lines within L of the
    /// corner and the cubic stays inside the triangle they span with the corner. Its farthest
    /// point from the two lines is no farther than its midpoint is from the corner,
    /// at most L·sin(α/2), which is also how far the corner is from the motion.
    fn blend_piece(&self, curves: &[Curve], k: usize, j: usize) -> Piece {
        let junction = &self.junctions[j];
        let l = junction.blend.unwrap_or(0.0);
        let e = self.knots[k].after.element;
        let (a, b) = (&curves[e], &curves[e + 1]);
        let dim = a.start.len();
        let mut start = vec![0.0; dim];
        let mut end = vec![0.0; dim];
        a.position(a.span - l, &mut start);
        b.position(l, &mut end);
        let (va, vb) = (self.knots[k].speed, self.knots[k + 1].speed);
        let scaled = |t: &[f64], v: f64| t.iter().map(|x| x * v).collect::<Vec<f64>>();
        Piece {
            start,
            end,
            start_velocity: scaled(&junction.tangents[0], va),
            end_velocity: scaled(&junction.tangents[1], vb),
            duration: blend_time(l, va, vb),
            error: l * junction.half_turn_sin,
        }
    }
}

/// Time of a blend of half-length `l` from speed `va` to `vb`: 4L/(va + vb), the
/// constant-acceleration time over its 2L, while that keeps each inner control point
/// within L of the corner (the faster end at most three times the slower); else 3L over
/// the faster speed, which puts that control point at the corner.
fn blend_time(l: f64, va: f64, vb: f64) -> f64 {
    let (slow, fast) = (va.min(vb), va.max(vb));
    if fast <= 3.0 * slow {
        4.0 * l / (va + vb)
    } else {
        3.0 * l / fast
    }
}

impl Piece {
    /// True when the piece starts and ends at rest.
    pub fn at_rest(&self) -> bool {
        self.start_velocity
            .iter()
            .chain(&self.end_velocity)
            .all(|v| *v == 0.0)
    }

    /// 1 when every axis' closed-form velocity and acceleration peaks are within its
    /// limits; otherwise the factor by which the piece's speeds should shrink.
    pub fn limit_factor(&self, bounds: &AxisBounds) -> f64 {
        let mut factor: f64 = 1.0;
        for i in 0..self.start.len() {
            let h = HermiteSegment::new(
                self.start[i],
                self.start_velocity[i],
                self.end[i],
                self.end_velocity[i],
                self.duration,
            );
            let (velocity, acceleration) = peaks(&h);
            let (vmax, amax) = (bounds.velocity[i], bounds.acceleration[i]);
            if velocity > vmax * (1.0 + 1e-9) {
                factor = factor.min(vmax / velocity);
            }
            if acceleration > amax * (1.0 + 1e-9) {
                factor = factor.min((amax / acceleration).sqrt());
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

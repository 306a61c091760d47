//! The pieces between knots: their cubic's end conditions, time and error bound.
//!
//! Owns the piece time from the reference motion (constant parameter acceleration), the
//! per-piece error bound of the module documentation, and the closed-form per-axis peaks
//! that limits are checked against, and the same pieces on a quantum grid. It must not
//! move knots or change speeds.

use super::curve::Curve;
use super::knots::Knots;
use super::{AxisBounds, Vector};
use crate::hermite::HermiteSegment;
use crate::plan::quantize::{quanta_time, Quantum};

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
            start: Vector::zeros(dim),
            end: Vector::zeros(dim),
            start_velocity: Vector::zeros(dim),
            end_velocity: Vector::zeros(dim),
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
    /// corner; its error is [`blend_error`].
    fn blend_piece(&self, curves: &[Curve], k: usize, j: usize) -> Piece {
        let junction = &self.junctions[j];
        let l = junction.blend.unwrap_or(0.0);
        let e = self.knots[k].after.element;
        let (a, b) = (&curves[e], &curves[e + 1]);
        let dim = a.start.len();
        let mut start = Vector::zeros(dim);
        let mut end = Vector::zeros(dim);
        a.position(a.span - l, &mut start);
        b.position(l, &mut end);
        let (va, vb) = (self.knots[k].speed, self.knots[k + 1].speed);
        let scaled = |t: &[f64], v: f64| Vector::from_fn(t.len(), |i| t[i] * v);
        let duration = blend_time(l, va, vb);
        Piece {
            start,
            end,
            start_velocity: scaled(&junction.tangents[0], va),
            end_velocity: scaled(&junction.tangents[1], vb),
            duration,
            error: blend_error(
                l,
                va * duration / 3.0,
                vb * duration / 3.0,
                junction.half_turn_sin,
            ),
        }
    }
}

/// How far a corner blend of half-length `l` whose inner control points lie `da` and
/// `db` from its ends (towards the corner C, both at most `l`) can be from the two lines
/// and how far C can be from it.
///
/// With unit tangents t₁, t₂ and turning angle α, the blend is
/// `B(u) − C = −A(u)·t₁ + E(u)·t₂`, `A(u) = (1−u)³l + 3u(1−u)²(l − da)` falling from l to
/// 0 and `E(u) = 3u²(1−u)(l − db) + u³l` rising from 0 to l. Its distance from the first
/// line is `E·sin α` and from the second `A·sin α` (whichever foot lies on its line; one
/// does), so at most `min(A, E)·sin α`; and C is at most `|B(u*) − C| = 2·A(u*)·sin(α/2)`
/// from it, where A and E cross at u*. Both are at most `2·A(u*)·sin(α/2)`; at equal end
/// speeds (da = db = 2l/3) `A(u*) = l/4`, so `l·sin(α/2)/2`.
fn blend_error(l: f64, da: f64, db: f64, half_turn_sin: f64) -> f64 {
    let (a, e) = ((l - da).clamp(0.0, l), (l - db).clamp(0.0, l));
    let first = |u: f64| (1.0 - u).powi(3) * l + 3.0 * u * (1.0 - u).powi(2) * a;
    let second = |u: f64| 3.0 * u * u * (1.0 - u) * e + u.powi(3) * l;
    let (mut lo, mut hi) = (0.0_f64, 1.0_f64);
    for _ in 0..64 {
        let mid = 0.5 * (lo + hi);
        if first(mid) >= second(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    // min(A, E) ≤ A(lo) everywhere: E ≤ E(lo) ≤ A(lo) left of lo, A ≤ A(lo) right of it.
    // Whatever da and db, the blend stays in the triangle of its ends and C, within
    // l·sin(α/2) of both lines and of C.
    (2.0 * first(lo)).min(l) * half_turn_sin
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

    /// 1 when every axis' closed-form velocity and acceleration peaks and its jerk are
    /// within its limits; otherwise the factor by which the piece's speeds should shrink.
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
            let (jerk, jmax) = (h.jerk.abs(), bounds.jerk[i]);
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

/// Most rounds of lengthening pieces on the grid before the planner lowers speeds instead.
const GRID_ROUNDS: usize = 64;

/// Pieces on a time grid.
#[derive(Debug, Clone)]
pub(super) struct Grid {
    pub pieces: Vec<Piece>,
}

impl Knots {
    /// The pieces on the quantum grid (see the module documentation of [`super`],
    /// "Quantization"): each piece gets whole quanta, at first as the grid rounds its
    /// planned time, and each knot's velocity is divided by the larger stretch of its two
    /// pieces (the first knot, whose velocity is already written, by 1). A piece whose
    /// closed-form peaks then exceed a limit gets more quanta, up to [`GRID_ROUNDS`]
    /// rounds; each piece's error bound is recomputed for its new reference motion.
    pub fn on_grid(
        &self,
        curves: &[Curve],
        bounds: &AxisBounds,
        pieces: &[Piece],
        quantum: Quantum,
    ) -> Grid {
        let mut counts: Vec<f64> = pieces
            .iter()
            .map(|p| quantum.count(p.duration).max(1.0))
            .collect();
        let mut grid = self.grid_pieces(curves, pieces, &counts, quantum.seconds);
        for _ in 0..GRID_ROUNDS {
            let mut raised = false;
            for (count, piece) in counts.iter_mut().zip(&grid.pieces) {
                let factor = piece.limit_factor(bounds);
                if factor < 1.0 {
                    *count = (*count / factor).ceil().max(*count + 1.0);
                    raised = true;
                }
            }
            if !raised {
                break;
            }
            grid = self.grid_pieces(curves, pieces, &counts, quantum.seconds);
        }
        grid
    }

    /// The pieces with `counts[i]` quanta each and the knot velocities divided by the
    /// larger stretch beside them.
    fn grid_pieces(&self, curves: &[Curve], pieces: &[Piece], counts: &[f64], q: f64) -> Grid {
        let n = pieces.len();
        let times: Vec<f64> = counts.iter().map(|&k| quanta_time(k, q)).collect();
        let stretch: Vec<f64> = times
            .iter()
            .zip(pieces)
            .map(|(t, p)| t / p.duration)
            .collect();
        let mut scale = vec![1.0; n + 1];
        for j in 1..=n {
            scale[j] = if j == n {
                stretch[n - 1]
            } else {
                stretch[j - 1].max(stretch[j])
            };
        }

        let pieces = pieces
            .iter()
            .enumerate()
            .map(|(k, p)| self.grid_piece(curves, p, k, times[k], [scale[k], scale[k + 1]]))
            .collect();
        Grid { pieces }
    }

    /// Piece `k` in time `t` with its end velocities divided by `scale`, and its error
    /// bound for the reference motion φ(t) that is the cubic in the parameter from the
    /// knots' new parameter rates (see "Quantization" in [`super`]).
    fn grid_piece(&self, curves: &[Curve], p: &Piece, k: usize, t: f64, scale: [f64; 2]) -> Piece {
        let divide = |v: &[f64], s: f64| Vector::from_fn(v.len(), |i| v[i] / s);
        let mut piece = Piece {
            start: p.start,
            end: p.end,
            start_velocity: divide(&p.start_velocity, scale[0]),
            end_velocity: divide(&p.end_velocity, scale[1]),
            duration: t,
            error: p.error,
        };
        if let Some(j) = self.knots[k].blend {
            // The inner control points move towards the ends (scale ≥ stretch): within
            // the triangle bound, which sizes blends on a grid.
            let l = self.junctions[j].blend.unwrap_or(0.0);
            let offset = |v: &[f64]| crate::vector::norm(v) * t / 3.0;
            let (da, db) = (offset(&piece.start_velocity), offset(&piece.end_velocity));
            piece.error = blend_error(l, da, db, self.junctions[j].half_turn_sin);
            return piece;
        }
        if p.at_rest() {
            // A slower smoothstep on the same chord.
            return piece;
        }
        let (curve, from, to) = self.piece_span(curves, k);
        let (a, b) = (&self.knots[k], &self.knots[k + 1]);
        let (wa, wb) = (
            a.speed / (scale[0] * curve.rate(from)),
            b.speed / (scale[1] * curve.rate(to)),
        );
        let phi = HermiteSegment::new(from, wa, to, wb, t);
        let (rate, accel, slowest) = parameter_peaks(&phi);
        if slowest < 0.0 {
            // φ would leave the piece's parameter range (not with K ≥ k).
            piece.error = f64::INFINITY;
            return piece;
        }
        let [d2, d3, d4] = curve.derivative_bounds();
        let jerk = phi.jerk.abs();
        let bend = t.powi(4) / 384.0
            * (d4 * rate.powi(4)
                + 6.0 * d3 * rate * rate * accel
                + 3.0 * d2 * accel * accel
                + 4.0 * d2 * rate * jerk);
        let mismatch = |speed: f64, junction: Option<usize>, s: f64| {
            junction.map_or(0.0, |j| speed * self.junctions[j].deviation / s)
        };
        let turn = 4.0 / 27.0
            * t
            * (mismatch(a.speed, a.junction, scale[0]) + mismatch(b.speed, b.junction, scale[1]));
        piece.error = bend + turn;
        piece
    }
}

/// Largest |φ'| and |φ''| of a cubic parameter motion, and its least φ'.
fn parameter_peaks(phi: &HermiteSegment) -> (f64, f64, f64) {
    let end = phi.end();
    let (mut fastest, mut slowest) = (phi.v0.max(end.velocity), phi.v0.min(end.velocity));
    if phi.jerk != 0.0 {
        let t = -phi.a0 / phi.jerk;
        if t > 0.0 && t < phi.duration {
            let v = phi.at(t).velocity;
            fastest = fastest.max(v);
            slowest = slowest.min(v);
        }
    }
    (
        fastest.max(-slowest),
        phi.a0.abs().max(end.acceleration.abs()),
        slowest,
    )
}

/// Largest relative change of the vector speed at mid-piece from `before` to `after`
/// (pieces that stand still at mid-piece left out).
pub(super) fn mid_speed_change(before: &[Piece], after: &[Piece]) -> f64 {
    let mid = |p: &Piece| {
        let v = Vector::from_fn(p.start.len(), |i| {
            HermiteSegment::new(
                p.start[i],
                p.start_velocity[i],
                p.end[i],
                p.end_velocity[i],
                p.duration,
            )
            .at(p.duration / 2.0)
            .velocity
        });
        crate::vector::norm(&v)
    };
    before
        .iter()
        .zip(after)
        .map(|(b, a)| (mid(b), mid(a)))
        .filter(|(b, _)| *b > 1e-12)
        .map(|(b, a)| (a - b).abs() / b)
        .fold(0.0, f64::max)
}

#[cfg(test)]
// std's trigonometry on purpose: the check is independent of the planner's libm.
#[allow(clippy::disallowed_methods)]
mod tests {
    use super::blend_error;

    /// Pieces, curves and junctions own no heap memory (nothing to drop): the planner
    /// makes several pieces per element in every round of every window.
    #[test]
    fn planner_values_hold_no_heap_memory() {
        use std::mem::needs_drop;
        assert!(!needs_drop::<super::Piece>());
        assert!(!needs_drop::<super::super::curve::Curve>());
        assert!(!needs_drop::<super::super::knots::Junction>());
        assert!(!needs_drop::<super::super::knots::Start>());
    }

    /// Distance from `p` to the ray from the origin along `t` (unit).
    fn to_ray(p: [f64; 2], t: [f64; 2]) -> f64 {
        let along = (p[0] * t[0] + p[1] * t[1]).max(0.0);
        (p[0] - along * t[0]).hypot(p[1] - along * t[1])
    }

    /// The blend bound against the cubic sampled densely: its distance from the two
    /// lines and the corner's distance from it, for turns from 10° to 170° and inner
    /// control points anywhere within L of the ends.
    #[test]
    fn blend_bound_holds_and_is_tight_at_equal_speeds() {
        let l = 1.0;
        for degrees in [10.0f64, 45.0, 90.0, 135.0, 170.0] {
            let alpha = degrees.to_radians();
            // Corner at the origin; arrive along +x, leave turned by α.
            let t1 = [1.0, 0.0];
            let t2 = [alpha.cos(), alpha.sin()];
            let half = (alpha / 2.0).sin();
            for i in 0..=6 {
                for j in 0..=6 {
                    let (da, db) = (l * i as f64 / 6.0, l * j as f64 / 6.0);
                    let p = [
                        [-l * t1[0], -l * t1[1]],
                        [-(l - da) * t1[0], -(l - da) * t1[1]],
                        [(l - db) * t2[0], (l - db) * t2[1]],
                        [l * t2[0], l * t2[1]],
                    ];
                    let (mut far, mut near) = (0.0f64, f64::INFINITY);
                    for s in 0..=4000 {
                        let u = s as f64 / 4000.0;
                        let w = [
                            (1.0 - u).powi(3),
                            3.0 * u * (1.0 - u).powi(2),
                            3.0 * u * u * (1.0 - u),
                            u.powi(3),
                        ];
                        let b = [0, 1].map(|k| (0..4).map(|m| w[m] * p[m][k]).sum::<f64>());
                        // The incoming line is the ray from the corner along −t1.
                        let lines = to_ray(b, [-t1[0], -t1[1]]).min(to_ray(b, t2));
                        far = far.max(lines);
                        near = near.min(b[0].hypot(b[1]));
                    }
                    let bound = blend_error(l, da, db, half);
                    assert!(
                        far <= bound * (1.0 + 1e-9),
                        "lines: {degrees}° {da} {db}: {far} > {bound}"
                    );
                    // The corner's bound is its distance at one instant, which the
                    // samples straddle: 1e-4 covers their spacing.
                    assert!(
                        near <= bound * (1.0 + 1e-4),
                        "corner: {degrees}° {da} {db}: {near} > {bound}"
                    );
                }
            }
            let equal = blend_error(l, 2.0 * l / 3.0, 2.0 * l / 3.0, half);
            assert!((equal - l * half / 2.0).abs() < 1e-12, "{equal}");
        }
    }
}

//! Closed-form peaks of |velocity|, |acceleration| and |jerk| of every piece, and the
//! acceleration step at every knot.
//!
//! A PVT piece is a cubic: its velocity is a parabola that peaks at an end or where the
//! acceleration is zero inside (`t* = −A/J`), its acceleration is linear so it peaks at an
//! end, and its jerk is constant. Pieces meet in position and velocity, not acceleration:
//! at a knot the acceleration steps by `Δa = a(0) of the next − a(T) of the previous`
//! (each end's acceleration in closed form from the piece's P, V and T). Where the
//! machine rests (the program's start and end, a dwell, a pause, a tool change) the
//! acceleration on the rest side is 0; a contour that follows the previous one straight
//! on (nothing or only spindle, coolant or message events between) steps once, from the
//! previous contour's last piece into its first. A servo loop spreads a step over one servo period `P`, so it is
//! reported as the jerk the loop sees, `|Δa|/P`, at the knot's time. A PT piece has
//! constant velocity; its velocity steps at the points have no finite acceleration, so
//! pvtc reports each step `ΔV` as the servo loop sees it, spread over one servo period:
//! acceleration `|ΔV|/P` and jerk `|ΔV|/P²`, at the point's time; that acceleration
//! rises from 0 and falls back within the period, so its step is `|ΔV|/P` and the
//! acceleration step reported is `|ΔV|/P²`, the same number as the jerk. It must not
//! sample: that is [`super::servo`].

use super::timeline::{Piece, Timeline};
use super::{Peak, Quantity};

/// The accelerations at the start and the end of a PVT piece on axis column `k`, each in
/// closed form from the piece's ends: `a(0) = (6Δp − 4v₀T − 2v₁T)/T²` and
/// `a(T) = (−6Δp + 2v₀T + 4v₁T)/T²`.
pub(super) fn end_accelerations(tl: &Timeline<'_>, p: &Piece, k: usize) -> (f64, f64) {
    let h = tl.cubic(p, k);
    let end = tl.position(p, k, p.duration);
    let v1 = tl.end_velocity(p, k);
    let (d, t) = (end - h.p0, p.duration);
    let start = (6.0 * d - (4.0 * h.v0 + 2.0 * v1) * t) / (t * t);
    let finish = (-6.0 * d + (2.0 * h.v0 + 4.0 * v1) * t) / (t * t);
    (start, finish)
}

/// The peaks of one axis over one piece (or one PT point), each with its absolute time;
/// the acceleration step is the one into the piece (from rest into a contour's first).
pub(super) fn piece_peaks(
    tl: &Timeline<'_>,
    i: usize,
    k: usize,
    period: f64,
) -> [(Quantity, Peak); 4] {
    let p = &tl.pieces[i];
    let at = |value: f64, t: f64| Peak {
        value,
        time: p.start + t,
        line: p.line,
    };
    if tl.is_pt() {
        let v = tl.cubic(p, k).v0;
        let before = if p.index == 0 {
            0.0
        } else {
            tl.cubic(&tl.pieces[i - 1], k).v0
        };
        let step = (v - before).abs();
        return [
            (Quantity::Velocity, at(v.abs(), 0.0)),
            (Quantity::Acceleration, at(step / period, 0.0)),
            (Quantity::Jerk, at(step / (period * period), 0.0)),
            (
                Quantity::AccelerationStep,
                at(step / (period * period), 0.0),
            ),
        ];
    }
    let h = tl.cubic(p, k);
    let t_end = p.duration;
    let mut v = at(h.v0.abs(), 0.0);
    let end = h.at(t_end);
    if end.velocity.abs() > v.value {
        v = at(end.velocity.abs(), t_end);
    }
    if h.jerk != 0.0 {
        let t_star = -h.a0 / h.jerk;
        if t_star > 0.0 && t_star < t_end {
            let inside = h.at(t_star).velocity.abs();
            if inside > v.value {
                v = at(inside, t_star);
            }
        }
    }
    let a = if end.acceleration.abs() > h.a0.abs() {
        at(end.acceleration.abs(), t_end)
    } else {
        at(h.a0.abs(), 0.0)
    };
    // From rest, or from the piece before: in this contour, or the last of a contour
    // this one follows straight on (one step there, not two against rest).
    let before = if p.index == 0 && tl.rests_before(p.contour) {
        0.0
    } else {
        end_accelerations(tl, &tl.pieces[i - 1], k).1
    };
    let step = (end_accelerations(tl, p, k).0 - before).abs();
    [
        (Quantity::Velocity, v),
        (Quantity::Acceleration, a),
        (Quantity::Jerk, at(h.jerk.abs(), 0.0)),
        (Quantity::AccelerationStep, at(step / period, 0.0)),
    ]
}

/// The step to rest after the last piece of a contour, as peaks at its end time: PT, the
/// velocity step (acceleration, jerk and acceleration step as at a point); PVT, the
/// acceleration step from the piece's end acceleration to 0.
pub(super) fn stop(
    tl: &Timeline<'_>,
    p: &Piece,
    k: usize,
    period: f64,
) -> impl Iterator<Item = (Quantity, Peak)> {
    // A PVT contour followed straight on by another steps once, into that one's first
    // piece (see `piece_peaks`); at rest, or at the program's end, it steps to rest.
    let last = tl.program.contours[p.contour].len() == p.index + 1
        && (tl.is_pt() || tl.rests_before(p.contour + 1));
    let at = |value: f64| Peak {
        value,
        time: p.start + p.duration,
        line: p.line,
    };
    let found = match (last, tl.is_pt()) {
        (false, _) => Vec::new(),
        (true, true) => {
            let step = tl.cubic(p, k).v0.abs();
            let jerk = step / (period * period);
            vec![
                (Quantity::Acceleration, at(step / period)),
                (Quantity::Jerk, at(jerk)),
                (Quantity::AccelerationStep, at(jerk)),
            ]
        }
        (true, false) => {
            let step = end_accelerations(tl, p, k).1.abs();
            vec![(Quantity::AccelerationStep, at(step / period))]
        }
    };
    found.into_iter()
}

//! Closed-form peaks of |velocity|, |acceleration| and |jerk| of every piece.
//!
//! A PVT piece is a cubic: its velocity is a parabola that peaks at an end or where the
//! acceleration is zero inside (`t* = −A/J`), its acceleration is linear so it peaks at an
//! end, and its jerk is constant. A PT piece has constant velocity; its velocity steps at
//! the points have no finite acceleration, so pvtc reports each step `ΔV` as the servo
//! loop sees it, spread over one servo period `P`: acceleration `|ΔV|/P` and jerk
//! `|ΔV|/P²`, at the point's time. It must not sample: that is [`super::servo`].

use super::timeline::{Piece, Timeline};
use super::{Peak, Quantity};

/// The peaks of one axis over one piece (or one PT point), each with its absolute time.
pub(super) fn piece_peaks(
    tl: &Timeline<'_>,
    i: usize,
    k: usize,
    period: f64,
) -> [(Quantity, Peak); 3] {
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
    [
        (Quantity::Velocity, v),
        (Quantity::Acceleration, a),
        (Quantity::Jerk, at(h.jerk.abs(), 0.0)),
    ]
}

/// The step to rest after the last PT piece of a contour, as a peak at its end time.
pub(super) fn pt_stop(
    tl: &Timeline<'_>,
    p: &Piece,
    k: usize,
    period: f64,
) -> Option<[(Quantity, Peak); 2]> {
    let last = tl.program.contours[p.contour].len() == p.index + 1;
    if !tl.is_pt() || !last {
        return None;
    }
    let step = tl.cubic(p, k).v0.abs();
    let at = |value: f64| Peak {
        value,
        time: p.start + p.duration,
        line: p.line,
    };
    Some([
        (Quantity::Acceleration, at(step / period)),
        (Quantity::Jerk, at(step / (period * period))),
    ])
}

//! The comparison of the two readings: which moves agree, and the first difference.

use super::*;

/// Whether `a` and `b` agree within [`TOLERANCE`] of `unit` millimetres (at least 1).
pub(crate) fn close(a: &[f64], b: &[f64], unit: f64) -> bool {
    let tolerance = TOLERANCE * unit.max(1.0);
    a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tolerance)
}

/// Whether two moves agree; a rapid's feed is the machine's, not the program's.
pub(crate) fn same(ours: &Move, theirs: &Move) -> bool {
    match (ours, theirs) {
        (
            Move::Straight {
                rapid,
                end,
                feed,
                control,
                minutes,
                ..
            },
            Move::Straight {
                rapid: r,
                end: e,
                feed: f,
                control: c,
                minutes: m,
                unit,
                spread,
            },
        ) => {
            // rs274's minutes come from its printed ends: each axis of both ends up to
            // TOLERANCE of the units off, over the feed.
            let rounding = 2.0 * 3f64.sqrt() * TOLERANCE * unit.max(1.0) / f.max(1e-9);
            let timed = match *minutes > 0.0 || *m > 0.0 {
                true => (minutes - m).abs() <= 1e-6 * m.abs() + rounding,
                false => close_feed(*feed, *f, *unit),
            };
            rapid == r
                && close(end, e, unit * spread.max(1.0))
                && (*rapid || timed)
                && same_control(control, c, *unit)
        }
        (
            Move::Arc {
                plane,
                end,
                center,
                rotation,
                feed,
                control,
                ..
            },
            Move::Arc {
                plane: p,
                end: e,
                center: c,
                rotation: r,
                feed: f,
                control: k,
                unit,
                spread,
            },
        ) => {
            plane == p
                && rotation == r
                && close(end, e, unit * spread.max(1.0))
                && close(center, c, unit * spread.max(1.0))
                && close_feed(*feed, *f, *unit)
                && same_control(control, k, *unit)
        }
        (Move::Dwell(a), Move::Dwell(b)) => (a - b).abs() <= 1e-6,
        (Move::Speed(a), Move::Speed(b)) => (a - b).abs() <= TOLERANCE,
        (Move::Spindle(a), Move::Spindle(b)) | (Move::Coolant(a), Move::Coolant(b)) => a == b,
        _ => false,
    }
}

/// Whether two feeds agree: within [`TOLERANCE`] of `unit` millimetres per minute, or
/// 1e-5 of the feed (a synchronised move's pitch, which rs274 prints with six decimals,
/// times S).
fn close_feed(ours: f64, theirs: f64, unit: f64) -> bool {
    (ours - theirs).abs() <= TOLERANCE * unit.max(1.0) + 1e-5 * theirs.abs()
}

/// Whether two path control modes agree: the mode, and under G64 P and Q within
/// [`TOLERANCE`] of `unit` millimetres.
fn same_control(ours: &Control, theirs: &Control, unit: f64) -> bool {
    let tolerances = [[ours.p, ours.q], [theirs.p, theirs.q]];
    ours.mode == theirs.mode
        && (ours.mode != "continuous" || close(&tolerances[0], &tolerances[1], unit))
}

/// The first difference between the two readings, described, or `None`.
///
/// rs274's reading drops a straight move whose printed end is the end before it (see
/// [`Move::Straight`]'s parse), so a move of pvtc's that rs274 prints as none, one whose
/// every axis is within what rs274 prints of pvtc's end before it (its [`TOLERANCE`] of
/// the units of rs274's next move), is passed over: `G20 G91 X-0.0394` from X1 mm ends
/// 0.00076 mm before X0, and a `G90 X0` after it moves 0.00076 mm, printed as no move.
pub(crate) fn difference(ours: &[Move], theirs: &[Move]) -> Option<String> {
    let (mut i, mut j) = (0, 0);
    let mut at: Option<[f64; 6]> = None;
    let end = |m: &Move| match m {
        Move::Straight { end, .. } | Move::Arc { end, .. } => Some(*end),
        _ => None,
    };
    while i < ours.len() {
        let theirs_next = theirs.get(j).or(theirs.last());
        let unit = match theirs_next {
            Some(Move::Straight { unit, .. } | Move::Arc { unit, .. }) => *unit,
            _ => 1.0,
        };
        let unprinted = match (&ours[i], at) {
            (Move::Straight { end, .. }, Some(at)) => close(end, &at, unit),
            _ => false,
        };
        let (joined, parts) = turns_of_one_arc(&ours[i..], theirs.get(j));
        match theirs.get(j) {
            Some(t) if same(&joined, t) => {
                j += 1;
                i += parts - 1;
            }
            _ if unprinted => {}
            Some(t) => return Some(format!("move {i}:\n  pvtc:  {:?}\n  rs274: {t:?}", ours[i])),
            None => break,
        }
        at = end(&ours[i]).or(at);
        i += 1;
    }
    (i != ours.len() || j != theirs.len()).then(|| {
        format!(
            "pvtc has {} moves, rs274 {}; the first extra: {:?}",
            ours.len(),
            theirs.len(),
            ours.get(i).or(theirs.get(j))
        )
    })
}

/// `ours[0]`, or, where it is an arc and rs274's next move is an arc of more turns about
/// the same centre, it joined with the arcs after it about that centre until it has
/// those turns (pvtc hands an arc of many turns on a turn at a time, rs274 prints it
/// whole; a loop that repeats a full circle stays one arc a turn on both sides); and
/// how many of `ours` it took.
fn turns_of_one_arc(ours: &[Move], theirs: Option<&Move>) -> (Move, usize) {
    let first = ours[0].clone();
    let (Move::Arc { rotation: mine, .. }, Some(Move::Arc { rotation: want, .. })) =
        (&first, theirs)
    else {
        return (first, 1);
    };
    let (mine, want) = (*mine, *want);
    if want.abs() <= mine.abs() || want.signum() != mine.signum() {
        return (first, 1);
    }
    let mut joined = first;
    let mut parts = 1;
    for next in &ours[1..] {
        if !same_centre(&joined, next) {
            break;
        }
        join_turns(&mut joined, next.clone());
        parts += 1;
        if let Move::Arc { rotation, .. } = &joined {
            if rotation.abs() >= want.abs() {
                break;
            }
        }
    }
    (joined, parts)
}

/// Whether `last` is an arc about the centre of the arc `next`.
fn same_centre(last: &Move, next: &Move) -> bool {
    match (last, next) {
        (Move::Arc { center: a, .. }, Move::Arc { center: b, .. }) => close(a, b, 1.0),
        _ => false,
    }
}

/// `next`, the next turn of the arc `last` is part of, joined to it: its end and its turn.
fn join_turns(last: &mut Move, next: Move) {
    let (
        Move::Arc {
            end,
            center,
            rotation,
            ..
        },
        Move::Arc {
            end: next_end,
            center: next_center,
            rotation: next_rotation,
            ..
        },
    ) = (last, next)
    else {
        return;
    };
    debug_assert!(close(center, &next_center, 1.0));
    *end = next_end;
    *rotation += next_rotation;
}

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
                ..
            },
            Move::Straight {
                rapid: r,
                end: e,
                feed: f,
                control: c,
                unit,
                spread,
            },
        ) => {
            rapid == r
                && close(end, e, unit * spread.max(1.0))
                && (*rapid || close(&[*feed], &[*f], *unit))
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
                && close(&[*feed], &[*f], *unit)
                && same_control(control, k, *unit)
        }
        (Move::Dwell(a), Move::Dwell(b)) => (a - b).abs() <= 1e-6,
        (Move::Speed(a), Move::Speed(b)) => (a - b).abs() <= TOLERANCE,
        (Move::Spindle(a), Move::Spindle(b)) | (Move::Coolant(a), Move::Coolant(b)) => a == b,
        _ => false,
    }
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
        match theirs.get(j) {
            Some(t) if same(&ours[i], t) => j += 1,
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

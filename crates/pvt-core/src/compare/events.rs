//! The programmed events and the triggers of two programs, in order.
//!
//! Owns the comparison of the events other than dwells (a dwell is time at rest, which
//! the time lines compare): the same kinds in the same order, with the same values where
//! both carry them, each where the axes rest within the tolerance of the other's; and of
//! the triggers: as many, each firing where the other's fires (within the position
//! tolerance) or when (within the time tolerance). It must not compare motion.

use super::track::Track;
use crate::axis::AXIS_COUNT;
use crate::toolpath::{EventKind, ProgramEvent};

/// The first place where two lists differ.
#[derive(Debug, Clone, PartialEq)]
pub struct Mismatch {
    /// 0-based index in the lists.
    pub index: usize,
    /// What each program has there (an event's name, or `trigger`), `None` past its end.
    pub names: [Option<String>; 2],
    /// When, on each program's time line (seconds; past a list's end, its program's end).
    pub times: [f64; 2],
    /// The lines each program has there (0 past its end).
    pub lines: [u32; 2],
}

/// Two lists compared.
#[derive(Debug, Clone, PartialEq)]
pub struct Listed {
    /// How many each program has.
    pub counts: [usize; 2],
    /// The first difference, if any.
    pub mismatch: Option<Mismatch>,
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-9 * a.abs().max(b.abs()).max(1.0)
}

fn words(e: &EventKind) -> [Option<f64>; 4] {
    match e {
        EventKind::MachineCode { words, .. } => [words.p, words.q, words.e, words.l],
        _ => [None; 4],
    }
}

/// Whether two events are the same: the same kind and the same values.
fn same(a: &EventKind, b: &EventKind) -> bool {
    let text = |s: &str| s.replace(['"', '\''], "'").replace('\n', " ");
    a.name() == b.name()
        && match (a, b) {
            (EventKind::SpindleSpeed { rpm: x }, EventKind::SpindleSpeed { rpm: y }) => {
                close(*x, *y)
            }
            (EventKind::ToolSelect { tool: x }, EventKind::ToolSelect { tool: y }) => x == y,
            (EventKind::Message { text: x }, EventKind::Message { text: y }) => text(x) == text(y),
            _ => words(a).iter().zip(words(b)).all(|(x, y)| match (x, y) {
                (Some(x), Some(y)) => close(*x, y),
                (x, y) => x.is_none() == y.is_none(),
            }),
        }
}

fn far(a: &[f64; AXIS_COUNT], b: &[f64; AXIS_COUNT], dim: usize, tolerance: f64) -> bool {
    crate::vector::distance(&a[..dim], &b[..dim]) > tolerance
}

/// Compares the events (but dwells) of two programs.
pub(super) fn events(
    tracks: [&Track<'_>; 2],
    lists: [&[ProgramEvent]; 2],
    tolerance: f64,
) -> Listed {
    let kept: Vec<Vec<&ProgramEvent>> = lists
        .iter()
        .map(|l| {
            l.iter()
                .filter(|e| !matches!(e.kind, EventKind::Dwell { .. }))
                .collect()
        })
        .collect();
    let counts = [kept[0].len(), kept[1].len()];
    let dim = tracks[0].dim();
    let mismatch = (0..counts[0].max(counts[1])).find_map(|i| {
        let (x, y) = (kept[0].get(i), kept[1].get(i));
        let equal = match (x, y) {
            (Some(x), Some(y)) => {
                same(&x.kind, &y.kind)
                    && !far(
                        &tracks[0].place(x.before_contour),
                        &tracks[1].place(y.before_contour),
                        dim,
                        tolerance,
                    )
            }
            _ => false,
        };
        let time = |e: Option<&&ProgramEvent>, t: &Track<'_>| {
            e.map_or(t.total, |e| {
                t.contour_starts
                    .get(e.before_contour)
                    .copied()
                    .unwrap_or(t.total)
            })
        };
        (!equal).then(|| Mismatch {
            index: i,
            names: [x, y].map(|e| e.map(|e| e.kind.name().to_string())),
            times: [time(x, tracks[0]), time(y, tracks[1])],
            lines: [x, y].map(|e| e.map_or(0, |e| e.line)),
        })
    });
    Listed { counts, mismatch }
}

/// Compares two lists of triggers, each given as the number of pieces before it.
pub(super) fn triggers(
    tracks: [&Track<'_>; 2],
    lists: [&[usize]; 2],
    tolerances: [f64; 2],
) -> Listed {
    let times = [
        tracks[0].after_pieces(lists[0]),
        tracks[1].after_pieces(lists[1]),
    ];
    let counts = [lists[0].len(), lists[1].len()];
    let dim = tracks[0].dim();
    let [tolerance, time_tolerance] = tolerances;
    let mismatch = (0..counts[0].max(counts[1])).find_map(|i| {
        let (x, y) = (times[0].get(i).copied(), times[1].get(i).copied());
        let equal = match (x, y) {
            (Some(x), Some(y)) => {
                (x - y).abs() <= time_tolerance
                    || !far(
                        &tracks[0].position(x),
                        &tracks[1].position(y),
                        dim,
                        tolerance,
                    )
            }
            _ => false,
        };
        let ts = [x.unwrap_or(tracks[0].total), y.unwrap_or(tracks[1].total)];
        (!equal).then(|| Mismatch {
            index: i,
            names: [x, y].map(|t| t.map(|_| "trigger".to_string())),
            times: ts,
            lines: [
                x.map_or(0, |t| tracks[0].line_to(t)),
                y.map_or(0, |t| tracks[1].line_to(t)),
            ],
        })
    });
    Listed { counts, mismatch }
}

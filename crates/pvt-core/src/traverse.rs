//! One traversal of a toolpath or a program: its contours in order, each event at rest
//! before the contour it precedes (and the events after the last contour at the end),
//! and, for a toolpath, each G64 P path tolerance before the first contour it holds for.
//!
//! Owns the interleaving rule, so that every reader of a whole toolpath or program
//! (pvt-emit's `emit` and `replay`; the planning driver may adopt it) walks it the same
//! way. It must not plan, write or change what it walks.

use crate::program::PvtProgram;
use crate::stream::ToolpathSink;
use crate::toolpath::{ProgramEvent, Toolpath};

/// One step of a traversal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Step<'a, C> {
    /// An event, at rest.
    Event(&'a ProgramEvent),
    /// The path tolerance (G64 P) from here on, program units.
    PathTolerance(f64),
    /// The next contour.
    Contour(&'a C),
}

/// The steps of contours `contours` with `events` and `tolerances` (each `(index of the
/// first contour it holds for, value)`) interleaved, both in program order.
#[derive(Debug, Clone)]
pub struct Steps<'a, C> {
    contours: &'a [C],
    events: &'a [ProgramEvent],
    tolerances: &'a [(usize, f64)],
    next_contour: usize,
    next_event: usize,
    next_tolerance: usize,
}

impl<'a, C> Iterator for Steps<'a, C> {
    type Item = Step<'a, C>;

    fn next(&mut self) -> Option<Step<'a, C>> {
        let index = self.next_contour;
        let ended = index >= self.contours.len();
        if let Some(event) = self.events.get(self.next_event) {
            if ended || event.before_contour <= index {
                self.next_event += 1;
                return Some(Step::Event(event));
            }
        }
        if ended {
            return None;
        }
        if let Some(&(from, tolerance)) = self.tolerances.get(self.next_tolerance) {
            if from <= index {
                self.next_tolerance += 1;
                return Some(Step::PathTolerance(tolerance));
            }
        }
        self.next_contour += 1;
        Some(Step::Contour(&self.contours[index]))
    }
}

/// The steps of `toolpath`: its contours, events and path tolerances.
pub fn toolpath(toolpath: &Toolpath) -> Steps<'_, crate::toolpath::Contour> {
    steps(
        &toolpath.contours,
        &toolpath.events,
        &toolpath.path_tolerances,
    )
}

/// The steps of `program`: its contours and events.
pub fn program(program: &PvtProgram) -> Steps<'_, crate::program::PvtContour> {
    steps(&program.contours, &program.events, &[])
}

fn steps<'a, C>(
    contours: &'a [C],
    events: &'a [ProgramEvent],
    tolerances: &'a [(usize, f64)],
) -> Steps<'a, C> {
    Steps {
        contours,
        events,
        tolerances,
        next_contour: 0,
        next_event: 0,
        next_tolerance: 0,
    }
}

/// Hands a whole `toolpath` to `sink` in program order, as a streaming front end would.
pub fn replay(toolpath: &Toolpath, sink: &mut dyn ToolpathSink) {
    for step in self::toolpath(toolpath) {
        match step {
            Step::Event(event) => sink.event(&event.kind, event.line),
            Step::PathTolerance(tolerance) => sink.path_tolerance(tolerance),
            Step::Contour(contour) => {
                for element in &contour.elements {
                    sink.element(contour.motion, element);
                }
                sink.end_contour();
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::toolpath::{Contour, EventKind, Motion};

    fn event(before_contour: usize, line: u32) -> ProgramEvent {
        ProgramEvent {
            before_contour,
            kind: EventKind::Dwell { seconds: 1.0 },
            line,
        }
    }

    #[test]
    fn events_and_tolerances_come_before_their_contour_and_late_events_last() {
        let contour = |motion| Contour {
            motion,
            elements: Vec::new(),
        };
        let toolpath = Toolpath {
            contours: vec![contour(Motion::Rapid), contour(Motion::Feed)],
            events: vec![event(0, 10), event(1, 11), event(2, 12), event(9, 13)],
            path_tolerances: vec![(1, 0.5)],
            ..Toolpath::default()
        };
        let walked: Vec<String> = self::toolpath(&toolpath)
            .map(|step| match step {
                Step::Event(e) => format!("event {}", e.line),
                Step::PathTolerance(t) => format!("tolerance {t}"),
                Step::Contour(c) => format!("contour {:?}", c.motion),
            })
            .collect();
        assert_eq!(
            walked,
            [
                "event 10",
                "contour Rapid",
                "event 11",
                "tolerance 0.5",
                "contour Feed",
                "event 12",
                "event 13"
            ]
        );
    }
}

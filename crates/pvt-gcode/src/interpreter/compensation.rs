//! Cutter-radius compensation's modal state (G40, G41/G42 with D from the tool table,
//! G41.1/G42.1 with D a diameter) and the routing of moves and events through
//! [`pvt_core::compensate::Compensation`] while it is on.
//!
//! Owns which side, radius and lathe tool orientation are in effect, where the exit move after G40 starts, and
//! the codes refused while compensation is on (as LinuxCNC refuses them). The offset
//! geometry and the one-move look-ahead are pvt-core's; this must not compute offsets.
//! The interpreter's position stays the programmed point: incremental moves and
//! parameters read it, as rs274 reads its programmed point under compensation.

use pvt_core::compensate::{self, Compensation, Gouge, Programmed, Released, Side};
use pvt_core::{Element, ElementKind, EventKind, Motion, Plane, Position};

use super::Interpreter;
use crate::block::Word;
use crate::codes::{CutterComp, MotionMode, NonModal};
use crate::diagnostic::{span, GcodeDiagnostic};
use crate::request::Request;

/// G40/G41/G42 state kept between blocks.
#[derive(Debug, Clone, Default)]
pub(crate) struct CutterState {
    /// G41/G42 (or G41.1/G42.1) is in effect, even with a zero radius.
    on: bool,
    /// The side it was turned on to (as written: a negative radius does not turn it).
    side: Option<Side>,
    /// The compensation itself, while on with a radius above zero.
    active: Option<Compensation>,
    /// After G40: where the tool's centre stands, the start of the exit move.
    exit_from: Option<Position>,
}

impl Interpreter<'_> {
    /// G40, G41, G41.1, G42, G42.1 of the block, after its plane and units; and the
    /// block's codes compensation does not allow.
    pub(super) fn set_compensation(&mut self, request: &Request) {
        if self.cutter.on {
            self.refuse_while_on(request);
        }
        let Some((code, word)) = request.cutter_comp else {
            return;
        };
        match code {
            CutterComp::Off => self.compensation_off(word),
            CutterComp::On(side, direct) => self.compensation_on(side, direct, request, word),
        }
    }

    /// Where the tool stands after G40, off the programmed point, taken: the position
    /// from here on (rs274 re-reads it after M6).
    pub(super) fn take_exit_point(&mut self) -> Option<Position> {
        self.cutter.exit_from.take()
    }

    /// True while G41/G42 is in effect.
    pub(super) fn cutter_on(&self) -> bool {
        self.cutter.on
    }

    /// The code of the compensation in effect, in tenths (G40 400, G41 410, G42 420), as
    /// M70 records it.
    pub(super) fn compensation_code(&self) -> u32 {
        match self.cutter.side.filter(|_| self.cutter.on) {
            None => 400,
            Some(Side::Left) => 410,
            Some(Side::Right) => 420,
        }
    }

    fn compensation_off(&mut self, word: Word) {
        self.cutter.on = false;
        self.cutter.side = None;
        let Some(compensation) = self.cutter.active.take() else {
            return;
        };
        let mut out = Vec::new();
        let result = compensation.finish(&mut out);
        self.deliver(out);
        match result {
            Ok(exit_from) => self.cutter.exit_from = exit_from,
            Err(gouge) => self.report_gouge(gouge, word.span()),
        }
    }

    fn compensation_on(&mut self, side: Side, direct: bool, request: &Request, word: Word) {
        let refuse = |what| GcodeDiagnostic::CompensationConflict {
            what,
            span: span(word.span()),
        };
        if self.cutter.on {
            return self.push(refuse("G41/G42 while it is already on"));
        }
        let plane = self.modal.plane;
        if !matches!(plane, Plane::XY | Plane::ZX) {
            return self.push(refuse("G41/G42 outside the XY (G17) and XZ (G18) planes"));
        }
        let Some((radius, orientation)) = self.compensation_tool(direct, request, word) else {
            return;
        };
        self.cutter.on = true;
        self.cutter.side = Some(side);
        let side = if radius < 0.0 { side.opposite() } else { side };
        if radius != 0.0 {
            let at = self.position;
            let tool = self.cutter.exit_from.take().unwrap_or(at);
            let slack = match self.modal.units {
                pvt_core::Units::Millimetre => compensate::SWEEP_SLACK_MM,
                pvt_core::Units::Inch => compensate::SWEEP_SLACK_INCH,
            };
            let compensation = Compensation::new(side, radius.abs(), plane, at)
                .released_from(tool)
                .with_sweep_slack(slack)
                .with_tool_orientation(orientation);
            self.cutter.active = Some(compensation);
        }
    }

    /// The tool radius in output units (negative: the other side) and a lathe tool's
    /// orientation, from D as a diameter and L as the orientation (G41.1/G42.1) or D as a
    /// tool of the table (G41/G42; without D, the loaded tool).
    fn compensation_tool(
        &mut self,
        direct: bool,
        request: &Request,
        word: Word,
    ) -> Option<(f64, u32)> {
        self.output_units.get_or_insert(self.modal.units);
        if direct {
            let Some(d) = request.d else {
                self.push(super::missing(word, "a D word (the tool diameter)"));
                return None;
            };
            let orientation = match request.l {
                None => 0,
                Some(l) => self.lathe_orientation(l)?,
            };
            return Some((d.value * self.scale() / 2.0, orientation));
        }
        let number = match request.d {
            Some(d) => match super::whole(d.value) {
                Some(n) => n,
                None => {
                    self.push(super::bad_value(d, "a tool number ≥ 0"));
                    return None;
                }
            },
            None => self.tool.current,
        };
        // No tool loaded (T0) has no radius; a loaded tool the table lacks is unknown,
        // as LinuxCNC's M6 would have refused it (compensating by 0 would cut wrong).
        let (diameter, orientation) = match (self.tools.get(number), request.d) {
            (Some(tool), _) => (tool.diameter, tool.orientation),
            (None, None) if number == 0 => (0.0, 0),
            (None, d) => {
                self.push(GcodeDiagnostic::UnknownTool {
                    tool: number,
                    span: span(d.unwrap_or(word).span()),
                });
                return None;
            }
        };
        if !matches!(orientation, 0 | 9) && self.modal.plane != Plane::ZX {
            self.push(GcodeDiagnostic::CompensationConflict {
                what: "a lathe tool (an orientation Q) outside the XZ plane (G18)",
                span: span(word.span()),
            });
            return None;
        }
        Some((self.output().from_mm(diameter) / 2.0, orientation))
    }

    /// G41.1/G42.1 L: a lathe tool's orientation, in G18 only.
    fn lathe_orientation(&mut self, l: Word) -> Option<u32> {
        if self.modal.plane != Plane::ZX {
            self.push(GcodeDiagnostic::CompensationConflict {
                what: "an orientation L outside the XZ plane (G18)",
                span: span(l.span()),
            });
            return None;
        }
        match super::whole(l.value).filter(|o| *o <= 9) {
            Some(orientation) => Some(orientation),
            None => {
                self.push(super::bad_value(l, "an orientation 0…9"));
                None
            }
        }
    }

    /// Codes LinuxCNC refuses while compensation is on (units, which rs274 rescales its
    /// held moves for, too).
    fn refuse_while_on(&mut self, request: &Request) {
        let changes_offsets = matches!(
            request.non_modal,
            Some((
                NonModal::SetOffset
                    | NonModal::ClearOffset { .. }
                    | NonModal::RestoreOffset
                    | NonModal::LocalOffset
                    | NonModal::MachineCoords
                    | NonModal::Home(_),
                _
            ))
        );
        let checks: [(Option<Word>, &'static str); 7] = [
            (
                request
                    .non_modal
                    .filter(|_| changes_offsets)
                    .map(|(_, w)| w),
                "G53, G28/G30 and G52/G92 offsets",
            ),
            (request.plane.map(|(_, w)| w), "a plane change"),
            (
                request.coord_system.map(|(_, w)| w),
                "a coordinate system change",
            ),
            (request.tool_change.map(|(_, w)| w), "a tool change"),
            (
                request.tool_length.map(|(_, w)| w),
                "a tool length offset change",
            ),
            (request.units.map(|(_, w)| w), "a units change"),
            (
                request
                    .motion
                    .filter(|(m, _)| matches!(m, MotionMode::Cycle(_)))
                    .map(|(_, w)| w),
                "a canned cycle",
            ),
        ];
        for (word, what) in checks {
            if let Some(word) = word {
                self.push(GcodeDiagnostic::CompensationConflict {
                    what,
                    span: span(word.span()),
                });
            }
        }
    }

    /// Where every move goes: through the compensation while it is on; the exit move
    /// after G40 starts where the tool's centre stands.
    pub(super) fn route(&mut self, motion: Motion, mut element: Element) {
        let at = element.span.start..element.span.end;
        if let Some(compensation) = self.cutter.active.as_mut() {
            if matches!(element.kind, ElementKind::Arc(arc) if arc.plane != compensation.plane()) {
                return self.push(GcodeDiagnostic::CompensationConflict {
                    what: "an arc outside the compensation plane",
                    span: span(at),
                });
            }
            let step = Programmed {
                motion,
                kind: element.kind,
                end: element.end,
                feed: element.feed,
                span: element.span,
            };
            let mut out = Vec::new();
            let result = compensation.feed(step, &mut out);
            self.deliver(out);
            if let Err(gouge) = result {
                // One refusal is enough: the rest of the path is not compensated.
                self.cutter.active = None;
                self.report_gouge(gouge, at);
            }
            return;
        }
        if let Some(from) = self.cutter.exit_from.take() {
            if matches!(element.kind, ElementKind::Arc(_)) {
                return self.push(GcodeDiagnostic::CompensationConflict {
                    what: "an arc as the exit move after G40 (it must be straight)",
                    span: span(at),
                });
            }
            element.start = from;
            if element.start == element.end {
                return;
            }
        }
        self.emit(motion, &element);
    }

    /// True when compensation is off and has no exit move pending: a move goes straight
    /// to the sink.
    pub(super) fn cutter_idle(&self) -> bool {
        !self.cutter.on && self.cutter.active.is_none() && self.cutter.exit_from.is_none()
    }

    /// Where the next straight move starts: the tool's centre after G40 (the exit move),
    /// else the machine position (after M6, rs274's re-read one).
    pub(super) fn tool_start(&self) -> Position {
        self.cutter
            .exit_from
            .unwrap_or_else(|| self.machine_position())
    }

    /// An event: held with the move before it while compensation holds that move.
    pub(super) fn compensated_event(&mut self, kind: EventKind, line: u32) -> Option<EventKind> {
        let Some(compensation) = self.cutter.active.as_mut() else {
            return Some(kind);
        };
        let mut out = Vec::new();
        compensation.event(kind, line, &mut out);
        self.deliver(out);
        None
    }

    /// The end of the program (M2/M30 at `at`, or the end of the text): held moves are
    /// released as G40 releases them.
    pub(super) fn finish_compensation(&mut self, at: std::ops::Range<usize>) {
        if let Some(compensation) = self.cutter.active.take() {
            let mut out = Vec::new();
            let result = compensation.finish(&mut out);
            self.deliver(out);
            if let Err(gouge) = result {
                self.report_gouge(gouge, at);
            }
        }
    }

    /// Sends what the compensation released on, in order.
    fn deliver(&mut self, released: Vec<Released>) {
        for item in released {
            match item {
                Released::Element(motion, element) => self.emit(motion, &element),
                Released::Event(kind, line) => {
                    self.end_contour();
                    self.sink.event(&kind, line);
                }
            }
        }
    }

    fn report_gouge(&mut self, gouge: Gouge, at: std::ops::Range<usize>) {
        let units = self.output().name();
        let at = span(at);
        self.push(match gouge {
            Gouge::EntryTooShort { radius } => GcodeDiagnostic::CompensationEntry {
                radius,
                units,
                span: at,
            },
            Gouge::ToolLargerThanArc { radius } => GcodeDiagnostic::ToolRadiusOverArc {
                radius,
                units,
                span: at,
            },
            Gouge::ConcaveCorner(detail) => GcodeDiagnostic::ConcaveCorner { detail, span: at },
            Gouge::SameCentre => GcodeDiagnostic::ConcaveCorner {
                detail: "two arcs about the same centre meet at the corner",
                span: at,
            },
            Gouge::Spline => GcodeDiagnostic::CompensationConflict {
                what: "a spline (G5, G5.1, G5.2)",
                span: at,
            },
        });
    }
}

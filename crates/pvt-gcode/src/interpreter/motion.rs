//! Moves: G0/G1 lines and G2/G3 arcs from a block's words and the modal state.
//!
//! Owns end points (distance mode, offsets, G53), centres (I/J/K by G90.1/G91.1, or R),
//! feeds (G94 units per minute, G93 inverse time) and where contours end (rapids, G61).
//! It must not read words (that is [`crate::request`]) nor change modes.

use std::ops::Range;

use pvt_core::{
    Arc, ArcDirection, Axis, Element, ElementKind, Motion, PathControl, Plane, Position, Span,
    Units,
};

use super::{Feed, Interpreter};
use crate::arcs::{self, ArcProblem, ArcTolerance};
use crate::block::{cover, Block, Word};
use crate::codes::{Distance, FeedMode, MotionMode, NonModal, ToolLength};
use crate::diagnostic::{span, GcodeDiagnostic};
use crate::request::Request;

impl Interpreter<'_> {
    /// G93/G94/G95. G94 and G95 set a feed in force to 0, as LinuxCNC does (a feed move
    /// then needs an F of its own); before any F the default feed stays.
    pub(super) fn set_feed_mode(&mut self, request: &Request) {
        let Some((mode, _)) = request.feed_mode else {
            return;
        };
        self.modal.feed_mode = mode;
        if mode == FeedMode::PerRevolution {
            if let Some((_, word)) = request.feed_mode {
                self.spindle_sync("G95", word.span());
            }
        }
        if mode != FeedMode::InverseTime {
            if let Some(feed) = self.modal.feed.as_mut() {
                feed.written = 0.0;
                feed.reset_by = Some(mode.name());
            }
        }
    }

    /// F: the feed for G94 and G95 moves (under G93 each move reads its own F), in the
    /// units in force now: before the block's G20/G21 ([`super::order`]).
    pub(super) fn set_feed(&mut self, request: &Request) {
        let Some(word) = request.feed else { return };
        if self.modal.feed_mode == FeedMode::InverseTime {
            return;
        }
        if !word.value.is_finite() {
            return self.push(out_of_range("feed", word.value, word.span()));
        }
        self.modal.feed = Some(self.feed_word(word.value));
        self.feed_reported = false;
    }

    /// The feed an F word of `written` sets now.
    pub(super) fn feed_word(&self, written: f64) -> Feed {
        Feed {
            written,
            units: self.modal.units,
            reset_by: None,
        }
    }

    /// The block's move in the motion mode in effect.
    pub(super) fn run_motion(&mut self, request: &Request, block: &Block) {
        let offsets_use_axes = matches!(
            request.non_modal,
            Some((
                NonModal::SetOffset
                    | NonModal::Home(_)
                    | NonModal::SetHome(_)
                    | NonModal::SetTable
                    | NonModal::LocalOffset,
                _
            ))
        ) || matches!(
            request.tool_length,
            Some((ToolLength::Dynamic | ToolLength::Add, _))
        );
        if request.no_move || offsets_use_axes {
            return;
        }
        let has_axes = request.has_axis_words();
        let g6 = self.nurbs.as_ref().map(|n| n.knots.is_some());
        let modes_of_block = match g6 {
            Some(false) => matches!(
                self.modal.motion,
                Some(MotionMode::Nurbs | MotionMode::NurbsEnd)
            ),
            Some(true) => self.modal.motion == Some(MotionMode::NurbsKnots),
            None => true,
        };
        if !modes_of_block {
            self.nurbs_unclosed();
        }
        match self.modal.motion {
            Some(MotionMode::Nurbs) => self.nurbs_point(request, block),
            Some(MotionMode::NurbsKnots) => self.nurbs_knot_line(request, block),
            Some(MotionMode::NurbsEnd) => {
                if request.motion.is_some() {
                    self.nurbs_close(request, block);
                }
                self.reject_axes_without_mode(request);
            }
            Some(MotionMode::Arc(direction)) => {
                if has_axes
                    || request.offsets.iter().any(Option::is_some)
                    || request.radius.is_some()
                {
                    self.arc_move(direction, request, block);
                }
            }
            Some(MotionMode::Unsupported) => {}
            Some(MotionMode::Thread) => {
                if has_axes {
                    self.thread_move(request, block);
                }
            }
            Some(MotionMode::RigidTap) => {
                if has_axes {
                    self.rigid_tap(request, block);
                }
            }
            Some(MotionMode::LatheCycle(cycle)) => {
                if has_axes || request.motion.is_some() {
                    self.lathe_cycle(cycle, request, block);
                }
            }
            Some(MotionMode::ThreadCycle) => {
                if has_axes {
                    self.thread_cycle(request, block);
                }
            }
            Some(MotionMode::Spline { quadratic }) => {
                if has_axes {
                    self.spline_move(quadratic, request, block);
                }
            }
            Some(MotionMode::Probe(code)) => {
                if has_axes {
                    self.probe_move(MotionMode::Probe(code), request, block);
                }
            }
            Some(MotionMode::Cycle(cycle)) => {
                if has_axes {
                    self.cycle_move(cycle, request, block);
                }
            }
            Some(mode @ (MotionMode::Rapid | MotionMode::Linear)) => {
                self.reject_arc_words(request, mode.name());
                if has_axes {
                    self.line_move(mode, request, block);
                }
            }
            mode @ (None | Some(MotionMode::Cancel)) => {
                self.reject_arc_words(request, mode.map_or("not set", MotionMode::name));
                self.reject_axes_without_mode(request);
            }
        }
    }

    /// Axis words with no motion mode to move them (G80, G5.3, none yet): an error, the
    /// position taken as given.
    fn reject_axes_without_mode(&mut self, request: &Request) {
        if let Some(&word) = request.axis_words().next() {
            self.push(GcodeDiagnostic::NoMotionMode {
                word: word.name(),
                span: span(word.span()),
            });
            if let Ok(end) = self.target(request) {
                self.position = end;
            }
        }
    }

    fn reject_arc_words(&mut self, request: &Request, mode: &'static str) {
        if request.radius.is_none() && request.offsets.iter().all(Option::is_none) {
            return;
        }
        for &word in request.offsets.iter().chain([&request.radius]).flatten() {
            self.push(GcodeDiagnostic::ArcWordWithoutArc {
                word: word.name(),
                mode,
                span: span(word.span()),
            });
        }
    }

    /// The end position of the block's move: machine coordinates, output units.
    pub(super) fn target(&self, request: &Request) -> Result<Position, GcodeDiagnostic> {
        const WHAT: [&str; 6] = [
            "X coordinate",
            "Y coordinate",
            "Z coordinate",
            "A angle",
            "B angle",
            "C angle",
        ];
        let machine = matches!(request.non_modal, Some((NonModal::MachineCoords, _)));
        // In a rotated system X and Y are read in the program's frame and placed
        // together; every other axis (and G53) is one machine axis. `here`, the program
        // point where the tool is, is made only in a rotated system, which alone reads it.
        let here = (!machine && self.rotation() != 0.0).then(|| self.to_program(self.position));
        let mut program = here.unwrap_or_default();
        let mut end = self.position;
        for axis in Axis::ALL {
            let i = axis.index();
            let Some(word) = request.axes[i] else {
                continue;
            };
            let value = self.program_value(axis, word.value);
            if let (Some(here), true) = (here, i < 2) {
                program[i] = match self.modal.distance {
                    Distance::Absolute => value,
                    Distance::Incremental => program[i] + value,
                };
                // The program point where the tool is stays that machine point exactly
                // (no move from rounding in and out of the turned frame).
                let placed = match program[..2] == here[..2] {
                    true => self.position,
                    false => self.to_machine(program),
                };
                end[..2].copy_from_slice(&placed[..2]);
            } else {
                end[i] = match (machine, self.modal.distance) {
                    (true, _) => value,
                    (false, Distance::Absolute) => value + self.offset(i),
                    (false, Distance::Incremental) => end[i] + value,
                };
            }
            if let Some(bad) = end.iter().copied().find(|v| !v.is_finite()) {
                return Err(out_of_range(WHAT[i], bad, word.span()));
            }
        }
        if request.polar.iter().any(Option::is_some) {
            self.polar_target(request, machine, &mut end)?;
        }
        Ok(end)
    }

    /// `@` radius and `^` angle (degrees) from the program origin in the XY plane, set
    /// as LinuxCNC does: under G91 added to the current radius and angle.
    fn polar_target(
        &self,
        request: &Request,
        machine: bool,
        end: &mut Position,
    ) -> Result<(), GcodeDiagnostic> {
        let first = request.polar.iter().flatten().next().copied();
        let at = first.map_or(0..0, |w| w.span());
        let refuse = |detail: &'static str| GcodeDiagnostic::BadValue {
            word: first.map_or_else(String::new, |w| w.name()),
            expected: detail,
            span: span(at.clone()),
        };
        if request.axes[0].is_some() || request.axes[1].is_some() {
            return Err(refuse(
                "polar words (@, ^) replace X and Y; give one or the other",
            ));
        }
        if self.modal.plane != Plane::XY || machine {
            return Err(refuse("polar words (@, ^) work in G17 without G53"));
        }
        let scale = self.scale();
        let mut program = self.to_program(self.position);
        let words = request.polar.map(|w| w.map(|w| w.value));
        let from = [program[0] / scale, program[1] / scale];
        let [x, y] = polar_point(from, words, self.modal.distance);
        program[0] = x * scale;
        program[1] = y * scale;
        let placed = self.to_machine(program);
        end[..2].copy_from_slice(&placed[..2]);
        if end[0].is_finite() && end[1].is_finite() {
            Ok(())
        } else {
            Err(out_of_range("X coordinate", end[0], at))
        }
    }

    /// The feed of a feed move, units per second; `None` (reported) when there is none.
    /// The move's `length` is measured only under G93, the one mode that needs it.
    pub(super) fn feed_rate(
        &mut self,
        request: &Request,
        block: &Block,
        length: impl FnOnce() -> f64,
    ) -> Option<f64> {
        if self.modal.feed_mode == FeedMode::InverseTime {
            return self.inverse_time_rate(request, block, length());
        }
        if self.modal.feed_mode == FeedMode::PerRevolution {
            return self.per_revolution_rate(request, block);
        }
        let Some(per_minute) = self.feed_per_minute(self.modal.feed) else {
            if !self.feed_reported {
                self.feed_reported = true;
                let at = move_span(request, block);
                self.push(GcodeDiagnostic::NoFeed { span: span(at) });
            }
            return None;
        };
        if let Some(rate) = feed_per_second(per_minute) {
            return Some(rate);
        }
        if !self.feed_reported {
            self.feed_reported = true;
            let feed = match self.modal.feed {
                Some(Feed {
                    reset_by: Some(code),
                    ..
                }) => format!("F0 ({code} sets the feed to 0, as LinuxCNC does)"),
                Some(feed) => format!("F{}", feed.written),
                None => format!("default feed {per_minute}"),
            };
            let at = request
                .feed
                .map_or_else(|| move_span(request, block), |w| w.span());
            self.push(GcodeDiagnostic::ZeroFeed {
                feed,
                span: span(at),
            });
        }
        None
    }

    /// The feed of a G94 move at `feed` (the F in force), output units per minute: its
    /// number in the units in force when it was set, as LinuxCNC converts it then
    /// (`G20 F20` then `G21 G1 X100` feeds at 20 in/min, 508 mm/min), else the default
    /// feed; `None` without either. Plain lines ([`super::plain`]) take it from here too.
    pub(super) fn feed_per_minute(&self, feed: Option<Feed>) -> Option<f64> {
        match (feed, self.options.default_feed) {
            (Some(feed), _) => {
                Some(feed.written * feed.units.mm_per_unit() / self.output().mm_per_unit())
            }
            (None, default) => default,
        }
    }

    /// G95: the F in force per revolution at the programmed S, taken as exact (the
    /// refusal without `--spindle-rpm-exact` is G95's, [`Self::set_feed_mode`]).
    fn per_revolution_rate(&mut self, request: &Request, block: &Block) -> Option<f64> {
        if self.spindle_sync_refused() {
            return None;
        }
        let feed = self.modal.feed;
        let per_revolution = self.feed_per_minute(feed).filter(|f| *f > 0.0);
        let rate = per_revolution.map(|f| f * self.modal.speed / 60.0);
        if let Some(rate) = rate.filter(|r| *r > 0.0 && r.is_finite()) {
            return Some(rate);
        }
        if !self.feed_reported {
            self.feed_reported = true;
            let feed = match feed {
                Some(f) => format!("F{} per revolution at S{}", f.written, self.modal.speed),
                None => "no F per revolution".to_owned(),
            };
            let at = move_span(request, block);
            self.push(GcodeDiagnostic::ZeroFeed {
                feed,
                span: span(at),
            });
        }
        None
    }

    /// The feed of a line that turns a rotary axis, along the path the planner measures
    /// (all axes, degrees included), as LinuxCNC's canonical layer feeds it: with X, Y or
    /// Z, at F along X Y Z alone, the rotary axes keeping pace (the rate grows by the
    /// whole length over that length); alone, at F degrees per minute, the number
    /// unconverted by the units. G93's rate, a time already, stays.
    /// `feed` is the F the rate comes from.
    pub(super) fn rotary_rate(
        &self,
        rate: f64,
        feed: Option<Feed>,
        start: &Position,
        end: &Position,
    ) -> f64 {
        if self.modal.feed_mode == FeedMode::InverseTime {
            return rate;
        }
        let linear = line_length(&start[..3], &end[..3]);
        let full = line_length(start, end);
        match (linear > 0.0, full > linear) {
            (true, true) => rate * full / linear,
            (false, true) => match feed {
                Some(feed) => rate * self.output().mm_per_unit() / feed.units.mm_per_unit(),
                None => rate,
            },
            (_, false) => rate,
        }
    }

    /// G93: the block's F is 1 / the minutes the move takes.
    fn inverse_time_rate(&mut self, request: &Request, block: &Block, length: f64) -> Option<f64> {
        let Some(f) = request.feed else {
            let at = move_span(request, block);
            self.push(GcodeDiagnostic::InverseTimeFeed { span: span(at) });
            return None;
        };
        let rate = length * f.value / 60.0;
        if f.value > 0.0 && rate.is_finite() {
            return Some(rate.max(f64::MIN_POSITIVE));
        }
        self.push(GcodeDiagnostic::ZeroFeed {
            feed: f.name(),
            span: span(f.span()),
        });
        None
    }

    /// The rapid rate, units per second.
    pub(super) fn rapid_rate(&self) -> f64 {
        pvt_core::defaults::rapid_per_minute(self.options.rapid, self.output()) / 60.0
    }

    fn line_move(&mut self, mode: MotionMode, request: &Request, block: &Block) {
        self.output_units.get_or_insert(Units::Millimetre);
        let end = match self.target(request) {
            Ok(end) => end,
            Err(diagnostic) => return self.push(diagnostic),
        };
        let start = self.tool_start();
        let (motion, feed) = match mode {
            MotionMode::Rapid => (Motion::Rapid, Some(self.rapid_rate())),
            _ => {
                // G93 times the programmed move, not the exit move after G40 (rs274).
                let programmed = self.position;
                let length = || line_length(&programmed, &end);
                let rate = self.feed_rate(request, block, length);
                (
                    Motion::Feed,
                    rate.map(|r| self.rotary_rate(r, self.modal.feed, &start, &end)),
                )
            }
        };
        self.position = end;
        let Some(feed) = feed else { return };
        if no_move(&start, &end) {
            let span = span(block.span());
            return self.warn(match motion {
                Motion::Rapid => GcodeDiagnostic::RapidToCurrentPoint { span },
                Motion::Feed => GcodeDiagnostic::ZeroLengthMove { span },
            });
        }
        self.straight(motion, start, end, feed, block);
    }

    /// The machine position of program point X `x`, Z `z` (program units), the other
    /// axes where they are: the lathe cycles' and G76's points.
    pub(super) fn program_xz(&self, x: f64, z: f64) -> Position {
        let scale = self.scale();
        let mut program = self.to_program(self.position);
        program[0] = x * scale;
        program[2] = z * scale;
        self.to_machine(program)
    }

    /// A rapid from where the machine is to `end` (none where it is there already): a
    /// contour of its own.
    pub(super) fn rapid_to(&mut self, end: Position, block: &Block) {
        let start = self.machine_position();
        self.position = end;
        if !no_move(&start, &end) {
            let rate = self.rapid_rate();
            self.straight(Motion::Rapid, start, end, rate, block);
        }
    }

    /// A straight move from `start` to `end` (apart: not [`no_move`]) at `feed` units per
    /// second.
    pub(super) fn straight(
        &mut self,
        motion: Motion,
        start: Position,
        end: Position,
        feed: f64,
        block: &Block,
    ) {
        let element = Element {
            kind: ElementKind::Line,
            start,
            end,
            feed,
            span: element_span(block),
        };
        self.route(motion, element);
    }

    fn arc_move(&mut self, direction: ArcDirection, request: &Request, block: &Block) {
        self.output_units.get_or_insert(Units::Millimetre);
        if self.rotation() != 0.0 && self.modal.plane != Plane::XY {
            // Turned about Z, a G18/G19 arc leaves the planes an element can lie in.
            let at = move_span(request, block);
            return self.push(GcodeDiagnostic::Unsupported {
                code: format!(
                    "G{}",
                    if direction == ArcDirection::Clockwise {
                        2
                    } else {
                        3
                    }
                ),
                feature: "G18/G19 arcs in a rotated coordinate system",
                places: 1,
                span: span(at),
            });
        }
        let end = match self.target(request) {
            Ok(end) => end,
            Err(diagnostic) => return self.push(diagnostic),
        };
        let center = self.arc_center(direction, request, block, &end);
        let turns = self.arc_turns(request);
        let start = std::mem::replace(&mut self.position, end);
        let (Some(center), Some(extra_turns)) = (center, turns) else {
            return;
        };
        let arc = Arc {
            plane: self.modal.plane,
            center,
            direction,
            extra_turns,
        };
        let length = || arc_length(&arc, &start, &end);
        let Some(feed) = self.feed_rate(request, block, length) else {
            return;
        };
        let element = Element {
            kind: ElementKind::Arc(arc),
            start,
            end,
            feed,
            span: element_span(block),
        };
        if arc.extra_turns < TURNS_HANDED_ON_WHOLE {
            return self.route(Motion::Feed, element);
        }
        for part in turn_by_turn(&element, arc) {
            self.route(Motion::Feed, part);
        }
    }

    /// Extra full turns from the P word (P1, the default, is none); at most
    /// [`crate::MAX_ARC_TURNS`] in a block and [`crate::MAX_TOTAL_ARC_TURNS`] in a run.
    fn arc_turns(&mut self, request: &Request) -> Option<u32> {
        let Some(p) = request.p else { return Some(0) };
        let rounded = p.value.round();
        if (p.value - rounded).abs() >= 1e-6 || rounded < 1.0 {
            self.push(GcodeDiagnostic::BadValue {
                word: p.name(),
                expected: "the turns of an arc must be a whole number from 1",
                span: span(p.span()),
            });
            return None;
        }
        let all = self.arc_turns_run.saturating_add(rounded as u64) > crate::MAX_TOTAL_ARC_TURNS;
        if rounded > crate::MAX_ARC_TURNS as f64 || all {
            let limit = match all {
                true => crate::MAX_TOTAL_ARC_TURNS,
                false => crate::MAX_ARC_TURNS,
            };
            let at = span(p.span());
            self.push(GcodeDiagnostic::TurnLimit {
                limit,
                all,
                span: at,
            });
            return None;
        }
        self.arc_turns_run += rounded as u64;
        Some(rounded as u32 - 1)
    }

    /// G38.2…G38.5: a feed move to where the probe trips, the next of
    /// [`crate::GcodeOptions::probe_results`], which #5061… then read; without one the
    /// block is `pvtc::gcode::probe` (where a probe stops is only known on the machine).
    fn probe_move(&mut self, mode: MotionMode, request: &Request, block: &Block) {
        let Some(&[x, y, z]) = self.options.probe_results.get(self.probes) else {
            let at = request
                .motion
                .map_or_else(|| move_span(request, block), |(_, w)| w.span());
            return self.push(GcodeDiagnostic::Probe {
                code: mode.name().to_owned(),
                span: span(at),
            });
        };
        self.probes += 1;
        let scale = self.scale();
        let mut program = self.to_program(self.machine_position());
        for (i, v) in [x, y, z].into_iter().enumerate() {
            program[i] = v * scale;
        }
        let end = self.to_machine(program);
        let start = self.machine_position();
        let length = || line_length(&start, &end);
        let feed = self.feed_rate(request, block, length);
        self.position = end;
        self.probe = Some(std::array::from_fn(|i| match i < 3 {
            true => program[i] / scale,
            false => program[i],
        }));
        if let Some(feed) = feed.filter(|_| !no_move(&start, &end)) {
            self.straight(Motion::Feed, start, end, feed, block);
        }
    }

    /// Sends an element to the sink: a rapid is a contour of its own; a feed move joins
    /// the open contour, which G61 ends after every move.
    pub(super) fn emit(&mut self, motion: Motion, element: &Element) {
        if motion == Motion::Rapid {
            self.end_contour();
        }
        self.tool.moved_with = self.tool.offset;
        // Copied (an element is large) only when the machine stands elsewhere.
        let Some(at) = self.tool.machine_at.take() else {
            return self.hand_on(motion, element);
        };
        let mut element = *element;
        let plane = match element.kind {
            ElementKind::Line => None,
            ElementKind::Arc(arc) => Some(arc.plane),
            ElementKind::Bezier(bezier) => Some(bezier.plane),
        };
        match plane {
            None => element.start = at,
            // Off its plane (a Z offset under G17) an arc or spline starts where the
            // machine is (a helix); in its plane it keeps its start and the machine
            // gets there first, straight.
            Some(plane) if plane.project(&at) == plane.project(&element.start) => {
                element.start = at;
            }
            Some(_) => {
                let to_start = Element {
                    kind: ElementKind::Line,
                    start: at,
                    end: element.start,
                    ..element
                };
                self.sink.element(motion, &to_start);
            }
        }
        self.hand_on(motion, &element);
    }

    /// Hands `element` to the sink, in the open contour (ended after a rapid, or after
    /// every move under G61).
    fn hand_on(&mut self, motion: Motion, element: &Element) {
        self.sink.element(motion, element);
        self.open = true;
        self.moved = true;
        let exact = matches!(
            self.modal.path,
            PathControl::ExactPath | PathControl::ExactStop
        );
        if motion == Motion::Rapid || exact {
            self.end_contour();
        }
    }

    /// The arc's centre in its plane, or `None` after reporting why there is none.
    fn arc_center(
        &mut self,
        direction: ArcDirection,
        request: &Request,
        block: &Block,
        end: &Position,
    ) -> Option<[f64; 2]> {
        let plane = self.modal.plane;
        let words = match center_words(plane, direction, request, block) {
            Ok(words) => words,
            Err(diagnostic) => {
                self.push(diagnostic);
                return None;
            }
        };
        let (start, end) = (plane.project(&self.position), plane.project(end));
        let scale = self.scale();
        let tolerance = self.arc_tolerance();
        let found = match words {
            CenterWords::Radius(r) => {
                arcs::center_from_radius(start, end, r.value * scale, direction, tolerance)
            }
            CenterWords::Offsets(offsets) => {
                let values = offsets.map(|w| w.map(|w| w.value));
                let offsets = self.center_offsets(plane, values, start);
                arcs::center_from_offsets(start, end, offsets, tolerance)
            }
        };
        match found {
            Ok(center) if center.iter().all(|c| c.is_finite()) => Some(center),
            Ok(center) => {
                let value = if center[0].is_finite() {
                    center[1]
                } else {
                    center[0]
                };
                let at = move_span(request, block);
                self.push(out_of_range("arc centre", value, at));
                None
            }
            Err(problem) => {
                self.report_arc_problem(problem, request, block);
                None
            }
        }
    }

    /// I/J/K as offsets from the start in the plane: G91.1 as written, G90.1 from
    /// absolute centre coordinates (work and G92 offsets applied).
    pub(super) fn center_offsets(
        &self,
        plane: Plane,
        words: [Option<f64>; 2],
        start: [f64; 2],
    ) -> [f64; 2] {
        let scale = self.scale();
        let (first, second, _) = plane.axes();
        let values = words.map(|w| w.map_or(0.0, |value| value * scale));
        if self.rotation() != 0.0 {
            // Only G17 arcs reach here in a rotated system (see `arc_move`).
            return match self.modal.arc_centers.0 {
                Distance::Incremental => self.rotate_xy(values),
                Distance::Absolute => {
                    let mut centre = self.to_program(self.position);
                    centre[..2].copy_from_slice(&values);
                    let centre = self.to_machine(centre);
                    [centre[0] - start[0], centre[1] - start[1]]
                }
            };
        }
        let mut offsets = [0.0; 2];
        for (k, axis) in [first, second].into_iter().enumerate() {
            offsets[k] = match self.modal.arc_centers.0 {
                Distance::Incremental => values[k],
                Distance::Absolute => values[k] + self.offset(axis.index()) - start[k],
            };
        }
        offsets
    }

    /// The arc tolerances of the units in force, output units (LinuxCNC's by default).
    pub(super) fn arc_tolerance(&self) -> ArcTolerance {
        let units = self.modal.units;
        let absolute =
            pvt_core::defaults::arc_abs_tolerance(self.options.arc_abs_tolerance_mm, units);
        let radius = pvt_core::defaults::arc_radius_tolerance(units);
        ArcTolerance {
            absolute: absolute * self.scale(),
            relative: self.options.arc_rel_tolerance,
            radius: radius * self.scale(),
        }
    }

    fn report_arc_problem(&mut self, problem: ArcProblem, request: &Request, block: &Block) {
        let units = self.output().name();
        let r_span = || {
            span(
                request
                    .radius
                    .map_or_else(|| move_span(request, block), |w| w.span()),
            )
        };
        let offsets_span = || {
            span(
                cover(request.offsets.iter().flatten())
                    .unwrap_or_else(|| move_span(request, block)),
            )
        };
        let tolerance = self.arc_tolerance();
        self.push(match problem {
            ArcProblem::ZeroRadius => GcodeDiagnostic::ArcZeroRadius {
                span: offsets_span(),
            },
            ArcProblem::FullCircleR => GcodeDiagnostic::ArcFullCircleR { span: r_span() },
            ArcProblem::RadiusTooSmall { radius, half_chord } => {
                GcodeDiagnostic::ArcRadiusTooSmall {
                    radius,
                    half_chord,
                    units,
                    span: r_span(),
                }
            }
            ArcProblem::RadiusMismatch {
                start_radius,
                end_radius,
            } => GcodeDiagnostic::ArcRadiusMismatch {
                start_radius,
                end_radius,
                abs_tolerance: tolerance.absolute,
                rel_tolerance: tolerance.relative,
                units,
                span: span(move_span(request, block)),
            },
        });
    }
}

/// The XY point that `@` radius and `^` angle (degrees; `None` where not given) set from
/// `from`, program units about the program origin, as LinuxCNC sets it: a word not given
/// keeps `from`'s radius or angle, and under G91 the words are added to them.
pub(super) fn polar_point(from: [f64; 2], words: [Option<f64>; 2], distance: Distance) -> [f64; 2] {
    let [x, y] = from;
    let (mut radius, mut angle) = (libm::hypot(x, y), libm::atan2(y, x));
    let [r_word, a_word] = words;
    match distance {
        Distance::Absolute => {
            radius = r_word.unwrap_or(radius);
            angle = a_word.map_or(angle, f64::to_radians);
        }
        Distance::Incremental => {
            radius += r_word.unwrap_or(0.0);
            angle += a_word.map_or(0.0, f64::to_radians);
        }
    }
    [radius * libm::cos(angle), radius * libm::sin(angle)]
}

/// Arcs of this many extra turns or more are handed on a turn at a time ([`turn_by_turn`]), so
/// that the planner's window of elements bounds the memory whatever the P word.
const TURNS_HANDED_ON_WHOLE: u32 = 4;

/// `element`, an arc of many turns, as its turns: one element per full turn from its
/// start, then the rest of its sweep. Each boundary lies on the ray of the start point
/// (so each full turn's start and end angles agree exactly), at the radius and height
/// the whole arc has there (the radius and the other axes change linearly with angle).
fn turn_by_turn(element: &Element, arc: Arc) -> impl Iterator<Item = Element> + '_ {
    let sweep = arc.sweep(&element.start, &element.end);
    let total = sweep.sweep.abs();
    let (first, second, _) = arc.plane.axes();
    let at = move |k: u32| -> Position {
        let share = std::f64::consts::TAU * f64::from(k) / total;
        let radius = sweep.start_radius + (sweep.end_radius - sweep.start_radius) * share;
        let scale = radius / sweep.start_radius;
        let mut p: Position =
            std::array::from_fn(|i| element.start[i] + (element.end[i] - element.start[i]) * share);
        for (axis, centre) in [first, second].into_iter().zip(arc.center) {
            let i = axis.index();
            p[i] = centre + (element.start[i] - centre) * scale;
        }
        p
    };
    let part = Arc {
        extra_turns: 0,
        ..arc
    };
    (0..=arc.extra_turns).map(move |k| Element {
        kind: ElementKind::Arc(part),
        start: at(k),
        end: if k == arc.extra_turns {
            element.end
        } else {
            at(k + 1)
        },
        ..*element
    })
}

/// How a block gives its arc's centre: offsets in the plane's (first, second) order, or R.
#[derive(Debug, Clone, Copy)]
enum CenterWords {
    Offsets([Option<Word>; 2]),
    Radius(Word),
}

/// The centre words of an arc block in `plane`, or the diagnostic for a wrong set.
fn center_words(
    plane: Plane,
    direction: ArcDirection,
    request: &Request,
    block: &Block,
) -> Result<CenterWords, GcodeDiagnostic> {
    let (first, second, normal) = plane.axes();
    if let Some(word) = request.offsets[normal.index()] {
        let (name, plane, at) = (word.name(), plane_name(plane), span(word.span()));
        return Err(GcodeDiagnostic::ArcOffsetOffPlane {
            word: name,
            plane,
            span: at,
        });
    }
    let offsets = [
        request.offsets[first.index()],
        request.offsets[second.index()],
    ];
    match (offsets, request.radius) {
        ([None, None], None) => {
            let mode = MotionMode::Arc(direction).name();
            let at = request
                .motion
                .map_or_else(|| move_span(request, block), |(_, w)| w.span());
            Err(GcodeDiagnostic::ArcMissingCenter {
                mode,
                span: span(at),
            })
        }
        ([None, None], Some(r)) => Ok(CenterWords::Radius(r)),
        (_, Some(r)) => Err(GcodeDiagnostic::ArcRWithCenter {
            span: span(r.span()),
        }),
        (offsets, None) => Ok(CenterWords::Offsets(offsets)),
    }
}

/// The words that make the move (motion code, axes, centre), or the whole block.
pub(super) fn move_span(request: &Request, block: &Block) -> Range<usize> {
    let motion = request.motion.as_ref().map(|(_, w)| w);
    let words = motion
        .into_iter()
        .chain(request.axis_words())
        .chain(request.offsets.iter().flatten())
        .chain(&request.radius);
    cover(words).unwrap_or_else(|| block.span())
}

pub(super) fn element_span(block: &Block) -> Span {
    Span {
        start: block.start,
        end: block.end,
        line: block.line,
    }
}

fn out_of_range(what: &'static str, value: f64, at: Range<usize>) -> GcodeDiagnostic {
    GcodeDiagnostic::OutOfRange {
        what,
        value,
        span: span(at),
    }
}

fn plane_name(plane: Plane) -> &'static str {
    match plane {
        Plane::XY => "XY (G17)",
        Plane::ZX => "ZX (G18)",
        Plane::YZ => "YZ (G19)",
    }
}

/// True when a straight move from `start` to `end` moves no axis by more than the
/// rounding of the arithmetic that made its end: each axis within four units in the last
/// place of its larger coordinate, or of 1 (`G91 G1 Z-2.9` from Z3 ends at
/// 0.10000000000000009, and `G90 Z0.1` after it is no move). Such a move is dropped as
/// zero-length, as rs274's is where its printed end is its start.
pub(super) fn no_move(start: &Position, end: &Position) -> bool {
    start.iter().zip(end).all(|(a, b)| {
        let unit = a.abs().max(b.abs()).max(1.0);
        (a - b).abs() <= 4.0 * f64::EPSILON * unit
    })
}

/// Length of a straight move as the planner measures path length: Euclidean over every
/// axis, rotary degrees included, so a G93 move takes its 1/F minutes.
fn line_length(start: &[f64], end: &[f64]) -> f64 {
    start
        .iter()
        .zip(end)
        .map(|(a, b)| (b - a) * (b - a))
        .sum::<f64>()
        .sqrt()
}

/// Length of a (helical) arc: the mean-radius sweep in its plane and every other axis's
/// change, measured as [`line_length`] does.
fn arc_length(arc: &Arc, start: &Position, end: &Position) -> f64 {
    let sweep = arc.sweep(start, end);
    let in_plane = sweep.sweep.abs() * (sweep.start_radius + sweep.end_radius) / 2.0;
    let (first, second, _) = arc.plane.axes();
    let others: f64 = (0..start.len())
        .filter(|&i| i != first.index() && i != second.index())
        .map(|i| (end[i] - start[i]) * (end[i] - start[i]))
        .sum();
    (in_plane * in_plane + others).sqrt()
}

/// A feed of `per_minute`, units per second; `None` when it is not positive and finite
/// (`pvtc::gcode::zero_feed`).
pub(super) fn feed_per_second(per_minute: f64) -> Option<f64> {
    (per_minute > 0.0 && per_minute.is_finite()).then(|| per_minute / 60.0)
}

#[cfg(test)]
mod tests {
    use super::no_move;

    /// A move of the arithmetic's rounding alone is no move; a move of a program's
    /// smallest written step (or far less) is one.
    #[test]
    fn a_move_of_rounding_alone_is_no_move() {
        let at = |x: f64, z: f64| [x, 0.0, z, 0.0, 0.0, 0.0];
        // Z3 then G91 Z-2.9 ends 9e-17 past Z0.1.
        assert_ne!(3.0 + -2.9, 0.1);
        assert!(no_move(&at(0.0, 3.0 + -2.9), &at(0.0, 0.1)));
        assert!(no_move(
            &at(1e6, 0.0),
            &at(1e6 + 2.0 * f64::EPSILON * 1e6, 0.0)
        ));
        assert!(!no_move(&at(0.0, 0.1), &at(0.0, 0.1001)));
        assert!(!no_move(&at(0.0, 0.0), &at(1e-12, 0.0)));
        assert!(!no_move(&at(1e6, 0.0), &at(1e6 + 1e-6, 0.0)));
    }
}

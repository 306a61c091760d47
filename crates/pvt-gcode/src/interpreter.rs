//! The modal interpreter: blocks in program order to toolpath elements and events.
//!
//! Owns the modal state ([`modal::Modal`]: motion, plane, units, distance and arc-centre
//! modes, feed mode and feed, path control, lathe diameter mode, coordinate system,
//! spindle and coolant), the G92 offsets, the current position, and what each step of a
//! block does; the steps run in the order of [`order::ORDER`], LinuxCNC's (F and S
//! before the block's G20/G21, M6 before G43, motion last but the stop).
//! It hands elements and events to a [`ToolpathSink`] as they are made and keeps none;
//! it must not parse text (that is [`crate::parser`]) nor compute arc centres (that is
//! [`crate::arcs`]). Its moves live in [`motion`].
//!
//! Positions are machine coordinates in output units: a program coordinate plus the G92
//! offset, turned in XY by the active system's rotation (G10 L2 R), plus the work offset
//! (G54…G59.3, from [`GcodeOptions::work_offsets`]) and the tool length offset; one pair
//! of functions (`to_machine`, `to_program`) makes that transform and its inverse. Rotary
//! axes are degrees and never converted. Every axis starts at 0.

mod compensation;
mod cycles;
mod lathe;
mod machine;
mod modal;
mod motion;
mod nurbs;
mod nurbs_g6;
mod order;
mod plain;
mod spline;
mod threading;

use pvt_core::{CoolantState, EventKind, PathControl, Position, Units, AXIS_COUNT};

pub(crate) use modal::Feed;
use modal::{ArcCenters, Modal};
use order::{Step, ORDER};

use crate::block::{Block, Word};
use crate::codes::{Distance, FeedMode, MotionMode, NonModal, PathMode};
use crate::diagnostic::{span, GcodeDiagnostic};
use crate::kept::Kept;
use crate::params::machine::MachineView;
use crate::request::{Request, Stop};
use crate::{GcodeErrors, GcodeOptions, StreamSummary, ToolpathSink};

/// Whether to read on after a block.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Flow {
    /// Read the next block.
    Continue,
    /// M2/M30: the program ends with this word.
    End(Word),
}

/// Executes blocks one at a time, streaming the toolpath into a sink.
pub(crate) struct Interpreter<'a> {
    options: &'a GcodeOptions,
    sink: &'a mut dyn ToolpathSink,
    modal: Modal,
    output_units: Option<Units>,
    position: Position,
    /// A missing or bad feed was reported and no F word came since.
    feed_reported: bool,
    /// G92 offsets and those G92.2 kept, output units.
    g92: Position,
    g92_kept: Position,
    /// Elements were sent since the last end of contour.
    open: bool,
    /// Any element was sent.
    moved: bool,
    path_tolerance: Option<f64>,
    errors: Kept,
    warnings: Kept,
    /// Set while a block whose line has a syntax error runs: its diagnostics are dropped.
    quiet: bool,
    /// Diagnostics of the block being read, before they are sorted into the two above.
    pending: Vec<GcodeDiagnostic>,
    /// The request of the block being executed, its storage reused from block to block.
    request: Option<Box<Request>>,
    /// Work offsets G54…G59.3 (rows; X Y Z millimetres, A B C degrees), from
    /// [`GcodeOptions::work_offsets`] and changed by G10 L2/L20.
    pub(crate) work_offsets: [[f64; AXIS_COUNT]; 9],
    /// The XY rotation of each coordinate system G54…G59.3 (#5230…), degrees
    /// counter-clockwise about the work origin; set by G10 L2/L20 R.
    pub(crate) rotations: [f64; 9],
    /// The tool table, from [`GcodeOptions::tool_table`] and changed by G10 L1/L10/L11.
    pub(crate) tools: crate::ToolTable,
    /// Tool selected and loaded, and the tool length offset in effect.
    pub(crate) tool: machine::ToolState,
    /// G28 and G30 home positions (#5161…, #5181…): machine positions, output units.
    pub(crate) homes: [Position; 2],
    /// Canned cycle levels kept between blocks, and the G98/G99 mode.
    pub(crate) cycle: cycles::CycleMemory,
    /// The last G64 Q (P where Q is not given): LinuxCNC's naive-CAM tolerance, output
    /// units; recorded, not applied.
    pub(crate) naive_cam_tolerance: Option<f64>,
    /// The modal state M70/M73 saved at each call level (the main program first).
    frames: Vec<Option<modal::Frame>>,
    /// `pvtc::gcode::spindle_rpm_exact` was given.
    spindle_sync_warned: bool,
    /// A lathe cycle waiting for, or reading, its profile.
    lathe: Option<Box<lathe::LatheRun>>,
    /// Set while held lines run (a loop or subroutine body, which may run many times):
    /// a diagnostic kept already is not kept again.
    pub once: bool,
    /// Set while a subroutine file runs: its diagnostics are shown at the call.
    pub origin: Option<crate::oword::Origin>,
    /// Arc turns (P words) of the run so far.
    arc_turns_run: u64,
    /// Probing moves run so far (the next takes that many results in).
    pub(crate) probes: usize,
    /// Where the last probing move tripped, program units (#5061…).
    pub(crate) probe: Option<[f64; 6]>,
    /// Cutter-radius compensation (G40/G41/G42).
    cutter: compensation::CutterState,
    /// The last G5's P Q (machine frame, output units): a G5 without I J continues it.
    last_spline: Option<[f64; 2]>,
    /// The NURBS block being gathered: G5.2 until its G5.3, G6.2 until its last knot.
    nurbs: Option<nurbs::NurbsBlock>,
}

impl<'a> Interpreter<'a> {
    /// A machine at 0 in every axis, in G17 G21 G90 G91.1 G94 G64 G54 G8 state.
    pub fn new(options: &'a GcodeOptions, sink: &'a mut dyn ToolpathSink) -> Self {
        Interpreter {
            options,
            sink,
            modal: Modal::default(),
            output_units: options.units,
            position: [0.0; AXIS_COUNT],
            feed_reported: false,
            g92: [0.0; AXIS_COUNT],
            g92_kept: [0.0; AXIS_COUNT],
            open: false,
            moved: false,
            path_tolerance: None,
            errors: Kept::default(),
            warnings: Kept::default(),
            quiet: false,
            pending: Vec::new(),
            request: None,
            work_offsets: options.work_offsets,
            rotations: [0.0; 9],
            tools: options.tool_table.clone(),
            tool: machine::ToolState::default(),
            homes: [[0.0; AXIS_COUNT]; 2],
            cycle: cycles::CycleMemory::default(),
            naive_cam_tolerance: None,
            frames: vec![None],
            spindle_sync_warned: false,
            lathe: None,
            once: false,
            origin: None,
            arc_turns_run: 0,
            probes: 0,
            probe: None,
            cutter: compensation::CutterState::default(),
            last_spline: None,
            nurbs: None,
        }
    }

    /// A program's write to a numbered parameter that holds interpreter state: the G28
    /// and G30 homes (#5161–#5166, #5181–#5186, millimetres or degrees, as they read) move
    /// where the next G28/G30 goes, as LinuxCNC reads its homes from those parameters.
    pub fn parameter_written(&mut self, index: usize, value: f64) {
        let home = [(0, 5161), (1, 5181)].into_iter().find_map(|(row, first)| {
            let axis = index.checked_sub(first).filter(|axis| *axis < AXIS_COUNT)?;
            Some((row, axis))
        });
        let Some((row, axis)) = home else {
            return;
        };
        let rotary = pvt_core::Axis::ALL[axis].is_rotary();
        let units = *self.output_units.get_or_insert(self.modal.units);
        self.homes[row][axis] = if rotary {
            value
        } else {
            value / units.mm_per_unit()
        };
    }

    /// The state machine parameters read (see [`crate::params::machine`]), in program
    /// units, as it stands after the last block; stored offsets, homes and tool offsets in
    /// millimetres (degrees for A B C).
    pub fn view(&self) -> MachineView {
        let scale = self.scale();
        let mm = self.output().mm_per_unit();
        let linear = |i: usize| !pvt_core::Axis::ALL.get(i).is_some_and(|a| a.is_rotary());
        let mut position = self.to_program(self.position);
        for (i, p) in position.iter_mut().enumerate() {
            if linear(i) {
                *p /= scale;
            }
        }
        let to_mm = |v: &Position| -> Position {
            std::array::from_fn(|i| if linear(i) { v[i] * mm } else { v[i] })
        };
        let m = &self.modal;
        MachineView {
            position,
            g92: to_mm(&self.g92),
            g92_active: self.g92.iter().any(|v| *v != 0.0),
            coord_system: m.coord_system,
            mm_per_unit: m.units.mm_per_unit(),
            absolute: m.distance == Distance::Absolute,
            inverse_time: m.feed_mode == FeedMode::InverseTime,
            motion_tenths: match m.motion {
                None => 0,
                Some(MotionMode::Rapid) => 0,
                Some(MotionMode::Linear) => 10,
                Some(MotionMode::Arc(pvt_core::ArcDirection::Clockwise)) => 20,
                Some(MotionMode::Arc(pvt_core::ArcDirection::CounterClockwise)) => 30,
                Some(MotionMode::Probe(tenths)) => tenths as i32,
                Some(_) => 800,
            },
            plane_tenths: match m.plane {
                pvt_core::Plane::XY => 170,
                pvt_core::Plane::ZX => 180,
                pvt_core::Plane::YZ => 190,
            },
            feed: m.feed.map_or(0.0, |f| f.written),
            rpm: m.speed,
            current_tool: f64::from(self.tool.current),
            selected_tool: self.tool.selected.map_or(0.0, f64::from),
            tool_offset: to_mm(&self.tool.offset),
            tool_diameter: self
                .tools
                .get(self.tool.current)
                .map_or(0.0, |t| t.diameter),
            work_offsets: self.work_offsets,
            rotations: self.rotations,
            homes: [to_mm(&self.homes[0]), to_mm(&self.homes[1])],
            line: 0,
            call_level: 0,
            probe: self.probe,
        }
    }

    /// Records a diagnostic found outside the interpreter (a syntax error).
    pub fn report(&mut self, diagnostic: GcodeDiagnostic) {
        self.push(diagnostic);
    }

    /// Records a warning.
    pub fn warn(&mut self, diagnostic: GcodeDiagnostic) {
        if !self.quiet {
            let diagnostic = self.wrap(diagnostic);
            if !(self.once && self.warnings.contains(&diagnostic)) {
                self.warnings.push(diagnostic);
            }
        }
    }

    /// `diagnostic` as shown from the main program.
    fn wrap(&self, diagnostic: GcodeDiagnostic) -> GcodeDiagnostic {
        match &self.origin {
            Some(origin) => origin.wrap(diagnostic),
            None => diagnostic,
        }
    }

    /// Executes one block in RS274NGC order (see the module documentation).
    pub fn execute(&mut self, block: &Block) -> Flow {
        if self.recording_profile() {
            // A lathe cycle's profile: its motion words only.
            self.profile_block(block);
            return Flow::Continue;
        }
        let mut request = self.request.take().unwrap_or_default();
        request.read(block, &mut self.pending);
        let flow = self.execute_request(&request, block);
        self.request = Some(request);
        flow
    }

    fn execute_request(&mut self, request: &Request, block: &Block) -> Flow {
        if !self.pending.is_empty() {
            let mut pending = std::mem::take(&mut self.pending);
            for d in pending.drain(..) {
                self.push(d);
            }
            self.pending = pending;
        }
        if request.unknown_g {
            // What the unknown code would do is unknown: nothing of the block runs, and
            // blocks in its motion mode are skipped without further errors.
            self.modal.motion = Some(crate::codes::MotionMode::Unsupported);
            return Flow::Continue;
        }
        for step in ORDER {
            if let Some(flow) = self.run_step(step, request, block) {
                return flow;
            }
        }
        Flow::Continue
    }

    /// Runs one step of a block ([`order::Step`]); the flow when the step ends the block.
    fn run_step(&mut self, step: Step, request: &Request, block: &Block) -> Option<Flow> {
        let line = block.line;
        let m = &mut self.modal;
        match step {
            Step::Comment => {
                if let Some(text) = &block.message {
                    self.event(EventKind::Message { text: text.clone() }, line);
                }
            }
            Step::SpindleMode => {
                if let Some((css, _)) = request.surface_speed {
                    m.surface_speed = css;
                }
            }
            Step::FeedMode => self.set_feed_mode(request),
            Step::Feed => self.set_feed(request),
            Step::Speed => self.set_speed(request, line),
            Step::SelectTool => self.select_tool(request, line),
            Step::Io => self.code_event(request.io, request, line),
            Step::ChangeTool => self.change_tool(request, line),
            Step::Spindle => self.set_spindle(request, line),
            Step::Coolant => self.set_coolant(request, line),
            // M48…M53 are accepted as state: pvtc plans at 100 %.
            Step::Overrides => {}
            Step::User => self.code_event(request.user, request, line),
            Step::Dwell => self.dwell(request, line),
            Step::Plane => m.plane = request.plane.map_or(m.plane, |(p, _)| p),
            Step::Units => self.set_units(request),
            Step::LatheDiameter => m.diameter = request.diameter.map_or(m.diameter, |(d, _)| d),
            Step::CutterComp => self.set_compensation(request),
            Step::ToolLength => self.set_tool_length(request),
            Step::CoordSystem => {
                m.coord_system = request.coord_system.map_or(m.coord_system, |(c, _)| c)
            }
            Step::PathControl => self.set_path_control(request),
            Step::Distance => m.distance = request.distance.map_or(m.distance, |(d, _)| d),
            Step::ArcDistance => {
                if let Some((centers, _)) = request.arc_centers {
                    m.arc_centers = ArcCenters(centers);
                }
            }
            Step::Retract => m.retract_to_r = request.retract.map_or(m.retract_to_r, |(r, _)| r),
            Step::NonModal => {
                self.set_offsets(request);
                self.set_tables(request);
                self.home(request, block);
            }
            Step::Motion => {
                self.set_motion_mode(request);
                self.check_p_word(request);
                self.check_words(request);
                self.run_motion(request, block);
                self.reread_after_tool_change(request);
            }
            Step::Stop => return Some(self.stop(request, line)),
        }
        None
    }

    /// M0/M1 (a pause), M2/M30 (the end), or none.
    fn stop(&mut self, request: &Request, line: u32) -> Flow {
        match request.stop {
            Some((Stop::Pause(optional), _)) => {
                self.event(EventKind::Pause { optional }, line);
                Flow::Continue
            }
            Some((Stop::End, word)) => {
                self.nurbs_unclosed();
                self.finish_compensation(word.span());
                Flow::End(word)
            }
            None => Flow::Continue,
        }
    }

    /// Executes a block whose line had a syntax error, reporting nothing more about it.
    pub fn execute_quietly(&mut self, block: &Block) -> Flow {
        self.quiet = true;
        let flow = self.execute(block);
        self.quiet = false;
        flow
    }

    /// Ends the last contour; the summary, or every error in source order.
    pub fn finish(mut self) -> Result<StreamSummary, GcodeErrors> {
        self.nurbs_unclosed();
        self.finish_compensation(0..0);
        self.end_contour();
        if self.errors.is_empty() && !self.moved {
            self.errors
                .push(GcodeDiagnostic::NoMotion { span: span(0..0) });
        }
        if !self.errors.is_empty() {
            let diagnostics = self
                .errors
                .into_sorted(|count, span| GcodeDiagnostic::MoreErrors { count, span });
            return Err(GcodeErrors { diagnostics });
        }
        Ok(StreamSummary {
            units: self.output(),
            warnings: self
                .warnings
                .into_sorted(|count, span| GcodeDiagnostic::MoreWarnings { count, span }),
            path_tolerance: self.path_tolerance,
            naive_cam_tolerance: self.naive_cam_tolerance,
        })
    }

    fn push(&mut self, diagnostic: GcodeDiagnostic) {
        if self.quiet {
            return;
        }
        let diagnostic = self.wrap(diagnostic);
        if self.once && (self.errors.contains(&diagnostic) || self.warnings.contains(&diagnostic)) {
            return;
        }
        if diagnostic.is_warning() {
            self.warnings.push(diagnostic);
        } else {
            self.errors.push(diagnostic);
        }
    }

    /// Ends the current contour, if one is open: the machine comes to rest.
    fn end_contour(&mut self) {
        if self.open {
            self.open = false;
            self.sink.end_contour();
        }
    }

    /// An event, at rest: it ends the current contour.
    fn event(&mut self, kind: EventKind, line: u32) {
        let Some(kind) = self.compensated_event(kind, line) else {
            return;
        };
        self.end_contour();
        self.sink.event(&kind, line);
    }

    /// S: the spindle speed (an event, but under G96, where S is a surface speed).
    fn set_speed(&mut self, request: &Request, line: u32) {
        let Some(s) = request.s else { return };
        if s.value < 0.0 {
            return self.push(bad_value(s, "a spindle speed must not be negative"));
        }
        self.modal.speed = s.value;
        if !self.modal.surface_speed {
            self.event(EventKind::SpindleSpeed { rpm: s.value }, line);
        }
    }

    /// T: select a tool.
    fn select_tool(&mut self, request: &Request, line: u32) {
        let Some(t) = request.t else { return };
        match whole(t.value) {
            Some(tool) => {
                self.tool.selected = Some(tool);
                self.event(EventKind::ToolSelect { tool }, line);
            }
            None => self.push(bad_value(t, "a tool number must be a whole number ≥ 0")),
        }
    }

    /// M6: the spindle stops, as LinuxCNC stops it for a tool change, and the selected
    /// tool is loaded (before G43 of the same block reads it).
    fn change_tool(&mut self, request: &Request, line: u32) {
        if request.tool_change.is_none() {
            return;
        }
        self.modal.spindle = pvt_core::SpindleState::Off;
        let off = pvt_core::SpindleState::Off;
        self.event(EventKind::Spindle { state: off }, line);
        self.event(EventKind::ToolChange, line);
        if let Some(t) = self.tool.selected {
            self.tool.current = t;
        }
    }

    /// M3/M4/M5, or M70…M73 (one modal group).
    fn set_spindle(&mut self, request: &Request, line: u32) {
        if let Some((code, word)) = request.context {
            self.modal_context(code, word, line);
        }
        if let Some((state, _)) = request.spindle {
            self.modal.spindle = state;
            self.event(EventKind::Spindle { state }, line);
        }
    }

    /// M7/M8/M9.
    fn set_coolant(&mut self, request: &Request, line: u32) {
        let Some((state, _)) = request.coolant else {
            return;
        };
        match state {
            CoolantState::Mist => self.modal.mist = true,
            CoolantState::Flood => self.modal.flood = true,
            CoolantState::Off => (self.modal.mist, self.modal.flood) = (false, false),
        }
        self.event(EventKind::Coolant { state }, line);
    }

    /// M62…M68 or M100…M199 as an event with the block's P, Q, E and L words.
    fn code_event(&mut self, code: Option<(u16, Word)>, request: &Request, line: u32) {
        let Some((code, _)) = code else { return };
        let value = |w: Option<Word>| w.map(|w| w.value);
        let words = pvt_core::CodeWords {
            p: value(request.p),
            q: value(request.q),
            e: value(request.e),
            l: value(request.l),
        };
        if let Some(kind) = EventKind::machine_code(code, words) {
            self.event(kind, line);
        }
    }

    /// G4: dwell P seconds.
    fn dwell(&mut self, request: &Request, line: u32) {
        let Some((NonModal::Dwell, g4)) = request.non_modal else {
            return;
        };
        match request.p {
            Some(p) if p.value >= 0.0 => self.event(EventKind::Dwell { seconds: p.value }, line),
            Some(p) => self.push(bad_value(p, "a dwell time must not be negative")),
            None => self.push(missing(g4, "a P word (seconds)")),
        }
    }

    /// A P word no code of the block uses is a warning.
    fn check_p_word(&mut self, request: &Request) {
        let Some(p) = request.p else { return };
        if self.modal.motion == Some(MotionMode::Unsupported) {
            return; // the unsupported code was reported; its words are not checked
        }
        let used = matches!(
            request.non_modal,
            Some((NonModal::Dwell | NonModal::SetTable, _))
        ) || matches!(request.path_mode, Some((PathMode::Continuous, _)))
            || matches!(self.modal.motion, Some(MotionMode::LatheCycle(_)))
            || request.overrides.is_some()
            || request.io.is_some()
            || request.user.is_some()
            || matches!(
                self.modal.motion,
                Some(
                    MotionMode::Arc(_)
                        | MotionMode::Cycle(_)
                        | MotionMode::Nurbs
                        | MotionMode::NurbsKnots
                        | MotionMode::ThreadCycle
                )
            );
        if !used {
            self.push(GcodeDiagnostic::IgnoredWord {
                word: p.name(),
                reason: "no code of this block takes P (G4, G64, G2/G3 do)",
                span: span(p.span()),
            });
        }
    }

    /// The output units (millimetres until a G20/G21 or a move decides them).
    fn output(&self) -> Units {
        self.output_units.unwrap_or_default()
    }

    /// Output units per program unit, for linear coordinates and feeds.
    fn scale(&self) -> f64 {
        self.modal.units.mm_per_unit() / self.output().mm_per_unit()
    }

    /// G20/G21. An F of the same block was read in the units before it, as LinuxCNC
    /// reads it: `pvtc::gcode::feed_before_units` says so.
    fn set_units(&mut self, request: &Request) {
        let Some((units, word)) = request.units else {
            return;
        };
        if let (Some(f), Some(feed)) = (request.feed, self.modal.feed) {
            let read_in_old = feed.units != units && self.modal.feed_mode != FeedMode::InverseTime;
            if read_in_old && f.value > 0.0 {
                self.warn(feed_before_units(f, feed.units, word, units));
            }
        }
        self.output_units.get_or_insert(units);
        self.modal.units = units;
    }

    /// G61, G61.1, G64 with P and Q: the path control mode, handed on from the next move;
    /// G64 P (not 0) is the path tolerance from the next contour on. G64 P0 is plain G64,
    /// as rs274 reads it: no tolerance of its own.
    fn set_path_control(&mut self, request: &Request) {
        let Some((mode, _)) = request.path_mode else {
            return;
        };
        let control = match mode {
            PathMode::ExactPath => PathControl::ExactPath,
            PathMode::ExactStop => PathControl::ExactStop,
            PathMode::Continuous => {
                let p = request.p.map_or(0.0, |p| p.value.abs());
                let q = request.q.map_or(p, |q| q.value.abs());
                self.naive_cam_tolerance = (q > 0.0).then(|| q * self.scale());
                PathControl::Continuous {
                    tolerance: p,
                    naive_cam_tolerance: q,
                }
            }
        };
        self.modal.path = control;
        self.hand_on_control(control);
        let Some(p) = request
            .p
            .filter(|p| p.value != 0.0 && mode == PathMode::Continuous)
        else {
            return;
        };
        if p.value.abs() < pvt_core::ChordTolerance::SMALLEST {
            return self.push(GcodeDiagnostic::BadValue {
                word: p.name(),
                expected: "a path tolerance of at least 0.000001 (program units), or P0 for none",
                span: span(p.span()),
            });
        }
        let tolerance = p.value.abs() * self.scale();
        self.path_tolerance = Some(tolerance);
        self.sink.path_tolerance(tolerance);
    }

    /// Hands the path control mode `control` (program units) on to the sink, in output
    /// units.
    fn hand_on_control(&mut self, control: PathControl) {
        let scale = self.scale();
        self.sink.path_control(&match control {
            PathControl::Continuous {
                tolerance,
                naive_cam_tolerance,
            } => PathControl::Continuous {
                tolerance: tolerance * scale,
                naive_cam_tolerance: naive_cam_tolerance * scale,
            },
            other => other,
        });
    }

    /// The motion mode of the block (G0…G3, a cycle, …), which a motion code other than a
    /// cycle's ends the canned cycles with.
    fn set_motion_mode(&mut self, request: &Request) {
        let Some((mode, _)) = request.motion else {
            return;
        };
        self.modal.motion = Some(mode);
        if !matches!(mode, MotionMode::Cycle(_)) {
            self.cycle.code = None;
            self.cycle.initial_level = None;
        }
    }

    /// The work plus G92 plus tool length offset of axis `i`, output units (degrees for rotary axes).
    fn offset(&self, i: usize) -> f64 {
        self.work(i) + self.g92[i] + self.tool.offset[i]
    }

    /// The work offset of axis `i` in the active system, output units (degrees for
    /// rotary axes).
    fn work(&self, i: usize) -> f64 {
        let work = self
            .work_offsets
            .get(self.modal.coord_system)
            .map_or(0.0, |w| w[i]);
        match pvt_core::Axis::ALL.get(i) {
            Some(axis) if axis.is_rotary() => work,
            _ => self.output().from_mm(work),
        }
    }

    /// The XY rotation of the active coordinate system, degrees.
    fn rotation(&self) -> f64 {
        self.rotations
            .get(self.modal.coord_system)
            .copied()
            .unwrap_or(0.0)
    }

    /// Program coordinates (output units, degrees for rotary axes) to machine
    /// coordinates: plus the G92 offset, rotated about the work origin by the active
    /// system's XY rotation, plus the work and tool length offsets. The one place the
    /// rotation is applied; without rotation each axis is `program + offset(i)`.
    fn to_machine(&self, program: Position) -> Position {
        let mut machine: Position = std::array::from_fn(|i| program[i] + self.offset(i));
        let rotation = self.rotation();
        if rotation != 0.0 {
            let (sin, cos) = libm::sincos(rotation.to_radians());
            let (x, y) = (program[0] + self.g92[0], program[1] + self.g92[1]);
            machine[0] = x * cos - y * sin + self.work(0) + self.tool.offset[0];
            machine[1] = x * sin + y * cos + self.work(1) + self.tool.offset[1];
        }
        machine
    }

    /// Machine coordinates to program coordinates: the inverse of [`Self::to_machine`].
    fn to_program(&self, machine: Position) -> Position {
        let mut program: Position = std::array::from_fn(|i| machine[i] - self.offset(i));
        let rotation = self.rotation();
        if rotation != 0.0 {
            let (sin, cos) = libm::sincos(rotation.to_radians());
            let x = machine[0] - self.work(0) - self.tool.offset[0];
            let y = machine[1] - self.work(1) - self.tool.offset[1];
            program[0] = x * cos + y * sin - self.g92[0];
            program[1] = -x * sin + y * cos - self.g92[1];
        }
        program
    }

    /// A vector (I J offsets, say) in the program's XY plane turned into the machine's.
    fn rotate_xy(&self, v: [f64; 2]) -> [f64; 2] {
        let rotation = self.rotation();
        if rotation == 0.0 {
            return v;
        }
        let (sin, cos) = libm::sincos(rotation.to_radians());
        [v[0] * cos - v[1] * sin, v[0] * sin + v[1] * cos]
    }

    /// G92, G92.1, G92.2, G92.3.
    fn set_offsets(&mut self, request: &Request) {
        let Some((code, word)) = request.non_modal else {
            return;
        };
        match code {
            NonModal::SetOffset => {
                if !request.has_axis_words() {
                    return self.push(missing(word, "at least one axis word"));
                }
                self.output_units.get_or_insert(self.modal.units);
                // The offset that makes the current position read `wanted`: in the
                // rotated frame, so from the program position plus the old offset.
                let program = self.to_program(self.position);
                let rotated = self.rotation() != 0.0;
                for axis in pvt_core::Axis::ALL {
                    let i = axis.index();
                    if let Some(w) = request.axes[i] {
                        let wanted = self.program_value(axis, w.value);
                        self.g92[i] = match rotated && i < 2 {
                            true => program[i] + self.g92[i] - wanted,
                            false => self.position[i] - (self.offset(i) - self.g92[i]) - wanted,
                        };
                    }
                }
            }
            NonModal::ClearOffset { keep } => {
                self.g92_kept = if keep { self.g92 } else { [0.0; AXIS_COUNT] };
                self.g92 = [0.0; AXIS_COUNT];
            }
            NonModal::RestoreOffset => self.g92 = self.g92_kept,
            NonModal::Dwell
            | NonModal::MachineCoords
            | NonModal::Home(_)
            | NonModal::SetHome(_)
            | NonModal::SetTable
            | NonModal::LocalOffset => {}
        }
    }

    /// An axis word's value in output units (degrees for rotary axes), G7 applied.
    fn program_value(&self, axis: pvt_core::Axis, value: f64) -> f64 {
        let value = if self.modal.diameter && axis == pvt_core::Axis::X {
            value / 2.0
        } else {
            value
        };
        if axis.is_rotary() {
            value
        } else {
            value * self.scale()
        }
    }
}

/// `pvtc::gcode::feed_before_units` for the F word `f`, read in `old` units, in a block
/// whose units code `code` sets `new`.
fn feed_before_units(f: Word, old: Units, code: Word, new: Units) -> GcodeDiagnostic {
    GcodeDiagnostic::FeedBeforeUnits {
        feed: f.name(),
        value: f.value,
        converted: f.value * old.mm_per_unit() / new.mm_per_unit(),
        old: old.name(),
        new: new.name(),
        code: code.name(),
        span: span(f.span()),
    }
}

/// `value` as a tool number: whole, ≥ 0, within `u32`.
fn whole(value: f64) -> Option<u32> {
    let rounded = value.round();
    ((value - rounded).abs() < 1e-6 && (0.0..=f64::from(u32::MAX)).contains(&rounded))
        .then_some(rounded as u32)
}

fn bad_value(word: Word, expected: &'static str) -> GcodeDiagnostic {
    GcodeDiagnostic::BadValue {
        word: word.name(),
        expected,
        span: span(word.span()),
    }
}

/// `code` at `at` lacks what it `needs`.
fn missing_at(code: &str, at: std::ops::Range<usize>, needs: &'static str) -> GcodeDiagnostic {
    GcodeDiagnostic::MissingWord {
        code: code.to_owned(),
        needs,
        span: span(at),
    }
}

fn missing(word: Word, needs: &'static str) -> GcodeDiagnostic {
    GcodeDiagnostic::MissingWord {
        code: word.name(),
        needs,
        span: span(word.span()),
    }
}

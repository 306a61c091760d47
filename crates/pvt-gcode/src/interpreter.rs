//! The modal interpreter: blocks in program order to toolpath elements.
//!
//! Owns the modal state (motion mode, plane, length units, distance mode, feed), the
//! current position and the order in which one block's words take effect: plane, units,
//! distance mode, feed, motion, stop. It must not parse text (that is [`crate::parser`])
//! nor compute arc centres (that is [`crate::arcs`]).
//!
//! Units: the output is in the units of the first G20/G21, or millimetres when a move
//! comes first; later coordinates, offsets and feeds are converted into them. Rotary
//! axes are degrees and never converted. Every axis starts at 0.

use std::ops::Range;

use pvt_core::{
    Arc, ArcDirection, Axis, Element, ElementKind, Motion, Plane, Position, Span, Toolpath, Units,
};

use crate::arcs::{self, ArcProblem, ArcTolerance};
use crate::block::{cover, Block, Word};
use crate::codes::{Distance, MotionMode};
use crate::contours::Contours;
use crate::diagnostic::{span, GcodeDiagnostic};
use crate::request::{Request, Stop};
use crate::{Compiled, GcodeErrors, GcodeOptions};

/// Whether to read on after a block.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Flow {
    /// Read the next block.
    Continue,
    /// M2/M30: the program ends with this word.
    End(Word),
}

/// The modal state RS274NGC keeps between blocks (the part this cut uses).
#[derive(Debug, Clone, Copy, Default)]
struct Modal {
    motion: Option<MotionMode>,
    plane: Plane,
    units: Units,
    distance: Distance,
}

/// The feed in effect: as written, and in output units per minute.
#[derive(Debug, Clone, Copy)]
struct Feed {
    written: f64,
    per_minute: f64,
}

/// Executes blocks one at a time and collects the toolpath and diagnostics.
pub(crate) struct Interpreter<'a> {
    options: &'a GcodeOptions,
    modal: Modal,
    output_units: Option<Units>,
    position: Position,
    feed: Option<Feed>,
    /// A missing or bad feed was reported and no F word came since.
    feed_reported: bool,
    contours: Contours,
    errors: Vec<GcodeDiagnostic>,
    warnings: Vec<GcodeDiagnostic>,
}

impl<'a> Interpreter<'a> {
    /// A machine at 0 in every axis, in G0-less, G17, G21, G90, G94 state.
    pub fn new(options: &'a GcodeOptions) -> Self {
        Interpreter {
            options,
            modal: Modal::default(),
            output_units: None,
            position: [0.0; pvt_core::AXIS_COUNT],
            feed: None,
            feed_reported: false,
            contours: Contours::default(),
            errors: Vec::new(),
            warnings: Vec::new(),
        }
    }

    /// Records a diagnostic found outside the interpreter (a syntax error).
    pub fn report(&mut self, diagnostic: GcodeDiagnostic) {
        self.push(diagnostic);
    }

    /// Records a warning.
    pub fn warn(&mut self, diagnostic: GcodeDiagnostic) {
        self.warnings.push(diagnostic);
    }

    /// Executes one block in RS274NGC order: modes, feed, motion, stop.
    pub fn execute(&mut self, block: &Block) -> Flow {
        let request = Request::read(block, &mut self.errors);
        self.set_modes(&request);
        self.set_feed(&request);
        self.run_motion(&request, block);
        match request.stop {
            Some((Stop::Pause, _)) => {
                self.contours.end_run();
                Flow::Continue
            }
            Some((Stop::End, word)) => Flow::End(word),
            None => Flow::Continue,
        }
    }

    /// Executes a block whose line had a syntax error, reporting nothing more about it.
    pub fn execute_quietly(&mut self, block: &Block) -> Flow {
        let (errors, warnings) = (self.errors.len(), self.warnings.len());
        let flow = self.execute(block);
        self.errors.truncate(errors);
        self.warnings.truncate(warnings);
        flow
    }

    /// The toolpath, or every error in source order.
    pub fn finish(mut self) -> Result<Compiled, GcodeErrors> {
        if self.errors.is_empty() && self.contours.is_empty() {
            self.errors
                .push(GcodeDiagnostic::NoMotion { span: span(0..0) });
        }
        if !self.errors.is_empty() {
            self.errors.sort_by_key(|d| d.span().start);
            return Err(GcodeErrors {
                diagnostics: self.errors,
            });
        }
        self.warnings.sort_by_key(|d| d.span().start);
        let toolpath = Toolpath {
            units: self.output(),
            contours: self.contours.finish(),
            events: Vec::new(),
        };
        Ok(Compiled {
            toolpath,
            warnings: self.warnings,
        })
    }

    fn push(&mut self, diagnostic: GcodeDiagnostic) {
        if diagnostic.is_warning() {
            self.warnings.push(diagnostic);
        } else {
            self.errors.push(diagnostic);
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

    fn set_modes(&mut self, request: &Request) {
        if let Some((plane, _)) = request.plane {
            self.modal.plane = plane;
        }
        if let Some((units, _)) = request.units {
            self.output_units.get_or_insert(units);
            self.modal.units = units;
        }
        if let Some((distance, _)) = request.distance {
            self.modal.distance = distance;
        }
        if let Some((mode, _)) = request.motion {
            self.modal.motion = Some(mode);
        }
    }

    fn set_feed(&mut self, request: &Request) {
        let Some(word) = request.feed else { return };
        let per_minute = word.value * self.scale();
        if !per_minute.is_finite() {
            return self.push(out_of_range("feed", per_minute, word.span()));
        }
        self.feed = Some(Feed {
            written: word.value,
            per_minute,
        });
        self.feed_reported = false;
    }

    fn run_motion(&mut self, request: &Request, block: &Block) {
        if request.no_move {
            return;
        }
        let has_axes = request.has_axis_words();
        match self.modal.motion {
            Some(MotionMode::Arc(direction)) => {
                if has_axes
                    || request.offsets.iter().any(Option::is_some)
                    || request.radius.is_some()
                {
                    self.arc_move(direction, request, block);
                }
            }
            Some(MotionMode::Unsupported) => {}
            Some(mode @ (MotionMode::Rapid | MotionMode::Linear)) => {
                self.reject_arc_words(request, mode.name());
                if has_axes {
                    self.line_move(mode, request, block);
                }
            }
            mode @ (None | Some(MotionMode::Cancel)) => {
                self.reject_arc_words(request, mode.map_or("not set", MotionMode::name));
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
        }
    }

    fn reject_arc_words(&mut self, request: &Request, mode: &'static str) {
        for &word in request.offsets.iter().chain([&request.radius]).flatten() {
            self.push(GcodeDiagnostic::ArcWordWithoutArc {
                word: word.name(),
                mode,
                span: span(word.span()),
            });
        }
    }

    /// The end position of the block's move, in output units.
    fn target(&self, request: &Request) -> Result<Position, GcodeDiagnostic> {
        const WHAT: [&str; 6] = [
            "X coordinate",
            "Y coordinate",
            "Z coordinate",
            "A angle",
            "B angle",
            "C angle",
        ];
        let scale = self.scale();
        let mut end = self.position;
        for axis in Axis::ALL {
            let i = axis.index();
            let Some(word) = request.axes[i] else {
                continue;
            };
            let value = if axis.is_rotary() {
                word.value
            } else {
                word.value * scale
            };
            end[i] = match self.modal.distance {
                Distance::Absolute => value,
                Distance::Incremental => end[i] + value,
            };
            if !end[i].is_finite() {
                return Err(out_of_range(WHAT[i], end[i], word.span()));
            }
        }
        Ok(end)
    }

    /// The feed of a feed move, units per second; `None` (reported once) when there is none.
    fn feed_rate(&mut self, request: &Request, block: &Block) -> Option<f64> {
        let per_minute = match (self.feed, self.options.default_feed) {
            (Some(feed), _) => feed.per_minute,
            (None, Some(default)) => default,
            (None, None) => {
                if !self.feed_reported {
                    self.feed_reported = true;
                    let at = move_span(request, block);
                    self.push(GcodeDiagnostic::NoFeed { span: span(at) });
                }
                return None;
            }
        };
        if per_minute > 0.0 && per_minute.is_finite() {
            return Some(per_minute / 60.0);
        }
        if !self.feed_reported {
            self.feed_reported = true;
            let feed = match self.feed {
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

    /// The rapid rate, units per second.
    fn rapid_rate(&self) -> f64 {
        let per_minute = match self.options.rapid {
            Some(rapid) if rapid > 0.0 && rapid.is_finite() => rapid,
            _ => self.output().from_mm(crate::DEFAULT_RAPID_MM_PER_MIN),
        };
        per_minute / 60.0
    }

    fn line_move(&mut self, mode: MotionMode, request: &Request, block: &Block) {
        self.output_units.get_or_insert(Units::Millimetre);
        let end = match self.target(request) {
            Ok(end) => end,
            Err(diagnostic) => return self.push(diagnostic),
        };
        let (motion, feed) = match mode {
            MotionMode::Rapid => (Motion::Rapid, Some(self.rapid_rate())),
            _ => (Motion::Feed, self.feed_rate(request, block)),
        };
        let start = std::mem::replace(&mut self.position, end);
        let Some(feed) = feed else { return };
        if end == start {
            return self.warn(GcodeDiagnostic::ZeroLengthMove {
                span: span(block.span()),
            });
        }
        let element = Element {
            kind: ElementKind::Line,
            start,
            end,
            feed,
            span: element_span(block),
        };
        self.contours.push(motion, element);
    }

    fn arc_move(&mut self, direction: ArcDirection, request: &Request, block: &Block) {
        self.output_units.get_or_insert(Units::Millimetre);
        let end = match self.target(request) {
            Ok(end) => end,
            Err(diagnostic) => return self.push(diagnostic),
        };
        let center = self.arc_center(direction, request, block, &end);
        let feed = self.feed_rate(request, block);
        let start = std::mem::replace(&mut self.position, end);
        let (Some(center), Some(feed)) = (center, feed) else {
            return;
        };
        let arc = Arc {
            plane: self.modal.plane,
            center,
            direction,
            extra_turns: 0,
        };
        let element = Element {
            kind: ElementKind::Arc(arc),
            start,
            end,
            feed,
            span: element_span(block),
        };
        self.contours.push(Motion::Feed, element);
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
                let offset = |w: Option<Word>| w.map_or(0.0, |w| w.value * scale);
                let offsets = [offset(offsets[0]), offset(offsets[1])];
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

    fn arc_tolerance(&self) -> ArcTolerance {
        ArcTolerance {
            absolute: self.output().from_mm(self.options.arc_abs_tolerance_mm),
            relative: self.options.arc_rel_tolerance,
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
fn move_span(request: &Request, block: &Block) -> Range<usize> {
    let motion = request.motion.as_ref().map(|(_, w)| w);
    let words = motion
        .into_iter()
        .chain(request.axis_words())
        .chain(request.offsets.iter().flatten())
        .chain(&request.radius);
    cover(words).unwrap_or_else(|| block.span())
}

fn element_span(block: &Block) -> Span {
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

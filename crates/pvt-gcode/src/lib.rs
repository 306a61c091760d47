//! pvt-gcode: the G-code front end of pvtc, part program text to a [`pvt_core::Toolpath`].
//!
//! Owns the accepted dialect (`grammars/gcode.ebnf`), the modal interpreter and every
//! diagnostic about a program, each with a stable code and the byte span of the offending
//! text. It must not plan motion, discretize arcs or write output (pvt-core and pvt-emit
//! do), must not read files or render diagnostics (the CLI does), and must never panic,
//! whatever the input.
//!
//! The pipeline, one line at a time and without per-word allocation:
//! `parser` (text → block of words, `value` evaluating parameters and expressions) →
//! `request` (words → what the block asks for) → `interpreter` (modal state → elements
//! and events) → a [`ToolpathSink`]. [`compile_into`] streams; [`compile`] collects into
//! a [`pvt_core::Toolpath`] through the same path.
//!
//! Dialect (see `grammars/gcode.ebnf` and the issue 4 list): G0 G1 G2 G3 in G17/G18/G19
//! (I/J/K under G90.1 or G91.1, R, P turns, helices), G4, G7/G8, G20/G21, G53, G54–G59.3,
//! G61/G61.1/G64 (P), G80, G90/G91, G92/G92.1/G92.2/G92.3, G93/G94, F S T, X Y Z A B C,
//! M0 M1 M2 M30 M3 M4 M5 M6 M7 M8 M9, parameters (`#1`, `#<name>`) and expressions,
//! `(MSG, …)`, `*nn` checksums. G40 and G49 are accepted as they select what pvtc always
//! does. Every axis starts at 0. Lines with block delete (`/`) are executed (the switch
//! is off). O-words, canned cycles, cutter and tool length compensation, G5.x, G38.x,
//! G28/G30 and reads of machine-specific parameters are `unsupported`, one diagnostic
//! per feature with the count of places, and the program fails.
//!
//! Contours: a rapid move is a contour of its own; feed moves run together until a
//! rapid, an event or a stop. Every event (G4 dwell, M0/M1 pause, S, T, M6, M3/M4/M5,
//! M7/M8/M9, `(MSG, …)`) happens with the machine at rest, so it ends the current
//! contour. G61 (exact stop) ends the contour after every move, so each block's end is a
//! rest point. G64's P tolerance is recorded ([`StreamSummary::path_tolerance`]): the
//! contour planner passes exactly through every programmed point, which meets any P.

mod arcs;
mod block;
mod codes;
mod contours;
mod diagnostic;
mod interpreter;
mod kept;
mod lines;
pub mod offsets;
mod params;
mod parser;
mod prescan;
mod request;
mod sink;
mod syntax;
mod value;

pub use diagnostic::{GcodeDiagnostic, GcodeErrors};
pub use kept::MAX_KEPT_DIAGNOSTICS;
pub use lines::MAX_LINE_BYTES;
pub use offsets::{parse_offsets, OffsetsError};
pub use prescan::{prescan, Prescan};
pub use pvt_core::text::line_col;
pub use sink::{StreamSummary, ToolpathSink};
pub use syntax::{check_syntax, SyntaxSummary};

use interpreter::{Flow, Interpreter};
use parser::{LineKind, SourceLine, SourceLines};

/// The rapid rate when [`GcodeOptions::rapid`] is `None`, millimetres per minute.
pub use pvt_core::defaults::RAPID_MM_PER_MIN as DEFAULT_RAPID_MM_PER_MIN;

/// How to compile a program: values the G-code itself does not give.
#[derive(Debug, Clone, PartialEq)]
pub struct GcodeOptions {
    /// Feed (output units per minute) for feed moves before any F word; `None` makes such
    /// a move the error `no_feed`.
    pub default_feed: Option<f64>,
    /// Rapid rate, output units per minute; `None` (or a value that is not positive) is
    /// [`DEFAULT_RAPID_MM_PER_MIN`] converted to the output units.
    pub rapid: Option<f64>,
    /// Arc centre check, absolute tolerance in millimetres (converted for inch programs);
    /// default [`pvt_core::defaults::ARC_ABS_TOLERANCE_MM`] (0.002).
    pub arc_abs_tolerance_mm: f64,
    /// Arc centre check, tolerance relative to the start radius; default
    /// [`pvt_core::defaults::ARC_REL_TOLERANCE`] (0.001, 0.1 %).
    /// A centre-form arc is rejected only when its start and end radii differ by more than
    /// both tolerances (as LinuxCNC does); an R that falls short of half the chord by no
    /// more than either gives a half circle.
    pub arc_rel_tolerance: f64,
    /// Output units; `None` keeps those of the program (its first G20/G21, millimetres
    /// when a move comes first). Coordinates and feeds are converted into them.
    pub units: Option<pvt_core::Units>,
    /// Work offsets of G54, G55, G56, G57, G58, G59, G59.1, G59.2, G59.3 (rows), each
    /// X Y Z in millimetres and A B C in degrees; zero by default. A position in the
    /// output is the program coordinate plus the active row plus any G92 offset.
    pub work_offsets: [[f64; 6]; 9],
}

impl Default for GcodeOptions {
    fn default() -> Self {
        GcodeOptions {
            default_feed: None,
            rapid: None,
            arc_abs_tolerance_mm: pvt_core::defaults::ARC_ABS_TOLERANCE_MM,
            arc_rel_tolerance: pvt_core::defaults::ARC_REL_TOLERANCE,
            units: None,
            work_offsets: [[0.0; 6]; 9],
        }
    }
}

/// A compiled program: its toolpath and the warnings met on the way.
#[derive(Debug, Clone, PartialEq)]
pub struct Compiled {
    /// The moves, grouped into contours, in the output units (see [`compile`]).
    pub toolpath: pvt_core::Toolpath,
    /// Warnings (zero-length moves, ignored words, blocks after the program end), in
    /// source order.
    pub warnings: Vec<GcodeDiagnostic>,
    /// The last G64 P tolerance, output units (see [`StreamSummary::path_tolerance`]).
    pub path_tolerance: Option<f64>,
}

/// Compiles G-code `source` into a toolpath, or returns every error in source order.
///
/// Output units: see [`GcodeOptions::units`]. Element feeds are in output units per
/// second. Reading stops at M2/M30 or at a second `%` line.
pub fn compile(source: &str, options: &GcodeOptions) -> Result<Compiled, GcodeErrors> {
    let mut sink = contours::CollectingSink::default();
    let summary = compile_into(source, options, &mut sink)?;
    let (contours, events, path_tolerances) = sink.finish();
    Ok(Compiled {
        toolpath: pvt_core::Toolpath {
            units: summary.units,
            contours,
            events,
            path_tolerances,
        },
        warnings: summary.warnings,
        path_tolerance: summary.path_tolerance,
    })
}

/// Compiles G-code `source`, handing each element, contour end and event to `sink` as
/// soon as it is made (nothing is accumulated); returns the units and warnings, or every
/// error in source order (the sink's input is then incomplete: discard it).
pub fn compile_into(
    source: &str,
    options: &GcodeOptions,
    sink: &mut dyn ToolpathSink,
) -> Result<StreamSummary, GcodeErrors> {
    let mut reader = Reader::new(options, sink);
    for line in SourceLines::new(source) {
        if !reader.source_line(line) {
            break;
        }
    }
    reader.finish()
}

/// Reads `input` line by line (constant memory, whatever its length) into `sink`.
///
/// Spans are byte offsets into `input`. Invalid UTF-8 in a line becomes U+FFFD, which
/// shifts the columns after it on that line only. A line longer than [`MAX_LINE_BYTES`]
/// is `pvtc::gcode::line_too_long` and is skipped without being held. A read error is
/// returned as such.
pub fn compile_read(
    input: &mut dyn std::io::BufRead,
    options: &GcodeOptions,
    sink: &mut dyn ToolpathSink,
) -> std::io::Result<Result<StreamSummary, GcodeErrors>> {
    let mut reader = Reader::new(options, sink);
    lines::read_lines(input, &mut |line| match line {
        lines::Line::Text { text, start } => reader.line(text, start),
        lines::Line::Bytes { bytes, start } => match std::str::from_utf8(bytes) {
            Ok(text) => reader.line(text, start),
            Err(_) => reader.line(&String::from_utf8_lossy(bytes), start),
        },
        lines::Line::TooLong { start, length } => reader.too_long_line(start, length),
    })?;
    Ok(reader.finish())
}

/// The G-code front end fed one line at a time; [`compile_into`] and [`compile_read`]
/// drive it.
pub struct Reader<'a> {
    interpreter: Interpreter<'a>,
    params: params::Parameters,
    block: block::Block,
    percent_lines: u32,
    number: u32,
    /// Set once the program has ended (M2/M30, closing `%`): what ended it.
    ended: Option<String>,
}

impl<'a> Reader<'a> {
    /// A reader compiling into `sink`.
    pub fn new(options: &'a GcodeOptions, sink: &'a mut dyn ToolpathSink) -> Reader<'a> {
        Reader {
            interpreter: Interpreter::new(options, sink),
            params: params::Parameters::default(),
            block: block::Block::default(),
            percent_lines: 0,
            number: 0,
            ended: None,
        }
    }

    /// Reads the next line (`text` without its line end, starting at byte `start` of the
    /// source); returns false when nothing after it can matter.
    pub fn line(&mut self, text: &str, start: usize) -> bool {
        let number = self.number.saturating_add(1);
        self.source_line(SourceLine {
            text,
            start,
            number,
        })
    }

    /// Skips the next line, `length` bytes from byte `start`, as longer than
    /// [`MAX_LINE_BYTES`] (reported, unless the program has ended); returns as [`Reader::line`].
    pub fn too_long_line(&mut self, start: usize, length: usize) -> bool {
        self.number = self.number.saturating_add(1);
        if let Some(end) = &self.ended {
            self.interpreter.warn(GcodeDiagnostic::AfterProgramEnd {
                end: end.clone(),
                span: diagnostic::span(start..start),
            });
            return false;
        }
        self.interpreter
            .report(diagnostic::line_too_long(self.number, length, start));
        true
    }

    fn source_line(&mut self, line: SourceLine<'_>) -> bool {
        if line.text.len() > MAX_LINE_BYTES {
            self.number = line.number.saturating_sub(1);
            return self.too_long_line(line.start, line.text.len());
        }
        self.number = line.number;
        if let Some(end) = &self.ended {
            let Some(warning) = after_end(line, &mut self.block, &self.params, end) else {
                return true;
            };
            self.interpreter.warn(warning);
            return false;
        }
        let parsed = parser::parse_line(line, &mut self.block, &self.params);
        // All assignments of a line take effect after the line is read.
        for assignment in &self.block.assignments {
            self.params.set(&assignment.param, assignment.value);
        }
        self.ended = match parsed {
            Ok(LineKind::Percent) => {
                self.percent_lines += 1;
                (self.percent_lines == 2).then(|| "the closing `%`".to_owned())
            }
            Ok(LineKind::Block) => match self.interpreter.execute(&self.block) {
                Flow::Continue => None,
                Flow::End(word) => Some(word.name()),
            },
            // The words read around the bad text still set modes, feed and position, but
            // whatever else they cause is not reported: the line has its error already.
            Err(diagnostic) => {
                self.interpreter.report(diagnostic);
                match self.interpreter.execute_quietly(&self.block) {
                    Flow::Continue => None,
                    Flow::End(word) => Some(word.name()),
                }
            }
        };
        true
    }

    /// Ends the program: its summary, or every error met.
    pub fn finish(self) -> Result<StreamSummary, GcodeErrors> {
        self.interpreter.finish()
    }
}

/// A warning if `line`, after the program end, has any content.
fn after_end(
    line: SourceLine<'_>,
    block: &mut block::Block,
    params: &params::Parameters,
    end: &str,
) -> Option<GcodeDiagnostic> {
    let empty = match parser::parse_line(line, block, params) {
        Ok(LineKind::Percent) => true,
        Ok(LineKind::Block) => block.words.is_empty() && block.line_number.is_none(),
        Err(_) => false,
    };
    (!empty).then(|| GcodeDiagnostic::AfterProgramEnd {
        end: end.to_owned(),
        span: diagnostic::span(line.start..line.start + line.text.len()),
    })
}

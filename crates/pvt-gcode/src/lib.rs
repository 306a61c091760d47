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
//! G61/G61.1/G64 (P, and Q recorded as LinuxCNC's naive-CAM tolerance, not applied),
//! G80, G90/G91, G92/G92.1/G92.2/G92.3, G93/G94, F S T, X Y Z A B C, polar `@` `^`,
//! M0 M1 M2 M30 M3 M4 M5 M6 M7 M8 M9, M62–M68 (E on M66–M68) and M100–M199 as events
//! with their words, parameters (`#1`, `#<name>`) and expressions,
//! `(MSG, …)`, `(DEBUG, …)`, `(PRINT, …)`, `*nn` checksums. Issue 16, as LinuxCNC's
//! `rs274` runs them: canned cycles G73 G81–G89 with G98/G99 and L ([`interpreter`]'s
//! `cycles`), tools (T, M6, G43/G43.1/G43.2/G49 from [`GcodeOptions::tool_table`]),
//! G10 L1/L2/L10/L11/L20 (L2 R: a coordinate system's XY rotation about its origin), G52,
//! G28/G30/G28.1/G30.1; G96/G97 and M48–M53 are kept as
//! state, `(LOG…)` comments accepted. G40 is accepted as it selects what pvtc always
//! does. Every axis starts at 0. Lines with block delete (`/`) are executed (the switch
//! is off). A program number (`O1001`) names the program. G76, cutter compensation,
//! G38.2–G38.5 move to the points [`GcodeOptions::probe_results`] gives, each one
//! without a point is `pvtc::gcode::probe`. G5 and G5.1 splines (G17 only, as LinuxCNC)
//! are cubic Bézier elements (`interpreter/spline.rs`), and so are G5.2/G5.3 NURBS
//! blocks (`interpreter/nurbs.rs`) and LinuxCNC 2.10's G6.2 blocks with their own knots
//! (`interpreter/nurbs_g6.rs`): exact for equal weights and order 2 to 4, else within
//! [`NURBS_FIT_SHARE`] of [`GcodeOptions::tolerance`]. G33 and reads of
//! machine-specific parameters are `unsupported`, one
//! diagnostic per feature with the count of places, and the program fails. A block with
//! an unknown G code runs nothing and the blocks after it in its motion mode are
//! skipped, so nothing cascades.
//!
//! O-words (`oword.rs`): `sub`/`endsub`/`return`/`call` with arguments `#1`–`#30` and
//! local names, `if`/`elseif`/`else`/`endif`, `while`/`endwhile`, `do`/`while`,
//! `repeat`/`endrepeat`, `break`, `continue`; `o<name> call` reads `name.ngc` through
//! [`GcodeOptions::subroutines`] when the program does not define it. Calls nest at most
//! [`MAX_CALL_DEPTH`] deep, a loop runs at most [`MAX_LOOP_ITERATIONS`] times (all loops
//! together [`MAX_TOTAL_ITERATIONS`]), held bodies take at most [`MAX_BUFFERED_BYTES`];
//! each limit is a coded error. Fanuc-style `M98 P<n> L<count>` runs the block `O<n>` …
//! `M99` of the same file (`subprogram.rs`).
//!
//! Parameters (`params.rs`, `params/machine.rs`): predefined names (`#<_x>`,
//! `#<_metric>`, `#<_feed>`, `#<_value>`, …) and machine parameters (#5161–#5428: homes,
//! G92, coordinate systems, tool, position) read the interpreter's state; HAL pins read
//! [`GcodeOptions::hal_pins`]; probe results, M66 inputs, HAL pins without a value and
//! ini values are `unsupported`.
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
mod lathe;
mod lines;
mod messages;
pub mod offsets;
mod oword;
mod params;
mod parser;
mod plain;
mod prescan;
mod request;
mod sink;
mod subprogram;
mod syntax;
mod tokens;
mod tools;
mod value;

pub use diagnostic::{GcodeDiagnostic, GcodeErrors};
pub use kept::MAX_KEPT_DIAGNOSTICS;
pub use lines::{trailing_crs, MAX_LINE_BYTES};
pub use offsets::{parse_offsets, OffsetsError};
pub use oword::{SubroutineFile, SubroutineFiles};
pub use prescan::{prescan, Prescan};
pub use pvt_core::text::line_col;
pub use sink::{StreamSummary, ToolpathSink};
pub use syntax::{check_syntax, SyntaxSummary};
pub use tools::{Tool, ToolTable, ToolTableError};

use interpreter::{Flow, Interpreter};
use parser::{LineKind, SourceLine, SourceLines};

/// How deep subroutine calls may nest, as in LinuxCNC (10 levels with the main program);
/// one more is `pvtc::gcode::recursion_limit`.
pub const MAX_CALL_DEPTH: usize = 9;

/// How many times one loop may run each time it is entered; one more is
/// `pvtc::gcode::loop_limit` (a loop that never ends is an error, never a hang).
pub const MAX_LOOP_ITERATIONS: u64 = 1_000_000;

/// How many loop iterations a run may make in all (nested loops multiply); one more is
/// `pvtc::gcode::loop_limit` too.
pub const MAX_TOTAL_ITERATIONS: u64 = 100_000_000;

/// The most turns one arc block may make (`P`); more is `pvtc::gcode::turn_limit`.
pub const MAX_ARC_TURNS: u64 = 1_000_000;

/// The most arc turns a run may make in all (arcs in loops add up); more is
/// `pvtc::gcode::turn_limit` too.
pub const MAX_TOTAL_ARC_TURNS: u64 = 10_000_000;

/// How many bytes of text the bodies of subroutines and of the main program's loops
/// held in memory may take together (the rest of a program streams); more is
/// `pvtc::gcode::body_too_large`.
pub const MAX_BUFFERED_BYTES: usize = 16 << 20;

/// Where `o<name> call` finds subroutines the program does not define
/// ([`SubroutineFiles`]); none by default.
#[derive(Clone, Default)]
pub struct Subroutines(pub Option<std::sync::Arc<dyn SubroutineFiles + Send + Sync>>);

impl std::fmt::Debug for Subroutines {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match &self.0 {
            Some(files) => write!(f, "Subroutines({})", files.describe()),
            None => f.write_str("Subroutines(none)"),
        }
    }
}

impl PartialEq for Subroutines {
    fn eq(&self, other: &Self) -> bool {
        match (&self.0, &other.0) {
            (Some(a), Some(b)) => std::sync::Arc::ptr_eq(a, b),
            (None, None) => true,
            _ => false,
        }
    }
}

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
    /// `None` is LinuxCNC's for the program's units
    /// ([`pvt_core::defaults::arc_abs_tolerance`]: 2·0.01·√2 mm, 2·0.001·√2 in).
    pub arc_abs_tolerance_mm: Option<f64>,
    /// Arc centre check, tolerance relative to the larger radius; default
    /// [`pvt_core::defaults::ARC_REL_TOLERANCE`] (0.001, 0.1 %).
    /// A centre-form arc is refused when its start and end radii differ by more than 100
    /// times the absolute tolerance, or by more than it and by more than the relative one
    /// (LinuxCNC's rule); within, it is the spiral LinuxCNC runs (the radius changing
    /// linearly with the angle). An R that falls short of half the chord by no more than
    /// [`pvt_core::defaults::ARC_RADIUS_TOLERANCE_IN`] gives a half circle.
    pub arc_rel_tolerance: f64,
    /// Output units; `None` keeps those of the program (its first G20/G21, millimetres
    /// when a move comes first). Coordinates and feeds are converted into them.
    pub units: Option<pvt_core::Units>,
    /// Work offsets of G54, G55, G56, G57, G58, G59, G59.1, G59.2, G59.3 (rows), each
    /// X Y Z in millimetres and A B C in degrees; zero by default. A position in the
    /// output is the program coordinate plus the active row plus any G92 offset.
    pub work_offsets: [[f64; 6]; 9],
    /// The tool table G43 and G43.2 read (LinuxCNC's `.tbl` format, millimetres); empty
    /// by default, where only H0 (no offset) is known.
    pub tool_table: ToolTable,
    /// Subroutine files for `o<name> call` (`--subroutine-path`).
    pub subroutines: Subroutines,
    /// Values of HAL pins, `#<_hal[NAME]>` (`--hal NAME=VALUE`); a pin not given is
    /// `unsupported`. Names are read as rs274 reads them: lower case, without blanks.
    pub hal_pins: Vec<(String, f64)>,
    /// Where successive probing moves (G38.2–G38.5) trip, X Y Z in the program's
    /// coordinates and units at each move (`--probe-result X,Y,Z`); a probing move
    /// without one is `pvtc::gcode::probe`.
    pub probe_results: Vec<[f64; 3]>,
    /// The chord (path) tolerance, output units; `None` is
    /// [`pvt_core::defaults::TOLERANCE_MM`] in the output units. A rational or
    /// order-5+ NURBS block (G5.2, G6.2) is fitted with cubics within
    /// [`NURBS_FIT_SHARE`] of it (of a G64 P in force, where that is less).
    pub tolerance: Option<f64>,
    /// What spindle-synchronised motion (G33, G33.1, G76, G95) becomes; refused by default.
    pub spindle_sync: SpindleSync,
}

/// What spindle-synchronised motion (G33, G33.1, G76, G95) becomes: a time-based PVT
/// program cannot follow a spindle's encoder.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SpindleSync {
    /// `pvtc::gcode::spindle_sync`, with the reason.
    #[default]
    Refuse,
    /// Planned at the programmed S, taken as exact (`--spindle-rpm-exact`): feed per
    /// revolution × S, pitch × S; a warning says so.
    ProgrammedSpeed,
}

/// Share of the tolerance a rational or order-5+ NURBS block's (G5.2, G6.2) cubics keep
/// to. Each such cubic carries it as its [`pvt_core::Bezier::fit`], and the path planner
/// keeps the motion within the rest of the tolerance of the cubic, so the motion is
/// within the tolerance of the true NURBS.
pub const NURBS_FIT_SHARE: f64 = 0.1;

impl Default for GcodeOptions {
    fn default() -> Self {
        GcodeOptions {
            default_feed: None,
            rapid: None,
            arc_abs_tolerance_mm: None,
            arc_rel_tolerance: pvt_core::defaults::ARC_REL_TOLERANCE,
            units: None,
            work_offsets: [[0.0; 6]; 9],
            tool_table: ToolTable::default(),
            subroutines: Subroutines::default(),
            hal_pins: Vec::new(),
            probe_results: Vec::new(),
            tolerance: None,
            spindle_sync: SpindleSync::Refuse,
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
/// second. Reading stops at M2/M30 or at the `%` that closes a program opened with `%`.
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
    options: &'a GcodeOptions,
    flow: oword::Flow,
    subprograms: subprogram::Subprograms,
    interpreter: Interpreter<'a>,
    params: params::Parameters,
    block: block::Block,
    /// The program opened with a `%` line (its first line that is not blank).
    opened: bool,
    /// No line with anything but blanks has been read before the current one.
    at_start: bool,
    /// Byte offset of the end of the last line read.
    end_offset: usize,
    number: u32,
    /// Set once the program has ended (M2/M30, closing `%`): what ended it.
    ended: Option<String>,
    /// Plain lines ([`plain`]) run without a block when the state allows; off only in
    /// tests that hold the two paths to the same output.
    plain_lines: bool,
    /// How many lines ran as plain lines: the tests' evidence that the plain path ran.
    #[cfg(test)]
    plain_runs: usize,
}

impl<'a> Reader<'a> {
    /// A reader compiling into `sink`.
    pub fn new(options: &'a GcodeOptions, sink: &'a mut dyn ToolpathSink) -> Reader<'a> {
        let mut params = params::Parameters::default();
        for (name, value) in &options.hal_pins {
            params.set_hal_pin(name, *value);
        }
        Reader {
            options,
            flow: oword::Flow::default(),
            subprograms: subprogram::Subprograms::default(),
            interpreter: Interpreter::new(options, sink),
            params,
            block: block::Block::default(),
            opened: false,
            at_start: true,
            end_offset: 0,
            number: 0,
            ended: None,
            plain_lines: true,
            #[cfg(test)]
            plain_runs: 0,
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

    /// Records a diagnostic, shown at the call when a subroutine file's line caused it.
    pub(crate) fn report(&mut self, diagnostic: GcodeDiagnostic) {
        self.interpreter.report(diagnostic);
    }

    /// Brings the machine parameters' view up to date for a line that reads parameters.
    pub(crate) fn refresh_view(&mut self, line: u32) {
        self.params.view = self.interpreter.view();
        self.params.view.line = line;
        self.params.view.call_level = self.params.call_level() as u32;
    }

    fn source_line(&mut self, line: SourceLine<'_>) -> bool {
        if line.text.len() > MAX_LINE_BYTES {
            self.number = line.number.saturating_sub(1);
            return self.too_long_line(line.start, line.text.len());
        }
        self.number = line.number;
        self.end_offset = line.start + line.text.len();
        let blank = is_bare(line.text);
        let first = self.at_start && !blank;
        self.at_start &= blank;
        if self.ended.is_some() && self.subprogram_after_end(line) {
            return true;
        }
        if let Some(end) = &self.ended {
            let Some(warning) = after_end(line, &mut self.block, &self.params, end) else {
                return true;
            };
            self.interpreter.warn(warning);
            return false;
        }
        // A plain line is not an O-word or `%` line: with no body being recorded or
        // searched for, it runs here, as `run_line` would run it.
        if self.flow.is_idle() && self.subprograms.is_idle() && self.run_plain_line(line) {
            return true;
        }
        if let Some(more) = self.subprogram_line(line) {
            return more;
        }
        if let Some(more) = self.flow_line(line) {
            return more;
        }
        if first && parser::percent_line(line.text).is_ok_and(|(_, rest)| is_bare(rest)) {
            self.opened = true;
            return true;
        }
        self.run_general_line(line);
        true
    }

    /// Parses and executes one line of G-code (not a control line); returns false once
    /// the program has ended.
    pub(crate) fn run_line(&mut self, line: SourceLine<'_>) -> bool {
        if self.run_plain_line(line) {
            return true;
        }
        self.run_general_line(line)
    }

    /// Runs `line` when it is plain ([`plain`]) and the state allows; returns whether it
    /// ran. Lines of a subroutine file (shown at the call) take the general path.
    fn run_plain_line(&mut self, line: SourceLine<'_>) -> bool {
        let reading_profile = self.interpreter.recording_profile();
        if !self.plain_lines
            || self.ended.is_some()
            || self.interpreter.origin.is_some()
            || reading_profile
        {
            return false;
        }
        let Some(plain) = plain::plain_line(line.text) else {
            return false;
        };
        let span = pvt_core::Span {
            start: line.start,
            end: line.start + line.text.len(),
            line: line.number,
        };
        let ran = match plain.has_center_words() {
            true => self.interpreter.run_plain_arc(&plain, span),
            false => self.interpreter.run_plain(&plain, span),
        };
        #[cfg(test)]
        {
            self.plain_runs += usize::from(ran);
        }
        ran
    }

    /// Parses and executes one line of G-code through its block and request; returns
    /// false once the program has ended.
    fn run_general_line(&mut self, line: SourceLine<'_>) -> bool {
        if self.ended.is_some() {
            return false;
        }
        if memchr::memchr(b'#', line.text.as_bytes()).is_some() {
            self.refresh_view(line.number);
        }
        let parsed = parser::parse_line(line, &mut self.block, &self.params);
        if let Some(origin) = &self.interpreter.origin {
            // Elements from a subroutine file carry the line of the call.
            self.block.line = origin.call_line;
        }
        // All assignments of a line take effect after the line is read.
        for assignment in &self.block.assignments {
            self.params.set(&assignment.param, assignment.value);
            if let params::ParamRef::Numbered(index) = assignment.param {
                self.interpreter.parameter_written(index, assignment.value);
            }
        }
        let call = self.take_subprogram_words();
        self.ended = match parsed {
            Ok(LineKind::Percent) => self.percent(line),
            Ok(LineKind::Block) => match self.interpreter.execute(&self.block) {
                Flow::Continue => None,
                Flow::End(word) => Some(word.name()),
            },
            // The words read around the bad text still set modes, feed and position, but
            // whatever else they cause is not reported: the line has its error already.
            Err(diagnostic) => {
                self.report(diagnostic);
                match self.interpreter.execute_quietly(&self.block) {
                    Flow::Continue => None,
                    Flow::End(word) => Some(word.name()),
                }
            }
        };
        if let (Some(call), None) = (call, &self.ended) {
            self.subprogram_call(call);
        }
        if let Some(label) = self.interpreter.lathe_profile_wanted() {
            // A lathe cycle's profile is its subroutine's moves, read, not run.
            self.interpreter.begin_profile();
            let at = self.block.span();
            self.invoke(&label, Vec::new(), at, line.number);
            self.interpreter.end_profile();
        }
        self.ended.is_none()
    }

    /// A `%` line after the first: the end of a program opened with `%` when it is
    /// alone on its line; anything else is `percent_line`, as `rs274` refuses it.
    fn percent(&mut self, line: SourceLine<'_>) -> Option<String> {
        let (_, text) = parser::percent_line(line.text).unwrap_or_default();
        if self.opened && is_bare(text) {
            return Some("the closing `%`".to_owned());
        }
        let at = line.start + line.text.find('%').unwrap_or(0);
        self.report(GcodeDiagnostic::PercentLine {
            span: diagnostic::span(at..at + 1),
        });
        None
    }

    /// Ends the program: its summary, or every error met.
    pub fn finish(mut self) -> Result<StreamSummary, GcodeErrors> {
        if self.ended.is_none() {
            let at = self.end_offset;
            self.interpreter.warn(GcodeDiagnostic::NoProgramEnd {
                opened: self.opened,
                span: diagnostic::span(at..at),
            });
        }
        self.flow_finish();
        self.subprograms_finish();
        self.interpreter.finish()
    }
}

/// True when `text` (a line, or what follows a `%`) holds only blanks: read up to its
/// first other byte, which starts most lines.
fn is_bare(text: &str) -> bool {
    text.bytes().all(|b| matches!(b, b' ' | b'\t'))
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

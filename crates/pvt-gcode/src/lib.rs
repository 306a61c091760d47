//! pvt-gcode: the G-code front end of pvtc, part program text to a [`pvt_core::Toolpath`].
//!
//! Owns the accepted dialect (`grammars/gcode.ebnf`), the modal interpreter and every
//! diagnostic about a program, each with a stable code and the byte span of the offending
//! text. It must not plan motion, discretize arcs or write output (pvt-core and pvt-emit
//! do), must not read files or render diagnostics (the CLI does), and must never panic,
//! whatever the input.
//!
//! The pipeline, one line at a time and without per-word allocation:
//! `parser` (text → block of words) → `request` (words → what the block
//! asks for) → `interpreter` (modal state → elements) → `contours`.
//!
//! Dialect of this version: G0 G1 G2 G3 (I/J/K centre offsets or R), G17 G18 G19, G20
//! G21, G90 G91, G94, G80, F, X Y Z A B C, M0 M1 M2 M30; G40, G49 and G91.1 are accepted
//! as they select what pvtc always does. Every axis starts at 0. Lines with block delete
//! (`/`) are executed (the block delete switch is off). Other RS274NGC codes are reported
//! as `unsupported`, naming the feature.

mod arcs;
mod block;
mod codes;
mod contours;
mod diagnostic;
mod interpreter;
mod parser;
mod request;

pub use diagnostic::{line_col, GcodeDiagnostic, GcodeErrors};

use interpreter::{Flow, Interpreter};
use parser::{LineKind, SourceLines};

/// The rapid rate when [`GcodeOptions::rapid`] is `None`, millimetres per minute.
pub const DEFAULT_RAPID_MM_PER_MIN: f64 = 5000.0;

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
    /// default 0.002.
    pub arc_abs_tolerance_mm: f64,
    /// Arc centre check, tolerance relative to the start radius; default 0.001 (0.1 %).
    /// A centre-form arc is rejected only when its start and end radii differ by more than
    /// both tolerances (as LinuxCNC does); an R that falls short of half the chord by no
    /// more than either gives a half circle.
    pub arc_rel_tolerance: f64,
}

impl Default for GcodeOptions {
    fn default() -> Self {
        GcodeOptions {
            default_feed: None,
            rapid: None,
            arc_abs_tolerance_mm: 0.002,
            arc_rel_tolerance: 0.001,
        }
    }
}

/// A compiled program: its toolpath and the warnings met on the way.
#[derive(Debug, Clone, PartialEq)]
pub struct Compiled {
    /// The moves, grouped into contours, in the output units (see [`compile`]).
    pub toolpath: pvt_core::Toolpath,
    /// Warnings (zero-length moves, blocks after the program end), in source order.
    pub warnings: Vec<GcodeDiagnostic>,
}

/// Compiles G-code `source` into a toolpath, or returns every error in source order.
///
/// Output units are those of the first G20/G21, millimetres when a move comes before
/// either; coordinates and feeds after a later switch are converted. Element feeds are
/// in output units per second. Reading stops at M2/M30 or at a second `%` line.
pub fn compile(source: &str, options: &GcodeOptions) -> Result<Compiled, GcodeErrors> {
    let mut interpreter = Interpreter::new(options);
    let mut block = block::Block::default();
    let mut lines = SourceLines::new(source);
    let mut percent_lines = 0;
    while let Some(line) = lines.next() {
        let end = match parser::parse_line(line, &mut block) {
            Ok(LineKind::Percent) => {
                percent_lines += 1;
                (percent_lines == 2).then(|| "the closing `%`".to_owned())
            }
            Ok(LineKind::Block) => match interpreter.execute(&block) {
                Flow::Continue => None,
                Flow::End(word) => Some(word.name()),
            },
            // The words read around the bad text still set modes, feed and position, but
            // whatever else they cause is not reported: the line has its error already.
            Err(diagnostic) => {
                interpreter.report(diagnostic);
                match interpreter.execute_quietly(&block) {
                    Flow::Continue => None,
                    Flow::End(word) => Some(word.name()),
                }
            }
        };
        if let Some(end) = end {
            if let Some(warning) = ignored_after_end(lines, &mut block, end) {
                interpreter.warn(warning);
            }
            break;
        }
    }
    interpreter.finish()
}

/// A warning naming the first block after the program end that has any content.
fn ignored_after_end(
    lines: SourceLines<'_>,
    block: &mut block::Block,
    end: String,
) -> Option<GcodeDiagnostic> {
    for line in lines {
        let empty = match parser::parse_line(line, block) {
            Ok(LineKind::Percent) => true,
            Ok(LineKind::Block) => block.words.is_empty() && block.line_number.is_none(),
            Err(_) => false,
        };
        if !empty {
            let span = diagnostic::span(line.start..line.start + line.text.len());
            return Some(GcodeDiagnostic::AfterProgramEnd { end, span });
        }
    }
    None
}

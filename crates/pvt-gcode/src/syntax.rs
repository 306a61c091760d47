//! The parser alone: every line read into words with spans, nothing interpreted.
//!
//! Owns [`check_syntax`], the syntax check and the parse-only benchmark's subject. It must
//! not give words a meaning (no modes, no motion): that is [`crate::compile`]'s.

use crate::block::Block;
use crate::diagnostic::{line_too_long, GcodeDiagnostic};
use crate::kept::Kept;
use crate::lines::MAX_LINE_BYTES;
use crate::params::Parameters;
use crate::parser::{self, SourceLines};

/// What [`check_syntax`] found: the size of the program and its syntax errors.
#[derive(Debug, Clone, PartialEq)]
pub struct SyntaxSummary {
    /// Lines read.
    pub lines: usize,
    /// Words read (letters with values, line numbers not counted).
    pub words: usize,
    /// Syntax errors in source order (at most [`crate::MAX_KEPT_DIAGNOSTICS`] and a count).
    pub errors: Vec<GcodeDiagnostic>,
}

/// Parses every line of `source` (words, numbers, comments, parameters and expressions,
/// each with its span) without interpreting any; an O-word control line is checked for
/// its keyword only. Assignments take effect at the end of
/// their line, so later reads of a parameter see its value.
pub fn check_syntax(source: &str) -> SyntaxSummary {
    let (mut block, mut params, mut errors) =
        (Block::default(), Parameters::default(), Kept::default());
    let (mut lines, mut words) = (0, 0);
    for line in SourceLines::new(source) {
        lines = line.number as usize;
        if line.text.len() > MAX_LINE_BYTES {
            errors.push(line_too_long(line.number, line.text.len(), line.start));
            continue;
        }
        // An O-word control line is read when it runs (its values then): here only its
        // keyword is checked.
        match crate::oword::parse_control(line.text, line.start) {
            Some(Ok(_)) => continue,
            Some(Err(diagnostic)) => {
                errors.push(diagnostic);
                continue;
            }
            None => {}
        }
        if let Err(diagnostic) = parser::parse_line(line, &mut block, &params) {
            errors.push(diagnostic);
        }
        words += block.words.len();
        for assignment in &block.assignments {
            params.set(&assignment.param, assignment.value);
        }
    }
    SyntaxSummary {
        lines,
        words,
        errors: errors.into_sorted(|count, span| GcodeDiagnostic::MoreErrors { count, span }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_words_and_keeps_every_syntax_error() {
        let summary = check_syntax("#1 = 2\nG1 X#1 Y[#1 * 2] (move)\nG1 X1e3\nG0 X)\n");
        assert_eq!((summary.lines, summary.words), (4, 5));
        let spans: Vec<_> = summary.errors.iter().map(|e| e.span()).collect();
        assert_eq!(spans, [36..38, 42..44]); // `e3`, `X)`
    }

    #[test]
    fn control_lines_are_checked_for_their_keyword_only() {
        let summary = check_syntax(
            "o1 while [#<n> LT 3]
G1 X1
o1 endwhile
o2 jump
",
        );
        assert_eq!((summary.lines, summary.words), (4, 2));
        let codes: Vec<_> = summary.errors.iter().map(|e| e.code()).collect();
        assert_eq!(codes, ["pvtc::gcode::oword"]);
    }
}

//! The work-offset table (`--offsets`): values for G54–G59.3 written as G-code words.
//!
//! Owns the table's text format and its diagnostic `pvtc::offsets::syntax`. One offset per
//! line, words like G-code:
//!
//! ```text
//! # work offsets, X Y Z in millimetres, A B C in degrees
//! G54 X100 Y50 Z-20
//! G55 X300 Y50 Z-20 A90
//! G59.1 X0 Y0 Z-5
//! ```
//!
//! Axes not given are 0; blank lines and text after `#` or `;` are ignored. The rows go
//! into [`crate::GcodeOptions::work_offsets`]. It must not read the file (the CLI reads it
//! once per run) nor apply the offsets (the interpreter does).

use miette::{Diagnostic, SourceSpan};
use thiserror::Error;

/// The codes in row order of [`crate::GcodeOptions::work_offsets`].
pub const CODES: [&str; 9] = [
    "G54", "G55", "G56", "G57", "G58", "G59", "G59.1", "G59.2", "G59.3",
];

/// A line of the table that is not an offset: a code that is not G54…G59.3, or a word
/// that is not an axis word with a finite number.
#[derive(Debug, Clone, PartialEq, Error, Diagnostic)]
#[error("{message}")]
#[diagnostic(
    code(pvtc::offsets::syntax),
    help("write one offset per line, e.g. `G54 X100 Y50 Z-20`")
)]
pub struct OffsetsError {
    /// What is wrong, naming the word.
    pub message: String,
    /// The word's bytes in the table's text.
    #[label("here")]
    pub span: SourceSpan,
}

/// Parses the table's text into the nine rows (X Y Z A B C each).
pub fn parse_offsets(text: &str) -> Result<[[f64; 6]; 9], OffsetsError> {
    let mut rows = [[0.0; 6]; 9];
    let mut offset = 0;
    let error = |at: usize, word: &str, message: String| OffsetsError {
        message,
        span: SourceSpan::from(at..at + word.len()),
    };
    for line in text.split_inclusive('\n') {
        let content = line.split(['#', ';']).next().unwrap_or("");
        let base = offset;
        offset += line.len();
        let mut words = content
            .split_whitespace()
            .map(|w| (base + word_start(line, w), w));
        let Some((at, code)) = words.next() else {
            continue;
        };
        let row = CODES
            .iter()
            .position(|c| c.eq_ignore_ascii_case(code))
            .ok_or_else(|| {
                let message = format!("`{code}` is not a work offset (G54…G59.3)");
                error(at, code, message)
            })?;
        for (at, word) in words {
            let bad = || error(at, word, format!("`{word}` is not an axis word like X100"));
            let (letter, value) = word.split_at_checked(1).ok_or_else(bad)?;
            let axis = "XYZABC"
                .find(&letter.to_ascii_uppercase())
                .ok_or_else(bad)?;
            let value: f64 = value.parse().map_err(|_| bad())?;
            if !value.is_finite() {
                return Err(bad());
            }
            rows[row][axis] = value;
        }
    }
    Ok(rows)
}

fn word_start(line: &str, word: &str) -> usize {
    word.as_ptr() as usize - line.as_ptr() as usize
}

#[cfg(test)]
mod tests {
    use super::*;

    fn range(e: &OffsetsError) -> std::ops::Range<usize> {
        e.span.offset()..e.span.offset() + e.span.len()
    }

    #[test]
    fn reads_rows_and_ignores_comments() {
        let rows = parse_offsets("# offsets\nG54 X100 Y50 Z-20\n\ng59.1 a90 ; rotary\n").unwrap();
        assert_eq!(rows[0], [100.0, 50.0, -20.0, 0.0, 0.0, 0.0]);
        assert_eq!(rows[6], [0.0, 0.0, 0.0, 90.0, 0.0, 0.0]);
        assert_eq!(rows[1], [0.0; 6]);
    }

    #[test]
    fn names_the_bad_word() {
        let text = "G54 X1\nG60 X2\n";
        let e = parse_offsets(text).unwrap_err();
        assert_eq!(&text[range(&e)], "G60");
        assert!(e.message.contains("G60"));
        assert_eq!(
            e.code().map(|c| c.to_string()).as_deref(),
            Some("pvtc::offsets::syntax")
        );
        let text = "G54 Q1\n";
        assert_eq!(&text[range(&parse_offsets(text).unwrap_err())], "Q1");
        assert!(parse_offsets("G54 Xnan\n").is_err());
    }
}

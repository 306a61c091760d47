//! The `--offsets` file: work offset values for G54–G59.3.
//!
//! Owns reading and checking that file. Format, one offset per line, words like G-code:
//!
//! ```text
//! # work offsets, X Y Z in millimetres, A B C in degrees
//! G54 X100 Y50 Z-20
//! G55 X300 Y50 Z-20 A90
//! G59.1 X0 Y0 Z-5
//! ```
//!
//! Axes not given are 0; blank lines and text after `#` or `;` are ignored. It must not
//! know how the front end applies the offsets.

use crate::pipeline::Failure;
use miette::{LabeledSpan, NamedSource};
use std::path::Path;

/// The codes in row order of `pvt_gcode::GcodeOptions::work_offsets`.
pub const CODES: [&str; 9] = [
    "G54", "G55", "G56", "G57", "G58", "G59", "G59.1", "G59.2", "G59.3",
];

/// Reads an offsets file into the nine rows (X Y Z A B C each).
pub fn read(path: &Path) -> Result<[[f64; 6]; 9], Failure> {
    let text = std::fs::read_to_string(path).map_err(|error| Failure::Io {
        path: path.to_path_buf(),
        action: "read",
        error,
    })?;
    parse(&text).map_err(|(range, message)| {
        let report = miette::miette!(
            code = "pvtc::offsets::syntax",
            labels = vec![LabeledSpan::at(range, "here")],
            help = "write one offset per line, e.g. `G54 X100 Y50 Z-20`",
            "{message}"
        )
        .with_source_code(NamedSource::new(path.display().to_string(), text.clone()));
        Failure::Input(vec![report])
    })
}

/// Parses the file's text; an error carries the byte range it is about.
pub fn parse(text: &str) -> Result<[[f64; 6]; 9], (std::ops::Range<usize>, String)> {
    let mut rows = [[0.0; 6]; 9];
    let mut offset = 0;
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
            .ok_or((
                at..at + code.len(),
                format!("`{code}` is not a work offset (G54…G59.3)"),
            ))?;
        for (at, word) in words {
            let bad = || {
                (
                    at..at + word.len(),
                    format!("`{word}` is not an axis word like X100"),
                )
            };
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

    #[test]
    fn reads_rows_and_ignores_comments() {
        let rows = parse("# offsets\nG54 X100 Y50 Z-20\n\ng59.1 a90 ; rotary\n").unwrap();
        assert_eq!(rows[0], [100.0, 50.0, -20.0, 0.0, 0.0, 0.0]);
        assert_eq!(rows[6], [0.0, 0.0, 0.0, 90.0, 0.0, 0.0]);
        assert_eq!(rows[1], [0.0; 6]);
    }

    #[test]
    fn names_the_bad_word() {
        let text = "G54 X1\nG60 X2\n";
        let (range, message) = parse(text).unwrap_err();
        assert_eq!(&text[range], "G60");
        assert!(message.contains("G60"));
        let text = "G54 Q1\n";
        assert_eq!(&text[parse(text).unwrap_err().0], "Q1");
        assert!(parse("G54 Xnan\n").is_err());
    }
}

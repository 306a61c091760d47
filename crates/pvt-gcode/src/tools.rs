//! The tool table: LinuxCNC's `.tbl` format read into tool length offsets.
//!
//! Owns the file format and its checks. One tool per line, words like G-code, text after
//! `;` a comment:
//!
//! ```text
//! T1 P1 Z0.5 D0.25 ;6 mm drill
//! T2 P2 X0.1 Z-1.5 D0.5
//! ```
//!
//! T (tool number) is required; P (pocket), X Y Z A B C U V W (offsets), D (diameter),
//! I J Q (lathe angles and orientation) are optional. Offsets are millimetres (A B C
//! degrees), like the `--offsets` file; U V W are read and unused. It must not apply the
//! offsets (the interpreter does, for G43) nor read files.

use miette::{Diagnostic, SourceSpan};
use std::ops::Range;
use thiserror::Error;

/// A line of the table that is not a tool: a word that is not a letter with a finite
/// number, a second T, a tool number that is not whole, or a letter the format lacks.
#[derive(Debug, Clone, PartialEq, Error, Diagnostic)]
#[error("{message}")]
#[diagnostic(
    code(pvtc::tool_table::syntax),
    help("write one tool per line, e.g. `T1 P1 Z0.5 D6 ;6 mm drill`")
)]
pub struct ToolTableError {
    /// What is wrong, naming the line and the word.
    pub message: String,
    /// The word's bytes in the table's text.
    #[label("here")]
    pub span: SourceSpan,
}

fn error(range: Range<usize>, message: String) -> ToolTableError {
    ToolTableError {
        message,
        span: SourceSpan::from(range),
    }
}

/// One tool of the table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tool {
    /// The T number.
    pub number: u32,
    /// Offsets X Y Z A B C: millimetres, degrees.
    pub offsets: [f64; 6],
    /// D, the diameter, millimetres (0 if not given).
    pub diameter: f64,
    /// Q, a lathe tool's orientation 1…8 (0 or 9: none), where its nose radius lies from
    /// the point the table's offsets name.
    pub orientation: u32,
}

/// A tool table: the tools by number, the last line for a number winning.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ToolTable {
    tools: Vec<Tool>,
}

impl ToolTable {
    /// Parses the text of a `.tbl` file; an error labels the word that is wrong.
    pub fn parse(text: &str) -> Result<ToolTable, ToolTableError> {
        let mut table = ToolTable::default();
        let mut offset = 0;
        for (index, line) in text.split_inclusive('\n').enumerate() {
            let base = offset;
            offset += line.len();
            let content = line.split(';').next().unwrap_or("");
            let mut tool: Option<Tool> = None;
            let mut words = content.split_whitespace().peekable();
            if words.peek().is_none() {
                continue;
            }
            let mut searched = 0;
            for word in words {
                let at = base + searched + content[searched..].find(word).unwrap_or(0);
                searched = at - base + word.len();
                let range = at..at + word.len();
                let (letter, value) = match word.split_at_checked(1) {
                    Some((l, v)) if !v.is_empty() => (l.to_ascii_uppercase(), v),
                    _ => return Err(error(range, not_a_word(word, index))),
                };
                let number: f64 = match value.parse() {
                    Ok(n) if f64::is_finite(n) => n,
                    _ => return Err(error(range, not_a_word(word, index))),
                };
                if letter == "T" {
                    if tool.is_some() {
                        return Err(error(range, format!("line {}: a second T word", index + 1)));
                    }
                    let rounded = number.round();
                    if rounded != number || !(0.0..=f64::from(u32::MAX)).contains(&number) {
                        return Err(error(
                            range,
                            format!(
                                "line {}: `{word}`: a tool number is a whole number ≥ 0",
                                index + 1
                            ),
                        ));
                    }
                    tool = Some(Tool {
                        number: rounded as u32,
                        offsets: [0.0; 6],
                        diameter: 0.0,
                        orientation: 0,
                    });
                    continue;
                }
                let Some(t) = tool.as_mut() else {
                    return Err(error(
                        range,
                        format!("line {}: a tool line starts with its T word", index + 1),
                    ));
                };
                match letter.as_str() {
                    "X" | "Y" | "Z" => {
                        t.offsets[usize::from(letter.as_bytes()[0] - b'X')] = number;
                    }
                    "A" | "B" | "C" => {
                        t.offsets[3 + usize::from(letter.as_bytes()[0] - b'A')] = number;
                    }
                    "D" => t.diameter = number,
                    "Q" if number.fract() == 0.0 && (0.0..=9.0).contains(&number) => {
                        t.orientation = number as u32;
                    }
                    "Q" => {
                        return Err(error(
                            range,
                            format!(
                                "line {}: `{word}`: an orientation is a whole number 0…9",
                                index + 1
                            ),
                        ))
                    }
                    "P" | "U" | "V" | "W" | "I" | "J" => {}
                    _ => {
                        return Err(error(
                            range,
                            format!(
                                "line {}: `{word}`: a tool line has T P X Y Z A B C U V W D I J Q words",
                                index + 1
                            ),
                        ))
                    }
                }
            }
            if let Some(tool) = tool {
                table.tools.retain(|t| t.number != tool.number);
                table.tools.push(tool);
            }
        }
        Ok(table)
    }

    /// The tool numbered `number`, if the table has it.
    pub fn get(&self, number: u32) -> Option<&Tool> {
        self.tools.iter().find(|t| t.number == number)
    }

    /// The tool numbered `number` to change (G10 L1, L10, L11).
    pub(crate) fn get_mut(&mut self, number: u32) -> Option<&mut Tool> {
        self.tools.iter_mut().find(|t| t.number == number)
    }

    /// Multiplies every length (X Y Z offsets, diameter) by `factor`, e.g. 25.4 for a
    /// table written in inches.
    pub fn scale_lengths(&mut self, factor: f64) {
        for tool in &mut self.tools {
            for offset in &mut tool.offsets[..3] {
                *offset *= factor;
            }
            tool.diameter *= factor;
        }
    }

    /// True when the table has no tools.
    pub fn is_empty(&self) -> bool {
        self.tools.is_empty()
    }
}

fn not_a_word(word: &str, index: usize) -> String {
    format!(
        "line {}: `{word}` is not a word like Z0.5 (a letter and a number)",
        index + 1
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_linuxcnc_lines() {
        let table = ToolTable::parse(
            "T1 P1 Z0.5 D0.25 ;comment\n\n; only a comment\nt2 p2 x0.1 z-1.5 d0.5\n",
        )
        .unwrap();
        let t1 = table.get(1).unwrap();
        assert_eq!(t1.offsets, [0.0, 0.0, 0.5, 0.0, 0.0, 0.0]);
        assert_eq!(t1.diameter, 0.25);
        assert_eq!(table.get(2).unwrap().offsets[..3], [0.1, 0.0, -1.5]);
        assert!(table.get(3).is_none());
    }

    #[test]
    fn errors_name_the_line_and_word() {
        let text = "T1 Z1\nT2 Z1.x\n";
        let parts =
            |e: ToolTableError| (e.span.offset()..e.span.offset() + e.span.len(), e.message);
        let (range, message) = parts(ToolTable::parse(text).unwrap_err());
        assert_eq!(&text[range], "Z1.x");
        assert!(message.starts_with("line 2:"), "{message}");
        let (range, message) = parts(ToolTable::parse("P1 Z1\n").unwrap_err());
        assert_eq!(range, 0..2);
        assert!(message.contains("starts with its T word"), "{message}");
        let (_, message) = parts(ToolTable::parse("T1.5 Z1\n").unwrap_err());
        assert!(message.contains("whole number"), "{message}");
        let (_, message) = parts(ToolTable::parse("T1 R2\n").unwrap_err());
        assert!(message.contains("`R2`"), "{message}");
        let (range, message) = parts(ToolTable::parse("T1 D1 Q10\n").unwrap_err());
        assert_eq!(range, 6..9);
        assert!(message.contains("orientation"), "{message}");
        let table = ToolTable::parse("T3 D0.8 Q6\n").unwrap();
        assert_eq!(table.get(3).map(|t| t.orientation), Some(6));
    }
}

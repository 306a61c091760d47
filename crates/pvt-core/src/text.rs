//! Positions in source text: a byte offset to its 1-based line and column, a 1-based
//! line to its byte range or span, the last line of a text, and [`SourceLocation`],
//! where a span is as a person reads it ([`crate::toolpath::Span::location`], in the
//! manner of naga's `Span::location`).
//!
//! Owns the only line/column arithmetic of the workspace: every front end and the CLI
//! call these (or miette's `SourceCode`, which answers the same questions for a
//! renderer), so a diagnostic names the same line and column on every route. It must
//! not read files or know any format: it works on text already in memory.

use std::ops::Range;

/// The UTF-8 byte order mark, which editors may put before the first line.
const BOM: char = '\u{feff}';

/// Where a span of source text is, as a person reads it: the one type every front end's
/// and the CLI's line and column take.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct SourceLocation {
    /// 1-based line of the span's start.
    pub line: u32,
    /// 1-based column of the span's start, in characters (a byte order mark not counted).
    pub column: u32,
    /// Byte offset of the span's start.
    pub offset: usize,
    /// Length of the span, bytes.
    pub length: usize,
}

impl SourceLocation {
    /// Where the byte range `span` of `source` is.
    pub fn of(source: &str, span: Range<usize>) -> SourceLocation {
        let (line, column) = line_col(source, span.start);
        SourceLocation {
            line: u32::try_from(line).unwrap_or(u32::MAX),
            column: u32::try_from(column).unwrap_or(u32::MAX),
            offset: span.start,
            length: span.end.saturating_sub(span.start),
        }
    }
}

impl crate::toolpath::Span {
    /// Where this span is in `source`, the text it was read from.
    pub fn location(&self, source: &str) -> SourceLocation {
        SourceLocation::of(source, self.start..self.end)
    }
}

impl crate::toolpath::Span {
    /// The span of 1-based `line` of `bytes` ([`line_range`]: its bytes without the `\n`),
    /// naming that line.
    pub fn of_line(bytes: &[u8], line: usize) -> crate::toolpath::Span {
        let range = line_range(bytes, line);
        crate::toolpath::Span {
            start: range.start,
            end: range.end,
            line: u32::try_from(line).unwrap_or(u32::MAX),
        }
    }
}

/// The 1-based number of the last line of `bytes`: a final `\n` ends that line and opens
/// none; an empty text is line 1.
pub fn last_line(bytes: &[u8]) -> usize {
    let trailing = usize::from(bytes.last() == Some(&b'\n'));
    line_of(bytes, bytes.len()).saturating_sub(trailing).max(1)
}

/// The 1-based line and column (in characters, a byte order mark not counted) of a byte
/// offset in `source`.
///
/// An offset past the end names the end of the source; one inside a character names it.
pub fn line_col(source: &str, byte_offset: usize) -> (usize, usize) {
    let mut offset = byte_offset.min(source.len());
    while !source.is_char_boundary(offset) {
        offset -= 1;
    }
    let before = &source[..offset];
    let line = line_of(source.as_bytes(), offset);
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    let text = &before[line_start..];
    let text = text.strip_prefix(BOM).unwrap_or(text);
    (line, 1 + text.chars().count())
}

/// The 1-based line holding byte `offset` of `bytes` (which need not be UTF-8); an offset
/// past the end is on the last line, the empty one after a final `\n` included.
pub fn line_of(bytes: &[u8], offset: usize) -> usize {
    let before = &bytes[..offset.min(bytes.len())];
    1 + before.iter().filter(|&&b| b == b'\n').count()
}

/// The byte range of 1-based `line` of `bytes`, without its `\n` (a `\r` before it is
/// kept: the line's bytes as written); line 0 is line 1, and a line past the end is the
/// empty range at the end.
pub fn line_range(bytes: &[u8], line: usize) -> Range<usize> {
    let mut start = 0;
    for _ in 1..line.max(1) {
        match newline(&bytes[start..]) {
            Some(i) => start += i + 1,
            None => return bytes.len()..bytes.len(),
        }
    }
    let end = newline(&bytes[start..]).map_or(bytes.len(), |i| start + i);
    start..end
}

fn newline(bytes: &[u8]) -> Option<usize> {
    bytes.iter().position(|&b| b == b'\n')
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_col_counts_lines_and_characters() {
        let src = "G0 X1\nG1 é Y2\r\nG2";
        assert_eq!(line_col(src, 0), (1, 1));
        assert_eq!(line_col(src, 6), (2, 1));
        // After the two-byte é, the column counts characters.
        assert_eq!(line_col(src, 12), (2, 6));
        // Inside é: the character's own column.
        assert_eq!(line_col(src, 10), (2, 4));
        assert_eq!(line_col(src, 1000), (3, 3));
        assert_eq!(line_col("\u{feff}G0", 3), (1, 1));
        assert_eq!(line_col("\u{feff}G0", 4), (1, 2));
        assert_eq!(line_of(b"a\n\xffb\n", 3), 2);
        assert_eq!(line_of(b"a\n", 2), 2);
        assert_eq!(line_of(b"a\n", 99), 2);
    }

    #[test]
    fn a_span_knows_its_location() {
        let src = "G0 X1\nG1 é Y2\r\nG2";
        let span = crate::toolpath::Span {
            start: 12,
            end: 14,
            line: 2,
        };
        let location = span.location(src);
        assert_eq!((location.line, location.column), (2, 6));
        assert_eq!((location.offset, location.length), (12, 2));
    }

    #[test]
    fn a_line_is_a_span_and_the_last_line_is_the_last_with_text() {
        let text = b"0\nSECTION\n2\nENTITIES";
        let span = crate::toolpath::Span::of_line(text, 3);
        assert_eq!((span.start, span.end, span.line), (10, 11, 3));
        assert_eq!(crate::toolpath::Span::of_line(text, 9).start, text.len());
        // Counted by hand: four lines, with or without a final newline.
        assert_eq!(last_line(text), 4);
        assert_eq!(last_line(b"0\nSECTION\n2\nENTITIES\n"), 4);
        assert_eq!(last_line(b"a\n\n"), 2);
        assert_eq!(last_line(b""), 1);
        assert_eq!(last_line(b"\n"), 1);
    }

    #[test]
    fn line_range_counts_from_one() {
        let text = b"0\nSECTION\n2\nENTITIES";
        assert_eq!(line_range(text, 3), 10..11);
        assert_eq!(line_range(text, 1), 0..1);
        assert_eq!(line_range(text, 0), 0..1);
        assert_eq!(line_range(text, 4), 12..text.len());
        assert_eq!(line_range(text, 9), text.len()..text.len());
        assert_eq!(line_range(b"a\r\nb\n", 1), 0..2);
        // The line after a final newline is the empty one at the end.
        assert_eq!(line_range(b"a\n", 2), 2..2);
    }

    #[test]
    fn the_two_agree() {
        // An independent statement of both: split the text on '\n' by hand.
        let src = "N1 G0\n\nN3 G1 X1\r\nlast";
        let mut offset = 0;
        for (i, l) in src.split('\n').enumerate() {
            assert_eq!(line_range(src.as_bytes(), i + 1), offset..offset + l.len());
            assert_eq!(line_col(src, offset), (i + 1, 1));
            offset += l.len() + 1;
        }
    }
}

//! A byte stream cut into lines: byte offsets, line ends, the BOM and the bound on line
//! length. Each buffer is checked as UTF-8 once and its lines handed over as text; a line
//! that is not (or not known to be) valid UTF-8 is handed over as bytes, for the caller to
//! read as it sees fit.
//!
//! Owns [`MAX_LINE_BYTES`] and the guarantee that reading a stream holds at most one line
//! of that length in memory, whatever the input (a 100 MB line, a 1 GB unterminated
//! comment). A line that fits in the reader's buffer is handed over in place, without a
//! copy. It must not parse a line.

use std::io::BufRead;

/// Longest line pvtc reads, in bytes, line end not counted (RS274NGC allows 256); a longer
/// line is `pvtc::gcode::line_too_long` and is skipped without being held in memory.
pub const MAX_LINE_BYTES: usize = 64 * 1024;

const BOM: &[u8] = "\u{feff}".as_bytes();

/// One line of the stream.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Line<'a> {
    /// A line within the limit, in valid UTF-8 (checked once for a whole buffer).
    Text {
        /// The text, line end (and a leading BOM) removed.
        text: &'a str,
        /// Byte offset of the text in the stream.
        start: usize,
    },
    /// A line within the limit that is not known to be UTF-8 (it has invalid bytes, or
    /// was completed across buffers): the reader decides how to read it as text.
    Bytes {
        /// The bytes, line end (and a leading BOM) removed.
        bytes: &'a [u8],
        /// Byte offset of the bytes in the stream.
        start: usize,
    },
    /// A line over [`MAX_LINE_BYTES`]: where it starts and how long it is.
    TooLong {
        /// Byte offset of the line in the stream.
        start: usize,
        /// Its length, line end not counted.
        length: usize,
    },
}

/// Hands every line of `input` to `each` ([`Line::Bytes`] or [`Line::TooLong`]) until
/// `each` returns false or the input ends.
pub(crate) fn read_lines(
    input: &mut dyn BufRead,
    each: &mut dyn FnMut(Line<'_>) -> bool,
) -> std::io::Result<()> {
    let mut splitter = Splitter::default();
    if each_buffer(input, &mut |chunk| splitter.feed(chunk, each))? {
        splitter.finish(each);
    }
    Ok(())
}

/// Hands every buffer `input` fills to `each` until `each` returns false (then returns
/// false) or the input ends (true); an interrupted read is retried.
pub(crate) fn each_buffer(
    input: &mut dyn BufRead,
    each: &mut dyn FnMut(&[u8]) -> bool,
) -> std::io::Result<bool> {
    loop {
        let chunk = match input.fill_buf() {
            Ok(chunk) => chunk,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(e),
        };
        if chunk.is_empty() {
            return Ok(true);
        }
        let len = chunk.len();
        let go_on = each(chunk);
        input.consume(len);
        if !go_on {
            return Ok(false);
        }
    }
}

/// The state between chunks: the start of the line being read and what is held of it.
#[derive(Default)]
struct Splitter {
    /// Offset of the next byte fed.
    offset: usize,
    /// Offset of the line being read.
    line_start: usize,
    /// Bytes of a line begun in an earlier chunk, while it is within the limit.
    pending: Vec<u8>,
    /// Once the line is over the limit: its length so far, and nothing is held.
    overlong: Option<usize>,
    /// Bytes of a BOM at the start of an over-long first line (not part of its length).
    bom: usize,
    /// How many `\r` end an over-long line so far (not part of its length).
    ends_cr: usize,
}

impl Splitter {
    fn feed(&mut self, chunk: &[u8], each: &mut dyn FnMut(Line<'_>) -> bool) -> bool {
        // The buffer is checked as UTF-8 once; its lines are then slices of that text.
        let text = match std::str::from_utf8(chunk) {
            Ok(text) => text,
            Err(e) => std::str::from_utf8(&chunk[..e.valid_up_to()]).unwrap_or_default(),
        };
        let mut at = 0;
        while let Some(len) = memchr::memchr(b'\n', &chunk[at..]) {
            let end = at + len;
            let go_on = if self.pending.is_empty() && self.overlong.is_none() {
                deliver(&chunk[at..end], text.get(at..end), self.line_start, each)
            } else {
                self.append(&chunk[at..end]);
                self.take_line(each)
            };
            self.offset += len + 1;
            self.line_start = self.offset;
            at = end + 1;
            if !go_on {
                return false;
            }
        }
        self.append(&chunk[at..]);
        self.offset += chunk.len() - at;
        true
    }

    /// Adds bytes to the line being read, letting go of them once it is over the limit.
    fn append(&mut self, piece: &[u8]) {
        let crs = trailing_crs(piece);
        self.ends_cr = match crs == piece.len() {
            true => self.ends_cr + crs,
            false => crs,
        };
        if let Some(length) = &mut self.overlong {
            *length += piece.len();
            return;
        }
        // Room for a BOM and a `\r`, which do not count; `deliver` measures exactly.
        if self.pending.len() + piece.len() <= MAX_LINE_BYTES + BOM.len() + 1 {
            self.pending.extend_from_slice(piece);
            return;
        }
        // The line goes over the limit here: note whether it began with a BOM, then keep
        // only its length.
        let head: Vec<u8> = self
            .pending
            .iter()
            .chain(piece)
            .take(BOM.len())
            .copied()
            .collect();
        self.bom = if self.line_start == 0 && head == BOM {
            BOM.len()
        } else {
            0
        };
        self.overlong = Some(self.pending.len() + piece.len());
        self.pending = Vec::new();
    }

    /// Hands over the line read so far and starts the next.
    fn take_line(&mut self, each: &mut dyn FnMut(Line<'_>) -> bool) -> bool {
        let go_on = match self.overlong.take() {
            Some(length) => each(Line::TooLong {
                start: self.line_start + self.bom,
                length: length - self.bom - self.ends_cr,
            }),
            None => deliver(&self.pending, None, self.line_start, each),
        };
        self.pending.clear();
        self.bom = 0;
        self.ends_cr = 0;
        go_on
    }

    /// Hands over a last line that has no line end.
    fn finish(mut self, each: &mut dyn FnMut(Line<'_>) -> bool) {
        // A file that is only a BOM has no line, as in `SourceLines`.
        let only_bom = self.line_start == 0 && self.pending == BOM;
        if (!self.pending.is_empty() && !only_bom) || self.overlong.is_some() {
            self.take_line(each);
        }
    }
}

/// Hands over one whole line (without its `\n`) that starts at byte `start`; `text` is
/// the same line when it is known to be UTF-8.
fn deliver(
    line: &[u8],
    text: Option<&str>,
    start: usize,
    each: &mut dyn FnMut(Line<'_>) -> bool,
) -> bool {
    let bom = if start == 0 && line.starts_with(BOM) {
        BOM.len()
    } else {
        0
    };
    let end = line.len() - trailing_crs(&line[bom..]);
    let (line, start) = (&line[bom..end], start + bom);
    if line.len() > MAX_LINE_BYTES {
        return each(Line::TooLong {
            start,
            length: line.len(),
        });
    }
    match text.and_then(|text| text.get(bom..end)) {
        Some(text) => each(Line::Text { text, start }),
        None => each(Line::Bytes { bytes: line, start }),
    }
}

/// How many `\r` end `bytes`: every one before a line's `\n` is part of its line end
/// (CR CR LF, as PyCAM 0.5 writes, is one line end, as `rs274` reads it).
pub fn trailing_crs(bytes: &[u8]) -> usize {
    bytes.iter().rev().take_while(|b| **b == b'\r').count()
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[derive(Debug, PartialEq)]
    enum Got {
        Text(String, usize),
        TooLong(usize, usize),
    }

    fn streamed(bytes: &[u8], capacity: usize) -> Vec<Got> {
        let mut input = std::io::BufReader::with_capacity(capacity, bytes);
        let mut got = Vec::new();
        read_lines(&mut input, &mut |line| {
            got.push(match line {
                Line::Bytes { bytes, start } => {
                    Got::Text(String::from_utf8_lossy(bytes).into_owned(), start)
                }
                Line::Text { text, start } => Got::Text(text.to_owned(), start),
                Line::TooLong { start, length } => Got::TooLong(start, length),
            });
            true
        })
        .unwrap();
        got
    }

    /// What the in-memory path sees: `SourceLines` and the same length check.
    fn in_memory(text: &str) -> Vec<Got> {
        crate::parser::SourceLines::new(text)
            .map(|l| match l.text.len() > MAX_LINE_BYTES {
                true => Got::TooLong(l.start, l.text.len()),
                false => Got::Text(l.text.to_owned(), l.start),
            })
            .collect()
    }

    #[test]
    fn offsets_line_ends_and_bom() {
        let text = "\u{feff}G0 X1\r\n\nG1 Y2";
        assert_eq!(
            streamed(text.as_bytes(), 4),
            [
                Got::Text("G0 X1".into(), 3),
                Got::Text(String::new(), 10),
                Got::Text("G1 Y2".into(), 11)
            ]
        );
    }

    #[test]
    fn a_file_of_only_a_bom_has_no_line() {
        assert_eq!(streamed("\u{feff}".as_bytes(), 2), []);
        assert_eq!(in_memory("\u{feff}"), []);
    }

    #[test]
    fn an_over_long_line_is_measured_not_held() {
        let mut text = vec![b'('; 3 * MAX_LINE_BYTES];
        text.extend_from_slice(b"\r\nG0 X1");
        assert_eq!(
            streamed(&text, 1000),
            [
                Got::TooLong(0, 3 * MAX_LINE_BYTES),
                Got::Text("G0 X1".into(), 3 * MAX_LINE_BYTES + 2)
            ]
        );
    }

    fn piece() -> impl Strategy<Value = String> {
        prop_oneof![
            4 => "[GX0-9 .]{1,12}",
            3 => Just("\n".to_owned()),
            1 => Just("\r\n".to_owned()),
            1 => Just("\r".to_owned()),
            1 => Just("\r\r\n".to_owned()),
            1 => Just("\u{feff}".to_owned()),
            1 => (MAX_LINE_BYTES - 3..MAX_LINE_BYTES + 4).prop_map(|n| "x".repeat(n)),
        ]
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]
        /// Streaming in chunks of any size gives the lines the in-memory path gives.
        #[test]
        fn chunked_reading_matches_the_in_memory_lines(
            pieces in proptest::collection::vec(piece(), 0..24),
            capacity in 1usize..200,
        ) {
            let text = pieces.concat();
            prop_assert_eq!(streamed(text.as_bytes(), capacity), in_memory(&text));
        }
    }
}

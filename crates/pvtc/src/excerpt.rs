//! Source lines around diagnostics, cut from a file that is not held in memory.
//!
//! Owns [`cut`]: one streaming pass over a file that keeps, for each span, the lines
//! around it with their line number and byte offset, and [`Excerpt`], a miette
//! [`SourceCode`] over those lines that answers in the file's own offsets and line
//! numbers, so a diagnostic from a ten-million-line program shows its line and column
//! while memory holds only a few lines. It must not decide which diagnostics to show.

use std::collections::VecDeque;
use std::io::{BufRead, Read};
use std::ops::Range;

use pvt_core::text::LineCursor;

use miette::{MietteError, MietteSpanContents, SourceCode, SourceSpan, SpanContents};

/// Lines kept before and after the lines of a span (miette shows one by default).
const CONTEXT_LINES: usize = 2;

/// Bytes shown of a line longer than [`MAX_EXCERPT_LINE`].
const LONG_LINE_SHOWN: usize = 120;

/// Longest line copied into an excerpt; a longer one ends the context around it.
const MAX_EXCERPT_LINE: u64 = 64 * 1024;

/// Whole lines of a file, from byte `offset` and 0-based line `first_line` on.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Excerpt {
    text: String,
    offset: usize,
    first_line: usize,
}

impl SourceCode for Excerpt {
    fn read_span<'a>(
        &'a self,
        span: &SourceSpan,
        before: usize,
        after: usize,
    ) -> Result<Box<dyn SpanContents<'a> + 'a>, MietteError> {
        let start = span
            .offset()
            .checked_sub(self.offset)
            .ok_or(MietteError::OutOfBounds)?;
        // A span running past the excerpt (a line too long to keep) shows what is kept.
        let start = start.min(self.text.len());
        let local = SourceSpan::new(start.into(), span.len().min(self.text.len() - start));
        let contents = self.text.as_str().read_span(&local, before, after)?;
        let at = contents.span().offset() + self.offset;
        Ok(Box::new(MietteSpanContents::new(
            contents.data(),
            SourceSpan::new(at.into(), contents.span().len()),
            contents.line() + self.first_line,
            contents.column(),
            contents.line_count(),
        )))
    }
}

/// An excerpt being gathered for one span.
struct Open {
    index: usize,
    excerpt: Excerpt,
    end: usize,
    /// Lines still to add once the span's last line is in.
    after: Option<usize>,
}

/// The byte range of 1-based `line` of `input` (without its line end), found in one
/// streaming pass; `None` past the end.
pub fn line_span(input: &mut impl BufRead, line: u32) -> std::io::Result<Option<Range<usize>>> {
    let (mut cursor, mut buf) = (LineCursor::default(), Vec::new());
    loop {
        buf.clear();
        let read = input.read_until(b'\n', &mut buf)?;
        if read == 0 {
            return Ok(None);
        }
        let at = cursor.pass(read);
        if at.number == line as usize {
            let body = buf.strip_suffix(b"\n").unwrap_or(&buf);
            let body = &body[..body.len() - pvt_gcode::trailing_crs(body)];
            return Ok(Some(at.offset..at.offset + body.len()));
        }
    }
}

/// For each span (byte range of `input`), the lines around it; `None` for a span past the
/// end of the input or on a line longer than [`MAX_EXCERPT_LINE`].
pub fn cut(
    input: &mut impl BufRead,
    spans: &[Range<usize>],
) -> std::io::Result<Vec<Option<Excerpt>>> {
    let mut order: Vec<usize> = (0..spans.len()).collect();
    order.sort_by_key(|&i| spans[i].start);
    let mut order = order.into_iter().peekable();
    let mut found = vec![None; spans.len()];
    let (mut ring, mut open) = (VecDeque::<(usize, String)>::new(), Vec::<Open>::new());
    let (mut cursor, mut line) = (LineCursor::default(), Vec::new());
    while order.peek().is_some() || !open.is_empty() {
        line.clear();
        let read = input
            .by_ref()
            .take(MAX_EXCERPT_LINE)
            .read_until(b'\n', &mut line)?;
        if read == 0 {
            break;
        }
        let long = read as u64 == MAX_EXCERPT_LINE && line.last() != Some(&b'\n');
        let skipped = if long { input.skip_until(b'\n')? } else { 0 };
        let at = cursor.pass(read + skipped);
        // The line's byte offset, where the next starts, and its 0-based number.
        let (start, offset, number) = (at.offset, cursor.offset, at.number - 1);
        if long {
            ring.clear();
            open.drain(..)
                .for_each(|o| found[o.index] = Some(o.excerpt));
            // A span on the long line gets its first bytes, so it keeps its line number.
            let head = String::from_utf8_lossy(&line[..line.len().min(LONG_LINE_SHOWN)]);
            while let Some(i) = order.next_if(|&i| spans[i].start < offset) {
                found[i] = Some(Excerpt {
                    text: format!("{head}…"),
                    offset: start,
                    first_line: number,
                });
            }
            continue;
        }
        let text = crate::options::shown(&line);
        while let Some(index) = order.next_if(|&i| spans[i].start < offset) {
            let first = ring.front().map_or(start, |(at, _)| *at);
            let before: String = ring.iter().map(|(_, t)| t.as_str()).collect();
            open.push(Open {
                index,
                excerpt: Excerpt {
                    text: before,
                    offset: first,
                    first_line: number - ring.len(),
                },
                end: spans[index].end,
                after: None,
            });
        }
        for o in &mut open {
            o.excerpt.text.push_str(&text);
            match &mut o.after {
                Some(left) => *left -= 1,
                None if o.end <= offset => o.after = Some(CONTEXT_LINES),
                None => {}
            }
        }
        open.retain_mut(|o| {
            let done = o.after == Some(0);
            if done {
                found[o.index] = Some(std::mem::take(&mut o.excerpt));
            }
            !done
        });
        ring.push_back((start, text));
        if ring.len() > CONTEXT_LINES {
            ring.pop_front();
        }
    }
    open.into_iter()
        .for_each(|o| found[o.index] = Some(o.excerpt));
    Ok(found)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(excerpt: &Excerpt, span: Range<usize>) -> (String, usize, usize) {
        let contents = excerpt
            .read_span(&SourceSpan::from(span.start..span.end), 0, 0)
            .unwrap();
        let data = String::from_utf8(contents.data().to_vec()).unwrap();
        (data, contents.line(), contents.column())
    }

    #[test]
    fn an_excerpt_answers_in_file_offsets_and_line_numbers() {
        let file: String = (1..=100).map(|n| format!("G1 X{n}\r\n")).collect();
        let at = file.find("X57").unwrap();
        let excerpts = cut(&mut file.as_bytes(), &[at..at + 3, 0..0, 9999..10000]).unwrap();
        let excerpt = excerpts[0].as_ref().unwrap();
        assert_eq!(read(excerpt, at..at + 3), ("X57".to_owned(), 56, 3));
        assert_eq!(excerpt.first_line, 54);
        assert_eq!(excerpt.text.lines().count(), 5);
        assert_eq!(read(excerpts[1].as_ref().unwrap(), 0..0).1, 0);
        assert!(excerpts[2].is_none());
    }

    #[test]
    fn a_miette_report_shows_the_line_from_an_excerpt() {
        let file: String = (1..=1000).map(|n| format!("G1 X{n}\n")).collect();
        let at = file.find("X777").unwrap();
        let spans = vec![at..at + 4, at..at];
        let excerpt = cut(&mut file.as_bytes(), &spans)
            .unwrap()
            .remove(0)
            .unwrap();
        let whole = file.as_str().read_span(&(at..at + 4).into(), 1, 1).unwrap();
        let cut = excerpt.read_span(&(at..at + 4).into(), 1, 1).unwrap();
        assert_eq!(cut.data(), whole.data());
        assert_eq!((cut.line(), cut.column()), (whole.line(), whole.column()));
        assert_eq!(cut.span(), whole.span());
    }
}

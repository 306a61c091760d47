//! A quick look at a program before compiling it: the axes its words name and its first
//! units word, read lexically (no parameters, expressions or modes).
//!
//! Owns nothing a compile relies on. Its answer is a guess that lets a streaming caller
//! write a header (which lists the moved axes and the units) before the compile has seen
//! the whole program; that caller must check the guess against what the compile itself
//! found ([`crate::StreamSummary::units`] and the elements it received) and start over
//! when they differ. It must not report diagnostics.

use std::io::BufRead;

use pvt_core::{Units, AXIS_COUNT};

use crate::lines::{each_buffer, MAX_LINE_BYTES};

/// What the words of a program suggest, before it is compiled.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Prescan {
    /// Per axis, in X Y Z A B C order: a word of that letter with a value appears outside
    /// comments and brackets.
    pub axis_words: [bool; AXIS_COUNT],
    /// The units of the first G20 or G21 word, if there is one.
    pub units: Option<Units>,
}

/// Reads `input` to its end and returns what its words suggest (see [`Prescan`]).
///
/// Reads whole buffers at a time: the complete lines of a buffer are first looked at
/// together (see [`scan_lines`]). A line begun in one buffer is completed from the next;
/// beyond [`MAX_LINE_BYTES`] (a line the compile refuses) its bytes are not kept.
pub fn prescan(input: &mut dyn BufRead) -> std::io::Result<Prescan> {
    let mut found = Prescan::default();
    let mut begun = Vec::new();
    each_buffer(input, &mut |chunk| {
        match memchr::memchr(b'\n', chunk) {
            None => keep_line_start(&mut begun, chunk),
            Some(first_end) => {
                keep_line_start(&mut begun, &chunk[..first_end]);
                scan_line(&begun, &mut found);
                begun.clear();
                let rest = &chunk[first_end + 1..];
                let whole = memchr::memrchr(b'\n', rest).map_or(0, |end| end + 1);
                scan_lines(&rest[..whole], &mut found);
                keep_line_start(&mut begun, &rest[whole..]);
            }
        }
        true
    })?;
    scan_line(&begun, &mut found);
    Ok(found)
}

/// Adds `piece` to the line being read, up to [`MAX_LINE_BYTES`].
fn keep_line_start(begun: &mut Vec<u8>, piece: &[u8]) {
    let room = (MAX_LINE_BYTES + 2).saturating_sub(begun.len());
    begun.extend_from_slice(&piece[..piece.len().min(room)]);
}

/// Notes the axis words of `lines` (complete lines, each ending in `\n`). Where none of
/// the letters that could still add to `found` appears in them, they add nothing. When
/// none of them needs the full scan, their letters are their words' letters, gathered in
/// one pass over all their bytes; otherwise each line is scanned alone.
fn scan_lines(lines: &[u8], found: &mut Prescan) {
    if !may_add(lines, found) {
        return;
    }
    let letters = letters_of(lines);
    let units_wanted = found.units.is_none() && letters & G_BIT != 0;
    if letters & SPECIAL == 0 && !units_wanted {
        mark_axes(letters, found);
        return;
    }
    let mut start = 0;
    for end in memchr::memchr_iter(b'\n', lines) {
        scan_line(&lines[start..end], found);
        start = end + 1;
    }
}

/// Whether `bytes` hold, in either case, the letter of an axis not yet found or, while
/// the units are unknown, a G: the only letters whose words can add to `found`. A
/// program's axes are mostly all found in its first lines, so that most buffers are
/// looked at by a few vector searches for the letters left (A, B and C on a mill) instead
/// of byte by byte.
fn may_add(bytes: &[u8], found: &Prescan) -> bool {
    let has = |letter: u8| memchr::memchr2(letter, letter.to_ascii_lowercase(), bytes).is_some();
    let axis_left = |(axis, &letter): (usize, &u8)| !found.axis_words[axis] && has(letter);
    b"XYZABC".iter().enumerate().any(axis_left) || (found.units.is_none() && has(b'G'))
}

/// The [`CLASS`] bits of every byte of `bytes`, or-ed together (eight accumulators, so
/// that the loads do not wait on each other).
fn letters_of(bytes: &[u8]) -> u32 {
    let mut lanes = [0u32; 8];
    let mut chunks = bytes.chunks_exact(8);
    for chunk in &mut chunks {
        for (lane, &c) in lanes.iter_mut().zip(chunk) {
            *lane |= CLASS[usize::from(c)];
        }
    }
    let tail = chunks
        .remainder()
        .iter()
        .fold(0, |seen, &c| seen | CLASS[usize::from(c)]);
    lanes.iter().fold(tail, |seen, lane| seen | lane)
}

/// Marks the axes whose letters are among `letters` ([`CLASS`] bits).
fn mark_axes(letters: u32, found: &mut Prescan) {
    for (seen, bit) in found.axis_words.iter_mut().zip(AXIS_BITS) {
        *seen |= letters & bit != 0;
    }
}

/// Per byte: the bit of its letter (either case, bit 0 for A), or [`SPECIAL`] for the
/// bytes after which a letter may not be a word (comment and bracket marks, `<` of a
/// named parameter, `%` of a program delimiter line, the `O` of a control word), or
/// nothing.
static CLASS: [u32; 256] = {
    let mut class = [0u32; 256];
    let mut c = 0;
    while c < 256 {
        let b = (c as u8).to_ascii_uppercase();
        class[c] = match b {
            b'(' | b';' | b'[' | b']' | b'<' | b'%' | b'O' => SPECIAL,
            b'A'..=b'Z' => 1 << (b - b'A'),
            _ => 0,
        };
        c += 1;
    }
    class
};

/// The class bit of bytes that send a line to the full scan.
const SPECIAL: u32 = 1 << 31;

/// The class bit of G, whose words hold the units.
const G_BIT: u32 = 1 << (b'G' - b'A');

/// The class bits of the axis letters, in X Y Z A B C order.
const AXIS_BITS: [u32; AXIS_COUNT] = {
    let letters = *b"XYZABC";
    let mut bits = [0u32; AXIS_COUNT];
    let mut i = 0;
    while i < AXIS_COUNT {
        bits[i] = 1 << (letters[i] - b'A');
        i += 1;
    }
    bits
};

/// Notes the axis words of line `b`. Most lines hold only words: the letters they
/// contain are their words' letters, found in one pass over the bytes. Lines with
/// comments, brackets, named parameters or O-words, and G words while the units are
/// unknown, take the full scan.
fn scan_line(b: &[u8], found: &mut Prescan) {
    let letters = letters_of(b);
    let units_wanted = found.units.is_none() && letters & G_BIT != 0;
    if letters & SPECIAL != 0 || units_wanted {
        return scan_words(b, found);
    }
    mark_axes(letters, found);
}

/// The bytes that can change what the full scan sees: letters, comment and bracket marks.
static MARKS: [bool; 256] = {
    let mut marks = [false; 256];
    let mut c = 0;
    while c < 256 {
        let b = c as u8;
        marks[c] = b.is_ascii_alphabetic() || matches!(b, b'(' | b';' | b'[' | b']');
        c += 1;
    }
    marks
};

/// The full scan of line `b`: each single letter with a value, outside comments and
/// brackets, is a word.
fn scan_words(b: &[u8], found: &mut Prescan) {
    let (mut at, mut depth) = (0, 0u32);
    while let Some(&c) = b.get(at) {
        if !MARKS[usize::from(c)] {
            at += 1;
            continue;
        }
        match c {
            b'(' if depth == 0 => {
                at += b[at..]
                    .iter()
                    .position(|&c| c == b')')
                    .unwrap_or(b.len() - at);
            }
            b';' if depth == 0 => return,
            b'[' => depth += 1,
            b']' => depth = depth.saturating_sub(1),
            c if c.is_ascii_alphabetic() => {
                let run = b[at..]
                    .iter()
                    .take_while(|c| c.is_ascii_alphabetic())
                    .count();
                if run == 1 && depth == 0 {
                    word(c.to_ascii_uppercase(), &b[at + 1..], found);
                }
                at += run;
                continue;
            }
            _ => {}
        }
        at += 1;
    }
}

/// Notes the word of `letter` whose value text follows in `after`.
fn word(letter: u8, after: &[u8], found: &mut Prescan) {
    let after = after.trim_ascii_start();
    if !matches!(
        after.first(),
        Some(b'0'..=b'9' | b'.' | b'+' | b'-' | b'[' | b'#')
    ) {
        return;
    }
    if let Some(axis) = b"XYZABC".iter().position(|&a| a == letter) {
        found.axis_words[axis] = true;
    } else if letter == b'G' && found.units.is_none() {
        let len = after
            .iter()
            .take_while(|c| c.is_ascii_digit() || **c == b'.')
            .count();
        let number: Option<f64> = std::str::from_utf8(&after[..len])
            .ok()
            .and_then(|t| t.parse().ok());
        found.units = match number {
            Some(20.0) => Some(Units::Inch),
            Some(21.0) => Some(Units::Millimetre),
            _ => None,
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scan(text: &str) -> Prescan {
        prescan(&mut text.as_bytes()).unwrap()
    }

    #[test]
    fn axis_words_outside_comments_brackets_and_names() {
        let p = scan("G21 G0X1 y2 (Z3) ; A4\n#<b> = [ACOS[0]] o100 repeat [2]\nC [#<b>]");
        assert_eq!(p.axis_words, [true, true, false, false, false, true]);
        assert_eq!(p.units, Some(Units::Millimetre));
    }

    #[test]
    fn the_quick_pass_agrees_with_the_full_scan() {
        let lines = [
            "X1 Y2 Z3",
            "x-.5 a+2 F1500",
            "G1 X1",
            "N10 G0 Z5 M3 S1000",
            "G2 X1 Y1 I0.5 J0 (arc) ; end",
            "#<xa> = 2",
            "#1 = [ACOS[0]] B2",
            "o100 sub",
            "% begin XYZ",
            "/ Y 1 . 5",
            "C7 *12",
        ];
        for units in [None, Some(Units::Inch)] {
            for line in lines {
                let (mut quick, mut full) = (
                    Prescan {
                        units,
                        ..Prescan::default()
                    },
                    Prescan {
                        units,
                        ..Prescan::default()
                    },
                );
                scan_line(line.as_bytes(), &mut quick);
                scan_words(line.as_bytes(), &mut full);
                assert_eq!(quick, full, "{line:?} with units {units:?}");
            }
        }
    }

    #[test]
    fn any_buffer_size_gives_the_line_by_line_answer() {
        let text = "%\r\nG0 X1 (Y2)\r\n; Z3\nG20 B1\n#<ax> = 2\nG1 C1 F[2*3]\nA1";
        let mut by_line = Prescan::default();
        for line in text.split('\n') {
            scan_words(line.as_bytes(), &mut by_line);
        }
        assert_eq!(by_line.axis_words, [true, false, false, true, true, true]);
        assert_eq!(by_line.units, Some(Units::Inch));
        for capacity in 1..=text.len() {
            let mut input = std::io::BufReader::with_capacity(capacity, text.as_bytes());
            assert_eq!(
                prescan(&mut input).unwrap(),
                by_line,
                "buffers of {capacity}"
            );
        }
    }

    /// Lines without a letter that could add to what was found add nothing, whatever
    /// else they hold; a line with one is scanned.
    #[test]
    fn lines_without_a_letter_left_are_passed_over() {
        let xy = Prescan {
            axis_words: [true, true, false, false, false, false],
            units: Some(Units::Millimetre),
        };
        let passed = [
            "X1 Y2\nG1 X3 F100 (feed)\n",
            "M3 S1000\n; end\n",
            "#<x> = [SIN[1]]\n",
        ];
        for lines in passed {
            assert!(!may_add(lines.as_bytes(), &xy), "{lines:?}");
            let mut after = xy;
            scan_lines(lines.as_bytes(), &mut after);
            assert_eq!(after, xy, "{lines:?}");
        }
        for (lines, axis) in [
            ("G1 z-1\n", 2),
            ("X1 A90\n", 3),
            ("b2\n", 4),
            ("(c) C1\n", 5),
        ] {
            assert!(may_add(lines.as_bytes(), &xy), "{lines:?}");
            let mut after = xy;
            scan_lines(lines.as_bytes(), &mut after);
            assert!(after.axis_words[axis], "{lines:?}");
        }
        // A word in a comment only: looked at, and still not a word.
        let mut after = xy;
        scan_lines(b"(Z is up)\n", &mut after);
        assert_eq!(after, xy);
        // Units unknown: a G is looked at.
        let unknown = Prescan { units: None, ..xy };
        assert!(may_add(b"g20\n", &unknown));
        let mut after = unknown;
        scan_lines(b"g20\n", &mut after);
        assert_eq!(after.units, Some(Units::Inch));
    }

    #[test]
    fn the_first_units_word_counts() {
        assert_eq!(scan("G0 X1\nG20\nG21").units, Some(Units::Inch));
        assert_eq!(scan("G0 X1").units, None);
        assert_eq!(scan("G2 X1").units, None);
    }
}
